//! Positions sampled by an encoder (quantized, at a few tens of frames per second) into q, q̇, q̈:
//! a Whittaker–Henderson smoother (penalized least squares on the 4th differences, a smoothing
//! spline's discrete twin) whose weight λ is chosen per joint by the discrepancy principle — the
//! smoothed curve leaves residuals as large as the samples' own noise, no larger — then 5-point
//! derivative stencils on the smooth curve.
//!
//! Why not Savitzky–Golay: on encoder-quantized 30 fps data its fixed window either passes the
//! quantization steps into q̈ (a lightly loaded joint's torque is then mostly noise: 4–8 % of its
//! peak) or rounds off real accelerations; the penalty here adapts to each joint's noise and
//! motion, and its bandwidth follows from λ (see [`Smoothed::cutoff_hz`]).

/// The order of the differences penalized: 4 keeps q̈ smooth (a cubic's 4th difference is 0, so
/// constant jerk passes untouched).
pub const PENALTY_ORDER: usize = 4;

/// One joint's smoothed motion at the sample times.
#[derive(Clone, Debug)]
pub struct Smoothed {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    /// The noise taken for the samples, σ (a quantum δ gives δ/√12).
    pub noise: f64,
    /// The encoder's quantum found in the samples, if they lie on one.
    pub quantum: Option<f64>,
    /// The smoothing weight λ chosen (0: none was needed).
    pub lambda: f64,
    /// The frequency where the smoother passes half the amplitude, Hz (the Nyquist frequency when
    /// λ = 0).
    pub cutoff_hz: f64,
}

/// The times' grid and the penalty built on it, shared by every joint of an episode.
pub struct Smoother {
    time: Vec<f64>,
    /// The penalty DᵀD in band storage: `penalty[i][m]` = (DᵀD)[i][i+m], m = 0..=d.
    penalty: Vec<[f64; PENALTY_ORDER + 1]>,
    /// The mean sample interval, s.
    step: f64,
    /// Derivative stencils per sample: the 5 neighbours used and their weights for q̇ and q̈.
    stencils: Vec<Stencil>,
    // factorization workspace (reused across λ)
    factor: Vec<[f64; PENALTY_ORDER + 1]>,
}

#[derive(Clone, Copy, Debug)]
struct Stencil {
    first: usize,
    d1: [f64; 5],
    d2: [f64; 5],
}

impl Smoother {
    /// A smoother for samples at `time` (strictly increasing, at least 5 of them).
    pub fn new(time: &[f64]) -> Self {
        let n = time.len();
        assert!(n > PENALTY_ORDER, "at least {} samples", PENALTY_ORDER + 1);
        let step = (time[n - 1] - time[0]) / (n - 1) as f64;
        let d = PENALTY_ORDER;
        let mut penalty = vec![[0.0; PENALTY_ORDER + 1]; n];
        for row in 0..n - d {
            // the d-th derivative from d+1 neighbours, times step^d: on a uniform grid exactly the
            // d-th difference, elsewhere its scaled divided-difference twin
            let w = fornberg(&time[row..=row + d], time[row], d);
            let scale = step.powi(d as i32);
            let w: Vec<f64> = w.iter().map(|x| x * scale).collect();
            for a in 0..=d {
                for b in a..=d {
                    penalty[row + a][b - a] += w[a] * w[b];
                }
            }
        }
        let stencils = (0..n)
            .map(|i| {
                let first = i.saturating_sub(2).min(n - 5);
                let nodes = &time[first..first + 5];
                let d1 = fornberg(nodes, time[i], 1);
                let d2 = fornberg(nodes, time[i], 2);
                Stencil { first, d1: d1.try_into().unwrap(), d2: d2.try_into().unwrap() }
            })
            .collect();
        Self { time: time.to_vec(), penalty, step, stencils, factor: vec![[0.0; PENALTY_ORDER + 1]; n] }
    }

