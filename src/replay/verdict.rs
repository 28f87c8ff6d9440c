//! Each joint's needed torque held against what its motor gives: the servo's or motor's torque at
//! that speed through its gearbox (with `--motors`), else the URDF's effort limit; when it was over,
//! by how much, for how long; the RMS against the continuous rating; the winding's temperature;
//! for a serial-bus servo, the duty and current it takes and the firmware protection it trips (from
//! then on it has what the protection leaves it).

use super::inverse::Motion;
use crate::actuator::MotorSet;
use crate::actuator::bus_servo::Trip;
use crate::actuator::thermal::{RunHeat, WindingSummary};
use crate::model::Model;
use serde::Serialize;

/// A stretch of samples where a joint needed more than it had.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Interval {
    /// Time of its first and last sample over, s.
    pub start: f64,
    pub end: f64,
    /// Its first and last sample.
    pub first: usize,
    pub last: usize,
    /// The largest shortfall, N·m (N), and the same as a percentage of what the joint had then.
    pub worst_excess: f64,
    pub worst_percent: f64,
    pub worst_time: f64,
}

impl Interval {
    /// How long it lasted, s: from its first sample to its last (a lone sample lasts 0).
    pub fn duration(&self) -> f64 {
        self.end - self.start
    }
}

/// The stretches where |needed[k]| > limit[k].
pub fn intervals_over(time: &[f64], needed: &[f64], limit: &[f64]) -> Vec<Interval> {
    let mut out: Vec<Interval> = Vec::new();
    let mut open: Option<Interval> = None;
    for k in 0..time.len() {
        let excess = needed[k].abs() - limit[k];
        if excess > 0.0 {
            let percent = if limit[k] > 0.0 { 100.0 * excess / limit[k] } else { f64::INFINITY };
            let interval = open.get_or_insert(Interval { start: time[k], end: time[k], first: k, last: k, worst_excess: excess, worst_percent: percent, worst_time: time[k] });
            interval.end = time[k];
            interval.last = k;
            if excess > interval.worst_excess {
                interval.worst_excess = excess;
                interval.worst_percent = percent;
                interval.worst_time = time[k];
            }
        } else if let Some(interval) = open.take() {
            out.push(interval);
        }
    }
    out.extend(open);
    out
}

/// One joint over one episode.
#[derive(Clone, Debug, Serialize)]
pub struct JointVerdict {
    pub joint: String,
    /// What its limit is: "URDF effort", or the motor's name.
    pub limit_source: String,
    /// The largest |torque| needed, N·m, and when.
    pub peak_torque: f64,
    pub peak_time: f64,
    /// What the joint had at that moment, N·m.
    pub limit_at_peak: f64,
    pub rms_torque: f64,
    /// The motor's continuous torque at the joint, N·m, where its catalogue entry gives one.
    pub continuous_torque: Option<f64>,
    pub over: Vec<Interval>,
    /// Total time over its limit, s (samples over × the sample interval).
    pub time_over: f64,
    /// What the motion did to the motor's winding, where its thermal data are known.
    pub winding: Option<WindingSummary>,
    /// A serial-bus servo's duty and current, and the protection it trips.
    pub servo: Option<ServoLoad>,
}

/// What a joint's motion asked of its serial-bus servo: the duty its firmware needed (above 1:
/// more than its PWM has) and the current its motor drew, at the servo.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ServoLoad {
    pub peak_duty: f64,
    pub peak_duty_time: f64,
    pub peak_current: f64,
    pub rms_current: f64,
    /// The first firmware protection the motion trips (a Feetech's overload or overcurrent).
    pub protection_trip: Option<Trip>,
}

/// Per coordinate with a serial-bus servo model: the duty and current the motion asked of it at
/// every sample (the servo's friction included while the joint slides), and the protection that
/// trips.
pub fn servo_loads(model: &Model, motors: Option<&MotorSet>, motion: &Motion) -> Vec<Option<ServoLoad>> {
    (0..model.dof())
        .map(|j| {
            let drive = motors.and_then(|m| m.joints[j].as_ref())?;
            let servo = drive.servo.as_ref()?;
            let mut duty = Vec::with_capacity(motion.len());
            let mut current = Vec::with_capacity(motion.len());
            for (&tau, &speed) in motion.needed[j].iter().zip(&motion.qd[j]) {
                let (d, i) = servo_demand(drive, tau, speed)?;
                duty.push(d);
                current.push(i);
            }
            let (peak_index, peak_duty) = duty.iter().enumerate().fold((0, 0.0_f64), |(bi, b), (i, d)| if d.abs() > b { (i, d.abs()) } else { (bi, b) });
            Some(ServoLoad {
                peak_duty,
                peak_duty_time: motion.time.get(peak_index).copied().unwrap_or(0.0),
                peak_current: current.iter().fold(0.0, |a: f64, c| a.max(c.abs())),
                rms_current: (current.iter().map(|c| c * c).sum::<f64>() / current.len().max(1) as f64).sqrt(),
                protection_trip: servo.firmware.protection.first_trip(&motion.time, &duty, &current),
            })
        })
        .collect()
}

