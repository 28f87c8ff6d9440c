//! Fitting a servo's parameters to bench logs: minimise the mean of the logs' position MAE (BAM's
//! loss) over the [`Space`]'s unit cube with CMA-ES ([`super::cmaes`]), in two stages (below), and
//! polish the end with Nelder–Mead (argmin's `NelderMead`).
//! Each generation's candidates are replayed at once, one per core, each over every log in turn and
//! stopped as soon as its loss cannot be among the generation's best ([`Cmaes::cutoff`]): a
//! candidate that will not be recombined costs a fraction of a replay.

use super::cmaes::Cmaes;
use super::space::Space;
use crate::actuator::bus_servo::ServoParams;
use crate::testbench::{BenchLog, ReplayOptions, mae_within};
use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How hard to search.
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// Independent searches of the first (windowed) stage, each from its own start: the best goes
    /// on to the second. The first starts at `start` (or the cube's centre), the others at random.
    /// 0: 120 / the logs' count, 2 to 6 (few logs are cheap to search more).
    pub searches: usize,
    /// Candidates a generation, λ (0: [`super::cmaes::default_population`]).
    pub population: usize,
    /// Generations of each first-stage search, at most.
    pub generations: usize,
    /// Generations of the second (free-running) stage, at most.
    pub refine_generations: usize,
    /// Nelder–Mead iterations a simplex of the polish (0: [`POLISH_REPLAYS`] divided among the
    /// logs, within [`POLISH_ITERATIONS`]).
    pub polish_iterations: usize,
    /// The first search's seed (search k uses seed + k).
    pub seed: u64,
    /// Where the first search starts (e.g. a published file, or the catalogue's parameters).
    pub start: Option<ServoParams>,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self { searches: 0, population: 0, generations: 200, refine_generations: 150, polish_iterations: 0, seed: 1, start: None }
    }
}

/// What the fit found.
#[derive(Clone, Debug)]
pub struct Fit {
    pub params: ServoParams,
    /// The mean MAE over the training logs, rad.
    pub loss: f64,
    /// Each first-stage search's loss on the windowed replay, rad (the spread says how sure the
    /// optimum is).
    pub search_losses: Vec<f64>,
    /// Candidates evaluated (each a replay of the logs, or of their first part when stopped early).
    pub evaluations: usize,
    /// Log replays run to their end, and stopped early.
    pub replays: usize,
    pub replays_stopped: usize,
}

/// Where a fit is, for a progress display.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// "windowed" or "free-running".
    pub stage: &'static str,
    /// The first stage's search (0-based), of `searches`.
    pub search: usize,
    pub searches: usize,
    pub generation: usize,
    pub generations: usize,
    /// The stage's best loss so far, rad.
    pub best: f64,
}

/// The loss on the unit cube: outside it, the value at the nearest point of the cube plus the
/// distance (CMA-ES samples the whole space; this brings it back without a cliff).
pub struct Objective<'a> {
    pub space: &'a Space,
    pub logs: &'a [BenchLog],
    pub options: ReplayOptions,
    evaluations: AtomicUsize,
    replays: AtomicUsize,
    stopped: AtomicUsize,
}

impl<'a> Objective<'a> {
    pub fn new(space: &'a Space, logs: &'a [BenchLog], options: ReplayOptions) -> Self {
        Self { space, logs, options, evaluations: AtomicUsize::new(0), replays: AtomicUsize::new(0), stopped: AtomicUsize::new(0) }
    }

    /// The mean MAE at `u`, the logs replayed in order and the evaluation stopped once the mean
    /// must exceed `cutoff` (then a value above `cutoff` and at most the whole loss).
    pub fn loss(&self, u: &[f64], cutoff: f64) -> f64 {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        let outside: f64 = u.iter().map(|x| (x - x.clamp(0.0, 1.0)).abs()).sum();
        let params = self.space.params(u);
        let count = self.logs.len() as f64;
        // the sum of the logs' MAEs the cutoff allows
        let budget = (cutoff - outside) * count;
        let mut sum = 0.0;
        for log in self.logs {
            let error = mae_within(log, &params, &self.options, budget - sum);
            sum += error;
            if !(sum <= budget) {
                self.stopped.fetch_add(1, Ordering::Relaxed);
                break;
            }
            self.replays.fetch_add(1, Ordering::Relaxed);
        }
        let loss = sum / count + outside;
        if loss.is_finite() { loss } else { f64::MAX }
    }

    /// The whole loss at `u`, the logs replayed in parallel (summed in their order: the same
    /// value whatever the threads did).
    pub fn loss_on_every_core(&self, u: &[f64]) -> f64 {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        self.replays.fetch_add(self.logs.len(), Ordering::Relaxed);
        let outside: f64 = u.iter().map(|x| (x - x.clamp(0.0, 1.0)).abs()).sum();
        let params = self.space.params(u);
        let per_log: Vec<f64> = self.logs.par_iter().map(|log| mae_within(log, &params, &self.options, f64::INFINITY)).collect();
        let loss = per_log.iter().sum::<f64>() / self.logs.len() as f64 + outside;
        if loss.is_finite() { loss } else { f64::MAX }
    }
}

