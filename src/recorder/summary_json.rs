use super::{Recorder, RunInfo};
use crate::error::Error;
use crate::sample::Sample;
use crate::summary::Summary;
use std::path::PathBuf;

/// `--summary-json`: the console summary's numbers, plus the run's configuration and gains.
pub struct SummaryJson {
    path: PathBuf,
}

impl SummaryJson {
    pub fn new(path: PathBuf) -> Self {
        Self { path }
    }
}

impl Recorder for SummaryJson {
    fn start(&mut self, _run: &RunInfo) -> Result<(), Error> {
        Ok(())
    }

    fn record(&mut self, _sample: &Sample) -> Result<(), Error> {
        Ok(())
    }

    fn finish(&mut self, run: &RunInfo, summary: &Summary) -> Result<(), Error> {
        let e = run.experiment;
        let doc = serde_json::json!({
            "model": e.model.name,
            "urdf": e.model.source,
            "config": e.config,
            "gains": e.gains,
            "notices": e.model.notices,
            "plant": run.plant,
            "command": run.trajectory,
            "summary": summary,
        });
        let text = serde_json::to_string_pretty(&doc).map_err(|err| Error::output(&self.path, err))?;
        std::fs::write(&self.path, text + "\n").map_err(|err| Error::output(&self.path, err))
    }
}
