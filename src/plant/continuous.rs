use super::Plant;
use super::joint_friction::JointFriction;
use super::stick_slip::{JointLaw, StickSlipSolver};
use crate::actuator::LossyGear;
use crate::dynamics::{Data, aba, crba_from_kinematics, forward_kinematics, gravity_and_bias_from_kinematics};
use crate::model::Model;

/// Error tolerances of the adaptive integrator (per state component:
/// |err| ≤ atol + rtol·|y|).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Tolerances {
    pub rtol: f64,
    pub atol: f64,
}

// Dormand–Prince 5(4) tableau (the dynamics do not depend on time within a control period, so
// the nodes c_i are not needed).
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
];
/// Fifth-order weights (= last row of A: first same as last).
const B5: [f64; 7] = [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0, 0.0];
/// Fifth minus fourth order weights: the local error estimate.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// The continuous plant M q̈ + C q̇ = u + τ_g − D q̇, integrated by an adaptive, error-controlled
/// Dormand–Prince 5(4) Runge–Kutta method. Each control period is integrated exactly to its end
/// (the torque is held over it). A joint that reaches a position limit stops there (an inelastic
/// stop: its velocity into the limit is removed).
///
/// With Coulomb friction the motion is piecewise smooth, and integrated piece by piece (Modelica's
/// stuck/forward/backward modes): each joint with friction slides (τ_f = −F⁺ or +F⁻, constant over
/// the period: the URDF's friction and the gear's losses for the held torque, [`JointFriction`])
/// or is stuck (q̈ = 0 imposed, q̇ = 0, its friction whatever holds it); a step that ends with a
/// sliding joint's velocity through zero, or a stuck joint needing more than F, is cut back to the
/// event (bisection to 1e-13 s), the crossing velocity set to exactly 0 and the modes decided
/// again by the acceleration-level problem M·q̈ = r + τ_f, solved exactly ([`StickSlipSolver`]).
/// A stuck joint's position and velocity do not change at all.
pub struct ContinuousPlant {
    pub tolerances: Tolerances,
    /// Largest step, as the reference's `max_step`.
    pub max_step: f64,
    period: f64,
    step_size: f64,
    n: usize,
    y: Vec<f64>,
    y_stage: Vec<f64>,
    y_new: Vec<f64>,
    k: [Vec<f64>; 7],
    tau: Vec<f64>,
    limit_active: Vec<bool>,
    friction: Friction,
    /// Accepted and rejected steps so far.
    pub accepted_steps: u64,
    pub rejected_steps: u64,
}

impl ContinuousPlant {
    pub fn new(model: &Model, period: f64, tolerances: Tolerances) -> Self {
        Self::with_gears(model, period, tolerances, &[])
    }

    /// The plant with the drive trains' gear losses (by coordinate) as friction at the joints.
    pub fn with_gears(model: &Model, period: f64, tolerances: Tolerances, gears: &[Option<LossyGear>]) -> Self {
        let n = model.dof();
        let state = || vec![0.0; 2 * n];
        Self {
            tolerances,
            max_step: period,
            period,
            step_size: period / 10.0,
            n,
            y: state(),
            y_stage: state(),
            y_new: state(),
            k: std::array::from_fn(|_| state()),
            tau: vec![0.0; n],
            limit_active: vec![false; n],
            friction: Friction::new(model, gears),
            accepted_steps: 0,
            rejected_steps: 0,
        }
    }

    /// ẏ = (q̇, q̈) with q̈ from ABA, damping included; with friction, in the current modes.
    fn derivative(&mut self, model: &Model, data: &mut Data, u: &[f64], stage: usize) {
        let n = self.n;
        if self.friction.any {
            let (q, v) = self.y_stage.split_at(n);
            let qdd = self.friction.acceleration(model, data, u, q, v);
            let k = &mut self.k[stage];
            k[..n].copy_from_slice(v);
            k[n..].copy_from_slice(qdd);
            return;
        }
        let (q, v) = self.y_stage.split_at(n);
        for i in 0..n {
            self.tau[i] = u[i] - model.joints[i].damping * v[i];
        }
        let qdd = aba(model, data, q, v, &self.tau);
        let k = &mut self.k[stage];
        k[..n].copy_from_slice(v);
        k[n..].copy_from_slice(qdd);
    }

