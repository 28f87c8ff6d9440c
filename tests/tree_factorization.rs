//! The discrete plant factorizes M + h·D along a branched tree's sparsity (LᵀDL); it must solve the
//! same system as a dense Cholesky, to round-off, on the real trees it is for.

mod common;

use armscope::dynamics::{Data, crba, ltdl_in_place, ltdl_solve_in_place};
use armscope::model::load_urdf;
use nalgebra::{DMatrix, DVector};

#[test]
fn the_tree_factorization_solves_what_a_dense_cholesky_solves() {
    for file in ["tiago.urdf", "allegro_right_hand.urdf"] {
        let model = load_urdf(&common::repo().join("tests/fixtures/robots").join(file)).unwrap();
        let n = model.dof();
        let parents: Vec<Option<usize>> = model.bodies.iter().map(|b| b.parent).collect();
        let mut data = Data::new(&model);
        for seed in 0..5 {
            let q: Vec<f64> = model.joints.iter().enumerate().map(|(i, j)| {
                let x = ((i * 7 + seed * 13) % 11) as f64 / 10.0 - 0.5;
                if j.lower.is_finite() && j.upper.is_finite() { j.lower + (x + 0.5) * (j.upper - j.lower) } else { x }
            }).collect();
            let mut a: DMatrix<f64> = crba(&model, &mut data, &q).clone();
            for (i, j) in model.joints.iter().enumerate() {
                a[(i, i)] += 1e-3 * j.damping;
            }
            let b = DVector::from_iterator(n, (0..n).map(|i| (i as f64 * 0.37 + seed as f64).sin()));
            let want = a.clone().cholesky().expect("positive definite").solve(&b);
            let mut factor = a.clone();
            assert!(ltdl_in_place(&mut factor, &parents), "{file}");
            let mut x: Vec<f64> = b.iter().copied().collect();
            ltdl_solve_in_place(&factor, &parents, &mut x);
            let residual = (&a * DVector::from_column_slice(&x) - &b).amax();
            let error = (DVector::from_column_slice(&x) - &want).amax() / want.amax();
            assert!(error < 1e-10 && residual < 1e-10 * b.amax(), "{file}: relative difference {error:e}, residual {residual:e}");
        }
    }
}
