//! The `run` flags: a run's configuration as `armscope run` and a batch manifest's experiments
//! write it.

use super::{GainArgs, MotorArgs, WaveArgs};
use crate::config::{IntegratorKind, RunConfig};
use clap::Args;
use std::path::PathBuf;

fn defaults() -> RunConfig {
    RunConfig::default()
}

#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    /// The robot model.
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// Simulated time, s.
    #[arg(long, value_name = "SECONDS", default_value_t = defaults().duration)]
    pub duration: f64,
    /// Control period, s (the controller runs at 1/dt).
    #[arg(long, value_name = "SECONDS", default_value_t = defaults().dt)]
    pub dt: f64,
    /// Plant step, s: 0 selects the continuous plant; default: the control period.
    #[arg(long, value_name = "SECONDS")]
    pub time_step: Option<f64>,
    /// discrete (Drake's update, the default) or continuous (adaptive Runge–Kutta).
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorKind>,
    /// Relative tolerance of the continuous plant.
    #[arg(long, default_value_t = defaults().rtol)]
    pub rtol: f64,
    /// Absolute tolerance of the continuous plant.
    #[arg(long, default_value_t = defaults().atol)]
    pub atol: f64,
    #[command(flatten)]
    pub wave: WaveArgs,
    #[command(flatten)]
    pub gains: GainArgs,
    /// Interval of the --csv rows, s.
    #[arg(long, value_name = "SECONDS", default_value_t = defaults().print_every)]
    pub print_every: f64,
    /// Hold every joint at 0.
    #[arg(long = "static")]
    pub hold: bool,
    /// No gravity feed-forward in the controller.
    #[arg(long)]
    pub no_ff: bool,
    /// Switch gravity off.
    #[arg(long)]
    pub no_gravity: bool,
    /// Step one joint (number from 1, or name) to --test-angle, the others held at 0.
    #[arg(long, value_name = "N|NAME")]
    pub test_joint: Option<String>,
    /// Follow a joint schedule (CSV or .npy with columns t,q1..qN, e.g. from `armscope trajectory`).
    #[arg(long, value_name = "FILE")]
    pub trajectory: Option<PathBuf>,
    /// Step size of --test-joint, rad.
    #[arg(long, allow_negative_numbers = true, default_value_t = defaults().test_angle)]
    pub test_angle: f64,
    /// Print command, error, τ_g and torque with every console line.
    #[arg(long)]
    pub debug: bool,
    /// The link whose origin is the tool tip (default: the deepest leaf link).
    #[arg(long, value_name = "LINK")]
    pub tool: Option<String>,
    /// A payload at the tool tip, kg (a point mass at the tool link's origin).
    #[arg(long, value_name = "KG", default_value_t = defaults().payload)]
    pub payload: f64,
    /// Tracking error statistics cover every step with t ≥ this, s.
    #[arg(long, value_name = "SECONDS", default_value_t = defaults().settle_time)]
    pub settle_time: f64,
    /// A joint speed above this is reported as divergence, rad/s.
    #[arg(long, default_value_t = defaults().divergence_speed)]
    pub divergence_speed: f64,
    /// Refuse physically inconsistent link inertias (as Drake does) instead of a notice.
    #[arg(long)]
    pub strict_inertia: bool,
    /// Every joint's Coulomb friction (URDF `<dynamics friction>`, simulated with exact stiction)
    /// times this: 0 runs without friction, 2 with twice the URDF's.
    #[arg(long = "friction", value_name = "SCALE", default_value_t = defaults().friction_scale)]
    pub friction_scale: f64,
    /// Initial joint positions (rad or m): a comma list in joint order, or NAME=VALUE pairs
    /// (default: each joint's 0 clamped into its range). The default wave swings around them.
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    pub q0: Option<String>,
    #[command(flatten)]
    pub motors: MotorArgs,
    /// Check every control step for self-collision (the links' <collision> shapes; flags only, the
    /// motion is not changed): first contact, each pair's steps in contact, closest approaches.
    #[arg(long)]
    pub collisions: bool,
    /// Also check a floor, at this height (world z, m; without a value, at the height of the base:
    /// the link the first joint hangs from). Implies --collisions.
    #[arg(long, value_name = "Z", num_args = 0..=1, default_missing_value = "NaN", allow_negative_numbers = true)]
    pub floor: Option<f64>,
    /// An SRDF whose <disable_collisions> pairs are not checked (default: the one beside the URDF,
    /// by name). Implies --collisions.
    #[arg(long, value_name = "FILE")]
    pub srdf: Option<PathBuf>,
    /// A scene file (TOML): fixed boxes, cylinders, spheres, capsules and meshes in the world frame,
    /// a floor, the payload's shape at the tool. Implies --collisions.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// End the run at the first collision (whole files up to there; exit code 4). Implies --collisions.
    #[arg(long)]
    pub stop_on_collision: bool,

    /// Write the tutorial's CSV (t, q, tool xyz every --print-every).
    #[arg(long, value_name = "PATH")]
    pub csv: Option<PathBuf>,
    /// Write one CSV row per control step with state, command, torque, τ_g and tool position.
    #[arg(long, value_name = "PATH")]
    pub trace: Option<PathBuf>,
    /// Write the summary as JSON.
    #[arg(long, value_name = "PATH")]
    pub summary_json: Option<PathBuf>,
    /// No console output.
    #[arg(long, short)]
    pub quiet: bool,

    /// Name of the recordings (default: from the flags, e.g. "default", "no-ff").
    #[arg(long)]
    pub name: Option<String>,
    #[command(flatten)]
    pub files: super::shared::RecordingFiles,
    /// foxglove: Foxglove's protobuf schemas; ros2: ROS 2's CDR with ros2msg schemas, as rosbag2
    /// writes a bag (`ros2 bag play`, RViz, PlotJuggler, rosbags, Rerun's MCAP importer).
    #[arg(long, value_enum, default_value_t = crate::recorder::McapEncoding::Foxglove)]
    pub mcap_encoding: crate::recorder::McapEncoding,
    /// Smaller recordings for more CPU: LZ4 in the .rrd, zstd in the .mcap (the 30 s run's 34 and
    /// 21 MB become 18 and 13 MB; as readable). Without it the chunks are stored as they are, fastest.
    #[arg(long)]
    pub compress: bool,
    /// Start a Rerun viewer and stream the run to it (the files are written too).
    #[arg(long)]
    pub spawn: bool,
    /// Stream to a running Rerun viewer (default URL: rerun+http://127.0.0.1:9876/proxy).
    #[arg(long, value_name = "URL", num_args = 0..=1, default_missing_value = crate::recorder::DEFAULT_CONNECT_URL)]
    pub connect: Option<String>,
    /// Serve the run live to Foxglove (Open connection → Foxglove WebSocket), the MCAP's channels,
    /// at HOST:PORT (default 127.0.0.1:8765); with --realtime the arm moves at real speed.
    #[arg(long, value_name = "HOST:PORT", num_args = 0..=1, default_missing_value = crate::recorder::mcap::live::DEFAULT_ADDRESS)]
    pub foxglove: Option<String>,
    /// Pace the simulation to the wall clock, FACTOR × real time (default 1).
    #[arg(long, value_name = "FACTOR", num_args = 0..=1, default_missing_value = "1")]
    pub realtime: Option<f64>,
}