    /// Stages 1–6 of a step of length h from y (stage 0 evaluated), and y_new.
    fn stages(&mut self, model: &Model, data: &mut Data, u: &[f64], h: f64) {
        let n = self.n;
        for s in 1..7 {
            for i in 0..2 * n {
                let mut acc = 0.0;
                for (j, a) in A[s][..s].iter().enumerate() {
                    acc += a * self.k[j][i];
                }
                self.y_stage[i] = self.y[i] + h * acc;
            }
            self.derivative(model, data, u, s);
        }
        // stage 6 was evaluated at the fifth-order solution (FSAL)
        for i in 0..2 * n {
            let mut acc = 0.0;
            for (j, b) in B5.iter().enumerate() {
                acc += b * self.k[j][i];
            }
            self.y_new[i] = self.y[i] + h * acc;
        }
    }

    /// The step from y that ends just past the first event within h (bisection on the step length:
    /// a shorter step is at least as accurate), y_new at its end; returns its length.
    fn step_to_event(&mut self, model: &Model, data: &mut Data, u: &[f64], h: f64) -> f64 {
        let n = self.n;
        let (mut before, mut after) = (0.0, h);
        while after - before > EVENT_TIME_TOLERANCE {
            let middle = 0.5 * (before + after);
            if middle <= before || middle >= after {
                break;
            }
            self.stages(model, data, u, middle);
            if self.friction.event(&self.y_new[n..]) {
                after = middle;
            } else {
                before = middle;
            }
        }
        self.stages(model, data, u, after);
        after
    }

    fn error_norm(&self, h: f64) -> f64 {
        let Tolerances { rtol, atol } = self.tolerances;
        let mut sum = 0.0;
        for i in 0..2 * self.n {
            let mut err = 0.0;
            for (s, e) in E.iter().enumerate() {
                err += e * self.k[s][i];
            }
            let scale = atol + rtol * self.y[i].abs().max(self.y_new[i].abs());
            let r = h * err / scale;
            sum += r * r;
        }
        (sum / (2 * self.n) as f64).sqrt()
    }

    fn apply_limits(&mut self, model: &Model) {
        let n = self.n;
        for (i, joint) in model.joints.iter().enumerate() {
            let q = self.y[i];
            if q > joint.upper || q < joint.lower {
                self.y[i] = q.clamp(joint.lower, joint.upper);
                let into_limit = if q > joint.upper { self.y[n + i] > 0.0 } else { self.y[n + i] < 0.0 };
                if into_limit {
                    self.y[n + i] = 0.0;
                }
                self.limit_active[i] = true;
            }
        }
    }
}

impl Plant for ContinuousPlant {
    /// The torque once per period (the adaptive steps integrate it held).
    fn advance_driven(&mut self, model: &Model, data: &mut Data, u: &mut [f64], torque: &mut dyn FnMut(f64, &[f64], &[f64], &mut [f64]), q: &mut [f64], v: &mut [f64]) {
        torque(self.period, q, v, u);
        self.advance(model, data, u, q, v);
    }

    fn advance(&mut self, model: &Model, data: &mut Data, u: &[f64], q: &mut [f64], v: &mut [f64]) {
        let n = self.n;
        self.y[..n].copy_from_slice(q);
        self.y[n..].copy_from_slice(v);
        self.limit_active.fill(false);
        if self.friction.any {
            self.friction.work = 0.0;
            self.friction.start_period(u, &mut self.y[n..]);
            self.friction.decide_modes(model, data, u, &self.y[..n], &self.y[n..]);
        }
        let mut remaining = self.period;
        // the torque is discontinuous at the period boundary: start each period afresh (no FSAL carry-over)
        let mut have_first_stage = false;
        while remaining > 0.0 {
            let last = self.step_size >= remaining * (1.0 - 1e-12);
            let h = if last { remaining } else { self.step_size.min(self.max_step) };
            if !have_first_stage {
                self.y_stage.copy_from_slice(&self.y);
                self.derivative(model, data, u, 0);
                have_first_stage = true;
            }
            self.stages(model, data, u, h);
            let err = self.error_norm(h);
            if err.is_finite() && err <= 1.0 && self.friction.any && self.friction.event(&self.y_new[n..]) {
                // a mode ends within this step: cut it back to the event and decide the modes again
                let taken = self.step_to_event(model, data, u, h);
                self.friction.book(&self.y[..n], &self.y_new[..n]);
                self.y.copy_from_slice(&self.y_new);
                self.friction.end_modes(&mut self.y[n..]);
                self.friction.decide_modes(model, data, u, &self.y[..n], &self.y[n..]);
                have_first_stage = false;
                remaining = if last && taken >= h { 0.0 } else { remaining - taken };
                self.accepted_steps += 1;
                continue;
            }
            if err.is_finite() && err <= 1.0 {
                if self.friction.any {
                    self.friction.book(&self.y[..n], &self.y_new[..n]);
                }
                self.y.copy_from_slice(&self.y_new);
                let k6 = std::mem::take(&mut self.k[6]);
                self.k[0].copy_from_slice(&k6);
                self.k[6] = k6;
                remaining = if last { 0.0 } else { remaining - h };
                self.accepted_steps += 1;
                if !last {
                    let growth = if err == 0.0 { 5.0 } else { (0.9 * err.powf(-0.2)).clamp(0.2, 5.0) };
                    self.step_size = (h * growth).min(self.max_step);
                }
            } else if h <= 1e-12 {
                // no step is small enough: hand a non-finite state to the divergence check
                self.y.fill(f64::NAN);
                break;
            } else {
                self.rejected_steps += 1;
                let shrink = if err.is_finite() { (0.9 * err.powf(-0.2)).clamp(0.2, 1.0) } else { 0.2 };
                self.step_size = h * shrink;
            }
        }
        self.apply_limits(model);
        q.copy_from_slice(&self.y[..n]);
        v.copy_from_slice(&self.y[n..]);
    }

