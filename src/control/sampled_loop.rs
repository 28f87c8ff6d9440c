//! Stability of the sampled closed loop: the controller at period h holding its torque, the plant
//! advancing the state, linearized about a pose held still (cmd = q*, v = 0, saturation ignored).
//!
//! Discrete plant (Drake's update): with δq, v the state and G = ∂τ_g/∂q,
//!   v₁ = (M + hD)⁻¹ [ (M − h·Kd) v₀ + h(−Kp + (1 − ff)·G) δq₀ ],   δq₁ = δq₀ + h v₁.
//! Continuous plant: ẋ = [[0, I], [M⁻¹G, −M⁻¹D]] x + [[0], [M⁻¹]] u with u = −(Kp + ff·G) δq − Kd v held
//! over h, discretized exactly (matrix exponential).

use crate::dynamics::{Data, crba, gravity_stiffness};
use crate::model::Model;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum LoopPlant {
    Discrete,
    Continuous,
}

/// Everything the linearization needs at one pose.
pub struct Linearization {
    pub mass: DMatrix<f64>,
    pub gravity_stiffness: DMatrix<f64>,
    pub damping: DVector<f64>,
}

impl Linearization {
    pub fn at(model: &Model, q: &[f64]) -> Self {
        let mut data = Data::new(model);
        let mass = crba(model, &mut data, q).clone();
        let gravity_stiffness = gravity_stiffness(model, &mut data, q);
        Self { mass, gravity_stiffness, damping: DVector::from_iterator(model.dof(), model.joints.iter().map(|j| j.damping)) }
    }

    /// The one-period transition matrix of the closed loop (state δq, v).
    pub fn closed_loop(&self, kp: &[f64], kd: &[f64], h: f64, feed_forward: bool, plant: LoopPlant) -> DMatrix<f64> {
        let n = kp.len();
        let (m, g) = (&self.mass, &self.gravity_stiffness);
        let kp_m = DMatrix::from_diagonal(&DVector::from_column_slice(kp));
        let kd_m = DMatrix::from_diagonal(&DVector::from_column_slice(kd));
        let d_m = DMatrix::from_diagonal(&self.damping);
        let ff = if feed_forward { 1.0 } else { 0.0 };
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        match plant {
            LoopPlant::Discrete => {
                let lhs = m + &d_m * h;
                let inv = lhs.try_inverse().expect("M + hD is positive definite");
                let b_q = &inv * ((-&kp_m + g * (1.0 - ff)) * h);
                let b_v = &inv * (m - &kd_m * h);
                a.view_mut((0, 0), (n, n)).copy_from(&(DMatrix::identity(n, n) + &b_q * h));
                a.view_mut((0, n), (n, n)).copy_from(&(&b_v * h));
                a.view_mut((n, 0), (n, n)).copy_from(&b_q);
                a.view_mut((n, n), (n, n)).copy_from(&b_v);
            }
            LoopPlant::Continuous => {
                let m_inv = m.clone().try_inverse().expect("M is positive definite");
                // augmented [[A, B], [0, 0]] so that exp(·h) = [[Φ, Γ], [0, I]]
                let mut aug = DMatrix::zeros(3 * n, 3 * n);
                aug.view_mut((0, n), (n, n)).copy_from(&DMatrix::identity(n, n));
                aug.view_mut((n, 0), (n, n)).copy_from(&(&m_inv * g));
                aug.view_mut((n, n), (n, n)).copy_from(&(-(&m_inv * &d_m)));
                aug.view_mut((n, 2 * n), (n, n)).copy_from(&m_inv);
                let e = (aug * h).exp();
                let phi = e.view((0, 0), (2 * n, 2 * n)).into_owned();
                let gamma = e.view((0, 2 * n), (2 * n, n)).into_owned();
                let mut k = DMatrix::zeros(n, 2 * n);
                k.view_mut((0, 0), (n, n)).copy_from(&(-(kp_m + g * ff)));
                k.view_mut((0, n), (n, n)).copy_from(&(-kd_m));
                a = phi + gamma * k;
            }
        }
        a
    }
}

