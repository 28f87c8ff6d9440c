//! One experiment with its outputs: assembles the recorders and runs the simulation. Shared by
//! `armscope run` and `armscope batch`.

use crate::error::Error;
use crate::experiment::Experiment;
use crate::recorder::{Console, LiveViewer, McapEncoding, McapOptions, McapRecorder, Pacer, Recorder, RerunOptions, RerunRecorder, Ros2McapRecorder, SummaryJson, Threaded, Trace, TutorialCsv};
use crate::sim::simulate;
use crate::summary::Summary;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// How long a recorder thread may wait for samples (keeps a live viewer current).
const RECORDER_LATENCY: Duration = Duration::from_millis(20);

/// Where one run's output goes.
#[derive(Default)]
pub struct Outputs {
    /// The recording's name in the viewer.
    pub name: String,
    pub console: Option<Box<dyn Write + Send>>,
    pub rrd: Option<PathBuf>,
    pub mcap: Option<PathBuf>,
    pub live: Option<LiveViewer>,
    /// `HOST:PORT` to serve the MCAP's channels live to Foxglove at.
    pub foxglove: Option<String>,
    pub realtime: Option<f64>,
    pub csv: Option<PathBuf>,
    pub trace: Option<PathBuf>,
    pub summary_json: Option<PathBuf>,
    /// Called with messages for the user (e.g. no viewer reachable).
    pub notice: Option<fn(&str)>,
    /// Compress the recordings' chunks (`--compress`): smaller files, more CPU.
    pub compress: bool,
    /// The MCAP's encoding (`--mcap-encoding`).
    pub mcap_encoding: crate::recorder::McapEncoding,
    /// Further recorders, run after the others (a batch's comparison series).
    pub recorders: Vec<Box<dyn Recorder>>,
    /// A torque law in place of the PD controller (Python's `armscope.simulate`).
    pub law: Option<Box<dyn crate::control::law::TorqueLaw>>,
}

/// `text` with every character that is not ASCII alphanumeric or `-_.` made a `-`: usable as a
/// file name and as an entity path part.
pub fn file_safe(text: &str) -> String {
    text.chars().map(|c| if c.is_ascii_alphanumeric() || "-_.".contains(c) { c } else { '-' }).collect()
}

pub fn create_parent(path: &Path) -> Result<(), Error> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, e)),
        _ => Ok(()),
    }
}

/// Run `experiment`, writing every requested output. Returns the summary, also for an interrupted
/// or diverged run (see its status).
pub fn run_experiment(experiment: &Experiment, outputs: Outputs, stop: Option<&AtomicBool>) -> Result<Summary, Error> {
    let mut recorders: Vec<Box<dyn Recorder>> = Vec::new();
    if let Some(out) = outputs.console {
        recorders.push(Box::new(Console::new(out)));
    }
    // the recordings, each written on its own thread from one copy of the samples
    let mut threaded = Threaded::new(RECORDER_LATENCY);
    if outputs.rrd.is_some() || outputs.live.is_some() {
        if let Some(path) = &outputs.rrd {
            create_parent(path)?;
        }
        let mut rrd = RerunRecorder::new(RerunOptions { file: outputs.rrd.clone(), live: outputs.live, name: outputs.name.clone(), compress: outputs.compress });
        if let Some(notice) = outputs.notice {
            rrd.on_notice(notice);
        }
        threaded = threaded.with(rrd);
    }
    if outputs.mcap.is_some() || outputs.foxglove.is_some() {
        if let Some(path) = &outputs.mcap {
            create_parent(path)?;
        }
        let options = McapOptions { file: outputs.mcap.clone(), live: outputs.foxglove.clone(), compress: outputs.compress };
        match outputs.mcap_encoding {
            McapEncoding::Foxglove => {
                let mut mcap = McapRecorder::new(options);
                if let Some(notice) = outputs.notice {
                    mcap.on_notice(notice);
                }
                threaded = threaded.with(mcap);
            }
            McapEncoding::Ros2 => {
                let mut mcap = Ros2McapRecorder::new(options);
                if let Some(notice) = outputs.notice {
                    mcap.on_notice(notice);
                }
                threaded = threaded.with(mcap);
            }
        }
    }
    if !threaded.is_empty() {
        recorders.push(Box::new(threaded));
    }
    if let Some(factor) = outputs.realtime {
        recorders.push(Box::new(Pacer::new(factor)));
    }
    for (path, make) in [
        (&outputs.csv, (|p| Box::new(TutorialCsv::new(p)) as Box<dyn Recorder>) as fn(PathBuf) -> Box<dyn Recorder>),
        (&outputs.trace, |p| Box::new(Trace::new(p))),
        (&outputs.summary_json, |p| Box::new(SummaryJson::new(p))),
    ] {
        if let Some(path) = path {
            create_parent(path)?;
            recorders.push(make(path.clone()));
        }
    }
    recorders.extend(outputs.recorders);
    let mut refs: Vec<&mut dyn Recorder> = recorders.iter_mut().map(|r| r.as_mut() as &mut dyn Recorder).collect();
    match outputs.law {
        Some(mut law) => crate::sim::simulate_with_law(experiment, &mut refs, stop, law.as_mut()),
        None => simulate(experiment, &mut refs, stop),
    }
}
