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
///
/// A long motion is walked in two halves at once (each sample is worked out on its own, and the
/// peaks of the halves are the peaks of the whole): a run's plots need it before the run starts,
/// while the second core has nothing else to do.
pub fn need(model: &Model, trajectory: &dyn Trajectory, duration: f64, dt: f64, limit: &(dyn Fn(usize, f64, f64) -> f64 + Sync)) -> (Vec<f64>, Vec<f64>) {
    const HALVED_FROM: usize = 2000;
    let n = model.dof();
    let walk = |samples: std::ops::Range<usize>| {
        let (mut peak, mut demand) = (vec![0.0f64; n], vec![0.0f64; n]);
        walk_commanded_motion(model, trajectory, duration, dt, samples, |_, qd, _, tau| {
            for j in 0..n {
                let torque = tau[j].abs();
                peak[j] = peak[j].max(torque);
                let available = limit(j, tau[j], qd[j]);
                demand[j] = demand[j].max(if available > 0.0 { torque / available } else if torque > 0.0 { f64::INFINITY } else { 0.0 });
            }
        });
        (peak, demand)
    };
    let samples = commanded_samples(duration, dt);
    if samples < HALVED_FROM {
        return walk(0..samples);
    }
    let ((mut peak, mut demand), (second_peak, second_demand)) = rayon::join(|| walk(0..samples / 2), || walk(samples / 2..samples));
    for j in 0..n {
        peak[j] = peak[j].max(second_peak[j]);
        demand[j] = demand[j].max(second_demand[j]);
    }
    (peak, demand)
}

/// How many samples [`along_commanded_motion`] visits: t = k·dt for k = 0 ..= ⌈duration / dt⌉.
fn commanded_samples(duration: f64, dt: f64) -> usize {
    (duration / dt).ceil() as usize + 1
}

/// Walk the commanded motion every `dt` from 0 to `duration`: `visit(t, q̇, q̈, τ)` with τ the
/// inverse dynamics of following it exactly (RNEA plus the joints' damping and Coulomb friction) — what a perfect
/// controller must supply. q̈ is the central difference of the commanded velocity, one-sided at the
/// ends: a command that starts (or stops) moving at full speed steps its velocity there, which no
/// drive follows and no drive is sized for (the controller or step generator ramps it).
pub fn along_commanded_motion(model: &Model, trajectory: &dyn Trajectory, duration: f64, dt: f64, visit: impl FnMut(f64, &[f64], &[f64], &[f64])) {
    walk_commanded_motion(model, trajectory, duration, dt, 0..commanded_samples(duration, dt), visit);
}

/// [`along_commanded_motion`] over the samples k in `samples` only.
fn walk_commanded_motion(model: &Model, trajectory: &dyn Trajectory, duration: f64, dt: f64, samples: std::ops::Range<usize>, mut visit: impl FnMut(f64, &[f64], &[f64], &[f64])) {
    let n = model.dof();
    let mut data = Data::new(model);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut qd_after, mut qd_before, mut torque) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let eps = 1e-5;
    let steps = commanded_samples(duration, dt) - 1;
    for k in samples {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::trajectory::Wave;

    /// A long motion walked in two halves at once has the peaks of one walk over every sample, to
    /// the last bit (the tutorial's wave on the box model, 30 s every 1.5 ms as the recordings' torque
    /// plots sample it; the limit taken as 1 + |q̇| so that the demand differs from the peak).
    #[test]
    fn a_motion_walked_in_halves_has_the_peaks_of_one_walk() {
        let model = crate::model::load_urdf_str(crate::builtin::builtin(std::path::Path::new(crate::builtin::DEFAULT_URDF)).unwrap(), std::path::Path::new("box.urdf")).unwrap();
        let wave = Wave { amplitude_rad: 30f64.to_radians(), omega: 0.5 };
        let limit = |_: usize, _: f64, qd: f64| 1.0 + qd.abs();
        let (duration, dt) = (30.0, 0.0015);
        assert!(commanded_samples(duration, dt) >= 2 * 2000, "long enough to be halved");
        let (peak, demand) = need(&model, &wave, duration, dt, &limit);
        let n = model.dof();
        let (mut one_peak, mut one_demand) = (vec![0.0f64; n], vec![0.0f64; n]);
        along_commanded_motion(&model, &wave, duration, dt, |_, qd, _, tau| {
            for j in 0..n {
                one_peak[j] = one_peak[j].max(tau[j].abs());
                one_demand[j] = one_demand[j].max(tau[j].abs() / limit(j, tau[j], qd[j]));
            }
        });
        assert_eq!(peak.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), one_peak.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
        assert_eq!(demand.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), one_demand.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
        assert!(peak[1] > 1.0, "the shoulder carries the arm: {peak:?}");
    }
}
