//! The command line: a thin layer that turns flags into library calls.

use crate::config::{IntegratorKind, RunConfig};
use crate::error::Error;
use crate::experiment::Experiment;
use crate::recorder::LiveViewer;
use crate::runner::{Outputs, run_experiment};
use crate::summary::RunStatus;
use clap::{Args, Parser, Subcommand};
use std::ffi::OsString;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

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
    /// Run many experiments from a TOML manifest, in parallel, into recordings/BATCH/.
    Batch(BatchArgs),
    /// Build one comparison recording (.rrd) from the .mcap files of finished runs.
    Compare(CompareArgs),
    /// Draw a shape with the tool: inverse kinematics into a joint schedule for `run --trajectory`.
    Trajectory(TrajectoryArgs),
    /// Is the sampled control loop stable? Spectral radius, the joints that drive it, stable dt and gains.
    Analyze(AnalyzeArgs),
    /// How fast can the arm go: sweep wave frequency × amplitude, map where each motor runs out of torque.
    Envelope(EnvelopeArgs),
    /// What armscope made of a URDF: joints, limits, motors, notices; with --states, the dynamics
    /// (M, τ_g, C·v, q̈, link poses) at given states as JSON, to compare with other libraries.
    Model(ModelArgs),
}

#[derive(Args, Debug)]
pub struct ModelArgs {
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// A JSON list of states by joint name, [{"q": {"J1": 0.1}, "v": {...}, "tau": {...}}, ...]:
    /// print the dynamics at each as JSON.
    #[arg(long, value_name = "FILE")]
    pub states: Option<PathBuf>,
    /// The model as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Refuse physically inconsistent link inertias (as Drake does) instead of a notice.
    #[arg(long)]
    pub strict_inertia: bool,
}

#[derive(Args, Debug)]
pub struct EnvelopeArgs {
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// Wave frequencies ω, rad/s (default: 10 values from 0.25 to 16, logarithmic).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub freqs: Option<Vec<f64>>,
    /// Wave amplitudes, degrees (default: 10 values from 5 to 60).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub amps: Option<Vec<f64>>,
    /// A payload at the tool, kg.
    #[arg(long, default_value_t = 0.0)]
    pub payload: f64,
    /// Gains (default: the model's, with kd made stable by `analyze` at the start pose).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kp: Option<Vec<f64>>,
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kd: Option<Vec<f64>>,
    #[arg(long, default_value_t = 0.001)]
    pub dt: f64,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "recordings/envelope")]
    pub out: PathBuf,
    /// Cells simulated at once (default: all cores).
    #[arg(long)]
    pub jobs: Option<usize>,
}

#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// Control period, s.
    #[arg(long, default_value_t = 0.001)]
    pub dt: f64,
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kp: Option<Vec<f64>>,
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kd: Option<Vec<f64>>,
    #[arg(long)]
    pub auto_tune: bool,
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
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub freq: f64,
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub amp_deg: f64,
    /// The plant in the loop.
    #[arg(long, value_enum, default_value = "discrete")]
    pub plant: crate::diagnose::analysis::LoopPlant,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct TrajectoryArgs {
    /// The shape, on a vertical plane in front of the arm.
    #[arg(value_enum)]
    pub shape: crate::control::ik::Shape,
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// Time to draw the shape, s.
    #[arg(long, default_value_t = 10.0)]
    pub duration: f64,
    /// Sample interval of the schedule, s.
    #[arg(long, default_value_t = 0.01)]
    pub step: f64,
    /// Half-width of the shape, m (default: a sixth of the arm's reach).
    #[arg(long)]
    pub size: Option<f64>,
    /// Centre of the shape "x,y,z" in m (default: 3/4 of the reach, at the tool's height).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub centre: Option<Vec<f64>>,
    /// Joints that move (numbers from 1 or names; default: the first three, the wrist locked at 0).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub ik_joints: Option<Vec<String>>,
    /// Output prefix: writes PREFIX.csv and PREFIX.npy (default: recordings/trajectory_SHAPE).
    #[arg(long, value_name = "PREFIX")]
    pub out: Option<PathBuf>,
}

