//! CMA-ES, the covariance matrix adaptation evolution strategy (Hansen, *The CMA Evolution
//! Strategy: A Tutorial*, arXiv:1604.00772, its default parameters and updates, §3–§4, with the
//! positive recombination weights only), as ask and tell: [`Cmaes::ask`] samples a generation,
//! the caller evaluates it however it likes (in parallel, each evaluation allowed to stop once it
//! cannot be among the best, [`Cmaes::cutoff`]), [`Cmaes::tell`] ranks it and moves the
//! distribution. A fit of a servo's parameters is rank-based and noisy where a stick or a slip
//! moves: CMA-ES needs only the ranking, and learns the parameters' correlations (k_t with R, the
//! friction terms with each other) that a swarm or a simplex rediscovers at every step.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, StandardNormal};

/// The λ a fit runs with by default for `dimension` parameters: CMA-ES's 4 + ⌊3 ln n⌋, rounded up to
/// an even number so that two cores share a generation evenly. It does not depend on the machine's
/// cores: a seed gives the same fit on any machine (rounded up to the cores, λ and with it every
/// generation would differ from one to the next).
pub fn default_population(dimension: usize) -> usize {
    tutorial_population(dimension).next_multiple_of(2)
}

/// The tutorial's default λ = 4 + ⌊3 ln n⌋.
fn tutorial_population(dimension: usize) -> usize {
    4 + (3.0 * (dimension.max(1) as f64).ln()).floor() as usize
}

/// The strategy's state.
pub struct Cmaes {
    dimension: usize,
    /// λ, μ and the recombination weights (μ of them, summing to 1).
    population: usize,
    weights: Vec<f64>,
    mu_eff: f64,
    c_sigma: f64,
    d_sigma: f64,
    c_c: f64,
    c_1: f64,
    c_mu: f64,
    /// E‖N(0, I)‖.
    chi_n: f64,
    mean: DVector<f64>,
    sigma: f64,
    covariance: DMatrix<f64>,
    /// C = B·diag(D²)·Bᵀ, refreshed every few generations.
    basis: DMatrix<f64>,
    scales: DVector<f64>,
    path_sigma: DVector<f64>,
    path_c: DVector<f64>,
    generation: usize,
    eigen_generation: usize,
    rng: StdRng,
    /// The last generation's sorted losses (for the cutoff of the next).
    last_losses: Vec<f64>,
}

/// One generation: the points, and the standard normal steps that made them.
pub struct Generation {
    pub points: Vec<Vec<f64>>,
    steps: Vec<DVector<f64>>,
}

