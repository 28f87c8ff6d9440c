use super::Plant;
use super::floor_contact::{FloorContact, FloorSolve};
use super::joint_friction::JointFriction;
use super::stick_slip::{JointLaw, StickSlipSolver};
use crate::actuator::LossyGear;
use crate::dynamics::{Data, crba_from_kinematics, forward_kinematics, gravity_and_bias_from_kinematics};
use crate::model::Model;

/// Drake's discrete MultibodyPlant without contact (but for an optional floor under one point,
/// [`FloorContact`], its work booked with the friction's): semi-implicit Euler with the joint damping
/// taken implicitly, everything evaluated at the start of the step,
///
/// ```text
///   (M(q₀) + h·D) · v₁ = M(q₀)·v₀ + h·( u + τ_g(q₀) − C(q₀,v₀)·v₀ )
///   q₁ = q₀ + h·v₁
/// ```
///
/// plus position limits as rigid one-sided constraints on v₁ (a joint that would pass its limit
/// stops exactly at it) and Coulomb friction as a bounded impulse −h·F⁺ ≤ h·τ_f ≤ h·F⁻ opposing v₁,
/// or holding the joint exactly still (v₁ = 0) when the rest of the step's impulse on it is within
/// that band — all solved exactly together ([`StickSlipSolver`]), coupled through M + hD. The band
/// is the URDF's friction plus the gearbox's losses for the step's motor torque ([`JointFriction`]:
/// wider against a back-driving load, locked on a self-locking gear's back-driven side); the
/// gear's viscous friction joins D. Several substeps per control period when the plant step is
/// shorter than the control period.
pub struct DiscretePlant {
    pub time_step: f64,
    pub substeps: usize,
    /// Each joint's Coulomb band and the gears' viscous friction.
    friction: JointFriction,
    /// Per joint: whether the last step's upper / lower velocity bound was a self-locking gear's
    /// lock rather than the position limit.
    locked: Vec<(bool, bool)>,
    /// h·D, added to M's diagonal: computed each step from the model's damping and the plant's
    /// time step (a cached copy would go stale when `time_step` changes).
    damping_step: Vec<f64>,
    rhs: Vec<f64>,
    v_next: Vec<f64>,
    residual: Vec<f64>,
    laws: Vec<JointLaw>,
    /// Each joint's friction bounds (F⁺, F⁻) of the last step (its law's, and its friction's after).
    bounds: Vec<(f64, f64)>,
    solver: StickSlipSolver,
    limit_active: Vec<bool>,
    friction_torque: Vec<f64>,
    stuck: Vec<bool>,
    /// Work of the friction over the last `advance` (≤ 0), J.
    friction_work: f64,
    /// A floor under a point of the arm, if any.
    floor: Option<FloorSolve>,
}

impl DiscretePlant {
    /// The plant with the model's joint friction (0: none, Drake's update exactly).
    pub fn new(model: &Model, time_step: f64, substeps: usize) -> Self {
        Self::with_gears(model, time_step, substeps, &[])
    }

    /// The plant with the model's joint friction and the drive trains' gear losses (by coordinate).
    pub fn with_gears(model: &Model, time_step: f64, substeps: usize, gears: &[Option<LossyGear>]) -> Self {
        Self::with_friction(model, time_step, substeps, JointFriction::new(model, gears))
    }

    /// The plant with the given joint friction (the URDF's, the gears', the servos').
    pub fn with_friction(model: &Model, time_step: f64, substeps: usize, friction: JointFriction) -> Self {
        let n = model.dof();
        Self {
            time_step,
            substeps,
            friction,
            locked: vec![(false, false); n],
            damping_step: vec![0.0; n],
            rhs: vec![0.0; n],
            v_next: vec![0.0; n],
            residual: vec![0.0; n],
            laws: vec![JointLaw::FREE; n],
            bounds: vec![(0.0, 0.0); n],
            solver: StickSlipSolver::new(n, branched_tree(model)),
            limit_active: vec![false; n],
            friction_torque: vec![0.0; n],
            stuck: vec![false; n],
            friction_work: 0.0,
            floor: None,
        }
    }

    /// The plant with a floor under a point of the arm.
    pub fn with_floor(mut self, contact: FloorContact, dof: usize) -> Self {
        self.floor = Some(FloorSolve::new(contact, dof));
        self
    }

