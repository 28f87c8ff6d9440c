//! `replay --trace FILE.csv`: one row per sample, `t,q1..qN,qd1..qN,qdd1..qN,tau1..tauN` in the
//! joint order of `armscope model`, t in seconds from the episode's first sample, every number
//! round-trip exact.

use super::inverse::Motion;
use crate::error::Error;
use std::io::{BufWriter, Write};
use std::path::Path;

pub fn header(n: usize) -> Vec<String> {
    let mut cols = vec!["t".to_string()];
    for prefix in ["q", "qd", "qdd", "tau"] {
        cols.extend((1..=n).map(|i| format!("{prefix}{i}")));
    }
    cols
}

pub fn write(path: &Path, motion: &Motion) -> Result<(), Error> {
    use std::fmt::Write as _;
    let file = std::fs::File::create(path).map_err(|e| Error::output(path, e))?;
    let mut out = BufWriter::new(file);
    let n = motion.q.len();
    let mut line = header(n).join(",");
    line.push('\n');
    for k in 0..motion.len() {
        let _ = write!(line, "{:?}", motion.time[k]);
        for series in [&motion.q, &motion.qd, &motion.qdd, &motion.needed] {
            for joint in series {
                let _ = write!(line, ",{:?}", joint[k]);
            }
        }
        line.push('\n');
        out.write_all(line.as_bytes()).map_err(|e| Error::output(path, e))?;
        line.clear();
    }
    out.flush().map_err(|e| Error::output(path, e))
}
