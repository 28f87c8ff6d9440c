//! An arm identified from its own teleoperated episodes (`identify --from DATASET`): what the forward
//! replay needs to follow the real follower — each servo kind's firmware, motor and friction
//! parameters (shared by the servos of one kind: an arm's episodes cannot tell them apart), their
//! command delay, and optionally the payload — fitted by CMA-ES on the mean gap between the simulated
//! and the real follower over the training episodes, starting from the motor file's (the catalogue's)
//! parameters, each kept within BAM's bounds (no negative friction, a delay within 0–0.1 s).

use super::cmaes::Cmaes;
use super::space::Space;
use crate::actuator::bus_servo::ServoParams;
use crate::actuator::MotorSet;
use crate::error::Error;
use crate::model::Model;
use crate::replay::forward::{Drives, FollowSetup, ForwardCase, gap_within};

/// The servo parameters an arm's motion tells: the loop's gain and the motor's torque (k_t, the
/// error gain), the rotor's inertia, the friction's base and viscous parts, and the command delay.
/// The rest (the resistance beside k_t, the Stribeck shape, the goal-speed bound) trade off against
/// these on an arm's slow motions and stay the motor file's; so do the load-dependent frictions
/// (the gearbox's loss per N·m it carries), which a bench pins by hanging known masses and an arm's
/// few poses do not: fitted on the real SO-101's two shared episodes they traded against the loop's
/// stiffness from seed to seed (the motor-side one anywhere from 0.15 to its 0.5 bound at gaps
/// within 0.15 mrad), where without them five seeds find one stiffness (×0.37 of the catalogue's).
pub const ARM_KEYS: [&str; 6] = ["kt", "error_gain_ratio", "armature", "friction_base", "friction_viscous", "command_delay"];

/// How far from its start a scale of the servo (its motor constant, loop gain, rotor inertia,
/// resistance, speed bound) is searched: a factor of 4 either way. An arm's slow motion trades the
/// rotor's inertia against the links' and k_t against the error gain; the catalogue's bench fit
/// pins their scale, and a rotor inertia far below it is no geared servo's (and stiffens the plant:
/// every halving of it doubles the steps a run needs).
const SCALE_RANGE: f64 = 4.0;

/// The parameters that are scales of the servo, searched within [`SCALE_RANGE`] of their start.
const SCALES: [&str; 5] = ["kt", "error_gain_ratio", "armature", "R", "max_velocity"];

/// `space`'s scales narrowed to within [`SCALE_RANGE`] of `start` (and BAM's bounds).
fn around(space: &mut Space, start: &ServoParams) {
    for d in space.dimensions.iter_mut().filter(|d| SCALES.contains(&d.key)) {
        // the start as the space holds it: clamped into BAM's bounds
        let value = d.value(d.coordinate(super::space::get(start, d.key)));
        if value > 0.0 {
            d.lower = d.lower.max(value / SCALE_RANGE);
            d.upper = d.upper.min(value * SCALE_RANGE);
            d.logarithmic = true;
        }
    }
}

/// Every parameter a servo of `family` with friction `model` can have fitted on an arm (ARM_KEYS'
/// and the rest of BAM's but the bench's angle offset).
pub fn fittable(motors: &MotorSet, fitted: &[usize]) -> Vec<&'static str> {
    let mut keys: Vec<&'static str> = Vec::new();
    for &j in fitted {
        let Some(servo) = motors.joints[j].as_ref().and_then(|d| d.servo.as_ref()) else { continue };
        let p = servo.params();
        for d in Space::new(p.family, p.friction.model, true, true, true).dimensions {
            if d.key != "q_offset" && !keys.contains(&d.key) {
                keys.push(d.key);
            }
        }
    }
    keys
}

/// How a fitted servo holds against the one it started from, at the same P gain and supply: the
/// position loop's torque per rad of error (k_t·e_g·r·k_p·V/R: the ratio of k_t × error gain / R)
/// and its stall torque (k_t·d_max·V/R: the ratio of k_t / R). An arm's episodes pin the first
/// (within 10 % on a simulated follower); k_t and the error gain apart trade with each other.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Strength {
    pub holding_stiffness: f64,
    pub stall_torque: f64,
}

impl Strength {
    pub fn of(fitted: &ServoParams, start: &ServoParams) -> Self {
        let stiffness = |p: &ServoParams| p.kt * p.error_gain_ratio / p.resistance;
        let stall = |p: &ServoParams| p.kt / p.resistance;
        Self { holding_stiffness: stiffness(fitted) / stiffness(start), stall_torque: stall(fitted) / stall(start) }
    }

