//! The "real" follower of the forward-replay tests: armscope's own SO-101 with its STS3215s (through
//! their firmware loop) and a payload at the tool, simulated along known commands.

use super::lerobot::Sines;
use armscope::config::RunConfig;
use armscope::experiment::Experiment;
use armscope::recorder::{Recorder, RunInfo};
use std::path::{Path, PathBuf};

pub fn so101() -> PathBuf {
    super::repo().join("tests/fixtures/robots/so101.urdf")
}

pub fn so101_motors() -> PathBuf {
    super::repo().join("assets/motors/so101.toml")
}

/// The SO-101 on BAM's 12 V STS3215 parameters: the servo the protection tests' scenarios were built on.
pub fn so101_motors_bam12v() -> PathBuf {
    super::repo().join("tests/fixtures/motors/so101_bam12v.toml")
}

/// The commands both tests drive: every joint swinging about its centre.
pub fn so101_commands() -> Vec<Sines> {
    let s = |center: f64, a: f64, w: f64| Sines { center, terms: vec![(a, w, 0.3)] };
    vec![s(0.0, 0.5, 1.2), s(0.3, 0.4, 1.0), s(-0.4, 0.4, 1.3), s(0.2, 0.4, 1.5), s(0.0, 0.6, 1.1), s(0.8, 0.3, 1.0)]
}

/// The run's joint positions at every control step.
pub struct Capture(pub Vec<Vec<f64>>);

impl Recorder for Capture {
    fn start(&mut self, _: &RunInfo) -> Result<(), armscope::Error> {
        Ok(())
    }
    fn record(&mut self, sample: &armscope::sample::Sample) -> Result<(), armscope::Error> {
        self.0.push(sample.q.to_vec());
        Ok(())
    }
    fn finish(&mut self, _: &RunInfo, _: &armscope::summary::Summary) -> Result<(), armscope::Error> {
        Ok(())
    }
}

/// The SO-101 simulated along `motion` (its exact commands every millisecond, from where they start)
/// for `seconds` with `payload` at the tool: its positions every millisecond.
pub fn follow(dir: &Path, motion: &[Sines], payload: f64, seconds: f64) -> Vec<Vec<f64>> {
    follow_on(dir, motion, payload, seconds, &so101_motors(), 0.0)
}

/// [`follow`] with the servos of the motor file `motors`, each command reaching them `latency` s
/// after it was sent (the first held until then: a teleop loop's delay).
pub fn follow_on(dir: &Path, motion: &[Sines], payload: f64, seconds: f64, motors: &Path, latency: f64) -> Vec<Vec<f64>> {
    let schedule = dir.join("exact_commands.csv");
    let mut text = String::from("t,q1,q2,q3,q4,q5,q6\n");
    for k in 0..=(seconds * 1e3).round() as usize {
        let t = k as f64 * 1e-3;
        text += &format!("{t:?}");
        for m in motion {
            text += &format!(",{:?}", m.q((t - latency).max(0.0)));
        }
        text.push('\n');
    }
    std::fs::write(&schedule, text).unwrap();
    let start: Vec<String> = motion.iter().map(|m| format!("{:?}", m.q(0.0))).collect();
    let config = RunConfig { urdf: so101(), motors: Some(motors.to_path_buf()), payload, trajectory: Some(schedule), duration: seconds, q0: Some(start.join(",")), ..RunConfig::default() };
    let experiment = Experiment::prepare(config).unwrap();
    let mut capture = Capture(Vec::new());
    armscope::sim::simulate(&experiment, &mut [&mut capture], None).unwrap();
    capture.0
}
