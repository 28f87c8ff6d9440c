use super::Plant;
use crate::dynamics::{Data, aba};
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
    /// Accepted and rejected steps so far.
    pub accepted_steps: u64,
    pub rejected_steps: u64,
}

impl ContinuousPlant {
    pub fn new(model: &Model, period: f64, tolerances: Tolerances) -> Self {
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
            accepted_steps: 0,
            rejected_steps: 0,
        }
    }

    /// ẏ = (q̇, q̈) with q̈ from ABA, damping included.
    fn derivative(&mut self, model: &Model, data: &mut Data, u: &[f64], stage: usize) {
        let n = self.n;
        let (q, v) = self.y_stage.split_at(n);
        for i in 0..n {
            self.tau[i] = u[i] - model.joints[i].damping * v[i];
        }
        let qdd = aba(model, data, q, v, &self.tau);
        let k = &mut self.k[stage];
        k[..n].copy_from_slice(v);
        k[n..].copy_from_slice(qdd);
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
            let err = self.error_norm(h);
            if err.is_finite() && err <= 1.0 {
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
