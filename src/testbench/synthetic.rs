//! Bench logs of a known servo, simulated: what the tests identify back and the benchmarks replay
//! (no real log is needed to check the replay and the fit). The trajectories are BAM's four
//! (`bam/trajectory.py`, all 6 s): a cubic lift to −π/2 in 2 s and then the torque off, sin(t²),
//! a cubic 0 → π/2 at 3 s → 0.8·π/2 at 6 s, and sin t·π/2 + sin 5t·½·sin 2t. The recorded position
//! is quantized to the encoder's 4096 counts a turn, as a real servo reports it.

use super::log::{BenchLog, Entry};
use super::replay::{ReplayOptions, rollout};
use crate::actuator::bus_servo::ServoParams;
use std::f64::consts::{FRAC_PI_2, TAU};
use std::path::PathBuf;

/// One of BAM's bench trajectories.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Trajectory {
    LiftAndDrop,
    SinTimeSquare,
    UpAndDown,
    SinSin,
}

impl Trajectory {
    pub const ALL: [Trajectory; 4] = [Trajectory::LiftAndDrop, Trajectory::SinTimeSquare, Trajectory::UpAndDown, Trajectory::SinSin];

    pub fn name(self) -> &'static str {
        match self {
            Trajectory::LiftAndDrop => "lift_and_drop",
            Trajectory::SinTimeSquare => "sin_time_square",
            Trajectory::UpAndDown => "up_and_down",
            Trajectory::SinSin => "sin_sin",
        }
    }

    /// The goal (rad) and whether the torque is on at time `t`.
    pub fn at(self, t: f64) -> (f64, bool) {
        match self {
            Trajectory::LiftAndDrop => (cubic(&[(0.0, 0.0), (2.0, -FRAC_PI_2)], t), t < 2.0),
            Trajectory::SinTimeSquare => ((t * t).sin(), true),
            Trajectory::UpAndDown => (cubic(&[(0.0, 0.0), (3.0, FRAC_PI_2), (6.0, 0.8 * FRAC_PI_2)], t), true),
            Trajectory::SinSin => (t.sin() * FRAC_PI_2 + (5.0 * t).sin() * 0.5 * (2.0 * t).sin(), true),
        }
    }
}

/// The cubic through keyframes (time, value) with zero slope at each, held outside them.
fn cubic(keys: &[(f64, f64)], t: f64) -> f64 {
    let (first, last) = (keys[0], keys[keys.len() - 1]);
    if t <= first.0 {
        return first.1;
    }
    if t >= last.0 {
        return last.1;
    }
    let k = keys.windows(2).position(|w| t <= w[1].0).unwrap_or(0);
    let ((t0, x0), (t1, x1)) = (keys[k], keys[k + 1]);
    let s = (t - t0) / (t1 - t0);
    x0 + (x1 - x0) * s * s * (3.0 - 2.0 * s)
}

/// The bench a synthetic log is recorded on.
#[derive(Clone, Debug)]
pub struct Bench {
    pub mass: f64,
    pub length: f64,
    pub kp: f64,
    pub vin: f64,
    pub dt: f64,
    pub duration: f64,
}

impl Default for Bench {
    /// BAM's XL330 bench: 0.49 kg at 0.10 m, 7.4 V, 5 ms rows, 6 s.
    fn default() -> Self {
        Self { mass: 0.49, length: 0.1, kp: 400.0, vin: 7.4, dt: 0.005, duration: 6.0 }
    }
}

/// The log `params`' servo would record on `bench` following `trajectory` (the replay's own
/// step per `options`), its position quantized to the encoder.
pub fn record(params: &ServoParams, bench: &Bench, trajectory: Trajectory, options: &ReplayOptions) -> BenchLog {
    let rows = (bench.duration / bench.dt).round() as usize;
    let entries: Vec<Entry> = (0..rows)
        .map(|k| {
            let time = k as f64 * bench.dt;
            let (goal, enabled) = trajectory.at(time);
            Entry { time, goal, enabled, position: 0.0, speed: 0.0, duty: None, volts: None }
        })
        .collect();
    let mut log = BenchLog {
        path: PathBuf::from(format!("{}_kp{}_{}.json", params.family.name, bench.kp, trajectory.name())),
        mass: bench.mass,
        arm_mass: 0.0,
        length: bench.length,
        kp: bench.kp,
        vin: bench.vin,
        actuator: params.family.name.to_string(),
        trajectory: Some(trajectory.name().to_string()),
        dt: bench.dt,
        resampled: false,
        glitches: 0,
        measured_supply: None,
        entries,
    };
    let truth = rollout(&log, params, options);
    let count = TAU / 4096.0;
    // a Dynamixel's Present Velocity counts 0.229 rpm
    let speed_unit = 0.229 * TAU / 60.0;
    for (((entry, q), v), duty) in log.entries.iter_mut().zip(&truth.position).zip(&truth.speed).zip(&truth.duty) {
        entry.position = (q / count).round() * count;
        entry.speed = (v / speed_unit).round() * speed_unit;
        entry.duty = Some(*duty);
        entry.volts = Some(bench.vin);
    }
    log.measured_supply = super::log::median_supply(&log.entries);
    log
}

/// The log as BAM's processed JSON.
pub fn to_json(log: &BenchLog) -> serde_json::Value {
    let entries: Vec<serde_json::Value> = log
        .entries
        .iter()
        .map(|e| {
            serde_json::json!({
                "timestamp": e.time, "position": e.position, "speed": e.speed, "goal_position": e.goal,
                "torque_enable": e.enabled, "load": e.duty.unwrap_or(0.0), "input_volts": e.volts.unwrap_or(log.vin),
            })
        })
        .collect();
    serde_json::json!({
        "mass": log.mass, "length": log.length, "kp": log.kp, "vin": log.vin, "motor": log.actuator,
        "trajectory": log.trajectory, "dt": log.dt, "entries": entries,
    })
}