#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct BatchArgs {
    #[command(subcommand)]
    pub action: Option<BatchAction>,
    /// The manifest.
    #[arg(value_name = "MANIFEST", default_value = crate::builtin::DEFAULT_MANIFEST)]
    pub manifest: PathBuf,
    /// Experiments run at once (default: the number of cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Run only shard I of N (I from 0), e.g. a Slurm array task: --shard $SLURM_ARRAY_TASK_ID/4.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Output folder (default: recordings/BATCH, BATCH the manifest's name).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Skip the comparison recording.
    #[arg(long)]
    pub no_compare: bool,
}

#[derive(Subcommand, Debug)]
pub enum BatchAction {
    /// Join the shard summaries in DIR… into one set of tables (and the comparison recording).
    Merge {
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Where to write the merged tables (default: the first DIR).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The runs' .mcap files (each run is labelled with its file name).
    #[arg(required = true, value_name = "RUN.mcap")]
    pub inputs: Vec<PathBuf>,
    /// The comparison recording to write.
    #[arg(long, value_name = "PATH", default_value = "recordings/comparison.rrd")]
    pub out: PathBuf,
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
    /// Tracking error statistics cover every step with t ≥ this, s.
    #[arg(long, value_name = "SECONDS", default_value_t = defaults().settle_time)]
    pub settle_time: f64,
    /// A joint speed above this is reported as divergence, rad/s.
    #[arg(long, default_value_t = defaults().divergence_speed)]
    pub divergence_speed: f64,
    /// Refuse physically inconsistent link inertias (as Drake does) instead of a notice.
    #[arg(long)]
    pub strict_inertia: bool,
    /// Initial joint positions (rad or m): a comma list in joint order, or NAME=VALUE pairs
    /// (default: each joint's 0 clamped into its range). The default wave swings around them.
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    pub q0: Option<String>,
    /// A motor file (TOML): each joint's motor from the catalogue (assets/motors/catalogue.toml, built
    /// in) and its gearbox (ratio, efficiency, rated torque); the torque a joint can get then falls
    /// with its speed. E.g. assets/motors/tutorial.toml.
    #[arg(long, value_name = "FILE")]
    pub motors: Option<PathBuf>,
    /// Joints whose motor is a stepper: `stepper` drives them open loop (the command in microsteps;
    /// steps can be lost), `pd` runs the tutorial's PD controller on their pull-out torque.
    #[arg(long, value_enum, default_value = "stepper")]
    pub drive: crate::config::DriveMode,

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
    /// Start a Rerun viewer and stream the run to it (the files are written too).
    #[arg(long)]
    pub spawn: bool,
    /// Stream to a running Rerun viewer (default URL: rerun+http://127.0.0.1:9876/proxy).
    #[arg(long, value_name = "URL", num_args = 0..=1, default_missing_value = crate::recorder::DEFAULT_CONNECT_URL)]
    pub connect: Option<String>,
    /// Serve the run live to Foxglove (Open connection → Foxglove WebSocket), the MCAP's channels,
    /// at HOST:PORT (default 127.0.0.1:8765); with --realtime the arm moves at real speed.
    #[arg(long, value_name = "HOST:PORT", num_args = 0..=1, default_missing_value = crate::recorder::foxglove_live::DEFAULT_ADDRESS)]
    pub foxglove: Option<String>,
    /// Pace the simulation to the wall clock, FACTOR × real time (default 1).
    #[arg(long, value_name = "FACTOR", num_args = 0..=1, default_missing_value = "1")]
    pub realtime: Option<f64>,
}

/// A file-name-safe name for a run, from the flags that differ from the tutorial's defaults.
pub fn default_run_name(config: &RunConfig) -> String {
    let d = RunConfig::default();
    let mut parts: Vec<String> = Vec::new();
    if config.urdf != d.urdf {
        parts.push(config.urdf.file_stem().map_or("model".into(), |s| s.to_string_lossy().to_string()));
    }
    if config.hold {
        parts.push("static".into());
    }
    if let Some(j) = &config.test_joint {
        parts.push(format!("test-joint-{j}"));
    }
    if config.no_ff {
        parts.push("no-ff".into());
    }
    if config.no_gravity {
        parts.push("no-gravity".into());
    }
    if config.freq != d.freq {
        parts.push(format!("freq{}", config.freq));
    }
    if config.amp_deg != d.amp_deg {
        parts.push(format!("amp{}", config.amp_deg));
    }
    if config.kp.is_some() || config.kd.is_some() || config.auto_tune {
        parts.push("gains".into());
    }
    if config.time_step == Some(0.0) || config.integrator == Some(IntegratorKind::Continuous) {
        parts.push("continuous".into());
    } else if let Some(h) = config.time_step {
        parts.push(format!("h{h}"));
    }
    if config.dt != d.dt {
        parts.push(format!("dt{}", config.dt));
    }
    if config.duration != d.duration {
        parts.push(format!("{}s", config.duration));
    }
    if parts.is_empty() {
        parts.push("default".into());
    }
    crate::runner::file_safe(&parts.join("_"))
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
            trajectory: self.trajectory.clone(),
            debug: self.debug,
            tool: self.tool.clone(),
            settle_time: self.settle_time,
            divergence_speed: self.divergence_speed,
            strict_inertia: self.strict_inertia,
            q0: self.q0.clone(),
            motors: self.motors.clone(),
            drive: self.drive,
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
        Command::Batch(args) => batch(&args),
        Command::Compare(args) => compare(&args),
        Command::Trajectory(args) => trajectory(&args),
        Command::Analyze(args) => analyze(&args),
        Command::Envelope(args) => envelope(&args),
        Command::Model(args) => model(&args),
    }
}

