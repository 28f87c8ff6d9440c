use super::manifest::{PlannedExperiment, load_manifest, shard};
use super::outcome::ExperimentOutcome;
use super::table::{BatchSummary, write_tables};
use super::compare::{ComparedRun, Comparison, SeriesRecorder, build_comparison};

use crate::flags::RunArgs;
use crate::error::Error;
use crate::experiment::Experiment;
use crate::runner::{Outputs, run_experiment};
use crate::summary::{RunStatus, Summary};
use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

#[derive(Clone, Debug)]
pub struct BatchOptions {
    pub manifest: PathBuf,
    /// Experiments run at once.
    pub jobs: usize,
    /// Run only shard I of N.
    pub shard: Option<(usize, usize)>,
    /// The output folder (default: recordings/BATCH).
    pub out: Option<PathBuf>,
    /// Build the comparison recording.
    pub compare: bool,
    /// Compress every experiment's recordings (or an experiment's own `--compress`).
    pub compress: bool,
    /// Every experiment's MCAP encoding (unless an experiment sets its own).
    pub mcap_encoding: crate::recorder::McapEncoding,
    pub progress: bool,
}

/// `run` flags as the CLI parses them.
#[derive(Parser)]
#[command(name = "run", no_binary_name = false)]
struct RunFlags {
    #[command(flatten)]
    args: RunArgs,
}

/// One experiment; with a comparison, its series are added to it when it has a summary (whatever
/// its status, as the comparison built from the `.mcap` files after the runs included it).
fn run_one(e: &PlannedExperiment, dir: &Path, compress: bool, encoding: crate::recorder::McapEncoding, stop: Option<&AtomicBool>, comparison: Option<&Comparison>) -> (ExperimentOutcome, Result<(), Error>) {
    let started = std::time::Instant::now();
    let (recorder, finished) = comparison.map(|_| SeriesRecorder::new()).unzip();
    let mut outcome = run_timed(e, dir, compress, encoding, stop, recorder.map(|r| Box::new(r) as Box<dyn crate::recorder::Recorder>));
    outcome.wall_time = started.elapsed().as_secs_f64();
    let mut added = Ok(());
    if let (Some(comparison), Some(finished), Some(_)) = (comparison, finished, &outcome.summary) {
        if let Some(series) = finished.lock().unwrap_or_else(|e| e.into_inner()).take() {
            added = comparison.add(&e.name, e.index, &series);
        }
    }
    (outcome, added)
}

/// A manifest experiment's `run` flags, parsed as `armscope run` parses them; the error is clap's
/// first line.
pub fn run_args(e: &PlannedExperiment) -> Result<RunArgs, String> {
    let argv = std::iter::once("run".to_string()).chain(e.args.iter().cloned());
    RunFlags::try_parse_from(argv).map(|f| f.args).map_err(|err| {
        let text = err.render().to_string();
        text.lines().next().unwrap_or("invalid flags").trim_start_matches("error: ").to_string()
    })
}

fn run_timed(e: &PlannedExperiment, dir: &Path, compress: bool, encoding: crate::recorder::McapEncoding, stop: Option<&AtomicBool>, series: Option<Box<dyn crate::recorder::Recorder>>) -> ExperimentOutcome {
    let failed = |error: String| ExperimentOutcome { index: e.index, name: e.name.clone(), args: e.args.clone(), status: "failed".into(), summary: None, error: Some(error), wall_time: 0.0 };
    let flags = match run_args(e) {
        Ok(args) => args,
        Err(message) => return failed(message),
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| -> Result<Summary, Error> {
        let experiment = Experiment::prepare(flags.config())?;
        let log = dir.join(format!("{}.log", e.name));
        let console = std::fs::File::create(&log).map_err(|err| Error::output(&log, err))?;
        let outputs = Outputs {
            name: e.name.clone(),
            console: Some(Box::new(std::io::BufWriter::new(console))),
            rrd: Some(dir.join(format!("{}.rrd", e.name))),
            mcap: Some(dir.join(format!("{}.mcap", e.name))),
            csv: Some(dir.join(format!("{}.csv", e.name))),
            summary_json: Some(dir.join(format!("{}.json", e.name))),
            compress: compress || flags.compress,
            mcap_encoding: if flags.mcap_encoding == crate::recorder::McapEncoding::Foxglove { encoding } else { flags.mcap_encoding },
            recorders: series.into_iter().collect(),
            ..Outputs::default()
        };
        run_experiment(&experiment, outputs, stop)
    }));
    match result {
        Ok(Ok(summary)) => {
            let (status, error) = match &summary.status {
                RunStatus::Completed => ("completed", None),
                RunStatus::Interrupted { .. } => ("interrupted", None),
                RunStatus::Diverged { message, .. } => ("diverged", Some(message.clone())),
                RunStatus::Collided { time, link1, link2 } => ("collided", Some(format!("stopped at the first collision, t = {time:.3} s: {link1} with {link2}"))),
            };
            ExperimentOutcome { index: e.index, name: e.name.clone(), args: e.args.clone(), status: status.into(), summary: Some(summary), error, wall_time: 0.0 }
        }
        Ok(Err(err)) => failed(err.to_string()),
        Err(panic) => failed(format!("internal error: {}", panic.downcast_ref::<String>().cloned().or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string())).unwrap_or_default())),
    }
}

