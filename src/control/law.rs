//! A torque law of the user's in the loop in place of the tutorial's PD (`armscope.simulate` in
//! Python): at every control step it asks a torque of each joint; the motors' limits then clip it
//! as they clip the PD's ([`super::controller::PdGravityController::apply`]), and the plant takes it
//! as it takes the PD's. Joints driven elsewhere (a servo's firmware, an open-loop stepper) keep
//! their drives.

use crate::error::Error;

/// What a law sees at a control step.
pub struct LawInput<'a> {
    /// The step's time, k·dt, s.
    pub t: f64,
    pub q: &'a [f64],
    pub v: &'a [f64],
    /// The command (the run's trajectory) and its rate, for laws that track it.
    pub cmd: &'a [f64],
    pub cmd_dot: &'a [f64],
    /// τ_g(q), the force gravity applies (Drake's sign).
    pub tau_g: &'a [f64],
}

pub trait TorqueLaw: Send {
    /// The torque asked of each joint into `u` (before the motors' limits). An error stops the run
    /// there: its recordings end whole at that step, and the run returns the error.
    fn torque(&mut self, input: &LawInput, u: &mut [f64]) -> Result<(), Error>;
}
