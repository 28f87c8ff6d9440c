//! `replay --trace FILE.csv`: one row per sample, `t,q1..qN,qd1..qN,qdd1..qN,tau1..tauN` in the
//! joint order of `armscope model`, t in seconds from the episode's first sample, every number
//! round-trip exact; with `--forward`, one row per frame, each compared joint's commanded, real and
//! simulated position (`t,command_J..,real_J..,model_J..`). The CSV writer here also writes the
//! joint schedules of [`super::schedule`].

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
    write_columns(path, &header(motion.q.len()), &motion.time, 0.0, &[&motion.q, &motion.qd, &motion.qdd, &motion.needed])
}

/// A forward replay's frames: `t`, then each compared joint's command, the real follower's and the
/// simulated follower's positions, named by joint.
pub fn write_forward(path: &Path, replay: &super::forward::ForwardReplay) -> Result<(), Error> {
    let mut header = vec!["t".to_string()];
    for prefix in ["command", "real", "model"] {
        header.extend(replay.joints.iter().map(|g| format!("{prefix}_{}", g.joint)));
    }
    write_columns(path, &header, &replay.time, 0.0, &[&replay.commanded, &replay.observed, &replay.simulated])
}

/// A CSV under `header`: per sample k, `time[k] − t0`, then every joint of each of `series` in turn,
/// every number round-trip exact.
pub(super) fn write_columns(path: &Path, header: &[String], time: &[f64], t0: f64, series: &[&Vec<Vec<f64>>]) -> Result<(), Error> {
    use std::fmt::Write as _;
    let file = std::fs::File::create(path).map_err(|e| Error::output(path, e))?;
    let mut out = BufWriter::new(file);
    let mut line = header.join(",");
    line.push('\n');
    for (k, t) in time.iter().enumerate() {
        let _ = write!(line, "{:?}", t - t0);
        for joints in series {
            for joint in joints.iter() {
                let _ = write!(line, ",{:?}", joint[k]);
            }
        }
        line.push('\n');
        out.write_all(line.as_bytes()).map_err(|e| Error::output(path, e))?;
        line.clear();
    }
    out.flush().map_err(|e| Error::output(path, e))
}
