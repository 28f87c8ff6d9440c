//! Rigid-body algorithms on a [`Model`](crate::model::Model), Pinocchio-style: each algorithm is a
//! free function taking the read-only model and a mutable [`Data`] workspace, which holds every
//! intermediate so that no step allocates.
//!
//! All spatial quantities are in world coordinates, referred to the world origin
//! (see [`crate::spatial`]). Sign conventions follow Drake:
//! `M(q) q̈ + C(q,q̇) q̇ = τ + τ_g(q) − D q̇`, with τ_g the generalized force gravity applies.

mod aba;
mod cholesky;
mod crba;
mod data;
mod energy;
mod gravity_stiffness;
mod jacobian;
mod kinematics;
mod ldlt;
mod ltdl;
mod rnea;
mod rnea_many;
mod solvable;

pub use aba::{aba, aba_from_kinematics};
pub use cholesky::{cholesky_in_place, cholesky_solve_in_place};
pub use crba::{crba, crba_from_kinematics};
pub use data::Data;
pub use gravity_stiffness::gravity_stiffness;
pub use energy::{kinetic_energy, kinetic_energy_from_momenta, kinetic_energy_from_velocities, potential_energy_from_kinematics};
pub use jacobian::{frame_jacobian, frame_vertical_jacobian};
pub use ldlt::{ldlt_in_place, ldlt_in_place_slice, ldlt_solve_in_place, ldlt_solve_slice};
pub use ltdl::{ltdl_in_place, ltdl_solve_in_place};
pub use kinematics::{body_poses, forward_kinematics, frame_pose, frame_pose_in};
pub use rnea_many::{RneaManyData, rnea_many};
pub use solvable::check_solvable;
pub use rnea::{bias_forces, gravity_and_bias_from_kinematics, gravity_forces, gravity_from_kinematics, rnea, rnea_from_kinematics};
