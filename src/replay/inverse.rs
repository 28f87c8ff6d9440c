//! Inverse replay: a recorded episode's positions → smoothed q, q̇, q̈ → the torque each joint
//! needed (RNEA on the model with its payload and the motors' reflected inertia, plus the URDF's
//! joint damping and sliding friction).

use super::past_limits::{PastLimit, follow_to_limits, range_of};
use super::smoothing::{Smoothed, Smoother};
use crate::dynamics::{Data, rnea};
use crate::error::Error;
use crate::model::Model;
use crate::motion::{Episode, JointMap};

/// How one joint's samples were smoothed (None for a joint the map leaves out, held still).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct SmoothingInfo {
    /// The samples' noise, rad (m): their quantum δ/√12 where they lie on one.
    pub noise: f64,
    pub quantum: Option<f64>,
    pub lambda: f64,
    /// Where the smoother passes half the amplitude, Hz.
    pub cutoff_hz: f64,
}

/// An episode's motion and the torques it took, per coordinate (the model's joint order).
#[derive(Clone, Debug)]
pub struct Motion {
    pub label: String,
    pub time: Vec<f64>,
    pub q: Vec<Vec<f64>>,
    pub qd: Vec<Vec<f64>>,
    pub qdd: Vec<Vec<f64>>,
    /// The torque (force) each joint needed, N·m (N).
    pub needed: Vec<Vec<f64>>,
    /// Per coordinate, the recorded positions in it (before smoothing; None where the map leaves the
    /// joint out).
    pub recorded: Vec<Option<Vec<f64>>>,
    /// Per coordinate, the recording's measured effort where it has one (a ROS 2 bag's `effort`).
    pub measured: Vec<Option<Vec<f64>>>,
    pub smoothing: Vec<Option<SmoothingInfo>>,
    pub notices: Vec<String>,
    /// Where the recorded positions passed a joint's URDF limit (followed to it): said once for the
    /// whole recording ([`super::past_limits::notice`]).
    pub past_limits: Vec<PastLimit>,
}

impl Motion {
    pub fn len(&self) -> usize {
        self.time.len()
    }

    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Joint `j`'s recorded position at sample `k`, or its smoothed one where it has none.
    pub fn recorded_or_smoothed(&self, j: usize, k: usize) -> f64 {
        self.recorded[j].as_ref().map_or(self.q[j][k], |r| r[k])
    }
}

/// The fewest samples a motion can be differentiated from (the derivative stencils' width).
pub const MIN_SAMPLES: usize = 5;

/// An episode's positions per coordinate of the model (None where the map leaves the joint out),
/// followed to each joint's limit where they pass it (and by how far) — as recorded, before
/// smoothing.
pub fn mapped_positions(model: &Model, map: &JointMap, episode: &Episode) -> Result<(Vec<Option<Vec<f64>>>, Vec<PastLimit>), Error> {
    follow_to_limits(model, episode, map.apply(model, episode)?)
}

/// Smooth an episode mapped onto the model's coordinates and work out the torques it needed.
/// Joints the map leaves out are held at their start pose `hold` (zero speed).
pub fn inverse_replay(model: &Model, map: &JointMap, episode: &Episode, hold: &[f64]) -> Result<Motion, Error> {
    let n = model.dof();
    let samples = episode.time.len();
    if samples < MIN_SAMPLES {
        return Err(Error::flag(episode.label.clone(), format!("{samples} samples: a replay needs at least {MIN_SAMPLES}")));
    }
    let mut notices = episode.notices.clone();
    let (mapped, past_limits) = mapped_positions(model, map, episode)?;
    let mut smoother = Smoother::new(&episode.time);
    let mut q = Vec::with_capacity(n);
    let mut qd = Vec::with_capacity(n);
    let mut qdd = Vec::with_capacity(n);
    let mut smoothing = Vec::with_capacity(n);
    let mut held = Vec::new();
    for (j, series) in mapped.iter().enumerate() {
        match series {
            Some(values) => {
                if let Some((k, _)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                    return Err(Error::flag(episode.label.clone(), format!("joint '{}': value at sample {k} ({} s) is not a number", model.joints[j].name, episode.time[k])));
                }
                let Smoothed { q: mut sq, qd: sqd, qdd: sqdd, noise, quantum, lambda, cutoff_hz } = smoother.smooth(values);
                // the smoothing may overshoot a limit the values were followed to
                let (lower, upper) = range_of(model, j);
                sq.iter_mut().for_each(|x| *x = x.clamp(lower, upper));
                q.push(sq);
                qd.push(sqd);
                qdd.push(sqdd);
                smoothing.push(Some(SmoothingInfo { noise, quantum, lambda, cutoff_hz }));
            }
            None => {
                held.push(model.joints[j].name.clone());
                q.push(vec![hold[j]; samples]);
                qd.push(vec![0.0; samples]);
                qdd.push(vec![0.0; samples]);
                smoothing.push(None);
            }
        }
    }
    if !held.is_empty() {
        notices.push(format!("{}: not in the joint map, held still at the start pose: {}", episode.label, held.join(", ")));
    }
    let needed = needed_torques(model, &q, &qd, &qdd);
    let measured = model.joints.iter().map(|j| episode.effort.iter().find(|c| c.name == j.name).map(|c| c.values.clone())).collect();
    Ok(Motion { label: episode.label.clone(), time: episode.time.clone(), q, qd, qdd, needed, recorded: mapped, measured, smoothing, notices, past_limits })
}

/// Per coordinate, the torque needed at every sample: RNEA(q, q̇, q̈) + D·q̇ + F·sign(q̇) (friction
/// only while the joint slides: at rest it holds whatever it can, and the motor is asked for all).
pub fn needed_torques(model: &Model, q: &[Vec<f64>], qd: &[Vec<f64>], qdd: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = model.dof();
    let samples = q.first().map_or(0, Vec::len);
    let mut data = Data::new(model);
    let mut needed = vec![vec![0.0; samples]; n];
    let (mut qk, mut vk, mut ak) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for k in 0..samples {
        for j in 0..n {
            qk[j] = q[j][k];
            vk[j] = qd[j][k];
            ak[j] = qdd[j][k];
        }
        let tau = rnea(model, &mut data, &qk, &vk, &ak);
        for (j, joint) in model.joints.iter().enumerate() {
            let sliding = if vk[j].abs() > SLIDING_SPEED { joint.friction * vk[j].signum() } else { 0.0 };
            needed[j][k] = tau[j] + joint.damping * vk[j] + sliding;
        }
    }
    needed
}

/// Below this joint speed (rad/s) a smoothed joint counts as at rest for its Coulomb friction: a
/// quantized encoder's smoothed speed hovers within about this of zero while the joint stands.
pub const SLIDING_SPEED: f64 = 1e-3;
