//! Where a recorded arm put its tool: the height (world z) of a frame's origin at each frame of an
//! episode, from the positions as recorded — and whether a recording's tool went through a motor
//! file's floor, which is then not the table that recording's arm stood on.

use super::inverse::mapped_positions;
use super::{Motion, Replayer};
use crate::dynamics::{Data, forward_kinematics, frame_pose};
use crate::error::Error;
use crate::model::Model;
use crate::motion::Source;
use crate::motion::commands::CommandSource;
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

/// Whether the follower a forward replay of `episodes` of `source` follows (recorded as `feature`;
/// a bag's joint states beside `commands`) took its tool (`floor`'s frame) more than
/// [`THROUGH_FLOOR`] below `floor` (None: never); the episodes read on `jobs` threads.
pub fn through_floor(replayer: &Replayer, source: &Source, episodes: &[i64], feature: &str, commands: &CommandSource, floor: FloorContact, jobs: usize) -> Result<Option<Through>, Error> {
    let depths = super::over_episodes(episodes, jobs, |index| {
        let (_, observed) = source.read_forward(index, feature, commands)?;
        // the positions as the replay maps them, a joint the map leaves out where the replay holds it
        // (the smoothing and the torques a replay works out are not needed for the tool's heights)
        let positions = mapped_positions(&replayer.model, &replayer.map, &observed, &mut Vec::new())?;
        let position_at = |j: usize, k: usize| positions[j].as_ref().map_or(replayer.hold[j], |p| p[k]);
        let lowest = heights(&replayer.base_model, floor.frame, observed.time.len(), position_at).into_iter().fold(f64::INFINITY, f64::min);
        Ok((index, floor.height - lowest))
    })?;
    let through: Vec<(i64, f64)> = depths.into_iter().filter(|&(_, depth)| depth > THROUGH_FLOOR).collect();
    let deepest = through.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1));
    Ok(deepest.map(|(episode, depth)| Through { episode, depth, episodes: through.len() }))
}