    /// What a holding stiffness outside 3/4–4/3 of the start's says of the real servos, in words
    /// (None within it: the catalogue's servo, as far as these episodes tell).
    pub fn verdict(&self) -> Option<&'static str> {
        if self.holding_stiffness < 0.75 {
            Some("the real servos hold weaker than the motor file's: a lower supply, a weaker variant of the servo, or a load at the tool the URDF lacks (fitted unless --payload is given)")
        } else if self.holding_stiffness > 4.0 / 3.0 {
            Some("the real servos hold stiffer than the motor file's: a higher supply, a stronger variant of the servo, or a higher P gain than the motor file's kp")
        } else {
            None
        }
    }
}

/// The loss of a candidate whose run diverged or failed, rad: worse than any follower's gap.
const FAILED: f64 = 10.0;

/// One kind of servo on the arm: its name, the joints it drives, its parameters to start from, and
/// the space they are searched in.
#[derive(Clone, Debug)]
pub struct ServoKind {
    pub name: String,
    pub joints: Vec<usize>,
    pub start: ServoParams,
    pub space: Space,
    /// The parameters of this one joint's servo (`--per-joint`), not of every servo of the name.
    pub one_joint: bool,
}

impl ServoKind {
    /// Whether the drive of joint `joint`, a servo named `servo`, takes this kind's parameters: the
    /// kind's own joint, or every servo of its name (those left out of the fit too: the same part).
    pub fn drives(&self, joint: usize, servo: &str) -> bool {
        if self.one_joint { self.joints == [joint] } else { self.name == servo }
    }
}

/// The largest calibration offset searched, rad (9°: a mid-range pose set by eye is off by a few
/// degrees; more is a wrong map, not an offset).
pub const OFFSET_RANGE: f64 = 0.15;

/// The payload at the tool: searched from 0 to `most` kg, or known, kg.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Payload {
    Fitted { most: f64 },
    Known(f64),
}

/// What is searched: each kind's parameters, then the payload (kg, 0 to its bound) where fitted,
/// then a calibration offset per joint of `offsets` (model coordinates) where fitted.
#[derive(Clone, Debug)]
pub struct ArmSpace {
    pub kinds: Vec<ServoKind>,
    pub payload: Payload,
    pub offsets: Vec<usize>,
    pub dof: usize,
}

impl ArmSpace {
    /// The servo kinds of `motors` on the joints `fitted` (model coordinates) with their parameters
    /// `keys` (those their family has), the `payload`, and the fitted joints' offsets where asked.
    /// With `per_joint` each fitted joint's servo is a kind of its own, named "SERVO JOINT"
    /// (`joint_names` by coordinate).
    pub fn new(motors: &MotorSet, fitted: &[usize], keys: &[&str], payload: Payload, offsets: bool, per_joint: Option<&[String]>) -> Self {
        let mut kinds: Vec<ServoKind> = Vec::new();
        for &j in fitted {
            let Some(servo) = motors.joints[j].as_ref().and_then(|d| d.servo.as_ref()) else { continue };
            match kinds.iter_mut().find(|k| per_joint.is_none() && k.name == servo.name) {
                Some(kind) => kind.joints.push(j),
                None => {
                    let start = servo.params();
                    let mut space = Space::new(start.family, start.friction.model, false, false, true).only(keys);
                    around(&mut space, &start);
                    let name = per_joint.map_or_else(|| servo.name.clone(), |names| format!("{} {}", servo.name, names[j]));
                    kinds.push(ServoKind { name, joints: vec![j], start, space, one_joint: per_joint.is_some() });
                }
            }
        }
        Self { kinds, payload, offsets: if offsets { fitted.to_vec() } else { Vec::new() }, dof: motors.joints.len() }
    }

    pub fn len(&self) -> usize {
        self.kinds.iter().map(|k| k.space.len()).sum::<usize>() + usize::from(self.fits_payload()) + self.offsets.len()
    }