impl RunArgs {
    pub fn config(&self) -> RunConfig {
        RunConfig {
            urdf: self.urdf.clone(),
            duration: self.duration,
            dt: self.dt,
            time_step: self.time_step,
            integrator: self.integrator,
            rtol: self.rtol,
            atol: self.atol,
            freq: self.wave.freq(),
            amp_deg: self.wave.amp_deg(),
            wave_as_asked: self.wave.asked(),
            kp: self.gains.kp.clone(),
            kd: self.gains.kd.clone(),
            auto_tune: self.gains.auto_tune,
            print_every: self.print_every,
            hold: self.hold,
            no_ff: self.no_ff,
            no_gravity: self.no_gravity,
            test_joint: self.test_joint.clone(),
            test_angle: self.test_angle,
            trajectory: self.trajectory.clone(),
            debug: self.debug,
            tool: self.tool.clone(),
            payload: self.payload,
            settle_time: self.settle_time,
            divergence_speed: self.divergence_speed,
            strict_inertia: self.strict_inertia,
            friction_scale: self.friction_scale,
            q0: self.q0.clone(),
            motors: self.motors.motors.clone(),
            drive: self.motors.drive,
            collisions: self.collisions || self.stop_on_collision,
            stop_on_collision: self.stop_on_collision,
            floor: self.floor,
            srdf: self.srdf.clone(),
            scene: self.scene.clone(),
        }
    }
}