    pub fn len(&self) -> usize {
        self.time.len()
    }

    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Smooth and differentiate one joint's samples: λ such that the residual's RMS equals the
    /// samples' noise (found from their quantum, else estimated from their 4th differences).
    pub fn smooth(&mut self, samples: &[f64]) -> Smoothed {
        let (noise, quantum) = noise_of(samples);
        self.smooth_with_noise(samples, noise, quantum)
    }

    pub fn smooth_with_noise(&mut self, samples: &[f64], noise: f64, quantum: Option<f64>) -> Smoothed {
        let n = samples.len();
        assert_eq!(n, self.time.len());
        let mut z = vec![0.0; n];
        let mut lambda = 0.0;
        if noise > 0.0 {
            // the residual's RMS grows with λ: bisect in log λ for RMS = σ
            let rms = |this: &mut Self, lambda: f64, z: &mut Vec<f64>| {
                this.solve(lambda, samples, z);
                (samples.iter().zip(z.iter()).map(|(y, s)| (y - s) * (y - s)).sum::<f64>() / n as f64).sqrt()
            };
            let (mut lo, mut hi) = (-6.0_f64, 14.0_f64);
            if rms(self, 10f64.powf(hi), &mut z) <= noise {
                lambda = 10f64.powf(hi);
            } else if rms(self, 10f64.powf(lo), &mut z) >= noise {
                lambda = 10f64.powf(lo);
            } else {
                for _ in 0..30 {
                    let mid = 0.5 * (lo + hi);
                    if rms(self, 10f64.powf(mid), &mut z) > noise { hi = mid } else { lo = mid }
                    if hi - lo < 0.01 {
                        break;
                    }
                }
                lambda = 10f64.powf(0.5 * (lo + hi));
            }
            self.solve(lambda, samples, &mut z);
        } else {
            z.copy_from_slice(samples);
        }
        let (qd, qdd) = self.derivatives(&z);
        Smoothed { q: z, qd, qdd, noise, quantum, lambda, cutoff_hz: self.cutoff_hz(lambda) }
    }

    /// The half-amplitude frequency of the smoother with weight λ on this grid: where
    /// λ·(2 sin(π f h))^(2d) = 1.
    pub fn cutoff_hz(&self, lambda: f64) -> f64 {
        let nyquist = 0.5 / self.step;
        if lambda <= 0.0 {
            return nyquist;
        }
        let s = 0.5 * lambda.powf(-1.0 / (2 * PENALTY_ORDER) as f64);
        if s >= 1.0 { nyquist } else { s.asin() / (std::f64::consts::PI * self.step) }
    }

    /// q̇ and q̈ of a smooth curve, by 5-point stencils (central inside, one-sided at the ends).
    pub fn derivatives(&self, z: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut qd = vec![0.0; z.len()];
        let mut qdd = vec![0.0; z.len()];
        for (i, s) in self.stencils.iter().enumerate() {
            let window = &z[s.first..s.first + 5];
            qd[i] = window.iter().zip(&s.d1).map(|(a, b)| a * b).sum();
            qdd[i] = window.iter().zip(&s.d2).map(|(a, b)| a * b).sum();
        }
        (qd, qdd)
    }

