//! Where a recorded arm put its tool: the height (world z) of a frame's origin at each frame of an
//! episode, from the positions as recorded — and whether a recording's tool went through a motor
//! file's floor, which is then not the table that recording's arm stood on.

use super::{Motion, Replayer};
use crate::dynamics::{Data, forward_kinematics, frame_pose};
use crate::model::Model;
use crate::plant::FloorContact;

/// The height of `frame`'s origin at each frame of `motion`, m: its positions as recorded where it
/// has them (smoothing rounds the corner where a tool lands), smoothed elsewhere.
pub fn recorded_heights(model: &Model, frame: usize, motion: &Motion) -> Vec<f64> {
    heights(model, frame, motion.len(), |j, k| motion.recorded_or_smoothed(j, k))
}

/// The height of `frame`'s origin at each of `frames` frames, m, the arm's coordinate `j` at
/// `position(j, k)` in frame `k`.
fn heights(model: &Model, frame: usize, frames: usize, position: impl Fn(usize, usize) -> f64) -> Vec<f64> {
    let mut data = Data::new(model);
    let mut q = vec![0.0; model.dof()];
    (0..frames)
        .map(|k| {
            for (j, qj) in q.iter_mut().enumerate() {
                *qj = position(j, k);
            }
            forward_kinematics(model, &mut data, &q);
            frame_pose(model, &data, frame).translation.z
        })
        .collect()
}

/// How far below a motor file's floor a recorded tool may go and the floor still be its table, m:
/// a real tool cannot pass its table, but a calibration's errors move the computed tool by
/// millimetres (the real SO-101's held-out episodes rest 0.7 mm below the table found on its
/// other two).
pub const THROUGH_FLOOR: f64 = 3e-3;

/// A recording whose tool went through a floor: the episode where it went deepest, how deep (m),
/// and in how many episodes it went through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Through {
    pub episode: i64,
    pub depth: f64,
    pub episodes: usize,
}

/// How far the recorded tool went below `floor` in one episode of `frames` frames, m (negative:
/// it stayed above), the arm at the episode's mapped `positions` (per coordinate; None: a joint
/// the map leaves out, at the replay's hold).
pub fn depth_below(replayer: &Replayer, floor: FloorContact, positions: &[Option<Vec<f64>>], frames: usize) -> f64 {
    let position_at = |j: usize, k: usize| positions[j].as_ref().map_or(replayer.hold[j], |p| p[k]);
    let lowest = heights(&replayer.base_model, floor.frame, frames, position_at).into_iter().fold(f64::INFINITY, f64::min);
    floor.height - lowest
}

impl Through {
    /// Of each episode's depth below a floor, those more than [`THROUGH_FLOOR`] (None: none).
    pub fn deepest(depths: &[(i64, f64)]) -> Option<Self> {
        let through: Vec<(i64, f64)> = depths.iter().copied().filter(|&(_, depth)| depth > THROUGH_FLOOR).collect();
        let deepest = through.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1));
        deepest.map(|(episode, depth)| Self { episode, depth, episodes: through.len() })
    }
}