impl Cmaes {
    /// A strategy at `start` with step `sigma`; `population` 0 takes the default λ = 4 + ⌊3 ln n⌋.
    pub fn new(start: &[f64], sigma: f64, population: usize, seed: u64) -> Self {
        let n = start.len();
        let nf = n as f64;
        let lambda = if population >= 2 { population } else { tutorial_population(n) };
        let mu = lambda / 2;
        let raw: Vec<f64> = (0..mu).map(|i| ((lambda as f64 + 1.0) / 2.0).ln() - ((i + 1) as f64).ln()).collect();
        let total: f64 = raw.iter().sum();
        let weights: Vec<f64> = raw.iter().map(|w| w / total).collect();
        let mu_eff = 1.0 / weights.iter().map(|w| w * w).sum::<f64>();
        let c_sigma = (mu_eff + 2.0) / (nf + mu_eff + 5.0);
        let d_sigma = 1.0 + 2.0 * (((mu_eff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + c_sigma;
        let c_c = (4.0 + mu_eff / nf) / (nf + 4.0 + 2.0 * mu_eff / nf);
        let c_1 = 2.0 / ((nf + 1.3).powi(2) + mu_eff);
        let c_mu = (1.0 - c_1).min(2.0 * (mu_eff - 2.0 + 1.0 / mu_eff) / ((nf + 2.0).powi(2) + mu_eff));
        Self {
            dimension: n,
            population: lambda,
            weights,
            mu_eff,
            c_sigma,
            d_sigma,
            c_c,
            c_1,
            c_mu,
            chi_n: nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf)),
            mean: DVector::from_column_slice(start),
            sigma,
            covariance: DMatrix::identity(n, n),
            basis: DMatrix::identity(n, n),
            scales: DVector::from_element(n, 1.0),
            path_sigma: DVector::zeros(n),
            path_c: DVector::zeros(n),
            generation: 0,
            eigen_generation: 0,
            rng: StdRng::seed_from_u64(seed),
            last_losses: Vec::new(),
        }
    }

    pub fn population(&self) -> usize {
        self.population
    }

    pub fn generation(&self) -> usize {
        self.generation
    }

    pub fn mean(&self) -> &[f64] {
        self.mean.as_slice()
    }

    /// The largest standard deviation along any axis of the search distribution: the search has
    /// converged when it is small against the scale the parameters matter on.
    pub fn spread(&self) -> f64 {
        self.sigma * self.scales.max()
    }

    /// Sample a generation of λ points.
    pub fn ask(&mut self) -> Generation {
        let mut points = Vec::with_capacity(self.population);
        let mut steps = Vec::with_capacity(self.population);
        for _ in 0..self.population {
            let z = DVector::from_fn(self.dimension, |_, _| StandardNormal.sample(&mut self.rng));
            let y = &self.basis * self.scales.component_mul(&z);
            points.push((&self.mean + self.sigma * &y).as_slice().to_vec());
            steps.push(y);
        }
        Generation { points, steps }
    }

    /// A loss no point of the coming generation needs to be evaluated past: one worse than the
    /// last generation's μ-th best can no longer be recombined unless the whole generation is
    /// worse, and then the ranking of points cut off by their partial losses serves (∞ before the
    /// first generation).
    pub fn cutoff(&self) -> f64 {
        let mu = self.weights.len();
        self.last_losses.get(mu.saturating_sub(1)).copied().unwrap_or(f64::INFINITY)
    }

    /// Rank `generation` by `losses` (one per point; a point cut off ranks by its partial loss) and
    /// update the distribution.
    pub fn tell(&mut self, generation: Generation, losses: &[f64]) {
        let n = self.dimension as f64;
        let mut order: Vec<usize> = (0..losses.len()).collect();
        order.sort_by(|&a, &b| losses[a].total_cmp(&losses[b]));
        self.last_losses = order.iter().map(|&i| losses[i]).collect();
        let old_mean = self.mean.clone();
        let mut step = DVector::zeros(self.dimension);
        for (w, &i) in self.weights.iter().zip(&order) {
            step += *w * &generation.steps[i];
        }
        self.mean = &old_mean + self.sigma * &step;
        // C^(−1/2)·step = B·D⁻¹·Bᵀ·step
        let whitened = &self.basis * (self.basis.transpose() * &step).component_div(&self.scales);
        self.path_sigma = (1.0 - self.c_sigma) * &self.path_sigma + (self.c_sigma * (2.0 - self.c_sigma) * self.mu_eff).sqrt() * whitened;
        self.generation += 1;
        let norm = self.path_sigma.norm();
        let stalled = norm / (1.0 - (1.0 - self.c_sigma).powi(2 * self.generation as i32)).sqrt() / self.chi_n < 1.4 + 2.0 / (n + 1.0);
        let h_sigma = if stalled { 1.0 } else { 0.0 };
        self.path_c = (1.0 - self.c_c) * &self.path_c + h_sigma * (self.c_c * (2.0 - self.c_c) * self.mu_eff).sqrt() * &step;
        let mut rank_mu = DMatrix::zeros(self.dimension, self.dimension);
        for (w, &i) in self.weights.iter().zip(&order) {
            let y = &generation.steps[i];
            rank_mu += *w * y * y.transpose();
        }
        let correction = (1.0 - h_sigma) * self.c_c * (2.0 - self.c_c);
        self.covariance = (1.0 - self.c_1 - self.c_mu + correction * self.c_1) * &self.covariance + self.c_1 * &self.path_c * self.path_c.transpose() + self.c_mu * rank_mu;
        self.sigma *= ((self.c_sigma / self.d_sigma) * (norm / self.chi_n - 1.0)).min(1.0).exp();
        // the eigendecomposition costs O(n³): every n/(10·(c_1 + c_μ)) generations (the tutorial's)
        if (self.generation - self.eigen_generation) as f64 > 1.0 / ((self.c_1 + self.c_mu) * n * 10.0) {
            self.refresh_basis();
        }
    }

    fn refresh_basis(&mut self) {
        self.eigen_generation = self.generation;
        // symmetric by construction, up to round-off
        let symmetric = 0.5 * (&self.covariance + self.covariance.transpose());
        let eigen = SymmetricEigen::new(symmetric);
        self.basis = eigen.eigenvectors;
        self.scales = eigen.eigenvalues.map(|l| l.max(1e-30).sqrt());
        self.covariance = &self.basis * DMatrix::from_diagonal(&self.scales.map(|d| d * d)) * self.basis.transpose();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn minimise(f: impl Fn(&[f64]) -> f64, start: &[f64], sigma: f64, generations: usize) -> (Vec<f64>, f64) {
        let mut es = Cmaes::new(start, sigma, 0, 7);
        let mut best = (start.to_vec(), f(start));
        for _ in 0..generations {
            let g = es.ask();
            let losses: Vec<f64> = g.points.iter().map(|p| f(p)).collect();
            for (p, &l) in g.points.iter().zip(&losses) {
                if l < best.1 {
                    best = (p.clone(), l);
                }
            }
            es.tell(g, &losses);
        }
        best
    }

    #[test]
    fn finds_the_minimum_of_an_ill_conditioned_rotated_ellipsoid() {
        // f = Σ 10^(6·i/(n−1))·y_i², y a rotation of x − x*: condition number 10⁶, every axis
        // coupled. Adapting the covariance is what lets it converge (an isotropic search stalls
        // on the short axes); 1e-10 is far below what any fit here needs.
        let n = 8;
        let target: Vec<f64> = (0..n).map(|i| 0.1 * i as f64).collect();
        let angle = 0.4f64;
        let f = |x: &[f64]| {
            let d: Vec<f64> = x.iter().zip(&target).map(|(a, b)| a - b).collect();
            (0..n)
                .map(|i| {
                    let j = (i + 1) % n;
                    let y = angle.cos() * d[i] + angle.sin() * d[j];
                    10f64.powf(6.0 * i as f64 / (n - 1) as f64) * y * y
                })
                .sum()
        };
        let (x, loss) = minimise(f, &vec![0.5; n], 0.3, 900);
        assert!(loss < 1e-10, "loss {loss} at {x:?}");
    }

    #[test]
    fn the_cutoff_is_the_last_generations_mu_th_loss() {
        let mut es = Cmaes::new(&[0.0; 4], 0.1, 8, 1);
        assert_eq!(es.cutoff(), f64::INFINITY);
        let g = es.ask();
        let losses = [8.0, 1.0, 7.0, 2.0, 6.0, 3.0, 5.0, 4.0];
        es.tell(g, &losses);
        assert_eq!(es.cutoff(), 4.0);
    }

    #[test]
    fn the_same_seed_gives_the_same_generations() {
        let mut a = Cmaes::new(&[0.5; 3], 0.2, 0, 3);
        let mut b = Cmaes::new(&[0.5; 3], 0.2, 0, 3);
        assert_eq!(a.ask().points, b.ask().points);
    }
}
