//! Collisions as flags, like saturation: does the arm hit itself, or the floor, on the way? The
//! motion is not changed (no contact forces); the checks say when, where and between which links,
//! and how close the near misses come.
//!
//! `geometry`: each link's `<collision>` shapes as parry3d shapes (boxes, cylinders, spheres,
//! capsules, and exact triangle meshes from STL and OBJ); `pairs`: which link pairs are checked (all
//! but adjacent ones and those an SRDF disables, `srdf`); `check`: one state's colliding pairs and
//! distances (a bounding-sphere broad phase, then parry's exact distance, and its contact depth for
//! the pairs that overlap).

pub mod check;
pub mod geometry;
pub mod pairs;
pub mod run_log;
pub mod srdf;

pub use check::{CollisionData, PairDistance, StateCollisions, check_state};
pub use geometry::{CollisionModel, LinkShape};
pub use pairs::active_pairs;
pub use run_log::{CollisionSummary, PairRecord, RunLog};

use crate::model::Model;

/// A model's collision set-up for `armscope model` and the runs: its shapes, the active pairs, and
/// the notices made (links left out, SRDF names that are no link).
pub struct Collisions {
    pub shapes: CollisionModel,
    pub pairs: Vec<(usize, usize)>,
    pub notices: Vec<String>,
}

impl Collisions {
    /// The shapes of `model` and its active pairs, less those `srdf` disables (an SRDF file; when
    /// None, the one beside the URDF by name, if any, with a notice).
    pub fn new(model: &Model, srdf: Option<&std::path::Path>) -> Result<Self, crate::error::Error> {
        let shapes = CollisionModel::new(model);
        let mut notices = shapes.left_out.clone();
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
        Ok(Self { shapes, pairs, notices })
    }

    /// A checker of states of `model` one after another, with a floor at `floor` if any (its
    /// workspaces made once).
    pub fn checker<'a>(&'a self, model: &'a Model, floor: Option<f64>) -> Checker<'a> {
        Checker { model, collisions: self, data: crate::dynamics::Data::new(model), shapes: CollisionData::new(&self.shapes, floor), state: StateCollisions::default() }
    }

    /// The pairs closer than `threshold` (m) at joint positions `q`, with a floor at `floor` if any:
    /// (link, link or "floor", distance), nearest first.
    pub fn at(&self, model: &Model, q: &[f64], floor: Option<f64>, threshold: f64) -> Vec<(String, String, f64)> {
        let mut checker = self.checker(model, floor);
        checker.check(q, threshold);
        checker.named()
    }
}

/// Checks joint positions one after another (a path, sampled states) for their collisions.
pub struct Checker<'a> {
    model: &'a Model,
    collisions: &'a Collisions,
    data: crate::dynamics::Data,
    shapes: CollisionData,
    state: StateCollisions,
}

impl Checker<'_> {
    /// The pairs closer than `threshold` (m) at joint positions `q`, nearest first.
    pub fn check(&mut self, q: &[f64], threshold: f64) -> &StateCollisions {
        let (model, data) = (self.model, &mut self.data);
        crate::dynamics::forward_kinematics(model, data, q);
        check_state(model, &self.collisions.shapes, &self.collisions.pairs, &mut self.shapes, |f| crate::dynamics::frame_pose(model, data, f), threshold, &mut self.state);
        &self.state
    }

    /// The last check's pairs by name: (link, link or "floor", distance), nearest first.
    pub fn named(&self) -> Vec<(String, String, f64)> {
        let frames = &self.model.frames;
        self.state.close.iter().map(|p| (frames[p.a].name.clone(), p.b.map_or("floor".to_string(), |b| frames[b].name.clone()), p.distance)).collect()
    }
}
