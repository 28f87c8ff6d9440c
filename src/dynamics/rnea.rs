use super::{Data, forward_kinematics};
use crate::model::Model;
use crate::spatial::{cross_force, cross_motion, spatial};
use nalgebra::{Vector3, Vector6};

/// The spatial acceleration of the world that stands in for gravity (a₀ = −g).
#[inline]
pub(crate) fn base_acceleration(model: &Model) -> Vector6<f64> {
    spatial(Vector3::zeros(), -model.gravity)
}

/// Inverse dynamics: τ = M(q) q̈ + C(q,q̇) q̇ − τ_g(q), into `data.tau` (M with the motors'
/// reflected inertias).
pub fn rnea<'d>(model: &Model, data: &'d mut Data, q: &[f64], v: &[f64], a: &[f64]) -> &'d [f64] {
    forward_kinematics(model, data, q);
    rnea_from_kinematics(model, data, v, a);
    &data.tau
}

/// RNEA assuming `forward_kinematics` was run for the current q.
pub fn rnea_from_kinematics(model: &Model, data: &mut Data, v: &[f64], a: &[f64]) {
    let a0 = base_acceleration(model);
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate() {
        let s = data.motion_subspace[i];
        let (v_parent, a_parent) = match joint.parent {
            Some(p) => (data.velocity[p], data.acceleration[p]),
            None => (Vector6::zeros(), a0),
        };
        let c = coupling.coordinate;
        let vel = v_parent + s * v[c];
        let acc = a_parent + s * a[c] + cross_motion(&vel, &(s * v[c]));
        let inertia = &data.body_inertia[i];
        data.force[i] = inertia.mul_motion(&acc) + cross_force(&vel, &inertia.mul_motion(&vel));
        data.velocity[i] = vel;
        data.acceleration[i] = acc;
    }
    data.tau.fill(0.0);
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate().rev() {
        data.tau[coupling.coordinate] += data.motion_subspace[i].dot(&data.force[i]);
        if let Some(p) = joint.parent {
            let f = data.force[i];
            data.force[p] += f;
        }
    }
    // the motors' rotors: J_r·N²·q̈ (as in CRBA and ABA)
    for (c, armature) in model.armature.iter().enumerate() {
        data.tau[c] += armature * a[c];
    }
}

/// τ_g(q) into `data.gravity` and C(q,q̇)q̇ into `data.bias`, in one pass, assuming
/// `forward_kinematics` was run for the current q.
pub fn gravity_and_bias_from_kinematics(model: &Model, data: &mut Data, v: &[f64]) {
    // With q̈ = 0 and no gravity RNEA gives C q̇; gravity alone accelerates every body by −a₀.
    let g = model.gravity;
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate() {
        let s = data.motion_subspace[i];
        let (v_parent, a_parent) = match joint.parent {
            Some(p) => (data.velocity[p], data.acceleration[p]),
            None => (Vector6::zeros(), Vector6::zeros()),
        };
        let joint_velocity = s * v[coupling.coordinate];
        let vel = v_parent + joint_velocity;
        let acc = a_parent + cross_motion(&vel, &joint_velocity);
        let inertia = &data.body_inertia[i];
        let momentum = inertia.mul_motion(&vel);
        data.force[i] = inertia.mul_motion(&acc) + cross_force(&vel, &momentum);
        data.gravity_force[i] = inertia.mul_linear(&g);
        data.momentum[i] = momentum;
        data.velocity[i] = vel;
        data.acceleration[i] = acc;
    }
    data.bias.fill(0.0);
    data.gravity.fill(0.0);
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate().rev() {
        let s = data.motion_subspace[i];
        data.bias[coupling.coordinate] += s.dot(&data.force[i]);
        data.gravity[coupling.coordinate] += s.dot(&data.gravity_force[i]);
        if let Some(p) = joint.parent {
            let (f, fg) = (data.force[i], data.gravity_force[i]);
            data.force[p] += f;
            data.gravity_force[p] += fg;
        }
    }
}

/// τ_g(q), the generalized force gravity applies (Drake's CalcGravityGeneralizedForces).
pub fn gravity_forces<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d [f64] {
    forward_kinematics(model, data, q);
    gravity_from_kinematics(model, data);
    &data.gravity
}

/// τ_g into `data.gravity`, assuming `forward_kinematics` was run for the current q.
pub fn gravity_from_kinematics(model: &Model, data: &mut Data) {
    let g = model.gravity;
    for i in 0..model.bodies.len() {
        data.gravity_force[i] = data.body_inertia[i].mul_linear(&g);
    }
    data.gravity.fill(0.0);
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate().rev() {
        data.gravity[coupling.coordinate] += data.motion_subspace[i].dot(&data.gravity_force[i]);
        if let Some(p) = joint.parent {
            let fg = data.gravity_force[i];
            data.gravity_force[p] += fg;
        }
    }
}

/// C(q, q̇)·q̇ (Drake's CalcBiasTerm: no gravity, no damping).
pub fn bias_forces<'d>(model: &Model, data: &'d mut Data, q: &[f64], v: &[f64]) -> &'d [f64] {
    forward_kinematics(model, data, q);
    gravity_and_bias_from_kinematics(model, data, v);
    &data.bias
}
