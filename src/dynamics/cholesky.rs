use nalgebra::DMatrix;

/// In-place Cholesky factorization A = L·Lᵀ of a symmetric positive definite matrix: L is left in
/// the lower triangle. Returns false (and leaves `a` partly overwritten) if A is not positive
/// definite. No allocation.
pub fn cholesky_in_place(a: &mut DMatrix<f64>) -> bool {
    let n = a.nrows();
    // by columns (the storage order): column j of L from the columns before it, each column k < j
    // read from its row j down; the products are summed in the same order k = 0, 1, … as
    // L_ij = (A_ij − Σ_k L_ik·L_jk) / L_jj writes them
    let a = a.as_mut_slice();
    for j in 0..n {
        let (done, rest) = a.split_at_mut(j * n);
        let column = &mut rest[..n];
        let mut d = column[j];
        for k in 0..j {
            let l = done[j + k * n];
            d -= l * l;
        }
        if !(d > 0.0) {
            return false;
        }
        let d = d.sqrt();
        column[j] = d;
        for i in (j + 1)..n {
            let mut s = column[i];
            for k in 0..j {
                s -= done[i + k * n] * done[j + k * n];
            }
            column[i] = s / d;
        }
    }
    true
}

/// Solve L·Lᵀ x = b in place, with L from [`cholesky_in_place`].
pub fn cholesky_solve_in_place(l: &DMatrix<f64>, b: &mut [f64]) {
    let n = l.nrows();
    let l = l.as_slice();
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i + k * n] * b[k];
        }
        b[i] = s / l[i + i * n];
    }
    for i in (0..n).rev() {
        // row i of Lᵀ is column i of L, contiguous
        let column = &l[i * n..(i + 1) * n];
        let mut s = b[i];
        for k in (i + 1)..n {
            s -= column[k] * b[k];
        }
        b[i] = s / column[i];
    }
}
