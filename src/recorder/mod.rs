//! Recorders: everything that turns samples into output. The simulation loop knows only this
//! trait; a new format is one new file.

mod console;
pub mod mcap;
mod pacer;
pub mod rrd;
pub mod shared;
mod summary_json;
mod threaded;
mod trace;
mod tutorial_csv;

pub use console::Console;
pub use mcap::{ControllerTelemetry, McapEncoding, McapOptions, McapRecorder, RobotDescription, Ros2McapRecorder, TOPIC_CONTROLLER, TOPIC_JOINT_STATES, decode_controller_telemetry, decode_robot_description};
pub use pacer::Pacer;
pub use rrd::{DEFAULT_CONNECT_URL, LiveViewer, RerunOptions, RerunRecorder};
pub use summary_json::SummaryJson;
pub use threaded::Threaded;
pub use trace::Trace;
pub use tutorial_csv::TutorialCsv;

use crate::error::Error;
use crate::experiment::Experiment;
use crate::sample::Sample;
use crate::summary::Summary;

/// What a recorder is told about the run before the first sample.
pub struct RunInfo<'a> {
    pub experiment: &'a Experiment,
    /// One line each, for humans and for the recordings' configuration.
    pub plant: String,
    pub trajectory: String,
    /// The commanded tool path, every 10 ms (computed once for all recorders).
    pub commanded_tool_path: Vec<nalgebra::Vector3<f64>>,
    /// Each joint's torque plot scale, worked out on first use: recorders read it through
    /// [`RunInfo::torque_axes`]; only the loop that makes a `RunInfo` sets it.
    pub(crate) torque_axes: shared::torque_axis::LazyAxes<'a>,
    /// Per joint, whether the samples carry a measured effort beside the model's torque (a replayed
    /// bag's `effort`); empty for a simulation.
    pub measured_effort: Vec<bool>,
    /// Per joint, whether the samples carry a real arm's position beside the simulated one (a
    /// forward replay's follower); empty otherwise.
    pub observed_position: Vec<bool>,
}

impl RunInfo<'_> {
    /// Each joint's torque plot scale, worked out when first asked for: a file's plots are laid out
    /// when the run ends (where one core is otherwise idle, waiting for Rerun's last chunks), and a
    /// run without recordings never needs them.
    pub fn torque_axes(&self) -> &[shared::torque_axis::TorqueAxis] {
        self.torque_axes.get()
    }
}

pub trait Recorder {
    fn start(&mut self, run: &RunInfo) -> Result<(), Error>;
    fn record(&mut self, sample: &Sample) -> Result<(), Error>;
    /// Called once after the last sample, also when the run was interrupted or diverged.
    fn finish(&mut self, run: &RunInfo, summary: &Summary) -> Result<(), Error>;
}

/// The rate of the arm's 3D poses in the recordings (link transforms in the `.rrd`, `/tf` in the
/// `.mcap`): a display rate, 100 Hz, while the plots keep every control step. At every step the
/// poses were a fifth of both files (per simulated second: `.rrd` 1.46 → 1.13 MB, `.mcap` 0.57 →
/// 0.44 MB) for motion no screen shows: 100 Hz is still more than one pose per displayed frame.
pub const POSE_RATE_HZ: f64 = 100.0;

/// Control steps between two recorded poses (1 when the control rate is below the pose rate).
pub fn steps_per_pose(dt: f64) -> usize {
    ((1.0 / POSE_RATE_HZ) / dt).round().max(1.0) as usize
}

/// Whether t_k = k·dt is the first sample at or after a multiple of `period`.
pub fn is_on_period(k: usize, dt: f64, period: f64) -> bool {
    if k == 0 {
        return true;
    }
    // tolerance: k·dt carries rounding error, a whole multiple must still count as one
    let index = |k: usize| (k as f64 * dt / period + 1e-9).floor();
    index(k) > index(k - 1)
}

pub(crate) fn fmt_list(values: &[f64], decimals: usize) -> String {
    let items: Vec<String> = values.iter().map(|v| format!("{v:+.decimals$}")).collect();
    format!("[{}]", items.join(" "))
}

#[cfg(test)]
mod tests {
    use super::is_on_period;

    #[test]
    fn period_boundaries_are_hit_exactly_once() {
        let hits: Vec<usize> = (0..=3000).filter(|&k| is_on_period(k, 0.001, 0.5)).collect();
        assert_eq!(hits, vec![0, 500, 1000, 1500, 2000, 2500, 3000]);
        let hits: Vec<usize> = (0..=1000).filter(|&k| is_on_period(k, 0.003, 1.0)).collect();
        assert_eq!(hits, vec![0, 334, 667, 1000]);
    }
}
