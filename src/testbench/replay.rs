//! Replaying a bench log: the log's goals and torque enables sent to a simulated servo on the
//! log's pendulum, from the log's first measured state, never re-synchronised (BAM's
//! `rollout_log` with the control simulated). The firmware acts on each goal its
//! `command_delay` after the log sent it (0 in BAM's files).
//!
//! Two steps, chosen by [`Step`]:
//! - **BAM's** explicit step of Δt = the log's dt, which BAM's identified files were fitted with
//!   (so it is part of those models): the friction budget B + K_v·|q̇| clips the torque that would
//!   stop the joint within the step, then q̇' = q̇ + a·Δt (clipped at ±100 rad/s) and
//!   q' = q + q̇'·Δt + ½·a·Δt².
//! - **armscope's** exact step, as its discrete plant steps a joint: semi-implicit Euler with the
//!   viscous friction K_v and nothing else implicit, the Coulomb budget B as a band the friction
//!   impulse stays within, solved exactly (the joint sticks, q̇ = 0 exactly, when the rest of the
//!   step's impulse is within ±h·B), `substeps` steps per log row, the firmware ticking at each.

use super::log::BenchLog;
use super::pendulum::Pendulum;
use crate::actuator::bus_servo::friction::sign;
use crate::actuator::bus_servo::{BusServo, FirmwareState, ServoParams};

/// How the bench is stepped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Step {
    /// BAM's explicit step at the log's dt (what BAM's files were identified with).
    #[default]
    Bam,
    /// armscope's exact stick–slip step, `--substeps` per log row.
    Exact,
}

/// Which supply voltage drives the servo.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Supply {
    /// The header's `vin`, unless the log's measured supply disagrees with it (by more than 10 %):
    /// then the measured one, row by row.
    #[default]
    Auto,
    /// The header's nominal `vin` (BAM's assumption).
    Nominal,
    /// The log's measured `input_volts` at each row (the nominal where a row has none).
    Measured,
}

impl Supply {
    /// Whether `log` is replayed on its measured supply.
    pub fn measured_for(self, log: &BenchLog) -> bool {
        match self {
            Supply::Auto => log.supply_disagrees() == Some(true),
            Supply::Nominal => false,
            Supply::Measured => true,
        }
    }
}

/// How to replay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReplayOptions {
    pub step: Step,
    /// Exact steps per log row.
    pub substeps: usize,
    pub supply: Supply,
    /// Every this many rows the simulation restarts from the measured state (None: never, BAM's
    /// metric): short windows make a smoother loss for a fit's first stage.
    pub reset_rows: Option<usize>,
    /// g on the bench, m/s² (BAM's 9.80665).
    pub gravity: f64,
}

impl Default for ReplayOptions {
    fn default() -> Self {
        Self { step: Step::Bam, substeps: 5, supply: Supply::Auto, reset_rows: None, gravity: super::pendulum::GRAVITY }
    }
}

/// The simulated bench at every log row (before the row's step: row 0 is the measured start).
#[derive(Clone, Debug, Default)]
pub struct Rollout {
    pub position: Vec<f64>,
    pub speed: Vec<f64>,
    /// The firmware's duty over the row.
    pub duty: Vec<f64>,
    /// The motor's current and torque at the row's start.
    pub current: Vec<f64>,
    pub torque: Vec<f64>,
    /// The supply at the servo, V.
    pub supply: Vec<f64>,
}

impl Rollout {
    /// Mean absolute error of the position against the log's, rad, over every row (BAM's metric).
    pub fn mae(&self, log: &BenchLog) -> f64 {
        mean_abs(self.position.iter().zip(&log.entries).map(|(s, e)| s - e.position))
    }
}

fn mean_abs(errors: impl Iterator<Item = f64>) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for e in errors {
        sum += e.abs();
        n += 1;
    }
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// The servo and bench of one log.
struct Bench {
    servo: BusServo,
    pendulum: Pendulum,
    q_offset: f64,
    inertia: f64,
    measured_supply: bool,
}

impl Bench {
    fn new(log: &BenchLog, params: &ServoParams, options: &ReplayOptions) -> Self {
        let servo = BusServo::from_params(&log.actuator, params, log.kp, log.vin);
        let pendulum = Pendulum::from_log(log, options.gravity);
        Self { inertia: pendulum.inertia() + params.armature, servo, pendulum, q_offset: params.q_offset, measured_supply: options.supply.measured_for(log) }
    }

    fn supply(&self, log: &BenchLog, row: usize) -> f64 {
        if self.measured_supply { log.entries[row].volts.unwrap_or(log.vin) } else { log.vin }
    }
}