    fn limit_active(&self) -> &[bool] {
        &self.limit_active
    }

    fn friction_torque(&self) -> &[f64] {
        &self.friction.torque
    }

    fn stuck(&self) -> &[bool] {
        &self.friction.stuck
    }

    fn friction_work(&self) -> f64 {
        self.friction.work
    }

    fn describe(&self) -> String {
        format!(
            "continuous plant: adaptive Dormand–Prince 5(4), rtol = {:e}, atol = {:e}, max step {} ms, torque held over each {} ms control period",
            self.tolerances.rtol,
            self.tolerances.atol,
            self.max_step * 1e3,
            self.period * 1e3
        )
    }
}

/// How closely a mode's end is located in time, s.
const EVENT_TIME_TOLERANCE: f64 = 1e-13;

/// The continuous plant's friction: per joint the Coulomb band (F⁺, F⁻) for the period's motor
/// torque, the mode (−1/+1 sliding that way, 0 stuck, for joints with friction; sliding ones follow
/// their velocity's sign), and the acceleration-level solve.
struct Friction {
    joints: JointFriction,
    any: bool,
    /// (F⁺, F⁻) for this control period's torque (infinite on a self-locking gear's locked side).
    up: Vec<f64>,
    down: Vec<f64>,
    /// −1, +1: sliding (τ_f = −F⁺ or +F⁻); 0: stuck, or no friction.
    mode: Vec<i8>,
    laws: Vec<JointLaw>,
    solver: StickSlipSolver,
    rhs: Vec<f64>,
    qdd: Vec<f64>,
    residual: Vec<f64>,
    zeros: Vec<f64>,
    /// Stuck joints' friction at the last stage evaluated (stage 6: the step's end).
    torque: Vec<f64>,
    stuck: Vec<bool>,
    work: f64,
}

impl Friction {
    fn new(model: &Model, gears: &[Option<LossyGear>]) -> Self {
        let n = model.dof();
        let joints = JointFriction::new(model, gears);
        Self {
            any: joints.any,
            joints,
            up: vec![0.0; n],
            down: vec![0.0; n],
            mode: vec![0; n],
            laws: vec![JointLaw::FREE; n],
            solver: StickSlipSolver::new(n, None),
            rhs: vec![0.0; n],
            qdd: vec![0.0; n],
            residual: vec![0.0; n],
            zeros: vec![0.0; n],
            torque: vec![0.0; n],
            stuck: vec![false; n],
            work: 0.0,
        }
    }

    /// The bands for a control period with the motor torque `u` held; a joint moving towards a side
    /// its gear now locks stops there (an inelastic stop, as at a position limit).
    fn start_period(&mut self, u: &[f64], v: &mut [f64]) {
        for i in 0..u.len() {
            (self.up[i], self.down[i]) = self.joints.bounds(i, u[i]);
            if (v[i] > 0.0 && self.up[i].is_infinite()) || (v[i] < 0.0 && self.down[i].is_infinite()) {
                v[i] = 0.0;
            }
        }
    }

    /// The friction on joint i sliding in direction `mode` (±1): −F⁺ or +F⁻.
    fn sliding(&self, i: usize, mode: i8) -> f64 {
        if mode > 0 { -self.up[i] } else { self.down[i] }
    }