/// The largest eigenvalue magnitude, and per joint its share of the dominant mode. Eigenvalues at
/// z = 1 are left out: they are the neutral rigid-body modes of joints without motor or damping
/// (a free joint drifts, it does not blow up); they show as a defective pair split by up to ~1e-5.
pub fn spectral_radius(a: &DMatrix<f64>) -> (f64, Vec<f64>) {
    let n = a.nrows() / 2;
    let (rho, modes) = modes_above(a, f64::INFINITY);
    (rho, modes.into_iter().next().map_or_else(|| vec![1.0 / n as f64; n], |(_, shares)| shares))
}

/// The spectral radius (as [`spectral_radius`]) and every mode whose eigenvalue's magnitude is at
/// least `radius` — and the dominant one whatever its magnitude — largest first: (|λ|, per joint
/// its share of the mode). One eigenvalue of each complex pair.
pub fn modes_above(a: &DMatrix<f64>, radius: f64) -> (f64, Vec<(f64, Vec<f64>)>) {
    use nalgebra::Complex;
    let n = a.nrows() / 2;
    // nalgebra's Schur iteration can stall on badly scaled loops (grams and metres next to
    // micrograms): bounded, with the radius from the growth of Aᵏ as the fallback
    let Some(schur) = nalgebra::linalg::Schur::try_new(a.clone(), 1e-13, 20_000) else {
        let rho = power_radius(a);
        return (rho, vec![(rho, vec![1.0 / n as f64; n])]);
    };
    let mut eig: Vec<Complex<f64>> = schur.complex_eigenvalues().iter().copied().filter(|z| (z - Complex::new(1.0, 0.0)).norm() >= 1e-4 && z.im >= 0.0).collect();
    eig.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    let rho = eig.first().map_or(0.0, |z| z.norm());
    let a_c = a.map(|x| Complex::new(x, 0.0));
    let modes = eig
        .iter()
        .enumerate()
        .take_while(|(k, z)| *k == 0 || z.norm() >= radius)
        .map(|(_, &z)| {
            // the mode's shape: null vector of (A − λI) by inverse iteration (complex)
            let c = &a_c - DMatrix::<Complex<f64>>::identity(2 * n, 2 * n) * (z * Complex::new(1.0 + 1e-9, 0.0));
            let mut v = DVector::from_element(2 * n, Complex::new(1.0, 0.0));
            let lu = c.lu();
            for _ in 0..4 {
                if let Some(next) = lu.solve(&v) {
                    let norm = next.norm();
                    if norm > 0.0 && norm.is_finite() {
                        v = next / Complex::new(norm, 0.0);
                    }
                }
            }
            let weights: Vec<f64> = (0..n).map(|j| v[j].norm_sqr() + v[n + j].norm_sqr() / (1.0 + v[n + j].norm_sqr())).collect();
            let total: f64 = weights.iter().sum::<f64>().max(f64::MIN_POSITIVE);
            (z.norm(), weights.iter().map(|w| w / total).collect())
        })
        .collect();
    (rho, modes)
}

/// The spectral radius as the growth rate of ‖Aᵏ‖ (k = 512, by repeated squaring, renormalized):
/// for when the eigenvalues cannot be had. Neutral modes (z = 1) are not left out here.
fn power_radius(a: &DMatrix<f64>) -> f64 {
    let mut m = a.clone();
    let mut log_scale = 0.0;
    for _ in 0..9 {
        m = &m * &m;
        let norm = m.norm();
        if !(norm > 0.0 && norm.is_finite()) {
            return if norm == 0.0 { 0.0 } else { f64::INFINITY };
        }
        m /= norm;
        log_scale = 2.0 * log_scale + norm.ln();
    }
    (log_scale / 512.0).exp()
}

/// The largest control period ≤ `h_max` for which the loop is stable (bisection after a
/// logarithmic scan from 1 µs), or None when even 1 µs is unstable.
pub fn largest_stable_period(lin: &Linearization, kp: &[f64], kd: &[f64], h_max: f64, ff: bool, plant: LoopPlant) -> Option<f64> {
    let stable = |h: f64| spectral_radius(&lin.closed_loop(kp, kd, h, ff, plant)).0 < 1.0;
    let mut h = 1e-6;
    if !stable(h) {
        return None;
    }
    if stable(h_max) {
        return Some(h_max);
    }
    let mut hi = h;
    while hi < h_max && stable(hi) {
        h = hi;
        hi = (hi * 1.25).min(h_max);
    }
    let mut lo = h;
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if stable(mid) { lo = mid } else { hi = mid }
    }
    Some(lo)
}

