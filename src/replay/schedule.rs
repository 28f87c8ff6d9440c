//! A replayed episode as a joint schedule (`t,q1..qN`, as `run --trajectory` reads it): the smoothed
//! motion from the episode's first sample on, so that `run` and `size` can drive the simulated arm
//! along what the real one did.

use super::inverse::Motion;
use crate::error::Error;
use std::path::Path;

pub fn write(path: &Path, motion: &Motion) -> Result<(), Error> {
    write_delayed(path, motion, 0.0)
}

/// The schedule as it reaches the arm `latency` s after it was sent: every row that much later, the
/// first pose held until then (a teleop loop's commands reach the servos after the frame they were
/// recorded in).
pub fn write_delayed(path: &Path, motion: &Motion, latency: f64) -> Result<(), Error> {
    let header: Vec<String> = std::iter::once("t".to_string()).chain((1..=motion.q.len()).map(|i| format!("q{i}"))).collect();
    let t0 = motion.time[0];
    if latency <= 0.0 {
        return super::trace::write_columns(path, &header, &motion.time, t0, &[&motion.q]);
    }
    let time: Vec<f64> = std::iter::once(t0).chain(motion.time.iter().map(|t| t + latency)).collect();
    let q: Vec<Vec<f64>> = motion.q.iter().map(|joint| std::iter::once(joint[0]).chain(joint.iter().copied()).collect()).collect();
    super::trace::write_columns(path, &header, &time, t0, &[&q])
}

/// The schedule's duration and its first pose (the joints in model order), for the run that follows it.
pub fn span(motion: &Motion) -> (f64, Vec<f64>) {
    let last = motion.len() - 1;
    (motion.time[last] - motion.time[0], motion.q.iter().map(|joint| joint[0]).collect())
}

/// The median interval between a motion's samples, s (a recording's frame period; 0 with one sample).
pub fn frame_period(motion: &Motion) -> f64 {
    let mut steps: Vec<f64> = motion.time.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return 0.0;
    }
    steps.sort_by(f64::total_cmp);
    steps[steps.len() / 2]
}
