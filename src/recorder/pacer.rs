use super::{Recorder, RunInfo};
use crate::error::Error;
use crate::sample::Sample;
use crate::summary::Summary;
use std::time::{Duration, Instant};

/// `--realtime [FACTOR]`: holds the loop back so simulated time runs at FACTOR × the wall clock,
/// so the arm moves in a live viewer at real speed.
pub struct Pacer {
    factor: f64,
    started: Option<Instant>,
}

impl Pacer {
    pub fn new(factor: f64) -> Self {
        Self { factor, started: None }
    }
}

impl Recorder for Pacer {
    fn start(&mut self, _run: &RunInfo) -> Result<(), Error> {
        self.started = Some(Instant::now());
        Ok(())
    }

    fn record(&mut self, s: &Sample) -> Result<(), Error> {
        let started = self.started.expect("started");
        let due = Duration::from_secs_f64(s.t / self.factor);
        let elapsed = started.elapsed();
        // sleep in slices of at least 2 ms: finer sleeps cost more than they are worth
        if due > elapsed + Duration::from_millis(2) {
            std::thread::sleep(due - elapsed);
        }
        Ok(())
    }

    fn finish(&mut self, _run: &RunInfo, _summary: &Summary) -> Result<(), Error> {
        Ok(())
    }
}