    pub fn fits_payload(&self) -> bool {
        matches!(self.payload, Payload::Fitted { .. })
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The start: each kind's own parameters, no payload.
    pub fn start(&self) -> Vec<f64> {
        let mut u: Vec<f64> = self.kinds.iter().flat_map(|k| k.space.point(&k.start)).collect();
        if self.fits_payload() {
            u.push(0.0);
        }
        u.extend(self.offsets.iter().map(|_| 0.5));
        u
    }

    /// Each kind's parameters, the payload and the offsets (per coordinate) at point `u`.
    pub fn decode(&self, u: &[f64]) -> (Vec<ServoParams>, f64, Vec<f64>) {
        let mut at = 0;
        let params = self
            .kinds
            .iter()
            .map(|k| {
                let p = k.space.params_from(&k.start, &u[at..at + k.space.len()]);
                at += k.space.len();
                p
            })
            .collect();
        let payload = match self.payload {
            Payload::Fitted { most } => most * u[at].clamp(0.0, 1.0),
            Payload::Known(kg) => kg,
        };
        at += usize::from(self.fits_payload());
        let mut offsets = vec![0.0; self.dof];
        for (k, &j) in self.offsets.iter().enumerate() {
            offsets[j] = OFFSET_RANGE * (2.0 * u[at + k].clamp(0.0, 1.0) - 1.0);
        }
        (params, payload, offsets)
    }
}

/// The mean gap over the training episodes of a candidate: what the search minimises.
pub struct ArmObjective<'a> {
    pub model: &'a Model,
    /// The motor file's drives as read once (its path their `source`); each candidate's are a copy
    /// with its parameters: reading the file and its catalogue again for each of a candidate's
    /// runs took 5 % of its instructions.
    pub drives: &'a MotorSet,
    pub tool: Option<&'a str>,
    pub space: &'a ArmSpace,
    pub cases: &'a [ForwardCase],
    /// Per model coordinate: in the loss.
    pub fitted: Vec<bool>,
    /// The floor the real tool rested on, where the episodes show one (else the motor file's).
    pub floor: Option<crate::plant::FloorContact>,
}

impl ArmObjective<'_> {
    /// The motor file's drives with the servo parameters `params` (by kind).
    pub fn motors(&self, params: &[ServoParams]) -> MotorSet {
        let mut set = self.drives.clone();
        if self.floor.is_some() {
            set.floor = self.floor;
        }
        for (kind, p) in self.space.kinds.iter().zip(params) {
            for (j, d) in set.joints.iter_mut().enumerate() {
                if let Some(servo) = d.as_mut().and_then(|d| d.servo.as_mut()).filter(|s| kind.drives(j, &s.name)) {
                    servo.set_params(p);
                }
            }
        }
        set
    }

    /// The frames × fitted joints the loss averages over.
    fn samples(&self) -> usize {
        self.cases.iter().map(|c| c.frames() * c.compared().iter().filter(|&&j| self.fitted[j]).count()).sum()
    }

    /// The mean |simulated − real| over the training episodes' frames and fitted joints, rad; a
    /// candidate whose mean passes `cutoff` is stopped there, its loss then the part it had reached
    /// (past the cutoff: a lower bound, enough to rank it last).
    pub fn loss(&self, u: &[f64], cutoff: f64) -> f64 {
        let (params, payload, offsets) = self.space.decode(u);
        let make = || Ok(self.motors(&params));
        let setup = FollowSetup { payload, tool: self.tool, offsets: (!self.space.offsets.is_empty()).then_some(offsets.as_slice()), without_floor: false };
        let samples = self.samples().max(1) as f64;
        let budget = if cutoff.is_finite() { cutoff * samples } else { f64::INFINITY };
        let mut sum = 0.0;
        for case in self.cases {
            match gap_within(self.model, case, &Drives::Made { file: &self.drives.source, make: &make }, &setup, &self.fitted, budget - sum) {
                Ok((part, stopped)) => {
                    sum += part;
                    if stopped {
                        break;
                    }
                }
                Err(_) => return FAILED,
            }
        }
        if sum.is_finite() { sum / samples } else { FAILED }
    }
}

/// How the search runs.
#[derive(Clone, Debug)]
pub struct ArmFitOptions {
    /// Candidates a generation (0: [`super::cmaes::default_population`]).
    pub population: usize,
    /// Generations a search.
    pub generations: usize,
    /// The first step, on the unit cube.
    pub sigma: f64,
    /// The first search's seed (search k uses seed + k).
    pub seed: u64,
    /// Searches from the start, each with its own seed.
    pub searches: usize,
    /// Losses closer than this to the best are not told apart (rad): of the searches that end
    /// within it, the one whose servos hold nearest their start is kept.
    pub indistinct: f64,
    /// A search ends once its best loss has improved over this many generations by no more than
    /// [`settled_tolerance`] (0: every search runs all its generations).
    pub settled_after: usize,
    pub jobs: usize,
}

