//! The collision checks in the `.mcap`: a `/collisions` channel per control step (pairs in contact,
//! the smallest distance within 5 cm, the pairs in contact or else the nearest by name — protobuf
//! `armscope.CollisionState`), the scene's objects and the payload drawn with the robot's geometry, and `/collisions/contacts`, a
//! `SceneUpdate` that paints the links and objects in contact red. Each contacts message replaces
//! the whole set (all deleted, those in contact added), so the latest one, all a viewer reads after
//! seeking, is right on its own; it is sent only when the set changes.

use super::scene::add_primitives;
use crate::recorder::shared::contacts::{Body, ContactTracker, pair_name};
use crate::recorder::shared::floor_plate::drawn;
use crate::collision::Collisions;
use crate::model::Model;
use foxglove::messages::{Color, SceneEntity, SceneEntityDeletion, SceneUpdate, Timestamp};
use prost::Message;
use super::protobuf_schema::{Field, encode_as_protobuf, file_descriptor_set as file_descriptor_set_of};
use prost_types::field_descriptor_proto::Type;
use std::sync::Arc;

pub const TOPIC_COLLISIONS: &str = "/collisions";
pub const TOPIC_CONTACTS: &str = "/collisions/contacts";
pub const SCHEMA_NAME: &str = "armscope.CollisionState";

/// One control step's collision check.
#[derive(Clone, PartialEq, Message)]
pub struct CollisionState {
    /// Simulation time, s.
    #[prost(double, tag = "1")]
    pub time: f64,
    /// Pairs in contact (distance ≤ 0).
    #[prost(uint32, tag = "2")]
    pub in_contact: u32,
    /// The smallest distance among the checked pairs, m (negative: overlap); NaN when none is
    /// within 5 cm.
    #[prost(double, tag = "3")]
    pub min_distance: f64,
    /// The pairs in contact, or when none is, the nearest pair within 5 cm: "link — other",
    /// nearest first.
    #[prost(string, repeated, tag = "4")]
    pub pairs: Vec<String>,
    /// Their distances, m, in the same order.
    #[prost(double, repeated, tag = "5")]
    pub distances: Vec<f64>,
}

pub fn file_descriptor_set() -> Vec<u8> {
    file_descriptor_set_of(
        "collision_state",
        "CollisionState",
        &[
            Field("time", 1, false, Type::Double),
            Field("in_contact", 2, false, Type::Uint32),
            Field("min_distance", 3, false, Type::Double),
            Field("pairs", 4, true, Type::String),
            Field("distances", 5, true, Type::Double),
        ],
    )
}

encode_as_protobuf!(CollisionState);

const RED: Color = Color { r: 0.92, g: 0.12, b: 0.12, a: 0.75 };
const SCENE_GREY: Color = Color { r: 0.6, g: 0.6, b: 0.65, a: 0.6 };
const PAYLOAD: Color = Color { r: 0.8, g: 0.63, b: 0.24, a: 1.0 };

/// The recorder's collision state over a run.
pub struct McapCollisions {
    model: Arc<Model>,
    collisions: Arc<Collisions>,
    tracker: ContactTracker,
    pub state: CollisionState,
    /// Per link, its names of pairs (cached: the names are built once per pair).
    names: std::collections::HashMap<(usize, crate::collision::Against), String>,
}

impl McapCollisions {
    pub fn new(model: Arc<Model>, collisions: Arc<Collisions>) -> Self {
        let tracker = ContactTracker::new(&model, &collisions);
        Self { model, collisions, tracker, state: CollisionState::default(), names: Default::default() }
    }

    /// The scene's objects (in the world frame; the floor a thin square plate) and the payload (on the
    /// tool), drawn with the robot's geometry.
    pub fn world_entities(&self) -> Vec<SceneEntity> {
        let mut out = Vec::new();
        for shape in &self.collisions.world {
            let mut entity = SceneEntity { frame_id: "world".into(), id: format!("scene-{}", shape.name), frame_locked: true, ..Default::default() };
            let (geometry, pose) = drawn(shape);
            add_primitives(&mut entity, &geometry, &pose, SCENE_GREY, 0.0);
            out.push(entity);
        }
        if let Some((g, p)) = &self.collisions.payload {
            let tool = &self.model.frames[self.model.tool_frame].name;
            let mut entity = SceneEntity { frame_id: tool.clone(), id: "payload".into(), frame_locked: true, ..Default::default() };
            add_primitives(&mut entity, g, p, PAYLOAD, 0.0);
            out.push(entity);
        }
        out
    }

    /// Fill `state` from one sample; a contacts update when what is in contact changed.
    pub fn record(&mut self, s: &crate::sample::Sample, timestamp: Timestamp) -> Option<SceneUpdate> {
        let (model, collisions) = (&self.model, &self.collisions);
        let st = &mut self.state;
        st.time = s.t;
        st.in_contact = s.collisions.iter().filter(|p| p.distance <= 0.0).count() as u32;
        st.min_distance = s.collisions.first().map_or(f64::NAN, |p| p.distance);
        st.pairs.clear();
        st.distances.clear();
        for p in crate::collision::StateCollisions::in_contact_or_nearest(s.collisions) {
            st.pairs.push(self.names.entry((p.a, p.b)).or_insert_with(|| pair_name(model, collisions, (p.a, p.b))).clone());
            st.distances.push(p.distance);
        }
        if !self.tracker.update(s.collisions) {
            return None;
        }
        let mut entities = Vec::new();
        let mut touching: Vec<Body> = Vec::new();
        for &(a, b) in self.tracker.pairs() {
            touching.push(Body::Link(a));
            touching.push(match b {
                crate::collision::Against::Link(f) => Body::Link(f),
                crate::collision::Against::World(w) => Body::World(w),
            });
        }
        touching.dedup();
        let mut seen = Vec::new();
        for body in touching {
            if seen.contains(&body) {
                continue;
            }
            seen.push(body);
            let entity = match body {
                Body::Link(f) => {
                    let frame = &model.frames[f];
                    let mut e = SceneEntity { timestamp: Some(timestamp), frame_id: frame.name.clone(), id: format!("contact-{}", frame.name), frame_locked: true, ..Default::default() };
                    for c in &frame.collisions {
                        add_primitives(&mut e, &c.geometry, &c.origin, RED, 0.002);
                    }
                    if let (true, Some((g, p))) = (f == model.tool_frame, &collisions.payload) {
                        add_primitives(&mut e, g, p, RED, 0.002);
                    }
                    e
                }
                Body::World(w) => {
                    let shape = &collisions.world[w];
                    let mut e = SceneEntity { timestamp: Some(timestamp), frame_id: "world".into(), id: format!("contact-scene-{}", shape.name), frame_locked: true, ..Default::default() };
                    let (geometry, pose) = drawn(shape);
                    // the floor's thin plate grown less: a highlight, not a slab
                    let grow = if shape.drawn.is_some() { 0.002 } else { 0.001 };
                    add_primitives(&mut e, &geometry, &pose, RED, grow);
                    e
                }
            };
            entities.push(entity);
        }
        // every entity of this topic deleted before those in contact now are added
        let all = foxglove::messages::scene_entity_deletion::Type::All as i32;
        Some(SceneUpdate { deletions: vec![SceneEntityDeletion { timestamp: Some(timestamp), r#type: all, id: String::new() }], entities })
    }
}
