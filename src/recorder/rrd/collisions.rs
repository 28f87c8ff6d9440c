//! The collision checks in the `.rrd`: the scene's objects and the payload drawn in 3D, each link and
//! object turning red while in contact (only its colour is logged, at the changes), a `collisions`
//! series (pairs in contact, the smallest distance within 5 cm) and a `collisions/events` text log
//! naming the pairs as they touch and part.

use super::TIMELINE;
use super::geometry::{Recolour, log_colour, log_geometry, transform};
use crate::recorder::shared::floor_plate::drawn;
use crate::recorder::shared::contacts::{Body, ContactTracker, pair_name};
use crate::collision::Collisions;
use crate::model::{Geometry, Model};
use crate::spatial::Pose;
use rerun::{Color, RecordingStream, RecordingStreamResult};
use std::sync::Arc;

/// The colour of a link or object in contact (0xRRGGBBAA).
pub const CONTACT: Color = Color(rerun::datatypes::Rgba32(0xEB1E1EFF));
const SCENE_GREY: Color = Color(rerun::datatypes::Rgba32(0x9696A596));

/// The recorder's collision state over a run.
pub struct RrdCollisions {
    model: Arc<Model>,
    collisions: Arc<Collisions>,
    tracker: ContactTracker,
    /// Per frame and per world shape: the entities recoloured in contact.
    link_visuals: Vec<Vec<Recolour>>,
    world_visuals: Vec<Vec<Recolour>>,
    /// Per step of the block: pairs in contact, the smallest distance within 5 cm (NaN: none).
    pub count: Vec<f64>,
    pub min_distance: Vec<f64>,
    /// Colour changes and event lines of the block, with their times.
    colour_changes: Vec<(f64, Body, bool)>,
    events: Vec<(f64, String)>,
    started: bool,
}

impl RrdCollisions {
    pub fn new(model: Arc<Model>, collisions: Arc<Collisions>) -> Self {
        let tracker = ContactTracker::new(&model, &collisions);
        let (frames, world) = (model.frames.len(), collisions.world.len());
        Self { model, collisions, tracker, link_visuals: vec![Vec::new(); frames], world_visuals: vec![Vec::new(); world], count: Vec::new(), min_distance: Vec::new(), colour_changes: Vec::new(), events: Vec::new(), started: false }
    }

    /// Whether link (frame) `f` is checked: its visuals' colours are then temporal.
    pub fn checked(&self, f: usize) -> bool {
        self.collisions.shapes.has_shapes(f)
    }

    /// A visual of link `f` logged without a static colour.
    pub fn register(&mut self, f: usize, recolour: Recolour) {
        self.link_visuals[f].push(recolour);
    }

    /// The scene's objects (under `world/scene`) and the payload (under the tool's entity, `tool`)
    /// drawn, statically; their colours temporal.
    pub fn log_world(&mut self, rec: &RecordingStream, tool: &str) -> Result<(), String> {
        let placed = |pose: &Pose, scale: Option<[f64; 3]>| {
            let t = transform(pose);
            match scale {
                Some(s) => t.with_scale([s[0] as f32, s[1] as f32, s[2] as f32]),
                None => t,
            }
        };
        let scale_of = |g: &Geometry| if let Geometry::Mesh { scale, .. } = g { Some(*scale) } else { None };
        for (w, shape) in self.collisions.world.iter().enumerate() {
            let path = format!("world/scene/{}", shape.name);
            let (geometry, pose) = drawn(shape);
            rec.log_static(path.as_str(), &placed(&pose, scale_of(&geometry))).map_err(|e| e.to_string())?;
            let kind = log_geometry(rec, &path, &geometry, None)?;
            self.world_visuals[w].push(Recolour { path, kind, colour: SCENE_GREY });
        }
        if let Some((geometry, origin)) = self.collisions.payload.clone() {
            let path = format!("{tool}/payload");
            rec.log_static(path.as_str(), &placed(&origin, scale_of(&geometry))).map_err(|e| e.to_string())?;
            let kind = log_geometry(rec, &path, &geometry, None)?;
            self.link_visuals[self.model.tool_frame].push(Recolour { path, kind, colour: Color::from_rgb(200, 160, 60) });
        }
        Ok(())
    }

    pub fn record(&mut self, s: &crate::sample::Sample) {
        if !self.started {
            self.started = true;
            // every recoloured entity's own colour, from the first step
            for f in 0..self.link_visuals.len() {
                self.colour_changes.push((s.t, Body::Link(f), false));
            }
            for w in 0..self.world_visuals.len() {
                self.colour_changes.push((s.t, Body::World(w), false));
            }
        }
        self.count.push(s.collisions.iter().filter(|p| p.distance <= 0.0).count() as f64);
        self.min_distance.push(s.collisions.first().map_or(f64::NAN, |p| p.distance));
        if self.tracker.update(s.collisions) {
            self.colour_changes.extend(self.tracker.changed.iter().map(|&(b, now)| (s.t, b, now)));
            let (model, collisions) = (&self.model, &self.collisions);
            let deepest = |pair: (usize, crate::collision::Against)| s.collisions.iter().find(|p| (p.a, p.b) == pair).map_or(0.0, |p| -p.distance);
            for &pair in &self.tracker.began {
                self.events.push((s.t, format!("contact: {} ({:.1} mm deep)", pair_name(model, collisions, pair), 1e3 * deepest(pair))));
            }
            for &pair in &self.tracker.ended {
                self.events.push((s.t, format!("apart: {}", pair_name(model, collisions, pair))));
            }
        }
    }

    /// Send the block's colour changes and event lines (the series go with the other columns).
    pub fn flush(&mut self, rec: &RecordingStream) -> RecordingStreamResult<()> {
        for &(t, body, in_contact) in &self.colour_changes {
            rec.set_duration_secs(TIMELINE, t);
            let visuals = match body {
                Body::Link(f) => &self.link_visuals[f],
                Body::World(w) => &self.world_visuals[w],
            };
            for r in visuals {
                log_colour(rec, r, if in_contact { CONTACT } else { r.colour })?;
            }
        }
        for (t, line) in &self.events {
            rec.set_duration_secs(TIMELINE, *t);
            let level = if line.starts_with("contact") { rerun::TextLogLevel::WARN } else { rerun::TextLogLevel::INFO };
            rec.log("collisions/events", &rerun::TextLog::new(line.as_str()).with_level(level))?;
        }
        if !self.colour_changes.is_empty() || !self.events.is_empty() {
            rec.reset_time();
        }
        self.colour_changes.clear();
        self.events.clear();
        self.count.clear();
        self.min_distance.clear();
        Ok(())
    }
}
