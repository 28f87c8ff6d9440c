//! The arm's mechanical energy (Pinocchio's computeKineticEnergy / computePotentialEnergy), from the
//! bodies rather than from M: O(bodies), and an independent check of CRBA (½ q̇ᵀ M q̇ is the same).

use super::{Data, forward_kinematics};
use crate::model::Model;
use nalgebra::Vector6;

/// ½ q̇ᵀ M(q) q̇, the motors' rotors (J_r·N²) included: every body's ½ vᵀ I v plus ½ J_r·N²·q̇².
pub fn kinetic_energy(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> f64 {
    forward_kinematics(model, data, q);
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate() {
        let parent = joint.parent.map_or(Vector6::zeros(), |p| data.velocity[p]);
        data.velocity[i] = parent + data.motion_subspace[i] * v[coupling.coordinate];
    }
    kinetic_energy_from_velocities(model, data, v)
}

/// [`kinetic_energy`] from the body velocities already in `data` (any velocity pass at (q, q̇):
/// RNEA, or the loop's gravity-and-bias pass).
pub fn kinetic_energy_from_velocities(model: &Model, data: &Data, v: &[f64]) -> f64 {
    let bodies: f64 = (0..model.bodies.len()).map(|i| data.velocity[i].dot(&data.body_inertia[i].mul_motion(&data.velocity[i]))).sum();
    0.5 * (bodies + rotors_twice(model, v))
}

/// [`kinetic_energy_from_velocities`] from the body velocities and momenta the gravity-and-bias pass
/// ([`super::gravity_and_bias_from_kinematics`]) left in `data` at (q, q̇): the same sum of the same
/// products, without applying each body's inertia a second time.
pub fn kinetic_energy_from_momenta(model: &Model, data: &Data, v: &[f64]) -> f64 {
    let bodies: f64 = (0..model.bodies.len()).map(|i| data.velocity[i].dot(&data.momentum[i])).sum();
    0.5 * (bodies + rotors_twice(model, v))
}

/// Σ J_r·N²·q̇² over the coordinates: twice the motors' rotors' kinetic energy.
fn rotors_twice(model: &Model, v: &[f64]) -> f64 {
    model.armature.iter().zip(v).map(|(a, v)| a * v * v).sum()
}

/// The potential energy of gravity, −Σ m·g·c (c each body's centre of mass in the world), zero with
/// every centre of mass at the world origin; from the body poses already in `data`.
pub fn potential_energy_from_kinematics(model: &Model, data: &Data) -> f64 {
    model.bodies.iter().enumerate().map(|(i, body)| -body.inertia.mass * model.gravity.dot(&data.body_pose[i].transform_point(&body.inertia.com))).sum()
}