/// Run a manifest (or one shard of it). Returns the batch summary and the files written.
pub fn run_batch(options: &BatchOptions, stop: Option<&AtomicBool>) -> Result<(BatchSummary, Vec<PathBuf>), Error> {
    let manifest = load_manifest(&options.manifest)?;
    let planned = match options.shard {
        Some((i, n)) => shard(&manifest.experiments, i, n),
        None => manifest.experiments.clone(),
    };
    let dir = options.out.clone().unwrap_or_else(|| PathBuf::from("recordings").join(&manifest.name));
    std::fs::create_dir_all(&dir).map_err(|e| Error::output(&dir, e))?;
    let jobs = options.jobs.max(1);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs).build().map_err(|e| Error::flag("--jobs", e.to_string()))?;
    let bar = ProgressBar::new(planned.len() as u64);
    if options.progress {
        bar.set_style(ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} experiments  {msg}").unwrap_or_else(|_| ProgressStyle::default_bar()));
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
    } else {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    // the comparison recording is written while the runs go on, from the series they keep
    let comparison_path = dir.join("comparison.rrd");
    let comparison = if options.compare && options.shard.is_none() { Some(Comparison::create(&comparison_path, &manifest.name)?) } else { None };
    let results: Vec<(ExperimentOutcome, Result<(), Error>)> = pool.install(|| {
        planned
            .par_iter()
            .map(|e| {
                let result = run_one(e, &dir, options.compress, options.mcap_encoding, stop, comparison.as_ref());
                bar.set_message(format!("{} {}", result.0.name, result.0.status));
                bar.inc(1);
                result
            })
            .collect()
    });
    bar.finish_and_clear();
    let (outcomes, added): (Vec<ExperimentOutcome>, Vec<Result<(), Error>>) = results.into_iter().unzip();
    let summary = BatchSummary {
        batch: manifest.name.clone(),
        manifest: manifest.path.clone(),
        shard: options.shard.map(|(i, n)| [i, n]),
        experiments: outcomes,
    };
    let mut files = write_tables(&dir, &summary)?;
    added.into_iter().collect::<Result<(), Error>>()?;
    if let Some(comparison) = comparison {
        let compared: Vec<String> = summary.experiments.iter().filter(|e| e.summary.is_some()).map(|e| e.name.clone()).collect();
        if compared.is_empty() {
            // nothing finished: no comparison file, as before
            drop(comparison);
            let _ = std::fs::remove_file(&comparison_path);
        } else {
            comparison.finish(&compared)?;
            files.push(comparison_path);
        }
    }
    Ok((summary, files))
}

/// `out_dir/comparison.rrd` from the experiments that finished, each from the first of `dirs`
/// that holds its .mcap. None when there is nothing to compare.
pub fn write_comparison(summary: &BatchSummary, dirs: &[PathBuf], out_dir: &Path) -> Result<Option<PathBuf>, Error> {
    let runs: Vec<ComparedRun> = summary
        .experiments
        .iter()
        .filter(|e| e.summary.is_some())
        .filter_map(|e| {
            let mcap = dirs.iter().map(|d| d.join(format!("{}.mcap", e.name))).find(|p| p.exists())?;
            Some(ComparedRun { label: e.name.clone(), mcap })
        })
        .collect();
    if runs.is_empty() {
        return Ok(None);
    }
    let out = out_dir.join("comparison.rrd");
    build_comparison(&runs, &out, &summary.batch)?;
    Ok(Some(out))
}
