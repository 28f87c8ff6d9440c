//! The command line: a thin layer that turns flags into library calls.

use crate::config::{IntegratorKind, RunConfig};
use crate::error::Error;
use crate::experiment::Experiment;
use crate::recorder::{Console, Recorder, SummaryJson, Trace, TutorialCsv};
use crate::sim::simulate;
use crate::summary::RunStatus;
use clap::{Args, Parser, Subcommand};
use std::ffi::OsString;
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(name = "armscope", version, about = "Simulate a robot arm with real rigid-body dynamics and record every experiment")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Run one experiment: the tutorial's PD + gravity-compensation controller on the arm.
    Run(RunArgs),
}

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
    /// Wave frequency ω, rad/s.
    #[arg(long, allow_negative_numbers = true, default_value_t = defaults().freq)]
    pub freq: f64,
    /// Wave amplitude, degrees.
    #[arg(long, allow_negative_numbers = true, default_value_t = defaults().amp_deg)]
    pub amp_deg: f64,
    /// Proportional gains: one value for every joint or a comma list, one per joint.
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kp: Option<Vec<f64>>,
    /// Derivative gains: one value for every joint or a comma list, one per joint.
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kd: Option<Vec<f64>>,
    /// Tune gains from the mass matrix (default for models without tutorial gains).
    #[arg(long)]
    pub auto_tune: bool,
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
    /// Step size of --test-joint, rad.
    #[arg(long, allow_negative_numbers = true, default_value_t = defaults().test_angle)]
    pub test_angle: f64,
    /// Print command, error, τ_g and torque with every console line.
    #[arg(long)]
    pub debug: bool,
    /// The link whose origin is the tool tip (default: the deepest leaf link).
    #[arg(long, value_name = "LINK")]
    pub tool: Option<String>,
    /// Tracking error statistics cover every step with t ≥ this, s.
    #[arg(long, value_name = "SECONDS", default_value_t = defaults().settle_time)]
    pub settle_time: f64,
    /// A joint speed above this is reported as divergence, rad/s.
    #[arg(long, default_value_t = defaults().divergence_speed)]
    pub divergence_speed: f64,

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
            freq: self.freq,
            amp_deg: self.amp_deg,
            kp: self.kp.clone(),
            kd: self.kd.clone(),
            auto_tune: self.auto_tune,
            print_every: self.print_every,
            hold: self.hold,
            no_ff: self.no_ff,
            no_gravity: self.no_gravity,
            test_joint: self.test_joint.clone(),
            test_angle: self.test_angle,
            debug: self.debug,
            tool: self.tool.clone(),
            settle_time: self.settle_time,
            divergence_speed: self.divergence_speed,
        }
    }
}

/// Parse `args` and run; returns the process exit code. Errors are printed as one line.
pub fn main_with_args<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand) {
                let _ = e.print();
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand { 2 } else { 0 };
            }
            let rendered = e.render().to_string();
            let first = rendered.lines().find(|l| !l.trim().is_empty()).unwrap_or("invalid arguments");
            eprintln!("armscope: {}", first.trim_start_matches("error: "));
            return 2;
        }
    };
    match run_command(cli.command) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("armscope: error: {e}");
            e.exit_code()
        }
    }
}

fn run_command(command: Command) -> Result<i32, Error> {
    match command {
        Command::Run(args) => run(&args),
    }
}

fn create_parent(path: &std::path::Path) -> Result<(), Error> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, e)),
        _ => Ok(()),
    }
}

/// `armscope run`.
pub fn run(args: &RunArgs) -> Result<i32, Error> {
    let experiment = Experiment::prepare(args.config())?;
    for notice in &experiment.model.notices {
        eprintln!("armscope: notice: {notice}");
    }
    let mut recorders: Vec<Box<dyn Recorder>> = Vec::new();
    if !args.quiet {
        recorders.push(Box::new(Console::stdout()));
    }
    for (path, make) in [
        (&args.csv, (|p| Box::new(TutorialCsv::new(p)) as Box<dyn Recorder>) as fn(PathBuf) -> Box<dyn Recorder>),
        (&args.trace, |p| Box::new(Trace::new(p))),
        (&args.summary_json, |p| Box::new(SummaryJson::new(p))),
    ] {
        if let Some(path) = path {
            create_parent(path)?;
            recorders.push(make(path.clone()));
        }
    }
    let mut refs: Vec<&mut dyn Recorder> = recorders.iter_mut().map(|r| r.as_mut() as &mut dyn Recorder).collect();
    let summary = simulate(&experiment, &mut refs, None)?;
    match summary.status {
        RunStatus::Diverged { message, .. } => Err(Error::Diverged(message)),
        RunStatus::Interrupted { .. } => Ok(130),
        RunStatus::Completed => Ok(0),
    }
}
