use crate::model::Model;
use crate::spatial::{Pose, SpatialInertia};
use nalgebra::{DMatrix, Matrix6, Vector6};

/// The per-simulation workspace of the dynamics algorithms. Sized once for a model; the
/// algorithms only write into it.
#[derive(Clone, Debug)]
pub struct Data {
    /// World pose of each body (set by `forward_kinematics`).
    pub body_pose: Vec<Pose>,
    /// Body i's motion per unit of its coordinate, multiplier_i·S_i, in world coordinates (set by
    /// `forward_kinematics`); S_i itself for an independent joint.
    pub motion_subspace: Vec<Vector6<f64>>,
    /// Each body's spatial inertia in world coordinates (set by `forward_kinematics`).
    pub body_inertia: Vec<SpatialInertia>,
    /// Body spatial velocities and accelerations (RNEA, ABA).
    pub velocity: Vec<Vector6<f64>>,
    pub acceleration: Vec<Vector6<f64>>,
    /// Body spatial momenta I·v (the gravity-and-bias pass: what the energy audit's ½ vᵀ I v reuses).
    pub momentum: Vec<Vector6<f64>>,
    /// Body forces (RNEA) and gravity wrenches (gravity pass).
    pub force: Vec<Vector6<f64>>,
    pub gravity_force: Vec<Vector6<f64>>,
    /// Composite rigid-body inertias (CRBA).
    pub composite_inertia: Vec<SpatialInertia>,
    /// ABA intermediates.
    pub bias_acceleration: Vec<Vector6<f64>>,
    pub articulated_inertia: Vec<Matrix6<f64>>,
    pub articulated_bias: Vec<Vector6<f64>>,
    pub aba_u: Vec<Vector6<f64>>,
    pub aba_d: Vec<f64>,
    pub aba_torque: Vec<f64>,
    /// Outputs. M(q): without `<mimic>` joints CRBA writes only the entries of joints where one
    /// supports the other; the rest keep the zero they start with here, so nothing else may write it.
    pub mass_matrix: DMatrix<f64>,
    pub tau: Vec<f64>,
    pub qdd: Vec<f64>,
    /// τ_g(q): the generalized force of gravity.
    pub gravity: Vec<f64>,
    /// C(q, q̇)·q̇.
    pub bias: Vec<f64>,
    /// The Cholesky factor of M, for forward dynamics of models with `<mimic>` joints.
    pub mass_factor: DMatrix<f64>,
}

impl Data {
    pub fn new(model: &Model) -> Self {
        let (n, b) = (model.dof(), model.bodies.len());
        Self {
            body_pose: vec![Pose::identity(); b],
            motion_subspace: vec![Vector6::zeros(); b],
            body_inertia: vec![SpatialInertia::zero(); b],
            velocity: vec![Vector6::zeros(); b],
            acceleration: vec![Vector6::zeros(); b],
            momentum: vec![Vector6::zeros(); b],
            force: vec![Vector6::zeros(); b],
            gravity_force: vec![Vector6::zeros(); b],
            composite_inertia: vec![SpatialInertia::zero(); b],
            bias_acceleration: vec![Vector6::zeros(); b],
            articulated_inertia: vec![Matrix6::zeros(); b],
            articulated_bias: vec![Vector6::zeros(); b],
            aba_u: vec![Vector6::zeros(); b],
            aba_d: vec![0.0; b],
            aba_torque: vec![0.0; b],
            mass_matrix: DMatrix::zeros(n, n),
            tau: vec![0.0; n],
            qdd: vec![0.0; n],
            gravity: vec![0.0; n],
            bias: vec![0.0; n],
            mass_factor: if model.has_mimic() { DMatrix::zeros(n, n) } else { DMatrix::zeros(0, 0) },
        }
    }
}
