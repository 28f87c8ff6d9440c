//! Flag groups more than one subcommand takes, defined once so that they read and default alike.

use super::*;

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
    /// Wave frequency ω, rad/s.
    #[arg(long, allow_negative_numbers = true, default_value_t = RunConfig::default().freq)]
    pub freq: f64,
    /// Wave amplitude, degrees.
    #[arg(long, allow_negative_numbers = true, default_value_t = RunConfig::default().amp_deg)]
    pub amp_deg: f64,
}

/// The motors and how stepper joints are driven.
#[derive(Args, Debug, Clone)]
pub struct MotorArgs {
    /// A motor file (TOML): each joint's motor from the catalogue (assets/motors/catalogue.toml, built
    /// in) and its gearbox (ratio, efficiency, rated torque); the torque a joint can get then falls
    /// with its speed, and the rotors' reflected inertia joins M. E.g. assets/motors/tutorial.toml.
    #[arg(long, value_name = "FILE")]
    pub motors: Option<PathBuf>,
    /// Joints whose motor is a stepper: `stepper` drives them open loop (the command in microsteps;
    /// steps can be lost), `pd` runs the tutorial's PD controller on their pull-out torque.
    #[arg(long, value_enum, default_value = "stepper")]
    pub drive: crate::config::DriveMode,
}
