//! The torque a commanded motion needs: the inverse dynamics of following it exactly (what a
//! perfect controller must supply), used to fit the default experiment to a URDF's motors
//! (`within_effort`), to draw the speed envelope and to size motors. Below the experiment and the
//! simulation loop, which both build on it.

use crate::control::trajectory::Trajectory;
use crate::dynamics::{Data, rnea};
use crate::model::Model;

/// Peak |τ| per joint to follow `trajectory` exactly for `duration` seconds.
pub fn required_torque(model: &Model, trajectory: &dyn Trajectory, duration: f64, dt: f64) -> Vec<f64> {
    need(model, trajectory, duration, dt, &|_, _, _| 1.0).0
}

/// Per joint: the peak |τ| and the largest |τ(t)| / limit(joint, τ(t), q̇(t)) along the exact motion
/// (the limit in the direction of the torque, at the speed).
pub fn need(model: &Model, trajectory: &dyn Trajectory, duration: f64, dt: f64, limit: &dyn Fn(usize, f64, f64) -> f64) -> (Vec<f64>, Vec<f64>) {
    let n = model.dof();
    let (mut peak, mut demand) = (vec![0.0f64; n], vec![0.0f64; n]);
    along_commanded_motion(model, trajectory, duration, dt, |_, qd, _, tau| {
        for j in 0..n {
            let torque = tau[j].abs();
            peak[j] = peak[j].max(torque);
            let available = limit(j, tau[j], qd[j]);
            demand[j] = demand[j].max(if available > 0.0 { torque / available } else if torque > 0.0 { f64::INFINITY } else { 0.0 });
        }
    });
    (peak, demand)
}

/// Walk the commanded motion every `dt` from 0 to `duration`: `visit(t, q̇, q̈, τ)` with τ the
/// inverse dynamics of following it exactly (RNEA plus the joints' damping and Coulomb friction) — what a perfect
/// controller must supply. q̈ is the central difference of the commanded velocity, one-sided at the
/// ends: a command that starts (or stops) moving at full speed steps its velocity there, which no
/// drive follows and no drive is sized for (the controller or step generator ramps it).
pub fn along_commanded_motion(model: &Model, trajectory: &dyn Trajectory, duration: f64, dt: f64, mut visit: impl FnMut(f64, &[f64], &[f64], &[f64])) {
    let n = model.dof();
    let mut data = Data::new(model);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut qd_after, mut qd_before, mut torque) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let eps = 1e-5;
    let steps = (duration / dt).ceil() as usize;
    for k in 0..=steps {
        let t = k as f64 * dt;
        let (before, after) = match k {
            0 => (t + eps, t + 3.0 * eps),
            _ if k == steps => (t - 3.0 * eps, t - eps),
            _ => (t - eps, t + eps),
        };
        trajectory.sample(after, &mut q, &mut qd_after);
        trajectory.sample(before, &mut q, &mut qd_before);
        for j in 0..n {
            qdd[j] = (qd_after[j] - qd_before[j]) / (after - before);
        }
        trajectory.sample(t, &mut q, &mut qd);
        let tau = rnea(model, &mut data, &q, &qd, &qdd);
        for j in 0..n {
            // the joint's Coulomb friction against the motion (at a standstill it takes only what
            // holds the joint, which the motion around it bounds)
            let joint = &model.joints[j];
            let friction = if qd[j] != 0.0 { joint.friction * qd[j].signum() } else { 0.0 };
            torque[j] = tau[j] + joint.damping * qd[j] + friction;
        }
        visit(t, &qd, &qdd, &torque);
    }
}