    /// One plant step; `data` must hold kinematics, τ_g and C·v at (q, v).
    pub fn step(&mut self, model: &Model, data: &mut Data, u: &[f64], q: &mut [f64], v: &mut [f64]) {
        let n = model.dof();
        let h = self.time_step;
        crba_from_kinematics(model, data);
        // b = M·v + h·(u + τ_g − C·v); row i of M·v from column i (M is symmetric and stored by
        // columns), summed over j in order
        let mass = data.mass_matrix.as_slice();
        for (i, (b, column)) in self.rhs.iter_mut().zip(mass.chunks_exact(n)).enumerate() {
            let mut momentum = 0.0;
            for (mij, vj) in column.iter().zip(v.iter()) {
                momentum += mij * vj;
            }
            *b = momentum + h * (u[i] + data.gravity[i] - data.bias[i]);
        }
        // each joint's h·D, velocity bounds (the limits reached at the step's end) and friction impulses
        if self.friction.any {
            if self.friction.has_servos() {
                self.friction.observe(&data.gravity, v);
            }
            self.friction.all_bounds(u, &mut self.bounds);
            for (i, joint) in model.joints.iter().enumerate() {
                self.damping_step[i] = h * (joint.damping + self.friction.viscous(i));
                let (law, locked_up, locked_down) = JointFriction::law_of(self.bounds[i], h, (joint.lower - q[i]) / h, (joint.upper - q[i]) / h);
                self.laws[i] = law;
                self.locked[i] = (locked_up, locked_down);
            }
        } else {
            // without friction or gear losses only the limits bound a joint (the same laws)
            for (((joint, damping), law), q) in model.joints.iter().zip(&mut self.damping_step).zip(&mut self.laws).zip(&*q) {
                *damping = h * joint.damping;
                *law = JointLaw { lower: (joint.lower - q) / h, upper: (joint.upper - q) / h, ..JointLaw::FREE };
            }
        }
        // M + hD is symmetric positive definite for any valid model; a failure means the state is
        // no longer finite, which the simulation loop reports as divergence
        let mut solved = self.solver.solve(mass, &self.damping_step, &self.rhs, &self.laws, &mut self.v_next, &mut self.residual);
        if let (Ok(()), Some(floor)) = (&solved, self.floor.as_mut()) {
            solved = floor.impose(model, data, h, v, &mut self.solver, mass, &self.damping_step, &self.rhs, &self.laws, &mut self.v_next, &mut self.residual);
            self.friction_work += floor.work;
        }
        if solved.is_err() {
            self.v_next.fill(f64::NAN);
        }
        for i in 0..n {
            let v_before = v[i];
            v[i] = self.v_next[i];
            q[i] += h * v[i];
            let side = match self.solver.limit_side(i) {
                // held by a self-locking gear, not by the limit
                1 if self.locked[i].0 => 0,
                -1 if self.locked[i].1 => 0,
                side => side,
            };
            if side != 0 {
                // land exactly on the limit, not a rounding error past it
                q[i] = if side > 0 { model.joints[i].upper } else { model.joints[i].lower };
                self.limit_active[i] = true;
            }
            // the friction's work, booked at the step's mean speed as the energy audit books the
            // torques and damping (a limit's inelastic stop is not booked: it only takes energy)
            let mean = 0.5 * (v_before + v[i]);
            if self.friction.has(i) {
                let torque = self.friction_on(i, side, v[i]);
                self.friction_torque[i] = torque;
                self.stuck[i] = v[i] == 0.0;
                // the gear's viscous friction is booked here too (the audit books the URDF's damping)
                self.friction_work += h * (torque * mean - self.friction.viscous(i) * mean * mean);
            }
        }
    }

    /// The Coulomb friction torque on joint i after a step: −g/h within its band; at rest on a
    /// limit the limit takes what pushes into it, the friction only what pulls away.
    fn friction_on(&self, i: usize, side: i8, v: f64) -> f64 {
        let g = self.residual[i] / self.time_step;
        let g = if side != 0 && v == 0.0 { if side > 0 { g.min(0.0) } else { g.max(0.0) } } else { g };
        let (up, down) = self.bounds[i];
        (-g).clamp(-up, down)
    }

    /// The control period's plant steps, each by `step`; the kinematics, τ_g and C·v it needs are
    /// computed for every step after the first (the loop computed them for the first).
    fn over_substeps(&mut self, model: &Model, data: &mut Data, q: &mut [f64], v: &mut [f64], mut step: impl FnMut(&mut Self, &mut Data, &mut [f64], &mut [f64])) {
        self.limit_active.fill(false);
        self.friction_work = 0.0;
        for s in 0..self.substeps {
            if s > 0 {
                forward_kinematics(model, data, q);
                gravity_and_bias_from_kinematics(model, data, v);
            }
            step(self, data, q, v);
        }
    }
}

impl Plant for DiscretePlant {
    fn advance(&mut self, model: &Model, data: &mut Data, u: &[f64], q: &mut [f64], v: &mut [f64]) {
        self.over_substeps(model, data, q, v, |plant, data, q, v| plant.step(model, data, u, q, v));
    }

    fn advance_driven(&mut self, model: &Model, data: &mut Data, u: &mut [f64], torque: &mut dyn FnMut(f64, &[f64], &[f64], &mut [f64]), q: &mut [f64], v: &mut [f64]) {
        self.over_substeps(model, data, q, v, |plant, data, q, v| {
            torque(plant.time_step, q, v, u);
            plant.step(model, data, u, q, v)
        });
    }

    fn limit_active(&self) -> &[bool] {
        &self.limit_active
    }

    fn friction_torque(&self) -> &[f64] {
        &self.friction_torque
    }

    fn stuck(&self) -> &[bool] {
        &self.stuck
    }

    fn friction_work(&self) -> f64 {
        self.friction_work
    }

    fn describe(&self) -> String {
        format!(
            "discrete plant: semi-implicit Euler, implicit joint damping (Drake's update){}, h = {} ms{}",
            if self.friction.has_servos() { ", exact Coulomb stick–slip with the servos' friction budgets" } else if self.friction.has_gears() { ", exact Coulomb stick–slip with the gearboxes' losses" } else if self.friction.any { ", exact Coulomb stick–slip" } else { "" },
            self.time_step * 1e3,
            if self.substeps > 1 { format!(", {} steps per control period", self.substeps) } else { String::new() },
        ) + &self.floor.as_ref().map_or(String::new(), |f| format!(", a floor at z = {} m under one point of the arm", f.contact.height))
    }
}

/// Each joint's parent joint when the model is a branched tree without `<mimic>` joints (then M has
/// the tree's sparsity in its coordinates); None for a chain or a coupled model.
fn branched_tree(model: &Model) -> Option<Vec<Option<usize>>> {
    if model.has_mimic() {
        return None;
    }
    let parents: Vec<Option<usize>> = model.bodies.iter().map(|b| b.parent).collect();
    let mut children = vec![0usize; parents.len()];
    let mut roots = 0;
    for p in &parents {
        match p {
            Some(p) => children[*p] += 1,
            None => roots += 1,
        }
    }
    (roots > 1 || children.iter().any(|&c| c > 1)).then_some(parents)
}
