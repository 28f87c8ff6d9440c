//! Plants: how the state advances over one control period with the torque held.

mod continuous;
mod discrete;

pub use continuous::{ContinuousPlant, Tolerances};
pub use discrete::DiscretePlant;

use crate::dynamics::Data;
use crate::model::Model;

/// Advances (q, q̇) over one control period with u held constant.
pub trait Plant: Send {
    /// On entry `data` holds forward kinematics, τ_g and C·q̇ at (q, q̇) (the simulation loop
    /// computed them for the controller); on exit it is stale.
    fn advance(&mut self, model: &Model, data: &mut Data, u: &[f64], q: &mut [f64], v: &mut [f64]);

    /// Per joint: whether it was stopped at a position limit during the last `advance`.
    fn limit_active(&self) -> &[bool];

    /// One line for the console and the recordings.
    fn describe(&self) -> String;
}
