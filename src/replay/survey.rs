//! What `replay --forward` reads of a recording before replaying it: each episode's recorded
//! positions, as the replay maps them, read once for the joints that do not follow their commands
//! in some episode and for how far the real tool went below a motor file's floor.

use super::Replayer;
use super::following::{self, OffJoint};
use super::inverse::mapped_positions;
use super::tool_height::{Through, depth_below};
use crate::error::Error;
use crate::motion::Source;
use crate::motion::commands::CommandSource;
use crate::plant::FloorContact;

/// A recording surveyed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Survey {
    pub off: Vec<OffJoint>,
    /// Where the real tool went through the floor asked about (None: nowhere, or no floor asked).
    pub through_floor: Option<Through>,
}

impl Survey {
    /// The joints that do not follow their commands in at least one episode.
    pub fn off_joints(&self) -> Vec<usize> {
        self.off.iter().map(|o| o.joint).collect()
    }
}

/// Survey `episodes` of `source` (the follower recorded as `feature`, a bag's joint states beside
/// `commands`) on `jobs` threads; `floor`: the motor file's floor to hold the real tool against.
pub fn survey(replayer: &Replayer, source: &Source, episodes: &[i64], feature: &str, commands: &CommandSource, floor: Option<FloorContact>, jobs: usize) -> Result<Survey, Error> {
    let surveyed = super::over_episodes(episodes, jobs, |index| {
        let (commanded, observed) = source.read_forward(index, feature, commands)?;
        // the positions as the replay maps them (the smoothing and the torques a replay works out
        // are not needed here)
        let (commanded_at, _) = mapped_positions(&replayer.model, &replayer.map.only_columns_of(&commanded), &commanded)?;
        let (observed_at, _) = mapped_positions(&replayer.model, &replayer.map, &observed)?;
        let depth = floor.map(|f| depth_below(replayer, f, &observed_at, observed.time.len()));
        Ok((index, following::sweeps(&commanded_at, &observed_at), depth))
    })?;
    let (mut sweeps, mut depths) = (Vec::new(), Vec::new());
    for (index, episode_sweeps, depth) in surveyed {
        sweeps.push((index, episode_sweeps));
        depths.extend(depth.map(|d| (index, d)));
    }
    Ok(Survey { off: following::off_joints(&sweeps), through_floor: Through::deepest(&depths) })
}
