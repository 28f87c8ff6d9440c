use super::{Data, gravity_forces};
use crate::model::Model;
use nalgebra::DMatrix;

/// G = ∂τ_g/∂q at `q`, by central differences (step 1e-6).
pub fn gravity_stiffness(model: &Model, data: &mut Data, q: &[f64]) -> DMatrix<f64> {
    let n = model.dof();
    let eps = 1e-6;
    let mut stiffness = DMatrix::zeros(n, n);
    let mut qp = q.to_vec();
    for j in 0..n {
        qp[j] = q[j] + eps;
        let plus = gravity_forces(model, data, &qp).to_vec();
        qp[j] = q[j] - eps;
        let minus = gravity_forces(model, data, &qp).to_vec();
        qp[j] = q[j];
        for i in 0..n {
            stiffness[(i, j)] = (plus[i] - minus[i]) / (2.0 * eps);
        }
    }
    stiffness
}