impl Default for ArmFitOptions {
    fn default() -> Self {
        Self { population: 0, generations: 60, sigma: 0.1, seed: 1, searches: 1, indistinct: 0.0, settled_after: 0, jobs: 1 }
    }
}

/// Where one search ended.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SearchEnd {
    pub seed: u64,
    #[serde(rename = "gap_rad")]
    pub loss: f64,
    #[serde(rename = "payload_kg")]
    pub payload: f64,
    /// Per servo kind, its holding stiffness against its start.
    pub holding_stiffness: Vec<f64>,
    /// The generations it ran (fewer than asked where it settled).
    pub generations: usize,
    #[serde(skip)]
    point: Vec<f64>,
}

impl SearchEnd {
    /// How far its servos hold from their starts: Σ |ln stiffness| over the kinds.
    fn from_start(&self) -> f64 {
        self.holding_stiffness.iter().map(|s| s.ln().abs()).sum()
    }
}

/// The fit: the point kept, its loss, the start's, every search's end, and how many candidates
/// were run.
#[derive(Clone, Debug)]
pub struct ArmFit {
    pub point: Vec<f64>,
    pub params: Vec<ServoParams>,
    pub payload: f64,
    /// Per coordinate (0 where not fitted), rad (m).
    pub offsets: Vec<f64>,
    pub loss: f64,
    pub start_loss: f64,
    pub searches: Vec<SearchEnd>,
    /// The search kept (an index of `searches`).
    pub kept: usize,
    pub evaluations: usize,
}

/// The readings' own error, rad: the mean |error| of the real follower's recorded positions on the
/// fitted joints (an encoder's quantum δ rounds by δ/4 on average; noise σ by σ·√(2/π)). A gap
/// between two fits smaller than this is below what the recording resolves.
pub fn reading_error(cases: &[ForwardCase], fitted: &[bool]) -> f64 {
    let errors: Vec<f64> = cases
        .iter()
        .flat_map(|c| c.compared().iter().filter(|&&j| fitted[j]).filter_map(|&j| c.real().smoothing[j].as_ref()))
        .map(|s| s.quantum.map_or(s.noise * std::f64::consts::FRAC_2_PI.sqrt(), |q| q / 4.0))
        .collect();
    if errors.is_empty() { 0.0 } else { errors.iter().sum::<f64>() / errors.len() as f64 }
}

/// Minimise `objective` from its space's start, `options.searches` times with successive seeds,
/// and keep, of the searches ending within `options.indistinct` of the best, the one whose servos
/// hold nearest their start: an arm's episodes can leave a ridge (the servos' stiffness against a
/// load at the tool) flat to well below their readings' resolution, and along it the motor file's
/// servo (the catalogue's bench identification) is what is known. `progress` sees (generations
/// counted over the searches, a settled search's remaining ones with its last; best loss so far).
pub fn fit_arm(objective: &ArmObjective, options: &ArmFitOptions, progress: &(dyn Fn(usize, f64) + Sync)) -> Result<ArmFit, Error> {
    use rayon::prelude::*;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(options.jobs.max(1)).build().map_err(|e| Error::flag("--jobs", e.to_string()))?;
    let start = objective.space.start();
    let start_loss = objective.loss(&start, f64::INFINITY);
    let population = if options.population >= 2 { options.population } else { super::cmaes::default_population(start.len()) };
    // the generations done over all the searches, and the best loss so far
    let so_far = std::sync::Mutex::new((0usize, start_loss));
    let report = |generations: usize, loss: f64| {
        let mut so_far = so_far.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        *so_far = (so_far.0 + generations, so_far.1.min(loss));
        progress(so_far.0, so_far.1);
    };
    // the searches are independent (each its own seed: the same ends in any order), so they run
    // at once: the cores then share every search's candidates, where one search's generation at a
    // time left a core idle while its last candidates finished (186 % of two cores busy)
    let ends: Vec<Searched> = pool.install(|| (0..options.searches.max(1)).into_par_iter().map(|k| search(objective, &start, start_loss, options, population, options.seed + k as u64, &report)).collect());
    let mut evaluations = 1;
    let mut searches = Vec::new();
    for (k, end) in ends.into_iter().enumerate() {
        evaluations += end.evaluations;
        let (params, payload, _) = objective.space.decode(&end.point);
        let holding_stiffness = objective.space.kinds.iter().zip(&params).map(|(kind, p)| Strength::of(p, &kind.start).holding_stiffness).collect();
        searches.push(SearchEnd { seed: options.seed + k as u64, loss: end.loss, payload, holding_stiffness, generations: end.generations, point: end.point });
    }
    let kept = nearest_start_of_the_best(&searches, options.indistinct);
    let point = searches[kept].point.clone();
    let (params, payload, offsets) = objective.space.decode(&point);
    Ok(ArmFit { point, params, payload, offsets, loss: searches[kept].loss, start_loss, searches, kept, evaluations })
}