/// The duty (1 = 100 %) and current (A) a joint torque `tau` at joint speed `speed` asks of the
/// joint's servo, its friction included while the joint slides; None without a servo model. Past
/// what full duty gives (its datasheet's line) the firmware's error grows until its duty is full:
/// the load it sees is all its PWM, and more was needed (at least 1).
pub fn servo_demand(drive: &crate::actuator::DriveTrain, tau: f64, speed: f64) -> Option<(f64, f64)> {
    let servo = drive.servo.as_ref()?;
    let (torque, shaft) = drive.servo_torque_for(tau, speed, speed.abs() > super::inverse::SLIDING_SPEED)?;
    let full = servo.drive(servo.firmware.family.max_duty * torque.signum(), shaft, servo.supply, true).torque.abs();
    let needed = servo.duty_for(torque, shaft);
    let duty = if torque.abs() > full { torque.signum() * needed.abs().max(1.0) } else { needed };
    Some((duty, torque / servo.kt))
}

/// From each trip on, what its joint had is what the protection leaves the servo (its
/// protective duty, or nothing with its torque off).
pub fn limit_after_trips(motors: Option<&MotorSet>, motion: &Motion, loads: &[Option<ServoLoad>], available: &mut [Vec<f64>]) {
    for (j, load) in loads.iter().enumerate() {
        let (Some(trip), Some(drive)) = (load.and_then(|l| l.protection_trip), motors.and_then(|m| m.joints[j].as_ref())) else { continue };
        for k in (0..motion.len()).filter(|&k| motion.time[k] >= trip.time) {
            available[j][k] = drive.available_at_duty(motion.needed[j][k], motion.qd[j][k], trip.leaves_duty).min(available[j][k]);
        }
    }
}

/// The largest |needed| / available over a series (1 = exactly at its limit).
pub fn peak_load(needed: &[f64], limit: &[f64]) -> f64 {
    needed.iter().zip(limit).map(|(n, l)| if *l > 0.0 { n.abs() / l } else if n.abs() > 0.0 { f64::INFINITY } else { 0.0 }).fold(0.0, f64::max)
}

/// Per coordinate and sample, the torque the joint could have had in the direction it needed:
/// with a motor, what its drive train gives at that speed; else the URDF's effort (infinite when
/// the URDF gives none).
pub fn available_torques(model: &Model, motors: Option<&MotorSet>, motion: &Motion) -> Vec<Vec<f64>> {
    (0..model.dof())
        .map(|j| match motors.and_then(|m| m.joints[j].as_ref()) {
            Some(drive) => motion.needed[j].iter().zip(&motion.qd[j]).map(|(&tau, &speed)| drive.available(tau, speed)).collect(),
            None => vec![model.joints[j].effort; motion.len()],
        })
        .collect()
}

/// Every joint's verdict over an episode.
pub fn judge(model: &Model, motors: Option<&MotorSet>, motion: &Motion, available: &[Vec<f64>], servos: &[Option<ServoLoad>]) -> Vec<JointVerdict> {
    let samples = motion.len();
    let interval = if samples > 1 { motion.time[samples - 1] / (samples - 1) as f64 } else { 0.0 };
    let mut heat = motors.map(|m| RunHeat::new(&m.heat(), interval)).filter(RunHeat::any);
    if let Some(heat) = heat.as_mut() {
        let mut u = vec![0.0; model.dof()];
        // each sample's torque held over the interval to the next (the last carries none further)
        for k in 0..samples.saturating_sub(1) {
            for (j, value) in u.iter_mut().enumerate() {
                *value = motion.needed[j][k];
            }
            heat.step(&u);
        }
    }
    let windings = heat.map(|h| h.summary());
    (0..model.dof())
        .map(|j| {
            let needed = &motion.needed[j];
            let (peak_index, peak_torque) = needed.iter().enumerate().fold((0, 0.0_f64), |(bi, b), (i, v)| if v.abs() > b { (i, v.abs()) } else { (bi, b) });
            let rms_torque = (needed.iter().map(|v| v * v).sum::<f64>() / samples.max(1) as f64).sqrt();
            let drive = motors.and_then(|m| m.joints[j].as_ref());
            let over = intervals_over(&motion.time, needed, &available[j]);
            let samples_over: usize = over.iter().map(|i| i.last - i.first + 1).sum();
            JointVerdict {
                joint: model.joints[j].name.clone(),
                limit_source: drive.map_or_else(|| "URDF effort".to_string(), |d| d.motor.name().to_string()),
                peak_torque,
                peak_time: motion.time.get(peak_index).copied().unwrap_or(0.0),
                limit_at_peak: available[j].get(peak_index).copied().unwrap_or(f64::INFINITY),
                rms_torque,
                continuous_torque: drive.and_then(|d| d.continuous_torque.map(|c| c * d.gear_ratio * d.efficiency())),
                time_over: samples_over as f64 * interval,
                over,
                winding: windings.as_ref().and_then(|w| w[j]),
                servo: servos.get(j).copied().flatten(),
            }
        })
        .collect()
}
