//! The default experiment fitted to what the arm's own motors give (its URDF's effort limits), as
//! the default wave is fitted to its joint ranges: a start pose they can hold, a wave they can
//! carry. Baxter's and PR2's URDFs leave out the springs that carry their real arms: at each
//! joint's 0 (arm out) the shoulders need 56 N·m of 50 and 52 of 30, and a default run would only
//! show the arm falling. Asked for explicitly (`--q0`, `--amp-deg`, `--freq`) the experiment is run
//! as asked, with a notice where the motors fall short.

use super::demand::required_torque;
use crate::dynamics::{Data, gravity_forces, gravity_stiffness};
use crate::model::{JointKind, Model};
use nalgebra::{DMatrix, DVector};

use super::trajectory::JointWave;

/// The default start pose leaves this share of each joint's effort unused by the weight, for the
/// wave's motion (and its weight at the far ends of the swing).
pub const START_LOAD: f64 = 0.6;
/// The default wave needs at most this share of each joint's effort (inverse dynamics of the
/// commanded motion plus damping); the rest is the controller's, to correct errors.
pub const MOTION_LOAD: f64 = 0.8;

/// The joints whose effort limits the default experiment respects: driven, with a finite effort.
fn limits(model: &Model) -> Vec<Option<f64>> {
    model.effort_limits().into_iter().enumerate().map(|(j, e)| (model.is_actuated(j) && e > 0.0 && e.is_finite()).then_some(e)).collect()
}

/// The driven joints whose weight at `pose` takes more than `load` of their effort: (joint, |τ_g|, effort).
pub fn overloaded_by_weight(model: &Model, pose: &[f64], load: f64) -> Vec<(usize, f64, f64)> {
    let tau_g = gravity_forces(model, &mut Data::new(model), pose).to_vec();
    limits(model).into_iter().enumerate().filter_map(|(j, e)| e.filter(|&e| tau_g[j].abs() > load * e).map(|e| (j, tau_g[j].abs(), e))).collect()
}

/// A pose near `pose`, within the joint ranges, at which the weight takes at most `load` of each
/// driven joint's effort: Gauss–Newton steps of least norm on the overloaded joints' gravity
/// torques (each aimed a little inside the bound), from `pose`. None if it finds none (a joint
/// whose load does not change with the pose: a lift carrying more than its motor).
pub fn holdable_pose(model: &Model, pose: &[f64], load: f64) -> Option<Vec<f64>> {
    let n = model.dof();
    let limit = limits(model);
    let mut data = Data::new(model);
    let mut q = pose.to_vec();
    let aim = 0.95 * load;
    for _ in 0..200 {
        let tau_g = gravity_forces(model, &mut data, &q).to_vec();
        let over: Vec<usize> = (0..n).filter(|&j| limit[j].is_some_and(|e| tau_g[j].abs() > load * e)).collect();
        if over.is_empty() {
            return Some(back_where_not_needed(model, pose, q, load));
        }
        // ∂τ_g/∂q of the overloaded joints
        let all = gravity_stiffness(model, &mut data, &q);
        let stiffness = DMatrix::from_fn(over.len(), n, |r, c| all[(over[r], c)]);
        let residual = DVector::from_iterator(over.len(), over.iter().map(|&j| tau_g[j] - tau_g[j].signum() * aim * limit[j].unwrap_or(0.0)));
        // a joint at the end of its range does not move further out: solve without it
        let mut free = vec![true; n];
        let mut step = DVector::zeros(n);
        for _ in 0..2 {
            let k = DMatrix::from_fn(over.len(), n, |r, c| if free[c] { stiffness[(r, c)] } else { 0.0 });
            let kkt = &k * k.transpose();
            let regular = 1e-12 * kkt.trace().max(f64::MIN_POSITIVE);
            let Some(solved) = (kkt + DMatrix::identity(over.len(), over.len()) * regular).cholesky() else { return None };
            step = -(k.transpose() * solved.solve(&residual));
            let mut pinned = false;
            for c in 0..n {
                let j = &model.joints[c];
                if free[c] && ((q[c] <= j.lower && step[c] < 0.0) || (q[c] >= j.upper && step[c] > 0.0)) {
                    free[c] = false;
                    pinned = true;
                }
            }
            if !pinned {
                break;
            }
        }
        // Newton's step on a cosine overshoots from far away: at most a quarter radian (5 cm) a go
        let largest = (0..n)
            .map(|c| step[c].abs() / if model.joints[c].kind == JointKind::Prismatic { 0.05 } else { 0.25 })
            .fold(0.0, f64::max);
        if !largest.is_finite() {
            return None;
        }
        if largest < 1e-3 {
            // at the top of a load (an arm straight out: its weight's torque is largest there and
            // flat), the gradient says nothing: step the joint that sheds the most load
            q = shed_load_by_one_joint(model, &q, load)?;
            continue;
        }
        let shrink = largest.max(1.0);
        for c in 0..n {
            q[c] = (q[c] + step[c] / shrink).clamp(model.joints[c].lower, model.joints[c].upper);
        }
    }
    None
}

