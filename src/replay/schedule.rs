//! A replayed episode as a joint schedule (`t,q1..qN`, as `run --trajectory` reads it): the smoothed
//! motion from the episode's first sample on, so that `run` and `size` can drive the simulated arm
//! along what the real one did.

use super::inverse::Motion;
use crate::error::Error;
use std::path::Path;

pub fn write(path: &Path, motion: &Motion) -> Result<(), Error> {
    let header: Vec<String> = std::iter::once("t".to_string()).chain((1..=motion.q.len()).map(|i| format!("q{i}"))).collect();
    super::trace::write_columns(path, &header, &motion.time, motion.time[0], &[&motion.q])
}

/// The schedule's duration and its first pose (the joints in model order), for the run that follows it.
pub fn span(motion: &Motion) -> (f64, Vec<f64>) {
    let last = motion.len() - 1;
    (motion.time[last] - motion.time[0], motion.q.iter().map(|joint| joint[0]).collect())
}
