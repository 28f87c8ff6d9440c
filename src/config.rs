//! What one experiment is: the tutorial's flags as a plain, serializable struct. The CLI fills it;
//! batch manifests and tests can build it directly.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum IntegratorKind {
    Discrete,
    Continuous,
}

/// How a joint whose motor is a stepper or a serial-bus servo is driven.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum DriveMode {
    /// As the real arm runs them: steppers open loop (the command in microsteps, lost steps
    /// possible, as the SmallRobotArm), servos with a firmware model by their own position loop.
    #[default]
    #[value(alias = "stepper")]
    #[serde(alias = "stepper")]
    Native,
    /// The tutorial's PD controller on the motor's torque–speed limit.
    Pd,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", default)]
pub struct RunConfig {
    pub urdf: PathBuf,
    /// Simulated time, s.
    pub duration: f64,
    /// Control period, s.
    pub dt: f64,
    /// Plant step, s: `None` is the control period, 0 the continuous plant.
    pub time_step: Option<f64>,
    pub integrator: Option<IntegratorKind>,
    pub rtol: f64,
    pub atol: f64,
    /// Wave frequency ω, rad/s.
    pub freq: f64,
    /// Wave amplitude, degrees.
    pub amp_deg: f64,
    /// The wave's size was asked for (`--freq`, `--amp-deg`; `size` and `envelope` always): run as
    /// asked. Otherwise the default wave is scaled down where the URDF's motors cannot carry it.
    pub wave_as_asked: bool,
    /// One value for every joint, or one per joint.
    pub kp: Option<Vec<f64>>,
    pub kd: Option<Vec<f64>>,
    pub auto_tune: bool,
    /// Interval of the tutorial CSV rows, s.
    pub print_every: f64,
    /// Hold every joint at 0.
    #[serde(rename = "static")]
    pub hold: bool,
    pub no_ff: bool,
    pub no_gravity: bool,
    /// Step one joint (number from 1, or name) to `test_angle`.
    pub test_joint: Option<String>,
    pub test_angle: f64,
    /// Follow this joint schedule (CSV or .npy, `t,q1..qN`).
    pub trajectory: Option<PathBuf>,
    pub debug: bool,
    /// The link whose origin is the tool tip.
    pub tool: Option<String>,
    /// A payload at the tool tip, kg (a point mass).
    pub payload: f64,
    /// Tracking error statistics cover every step with t ≥ this, s.
    pub settle_time: f64,
    /// A joint speed above this (rad/s or m/s) is divergence.
    pub divergence_speed: f64,
    /// Refuse physically inconsistent link inertias instead of a notice.
    pub strict_inertia: bool,
    /// Every joint's Coulomb friction (URDF `<dynamics friction>`) times this: 1 as the URDF says,
    /// 0 none.
    pub friction_scale: f64,
    /// Initial joint positions: a comma list in joint order, or NAME=VALUE pairs (others: 0
    /// clamped into the joint's range).
    pub q0: Option<String>,
    /// A motor file: each named joint's motor and drive train (its torque falls with speed).
    pub motors: Option<PathBuf>,
    /// Stepper joints open loop (default) or under the PD controller.
    pub drive: DriveMode,
    /// Check every control step for self-collision (and with the floor, if any).
    pub collisions: bool,
    /// A floor at this height (world z, m), checked against every moving link; NaN: at the height of
    /// the link the first joint hangs from (the base).
    #[serde(skip)]
    pub floor: Option<f64>,
    /// An SRDF whose disabled pairs are not checked (default: the one beside the URDF).
    pub srdf: Option<PathBuf>,
    /// A scene file: fixed objects in the world, a floor, the payload's shape (`collision::scene`).
    pub scene: Option<PathBuf>,
    /// End the run at the first collision.
    pub stop_on_collision: bool,
}

pub use crate::builtin::DEFAULT_URDF;

impl Default for RunConfig {
    fn default() -> Self {
        Self {
            urdf: PathBuf::from(DEFAULT_URDF),
            duration: 30.0,
            dt: 0.001,
            time_step: None,
            integrator: None,
            rtol: 1e-8,
            atol: 1e-10,
            freq: 0.5,
            amp_deg: 30.0,
            wave_as_asked: false,
            kp: None,
            kd: None,
            auto_tune: false,
            print_every: 0.5,
            hold: false,
            no_ff: false,
            no_gravity: false,
            test_joint: None,
            test_angle: 0.3,
            trajectory: None,
            debug: false,
            tool: None,
            payload: 0.0,
            settle_time: 2.0,
            divergence_speed: 1e4,
            strict_inertia: false,
            friction_scale: 1.0,
            q0: None,
            motors: None,
            drive: DriveMode::Native,
            collisions: false,
            floor: None,
            srdf: None,
            scene: None,
            stop_on_collision: false,
        }
    }
}