/// The pose one joint's step of a tenth of a radian (a centimetre) away that most lowers the load
/// beyond the bound, if any does.
fn shed_load_by_one_joint(model: &Model, q: &[f64], load: f64) -> Option<Vec<f64>> {
    let excess = |pose: &[f64]| overloaded_by_weight(model, pose, load).iter().map(|&(_, tau, e)| tau - load * e).sum::<f64>();
    let now = excess(q);
    let mut best: Option<(f64, Vec<f64>)> = None;
    for c in 0..model.dof() {
        let joint = &model.joints[c];
        let step = if joint.kind == JointKind::Prismatic { 0.01 } else { 0.1 };
        for direction in [1.0, -1.0] {
            let mut probe = q.to_vec();
            probe[c] = (q[c] + direction * step).clamp(joint.lower, joint.upper);
            let e = excess(&probe);
            if e < now - 1e-12 && best.as_ref().is_none_or(|(b, _)| e < *b) {
                best = Some((e, probe));
            }
        }
    }
    best.map(|(_, pose)| pose)
}

/// The least-norm steps move every joint that touches the load a little (a gripper finger, a
/// wrist): put back, smallest move first, each joint the held pose does not need moved.
fn back_where_not_needed(model: &Model, pose: &[f64], mut held: Vec<f64>, load: f64) -> Vec<f64> {
    let mut moved: Vec<usize> = (0..model.dof()).filter(|&j| held[j] != pose[j]).collect();
    moved.sort_by(|&a, &b| (held[a] - pose[a]).abs().total_cmp(&(held[b] - pose[b]).abs()));
    for j in moved {
        let kept = held[j];
        held[j] = pose[j];
        if !overloaded_by_weight(model, &held, load).is_empty() {
            held[j] = kept;
        }
    }
    held
}

