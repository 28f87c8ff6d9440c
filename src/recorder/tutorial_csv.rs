use super::{Recorder, RunInfo, is_on_period};
use crate::error::Error;
use crate::sample::Sample;
use crate::summary::Summary;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;

/// `--csv`: the tutorial's CSV, `t,q1..qN,x,y,z` every `--print-every` seconds, the first row the
/// initial state.
pub struct TutorialCsv {
    path: PathBuf,
    out: Option<BufWriter<File>>,
    dt: f64,
    period: f64,
}

impl TutorialCsv {
    pub fn new(path: PathBuf) -> Self {
        Self { path, out: None, dt: 0.0, period: 0.0 }
    }
}

impl Recorder for TutorialCsv {
    fn start(&mut self, run: &RunInfo) -> Result<(), Error> {
        let e = run.experiment;
        self.dt = e.config.dt;
        self.period = e.config.print_every;
        let mut out = BufWriter::new(File::create(&self.path).map_err(|err| Error::output(&self.path, err))?);
        let mut header = vec!["t".to_string()];
        header.extend((1..=e.model.dof()).map(|i| format!("q{i}")));
        header.extend(["x", "y", "z"].map(String::from));
        writeln!(out, "{}", header.join(",")).map_err(|err| Error::output(&self.path, err))?;
        self.out = Some(out);
        Ok(())
    }

    fn record(&mut self, s: &Sample) -> Result<(), Error> {
        if !is_on_period(s.k, self.dt, self.period) {
            return Ok(());
        }
        let out = self.out.as_mut().expect("started");
        let mut line = format!("{:?}", s.t);
        for q in s.q {
            line.push_str(&format!(",{q:?}"));
        }
        let p = s.tool_position;
        line.push_str(&format!(",{:?},{:?},{:?}", p.x, p.y, p.z));
        writeln!(out, "{line}").map_err(|err| Error::output(&self.path, err))
    }

    fn finish(&mut self, _run: &RunInfo, _summary: &Summary) -> Result<(), Error> {
        if let Some(out) = self.out.as_mut() {
            out.flush().map_err(|err| Error::output(&self.path, err))?;
        }
        Ok(())
    }
}