/// Set by SIGINT (Ctrl-C): the run stops after the current step and finishes its files.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Ctrl-C sets a flag the simulation loop checks every step (the files are then finished).
pub fn install_interrupt_handler() {
    static INSTALLED: std::sync::Once = std::sync::Once::new();
    INSTALLED.call_once(|| {
        // a second handler cannot be installed (e.g. by an embedding program): then Ctrl-C just kills
        let _ = ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst));
    });
}

/// `armscope run`.
pub fn run(args: &RunArgs) -> Result<i32, Error> {
    let config = args.config();
    let name = args.name.clone().unwrap_or_else(|| default_run_name(&config));
    let experiment = Experiment::prepare(config)?;
    for notice in &experiment.model.notices {
        eprintln!("armscope: notice: {notice}");
    }
    if let Some(f) = args.realtime {
        if !(f.is_finite() && f > 0.0) {
            return Err(Error::flag("--realtime", format!("must be a positive factor (got {f})")));
        }
    }
    let recordings = PathBuf::from("recordings");
    let rrd_path = (!args.no_rrd).then(|| args.rrd.clone().unwrap_or_else(|| recordings.join(format!("{name}.rrd"))));
    let mcap_path = (!args.no_mcap).then(|| args.mcap.clone().unwrap_or_else(|| recordings.join(format!("{name}.mcap"))));
    let live = if args.spawn {
        Some(LiveViewer::Spawn)
    } else {
        args.connect.clone().map(LiveViewer::Connect)
    };

    let outputs = Outputs {
        name: name.clone(),
        console: (!args.quiet).then(|| Box::new(std::io::stdout()) as Box<dyn std::io::Write + Send>),
        rrd: rrd_path.clone(),
        mcap: mcap_path.clone(),
        live,
        foxglove: args.foxglove.clone(),
        realtime: args.realtime,
        csv: args.csv.clone(),
        trace: args.trace.clone(),
        summary_json: args.summary_json.clone(),
        notice: Some(|n| eprintln!("armscope: notice: {n}")),
    };
    install_interrupt_handler();
    INTERRUPTED.store(false, Ordering::SeqCst);
    let summary = run_experiment(&experiment, outputs, Some(&INTERRUPTED))?;
    if !args.quiet {
        let mut files = Vec::new();
        if let Some(p) = &rrd_path {
            files.push(format!("  {}   open in Rerun: rerun {}", p.display(), p.display()));
        }
        if let Some(p) = &mcap_path {
            files.push(format!("  {}  open in Foxglove: Open local file… → {}", p.display(), p.display()));
        }
        if !files.is_empty() {
            println!("\nRecordings{}:\n{}", if matches!(summary.status, RunStatus::Completed) { "" } else { " (complete up to the last step simulated)" }, files.join("\n"));
        }
    }
    match summary.status {
        RunStatus::Diverged { message, .. } => Err(Error::Diverged(message)),
        RunStatus::Interrupted { .. } => Ok(130),
        RunStatus::Completed => Ok(0),
    }
}

