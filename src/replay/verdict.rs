//! Each joint's needed torque held against what its motor gives: the servo's or motor's torque at
//! that speed through its gearbox (with `--motors`), else the URDF's effort limit; when it was over,
//! by how much, for how long; the RMS against the continuous rating; the winding's temperature.

use super::inverse::Motion;
use crate::actuator::MotorSet;
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
pub fn judge(model: &Model, motors: Option<&MotorSet>, motion: &Motion, available: &[Vec<f64>]) -> Vec<JointVerdict> {
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
            }
        })
        .collect()
}