/// Nelder–Mead sees the loss of a whole point, the logs replayed on every core.
struct Whole<'o, 'a>(&'o Objective<'a>);

impl CostFunction for Whole<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, u: &Self::Param) -> Result<f64, argmin::core::Error> {
        Ok(self.0.loss_on_every_core(u))
    }
}

/// The windowed loss's window, s: the simulation restarts from the measured state this often.
pub const WINDOW_SECONDS: f64 = 1.0;

/// The first stage's step on the unit cube: a third of every range, the whole space in reach.
const FIRST_SIGMA: f64 = 0.3;
/// The second stage's step: the free-running loss is rugged (a stick or a slip moves with a small
/// change), so it refines close to where the first stage ended. On K-Scale's 60 STS3215 logs
/// (300 generations) steps of 0.002, 0.005, 0.01, 0.05 and 0.1 ended at 28.6, 28.4, 28.4, 31.6
/// and 31.6 mrad (the last two no better than their start).
const SECOND_SIGMA: f64 = 0.01;
/// First-stage searches by default: this many log replays' worth divided among the logs.
const SEARCH_BUDGET: usize = 120;

/// Fit `space` to `logs`, in two stages. A free-running replay's loss jumps wherever a small
/// change of a parameter moves a stick or a slip, and that grows with the log's length; so the
/// first stage minimises the windowed loss (each [`WINDOW_SECONDS`] the replay restarts from the
/// measured position and speed), and the second refines its best on the free-running replay,
/// BAM's loss, which the fit reports. (On a simulated bench the free-running loss alone left
/// searches of M4–M6 at 6–12 mrad where the truth is at the encoder's 0.4 mrad; windowed first,
/// every search ends within the noise.) `progress` hears of every generation.
pub fn fit(space: &Space, logs: &[BenchLog], replay: ReplayOptions, options: &FitOptions, progress: &(dyn Fn(Progress) + Sync)) -> Result<Fit, String> {
    if logs.is_empty() {
        return Err("no log to fit".into());
    }
    let window = logs.iter().map(|l| (WINDOW_SECONDS / l.dt).round().max(1.0) as usize).min();
    let windowed = Objective::new(space, logs, ReplayOptions { reset_rows: window, ..replay });
    let free = Objective::new(space, logs, ReplayOptions { reset_rows: None, ..replay });
    let n = space.len();
    let population = match options.population {
        0 => super::cmaes::default_population(n),
        p => p.max(2),
    };
    // logs are cheap when few: more first-stage searches then (2 for 60 logs, 6 for 8 or fewer)
    let searches = match options.searches {
        0 => (SEARCH_BUDGET / logs.len()).clamp(2, 6),
        k => k,
    };
    let mut rng = rand::rngs::StdRng::seed_from_u64(options.seed);
    let mut ends: Vec<(Vec<f64>, f64)> = Vec::new();
    let mut search_losses = Vec::new();
    for k in 0..searches {
        let start = match (k, &options.start) {
            (0, Some(p)) => space.point(p),
            (0, None) => vec![0.5; n],
            _ => (0..n).map(|_| rng.random_range(0.2..0.8)).collect(),
        };
        let report = |generation, best| progress(Progress { stage: "windowed", search: k, searches, generation, generations: options.generations, best });
        let (end, windowed_loss) = search(&windowed, &start, FIRST_SIGMA, population, options.generations, options.seed + k as u64, 1e-3, &report);
        search_losses.push(windowed_loss);
        // the search whose end does best free-running goes on (the windowed loss ranks the ends
        // poorly: on K-Scale's STS3215 logs ends of 23.0 and 23.4 mrad windowed were 34.1 and
        // 31.6 free-running)
        let free_loss = free.loss(&end, f64::INFINITY);
        ends.push((end, free_loss));
    }
    let (start, _) = ends.into_iter().min_by(|a, b| a.1.total_cmp(&b.1)).ok_or("no search ran")?;
    let report = |generation, best| progress(Progress { stage: "free-running", search: 0, searches: 1, generation, generations: options.refine_generations, best });
    let (best, loss) = search(&free, &start, SECOND_SIGMA, population, options.refine_generations, options.seed + searches as u64, 2e-4, &report);
    progress(Progress { stage: "polish", search: 0, searches: 1, generation: 0, generations: 1, best: loss });
    let iterations = match options.polish_iterations {
        0 => (POLISH_REPLAYS / logs.len()).clamp(*POLISH_ITERATIONS.start(), *POLISH_ITERATIONS.end()),
        i => i,
    };
    let (best, loss) = polish(&free, best, loss, iterations)?;
    let both = |of: for<'o> fn(&'o Objective<'o>) -> &'o AtomicUsize| of(&windowed).load(Ordering::Relaxed) + of(&free).load(Ordering::Relaxed);
    Ok(Fit {
        params: space.params(&best),
        loss,
        search_losses,
        evaluations: both(|o| &o.evaluations),
        replays: both(|o| &o.replays),
        replays_stopped: both(|o| &o.stopped),
    })
}

