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
///
/// The composite inertias are kept in their ten numbers (world frame, so a child's is added to its
/// parent's as it is), and each body's force set F_i = I_i^c·S_i is projected on the motion
/// subspaces of its ancestors: M_ij = S_jᵀ·F_i, only the entries of the body and its supports.
pub fn crba_from_kinematics(model: &Model, data: &mut Data) {
    let b = model.bodies.len();
    let n = model.dof();
    data.composite_inertia[..b].copy_from_slice(&data.body_inertia[..b]);
    let coupled = model.has_mimic();
    let mass = data.mass_matrix.as_mut_slice(); // column-major: (row, column) at row + column·n
    if coupled {
        mass.fill(0.0);
    }
    // Without mimic joints body i is coordinate i, and only the entries (i, j) with j supporting i
    // (and their mirror) are non-zero: they are all written below, and the others keep the zero
    // they got in Data::new, so the matrix is not cleared first.
    //
    // Children have larger indices, so a body's composite inertia is complete when the reverse
    // sweep reaches it.
    for i in (0..b).rev() {
        let force = data.composite_inertia[i].mul_motion(&data.motion_subspace[i]);
        let ci = model.couplings[i].coordinate;
        let diagonal = data.motion_subspace[i].dot(&force);
        let mut ancestor = model.bodies[i].parent;
        if coupled {
            mass[ci + ci * n] += diagonal;
            while let Some(j) = ancestor {
                let m = data.motion_subspace[j].dot(&force);
                let cj = model.couplings[j].coordinate;
                mass[ci + cj * n] += m;
                mass[cj + ci * n] += m;
                ancestor = model.bodies[j].parent;
            }
        } else {
            mass[i + i * n] = diagonal;
            while let Some(j) = ancestor {
                let m = data.motion_subspace[j].dot(&force);
                mass[i + j * n] = m;
                mass[j + i * n] = m;
                ancestor = model.bodies[j].parent;
            }
        }
        if let Some(p) = model.bodies[i].parent {
            let c = data.composite_inertia[i];
            data.composite_inertia[p] += c;
        }
    }
    // the motors' rotors, J_r·N² on the diagonal (Drake: M.diagonal() += reflected_inertia)
    for (c, a) in model.armature.iter().enumerate() {
        mass[c + c * n] += a;
    }
}