/// `armscope model`.
pub fn model(args: &ModelArgs) -> Result<i32, Error> {
    let model = crate::model::load_urdf_with(&args.urdf, crate::model::LoadOptions { strict_inertia: args.strict_inertia })?;
    for notice in &model.notices {
        eprintln!("armscope: notice: {notice}");
    }
    if let Some(path) = &args.states {
        let text = std::fs::read_to_string(path).map_err(|e| Error::flag("--states", format!("{}: {e}", path.display())))?;
        let states: Vec<crate::inspect::State> = serde_json::from_str(&text).map_err(|e| Error::flag("--states", format!("{}: {e}", path.display())))?;
        println!("{}", crate::inspect::dynamics_at(&model, &states)?);
    } else if args.json {
        println!("{}", serde_json::to_string_pretty(&crate::inspect::describe(&model)).unwrap_or_default());
    } else {
        print!("{}", crate::inspect::table(&model));
    }
    Ok(0)
}

/// `armscope batch`.
pub fn batch(args: &BatchArgs) -> Result<i32, Error> {
    use crate::batch::{BatchOptions, merge_summaries, parse_shard, write_tables};
    let summary = match &args.action {
        Some(BatchAction::Merge { dirs, out }) => {
            let merged = merge_summaries(dirs)?;
            let dir = out.clone().unwrap_or_else(|| dirs[0].clone());
            std::fs::create_dir_all(&dir).map_err(|e| Error::output(&dir, e))?;
            let mut files = write_tables(&dir, &merged)?;
            files.extend(crate::batch::write_comparison(&merged, dirs, &dir)?);
            report_batch(&merged, &files);
            merged
        }
        None => {
            let options = BatchOptions {
                manifest: args.manifest.clone(),
                jobs: args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                shard: args.shard.as_deref().map(parse_shard).transpose()?,
                out: args.out.clone(),
                compare: !args.no_compare,
                progress: true,
            };
            if options.jobs == 0 {
                return Err(Error::flag("--jobs", "must be at least 1"));
            }
            install_interrupt_handler();
            INTERRUPTED.store(false, Ordering::SeqCst);
            let (summary, files) = crate::batch::run_batch(&options, Some(&INTERRUPTED))?;
            report_batch(&summary, &files);
            summary
        }
    };
    let failed = summary.experiments.iter().filter(|e| e.status != "completed").count();
    Ok(if failed == 0 { 0 } else { 1 })
}

fn report_batch(summary: &crate::batch::BatchSummary, files: &[PathBuf]) {
    print!("{}", crate::batch::BatchSummary::markdown(summary));
    for e in summary.experiments.iter().filter(|e| e.status != "completed") {
        eprintln!("armscope: experiment '{}' {}: {}", e.name, e.status, e.error.clone().unwrap_or_default());
    }
    println!("\nWritten: {}", files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", "));
}

