//! A replayed episode as a joint schedule (`t,q1..qN`, as `run --trajectory` reads it): the smoothed
//! motion from the episode's first sample on, so that `run` and `size` can drive the simulated arm
//! along what the real one did.

use super::inverse::Motion;
use crate::error::Error;
use std::io::{BufWriter, Write};
use std::path::Path;

pub fn write(path: &Path, motion: &Motion) -> Result<(), Error> {
    use std::fmt::Write as _;
    let file = std::fs::File::create(path).map_err(|e| Error::output(path, e))?;
    let mut out = BufWriter::new(file);
    let n = motion.q.len();
    let mut line = String::from("t");
    for i in 1..=n {
        let _ = write!(line, ",q{i}");
    }
    line.push('\n');
    let start = motion.time[0];
    for k in 0..motion.len() {
        let _ = write!(line, "{:?}", motion.time[k] - start);
        for joint in &motion.q {
            let _ = write!(line, ",{:?}", joint[k]);
        }
        line.push('\n');
        out.write_all(line.as_bytes()).map_err(|e| Error::output(path, e))?;
        line.clear();
    }
    out.flush().map_err(|e| Error::output(path, e))
}

/// The schedule's duration and its first pose (the joints in model order), for the run that follows it.
pub fn span(motion: &Motion) -> (f64, Vec<f64>) {
    let last = motion.len() - 1;
    (motion.time[last] - motion.time[0], motion.q.iter().map(|joint| joint[0]).collect())
}
