use super::{Data, forward_kinematics};
use crate::model::Model;

/// The joint-space mass matrix M(q), into `data.mass_matrix` (both triangles). Entries of joints on
/// different branches are never written and stay zero.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d nalgebra::DMatrix<f64> {
    forward_kinematics(model, data, q);
    crba_from_kinematics(model, data);
    &data.mass_matrix
}

/// CRBA assuming `forward_kinematics` was run for the current q.
pub fn crba_from_kinematics(model: &Model, data: &mut Data) {
    let n = model.dof();
    data.composite_inertia[..n].copy_from_slice(&data.body_inertia[..n]);
    // Children have larger indices, so a body's composite inertia is complete when the reverse
    // sweep reaches it.
    for i in (0..n).rev() {
        let force = data.composite_inertia[i] * data.motion_subspace[i];
        data.mass_matrix[(i, i)] = data.motion_subspace[i].dot(&force);
        let mut ancestor = model.joints[i].parent;
        while let Some(j) = ancestor {
            let m = data.motion_subspace[j].dot(&force);
            data.mass_matrix[(i, j)] = m;
            data.mass_matrix[(j, i)] = m;
            ancestor = model.joints[j].parent;
        }
        if let Some(p) = model.joints[i].parent {
            let c = data.composite_inertia[i];
            data.composite_inertia[p] += c;
        }
    }
}
