//! A replayed episode written as `run` writes a run (`.rrd`, `.mcap`), through the same recorders:
//! the arm in 3D following the smoothed motion, the recorded positions as the command (the tool's
//! target), the torque each joint needed as the torque and what its motor gave as the limit, a
//! joint over its limit flagged saturated (the overload intervals the plots mark).

use super::{EpisodeReplay, Replayer};
use crate::config::RunConfig;
use crate::dynamics::{Data, body_poses, forward_kinematics, frame_pose, frame_pose_in, gravity_from_kinematics};
use crate::error::Error;
use crate::experiment::Experiment;
use crate::recorder::{McapEncoding, McapOptions, McapRecorder, Recorder, RerunOptions, RerunRecorder, Ros2McapRecorder, RunInfo};
use crate::sample::Sample;
use crate::summary::{RunStatus, SummaryBuilder};
use std::path::PathBuf;

/// Which files to write, and the name the viewer shows.
#[derive(Clone, Debug, Default)]
pub struct RecordingOutputs {
    pub name: String,
    pub rrd: Option<PathBuf>,
    pub mcap: Option<PathBuf>,
    pub mcap_encoding: McapEncoding,
}

impl RecordingOutputs {
    /// The recorders that write these files (their folders made).
    pub fn open(&self) -> Result<Vec<Box<dyn Recorder>>, Error> {
        let mut recorders: Vec<Box<dyn Recorder>> = Vec::new();
        if let Some(path) = &self.rrd {
            crate::runner::create_parent(path)?;
            recorders.push(Box::new(RerunRecorder::new(RerunOptions { file: Some(path.clone()), live: None, name: self.name.clone(), compress: false })));
        }
        if let Some(path) = &self.mcap {
            crate::runner::create_parent(path)?;
            let options = McapOptions { file: Some(path.clone()), live: None, compress: false };
            recorders.push(match self.mcap_encoding {
                McapEncoding::Foxglove => Box::new(McapRecorder::new(options)),
                McapEncoding::Ros2 => Box::new(Ros2McapRecorder::new(options)),
            });
        }
        Ok(recorders)
    }
}

/// Write one replayed episode's recordings.
pub fn record(replayer: &Replayer, replay: &EpisodeReplay, outputs: &RecordingOutputs) -> Result<(), Error> {
    let motion = &replay.motion;
    let samples = motion.len();
    let duration = motion.time[samples - 1];
    let dt = duration / (samples - 1) as f64;
    // the experiment the recorders describe: the replay's model at the episode's own rate
    let base = &replayer.experiment.config;
    let config = RunConfig { dt, duration, print_every: duration.max(dt), ..base.clone() };
    let experiment = Experiment::with_model(config, replayer.base_model.clone())?;
    let model = &*experiment.model;
    let n = model.dof();
    let tool_path: Vec<_> = {
        let mut data = Data::new(model);
        let mut q = vec![0.0; n];
        let every = ((0.01 / dt).round() as usize).max(1);
        (0..samples)
            .step_by(every)
            .map(|k| {
                for (j, value) in q.iter_mut().enumerate() {
                    *value = motion.recorded_or_smoothed(j, k);
                }
                forward_kinematics(model, &mut data, &q);
                frame_pose(model, &data, model.tool_frame).translation
            })
            .collect()
    };
    let info = RunInfo {
        measured_effort: motion.measured.iter().map(Option::is_some).collect(),
        observed_position: Vec::new(),
        experiment: &experiment,
        plant: "a recorded motion, replayed by inverse dynamics (no simulation)".into(),
        trajectory: format!("{} as recorded", motion.label),
        commanded_tool_path: tool_path,
        torque_axes: crate::recorder::shared::torque_axis::LazyAxes::of(&experiment),
    };
    let mut recorders = outputs.open()?;
    for r in recorders.iter_mut() {
        r.start(&info)?;
    }
    let names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let at_rest: Vec<f64> = replay.available.iter().map(|a| a.first().copied().unwrap_or(f64::INFINITY)).collect();
    let mut stats = SummaryBuilder::new(names, at_rest, dt, 0.0);
    let mut data = Data::new(model);
    let mut target_poses = vec![crate::spatial::Pose::identity(); model.bodies.len()];
    let (mut q, mut v, mut cmd, mut cmd_dot, mut u, mut tau_g) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut saturated, mut limit) = (vec![false; n], vec![0.0; n]);
    let (zeros, no_steps, flags) = (vec![0.0; n], vec![0i64; n], vec![false; n]);
    // a bag's measured effort beside the model's torque (NaN on a joint it has none for)
    let has_measured = motion.measured.iter().any(Option::is_some);
    let mut measured = if has_measured { vec![f64::NAN; n] } else { Vec::new() };
    let started = std::time::Instant::now();
    for k in 0..samples {
        for j in 0..n {
            q[j] = motion.q[j][k];
            v[j] = motion.qd[j][k];
            cmd[j] = motion.recorded_or_smoothed(j, k);
            cmd_dot[j] = motion.qd[j][k];
            u[j] = motion.needed[j][k];
            limit[j] = replay.available[j][k];
            saturated[j] = u[j].abs() > limit[j];
            if let (Some(slot), Some(series)) = (measured.get_mut(j), &motion.measured[j]) {
                *slot = series[k];
            }
        }
        forward_kinematics(model, &mut data, &q);
        gravity_from_kinematics(model, &mut data);
        tau_g.copy_from_slice(&data.gravity);
        let tool_position = frame_pose(model, &data, model.tool_frame).translation;
        body_poses(model, &cmd, &mut target_poses);
        let tool_target = frame_pose_in(model, &target_poses, model.tool_frame).translation;
        let sample = Sample {
            k,
            t: motion.time[k],
            is_final: k + 1 == samples,
            q: &q,
            v: &v,
            cmd: &cmd,
            cmd_dot: &cmd_dot,
            u: &u,
            tau_g: &tau_g,
            saturated: &saturated,
            torque_limit: &limit,
            load_angle: &zeros,
            lost_steps: &no_steps,
            chatter: &flags,
            at_limit: &flags,
            friction: &[],
            stuck: &[],
            winding_temperature: &[],
            duty: &[],
            current: &[],
            supply: &[],
            measured_effort: &measured,
            observed_position: &[],
            collisions: &[],
            tool_position,
            tool_target,
            body_pose: &data.body_pose,
        };
        stats.record(&sample);
        for r in recorders.iter_mut() {
            r.record(&sample)?;
        }
    }
    let summary = stats.finish(RunStatus::Completed, started.elapsed().as_secs_f64());
    for r in recorders.iter_mut() {
        r.finish(&info, &summary)?;
    }
    Ok(())
}
