use super::{Data, forward_kinematics};
use crate::model::Model;

/// The joint-space mass matrix M(q), into `data.mass_matrix` (both triangles). With `<mimic>`
/// joints, the matrix of the coordinates: GᵀM_bodies G, each body's entries added into its
/// coordinate's row and column. The motors' reflected inertias are on its diagonal.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d nalgebra::DMatrix<f64> {
    forward_kinematics(model, data, q);
    crba_from_kinematics(model, data);
    &data.mass_matrix
}

/// CRBA assuming `forward_kinematics` was run for the current q.
pub fn crba_from_kinematics(model: &Model, data: &mut Data) {
    let b = model.bodies.len();
    data.composite_inertia[..b].copy_from_slice(&data.body_inertia[..b]);
    data.mass_matrix.fill(0.0);
    let coordinate = |i: usize| model.couplings[i].coordinate;
    // Children have larger indices, so a body's composite inertia is complete when the reverse
    // sweep reaches it.
    for i in (0..b).rev() {
        let force = data.composite_inertia[i] * data.motion_subspace[i];
        let ci = coordinate(i);
        data.mass_matrix[(ci, ci)] += data.motion_subspace[i].dot(&force);
        let mut ancestor = model.bodies[i].parent;
        while let Some(j) = ancestor {
            let m = data.motion_subspace[j].dot(&force);
            let cj = coordinate(j);
            data.mass_matrix[(ci, cj)] += m;
            data.mass_matrix[(cj, ci)] += m;
            ancestor = model.bodies[j].parent;
        }
        if let Some(p) = model.bodies[i].parent {
            let c = data.composite_inertia[i];
            data.composite_inertia[p] += c;
        }
    }
    // the motors' rotors, J_r·N² on the diagonal (Drake: M.diagonal() += reflected_inertia)
    for (c, a) in model.armature.iter().enumerate() {
        data.mass_matrix[(c, c)] += a;
    }
}