    /// (I + λ·DᵀD) z = y by a banded Cholesky factorization (bandwidth d).
    fn solve(&mut self, lambda: f64, y: &[f64], z: &mut [f64]) {
        let n = y.len();
        let d = PENALTY_ORDER;
        let f = &mut self.factor;
        for (row, penalty) in f.iter_mut().zip(&self.penalty) {
            for (value, p) in row.iter_mut().zip(penalty) {
                *value = lambda * p;
            }
            row[0] += 1.0;
        }
        // A = LLᵀ with L stored by rows: f[i][m] holds L[i+m][i] (column i of L below the diagonal)
        for i in 0..n {
            let mut diagonal = f[i][0];
            for k in 1..=d.min(i) {
                let l = f[i - k][k];
                diagonal -= l * l;
            }
            let diagonal = diagonal.sqrt();
            f[i][0] = diagonal;
            for m in 1..=d.min(n - 1 - i) {
                // L[i+m][i] = (A[i+m][i] − Σ_k L[i+m][i−k]·L[i][i−k]) / L[i][i]
                let mut value = f[i][m];
                for k in 1..=(d - m).min(i) {
                    value -= f[i - k][m + k] * f[i - k][k];
                }
                f[i][m] = value / diagonal;
            }
        }
        // forward: L w = y
        for i in 0..n {
            let mut value = y[i];
            for k in 1..=d.min(i) {
                value -= f[i - k][k] * z[i - k];
            }
            z[i] = value / f[i][0];
        }
        // backward: Lᵀ z = w
        for i in (0..n).rev() {
            let mut value = z[i];
            for m in 1..=d.min(n - 1 - i) {
                value -= f[i][m] * z[i + m];
            }
            z[i] = value / f[i][0];
        }
    }
}

/// The samples' noise σ and the quantum they lie on, if any: values on a lattice a + k·δ (an
/// encoder's ticks, whatever unit and offset they were written in) have a rounding error uniform
/// over δ, σ = δ/√12. Otherwise σ is estimated from the 4th differences (a smooth motion's are
/// tiny at these rates, white noise's have variance 70σ²), robustly by their median.
pub fn noise_of(samples: &[f64]) -> (f64, Option<f64>) {
    if let Some(quantum) = quantum_of(samples) {
        return (quantum / 12f64.sqrt(), Some(quantum));
    }
    if samples.len() < 6 {
        return (0.0, None);
    }
    let mut fourth: Vec<f64> = samples.windows(5).map(|w| (w[0] - 4.0 * w[1] + 6.0 * w[2] - 4.0 * w[3] + w[4]).abs()).collect();
    fourth.sort_by(f64::total_cmp);
    let median = fourth[fourth.len() / 2];
    (1.4826 * median / 70f64.sqrt(), None)
}

/// The smallest step between the distinct values, if every value is a whole number of such steps
/// from the smallest (to 1e-3 of a step): the encoder's quantum.
pub fn quantum_of(samples: &[f64]) -> Option<f64> {
    let mut values: Vec<f64> = samples.iter().copied().filter(|v| v.is_finite()).collect();
    values.sort_by(f64::total_cmp);
    let range = values.last()? - values.first()?;
    if range <= 0.0 {
        return None;
    }
    // values written as float32 carry their rounding: a step below 1e-6 of the range is none
    let tiny = range * 1e-6;
    let step = values.windows(2).map(|w| w[1] - w[0]).filter(|s| *s > tiny).fold(f64::INFINITY, f64::min);
    if !step.is_finite() || range / step > 1e7 {
        return None;
    }
    let base = values[0];
    // a quantum's multiples on the lattice agree to float32 rounding; refine δ from the range
    let steps = (range / step).round();
    let quantum = range / steps;
    let on_lattice = values.iter().all(|v| {
        let k = (v - base) / quantum;
        (k - k.round()).abs() < 1e-3
    });
    // fewer than a few distinct levels say nothing about a lattice
    (on_lattice && steps >= 3.0).then_some(quantum)
}

