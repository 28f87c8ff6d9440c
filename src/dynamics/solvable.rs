//! Whether a model's plant can be solved at all: its mass matrix at q = 0 finite and positive
//! definite. A URDF (or a payload) can hold numbers that pass every check of their own and still
//! give neither: a massless link 1e308 m away overflows the products, and a 1e308 kg tool swamps the
//! joints' own 1e-4 kg·m² so that M's last row rounds to zero. The loader parses; this is the
//! dynamics' verdict on what it built, asked where a model is about to be simulated or inspected
//! (`Experiment`, `armscope model`, `armscope size`).

use super::{Data, crba};
use crate::model::{Model, ModelError, ModelErrorKind};

/// `Ok` when the plant can be solved for `model`; else the one-line error naming the first joint
/// whose row of the mass matrix is not finite or whose inertia the factorization cannot find.
pub fn check_solvable(model: &Model) -> Result<(), ModelError> {
    let fail = |kind| ModelError { file: model.source.clone(), kind };
    let mut data = Data::new(model);
    let m = crba(model, &mut data, &vec![0.0; model.dof()]);
    if let Some(j) = (0..model.dof()).find(|&j| m.row(j).iter().any(|x| !x.is_finite())) {
        return Err(fail(ModelErrorKind::NonFinite { element: format!("link '{}'", model.joints[j].child_link), field: "mass matrix (numbers too large)", value: f64::INFINITY }));
    }
    if let Some(j) = first_singular_coordinate(m) {
        return Err(fail(ModelErrorKind::MassMatrixSingular { joint: model.joints[j].name.clone(), link: model.joints[j].child_link.clone() }));
    }
    Ok(())
}

/// The first coordinate j for which the leading (j+1)×(j+1) block of `m` is not positive definite
/// (None when `m` is): the joint whose inertia the factorization cannot find.
fn first_singular_coordinate(m: &nalgebra::DMatrix<f64>) -> Option<usize> {
    if m.clone().cholesky().is_some() {
        return None;
    }
    // only on the way to an error: each leading block in turn
    (0..m.nrows()).find(|&j| m.view((0, 0), (j + 1, j + 1)).clone_owned().cholesky().is_none())
}