/// The largest share s ≤ 1 of the wanted amplitude (`amplitude_deg`) for which the fitted wave at
/// `omega` around `start` needs at most `load` of each driven joint's effort along one period
/// (bisection: the need grows with the amplitude). Returns the wave, s, and at full size the joint
/// that needed the most of its effort (joint, torque, effort) when s < 1.
pub fn carried_wave(model: &Model, start: &[f64], amplitude_deg: f64, omega: f64, load: f64) -> (JointWave, f64, Option<(usize, f64, f64)>) {
    let limit = limits(model);
    let wave_at = |share: f64| JointWave::fitted(model, start, amplitude_deg * share, omega);
    let full = wave_at(1.0);
    // one period, 96 samples (a wave slower than 1/10 Hz: its first 10 s)
    let period = super::trajectory::Trajectory::period(&full).unwrap_or(10.0).min(10.0);
    let worst = |wave: &JointWave| -> Option<(usize, f64, f64, f64)> {
        let peak = required_torque(model, wave, period, period / 96.0);
        (0..model.dof()).filter_map(|j| limit[j].map(|e| (j, peak[j], e, peak[j] / e))).max_by(|a, b| a.3.total_cmp(&b.3))
    };
    let Some((joint, torque, effort, share)) = worst(&full) else { return (full, 1.0, None) };
    if share <= load {
        return (full, 1.0, None);
    }
    // standing still at the start must fit, or no amplitude does
    if worst(&wave_at(0.0)).is_some_and(|w| w.3 > load) {
        return (full, 1.0, None);
    }
    let (mut fits, mut too_big) = (0.0, 1.0);
    for _ in 0..20 {
        let mid = 0.5 * (fits + too_big);
        if worst(&wave_at(mid)).is_some_and(|w| w.3 > load) { too_big = mid } else { fits = mid }
    }
    (wave_at(fits), fits, Some((joint, torque, effort)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::load_urdf_str;

    /// A pendulum: 1 kg at 1 m on a horizontal axis, its weight 9.81·cos(q) N·m, a 10 N·m motor.
    fn pendulum(effort: f64) -> Model {
        pendulum_in(effort, 3.0)
    }

    fn pendulum_in(effort: f64, range: f64) -> Model {
        let urdf = format!(
            r#"<robot name="p"><link name="world"/><link name="arm"><inertial><origin xyz="1 0 0"/><mass value="1"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
<joint name="swing" type="revolute"><parent link="world"/><child link="arm"/><axis xyz="0 1 0"/><limit lower="-{range}" upper="{range}" effort="{effort}" velocity="5"/></joint></robot>"#
        );
        load_urdf_str(&urdf, std::path::Path::new("pendulum.urdf")).unwrap()
    }

    #[test]
    fn the_held_pose_is_the_nearest_within_the_load_not_far_past_it() {
        let model = pendulum(10.0);
        assert_eq!(overloaded_by_weight(&model, &[0.0], START_LOAD).len(), 1, "9.81 of 10 N·m at 0");
        let q = holdable_pose(&model, &[0.0], START_LOAD).unwrap()[0];
        // the nearest such pose: 9.81·cos q = 6, |q| = 0.913 rad; aimed a little inside (95 %), so
        // the weight there takes between 90 and 100 % of the 6 N·m allowed
        let nearest = (START_LOAD * 10.0 / 9.81f64).acos();
        let weight = 9.81 * q.cos();
        assert!(q.abs() >= nearest - 1e-9 && weight >= 0.9 * START_LOAD * 10.0, "q = {q} (nearest {nearest}), weight {weight} N·m");
        // a motor that holds the arm anywhere: nothing moves
        assert!(overloaded_by_weight(&pendulum(100.0), &[0.0], START_LOAD).is_empty());
        // a weak motor holds it hanging (q = ±π/2 is in the range) ...
        let hanging = holdable_pose(&pendulum(0.1), &[0.0], START_LOAD).unwrap()[0];
        assert!(9.81 * hanging.cos() <= START_LOAD * 0.1 && hanging.abs() < std::f64::consts::FRAC_PI_2, "{hanging}");
        // ... and nowhere when the range stops it 0.5 rad short of that (8.6 N·m there)
        assert!(holdable_pose(&pendulum_in(1.0, 0.5), &[0.0], START_LOAD).is_none());
    }

    #[test]
    fn the_carried_wave_is_the_largest_that_needs_at_most_the_load() {
        let model = pendulum(10.0);
        let start = holdable_pose(&model, &[0.0], START_LOAD).unwrap();
        let (wave, share, worst) = carried_wave(&model, &start, 30.0, 0.5, MOTION_LOAD);
        assert!(share < 1.0 && worst.is_some_and(|(j, tau, e)| j == 0 && tau > MOTION_LOAD * e), "{share} {worst:?}");
        let peak = |w: &JointWave| required_torque(&model, w, 4.0 * std::f64::consts::PI, 0.005)[0];
        assert!(peak(&wave) <= MOTION_LOAD * 10.0 + 1e-3, "needs {}", peak(&wave));
        // 2 % larger needs more than the load: the largest that fits
        assert!(peak(&JointWave::fitted(&model, &start, 30.0 * share * 1.02, 0.5)) > MOTION_LOAD * 10.0);
        // a wave the motor carries whole is not touched
        assert_eq!(carried_wave(&pendulum(100.0), &[0.0], 30.0, 0.5, MOTION_LOAD).1, 1.0);
    }
}
