use nalgebra::DMatrix;

/// In-place LDLᵀ factorization A = L·D·Lᵀ of a symmetric positive definite matrix (L unit lower
/// triangular, D diagonal): L is left in the strict lower triangle, D on the diagonal. Returns false
/// (and leaves `a` partly overwritten) if a pivot is not positive (A not positive definite). No
/// allocation.
///
/// Chosen over Cholesky for the plant's solve because its chain of dependent operations is shorter
/// — no square root per column, and the substitution divides by D once per entry, all independent,
/// instead of once per row of each triangular solve — which is what a small system's time is.
pub fn ldlt_in_place(a: &mut DMatrix<f64>) -> bool {
    let n = a.nrows();
    ldlt_in_place_slice(a.as_mut_slice(), n)
}

/// [`ldlt_in_place`] on an n×n matrix stored by columns in a slice (a workspace sized for the
/// largest system it will hold).
pub fn ldlt_in_place_slice(a: &mut [f64], n: usize) -> bool {
    // an arm's size known at compile time: the loops unroll with no bounds checks (the 6-joint
    // arm's plant step 7 % faster than with the general loops alone)
    match n {
        1 => factor::<1>(a),
        2 => factor::<2>(a),
        3 => factor::<3>(a),
        4 => factor::<4>(a),
        5 => factor::<5>(a),
        6 => factor::<6>(a),
        7 => factor::<7>(a),
        _ => factor_any(a, n),
    }
}

/// Solve L·D·Lᵀ x = b in place, with the factor of [`ldlt_in_place`].
pub fn ldlt_solve_in_place(factor: &DMatrix<f64>, b: &mut [f64]) {
    ldlt_solve_slice(factor.as_slice(), b, factor.nrows());
}

/// [`ldlt_solve_in_place`] with the factor of [`ldlt_in_place_slice`].
pub fn ldlt_solve_slice(l: &[f64], b: &mut [f64], n: usize) {
    match n {
        1 => substitute::<1>(l, b),
        2 => substitute::<2>(l, b),
        3 => substitute::<3>(l, b),
        4 => substitute::<4>(l, b),
        5 => substitute::<5>(l, b),
        6 => substitute::<6>(l, b),
        7 => substitute::<7>(l, b),
        _ => substitute_any(l, b, n),
    }
}

/// The factorization on N×N columns of fixed size (column-major: `columns[k][i]` is entry (i, k)).
/// The same operations in the same order as [`factor_any`].
fn factor<const N: usize>(a: &mut [f64]) -> bool {
    let columns: &mut [[f64; N]; N] = a.as_chunks_mut::<N>().0.try_into().expect("an N×N matrix");
    let mut scaled = [0.0; N];
    for j in 0..N {
        // row j of L times D, which every entry of column j needs
        for k in 0..j {
            scaled[k] = columns[k][j] * columns[k][k];
        }
        let mut d = columns[j][j];
        for k in 0..j {
            d -= columns[k][j] * scaled[k];
        }
        if !(d > 0.0) {
            return false;
        }
        columns[j][j] = d;
        for i in (j + 1)..N {
            let mut s = columns[j][i];
            for k in 0..j {
                s -= columns[k][i] * scaled[k];
            }
            columns[j][i] = s / d;
        }
    }
    true
}

/// The factorization for any size: column j of L from the columns before it,
/// L_ij = (A_ij − Σ_k L_ik·D_k·L_jk) / D_j, D_j = A_jj − Σ_k L_jk·D_k·L_jk.
fn factor_any(a: &mut [f64], n: usize) -> bool {
    assert_eq!(a.len(), n * n);
    for j in 0..n {
        let (done, rest) = a.split_at_mut(j * n);
        let column = &mut rest[..n];
        let scaled = |k: usize| done[j + k * n] * done[k + k * n];
        let mut d = column[j];
        for k in 0..j {
            d -= done[j + k * n] * scaled(k);
        }
        if !(d > 0.0) {
            return false;
        }
        column[j] = d;
        for i in (j + 1)..n {
            let mut s = column[i];
            for k in 0..j {
                s -= done[i + k * n] * scaled(k);
            }
            column[i] = s / d;
        }
    }
    true
}

