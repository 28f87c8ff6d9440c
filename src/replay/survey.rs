//! What `replay --forward` reads of a recording before replaying it: each episode's recorded
//! positions, as the replay maps them, read once for the joints that do not follow their commands
//! in some episode and for how far the real tool went below a motor file's floor.

use super::inverse::mapped_positions;
use super::tool_height::{Through, depth_below};
use super::{Replayer, following};
use crate::error::Error;
use crate::motion::Source;
use crate::motion::commands::CommandSource;
use crate::plant::FloorContact;

/// A joint that does not follow its commands in some of a recording's episodes.
#[derive(Clone, Debug, PartialEq)]
pub struct OffJoint {
    /// The model's coordinate.
    pub joint: usize,
    /// The episodes where it does not follow its commands (they swept at least 5°).
    pub off_in: Vec<i64>,
    /// The episodes where its commands swept less and it stayed put: taken as off there too.
    pub taken_off_in: Vec<i64>,
}

/// A recording surveyed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Survey {
    pub off: Vec<OffJoint>,
    /// Where the real tool went through the floor asked about (None: nowhere, or no floor asked).
    pub through_floor: Option<Through>,
}

impl OffJoint {
    /// The one notice of the episodes where the joint is taken as off without their telling (None:
    /// none).
    pub fn notice(&self, model: &crate::model::Model) -> Option<String> {
        if self.taken_off_in.is_empty() {
            return None;
        }
        Some(format!(
            "{} does not follow its commands in {}; in {} its commands sweep less than {:.0}° and it stayed within {:.1}°: taken as not following there too (held where the real one was, left out of the ranking)",
            model.joints[self.joint].name,
            episode_list(&self.off_in),
            episode_list(&self.taken_off_in),
            following::SWEEP_EXPECTED.to_degrees(),
            (following::FOLLOWS_FRACTION * following::SWEEP_EXPECTED).to_degrees()
        ))
    }
}

/// "episode 3", "episodes 3, 5 and 7", "episodes 3, 5, 7, 9, 11, 13 and 20 more".
fn episode_list(episodes: &[i64]) -> String {
    const NAMED: usize = 6;
    let named: Vec<String> = episodes.iter().take(NAMED).map(|e| e.to_string()).collect();
    match episodes.len() {
        0 => "no episode".into(),
        1 => format!("episode {}", named[0]),
        n if n <= NAMED => format!("episodes {} and {}", named[..n - 1].join(", "), named[n - 1]),
        n => format!("episodes {} and {} more", named.join(", "), n - NAMED),
    }
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
        let commanded_at = mapped_positions(&replayer.model, &replayer.map.only_columns_of(&commanded), &commanded, &mut Vec::new())?;
        let observed_at = mapped_positions(&replayer.model, &replayer.map, &observed, &mut Vec::new())?;
        let depth = floor.map(|f| depth_below(replayer, f, &observed_at, observed.time.len()));
        Ok((index, following::sweeps(&commanded_at, &observed_at), depth))
    })?;
    let sweeps: Vec<_> = surveyed.iter().map(|(_, s, _)| s.clone()).collect();
    let off = following::off_somewhere(&sweeps)
        .into_iter()
        .map(|joint| {
            let (mut off_in, mut taken_off_in) = (Vec::new(), Vec::new());
            for (index, sweeps, _) in &surveyed {
                if let Some(Some((c, o))) = sweeps.get(joint) {
                    if !following::follows(*c, *o, false) {
                        off_in.push(*index);
                    } else if !following::follows(*c, *o, true) {
                        taken_off_in.push(*index);
                    }
                }
            }
            OffJoint { joint, off_in, taken_off_in }
        })
        .collect();
    let depths: Vec<(i64, f64)> = surveyed.iter().filter_map(|&(index, _, depth)| Some((index, depth?))).collect();
    Ok(Survey { off, through_floor: Through::deepest(&depths) })
}
