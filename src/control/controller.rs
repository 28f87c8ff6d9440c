//! The tutorial's joint controller: PD on the command plus gravity feed-forward, clipped to the
//! motors' limits.

/// u = kp∘(cmd − q) + kd∘(cmd_dot − q̇) − τ_g(q), clipped to ±effort (with `--motors`, the motor's
/// torque at the joint, N·τ_m: a stepper's detent torque added, clipped to what the motor gives at
/// the joint's speed, with the motion or braking; the gearbox's losses are the plant's friction);
/// zero on unactuated joints.
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
    pub motors: Option<std::sync::Arc<crate::actuator::MotorSet>>,
    /// The start pose, where each stepper's rotor sits in a detent position: its detent torque
    /// joins the motor's torque (within the motor's limit: the pull-out curve is measured at the
    /// shaft, detent included).
    pub detent_origin: Vec<f64>,
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

    /// Joint i's drive train, with `--motors`.
    fn drive(&self, i: usize) -> Option<&crate::actuator::DriveTrain> {
        self.motors.as_ref().and_then(|m| m.joints[i].as_ref())
    }

    /// The torque joint i can be commanded at joint speed `speed`: (lowest ≤ 0, highest ≥ 0).
    fn range(&self, i: usize, speed: f64) -> (f64, f64) {
        match self.drive(i) {
            Some(drive) => drive.torque_range(speed),
            None => (-self.effort[i], self.effort[i]),
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub fn compute(&self, q: &[f64], v: &[f64], cmd: &[f64], cmd_dot: &[f64], tau_g: &[f64], out: ControlOutput) {
        for i in 0..q.len() {
            if !self.actuated[i] {
                out.u[i] = 0.0;
                out.saturated[i] = false;
                out.limit[i] = 0.0;
                continue;
            }
            let mut u = self.kp[i] * (cmd[i] - q[i]) + self.kd[i] * (cmd_dot[i] - v[i]);
            if self.feed_forward {
                u -= tau_g[i];
            }
            if let Some(drive) = self.drive(i) {
                u += drive.detent_torque(q[i] - self.detent_origin[i]);
            }
            let (lowest, highest) = self.range(i, v[i]);
            out.saturated[i] = u > highest || u < lowest;
            out.u[i] = u.clamp(lowest, highest);
            out.limit[i] = if u >= 0.0 { highest } else { -lowest };
        }
    }
}