/// The substitution on N×N columns of fixed size; the same operations as [`substitute_any`].
fn substitute<const N: usize>(l: &[f64], b: &mut [f64]) {
    let columns: &[[f64; N]; N] = l.as_chunks::<N>().0.try_into().expect("an N×N matrix");
    let b: &mut [f64; N] = b.try_into().expect("N entries");
    for i in 0..N {
        let mut s = b[i];
        for k in 0..i {
            s -= columns[k][i] * b[k];
        }
        b[i] = s;
    }
    for i in 0..N {
        b[i] /= columns[i][i];
    }
    for i in (0..N).rev() {
        let mut s = b[i];
        for k in (i + 1)..N {
            s -= columns[i][k] * b[k];
        }
        b[i] = s;
    }
}

/// L y = b (unit lower), z = D⁻¹ y, Lᵀ x = z.
fn substitute_any(l: &[f64], b: &mut [f64], n: usize) {
    assert!(l.len() == n * n && b.len() == n);
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i + k * n] * b[k];
        }
        b[i] = s;
    }
    for i in 0..n {
        b[i] /= l[i + i * n];
    }
    for i in (0..n).rev() {
        // row i of Lᵀ is column i of L, contiguous
        let column = &l[i * n..(i + 1) * n];
        let mut s = b[i];
        for k in (i + 1)..n {
            s -= column[k] * b[k];
        }
        b[i] = s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    /// Symmetric positive definite test matrices of sizes 1–10, with entries of several magnitudes
    /// and a condition number of ~10⁴ (a light link far out on a heavy arm is of that order).
    fn spd(n: usize) -> DMatrix<f64> {
        let b = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 / 3.0 - 1.7 + 1e-3 * (i + j) as f64);
        &b * b.transpose() + DMatrix::from_fn(n, n, |i, j| if i == j { 1e-3 * (1 + i) as f64 } else { 0.0 })
    }

    #[test]
    fn solves_what_a_cholesky_solves() {
        for n in 1..=10 {
            let a = spd(n);
            let b = DVector::from_fn(n, |i, _| (i as f64 * 0.91).sin());
            let want = a.clone().cholesky().expect("positive definite").solve(&b);
            let mut factor = a.clone();
            assert!(ldlt_in_place(&mut factor), "n = {n}");
            let mut x = b.as_slice().to_vec();
            ldlt_solve_in_place(&factor, &mut x);
            // both are backward stable: they agree to the condition number times the rounding
            let scale = want.amax();
            for (got, want) in x.iter().zip(want.iter()) {
                assert!((got - want).abs() <= 1e-10 * scale, "n = {n}: {got} vs {want}");
            }
            // and A·x = b to rounding
            let residual = &a * DVector::from_column_slice(&x) - &b;
            assert!(residual.amax() < 1e-12 * a.amax() * scale.max(1.0), "n = {n}: residual {}", residual.amax());
        }
    }

    /// The loops specialized for a size give the general loop's bits (same operations, same order).
    #[test]
    fn sizes_known_at_compile_time_give_the_general_loops_bits() {
        for n in 1..=9 {
            let a = spd(n);
            let mut specialized = a.clone();
            assert!(ldlt_in_place(&mut specialized));
            let mut general = a.clone();
            assert!(factor_any(general.as_mut_slice(), n));
            assert_eq!(specialized.as_slice(), general.as_slice(), "factor, n = {n}");
            let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.91).cos()).collect();
            let (mut x_specialized, mut x_general) = (rhs.clone(), rhs.clone());
            ldlt_solve_in_place(&specialized, &mut x_specialized);
            substitute_any(general.as_slice(), &mut x_general, n);
            assert_eq!(x_specialized, x_general, "solve, n = {n}");
        }
    }

    #[test]
    fn refuses_a_matrix_that_is_not_positive_definite() {
        for n in 2..=9 {
            // positive definite but for the last pivot: a zero eigenvalue, then a negative one
            let mut a = spd(n);
            let v = DVector::from_fn(n, |i, _| 1.0 + i as f64);
            let mut singular = a.clone() - (&v * v.transpose()) * (1.0 / (v.transpose() * a.clone().cholesky().unwrap().solve(&v))[0]);
            singular[(n - 1, n - 1)] -= 1e-3;
            assert!(!ldlt_in_place(&mut singular), "n = {n}: indefinite accepted");
            a[(0, 0)] = -1.0;
            assert!(!ldlt_in_place(&mut a), "n = {n}: a negative pivot accepted");
        }
    }
}
