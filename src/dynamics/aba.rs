use super::{Data, cholesky_in_place, cholesky_solve_in_place, crba_from_kinematics, forward_kinematics, gravity_and_bias_from_kinematics};
use super::rnea::base_acceleration;
use crate::model::Model;
use crate::spatial::{cross_force, cross_motion};
use nalgebra::Vector6;

/// Forward dynamics q̈ = M⁻¹(τ + τ_g − C q̇) by the articulated-body algorithm, into `data.qdd`.
/// Joint damping is not included: pass τ − D q̇ for it. The motors' reflected inertias are.
pub fn aba<'d>(model: &Model, data: &'d mut Data, q: &[f64], v: &[f64], tau: &[f64]) -> &'d [f64] {
    forward_kinematics(model, data, q);
    aba_from_kinematics(model, data, v, tau);
    &data.qdd
}

/// ABA assuming `forward_kinematics` was run for the current q. With `<mimic>` joints the
/// articulated-body recursion does not apply (a coordinate moves several bodies), and q̈ comes from
/// the coordinates' M q̈ = τ + τ_g − C q̇ by Cholesky, as Pinocchio's mimic support does.
pub fn aba_from_kinematics(model: &Model, data: &mut Data, v: &[f64], tau: &[f64]) {
    if model.has_mimic() {
        return coupled_forward_dynamics(model, data, v, tau);
    }
    let n = model.dof();
    for (i, joint) in model.bodies.iter().enumerate() {
        let s = data.motion_subspace[i];
        let v_parent = joint.parent.map_or(Vector6::zeros(), |p| data.velocity[p]);
        let joint_velocity = s * v[i];
        let vel = v_parent + joint_velocity;
        data.bias_acceleration[i] = cross_motion(&vel, &joint_velocity);
        let inertia = &data.body_inertia[i];
        data.articulated_bias[i] = cross_force(&vel, &inertia.mul_motion(&vel));
        data.articulated_inertia[i] = inertia.to_matrix();
        data.velocity[i] = vel;
    }
    for i in (0..n).rev() {
        let s = data.motion_subspace[i];
        let ia = data.articulated_inertia[i];
        let u_vec = ia * s;
        // a rotor's reflected inertia acts on the joint alone (Featherstone's armature; Pinocchio's D_i)
        let d = s.dot(&u_vec) + model.armature[i];
        let u = tau[i] - s.dot(&data.articulated_bias[i]);
        data.aba_u[i] = u_vec;
        data.aba_d[i] = d;
        data.aba_torque[i] = u;
        if let Some(p) = model.bodies[i].parent {
            let inv_d = 1.0 / d;
            let ia_reduced = ia - (u_vec * u_vec.transpose()) * inv_d;
            let pa = data.articulated_bias[i] + ia_reduced * data.bias_acceleration[i] + u_vec * (u * inv_d);
            data.articulated_inertia[p] += ia_reduced;
            data.articulated_bias[p] += pa;
        }
    }
    let a0 = base_acceleration(model);
    for (i, joint) in model.bodies.iter().enumerate() {
        let a_parent = joint.parent.map_or(a0, |p| data.acceleration[p]);
        let a_prime = a_parent + data.bias_acceleration[i];
        let qdd = (data.aba_torque[i] - data.aba_u[i].dot(&a_prime)) / data.aba_d[i];
        data.qdd[i] = qdd;
        data.acceleration[i] = a_prime + data.motion_subspace[i] * qdd;
    }
}

/// q̈ = M⁻¹(τ + τ_g − C q̇) in the coordinates of a model with `<mimic>` joints.
fn coupled_forward_dynamics(model: &Model, data: &mut Data, v: &[f64], tau: &[f64]) {
    crba_from_kinematics(model, data);
    gravity_and_bias_from_kinematics(model, data, v);
    data.mass_factor.copy_from(&data.mass_matrix);
    for i in 0..model.dof() {
        data.qdd[i] = tau[i] + data.gravity[i] - data.bias[i];
    }
    if cholesky_in_place(&mut data.mass_factor) {
        cholesky_solve_in_place(&data.mass_factor, &mut data.qdd);
    } else {
        data.qdd.fill(f64::NAN);
    }
}
