//! Flag groups more than one subcommand takes, defined once so that they read and default alike.

use crate::config::RunConfig;
use clap::Args;
use std::path::PathBuf;

/// The controller's gains.
#[derive(Args, Debug, Clone, Default)]
pub struct GainArgs {
    /// Proportional gains: one value for every joint or a comma list, one per joint.
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kp: Option<Vec<f64>>,
    /// Derivative gains: one value for every joint or a comma list, one per joint.
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kd: Option<Vec<f64>>,
    /// Tune gains from the mass matrix (default for models without tutorial gains).
    #[arg(long)]
    pub auto_tune: bool,
}

impl GainArgs {
    /// Into a run's configuration.
    pub fn apply(&self, config: &mut RunConfig) {
        config.kp = self.kp.clone();
        config.kd = self.kd.clone();
        config.auto_tune = self.auto_tune;
    }
}

/// The tutorial's wave: every joint swings A·sin(ω·t) about its start.
#[derive(Args, Debug, Clone)]
pub struct WaveArgs {
    /// Wave frequency ω, rad/s [default: 0.5]. Either flag runs the wave as asked; without them the
    /// default wave is scaled down where the URDF's motors cannot carry it (with a notice).
    #[arg(long, allow_negative_numbers = true)]
    pub freq: Option<f64>,
    /// Wave amplitude, degrees [default: 30].
    #[arg(long, allow_negative_numbers = true)]
    pub amp_deg: Option<f64>,
}

impl WaveArgs {
    pub fn freq(&self) -> f64 {
        self.freq.unwrap_or(RunConfig::default().freq)
    }

    pub fn amp_deg(&self) -> f64 {
        self.amp_deg.unwrap_or(RunConfig::default().amp_deg)
    }

    /// Whether the wave's size was asked for.
    pub fn asked(&self) -> bool {
        self.freq.is_some() || self.amp_deg.is_some()
    }
}

/// The motors and how stepper joints are driven.
#[derive(Args, Debug, Clone)]
pub struct MotorArgs {
    /// A motor file (TOML): each joint's motor from the catalogue (assets/motors/catalogue.toml, built
    /// in) and its gearbox (ratio, efficiency, rated torque); the torque a joint can get then falls
    /// with its speed, and the rotors' reflected inertia joins M. E.g. assets/motors/tutorial.toml.
    #[arg(long, value_name = "FILE")]
    pub motors: Option<PathBuf>,
    /// Joints whose motor is a stepper or a servo with a firmware model: `native` drives each as the
    /// real arm does (a stepper open loop, the command in microsteps, steps can be lost; a servo by
    /// its own firmware's position loop), `pd` runs the tutorial's PD controller on their torque
    /// limits. `stepper` is another name for `native`.
    #[arg(long, value_enum, default_value = "native")]
    pub drive: crate::config::DriveMode,
}

/// Where a command writes its recordings: `recordings/NAME.rrd` and `recordings/NAME.mcap` unless
/// told otherwise.
#[derive(Args, Debug, Clone, Default)]
pub struct RecordingFiles {
    /// Where to write the Rerun recording (default: recordings/NAME.rrd).
    #[arg(long, value_name = "PATH")]
    pub rrd: Option<PathBuf>,
    /// Where to write the MCAP for Foxglove (default: recordings/NAME.mcap).
    #[arg(long, value_name = "PATH")]
    pub mcap: Option<PathBuf>,
    /// No Rerun recording file.
    #[arg(long)]
    pub no_rrd: bool,
    /// No MCAP file.
    #[arg(long)]
    pub no_mcap: bool,
}

impl RecordingFiles {
    /// The folder the recordings go to by default.
    pub const FOLDER: &'static str = "recordings";

    /// The `.rrd` and `.mcap` to write for a recording named `name` (None: not wanted).
    pub fn paths(&self, name: &str) -> (Option<PathBuf>, Option<PathBuf>) {
        let recordings = PathBuf::from(Self::FOLDER);
        let rrd = (!self.no_rrd).then(|| self.rrd.clone().unwrap_or_else(|| recordings.join(format!("{name}.rrd"))));
        let mcap = (!self.no_mcap).then(|| self.mcap.clone().unwrap_or_else(|| recordings.join(format!("{name}.mcap"))));
        (rrd, mcap)
    }

    /// Where files that go with the recordings belong: beside `--rrd`, else the default folder.
    pub fn folder(&self) -> PathBuf {
        let beside = self.rrd.as_ref().and_then(|p| p.parent()).filter(|d| !d.as_os_str().is_empty());
        beside.map_or_else(|| PathBuf::from(Self::FOLDER), PathBuf::from)
    }
}

/// Which episodes of a recorded motion, and how its columns become the URDF's joints: shared by
/// `replay` and `size --from`.
#[derive(Args, Debug, Clone, Default)]
pub struct RecordedMotionArgs {
    /// Episodes to use (comma list; default: all).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub episode: Option<Vec<i64>>,
    /// The dataset's columns to use: `observation.state` (the follower's positions) or `action`
    /// (the commands).
    #[arg(long, default_value = "observation.state")]
    pub feature: String,
    /// How the recording's columns become the URDF's joints (TOML: `[joints.NAME] column, unit,
    /// sign, offset`; optionally a LeRobot `calibration` file; a file with only `calibration` gives
    /// it to the built-in map). Built in: bags and tables named by joint in SI units, the SO-101's
    /// LeRobot datasets.
    #[arg(long, value_name = "FILE")]
    pub joint_map: Option<PathBuf>,
    /// A bag's joint-state topic (default: /joint_states, or the only one).
    #[arg(long)]
    pub topic: Option<String>,
    /// A LeRobot dataset's body joints' unit for the built-in map: degrees or range (LeRobot's
    /// RANGE_M100_100); default: what the values tell (a value beyond ±100 is degrees, values at
    /// exactly ±100 a range), else armscope asks.
    #[arg(long, value_enum)]
    pub units: Option<crate::motion::BodyUnits>,
    /// A LeRobot calibration file (the follower's `<id>.json`: per motor range_min, range_max,
    /// drive_mode) for the built-in map: a range value becomes the motor's angle exactly.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
}

impl RecordedMotionArgs {
    /// How the values are to be read, as the flags say.
    pub fn reading(&self) -> crate::motion::Reading<'_> {
        crate::motion::Reading { units: self.units, calibration: self.calibration.as_deref() }
    }
}