/// `armscope compare`.
pub fn compare(args: &CompareArgs) -> Result<i32, Error> {
    let runs: Vec<crate::batch::ComparedRun> = args
        .inputs
        .iter()
        .map(|p| crate::batch::ComparedRun { label: p.file_stem().map_or("run".into(), |s| s.to_string_lossy().to_string()), mcap: p.clone() })
        .collect();
    crate::runner::create_parent(&args.out)?;
    crate::batch::build_comparison(&runs, &args.out, "comparison")?;
    println!("Comparison of {} runs: {}   open in Rerun: rerun {}", runs.len(), args.out.display(), args.out.display());
    Ok(0)
}

/// `armscope trajectory`.
pub fn trajectory(args: &TrajectoryArgs) -> Result<i32, Error> {
    use crate::control::ik::{default_drawing, solve_drawing};
    let model = crate::model::load_urdf(&args.urdf)?;
    if !(args.duration > 0.0 && args.step > 0.0 && args.step <= args.duration) {
        return Err(Error::flag("--step", "must be positive and at most --duration"));
    }
    let mut drawing = default_drawing(&model, args.shape);
    if let Some(size) = args.size {
        if !(size > 0.0 && size.is_finite()) {
            return Err(Error::flag("--size", format!("must be a positive length (got {size})")));
        }
        drawing.size = size;
    }
    if let Some(c) = &args.centre {
        if c.len() != 3 || c.iter().any(|x| !x.is_finite()) {
            return Err(Error::flag("--centre", "expected x,y,z in metres"));
        }
        drawing.centre = nalgebra::Vector3::new(c[0], c[1], c[2]);
    }
    let joints: Vec<usize> = match &args.ik_joints {
        Some(list) => list.iter().map(|j| crate::experiment::resolve_joint(j, &model).map_err(|_| Error::flag("--ik-joints", format!("no joint '{j}' in {}", model.source.display())))).collect::<Result<_, _>>()?,
        None => (0..model.dof().min(3)).collect(),
    };
    let (times, positions, targets) = solve_drawing(&model, &drawing, joints, args.duration, args.step).map_err(|m| Error::flag("trajectory", m))?;
    let shape = format!("{:?}", args.shape).to_lowercase();
    let prefix = args.out.clone().unwrap_or_else(|| PathBuf::from("recordings").join(format!("trajectory_{shape}")));
    let (csv, npy) = (prefix.with_extension("csv"), prefix.with_extension("npy"));
    crate::runner::create_parent(&csv)?;
    let n = model.dof();
    let mut text = std::iter::once("t".to_string()).chain((1..=n).map(|i| format!("q{i}"))).collect::<Vec<_>>().join(",") + "\n";
    let mut flat = Vec::with_capacity(times.len() * (n + 1));
    for (t, q) in times.iter().zip(&positions) {
        text += &std::iter::once(format!("{t:?}")).chain(q.iter().map(|x| format!("{x:?}"))).collect::<Vec<_>>().join(",");
        text += "\n";
        flat.push(*t);
        flat.extend_from_slice(q);
    }
    std::fs::write(&csv, text).map_err(|e| Error::output(&csv, e))?;
    std::fs::write(&npy, crate::npy::write_f64(times.len(), n + 1, &flat)).map_err(|e| Error::output(&npy, e))?;
    // check: every point by forward kinematics
    let mut ik = crate::control::ik::PositionIk::new(&model, vec![]);
    let worst = positions.iter().zip(&targets).map(|(q, p)| (ik.tool_position(q) - p).norm()).fold(0.0, f64::max);
    let c = drawing.centre;
    println!(
        "{shape}: {} points over {} s on the plane x = {:.3} m, centre ({:.3}, {:.3}, {:.3}) m, size {:.3} m; worst IK error {:.2e} m",
        times.len(), args.duration, c.x, c.x, c.y, c.z, drawing.size, worst
    );
    println!("wrote {} and {}\nfollow it: armscope run --urdf {} --trajectory {} --duration {}", csv.display(), npy.display(), args.urdf.display(), csv.display(), args.duration);
    Ok(0)
}

