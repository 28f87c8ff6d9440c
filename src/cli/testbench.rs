//! `armscope testbench`: replay servo bench logs (BAM's JSON) against a servo model and say how
//! far the simulation is from what the servo did.

use super::*;
use std::path::Path;
use crate::actuator::bus_servo::ServoParams;
use crate::testbench::{BenchLog, LogResult, ReplayOptions, Step, Summary, Supply, recording, rollout};

#[derive(Args, Debug)]
pub struct TestbenchArgs {
    /// Bench logs in BAM's JSON: processed (with their dt) or raw (resampled to --dt).
    #[arg(required = true, value_name = "LOG.json")]
    pub logs: Vec<PathBuf>,
    /// The servo's parameters in BAM's JSON (kt, R, armature, the friction model's keys, model,
    /// actuator), e.g. a file of Rhoban/bam's params/ or one `armscope identify` wrote.
    #[arg(long, value_name = "P.json", required_unless_present = "servo", conflicts_with = "servo")]
    pub servo_params: Option<PathBuf>,
    /// A servo of the motor catalogue with a firmware model (e.g. STS3215-C018): its identified
    /// parameters, in place of --servo-params.
    #[arg(long, value_name = "NAME")]
    pub servo: Option<String>,
    /// bam: BAM's explicit step at the log's dt, which BAM's files were identified with; exact:
    /// armscope's exact stick–slip step, --substeps per row.
    #[arg(long, value_enum, default_value_t = Step::Bam)]
    pub step: Step,
    /// Exact steps per log row (--step exact).
    #[arg(long, default_value_t = 5)]
    pub substeps: usize,
    /// auto: the header's vin, or the log's input_volts row by row where the two disagree by more than
    /// 10 %; nominal: the header's vin (BAM's assumption); measured: the log's input_volts row by row.
    #[arg(long, value_enum, default_value_t = Supply::Auto)]
    pub supply: Supply,
    /// The grid a raw log is resampled to, s (BAM's `bam.process --dt`).
    #[arg(long, value_name = "SECONDS", default_value_t = crate::testbench::log::DEFAULT_DT)]
    pub dt: f64,
    /// Write every log's result and the mean MAE as JSON.
    #[arg(long, value_name = "PATH")]
    pub summary_json: Option<PathBuf>,
    /// Write one CSV per log here, named after the log (t,goal_position,position_measured,position_sim).
    #[arg(long, value_name = "DIR")]
    pub trace_dir: Option<PathBuf>,
    /// The recordings (NAME: testbench).
    #[command(flatten)]
    pub files: crate::flags::RecordingFiles,
    /// No table on the console.
    #[arg(long, short)]
    pub quiet: bool,
}

impl TestbenchArgs {
    pub fn options(&self) -> Result<ReplayOptions, Error> {
        if self.substeps == 0 {
            return Err(Error::flag("--substeps", "must be at least 1"));
        }
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::flag("--dt", format!("must be a positive number of seconds (got {})", self.dt)));
        }
        Ok(ReplayOptions { step: self.step, substeps: self.substeps, supply: self.supply, reset_rows: None, ..Default::default() })
    }
}

/// Read logs (each error naming its file and field), on every core.
pub fn read_logs(paths: &[PathBuf], dt: f64) -> Result<Vec<BenchLog>, Error> {
    use rayon::prelude::*;
    paths.par_iter().map(|p| BenchLog::load(p, Some(dt)).map_err(|m| Error::flag("LOG", m))).collect()
}

/// Read logs for a replay on `supply`: a measured supply a log lacks is an error naming it; what
/// was dropped or assumed is said in one notice each.
pub fn read_logs_for(paths: &[PathBuf], dt: f64, supply: Supply) -> Result<Vec<BenchLog>, Error> {
    let logs = read_logs(paths, dt)?;
    crate::testbench::reading::check_supply(&logs, supply).map_err(|m| Error::flag("--supply", m))?;
    for n in crate::testbench::reading::notices(&logs, supply) {
        eprintln!("armscope: notice: {n}");
    }
    Ok(logs)
}

