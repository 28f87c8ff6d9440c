use super::{Recorder, RunInfo};
use crate::error::Error;
use crate::sample::Sample;
use crate::summary::Summary;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;

/// `--trace`: one row per step k at t_k = k·dt,
/// `t,q1..qN,qd1..qN,cmd1..cmdN,cmd_dot1..cmd_dotN,u1..uN,tau_g1..tau_gN,x,y,z`, every number
/// written round-trip exact. u is the torque held over [t_k, t_k + dt).
pub struct Trace {
    path: PathBuf,
    out: Option<BufWriter<File>>,
    line: String,
}

impl Trace {
    pub fn new(path: PathBuf) -> Self {
        Self { path, out: None, line: String::with_capacity(1024) }
    }

    /// The column names for a model with `n` joints.
    pub fn header(n: usize) -> Vec<String> {
        let mut cols = vec!["t".to_string()];
        for prefix in ["q", "qd", "cmd", "cmd_dot", "u", "tau_g"] {
            cols.extend((1..=n).map(|i| format!("{prefix}{i}")));
        }
        cols.extend(["x", "y", "z"].map(String::from));
        cols
    }
}

impl Recorder for Trace {
    fn start(&mut self, run: &RunInfo) -> Result<(), Error> {
        let mut out = BufWriter::new(File::create(&self.path).map_err(|e| Error::output(&self.path, e))?);
        writeln!(out, "{}", Self::header(run.experiment.model.dof()).join(",")).map_err(|e| Error::output(&self.path, e))?;
        self.out = Some(out);
        Ok(())
    }

    fn record(&mut self, s: &Sample) -> Result<(), Error> {
        use std::fmt::Write as _;
        self.line.clear();
        let _ = write!(self.line, "{:?}", s.t);
        for series in [s.q, s.v, s.cmd, s.cmd_dot, s.u, s.tau_g] {
            for x in series {
                let _ = write!(self.line, ",{x:?}");
            }
        }
        let p = s.tool_position;
        let _ = writeln!(self.line, ",{:?},{:?},{:?}", p.x, p.y, p.z);
        let out = self.out.as_mut().expect("started");
        out.write_all(self.line.as_bytes()).map_err(|e| Error::output(&self.path, e))
    }

    fn finish(&mut self, _run: &RunInfo, _summary: &Summary) -> Result<(), Error> {
        if let Some(out) = self.out.as_mut() {
            out.flush().map_err(|e| Error::output(&self.path, e))?;
        }
        Ok(())
    }
}