/// `armscope analyze`.
pub fn analyze(args: &AnalyzeArgs) -> Result<i32, Error> {
    use crate::diagnose::analysis::{Linearization, LoopPlant, largest_stable_period, spectral_radius, stabilizing_kd_over, worst_radius};
    let config = RunConfig {
        urdf: args.urdf.clone(),
        dt: args.dt,
        kp: args.kp.clone(),
        kd: args.kd.clone(),
        auto_tune: args.auto_tune,
        no_ff: args.no_ff,
        no_gravity: args.no_gravity,
        ..RunConfig::default()
    };
    let experiment = Experiment::prepare(config)?;
    let model = &*experiment.model;
    let n = model.dof();
    let pose = args.pose.clone().unwrap_or_else(|| vec![0.0; n]);
    if pose.len() != n || pose.iter().any(|x| !x.is_finite()) {
        return Err(Error::flag("--pose", format!("expected {n} finite angles, one per joint")));
    }
    let (kp, kd) = experiment.controller().effective_gains();
    let ff = !args.no_ff;
    let h = args.dt;
    // the given pose first, then (--along-command) poses along the wave
    let poses: Vec<Vec<f64>> = if args.along_command {
        let wave = crate::control::trajectory::Wave { amplitude_rad: args.amp_deg.to_radians(), omega: args.freq };
        let period = 2.0 * std::f64::consts::PI / args.freq.abs().max(1e-6);
        let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
        std::iter::once(pose.clone())
            .chain((0..12).map(|i| {
                crate::control::trajectory::Trajectory::sample(&wave, period * i as f64 / 12.0, &mut q, &mut qd);
                q.clone()
            }))
            .collect()
    } else {
        vec![pose.clone()]
    };
    let lins: Vec<Linearization> = poses.iter().map(|p| Linearization::at(model, p)).collect();
    let lin = &lins[0];
    let (rho, participation) = spectral_radius(&lin.closed_loop(&kp, &kd, h, ff, args.plant));
    let stable = rho < 1.0;
    let largest_dt = largest_stable_period(lin, &kp, &kd, h, ff, args.plant);
    let worst = worst_radius(&lins, &kp, &kd, h, ff, args.plant);
    let (stable_kd, stable_rho) = stabilizing_kd_over(&lins, &kp, &kd, h, ff, args.plant);
    let names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let mut drivers: Vec<(String, f64)> = names.iter().cloned().zip(participation.iter().copied()).collect();
    drivers.sort_by(|a, b| b.1.total_cmp(&a.1));
    let kd_list = stable_kd.iter().map(|k| format!("{:.4}", k)).collect::<Vec<_>>().join(",");
    let plant_name = match args.plant {
        LoopPlant::Discrete => "discrete",
        LoopPlant::Continuous => "continuous",
    };
    let run_hint = format!(
        "armscope run --urdf {}{} --kp {} --kd {kd_list}{}",
        args.urdf.display(),
        if args.plant == LoopPlant::Continuous { " --time-step 0" } else { "" },
        kp.iter().map(|k| format!("{k}")).collect::<Vec<_>>().join(","),
        if args.dt != 0.001 { format!(" --dt {}", args.dt) } else { String::new() }
    );
    if args.json {
        let doc = serde_json::json!({
            "model": model.name, "urdf": args.urdf, "pose": pose, "dt": h, "plant": args.plant, "feed_forward": ff,
            "kp": kp, "kd": kd, "gains": experiment.gains.source,
            "spectral_radius": rho, "stable": stable,
            "poses": poses.len(), "worst_spectral_radius_over_poses": worst,
            "participation": names.iter().zip(&participation).map(|(n, p)| (n.clone(), *p)).collect::<std::collections::BTreeMap<_, _>>(),
            "largest_stable_dt": largest_dt,
            "stable_kd": if stable_rho < 1.0 { Some(&stable_kd) } else { None },
            "stable_kd_spectral_radius": stable_rho,
            "run_with_stable_kd": (stable_rho < 1.0).then_some(&run_hint),
        });
        println!("{}", serde_json::to_string_pretty(&doc).unwrap_or_default());
        return Ok(0);
    }
    println!("sampled closed loop of {} at pose {:?}, dt = {} ms, {plant_name} plant, gains {}:", model.name, pose, h * 1e3, experiment.gains.source);
    println!("  kp = {kp:?}\n  kd = {kd:?}");
    if stable {
        println!("  spectral radius {rho:.3}: STABLE (a small disturbance decays by {rho:.3}× per control step)");
    } else {
        println!("  spectral radius {rho:.3}: UNSTABLE (a small disturbance grows {rho:.2}× per control step, until the torque limits clip it into chatter)");
        println!("  driven by: {}", drivers.iter().filter(|d| d.1 > 0.02).map(|(n, p)| format!("{n} {:.0}%", 100.0 * p)).collect::<Vec<_>>().join(", "));
    }
    if args.along_command {
        println!("  worst spectral radius over {} poses along the wave: {worst:.3}", poses.len());
    }
    match largest_dt {
        Some(d) if d >= h => println!("  these gains are stable at this dt"),
        Some(d) => println!("  largest stable dt for these gains: {:.4} ms (run with --dt {:.6})", d * 1e3, d),
        None => println!("  these gains are unstable even at 1 µs"),
    }
    if stable_rho < 1.0 {
        println!("  stable derivative gains at dt = {} ms (kp unchanged): kd = [{kd_list}], spectral radius {stable_rho:.3}", h * 1e3);
        println!("  run with them: {run_hint}");
    } else {
        println!("  no kd scaling makes this loop stable at dt = {} ms (best spectral radius {stable_rho:.3}): lower kp or dt", h * 1e3);
    }
    Ok(0)
}

