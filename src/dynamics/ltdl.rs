use nalgebra::DMatrix;

/// In-place LᵀDL factorization of a joint-space matrix with the tree's sparsity (Featherstone, RBDA
/// §6.5): entry (i, j) of M is non-zero only when one joint supports the other, so the factor has the
/// same pattern and costs Σ depth² instead of n³/6. `parent[k]` is joint k's parent joint (smaller
/// index). On return the strict lower triangle holds L (unit diagonal implied) and the diagonal D.
/// Returns false if a pivot is not positive (not positive definite).
pub fn ltdl_in_place(a: &mut DMatrix<f64>, parent: &[Option<usize>]) -> bool {
    let n = a.nrows();
    for k in (0..n).rev() {
        let d = a[(k, k)];
        if !(d > 0.0) {
            return false;
        }
        let mut i = parent[k];
        while let Some(ii) = i {
            let factor = a[(k, ii)] / d;
            let mut j = Some(ii);
            while let Some(jj) = j {
                a[(ii, jj)] -= factor * a[(k, jj)];
                j = parent[jj];
            }
            a[(k, ii)] = factor;
            i = parent[ii];
        }
    }
    true
}

/// Solve LᵀDL x = b in place, with the factor of [`ltdl_in_place`].
pub fn ltdl_solve_in_place(l: &DMatrix<f64>, parent: &[Option<usize>], b: &mut [f64]) {
    let n = l.nrows();
    for i in (0..n).rev() {
        let mut j = parent[i];
        while let Some(jj) = j {
            b[jj] -= l[(i, jj)] * b[i];
            j = parent[jj];
        }
    }
    for i in 0..n {
        b[i] /= l[(i, i)];
    }
    for i in 0..n {
        let mut j = parent[i];
        while let Some(jj) = j {
            b[i] -= l[(i, jj)] * b[jj];
            j = parent[jj];
        }
    }
}
