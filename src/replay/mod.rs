//! Replay what a real arm did: a recorded episode (`crate::motion`) into the torque each joint
//! needed, held against what its motor gives.
//!
//! config (URDF, payload, tool, motors) → [`Replayer`] (the model built once) → per episode:
//! [`past_limits`] → [`smoothing`] → [`inverse`] → [`verdict`] → [`report`] (text, JSON) and
//! [`trace`] (CSV);
//! forward, the commands followed by the simulated arm and held against the real follower
//! ([`forward`]; the part of its gap made at rest: [`at_rest`]; where its tool went:
//! [`tool_height`]).

pub mod at_rest;
pub mod following;
pub mod forward;
pub mod inverse;
pub mod past_limits;
pub mod recording;
pub mod report;
pub mod schedule;
pub mod smoothing;
pub mod survey;
pub mod tool_height;
pub mod trace;
pub mod verdict;

pub use inverse::{Motion, inverse_replay};
pub use verdict::{Interval, JointVerdict, intervals_over};

use crate::actuator::MotorSet;
use crate::config::{DriveMode, RunConfig};
use crate::error::Error;
use crate::experiment::Experiment;
use crate::model::Model;
use crate::motion::{Episode, JointMap};
use std::path::PathBuf;
use std::sync::Arc;

/// What the replay is asked to model beyond the URDF.
#[derive(Clone, Debug, Default)]
pub struct ReplayOptions {
    /// A payload at the tool, kg.
    pub payload: f64,
    /// The link whose origin is the tool (where the payload sits).
    pub tool: Option<String>,
    /// A motor file: each joint's motor and gearbox (its torque at speed, its rotor's reflected
    /// inertia, its thermal data).
    pub motors: Option<PathBuf>,
}

/// The model (with payload and motors) and the joint map, built once for every episode.
pub struct Replayer {
    /// The model with the payload and the motors' parts and rotors.
    pub model: Arc<Model>,
    /// The URDF's model as loaded (recordings build their experiment from it).
    pub base_model: Model,
    pub motors: Option<Arc<MotorSet>>,
    pub map: JointMap,
    /// Where joints the map leaves out are held: 0 clamped into their range.
    pub hold: Vec<f64>,
    /// The experiment the model was built by (the recordings describe it).
    pub experiment: Experiment,
}

/// One episode replayed.
pub struct EpisodeReplay {
    pub motion: Motion,
    /// Per coordinate and sample, what the joint had in the direction it needed, N·m.
    pub available: Vec<Vec<f64>>,
    pub verdicts: Vec<JointVerdict>,
}

impl Replayer {
    pub fn new(model: Model, options: &ReplayOptions, map: JointMap) -> Result<Self, Error> {
        let config = RunConfig { urdf: model.source.clone(), payload: options.payload, tool: options.tool.clone(), motors: options.motors.clone(), drive: DriveMode::Pd, hold: true, ..RunConfig::default() };
        let base_model = model.clone();
        let experiment = Experiment::with_model(config, model)?;
        let model = experiment.model.clone();
        let hold = model.joints.iter().map(|j| {
            let (lowest, highest) = j.range();
            0.0_f64.clamp(lowest, highest)
        }).collect();
        Ok(Self { model, base_model, motors: experiment.motors.clone(), map, hold, experiment })
    }

    pub fn replay(&self, episode: &Episode) -> Result<EpisodeReplay, Error> {
        let motion = inverse_replay(&self.model, &self.map, episode, &self.hold)?;
        let motors = self.motors.as_deref();
        let mut available = verdict::available_torques(&self.model, motors, &motion);
        let servos = verdict::servo_loads(&self.model, motors, &motion);
        verdict::limit_after_trips(motors, &motion, &servos, &mut available);
        let verdicts = verdict::judge(&self.model, motors, &motion, &available, &servos);
        Ok(EpisodeReplay { motion, available, verdicts })
    }
}

/// Replay `episodes` of `source` on `jobs` threads, each read, replayed and reduced to its summary
/// as it goes (memory stays that of one episode per thread); `each` sees every replay whole (to
/// write its trace). The summaries come back the most loaded first.
pub fn replay_episodes(
    replayer: &Replayer,
    source: &crate::motion::Source,
    episodes: &[i64],
    feature: &str,
    jobs: usize,
    each: &(dyn Fn(i64, &EpisodeReplay) -> Result<(), Error> + Sync),
) -> Result<Vec<report::EpisodeSummary>, Error> {
    let mut summaries = over_episodes(episodes, jobs, |index| {
        let episode = source.read(index, feature)?;
        let replay = replayer.replay(&episode)?;
        each(index, &replay)?;
        Ok(report::EpisodeSummary::of(&replay, episode.index))
    })?;
    summaries.sort_by(|a, b| b.peak_load.total_cmp(&a.peak_load));
    Ok(summaries)
}

/// `each` over `episodes` on `jobs` threads: the results in episode order, or the first episode's
/// error.
fn over_episodes<T: Send>(episodes: &[i64], jobs: usize, each: impl Fn(i64) -> Result<T, Error> + Sync) -> Result<Vec<T>, Error> {
    use rayon::prelude::*;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs.max(1)).build().map_err(|e| Error::flag("--jobs", e.to_string()))?;
    let results: Vec<Result<T, Error>> = pool.install(|| episodes.par_iter().map(|&index| each(index)).collect());
    results.into_iter().collect()
}
