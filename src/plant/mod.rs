//! Plants: how the state advances over one control period with the torque held.

mod continuous;
mod discrete;
mod floor_contact;
mod joint_friction;
mod stick_slip;

pub use continuous::{ContinuousPlant, Tolerances};
pub use discrete::DiscretePlant;
pub use floor_contact::FloorContact;
pub use joint_friction::JointFriction;
pub use stick_slip::{JointLaw, NotPositiveDefinite, StickSlipSolver};

use crate::dynamics::Data;
use crate::model::Model;

/// Advances (q, q̇) over one control period with u held constant.
pub trait Plant: Send {
    /// On entry `data` holds forward kinematics, τ_g and C·q̇ at (q, q̇) (the simulation loop
    /// computed them for the controller); on exit it is stale.
    fn advance(&mut self, model: &Model, data: &mut Data, u: &[f64], q: &mut [f64], v: &mut [f64]);

    /// Like `advance`, but `torque(h, q, q̇, u)` updates u from the state before every plant step,
    /// h the time that step covers (a stepper's torque follows its rotor within a control period,
    /// and its driver's pulses advance by h).
    fn advance_driven(&mut self, model: &Model, data: &mut Data, u: &mut [f64], torque: &mut dyn FnMut(f64, &[f64], &[f64], &mut [f64]), q: &mut [f64], v: &mut [f64]);

    /// Per joint: whether it was stopped at a position limit during the last `advance`.
    fn limit_active(&self) -> &[bool];

    /// Per joint: the Coulomb friction torque at the end of the last `advance` (0 without friction).
    fn friction_torque(&self) -> &[f64];

    /// Per joint with friction: whether it is stuck (q̇ exactly 0, held by friction) at the end of
    /// the last `advance`.
    fn stuck(&self) -> &[bool];

    /// The work the friction (and a floor's contact) did over the last `advance`, J (the friction's
    /// ≤ 0: it dissipates), for the energy audit.
    fn friction_work(&self) -> f64;

    /// One line for the console and the recordings.
    fn describe(&self) -> String;
}