/// `armscope envelope`.
pub fn envelope(args: &EnvelopeArgs) -> Result<i32, Error> {
    use crate::diagnose::analysis::{Linearization, LoopPlant, spectral_radius, stabilizing_kd};
    use crate::diagnose::envelope::{sweep, with_payload};
    let freqs = args.freqs.clone().unwrap_or_else(|| (0..10).map(|i| 0.25 * 64f64.powf(i as f64 / 9.0)).map(|f| (f * 100.0).round() / 100.0).collect());
    let amps = args.amps.clone().unwrap_or_else(|| (0..10).map(|i| 5.0 + 55.0 * i as f64 / 9.0).map(|a| a.round()).collect());
    if freqs.iter().chain(&amps).any(|x| !(x.is_finite() && *x > 0.0)) {
        return Err(Error::flag("--freqs/--amps", "values must be positive"));
    }
    if !(args.payload >= 0.0 && args.payload.is_finite()) {
        return Err(Error::flag("--payload", "must be a mass in kg, not negative"));
    }
    let model = with_payload(crate::model::load_urdf(&args.urdf)?, args.payload);
    let mut config = RunConfig { urdf: args.urdf.clone(), dt: args.dt, kp: args.kp.clone(), kd: args.kd.clone(), ..RunConfig::default() };
    let probe = Experiment::with_model(config.clone(), model.clone())?;
    let (kp, kd) = probe.controller().effective_gains();
    let lin = Linearization::at(&model, &vec![0.0; model.dof()]);
    let (rho, _) = spectral_radius(&lin.closed_loop(&kp, &kd, args.dt, true, LoopPlant::Discrete));
    if args.kd.is_none() && rho >= 1.0 {
        let (kd, stable) = stabilizing_kd(&lin, &kp, &kd, args.dt, true, LoopPlant::Discrete);
        println!("gains {} are unstable at dt = {} ms (spectral radius {rho:.2}); using kd = {kd:.4?} (spectral radius {stable:.3})", probe.gains.source, args.dt * 1e3);
        config.kd = Some(kd);
    } else if rho >= 1.0 {
        println!("warning: the given gains are unstable at dt = {} ms (spectral radius {rho:.2}): saturation will include chatter", args.dt * 1e3);
    }
    let jobs = args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let started = std::time::Instant::now();
    let env = sweep(&config, &model, &freqs, &amps, args.payload, jobs)?;
    std::fs::create_dir_all(&args.out).map_err(|e| Error::output(&args.out, e))?;
    let x_ticks: Vec<String> = freqs.iter().map(|f| format!("{f}")).collect();
    let y_ticks: Vec<String> = amps.iter().map(|a| format!("{a}")).collect();
    let mut files = Vec::new();
    let rrd_path = args.out.join("envelope.rrd");
    let rec = rerun::RecordingStreamBuilder::new("armscope-envelope").save(&rrd_path).map_err(|e| Error::output(&rrd_path, e))?;
    for (j, name) in env.joints.iter().enumerate() {
        if env.effort[j] == 0.0 {
            continue;
        }
        let values: Vec<Vec<f64>> = (0..amps.len()).map(|a| (0..freqs.len()).map(|f| env.cell(a, f).required[j] / env.effort[j]).collect()).collect();
        let title = format!("{name} NEEDED TORQUE / LIMIT ({} NM){}", env.effort[j], if args.payload > 0.0 { format!(", PAYLOAD {} KG", args.payload) } else { String::new() });
        let canvas = crate::diagnose::heatmap::heatmap(&title, "WAVE FREQUENCY (RAD/S)", &x_ticks, "AMPLITUDE (DEG)", &y_ticks, &values);
        let png = args.out.join(format!("envelope_{name}.png"));
        canvas.save_png(&png).map_err(|e| Error::output(&png, e))?;
        files.push(png);
        rec.log_static(format!("envelope/{name}"), &rerun::Image::from_rgb24(canvas.rgb.clone(), [canvas.width as u32, canvas.height as u32]))
            .map_err(|e| Error::output(&rrd_path, e))?;
    }
    let table = env.table((0.5, 30.0));
    let mut md = format!(
        "# speed envelope of {}\n\nNeeded torque = peak |τ| of the inverse dynamics of the commanded wave (what a perfect controller must supply), against the motor's limit. Simulated with kp = {:?}, kd = {:.4?}.\n\n{table}\n",
        model.name, env.kp, env.kd
    );
    md += "\nFastest frequency (rad/s) within the limit, per amplitude:\n\n| amplitude (°) |";
    for n in &env.joints {
        md += &format!(" {n} |");
    }
    md += "\n|---|";
    md += &"---|".repeat(env.joints.len());
    md += "\n";
    for (a, amp) in amps.iter().enumerate() {
        md += &format!("| {amp} |");
        for j in 0..env.joints.len() {
            md += &format!(" {} |", env.boundary(j)[a].map_or("none".into(), |f| format!("{f}")));
        }
        md += "\n";
    }
    rec.log_static("table", &rerun::TextDocument::from_markdown(md.clone())).map_err(|e| Error::output(&rrd_path, e))?;
    rec.flush_blocking().map_err(|e| Error::output(&rrd_path, e))?;
    files.push(rrd_path);
    for (name, text) in [("envelope.md", md.clone()), ("envelope.json", serde_json::to_string_pretty(&env).unwrap_or_default())] {
        let p = args.out.join(name);
        std::fs::write(&p, text).map_err(|e| Error::output(&p, e))?;
        files.push(p);
    }
    print!("{md}");
    println!("\n{} cells in {:.1} s; wrote {}", env.cells.len(), started.elapsed().as_secs_f64(), files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", "));
    Ok(0)
}
