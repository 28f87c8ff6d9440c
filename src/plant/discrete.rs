use super::Plant;
use crate::dynamics::{Data, cholesky_in_place, cholesky_solve_in_place, ltdl_in_place, ltdl_solve_in_place, crba_from_kinematics, forward_kinematics, gravity_and_bias_from_kinematics};
use crate::model::Model;
use nalgebra::DMatrix;

/// Drake's discrete MultibodyPlant without contact: semi-implicit Euler with the joint damping
/// taken implicitly, everything evaluated at the start of the step,
///
/// ```text
///   (M(q₀) + h·D) · v₁ = M(q₀)·v₀ + h·( u + τ_g(q₀) − C(q₀,v₀)·v₀ )
///   q₁ = q₀ + h·v₁
/// ```
///
/// plus position limits as rigid one-sided constraints on v₁: a joint that would pass its limit
/// stops exactly at it (an active-set solve of the same system). Several substeps per control
/// period when the plant step is shorter than the control period.
pub struct DiscretePlant {
    pub time_step: f64,
    pub substeps: usize,
    factor: DMatrix<f64>,
    rhs: Vec<f64>,
    reduced_rhs: Vec<f64>,
    v_next: Vec<f64>,
    /// −1 lower limit, +1 upper limit, 0 free.
    constraint: Vec<i8>,
    limit_active: Vec<bool>,
    /// A branched tree (and no `<mimic>`): M + hD factorized along the tree's sparsity (LᵀDL), each
    /// joint's parent joint here; a chain keeps the dense Cholesky (the same cost, and its rounding).
    tree_parents: Option<Vec<Option<usize>>>,
}

impl DiscretePlant {
    pub fn new(model: &Model, time_step: f64, substeps: usize) -> Self {
        let n = model.dof();
        Self {
            time_step,
            substeps,
            factor: DMatrix::zeros(n, n),
            rhs: vec![0.0; n],
            reduced_rhs: vec![0.0; n],
            v_next: vec![0.0; n],
            constraint: vec![0; n],
            limit_active: vec![false; n],
            tree_parents: branched_tree(model),
        }
    }

    /// One plant step; `data` must hold kinematics, τ_g and C·v at (q, v).
    pub fn step(&mut self, model: &Model, data: &mut Data, u: &[f64], q: &mut [f64], v: &mut [f64]) {
        let n = model.dof();
        let h = self.time_step;
        crba_from_kinematics(model, data);
        // b = M·v + h·(u + τ_g − C·v), M·v by columns (M is stored by columns)
        let mass = data.mass_matrix.as_slice();
        self.rhs.fill(0.0);
        for (column, vj) in mass.chunks_exact(n).zip(v.iter()) {
            for (b, mij) in self.rhs.iter_mut().zip(column) {
                *b += mij * vj;
            }
        }
        for i in 0..n {
            self.rhs[i] += h * (u[i] + data.gravity[i] - data.bias[i]);
        }
        self.constraint.fill(0);
        self.solve_with_limits(model, mass, q);
        for i in 0..n {
            v[i] = self.v_next[i];
            q[i] += h * v[i];
            if self.constraint[i] != 0 {
                // land exactly on the limit, not a rounding error past it
                q[i] = if self.constraint[i] > 0 { model.joints[i].upper } else { model.joints[i].lower };
                self.limit_active[i] = true;
            }
        }
    }

    /// The control period's plant steps, each by `step`; the kinematics, τ_g and C·v it needs are
    /// computed for every step after the first (the loop computed them for the first).
    fn over_substeps(&mut self, model: &Model, data: &mut Data, q: &mut [f64], v: &mut [f64], mut step: impl FnMut(&mut Self, &mut Data, &mut [f64], &mut [f64])) {
        self.limit_active.fill(false);
        for s in 0..self.substeps {
            if s > 0 {
                forward_kinematics(model, data, q);
                gravity_and_bias_from_kinematics(model, data, v);
            }
            step(self, data, q, v);
        }
    }

    /// Active-set solve: start unconstrained, fix the velocity of every joint that would pass its
    /// limit to the velocity that lands on it, release a joint whose constraint would have to pull.
    fn solve_with_limits(&mut self, model: &Model, mass: &[f64], q: &[f64]) {
        let n = model.dof();
        let h = self.time_step;
        for _ in 0..(2 * n + 2) {
            self.solve_reduced(model, mass, q);
            let mut changed = false;
            for i in 0..n {
                let joint = &model.joints[i];
                match self.constraint[i] {
                    0 => {
                        let q_next = q[i] + h * self.v_next[i];
                        if q_next > joint.upper {
                            self.constraint[i] = 1;
                            changed = true;
                        } else if q_next < joint.lower {
                            self.constraint[i] = -1;
                            changed = true;
                        }
                    }
                    side => {
                        // impulse the constraint applies: λ = (A v − b)_i; an upper stop may only push down
                        // (A v)_i = Σ_j M_ij v_j + h·D_i·v_i, row i of the symmetric M read as its column i
                        let mut lambda = -self.rhs[i] + h * joint.damping * self.v_next[i];
                        for (mij, vj) in mass[i * n..(i + 1) * n].iter().zip(&self.v_next) {
                            lambda += mij * vj;
                        }
                        if lambda * side as f64 > 0.0 {
                            self.constraint[i] = 0;
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                return;
            }
        }
    }

    fn solve_reduced(&mut self, model: &Model, mass: &[f64], q: &[f64]) {
        let n = model.dof();
        let h = self.time_step;
        self.factor.as_mut_slice().copy_from_slice(mass);
        // A = M + h·D
        for (i, joint) in model.joints.iter().enumerate() {
            self.factor[(i, i)] += h * joint.damping;
        }
        self.reduced_rhs.copy_from_slice(&self.rhs);
        for j in 0..n {
            if self.constraint[j] == 0 {
                continue;
            }
            let limit = if self.constraint[j] > 0 { model.joints[j].upper } else { model.joints[j].lower };
            let v_fixed = (limit - q[j]) / h;
            for i in 0..n {
                self.reduced_rhs[i] -= self.factor[(i, j)] * v_fixed;
                self.factor[(i, j)] = 0.0;
                self.factor[(j, i)] = 0.0;
            }
            self.factor[(j, j)] = 1.0;
            self.reduced_rhs[j] = v_fixed;
        }
        // M + hD is symmetric positive definite for any valid model; a failure means the state is
        // no longer finite, which the simulation loop reports as divergence.
        let factored = match &self.tree_parents {
            Some(parents) => ltdl_in_place(&mut self.factor, parents),
            None => cholesky_in_place(&mut self.factor),
        };
        if !factored {
            self.v_next.fill(f64::NAN);
            return;
        }
        self.v_next.copy_from_slice(&self.reduced_rhs);
        match &self.tree_parents {
            Some(parents) => ltdl_solve_in_place(&self.factor, parents, &mut self.v_next),
            None => cholesky_solve_in_place(&self.factor, &mut self.v_next),
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

    fn describe(&self) -> String {
        format!(
            "discrete plant: semi-implicit Euler, implicit joint damping (Drake's update), h = {} ms{}",
            self.time_step * 1e3,
            if self.substeps > 1 { format!(", {} steps per control period", self.substeps) } else { String::new() }
        )
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
