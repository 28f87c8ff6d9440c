//! Collisions as flags, like saturation: does the arm hit itself, or the floor, on the way? The
//! motion is not changed (no contact forces); the checks say when, where and between which links,
//! and how close the near misses come.
//!
//! `geometry`: each link's `<collision>` shapes as parry3d shapes (boxes, cylinders, spheres,
//! capsules, and exact triangle meshes from STL and OBJ); `pairs`: which link pairs are checked (all
//! but adjacent ones and those an SRDF disables, `srdf`); `check`: one state's colliding pairs and
//! distances (a bounding-sphere broad phase, then parry's exact distance, and its contact depth for
//! the pairs that overlap).

pub mod aids;
pub mod check;
pub mod geometry;
pub mod hull;
mod mesh_distance;
pub mod pairs;
pub mod run_log;
pub mod scene;
pub mod srdf;

pub use check::{Against, CollisionData, PairDistance, StateCollisions, Wanted, WorldShape, check_state};
pub use scene::Scene;
pub use geometry::{CollisionModel, LinkShape};
pub use pairs::active_pairs;
pub use run_log::{CollisionSummary, PairRecord, RunLog};

use crate::model::Model;

/// A model's collision set-up for `armscope model` and the runs: its shapes, the active pairs, the
/// world's fixed shapes (floor, scene), and the notices made (links left out, SRDF names that are no
/// link, where the payload's shape went).
pub struct Collisions {
    pub shapes: CollisionModel,
    pub pairs: Vec<(usize, usize)>,
    /// Checked against every moving link: the floor first, if any, then the scene's objects.
    pub world: Vec<WorldShape>,
    /// The payload's shape and its pose in the tool frame (part of the tool link's shapes).
    pub payload: Option<(crate::model::Geometry, crate::spatial::Pose)>,
    pub notices: Vec<String>,
}

impl Collisions {
    /// The shapes of `model` (with the `scene`'s payload on the tool) and its active pairs, less
    /// those `srdf` disables (an SRDF file; when None, the one beside the URDF by name, if any, with
    /// a notice); the scene's floor and objects.
    pub fn new(model: &Model, srdf: Option<&std::path::Path>, scene: &Scene) -> Result<Self, crate::error::Error> {
        let mut shapes = CollisionModel::new(model);
        let mut notices = shapes.left_out.clone();
        let scene_name = || scene.source.as_ref().map_or("the scene".to_string(), |p| p.display().to_string());
        if let Some((geometry, origin)) = &scene.payload {
            shapes.add(model.tool_frame, geometry, origin).map_err(|e| crate::error::Error::flag("--scene", format!("{}: payload: {e}", scene_name())))?;
            notices.push(format!("{}: the payload's shape is checked as part of link '{}' (the tool)", scene_name(), model.frames[model.tool_frame].name));
        }
        let mut world: Vec<WorldShape> = scene.floor.map(WorldShape::floor).into_iter().collect();
        for o in &scene.objects {
            world.push(WorldShape::fixed(&o.name, &o.geometry, &o.pose).map_err(|e| crate::error::Error::flag("--scene", format!("{}: object '{}': {e}", scene_name(), o.name)))?);
        }
        let found = match srdf {
            Some(p) => Some(p.to_path_buf()),
            None => srdf::beside(&model.source).inspect(|p| notices.push(format!("collision pairs: the SRDF beside the URDF, {}, disables its pairs (--srdf chooses another)", p.display()))),
        };
        let disabled = match &found {
            Some(p) => srdf::disabled_pairs(p)?,
            None => Vec::new(),
        };
        let (pairs, unknown) = active_pairs(model, &shapes, &disabled);
        if !unknown.is_empty() {
            notices.push(format!("SRDF {}: names links the URDF does not have, ignored: {}", found.as_ref().map_or(String::new(), |p| p.display().to_string()), unknown.join(", ")));
        }
        Ok(Self { shapes, pairs, world, payload: scene.payload.clone(), notices })
    }

    /// The name of what a link is checked against: a link's, or the world shape's ("floor", a
    /// scene object's).
    pub fn name<'a>(&'a self, model: &'a Model, b: Against) -> &'a str {
        match b {
            Against::Link(f) => &model.frames[f].name,
            Against::World(w) => &self.world[w].name,
        }
    }

    /// What the checks cover, for a line of text: "15 link pairs, the floor at z = 0 m and 2 scene objects".
    pub fn describe(&self) -> String {
        let mut parts = vec![format!("{} link pairs", self.pairs.len())];
        if let Some(WorldShape { bound: check::WorldBound::Below(z), .. }) = self.world.first() {
            parts.push(format!("the floor at z = {z} m"));
        }
        let objects = self.world.iter().filter(|w| matches!(w.bound, check::WorldBound::Sphere { .. })).count();
        if objects > 0 {
            parts.push(format!("{objects} scene object{}", if objects == 1 { "" } else { "s" }));
        }
        match parts.len() {
            1 => parts.remove(0),
            _ => {
                let last = parts.pop().unwrap_or_default();
                format!("{} and {last}", parts.join(", "))
            }
        }
    }

    /// A checker of states of `model` one after another (its workspaces made once).
    pub fn checker<'a>(&'a self, model: &'a Model) -> Checker<'a> {
        Checker { model, collisions: self, body_poses: vec![crate::spatial::Pose::identity(); model.bodies.len()], shapes: CollisionData::new(&self.shapes), state: StateCollisions::default() }
    }

    /// The pairs closer than `threshold` (m) at joint positions `q`: (link, link or world shape,
    /// distance), nearest first.
    pub fn at(&self, model: &Model, q: &[f64], threshold: f64) -> Vec<(String, String, f64)> {
        let mut checker = self.checker(model);
        checker.check(q, threshold);
        checker.named()
    }
}

/// Checks joint positions one after another (a path, sampled states) for their collisions.
pub struct Checker<'a> {
    model: &'a Model,
    collisions: &'a Collisions,
    /// The bodies' world poses at the state checked (all a check needs of the kinematics).
    body_poses: Vec<crate::spatial::Pose>,
    shapes: CollisionData,
    state: StateCollisions,
}

impl Checker<'_> {
    /// The pairs closer than `threshold` (m) at joint positions `q`, nearest first.
    pub fn check(&mut self, q: &[f64], threshold: f64) -> &StateCollisions {
        let model = self.model;
        crate::dynamics::body_poses(model, q, &mut self.body_poses);
        check_state(model, &self.collisions.shapes, &self.collisions.pairs, &self.collisions.world, &mut self.shapes, &self.body_poses, threshold, &mut self.state);
        &self.state
    }

    /// The last check's pairs by name: (link, link or world shape, distance), nearest first.
    pub fn named(&self) -> Vec<(String, String, f64)> {
        self.state.close.iter().map(|p| (self.model.frames[p.a].name.clone(), self.collisions.name(self.model, p.b).to_string(), p.distance)).collect()
    }
}