/// Derivative gains that make the loop stable at `h` with the given kp: per joint, the kd
/// (scaled from the given one by factors from 1/1000 to 4) that most lowers the spectral radius,
/// in repeated sweeps. Returns the gains and the radius they reach.
pub fn stabilizing_kd(lin: &Linearization, kp: &[f64], kd: &[f64], h: f64, ff: bool, plant: LoopPlant) -> (Vec<f64>, f64) {
    stabilizing_kd_over(std::slice::from_ref(lin), kp, kd, h, ff, plant)
}

/// The worst spectral radius over several linearizations (poses).
pub fn worst_radius(lins: &[Linearization], kp: &[f64], kd: &[f64], h: f64, ff: bool, plant: LoopPlant) -> f64 {
    lins.iter().map(|l| spectral_radius(&l.closed_loop(kp, kd, h, ff, plant)).0).fold(0.0, f64::max)
}

/// The worst spectral radius over several poses, and every mode at any pose whose eigenvalue's
/// magnitude is at least `radius` (with each pose's dominant one), as [`modes_above`].
pub fn modes_over(lins: &[Linearization], kp: &[f64], kd: &[f64], h: f64, ff: bool, plant: LoopPlant, radius: f64) -> (f64, Vec<(f64, Vec<f64>)>) {
    lins.iter().map(|l| modes_above(&l.closed_loop(kp, kd, h, ff, plant), radius)).fold((0.0, Vec::new()), |(worst, mut all), (rho, modes)| {
        all.extend(modes);
        (f64::max(worst, rho), all)
    })
}

/// As [`stabilizing_kd`], but minimizing the worst radius over all the given poses.
pub fn stabilizing_kd_over(lins: &[Linearization], kp: &[f64], kd: &[f64], h: f64, ff: bool, plant: LoopPlant) -> (Vec<f64>, f64) {
    let mut best = kd.to_vec();
    let mut rho = worst_radius(lins, kp, &best, h, ff, plant);
    let factors: Vec<f64> = (0..=40).map(|i| 10f64.powf(-3.0 + 3.6 * i as f64 / 40.0)).collect();
    for _sweep in 0..4 {
        for j in 0..kd.len() {
            if kd[j] == 0.0 && kp[j] == 0.0 {
                continue;
            }
            let base = if kd[j] > 0.0 { kd[j] } else { 1e-3 };
            for f in &factors {
                let mut trial = best.clone();
                trial[j] = base * f;
                let r = worst_radius(lins, kp, &trial, h, ff, plant);
                if r < rho - 1e-12 {
                    rho = r;
                    best = trial;
                }
            }
        }
    }
    (best, rho)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_mode_above_the_radius_is_found_with_its_joints() {
        // three decoupled joints (state δq1..3, v1..3): joint 1 grows 1.5×, joint 3 1.2×, joint 2 decays
        let mut a = DMatrix::zeros(6, 6);
        for (j, z) in [(0, 1.5), (1, 0.5), (2, 1.2)] {
            a[(j, j)] = z;
            a[(3 + j, 3 + j)] = 0.1;
        }
        let (rho, modes) = modes_above(&a, 1.0);
        assert!((rho - 1.5).abs() < 1e-12 && modes.len() == 2, "{rho} {modes:?}");
        for ((z, shares), (joint, expected)) in modes.iter().zip([(0, 1.5), (2, 1.2)]) {
            assert!((z - expected).abs() < 1e-12 && shares[joint] > 0.99, "{z} {shares:?}");
        }
        // the dominant mode is given whatever its size, and spectral_radius agrees
        assert_eq!(modes_above(&a, f64::INFINITY).1.len(), 1);
        let (r, shares) = spectral_radius(&a);
        assert!((r - 1.5).abs() < 1e-12 && shares[0] > 0.99);
    }
}