/// Weights of the `order`-th derivative at `at` from values at `nodes` (Fornberg 1988).
pub fn fornberg(nodes: &[f64], at: f64, order: usize) -> Vec<f64> {
    let n = nodes.len();
    let mut c = vec![vec![0.0; order + 1]; n];
    c[0][0] = 1.0;
    let mut c1 = 1.0;
    let mut c4 = nodes[0] - at;
    for i in 1..n {
        let mn = i.min(order);
        let mut c2 = 1.0;
        let c5 = c4;
        c4 = nodes[i] - at;
        for j in 0..i {
            let c3 = nodes[i] - nodes[j];
            c2 *= c3;
            if j == i - 1 {
                for k in (1..=mn).rev() {
                    c[i][k] = c1 * (k as f64 * c[i - 1][k - 1] - c5 * c[i - 1][k]) / c2;
                }
                c[i][0] = -c1 * c5 * c[i - 1][0] / c2;
            }
            for k in (1..=mn).rev() {
                c[j][k] = (c4 * c[j][k] - k as f64 * c[j][k - 1]) / c3;
            }
            c[j][0] = c4 * c[j][0] / c3;
        }
        c1 = c2;
    }
    c.iter().map(|row| row[order]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fornberg_gives_the_textbook_stencils() {
        let nodes = [-2.0, -1.0, 0.0, 1.0, 2.0];
        let d1 = fornberg(&nodes, 0.0, 1);
        let expected = [1.0 / 12.0, -2.0 / 3.0, 0.0, 2.0 / 3.0, -1.0 / 12.0];
        for (a, b) in d1.iter().zip(expected) {
            assert!((a - b).abs() < 1e-14, "{d1:?}");
        }
        let d4 = fornberg(&nodes, -2.0, 4);
        for (a, b) in d4.iter().zip([1.0, -4.0, 6.0, -4.0, 1.0]) {
            assert!((a - b).abs() < 1e-12, "{d4:?}");
        }
    }

    #[test]
    fn banded_solve_matches_a_dense_solve() {
        let time: Vec<f64> = (0..40).map(|i| i as f64 * 0.01 + 0.002 * ((i * 7) % 3) as f64).collect();
        let mut s = Smoother::new(&time);
        let y: Vec<f64> = time.iter().map(|t| (3.0 * t).sin() + 0.01 * ((t * 1e3) as i64 % 5) as f64).collect();
        let mut z = vec![0.0; y.len()];
        s.solve(3.0, &y, &mut z);
        // dense A from the band, then check A z = y
        let n = y.len();
        for i in 0..n {
            let mut sum = z[i] * (1.0 + 3.0 * s.penalty[i][0]);
            for m in 1..=PENALTY_ORDER {
                if i + m < n {
                    sum += 3.0 * s.penalty[i][m] * z[i + m];
                }
                if i >= m {
                    sum += 3.0 * s.penalty[i - m][m] * z[i - m];
                }
            }
            assert!((sum - y[i]).abs() < 1e-10, "row {i}: {sum} vs {}", y[i]);
        }
    }

    #[test]
    fn a_cubic_passes_untouched() {
        let time: Vec<f64> = (0..60).map(|i| i as f64 / 30.0).collect();
        let mut s = Smoother::new(&time);
        let y: Vec<f64> = time.iter().map(|t| 0.3 - t + 0.5 * t * t - 0.2 * t * t * t).collect();
        let mut z = vec![0.0; y.len()];
        s.solve(100.0, &y, &mut z);
        for (a, b) in z.iter().zip(&y) {
            assert!((a - b).abs() < 1e-8);
        }
        let (qd, qdd) = s.derivatives(&z);
        for (i, t) in time.iter().enumerate() {
            assert!((qd[i] - (-1.0 + t - 0.6 * t * t)).abs() < 1e-7);
            assert!((qdd[i] - (1.0 - 1.2 * t)).abs() < 1e-6);
        }
    }

    #[test]
    fn the_quantum_is_found_whatever_the_offset_and_unit() {
        let tick = 360.0 / 4095.0;
        let samples: Vec<f64> = (0..300).map(|i| (((i as f64 * 0.05).sin() * 500.0).round() * tick + 12.345) as f32 as f64).collect();
        let q = quantum_of(&samples).unwrap();
        assert!((q - tick).abs() < 1e-6 * tick, "{q}");
        let smooth: Vec<f64> = (0..300).map(|i| (i as f64 * 0.05).sin()).collect();
        assert_eq!(quantum_of(&smooth), None);
    }
}