/// One CMA-ES search of `objective` from `start` with step `sigma`, until `generations` or the
/// distribution's spread falls below `tolerance` or the best has not moved for a third of the
/// generations; the best point (in the cube) and its loss.
#[allow(clippy::too_many_arguments)]
fn search(objective: &Objective, start: &[f64], sigma: f64, population: usize, generations: usize, seed: u64, tolerance: f64, report: &dyn Fn(usize, f64)) -> (Vec<f64>, f64) {
    let clamp = |u: &[f64]| u.iter().map(|x| x.clamp(0.0, 1.0)).collect::<Vec<f64>>();
    let start = clamp(start);
    let mut best = (start.clone(), objective.loss(&start, f64::INFINITY));
    let mut es = Cmaes::new(&start, sigma, population, seed);
    let patience = (generations / 3).max(20);
    let mut last_improvement = 0;
    for generation in 0..generations {
        let candidates = es.ask();
        let cutoff = es.cutoff();
        let losses: Vec<f64> = candidates.points.par_iter().map(|u| objective.loss(u, cutoff)).collect();
        for (u, &loss) in candidates.points.iter().zip(&losses) {
            // (a point cut off has a loss above the cutoff, which no best is above; one outside
            // the cube stands for its nearest point in it, whose loss is at most its own)
            if loss < best.1 {
                best = (clamp(u), loss);
                last_improvement = generation;
            }
        }
        es.tell(candidates, &losses);
        report(generation + 1, best.1);
        if es.spread() < tolerance || generation - last_improvement > patience {
            break;
        }
    }
    // the mean is the distribution's estimate of the optimum: kept where it does better
    let mean = clamp(es.mean());
    let at_mean = objective.loss(&mean, best.1);
    if at_mean < best.1 {
        best = (mean, at_mean);
    }
    best
}

/// The Nelder–Mead polish's budget: iterations per simplex, and simplices (each half the last's size,
/// while one improves). Each iteration replays every log, so many logs get fewer iterations: this
/// many log replays a simplex, within [`POLISH_ITERATIONS`]. On K-Scale's 60 STS3215 logs 600
/// iterations a simplex (of 1000) took the polish from 25 s to 14 s, ending at 14.68 mrad against
/// 14.50 (the catalogue's parameters replay them at 15.50); up to 36 logs keep every iteration
/// (on the simulated benches' 8 they reach the encoder's rounding).
pub const POLISH_REPLAYS: usize = 36_000;
pub const POLISH_ITERATIONS: std::ops::RangeInclusive<usize> = 600..=1000;
const POLISH_RESTARTS: usize = 3;

/// Nelder–Mead from `start` on the free-running loss, restarted on a simplex half the size while it
/// improves. Near the optimum the free-running loss is a valley narrower than any step a
/// population samples well (half a millirad of bench offset is 1/400 of its range): on simulated
/// benches CMA-ES's refinement stopped at twice the encoder's rounding error, the simplex reaches it.
fn polish(objective: &Objective, start: Vec<f64>, start_loss: f64, iterations: usize) -> Result<(Vec<f64>, f64), String> {
    let (mut best, mut best_loss) = (start, start_loss);
    let mut size = 0.02;
    for _ in 0..POLISH_RESTARTS {
        let (u, loss) = simplex(objective, &best, size, iterations)?;
        let improved = best_loss - loss;
        if loss < best_loss {
            (best, best_loss) = (u.iter().map(|x| x.clamp(0.0, 1.0)).collect(), loss);
        }
        if improved < 1e-7 {
            break;
        }
        size *= 0.5;
    }
    // the clamped point's own loss (a point outside the cube was charged its distance)
    let loss = objective.loss(&best, f64::INFINITY);
    Ok((best, loss))
}

/// Nelder–Mead from `start` on a simplex of edge `size` (each edge away from the nearer face).
fn simplex(objective: &Objective, start: &[f64], size: f64, iterations: usize) -> Result<(Vec<f64>, f64), String> {
    let mut vertices = vec![start.to_vec()];
    for i in 0..start.len() {
        let mut v = start.to_vec();
        v[i] += if v[i] > 0.5 { -size } else { size };
        vertices.push(v);
    }
    let solver = NelderMead::new(vertices).with_sd_tolerance(1e-9).map_err(|e| e.to_string())?;
    let result = Executor::new(Whole(objective), solver).configure(|state| state.max_iters(iterations as u64)).run().map_err(|e| format!("Nelder–Mead: {e}"))?;
    let state = result.state();
    let best = state.get_best_param().cloned().ok_or("Nelder–Mead: no point")?;
    Ok((best, state.get_best_cost()))
}