/// The servo a replay runs: a parameter file, or a catalogue servo's firmware model; and its name
/// for the report.
pub fn servo_of(params_path: Option<&Path>, catalogue_servo: Option<&str>) -> Result<(ServoParams, String), Error> {
    match (params_path, catalogue_servo) {
        (Some(path), _) => Ok((read_params(path, "--servo-params")?, path.display().to_string())),
        (None, Some(name)) => {
            let catalogue = crate::actuator::catalogue::Catalogue::load(Path::new(crate::actuator::catalogue::DEFAULT_CATALOGUE))?;
            let params = catalogue.servo_params(name).ok_or_else(|| Error::flag("--servo", format!("'{name}' is not a servo of the catalogue with a firmware model ({})", catalogue.servo_names())))??;
            Ok((params, name.to_string()))
        }
        (None, None) => Err(Error::flag("--servo-params", "give the servo's parameters (--servo-params P.json) or a catalogue servo (--servo NAME)")),
    }
}

/// Read a parameter file, its notices printed.
pub fn read_params(path: &Path, flag: &str) -> Result<ServoParams, Error> {
    let mut notices = Vec::new();
    let params = ServoParams::load(path, &mut notices).map_err(|m| Error::flag(flag, m))?;
    for n in notices {
        eprintln!("armscope: notice: {n}");
    }
    Ok(params)
}

/// `armscope testbench`.
pub fn testbench(args: &TestbenchArgs) -> Result<i32, Error> {
    let options = args.options()?;
    let (params, servo_name) = servo_of(args.servo_params.as_deref(), args.servo.as_deref())?;
    let logs = read_logs_for(&args.logs, args.dt, options.supply)?;
    for log in &logs {
        if crate::actuator::bus_servo::firmware::family(&log.actuator).map(|f| f.name) != Some(params.family.name) {
            eprintln!("armscope: notice: {}: a {} log replayed with {servo_name}'s {} parameters", log.path.display(), log.actuator, params.family.name);
        }
    }
    let rollouts: Vec<_> = {
        use rayon::prelude::*;
        logs.par_iter().map(|log| rollout(log, &params, &options)).collect()
    };
    let results: Vec<LogResult> = logs.iter().zip(&rollouts).map(|(log, r)| LogResult::of(log, r, params.family.max_duty)).collect();
    let summary = Summary::new(servo_name, &options, results);
    if !args.quiet {
        let step = match options.step {
            Step::Bam => "BAM's explicit step".to_string(),
            Step::Exact => format!("armscope's exact step ({} per row)", options.substeps),
        };
        let measured = logs.iter().filter(|l| options.supply.measured_for(l)).count();
        let supply = match measured {
            0 => "the header's supply".to_string(),
            m if m == logs.len() => "the measured supply".to_string(),
            m => format!("the measured supply ({m} logs) or the header's"),
        };
        println!("{} {} on {} log(s), {step}, {supply}:", params.family.name, params.friction.model.name(), logs.len());
        print!("{}", summary.table());
    }
    let runs: Vec<(&BenchLog, &crate::testbench::Rollout)> = logs.iter().zip(&rollouts).collect();
    if let Some(path) = &args.summary_json {
        crate::runner::create_parent(path)?;
        let text = serde_json::to_string_pretty(&summary).unwrap_or_default();
        std::fs::write(path, text + "\n").map_err(|e| Error::output(path, e))?;
    }
    if let Some(dir) = &args.trace_dir {
        recording::write_traces(dir, &runs)?;
    }
    let (rrd, mcap) = args.files.paths("testbench");
    if let Some(path) = rrd {
        crate::runner::create_parent(&path)?;
        recording::write_rrd(&path, &runs)?;
        if !args.quiet {
            println!("wrote {}", path.display());
        }
    }
    if let Some(path) = mcap {
        crate::runner::create_parent(&path)?;
        recording::write_mcap(&path, &runs)?;
        if !args.quiet {
            println!("wrote {}", path.display());
        }
    }
    Ok(0)
}