    /// M(q), and r = u − D·q̇ + τ_g − C·q̇ in `rhs` (D with the gears' viscous friction).
    fn mass_and_forces<'d>(&mut self, model: &Model, data: &'d mut Data, u: &[f64], q: &[f64], v: &[f64]) -> &'d [f64] {
        forward_kinematics(model, data, q);
        gravity_and_bias_from_kinematics(model, data, v);
        crba_from_kinematics(model, data);
        for (i, joint) in model.joints.iter().enumerate() {
            self.rhs[i] = u[i] - (joint.damping + self.joints.viscous(i)) * v[i] + data.gravity[i] - data.bias[i];
        }
        data.mass_matrix.as_slice()
    }

    /// At a state where the modes may change (a period's start, an event): joints moving slide
    /// their way; each joint at rest sticks, or starts sliding, as the exact solution of
    /// M·q̈ = r + τ_f (−F⁺ ≤ τ_f ≤ F⁻ at rest, the sliding friction moving) says.
    fn decide_modes(&mut self, model: &Model, data: &mut Data, u: &[f64], q: &[f64], v: &[f64]) {
        let mass = self.mass_and_forces(model, data, u, q, v);
        for i in 0..v.len() {
            self.laws[i] = if !self.joints.has(i) {
                JointLaw::FREE
            } else if v[i] != 0.0 {
                // g = r − M·q̈ = −τ_f
                let slope = -self.sliding(i, v[i].signum() as i8);
                JointLaw { below: slope, above: slope, ..JointLaw::FREE }
            } else {
                self.joints.law(i, u[i], 1.0, f64::NEG_INFINITY, f64::INFINITY).0
            };
        }
        if self.solver.solve(mass, &self.zeros, &self.rhs, &self.laws, &mut self.qdd, &mut self.residual).is_err() {
            // not positive definite: a state no longer finite; the divergence check reports it
            self.mode.fill(0);
            return;
        }
        for i in 0..v.len() {
            self.mode[i] = if !self.joints.has(i) {
                0
            } else if v[i] != 0.0 {
                v[i].signum() as i8
            } else if self.qdd[i] != 0.0 {
                self.qdd[i].signum() as i8
            } else {
                0
            };
            self.stuck[i] = self.joints.has(i) && self.mode[i] == 0;
            self.torque[i] = if self.stuck[i] { -self.residual[i] } else if self.mode[i] != 0 { self.sliding(i, self.mode[i]) } else { 0.0 };
        }
    }

    /// q̈ in the current modes: sliding joints' friction known, stuck joints' q̈ = 0.
    fn acceleration(&mut self, model: &Model, data: &mut Data, u: &[f64], q: &[f64], v: &[f64]) -> &[f64] {
        let mass = self.mass_and_forces(model, data, u, q, v);
        for i in 0..v.len() {
            self.laws[i] = if !self.joints.has(i) {
                JointLaw::FREE
            } else if self.mode[i] == 0 {
                JointLaw { lower: 0.0, upper: 0.0, below: 0.0, above: 0.0 }
            } else {
                let slope = -self.sliding(i, self.mode[i]);
                JointLaw { below: slope, above: slope, ..JointLaw::FREE }
            };
        }
        if self.solver.solve(mass, &self.zeros, &self.rhs, &self.laws, &mut self.qdd, &mut self.residual).is_err() {
            self.qdd.fill(f64::NAN);
        }
        for i in 0..v.len() {
            if self.joints.has(i) && self.mode[i] == 0 {
                self.torque[i] = -self.residual[i];
            }
        }
        &self.qdd
    }

    /// Whether a mode ends within the step to this velocity: a sliding joint's velocity reached or
    /// passed zero, or a stuck joint needs more than its band to stay (at stage 6, the end).
    fn event(&self, v_end: &[f64]) -> bool {
        (0..v_end.len()).any(|i| match self.mode[i] {
            // (a relative 1e-9 over the band: what held the joint at the mode's start is not
            // re-decided for the solve's rounding)
            0 => self.joints.has(i) && (self.torque[i] < -self.up[i] * (1.0 + 1e-9) || self.torque[i] > self.down[i] * (1.0 + 1e-9)),
            m => v_end[i] * m as f64 <= 0.0,
        })
    }

    /// At an event: the sliding joints whose velocity reached zero are at rest (exactly).
    fn end_modes(&mut self, v: &mut [f64]) {
        for i in 0..v.len() {
            if self.mode[i] != 0 && v[i] * self.mode[i] as f64 <= 0.0 {
                v[i] = 0.0;
            }
        }
    }

    /// The Coulomb friction's work over an accepted step: −F·|Δq| on each sliding joint.
    fn book(&mut self, q_before: &[f64], q_after: &[f64]) {
        for i in 0..q_before.len() {
            if self.mode[i] != 0 {
                self.work += self.sliding(i, self.mode[i]) * (q_after[i] - q_before[i]);
            }
        }
    }
}
