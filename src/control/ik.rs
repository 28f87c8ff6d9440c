//! Inverse kinematics of the tool position by damped least squares on the Jacobian, and the
//! trajectory lab's shapes on a drawing plane in front of the arm.

use crate::dynamics::{Data, forward_kinematics, frame_jacobian, frame_pose};
use crate::model::Model;
use nalgebra::{DMatrix, Matrix3, Vector3};

/// Solves for the tool position with a subset of joints moving, the others held.
pub struct PositionIk<'m> {
    model: &'m Model,
    data: Data,
    jacobian: DMatrix<f64>,
    /// The joints that move (the tutorial: J1–J3, the wrist locked at 0).
    pub joints: Vec<usize>,
    /// Damping λ of (J Jᵀ + λ² I)⁻¹.
    pub damping: f64,
    pub tolerance: f64,
    pub max_iterations: usize,
}

impl<'m> PositionIk<'m> {
    pub fn new(model: &'m Model, joints: Vec<usize>) -> Self {
        Self { model, data: Data::new(model), jacobian: DMatrix::zeros(6, model.dof()), joints, damping: 1e-3, tolerance: 1e-8, max_iterations: 500 }
    }

    pub fn tool_position(&mut self, q: &[f64]) -> Vector3<f64> {
        forward_kinematics(self.model, &mut self.data, q);
        frame_pose(self.model, &self.data, self.model.tool_frame).translation
    }

    /// Move `q` (starting from its value) until the tool is at `target`; returns the final error (m).
    pub fn solve(&mut self, target: &Vector3<f64>, q: &mut [f64]) -> f64 {
        let mut error = f64::INFINITY;
        for _ in 0..self.max_iterations {
            let p = self.tool_position(q);
            let e = target - p;
            error = e.norm();
            if error < self.tolerance {
                break;
            }
            frame_jacobian(self.model, &self.data, self.model.tool_frame, &mut self.jacobian);
            // J restricted to the moving joints, position rows only
            let jp = DMatrix::from_fn(3, self.joints.len(), |r, c| self.jacobian[(r + 3, self.joints[c])]);
            let jjt: Matrix3<f64> = Matrix3::from_iterator((&jp * jp.transpose()).iter().copied()) + Matrix3::identity() * self.damping.powi(2);
            let Some(inv) = jjt.try_inverse() else { break };
            let dq = jp.transpose() * (inv * e);
            for (c, &j) in self.joints.iter().enumerate() {
                let joint = &self.model.joints[j];
                q[j] = (q[j] + dq[c]).clamp(joint.lower, joint.upper);
            }
        }
        error
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Shape {
    Sine,
    Circle,
    Triangle,
}

/// A shape on a vertical plane facing the arm (normal along x).
#[derive(Clone, Debug)]
pub struct Drawing {
    pub shape: Shape,
    pub centre: Vector3<f64>,
    /// Half-width of the shape, m.
    pub size: f64,
}

impl Drawing {
    /// The point at phase s ∈ [0, 1].
    pub fn point(&self, s: f64) -> Vector3<f64> {
        let (y, z) = match self.shape {
            Shape::Circle => {
                let a = 2.0 * std::f64::consts::PI * s;
                (a.cos(), a.sin())
            }
            Shape::Sine => {
                // across and back, two periods of a sine each way
                let u = if s < 0.5 { 4.0 * s - 1.0 } else { 3.0 - 4.0 * s };
                (u, 0.35 * (2.0 * std::f64::consts::PI * u).sin())
            }
            Shape::Triangle => {
                let corners: Vec<(f64, f64)> = (0..3).map(|k| {
                    let a = std::f64::consts::FRAC_PI_2 + 2.0 * std::f64::consts::PI * k as f64 / 3.0;
                    (a.cos(), a.sin())
                }).collect();
                let x = 3.0 * s.clamp(0.0, 1.0);
                let k = (x.floor() as usize).min(2);
                let f = x - k as f64;
                let (a, b) = (corners[k], corners[(k + 1) % 3]);
                (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1))
            }
        };
        self.centre + Vector3::new(0.0, y * self.size, z * self.size)
    }
}

/// A drawing plane in front of the arm: 3/4 of the way out to the tool's reach at the zero pose,
/// at the tool's height there, sized to a sixth of that reach.
pub fn default_drawing(model: &Model, shape: Shape) -> Drawing {
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, &vec![0.0; model.dof()]);
    let p = frame_pose(model, &data, model.tool_frame).translation;
    let reach = (p.x * p.x + p.y * p.y).sqrt();
    Drawing { shape, centre: Vector3::new(0.75 * reach, 0.0, p.z), size: reach / 6.0 }
}

/// The joint schedule that draws `drawing` in `duration` seconds, sampled every `step` seconds:
/// times, joint positions, tool targets. The first point is solved from several starting poses
/// (the one with the smallest joint motion wins), every later one from its predecessor.
pub fn solve_drawing(model: &Model, drawing: &Drawing, joints: Vec<usize>, duration: f64, step: f64) -> Result<(Vec<f64>, Vec<Vec<f64>>, Vec<Vector3<f64>>), String> {
    let mut ik = PositionIk::new(model, joints.clone());
    let n = model.dof();
    let samples = (duration / step).round() as usize;
    let first = drawing.point(0.0);
    let mut best: Option<(f64, Vec<f64>)> = None;
    for guess in [[0.0, 0.0], [-0.5, 1.0], [0.5, -1.0], [-1.0, 1.5], [1.0, -1.5]] {
        let mut q = vec![0.0; n];
        for (k, &j) in joints.iter().enumerate().skip(1).take(2) {
            q[j] = guess[k - 1];
        }
        if ik.solve(&first, &mut q) < 1e-6 {
            let size: f64 = q.iter().map(|x| x * x).sum();
            if best.as_ref().is_none_or(|(s, _)| size < *s) {
                best = Some((size, q));
            }
        }
    }
    let (_, mut q) = best.ok_or_else(|| format!("the shape's first point ({:.3}, {:.3}, {:.3}) m is out of reach", first.x, first.y, first.z))?;
    let (mut times, mut positions, mut targets) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..=samples {
        let t = k as f64 * step;
        let target = drawing.point(t / duration);
        let error = ik.solve(&target, &mut q);
        if error > 1e-6 {
            return Err(format!("point ({:.3}, {:.3}, {:.3}) m at t = {t:.3} s is out of reach (IK error {:.2e} m)", target.x, target.y, target.z, error));
        }
        times.push(t);
        positions.push(q.clone());
        targets.push(target);
    }
    Ok((times, positions, targets))
}
