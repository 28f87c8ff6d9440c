//! A run's collisions, step by step into a summary: when the arm first touched something, each pair's
//! steps in contact and its closest approach.

use super::{Against, Collisions, StateCollisions};
use crate::model::Model;
use serde::{Deserialize, Serialize};

/// One pair over a run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PairRecord {
    pub link1: String,
    /// The other link, or the world's shape ("floor", a scene object's name).
    pub link2: String,
    /// Control steps the pair was in contact (distance ≤ 0).
    pub steps_in_contact: u64,
    /// Its smallest distance over the run, m (negative: the deepest overlap).
    pub closest: f64,
    /// When that was, s.
    pub closest_at: f64,
}

/// A run's collisions.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
pub struct CollisionSummary {
    /// Link pairs checked (the floor's not counted).
    pub pairs_checked: usize,
    pub floor: Option<f64>,
    /// The scene's objects checked against every moving link (`--scene`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scene_objects: Vec<String>,
    /// What was checked, in words ("15 link pairs and the floor at z = 0 m").
    #[serde(default)]
    pub checked: String,
    /// The first control step in contact: its time and the pair.
    pub first_contact: Option<(f64, String, String)>,
    /// Control steps with any pair in contact.
    pub steps_in_contact: u64,
    /// Every pair that came closer than 5 cm, in contact first, then nearest.
    pub pairs: Vec<PairRecord>,
}

/// Accumulates [`CollisionSummary`] step by step.
pub struct RunLog {
    summary: CollisionSummary,
    /// Per (a, b) key: the index into `summary.pairs`.
    index: std::collections::HashMap<(usize, Against), usize>,
}

impl RunLog {
    pub fn new(collisions: &Collisions) -> Self {
        let floor = collisions.world.iter().find_map(|w| match w.bound {
            super::check::WorldBound::Below(z) => Some(z),
            _ => None,
        });
        let scene_objects = collisions.world.iter().filter(|w| matches!(w.bound, super::check::WorldBound::Sphere { .. })).map(|w| w.name.clone()).collect();
        Self { summary: CollisionSummary { pairs_checked: collisions.pairs.len(), floor, scene_objects, checked: collisions.describe(), ..Default::default() }, index: Default::default() }
    }

    pub fn record(&mut self, model: &Model, collisions: &Collisions, t: f64, state: &StateCollisions) {
        let mut any = false;
        for p in &state.close {
            let n = self.summary.pairs.len();
            let i = *self.index.entry((p.a, p.b)).or_insert(n);
            if i == n {
                let link2 = collisions.name(model, p.b).to_string();
                self.summary.pairs.push(PairRecord { link1: model.frames[p.a].name.clone(), link2, steps_in_contact: 0, closest: f64::INFINITY, closest_at: t });
            }
            let r = &mut self.summary.pairs[i];
            if p.distance < r.closest {
                (r.closest, r.closest_at) = (p.distance, t);
            }
            if p.distance <= 0.0 {
                r.steps_in_contact += 1;
                if self.summary.first_contact.is_none() {
                    self.summary.first_contact = Some((t, r.link1.clone(), r.link2.clone()));
                }
                any = true;
            }
        }
        self.summary.steps_in_contact += any as u64;
    }

    pub fn finish(mut self) -> CollisionSummary {
        self.summary.pairs.sort_by(|a, b| (b.steps_in_contact > 0).cmp(&(a.steps_in_contact > 0)).then(a.closest.total_cmp(&b.closest)));
        self.summary
    }
}
