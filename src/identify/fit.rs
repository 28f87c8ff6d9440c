//! Fitting a servo's parameters to bench logs: minimise the mean of the logs' position MAE (BAM's
//! loss) over the [`Space`]'s unit cube. A particle swarm (argmin's `ParticleSwarm`) explores the
//! whole cube, then Nelder–Mead (argmin's `NelderMead`) refines its best point, restarted on a
//! smaller simplex until a restart no longer improves it. Every evaluation replays all the training
//! logs, in parallel (rayon).

use super::space::Space;
use crate::actuator::bus_servo::ServoParams;
use crate::testbench::{BenchLog, ReplayOptions, mae};
use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::ParticleSwarm;
use rand::SeedableRng;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How hard to search.
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// Independent searches (each a swarm from its own seed, then its refinement): the best wins.
    pub searches: usize,
    pub particles: usize,
    pub swarm_iterations: u64,
    pub simplex_iterations: u64,
    /// Nelder–Mead restarts at most, per search.
    pub restarts: usize,
    /// The first search's seed (search k uses seed + k).
    pub seed: u64,
    /// A point to start a refinement from as well (e.g. a published file).
    pub start: Option<ServoParams>,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self { searches: 8, particles: 48, swarm_iterations: 120, simplex_iterations: 2000, restarts: 3, seed: 1, start: None }
    }
}

/// What the fit found.
#[derive(Clone, Debug)]
pub struct Fit {
    pub params: ServoParams,
    /// The mean MAE over the training logs, rad.
    pub loss: f64,
    /// Each search's loss, rad (the spread says how sure the optimum is).
    pub search_losses: Vec<f64>,
    pub evaluations: usize,
}

/// The loss on the unit cube: outside it, the value at the nearest point of the cube plus the
/// distance (Nelder–Mead is unbounded; this brings it back without a cliff).
pub struct Objective<'a> {
    pub space: &'a Space,
    pub logs: &'a [BenchLog],
    pub options: ReplayOptions,
    pub evaluations: AtomicUsize,
}

impl Objective<'_> {
    pub fn loss(&self, u: &[f64]) -> f64 {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        let outside: f64 = u.iter().map(|x| (x - x.clamp(0.0, 1.0)).abs()).sum();
        let params = self.space.params(u);
        // in the logs' order whatever the threads did: the same seed gives the same fit
        let per_log: Vec<f64> = self.logs.par_iter().map(|log| mae(log, &params, &self.options)).collect();
        let loss = per_log.iter().sum::<f64>() / self.logs.len() as f64 + outside;
        if loss.is_finite() { loss } else { f64::MAX }
    }
}

impl CostFunction for &Objective<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, u: &Self::Param) -> Result<f64, argmin::core::Error> {
        Ok(self.loss(u))
    }
}

/// The windowed loss's window, s: the simulation restarts from the measured state this often.
pub const WINDOW_SECONDS: f64 = 1.0;

/// Fit `space` to `logs`, in two stages. A free-running replay's loss jumps wherever a small
/// change of a parameter moves a stick or a slip, and that grows with the log's length; so the
/// swarms and a first refinement minimise the windowed loss (each [`WINDOW_SECONDS`] the replay
/// restarts from the measured position and speed), and the second refines the best of those on
/// the free-running replay, BAM's loss, which the fit reports. (On a simulated bench the
/// free-running loss alone left the swarms of M4–M6 at 6–12 mrad where the truth is at the
/// encoder's 0.4 mrad; windowed first, every search ends within the noise.)
pub fn fit(space: &Space, logs: &[BenchLog], replay: ReplayOptions, options: &FitOptions) -> Result<Fit, String> {
    let window = logs.iter().map(|l| (WINDOW_SECONDS / l.dt).round().max(1.0) as usize).min();
    let windowed = Objective { space, logs, options: ReplayOptions { reset_rows: window, ..replay }, evaluations: AtomicUsize::new(0) };
    let free = Objective { space, logs, options: ReplayOptions { reset_rows: None, ..replay }, evaluations: AtomicUsize::new(0) };
    let n = space.len();
    let mut candidates = Vec::new();
    for k in 0..options.searches.max(1) {
        let swarm = ParticleSwarm::new((vec![0.0; n], vec![1.0; n]), options.particles).with_rng_generator(rand::rngs::StdRng::seed_from_u64(options.seed + k as u64));
        let result = Executor::new(&windowed, swarm).configure(|state| state.max_iters(options.swarm_iterations)).run().map_err(|e| format!("particle swarm: {e}"))?;
        candidates.push(result.state().get_best_param().map(|p| p.position.clone()).ok_or("particle swarm: no particle")?);
    }
    candidates.extend(options.start.iter().map(|p| space.point(p)));
    let mut results = Vec::new();
    for start in candidates {
        let (start, _) = refine(&windowed, start, options)?;
        results.push(refine(&free, start, options)?);
    }
    let search_losses: Vec<f64> = results.iter().map(|(_, loss)| *loss).collect();
    let (best, _) = results.into_iter().min_by(|a, b| a.1.total_cmp(&b.1)).ok_or("no search ran")?;
    let loss = free.loss(&best);
    let evaluations = windowed.evaluations.load(Ordering::Relaxed) + free.evaluations.load(Ordering::Relaxed);
    Ok(Fit { params: space.params(&best), loss, search_losses, evaluations })
}

/// Nelder–Mead from `start`, restarted on a simplex half the size while it improves.
fn refine(objective: &Objective, start: Vec<f64>, options: &FitOptions) -> Result<(Vec<f64>, f64), String> {
    let mut best_loss = objective.loss(&start);
    let mut best = start;
    let mut size = 0.1;
    for _ in 0..options.restarts {
        let (u, loss) = simplex(objective, &best, size, options.simplex_iterations)?;
        let improved = best_loss - loss;
        if loss < best_loss {
            (best, best_loss) = (u, loss);
        }
        if improved < 1e-6 {
            break;
        }
        size *= 0.5;
    }
    let best: Vec<f64> = best.iter().map(|x| x.clamp(0.0, 1.0)).collect();
    let loss = objective.loss(&best);
    Ok((best, loss))
}

/// Nelder–Mead from `start` on a simplex of edge `size` (each edge away from the nearer face).
fn simplex(objective: &Objective, start: &[f64], size: f64, iterations: u64) -> Result<(Vec<f64>, f64), String> {
    let mut vertices = vec![start.to_vec()];
    for i in 0..start.len() {
        let mut v = start.to_vec();
        v[i] += if v[i] > 0.5 { -size } else { size };
        vertices.push(v);
    }
    let solver = NelderMead::new(vertices).with_sd_tolerance(1e-7).map_err(|e| e.to_string())?;
    let result = Executor::new(objective, solver).configure(|state| state.max_iters(iterations)).run().map_err(|e| format!("Nelder–Mead: {e}"))?;
    let state = result.state();
    let best = state.get_best_param().cloned().ok_or("Nelder–Mead: no point")?;
    Ok((best, state.get_best_cost()))
}
