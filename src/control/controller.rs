//! The tutorial's joint controller: PD on the command plus gravity feed-forward, clipped to the
//! motors' limits.

use crate::actuator::DriveEnvelope;

/// u = kp∘(cmd − q) + kd∘(cmd_dot − q̇) − τ_g(q), clipped to ±effort (with `--motors`, the motor's
/// torque at the joint, N·τ_m: a stepper's detent torque added, clipped to what the motor gives at
/// the joint's speed, with the motion or braking; the gearbox's losses are the plant's friction);
/// zero on unactuated joints. Joints whose torque is set elsewhere (an open-loop stepper, a servo's
/// own firmware) are left alone.
#[derive(Clone, Debug)]
pub struct PdGravityController {
    pub kp: Vec<f64>,
    pub kd: Vec<f64>,
    /// Torque limit per joint (0 where the joint has no actuator).
    pub effort: Vec<f64>,
    pub actuated: Vec<bool>,
    /// Gravity feed-forward (off with `--no-ff`).
    pub feed_forward: bool,
    /// Motors whose torque falls with speed (`--motors`); `effort` elsewhere.
    motors: Option<std::sync::Arc<crate::actuator::MotorSet>>,
    /// Per joint with a motor, what it lets the controller command, worked out once.
    envelopes: Vec<Option<DriveEnvelope>>,
    /// The start pose, where each stepper's rotor sits in a detent position: its detent torque
    /// joins the motor's torque (within the motor's limit: the pull-out curve is measured at the
    /// shaft, detent included).
    detent_origin: Vec<f64>,
    /// Per joint: its torque is set elsewhere, not by this controller.
    elsewhere: Vec<bool>,
}

/// One controller output.
pub struct ControlOutput<'a> {
    /// The torque applied (after clipping).
    pub u: &'a mut [f64],
    /// Whether the unclipped torque exceeded the limit.
    pub saturated: &'a mut [bool],
    /// The limit at this step in the direction of the torque asked for (the motor's torque at the
    /// joint's speed through its gearbox: with the motion, or braking against it).
    pub limit: &'a mut [f64],
}

impl PdGravityController {
    /// The PD law with gravity feed-forward on the joints' effort limits.
    pub fn new(kp: Vec<f64>, kd: Vec<f64>, effort: Vec<f64>, actuated: Vec<bool>, feed_forward: bool) -> Self {
        let n = kp.len();
        Self { kp, kd, effort, actuated, feed_forward, motors: None, envelopes: vec![None; n], detent_origin: vec![0.0; n], elsewhere: vec![false; n] }
    }

    /// On the drive trains of `motors` (their torque at speed, a stepper's detent from where each
    /// rotor sat at `detent_origin`) instead of the effort limits.
    pub fn with_motors(mut self, motors: std::sync::Arc<crate::actuator::MotorSet>, detent_origin: Vec<f64>) -> Self {
        self.envelopes = motors.joints.iter().map(|d| d.as_ref().map(DriveEnvelope::of)).collect();
        self.motors = Some(motors);
        self.detent_origin = detent_origin;
        self
    }

    /// Leaving the joints flagged in `elsewhere` to what drives them (their outputs untouched).
    pub fn leaving(mut self, elsewhere: Vec<bool>) -> Self {
        self.elsewhere = elsewhere;
        self
    }

    /// The gains as the loop sees them: zero on joints without a motor.
    pub fn effective_gains(&self) -> (Vec<f64>, Vec<f64>) {
        let keep = |g: &[f64]| g.iter().zip(&self.actuated).map(|(g, &a)| if a { *g } else { 0.0 }).collect();
        (keep(&self.kp), keep(&self.kd))
    }

    /// Per joint, the largest torque the controller can command at rest: with `--motors`, the
    /// motor's N·T at the joint (before the gearbox's losses); the effort limit elsewhere.
    pub fn limits_at_rest(&self) -> Vec<f64> {
        (0..self.effort.len()).map(|i| self.range(i, 0.0).1).collect()
    }

    /// The torque joint i can be commanded at joint speed `speed`: (lowest ≤ 0, highest ≥ 0).
    fn range(&self, i: usize, speed: f64) -> (f64, f64) {
        match (&self.envelopes[i], &self.motors) {
            (Some(envelope), Some(motors)) => envelope.torque_range(speed, &*motors.joints[i].as_ref().expect("an envelope's drive train").motor),
            _ => (-self.effort[i], self.effort[i]),
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub fn compute(&self, q: &[f64], v: &[f64], cmd: &[f64], cmd_dot: &[f64], tau_g: &[f64], mut out: ControlOutput) {
        // (a joint driven elsewhere skipped before its PD: on an arm of servos, every joint)
        for i in (0..q.len()).filter(|&i| !self.elsewhere[i]) {
            let mut u = self.kp[i] * (cmd[i] - q[i]) + self.kd[i] * (cmd_dot[i] - v[i]);
            if self.feed_forward {
                u -= tau_g[i];
            }
            self.limit(i, u, q[i], v[i], &mut out);
        }
    }

    /// The torques `asked` (a user's law, in place of the PD) through the same limits.
    pub fn apply(&self, asked: &[f64], q: &[f64], v: &[f64], mut out: ControlOutput) {
        for i in 0..q.len() {
            self.limit(i, asked[i], q[i], v[i], &mut out);
        }
    }

    /// Joint i's torque `u` as asked, its stepper's detent added, clipped to what its motor gives
    /// at its speed (none on an unactuated joint; a joint driven elsewhere left alone).
    fn limit(&self, i: usize, mut u: f64, q: f64, v: f64, out: &mut ControlOutput) {
        if self.elsewhere[i] {
            return;
        }
        if !self.actuated[i] {
            out.u[i] = 0.0;
            out.saturated[i] = false;
            out.limit[i] = 0.0;
            return;
        }
        if let Some(envelope) = &self.envelopes[i] {
            u += envelope.detent_torque(q - self.detent_origin[i]);
        }
        let (lowest, highest) = self.range(i, v);
        out.saturated[i] = (u > highest) | (u < lowest);
        out.u[i] = u.clamp(lowest, highest);
        out.limit[i] = if u >= 0.0 { highest } else { -lowest };
    }
}