/// Of the searches ending within `indistinct` of the best loss, the one whose servos hold nearest
/// their starts.
fn nearest_start_of_the_best(searches: &[SearchEnd], indistinct: f64) -> usize {
    let best = searches.iter().map(|s| s.loss).fold(f64::INFINITY, f64::min);
    (0..searches.len()).filter(|&i| searches[i].loss <= best + indistinct).min_by(|&a, &b| searches[a].from_start().total_cmp(&searches[b].from_start())).unwrap_or(0)
}

/// How much a search's best loss may improve over [`ArmFitOptions::settled_after`] generations and
/// the search count as settled, rad: a tenth of what the recording resolves (`indistinct`: further
/// progress that small could not tell its end from another search's) and a hundredth of the loss
/// itself (a recording the model follows to its readings' error has its parameters pinned by
/// smaller steps).
pub fn settled_tolerance(indistinct: f64, best: f64) -> f64 {
    (0.1 * indistinct).min(0.01 * best)
}

/// Whether a search whose best loss after each generation so far was `history` has settled: over
/// its last `after` generations (0: never) the best fell by no more than [`settled_tolerance`].
fn settled(history: &[f64], after: usize, indistinct: f64) -> bool {
    match (history.last(), history.len().checked_sub(after + 1)) {
        (Some(&best), Some(earlier)) if after > 0 => history[earlier] - best <= settled_tolerance(indistinct, best),
        _ => false,
    }
}

/// Where one search ended: its best point, that point's loss, the candidates it ran and the
/// generations.
struct Searched {
    point: Vec<f64>,
    loss: f64,
    evaluations: usize,
    generations: usize,
}

/// One CMA-ES search from `start` (whose loss is `start_loss`), its candidates run on the current
/// rayon pool, for `options.generations` or until it settles. `progress` sees each generation's
/// best loss (with the generations it stands for: a settled search's last, those it leaves).
fn search(objective: &ArmObjective, start: &[f64], start_loss: f64, options: &ArmFitOptions, population: usize, seed: u64, progress: &(dyn Fn(usize, f64) + Sync)) -> Searched {
    use rayon::prelude::*;
    let (mut best, mut best_loss) = (start.to_vec(), start_loss);
    let mut es = Cmaes::new(start, options.sigma, population, seed);
    let mut evaluations = 0;
    // the best loss after each generation
    let mut history = Vec::with_capacity(options.generations);
    for generation in 1..=options.generations {
        let candidates = es.ask();
        let cutoff = es.cutoff();
        let losses: Vec<f64> = candidates.points.par_iter().map(|u| objective.loss(u, cutoff)).collect();
        evaluations += losses.len();
        for (u, &l) in candidates.points.iter().zip(&losses) {
            // a stopped candidate's loss is past the cutoff, never below the best
            if l < best_loss {
                (best, best_loss) = (u.clone(), l);
            }
        }
        es.tell(candidates, &losses);
        history.push(best_loss);
        if generation < options.generations && settled(&history, options.settled_after, options.indistinct) {
            progress(options.generations - generation + 1, best_loss);
            break;
        }
        progress(1, best_loss);
    }
    Searched { point: best, loss: best_loss, evaluations, generations: history.len() }
}

#[cfg(test)]
mod tests {
    use super::{SearchEnd, Strength, nearest_start_of_the_best, settled};