/// Replay `log` with the servo of `params`; `record` gets each row's state before its step, and
/// stops the replay by returning false.
fn replay(log: &BenchLog, params: &ServoParams, options: &ReplayOptions, mut record: impl FnMut(usize, f64, f64, &crate::actuator::bus_servo::ServoOutput) -> bool) {
    let bench = Bench::new(log, params, options);
    let dt = log.dt;
    let first = &log.entries[0];
    let (mut q, mut v) = (first.position, first.speed);
    // a Feetech's internal target starts at 0 when a log is loaded (BAM's feetech/actuator.py)
    let mut firmware = FirmwareState::default();
    let friction = &bench.servo.friction;
    let delay_rows = params.command_delay / dt;
    // J/Δt, the stopping torque's factor (BAM's order: (J/Δt)·q̇)
    let inertia_per_row = bench.inertia / dt;
    // rows until the next reset to the measured state (counted down: no division on every row)
    let reset_every = options.reset_rows.filter(|&n| n > 0).unwrap_or(usize::MAX);
    let mut until_reset = reset_every;
    for (row, entry) in log.entries.iter().enumerate() {
        if until_reset == 0 {
            (q, v) = (entry.position, entry.speed);
            until_reset = reset_every;
        }
        until_reset -= 1;
        let supply = bench.supply(log, row);
        let (goal, enabled) = delayed_command(log, row, delay_rows);
        match options.step {
            Step::Bam => {
                let out = bench.servo.tick(&mut firmware, goal, q, v, dt, supply, enabled);
                if !record(row, q, v, &out) {
                    return;
                }
                let external = bench.pendulum.gravity_torque(q + bench.q_offset);
                let budget = friction.budget(out.torque, external, v) + friction.viscous * v.abs();
                let net = out.torque + external;
                let stop = inertia_per_row * v + net;
                let friction_torque = -sign(stop) * stop.abs().min(budget);
                let acceleration = (net + friction_torque) / bench.inertia;
                v = (v + acceleration * dt).clamp(-100.0, 100.0);
                q += v * dt + 0.5 * acceleration * dt * dt;
            }
            Step::Exact => {
                let h = dt / options.substeps as f64;
                for s in 0..options.substeps {
                    let out = bench.servo.tick(&mut firmware, goal, q, v, h, supply, enabled);
                    if s == 0 && !record(row, q, v, &out) {
                        return;
                    }
                    let external = bench.pendulum.gravity_torque(q + bench.q_offset);
                    let band = h * friction.budget(out.torque, external, v);
                    // (J + h·K_v)·v' = J·v + h·(τ_m + τ_e) + h·τ_f, |τ_f| ≤ B, τ_f against v'
                    let impulse = bench.inertia * v + h * (out.torque + external);
                    v = if impulse.abs() <= band { 0.0 } else { (impulse - sign(impulse) * band) / (bench.inertia + h * friction.viscous) };
                    q += h * v;
                }
            }
        }
    }
}

/// The goal and torque enable the firmware acts on at `row`: those sent `delay_rows` rows before
/// (the goal interpolated between rows; before the log's first row, its first).
fn delayed_command(log: &BenchLog, row: usize, delay_rows: f64) -> (f64, bool) {
    let entries = &log.entries;
    if delay_rows == 0.0 {
        return (entries[row].goal, entries[row].enabled);
    }
    let at = row as f64 - delay_rows;
    if at <= 0.0 {
        return (entries[0].goal, entries[0].enabled);
    }
    // (at > 0: truncation is the floor, without libm's call on every row)
    let i = at as usize;
    let w = at - i as f64;
    let next = &entries[(i + 1).min(row)];
    let goal = entries[i].goal + w * (next.goal - entries[i].goal);
    (goal, if w < 0.5 { entries[i].enabled } else { next.enabled })
}

/// The whole rollout.
pub fn rollout(log: &BenchLog, params: &ServoParams, options: &ReplayOptions) -> Rollout {
    let n = log.entries.len();
    let mut out = Rollout { position: Vec::with_capacity(n), speed: Vec::with_capacity(n), duty: Vec::with_capacity(n), current: Vec::with_capacity(n), torque: Vec::with_capacity(n), supply: Vec::with_capacity(n) };
    replay(log, params, options, |_, q, v, servo| {
        out.position.push(q);
        out.speed.push(v);
        out.duty.push(servo.duty);
        out.current.push(servo.current);
        out.torque.push(servo.torque);
        out.supply.push(servo.supply);
        true
    });
    out
}

/// The position MAE alone, without keeping the rollout (for identification).
pub fn mae(log: &BenchLog, params: &ServoParams, options: &ReplayOptions) -> f64 {
    mae_within(log, params, options, f64::INFINITY)
}

/// The position MAE, the replay stopped as soon as it exceeds `limit` (rad): then the MAE so far,
/// above `limit` and below the whole replay's (every row adds to the sum), is returned.
pub fn mae_within(log: &BenchLog, params: &ServoParams, options: &ReplayOptions, limit: f64) -> f64 {
    let rows = log.entries.len() as f64;
    let budget = limit * rows;
    let mut sum = 0.0;
    replay(log, params, options, |row, q, _, _| {
        sum += (q - log.entries[row].position).abs();
        sum <= budget
    });
    sum / rows
}
