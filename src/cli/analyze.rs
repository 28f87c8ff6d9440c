//! `armscope analyze`: is the sampled control loop stable, and with which gains and dt.

use super::*;

#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// Control period, s.
    #[arg(long, default_value_t = 0.001)]
    pub dt: f64,
    #[command(flatten)]
    pub gains: GainArgs,
    /// A motor file: the loop with those motors' rotors (J_r·N² on M's diagonal), as `run --motors
    /// FILE --drive pd` runs it (an open-loop stepper has no loop to analyse).
    #[arg(long, value_name = "FILE")]
    pub motors: Option<PathBuf>,
    #[arg(long)]
    pub no_ff: bool,
    #[arg(long)]
    pub no_gravity: bool,
    /// The pose to linearize at, one angle per joint (default: all 0, the start pose).
    #[arg(long, value_delimiter = ',', num_args = 1, allow_negative_numbers = true)]
    pub pose: Option<Vec<f64>>,
    /// Also linearize at 12 poses along one period of the default wave (--freq/--amp-deg as `run`),
    /// and suggest kd that is stable at all of them (inertia changes with pose).
    #[arg(long)]
    pub along_command: bool,
    #[command(flatten)]
    pub wave: WaveArgs,
    /// The plant in the loop.
    #[arg(long, value_enum, default_value = "discrete")]
    pub plant: crate::control::sampled_loop::LoopPlant,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}


/// `armscope analyze`.
pub fn analyze(args: &AnalyzeArgs) -> Result<i32, Error> {
    let mut config = RunConfig {
        urdf: args.urdf.clone(),
        dt: args.dt,
        no_ff: args.no_ff,
        no_gravity: args.no_gravity,
        motors: args.motors.clone(),
        drive: crate::config::DriveMode::Pd,
        ..RunConfig::default()
    };
    args.gains.apply(&mut config);
    let experiment = Experiment::prepare(config)?;
    let n = experiment.model.dof();
    let pose = args.pose.clone().unwrap_or_else(|| vec![0.0; n]);
    if pose.len() != n || pose.iter().any(|x| !x.is_finite()) {
        return Err(Error::flag("--pose", format!("expected {n} finite angles, one per joint")));
    }
    // the given pose first, then (--along-command) 12 poses along one period of the wave
    let poses: Vec<Vec<f64>> = if args.along_command {
        let wave = crate::control::trajectory::Wave { amplitude_rad: args.wave.amp_deg().to_radians(), omega: args.wave.freq() };
        // a wave that stands still (ω = 0) gives the same pose at any time
        let period = crate::control::trajectory::Trajectory::period(&wave).unwrap_or(1.0);
        let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
        std::iter::once(pose.clone())
            .chain((0..12).map(|i| {
                crate::control::trajectory::Trajectory::sample(&wave, period * i as f64 / 12.0, &mut q, &mut qd);
                q.clone()
            }))
            .collect()
    } else {
        vec![pose]
    };
    let report = crate::diagnose::loop_report::LoopReport::new(&experiment, &args.urdf, args.motors.as_deref(), &poses, args.dt, !args.no_ff, args.plant);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report.to_json(&args.urdf)).unwrap_or_default());
    } else {
        print!("{}", report.text());
    }
    Ok(0)
}