    #[test]
    fn a_search_settles_once_its_best_has_stood_still_for_as_many_generations_as_asked() {
        // the real SO-101's search of seed 2 (mrad): 9.09 from its 12th generation on; its readings'
        // error 0.38 mrad, so progress of up to 0.038 counts as standing still
        let mut history: Vec<f64> = (0..11).map(|g| 1e-3 * (11.0 - 0.16 * g as f64)).collect();
        history.extend(std::iter::repeat_n(9.09e-3, 21));
        assert!(!settled(&history[..31], 20, 0.38e-3), "19 generations still: not yet");
        assert!(settled(&history, 20, 0.38e-3), "20 generations still (its 32nd): settled");
        assert!(!settled(&history, 0, 0.38e-3), "0: never");
        // its last 15 generations of 60 found 0.36 mrad: moving, whatever the window
        let moving: Vec<f64> = (0..21).map(|g| 1e-3 * (9.09 - 0.018 * g as f64)).collect();
        assert!(!settled(&moving, 20, 0.38e-3));
        // a simulated follower fitted to 0.42 mrad: steps of 0.01 mrad still count there (1 % of the
        // gap is finer than a tenth of the readings' error)
        let fine: Vec<f64> = (0..21).map(|g| 1e-3 * (0.62 - 0.01 * g as f64)).collect();
        assert!(!settled(&fine, 20, 0.38e-3));
        let still: Vec<f64> = (0..21).map(|g| 1e-3 * (0.4210 - 0.0002 * g as f64)).collect();
        assert!(settled(&still, 20, 0.38e-3));
    }

    #[test]
    fn of_the_searches_the_recording_cannot_tell_apart_the_one_nearest_the_start_is_kept() {
        let end = |loss: f64, stiffness: f64| SearchEnd { seed: 0, loss, payload: 0.0, holding_stiffness: vec![stiffness], generations: 60, point: Vec::new() };
        // the real SO-101's three searches (seeds 1–3): 8.51, 9.09 and 8.68 mrad at ×0.37, ×0.54, ×0.48
        let ridge = [end(8.51e-3, 0.37), end(9.09e-3, 0.54), end(8.68e-3, 0.48)];
        // its readings' error, 0.38 mrad: the first and the third are one, the stiffer (nearer ×1)
        // kept; the second, past the error, is not, though stiffer still
        assert_eq!(nearest_start_of_the_best(&ridge, 0.38e-3), 2);
        // a finer recording tells them apart: the best kept
        assert_eq!(nearest_start_of_the_best(&ridge, 0.1e-3), 0);
        // nearness is by ratio, either way: ×1.6 is nearer ×1 than ×0.5
        assert_eq!(nearest_start_of_the_best(&[end(1e-3, 0.5), end(1e-3, 1.6)], 1e-4), 1);
        // a search far worse is never kept, however near its start
        assert_eq!(nearest_start_of_the_best(&[end(8.51e-3, 0.37), end(9.87e-3, 1.0)], 0.38e-3), 0);
    }

    #[test]
    fn strength_is_held_against_the_start_at_the_same_gain_and_supply() {
        let catalogue = crate::actuator::Catalogue::load(std::path::Path::new(crate::actuator::catalogue::DEFAULT_CATALOGUE)).unwrap();
        let start = catalogue.servo_params("STS3215-C018").unwrap().unwrap();
        let scaled = |kt: f64, gain: f64, resistance: f64| {
            let mut p = start.clone();
            p.kt *= kt;
            p.error_gain_ratio *= gain;
            p.resistance *= resistance;
            Strength::of(&p, &start)
        };
        // a servo of 0.65 the torque constant (the STS3215's 19.5 kg·cm 7.4 V variant against the
        // 30 kg·cm 12 V one, catalogue-sources.md §2) and 0.8 the loop gain holds with half the
        // stiffness: said so
        let weak = scaled(0.65, 0.8, 1.0);
        assert!((weak.holding_stiffness - 0.52).abs() < 1e-12 && (weak.stall_torque - 0.65).abs() < 1e-12, "{weak:?}");
        assert!(weak.verdict().unwrap().starts_with("the real servos hold weaker"));
        // twice the resistance halves both
        let resistive = scaled(1.0, 1.0, 2.0);
        assert!((resistive.holding_stiffness - 0.5).abs() < 1e-12 && (resistive.stall_torque - 0.5).abs() < 1e-12);
        // k_t and the gain traded against each other: the same stiffness, no verdict
        assert!((scaled(0.8, 1.25, 1.0).holding_stiffness - 1.0).abs() < 1e-12);
        assert_eq!(scaled(0.8, 1.25, 1.0).verdict(), None);
        assert!(scaled(1.5, 1.0, 1.0).verdict().unwrap().starts_with("the real servos hold stiffer"));
    }
}
