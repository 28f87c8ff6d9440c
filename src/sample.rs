//! One instant of a run, as the simulation loop hands it to every recorder.

use crate::spatial::Pose;
use nalgebra::Vector3;

/// The state at t_k = k·dt, the command and the torque the controller holds over [t_k, t_k + dt).
/// Every value is at the same instant. Borrowed from the loop's buffers: recorders copy what they keep.
#[derive(Clone, Copy, Debug)]
pub struct Sample<'a> {
    pub k: usize,
    pub t: f64,
    /// The last sample of the run: its torque is computed but never applied.
    pub is_final: bool,
    pub q: &'a [f64],
    pub v: &'a [f64],
    pub cmd: &'a [f64],
    pub cmd_dot: &'a [f64],
    pub u: &'a [f64],
    /// The generalized force of gravity at q (what the feed-forward cancels).
    pub tau_g: &'a [f64],
    /// The controller asked for more than the motor's limit.
    pub saturated: &'a [bool],
    /// The torque limit at this step: the URDF's effort, or with `--motors` what the motor gives at
    /// the joint's speed through its gearbox (0 on a passive joint).
    pub torque_limit: &'a [f64],
    /// Stepper mode: each stepper joint's load angle, electrical degrees (±90° the peak torque, ±180°
    /// the slip point); 0 elsewhere.
    pub load_angle: &'a [f64],
    /// Stepper mode: full steps lost so far per joint (signed); 0 elsewhere.
    pub lost_steps: &'a [i64],
    /// Chatter: the torque flipped sign since the previous step while at least one of the two was
    /// saturated (the signature of an unstable sampled loop, not of torque demand).
    pub chatter: &'a [bool],
    /// The joint was stopped at a position limit in the step that led here.
    pub at_limit: &'a [bool],
    /// Coulomb friction torque on each joint at the end of the step that led here, N·m (empty when
    /// the experiment has no friction anywhere).
    pub friction: &'a [f64],
    /// Per joint with friction: stuck (q̇ exactly 0, held by friction); empty without friction.
    pub stuck: &'a [bool],
    /// Per joint, its motor's winding temperature, °C (NaN where the motor has no thermal data;
    /// empty when no motor of the run has).
    pub winding_temperature: &'a [f64],
    /// Per joint driven by its servo's firmware: the PWM duty (−1 … 1), the motor's current (A)
    /// and the supply at the servo (V); 0 elsewhere; all empty when no joint is.
    pub duty: &'a [f64],
    pub current: &'a [f64],
    pub supply: &'a [f64],
    /// A recording's measured effort per joint beside the model's torque `u` (a replayed bag's
    /// `effort`; NaN where a joint has none); empty for a simulation.
    pub measured_effort: &'a [f64],
    /// A real arm's position per joint beside the simulated one (a forward replay's recorded
    /// follower; NaN where a joint has none); empty otherwise.
    pub observed_position: &'a [f64],
    /// With collision checks: the pairs closer than 5 cm at this state, nearest first (distance ≤ 0:
    /// in contact); empty without checks.
    pub collisions: &'a [crate::collision::PairDistance],
    pub tool_position: Vector3<f64>,
    /// Where the command puts the tool (forward kinematics of cmd).
    pub tool_target: Vector3<f64>,
    /// World pose of every body (joint i moves body i), for drawing.
    pub body_pose: &'a [Pose],
}

impl Sample<'_> {
    /// Joint `j`'s tracking error, target − position.
    pub fn tracking_error(&self, j: usize) -> f64 {
        self.cmd[j] - self.q[j]
    }

    /// How far the tool tip is from where the command puts it, m.
    pub fn tool_error(&self) -> f64 {
        (self.tool_position - self.tool_target).norm()
    }
}
