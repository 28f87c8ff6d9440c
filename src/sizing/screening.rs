//! Motor sizing: for each joint, which motor of a catalogue and which gear ratio carry a motion.
//!
//! A larger ratio N multiplies the torque (η·N·T) but divides the top speed (the motor turns N·q̇)
//! and multiplies the rotor's inertia seen at the joint (J_r·N²). The sweep rates every (motor,
//! ratio) of every joint on the commanded motion first, cheaply and exactly: the inverse dynamics of
//! the motion give each joint's torque τ(t) without any rotor; a candidate adds its own J_r·N²·q̈ (the
//! reflected inertia sits on M's diagonal, so a joint's rotor changes only its own torque) and must
//! give, with the margin m on torque and on speed,
//!
//!   (1 + m)·|τ(t) + J_r·N²·q̈(t)| ≤ min(η·N·T_motor(N·(1 + m)·|q̇(t)|), gearbox rating)   at every t.
//!
//! The feasible candidates are ranked: the lightest motor, then the smallest ratio that keeps the
//! margin on torque and on speed. A larger ratio would only add speed and reflected inertia and
//! spend the speed a faster motion needs; and "the ratio with the most margin" is not monotone — on
//! the box model's J4 it climbs from 32 to 50 as the wave slows from 1.2 to 0.3 rad/s, recommending a
//! stronger drive for a gentler motion — while the smallest sufficient ratio never falls with a
//! heavier payload and never rises with a slower motion. Only the best and the runner-up of each joint
//! are simulated (stepper mode, or PD on servos), all joints with their motors at once, in parallel;
//! a joint whose choice loses steps or uses more than 1/(1 + m) of its torque in the full simulation
//! moves on to its next candidate with more torque to spare, until the whole set passes.

use crate::actuator::{Catalogue, DriveTrain, LossyGear, MotorSet};
use crate::config::RunConfig;
use crate::control::demand::along_commanded_motion;
use crate::error::Error;
use crate::experiment::Experiment;
use crate::model::Model;
use rayon::prelude::*;
use serde::Serialize;

/// What to size for.
pub struct SizeRequest {
    /// The motion: one or more experiments (name, config); every one must pass.
    pub motions: Vec<(String, RunConfig)>,
    /// The model as loaded (each motion's config adds its tool, payload, gravity switch).
    pub model: Model,
    /// The payload the motions carry, kg (for the report).
    pub payload_kg: f64,
    pub catalogue: Catalogue,
    /// Candidate motors (catalogue names with a mass).
    pub motors: Vec<String>,
    /// The reductions to try after the motor (and after a gearmotor's own gearbox).
    pub reductions: Reductions,
    /// Up to this many catalogue stages per drive train: 1, or 2 (a reduction, then a belt).
    pub max_stages: usize,
    /// Headroom on torque and on speed: 0.3 asks for 30 % more than the motion needs. None: the
    /// vendors' margin for each motor kind ([`vendor_margin`]).
    pub margin: Option<f64>,
    /// Efficiency of an ideal reduction (`Reductions::Ideal`; 1 at ratio 1: a direct drive).
    pub efficiency: f64,
    pub microsteps: u32,
    /// Simulations at once.
    pub jobs: usize,
    /// How long the motion goes on, s, for the thermal check (None: the motions' own duration).
    pub duty: Option<f64>,
    /// Carry the candidates' parts on the arm (false: the URDF's masses already include them).
    pub carry_parts: bool,
}

/// The vendors' torque margin for a motor of `kind` driven `open_loop`: 50 % for an open-loop stepper
/// (Parker; MotionControlTips' "pick a torque margin to prevent stepper stalls"), 30 % for a
/// closed-loop servo (Parker asks at least 10 %; the top of the 10–30 % range, as a sizing with
/// catalogue uncertainty should) — ../shared/reference/sizing.md [K3, K5].
pub fn vendor_margin(kind: &str, open_loop: bool) -> f64 {
    if kind == "stepper" && open_loop { 0.5 } else { 0.3 }
}

/// The load-to-rotor inertia ratio guideline for a motor of `kind` (and a stepper's `frame`), with
/// its source: Oriental Motor, open-loop NEMA17–34 steppers ≤ 10:1, NEMA8–14 ≤ 5:1, closed-loop
/// servos ≤ 30:1 (sizing.md [K2]).
pub fn inertia_ratio_guideline(kind: &str, frame: Option<&str>, open_loop: bool) -> (f64, &'static str) {
    match (kind, open_loop) {
        ("stepper", true) if frame.is_some_and(|f| ["NEMA8", "NEMA11", "NEMA14"].contains(&f)) => (5.0, "an open-loop NEMA8–14 stepper (Oriental Motor)"),
        ("stepper", true) => (10.0, "an open-loop NEMA17–34 stepper (Oriental Motor)"),
        _ => (30.0, "a closed-loop servo (Oriental Motor)"),
    }
}

/// What may follow a motor.
#[derive(Clone, Debug)]
pub enum Reductions {
    /// The catalogue's reductions of these names at each of their ratios, and a direct drive.
    Catalogue(Vec<String>),
    /// Per coordinate, ideal reductions at these ratios, of the request's efficiency (the user's own
    /// gearing, `--ratios`).
    Ideal(Vec<Vec<f64>>),
}

/// Why a candidate cannot carry the motion, at the instant where it falls shortest.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum Shortfall {
    /// Not enough torque even where the motor gives its full torque (low speed).
    Torque { at: Instant, need: f64, available: f64 },
    /// The motor's torque has fallen with speed (pull-out curve, servo line): too fast for this ratio.
    Speed { at: Instant, motor_rev_s: f64, need: f64, available: f64 },
    /// The gearbox's rated output torque is the limit.
    Gearbox { at: Instant, need: f64, rated: f64 },
    /// Without its own rotor's J_r·N² the motion would fit: the reflected inertia breaks it.
    ReflectedInertia { at: Instant, reflected: f64, need: f64, available: f64 },
    /// The motor turns faster than the reduction's input allows.
    InputSpeed { at: Instant, motor_speed: f64, limit: f64 },
    /// The cubic mean of the torque at the reduction's output exceeds its rated (average) torque.
    GearboxAverage { need: f64, rated: f64 },
    /// The motor's RMS torque over the motion (with the margin) exceeds its continuous rating.
    Rms { need: f64, continuous: f64 },
    /// The winding would pass its limit within the duty at the motion's RMS current (with the margin).
    Thermal { current: f64, reaches_limit_after: f64, duty: f64, max_temperature: f64 },
}

/// An instant of the motion: a time in one of its experiments (named when the motion has several).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Instant {
    pub t: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub experiment: Option<String>,
}

impl std::fmt::Display for Instant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "t = {:.2} s", self.t)?;
        match &self.experiment {
            Some(name) => write!(f, " of '{name}'"),
            None => Ok(()),
        }
    }
}

impl Shortfall {
    pub fn describe(&self) -> String {
        match self {
            Shortfall::Torque { at, need, available } => {
                let (need, available) = distinct(*need, *available);
                format!("torque at low speed: needs {need} N·m with the margin at {at}, gets {available}")
            }
            Shortfall::Speed { at, motor_rev_s, need, available } => {
                let (need, available) = distinct(*need, *available);
                format!("speed: at {motor_rev_s:.1} rev/s (with the margin) the motor's torque has fallen, {available} N·m for {need} needed at {at}")
            }
            Shortfall::Gearbox { at, need, rated } => {
                let (need, rated) = distinct(*need, *rated);
                format!("gearbox rating: {need} N·m needed at {at}, rated {rated}")
            }
            Shortfall::ReflectedInertia { at, reflected, need, available } => {
                let (need, available) = distinct(*need, *available);
                format!("reflected inertia: the rotor's J_r·N² = {reflected:.3} kg·m² raises the need to {need} N·m at {at}, gets {available}")
            }
            Shortfall::InputSpeed { at, motor_speed, limit } => {
                format!("input speed: the motor turns at {:.0} rpm with the margin at {at}, the reduction allows {:.0} rpm", motor_speed * 60.0 / std::f64::consts::TAU, limit * 60.0 / std::f64::consts::TAU)
            }
            Shortfall::GearboxAverage { need, rated } => {
                let (need_s, rated_s) = distinct(*need, *rated);
                format!("gearbox average torque: the cubic mean {need_s} N·m with the margin is {:.0} % over its rated {rated_s} N·m", 100.0 * (need / rated - 1.0))
            }
            Shortfall::Rms { need, continuous } => {
                let (need_s, continuous_s) = distinct(*need, *continuous);
                format!("RMS torque: the motor's {need_s} N·m RMS with the margin is {:.0} % over its continuous {continuous_s} N·m", 100.0 * (need / continuous - 1.0))
            }
            Shortfall::Thermal { current, reaches_limit_after, duty, max_temperature } => {
                format!("heat: at {current:.2} A RMS with the margin the winding reaches its {max_temperature:.0} °C after {reaches_limit_after:.0} s, within the {duty:.0} s duty")
            }
        }
    }
}

/// Two torques printed with as many decimals (2 to 4) as it takes to show that they differ.
fn distinct(a: f64, b: f64) -> (String, String) {
    let mut digits = 2;
    while digits < 4 && format!("{a:.digits$}") == format!("{b:.digits$}") {
        digits += 1;
    }
    (format!("{a:.digits$}"), format!("{b:.digits$}"))
}

/// One (motor, ratio) for one joint, rated on the commanded motion.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    pub motor: String,
    /// The catalogue reduction after the motor (None: a direct drive, or an ideal reduction); for
    /// two stages their names joined with " + ".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reduction: Option<String>,
    /// The catalogue stages from the motor out with their ratios (empty: direct or ideal).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<(String, f64)>,
    /// The motor's and the reduction's mass (a reduction without a published mass counts 0).
    pub mass_kg: f64,
    /// The ratio chosen after the motor.
    pub ratio: f64,
    /// Motor to joint, a gearmotor's own gearbox included.
    pub total_ratio: f64,
    /// The torque the joint gets at rest, N·m.
    pub torque_at_rest: f64,
    /// max over the motion of (1 + m)·need / available at (1 + m)·speed: ≤ 1 is feasible.
    pub share: f64,
    /// Torque to spare: min over the motion of available / need at its speed (×).
    pub torque_headroom: f64,
    /// Speed to spare: the joint speed at which the drive's torque has fallen to half, over the
    /// motion's top speed (×).
    pub speed_headroom: f64,
    pub shortfall: Option<Shortfall>,
    /// The margin it was rated with (the vendors' for its kind unless `--margin`).
    pub margin: f64,
    /// The motor's RMS torque over the motion at its shaft (through the gear's losses), N·m.
    pub rms_motor_torque: f64,
    /// The load's inertia over the rotor's (and the reductions' input) at the joint, J_L/(J·N²);
    /// None when the rotor's inertia is not published.
    pub inertia_ratio: Option<f64>,
    /// The motor's continuous rating, N·m, where the catalogue gives one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub continuous_torque: Option<f64>,
    /// The check its share comes from, where not the peak torque on the curve.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub binding: Option<&'static str>,
}

impl Candidate {
    pub fn feasible(&self) -> bool {
        self.share <= 1.0
    }

}

/// A candidate in the full simulation.
#[derive(Clone, Debug, Serialize)]
pub struct SimulatedCheck {
    pub candidate: usize,
    /// Driven open loop as a stepper in the simulation: its lost steps were counted (a servo or a
    /// closed-loop drive cannot lose any).
    pub stepped: bool,
    pub lost_steps: u64,
    /// Largest share of the torque available at its speed that the joint used.
    pub peak_torque_share: f64,
    pub passed: bool,
    /// Why it did not pass (the run diverged, or lost steps, or used more than the margin allows).
    pub note: Option<String>,
    /// The motor's peak winding temperature in the run, °C (motors with thermal data).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_winding_temperature: Option<f64>,
    /// A servo driven by its firmware: its motor's peak and RMS current in the run, A (the largest
    /// over the motions).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_current: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_current: Option<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct JointSizing {
    pub joint: String,
    /// Every candidate, motor by motor (lightest first), each motor's ratios in order.
    pub candidates: Vec<Candidate>,
    /// The feasible candidates, best first.
    pub ranked: Vec<usize>,
    pub chosen: Option<usize>,
    pub runner_up: Option<usize>,
    /// The candidates simulated, in the order tried.
    pub simulated: Vec<SimulatedCheck>,
    /// The rejected candidates nearest the choice: the same motor one ratio below and above the
    /// feasible band, and the next lighter motor at its best ratio.
    pub nearest_rejected: Vec<usize>,
    /// RMS of the motion's torque at the joint without any rotor, N·m, and of its acceleration, rad/s².
    pub rms_load_torque: f64,
    pub rms_acceleration: f64,
    /// The feasible candidate of the chosen motor with the lowest RMS motor torque.
    pub lowest_rms: Option<usize>,
    /// The vendors' optimal ratio N* for the chosen motor and its efficiency (pure inertia load).
    pub optimal_ratio: Option<f64>,
    /// The chosen drive's inertia ratio above the vendor's guideline for its kind: (guideline, for whom).
    pub inertia_ratio_above: Option<(f64, String)>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SizeReport {
    pub model: String,
    pub motions: Vec<String>,
    pub payload_kg: f64,
    /// `--margin`, or None: the vendors' margin per motor kind (`margins`).
    pub margin: Option<f64>,
    /// The margin used per motor kind.
    pub margins: Vec<(String, f64)>,
    pub efficiency: f64,
    pub microsteps: u32,
    pub motors: Vec<String>,
    pub joints: Vec<JointSizing>,
    /// Simulation rounds until the chosen set passed together.
    pub rounds: usize,
    /// The chosen set passed its full simulation on every motion (and the motion is free of
    /// self-collision: a colliding motion is no valid sizing).
    pub verified: bool,
    /// Where the commanded motion first brings two links into contact (experiment, time, links),
    /// checked every 10 ms of the command; None: it never does.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub collision: Option<(String, f64, String, String)>,
    /// The chosen set's full simulation, checked for collisions at every control step (the arm as it
    /// moves, tracking error included): per motion, its collision summary.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub simulated_collisions: Vec<(String, crate::collision::CollisionSummary)>,
    pub simulations: usize,
    /// The duty the thermal check used, s.
    pub duty_seconds: f64,
    /// Candidate motors whose duty was not checked, as they lack a continuous rating and thermal
    /// data (with what each lacks).
    pub duty_unchecked: Vec<String>,
    /// The URDF's mass, kg.
    pub arm_mass_kg: f64,
    /// The chosen drive trains' published mass, kg (carried on the arm unless `parts_in_urdf`).
    pub drive_mass_kg: f64,
    /// The URDF's masses already include the drive trains (nothing carried).
    pub parts_in_urdf: bool,
    /// The catalogue reductions tried (empty: ideal reductions of `efficiency`).
    pub reductions: Vec<String>,
    /// Reductions tried whose mass is not published (counted as weightless).
    pub weightless_reductions: Vec<String>,
    /// What to order, per joint ([`SizeReport::bill_rows`]).
    pub bill_of_materials: Vec<BillRow>,
}

/// One joint's line of the bill of materials.
#[derive(Clone, Debug, Serialize)]
pub struct BillRow {
    pub joint: String,
    pub motor: String,
    /// The reduction after the motor, if a catalogue one.
    pub reduction: Option<String>,
    pub ratio: f64,
    pub mass_kg: f64,
    /// The largest share of its torque at speed the full run used.
    pub peak_use: Option<f64>,
    /// The motor's RMS torque at its shaft, N·m, and its share of the continuous rating.
    pub rms_motor_torque: f64,
    pub rms_use: Option<f64>,
    /// The motor's peak winding temperature in the full run, °C.
    pub peak_winding_temperature: Option<f64>,
    /// A servo driven by its firmware: its motor's peak and RMS current in the full run, A.
    pub peak_current: Option<f64>,
    pub rms_current: Option<f64>,
    pub inertia_ratio: Option<f64>,
    /// The check that binds it.
    pub binding: String,
}

/// The commanded motion of every experiment, per joint: speed, acceleration and the torque without
/// any rotor (the rotor's share differs per candidate).
struct Motion {
    t: Vec<f64>,
    /// Per sample, the experiment it belongs to (an index into `names`).
    experiment: Vec<usize>,
    /// The experiments' names; empty for a single motion.
    names: Vec<String>,
    speed: Vec<Vec<f64>>,
    acceleration: Vec<Vec<f64>>,
    torque: Vec<Vec<f64>>,
    /// Per joint, the largest M_jj over the motion without any rotor: the load's inertia at the joint.
    load_inertia: Vec<f64>,
}

fn commanded_motion(request: &SizeRequest, model: &Model) -> Result<Motion, Error> {
    let n = model.dof();
    let names = if request.motions.len() > 1 { request.motions.iter().map(|(name, _)| name.clone()).collect() } else { Vec::new() };
    let mut motion = Motion { t: Vec::new(), experiment: Vec::new(), names, speed: vec![Vec::new(); n], acceleration: vec![Vec::new(); n], torque: vec![Vec::new(); n], load_inertia: vec![0.0; n] };
    for (index, (_, config)) in request.motions.iter().enumerate() {
        let experiment = Experiment::with_model(RunConfig { motors: None, ..config.clone() }, model.clone())?;
        let mut model = (*experiment.model).clone();
        model.armature = vec![0.0; n];
        let dt = config.dt;
        // the load's inertia at each joint, at up to 2000 instants of the motion
        let mut data = crate::dynamics::Data::new(&model);
        let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
        let samples = 2000.min((config.duration / dt) as usize).max(1);
        for k in 0..=samples {
            experiment.trajectory.sample(config.duration * k as f64 / samples as f64, &mut q, &mut qd);
            let m = crate::dynamics::crba(&model, &mut data, &q);
            for j in 0..n {
                motion.load_inertia[j] = motion.load_inertia[j].max(m[(j, j)]);
            }
        }
        along_commanded_motion(&model, experiment.trajectory.as_ref(), config.duration, dt, |t, qd, qdd, tau| {
            motion.t.push(t);
            motion.experiment.push(index);
            for j in 0..n {
                motion.speed[j].push(qd[j]);
                motion.acceleration[j].push(qdd[j]);
                motion.torque[j].push(tau[j]);
            }
        });
    }
    Ok(motion)
}

/// The first self-collision along the commanded motions, checked every 10 ms of the command (the
/// full runs follow it within their tracking error): (experiment, time, link, link).
fn commanded_collision(request: &SizeRequest, model: &Model) -> Result<Option<(String, f64, String, String)>, Error> {
    let mut own = None;
    for (name, config) in &request.motions {
        let experiment = Experiment::with_model(RunConfig { motors: None, ..config.clone() }, model.clone())?;
        // the motion's own checks (its --scene, --floor, --srdf), else self-collision
        let collisions = match &experiment.collisions {
            Some(c) => c.clone(),
            None => match &own {
                Some(c) => std::sync::Arc::clone(c),
                None => own.insert(std::sync::Arc::new(crate::collision::Collisions::new(model, None, &crate::collision::Scene::default())?)).clone(),
            },
        };
        let mut checker = collisions.checker(model);
        let (mut q, mut qd) = (vec![0.0; model.dof()], vec![0.0; model.dof()]);
        let steps = (config.duration / 0.01).ceil() as usize;
        for k in 0..=steps {
            let t = (k as f64 * 0.01).min(config.duration);
            experiment.trajectory.sample(t, &mut q, &mut qd);
            if checker.check(&q, 1e-9).colliding().next().is_some() {
                let (a, b, _) = checker.named().swap_remove(0);
                return Ok(Some((name.clone(), t, a, b)));
            }
        }
    }
    Ok(None)
}

/// The drive train of `motor` behind the catalogue's `stages` (from the motor out, each at its
/// ratio), or without any behind an ideal `ratio` at efficiency `efficiency` (1 for ratio 1).
pub fn drive_train(catalogue: &Catalogue, motor: &str, stages: &[(String, f64)], ratio: f64, efficiency: f64) -> Result<DriveTrain, Error> {
    let mut drive = catalogue.drive_train(motor).ok_or_else(|| Error::flag("--candidates", format!("no motor '{motor}' in {} (known: {})", catalogue.source.display(), catalogue.names())))??;
    if stages.is_empty() {
        return Ok(drive.followed_by(ratio, LossyGear::with_efficiency(if ratio == 1.0 { 1.0 } else { efficiency }), f64::INFINITY));
    }
    for (name, ratio) in stages {
        let r = catalogue.reduction(name).ok_or_else(|| Error::flag("--reductions", format!("no reduction '{name}' in {} (known: {})", catalogue.source.display(), catalogue.reduction_names())))?;
        drive = drive.then_reduction(r, *ratio).ok_or_else(|| Error::flag("--reductions", format!("'{name}' has no ratio {ratio}")))?;
    }
    Ok(drive)
}

/// One way to follow a motor: catalogue stages (from the motor out), or an ideal ratio.
#[derive(Clone, Debug)]
struct DriveOption {
    stages: Vec<(String, f64)>,
    ratio: f64,
}

/// Per joint, the drive options to try after each motor: a direct drive and every reduction at each
/// of its ratios, and with two stages every reduction followed by a belt at each of the belt's.
fn options(request: &SizeRequest, j: usize) -> Vec<DriveOption> {
    match &request.reductions {
        Reductions::Ideal(ratios) => ratios[j].iter().map(|&ratio| DriveOption { stages: Vec::new(), ratio }).collect(),
        Reductions::Catalogue(names) => {
            let mut out = vec![DriveOption { stages: Vec::new(), ratio: 1.0 }];
            let reductions: Vec<&crate::actuator::Reduction> = names.iter().filter_map(|n| request.catalogue.reduction(n)).collect();
            for r in &reductions {
                out.extend(r.ratios.iter().map(|&ratio| DriveOption { stages: vec![(r.name.clone(), ratio)], ratio }));
            }
            if request.max_stages >= 2 {
                for first in reductions.iter().filter(|r| r.kind != "belt") {
                    for belt in reductions.iter().filter(|r| r.kind == "belt") {
                        for &a in &first.ratios {
                            out.extend(belt.ratios.iter().map(|&b| DriveOption { stages: vec![(first.name.clone(), a), (belt.name.clone(), b)], ratio: (a * b * 1e9).round() / 1e9 }));
                        }
                    }
                }
            }
            out
        }
    }
}

/// Rate one candidate on joint `j`'s commanded motion: its share with the margin, torque and speed
/// headroom, and why it falls short.
fn rate(drive: &DriveTrain, motion: &Motion, j: usize, margin: f64) -> (f64, f64, f64, Option<Shortfall>) {
    let reflected = drive.reflected_inertia();
    let k = 1.0 + margin;
    let share_of = |need: f64, available: f64| if available > 0.0 { need / available } else if need > 0.0 { f64::INFINITY } else { 0.0 };
    let (mut worst, mut at, mut plain_worst, mut top_speed) = (0.0f64, 0usize, 0.0f64, 0.0f64);
    for i in 0..motion.t.len() {
        let torque = motion.torque[j][i] + reflected * motion.acceleration[j][i];
        let share = share_of(k * torque.abs(), drive.available(torque, k * motion.speed[j][i]));
        if share > worst {
            (worst, at) = (share, i);
        }
        plain_worst = plain_worst.max(share_of(torque.abs(), drive.available(torque, motion.speed[j][i])));
        top_speed = top_speed.max(motion.speed[j][i].abs());
    }
    let torque_headroom = if plain_worst > 0.0 { 1.0 / plain_worst } else { f64::INFINITY };
    let speed_headroom = if top_speed > 0.0 { drive.speed_at_fraction(0.5) / top_speed } else { f64::INFINITY };
    // the reduction's input speed, with the margin on speed
    if let Some(limit) = drive.max_motor_speed {
        let motor_speed = k * drive.gear_ratio * top_speed;
        if motor_speed > limit && motor_speed / limit > worst {
            let i = (0..motion.t.len()).max_by(|&a, &b| motion.speed[j][a].abs().total_cmp(&motion.speed[j][b].abs())).unwrap_or(0);
            let at = Instant { t: motion.t[i], experiment: motion.names.get(motion.experiment[i]).cloned() };
            return (motor_speed / limit, torque_headroom, speed_headroom, Some(Shortfall::InputSpeed { at, motor_speed, limit }));
        }
    }
    if worst <= 1.0 {
        return (worst, torque_headroom, speed_headroom, None);
    }
    let instant = Instant { t: motion.t[at], experiment: motion.names.get(motion.experiment[at]).cloned() };
    let speed = k * motion.speed[j][at];
    let torque = motion.torque[j][at] + reflected * motion.acceleration[j][at];
    let need = k * torque.abs();
    let braking = torque * speed < 0.0;
    let motor_torque = drive.motor_torque(torque, speed);
    let available = drive.available(torque, speed);
    let without_rotor = (0..motion.t.len()).all(|i| {
        let torque = motion.torque[j][i];
        k * torque.abs() <= drive.available(torque, k * motion.speed[j][i])
    });
    let shortfall = if drive.rated_torque < drive.gear.efficiency * motor_torque {
        Shortfall::Gearbox { at: instant, need, rated: drive.rated_torque }
    } else if without_rotor && reflected > 0.0 {
        Shortfall::ReflectedInertia { at: instant, reflected, need, available }
    } else if !braking && drive.motor.torque_at(drive.gear_ratio * speed) < 0.9 * drive.motor.torque_at(0.0) {
        Shortfall::Speed { at: instant, motor_rev_s: (drive.gear_ratio * speed).abs() / std::f64::consts::TAU, need, available }
    } else {
        Shortfall::Torque { at: instant, need, available }
    };
    (worst, torque_headroom, speed_headroom, Some(shortfall))
}

/// The vendors' duty checks of one candidate on joint `j`'s motion, beside the peak check: the
/// motor's RMS torque (the motion's, with its rotor and the gearbox's losses, times 1 + margin)
/// against its continuous rating, and with thermal data, the winding at that RMS current (through
/// K_t) against its limit over `duty` seconds from ambient. Returns the larger share (≤ 1 passes)
/// and why it fails.
fn rate_duty(drive: &DriveTrain, motion: &Motion, j: usize, margin: f64, duty: f64, rms_motor_torque: f64) -> (f64, Option<Shortfall>, &'static str) {
    let reflected = drive.reflected_inertia();
    let samples = motion.t.len().max(1) as f64;
    // the gearbox makers' average torque: the cubic mean at the output (Harmonic Drive's T_av)
    let gearbox = drive.rated_average_torque.map(|rated| {
        let cubic = (0..motion.t.len()).map(|i| (motion.torque[j][i] + reflected * motion.acceleration[j][i]).abs().powi(3)).sum::<f64>() / samples;
        let need = (1.0 + margin) * cubic.cbrt();
        (need / rated, (need > rated).then_some(Shortfall::GearboxAverage { need, rated }))
    });
    let (gearbox_share, gearbox_shortfall) = gearbox.unwrap_or((0.0, None));
    const AVERAGE: &str = "gearbox average torque";
    if drive.continuous_torque.is_none() && drive.heat.is_none() {
        return (gearbox_share, gearbox_shortfall, AVERAGE);
    }
    let need = (1.0 + margin) * rms_motor_torque;
    let (mut share, mut shortfall, mut binding) = (0.0f64, None, "RMS torque");
    if let Some(continuous) = drive.continuous_torque {
        share = need / continuous;
        if share > 1.0 {
            shortfall = Some(Shortfall::Rms { need, continuous });
        }
    }
    if let Some(heat) = drive.heat {
        // a stepper's driver current flows whatever the load (the margin is on torque, not on it)
        let current = heat.set_current.unwrap_or(need / heat.torque_constant);
        let winding = crate::actuator::thermal::MotorHeat::new(heat.thermal, crate::actuator::thermal::AMBIENT_TEMPERATURE, 1.0);
        let thermal_share = match winding.time_to_limit(current) {
            Some(after) => {
                if after <= duty && shortfall.is_none() {
                    shortfall = Some(Shortfall::Thermal { current, reaches_limit_after: after, duty, max_temperature: heat.thermal.max_winding_temperature });
                }
                if after > 0.0 { duty / after } else { f64::INFINITY }
            }
            // never reaches it: the steady rise's share of the allowed rise
            None => match heat.thermal.steady_winding_temperature(current, winding.ambient) {
                Some(steady) => (steady - winding.ambient) / (heat.thermal.max_winding_temperature - winding.ambient),
                None => f64::INFINITY,
            },
        };
        if thermal_share > share {
            (share, binding) = (thermal_share, "winding temperature over the duty");
        }
    }
    if gearbox_share > share {
        (share, binding) = (gearbox_share, AVERAGE);
    }
    (share, shortfall.or(gearbox_shortfall), binding)
}

/// The motor's RMS torque at its shaft over joint `j`'s motion — through the gear's losses, over the
/// ratio — without margin.
fn rms_motor_torque(drive: &DriveTrain, motion: &Motion, j: usize) -> f64 {
    let reflected = drive.reflected_inertia();
    let samples = motion.t.len().max(1) as f64;
    ((0..motion.t.len()).map(|i| (drive.gear.motor_torque_for(motion.torque[j][i] + reflected * motion.acceleration[j][i], motion.speed[j][i]) / drive.gear_ratio).powi(2)).sum::<f64>() / samples).sqrt()
}

/// The ratio with the lowest RMS motor torque for a pure inertia load, the vendors' optimum
/// N* = √(rms τ_load / (η·J·rms q̈)) (van de Straete's; sizing.md §1), for a motor of shaft inertia
/// `shaft_inertia` behind efficiency `efficiency`; None without a rotor inertia or acceleration.
pub fn optimal_ratio(rms_load_torque: f64, rms_acceleration: f64, shaft_inertia: f64, efficiency: f64) -> Option<f64> {
    (shaft_inertia > 0.0 && rms_acceleration > 0.0).then(|| (rms_load_torque / (efficiency * shaft_inertia * rms_acceleration)).sqrt())
}

impl SizeRequest {
    /// Open-loop steppers: the motions run in stepper mode.
    pub fn open_loop(&self) -> bool {
        self.motions.first().is_some_and(|(_, c)| c.drive == crate::config::DriveMode::Native)
    }

    /// The margin for a candidate of `motor`: `--margin`, else the vendors' for its kind.
    pub fn margin_for(&self, motor: &str) -> f64 {
        self.margin.unwrap_or_else(|| vendor_margin(self.catalogue.kind(motor), self.open_loop()))
    }
}

/// Size every actuated joint; see the module's notes for the method.
pub fn size(request: &SizeRequest) -> Result<SizeReport, Error> {
    let model = &request.model;
    let n = model.dof();
    let duty = request.duty.unwrap_or_else(|| request.motions.iter().map(|(_, config)| config.duration).sum());
    // from the tool inward: each joint rated on the motion of the arm carrying the parts already
    // chosen beyond it (a motor sits on or before its own joint, so joint j carries those of k > j)
    let mut joints: Vec<JointSizing> = (0..n).map(|j| JointSizing { joint: model.joints[j].name.clone(), candidates: Vec::new(), ranked: Vec::new(), chosen: None, runner_up: None, simulated: Vec::new(), nearest_rejected: Vec::new(), rms_load_torque: 0.0, rms_acceleration: 0.0, lowest_rms: None, optimal_ratio: None, inertia_ratio_above: None }).collect();
    let mut motion = commanded_motion(request, model)?;
    let collision = commanded_collision(request, model)?;
    let mut carried_so_far = 0.0;
    for j in (0..n).rev() {
        if request.carry_parts && model.is_actuated(j) {
            let set: Vec<Option<usize>> = (0..n).map(|k| if k > j { joints[k].ranked.first().copied() } else { None }).collect();
            let motors = motor_set(request, &joints, &set)?;
            let parts = crate::actuator::carried::placed_parts(model, &motors).map_err(|m| Error::flag("--motors", m))?;
            let mass: f64 = parts.iter().map(|p| p.part.mass).sum();
            if mass != carried_so_far {
                let mut carrying = model.clone();
                crate::actuator::carried::carry(&mut carrying, &parts);
                motion = commanded_motion(request, &carrying)?;
                carried_so_far = mass;
            }
        }
        let mut candidates = Vec::new();
        if model.is_actuated(j) {
            let options = options(request, j);
            let top_speed = motion.speed[j].iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for motor in &request.motors {
                let motor_mass = request.catalogue.mass(motor).unwrap_or(f64::NAN);
                for option in &options {
                    // the first stage takes the motor's flange; a belt after it takes any output
                    if option.stages.first().is_some_and(|(r, _)| !request.catalogue.fits(motor, r)) {
                        continue;
                    }
                    let ratio = option.ratio;
                    let reduction = (!option.stages.is_empty()).then(|| option.stages.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(" + "));
                    let mass_kg = motor_mass + option.stages.iter().filter_map(|(r, _)| request.catalogue.reduction(r)?.mass).sum::<f64>();
                    let drive = drive_train(&request.catalogue, motor, &option.stages, ratio, request.efficiency)?;
                    let margin = request.margin_for(motor);
                    let (peak_share, torque_headroom, speed_headroom, peak_shortfall) = rate(&drive, &motion, j, margin);
                    let rms_motor_torque = rms_motor_torque(&drive, &motion, j);
                    let (duty_share, duty_shortfall, duty_binding) = rate_duty(&drive, &motion, j, margin, duty, rms_motor_torque);
                    let binding = if duty_share > peak_share {
                        Some(duty_binding)
                    } else if matches!(peak_shortfall, Some(Shortfall::InputSpeed { .. })) || drive.max_motor_speed.is_some_and(|w| (1.0 + margin) * drive.gear_ratio * top_speed >= peak_share * w) {
                        Some("reduction input speed")
                    } else {
                        None
                    };
                    let reflected = drive.reflected_inertia();
                    let inertia_ratio = (reflected > 0.0).then(|| motion.load_inertia[j] / reflected);
                    let share = peak_share.max(duty_share);
                    let shortfall = peak_shortfall.or(duty_shortfall);
                    candidates.push(Candidate { motor: motor.clone(), reduction, stages: option.stages.clone(), mass_kg, ratio, total_ratio: drive.gear_ratio, torque_at_rest: drive.torque_limit(0.0), share, torque_headroom, speed_headroom, shortfall, margin, rms_motor_torque, inertia_ratio, binding, continuous_torque: drive.continuous_torque });
                }
            }
        }
        let mut ranked: Vec<usize> = (0..candidates.len()).filter(|&c| candidates[c].feasible()).collect();
        ranked.sort_by(|&a, &b| {
            let (x, y) = (&candidates[a], &candidates[b]);
            x.mass_kg.total_cmp(&y.mass_kg).then(x.motor.cmp(&y.motor)).then(x.ratio.total_cmp(&y.ratio)).then(x.reduction.cmp(&y.reduction))
        });
        joints[j].candidates = candidates;
        joints[j].ranked = ranked;
        let rms = |x: &[f64]| (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt();
        joints[j].rms_load_torque = rms(&motion.torque[j]);
        joints[j].rms_acceleration = rms(&motion.acceleration[j]);
    }

    // simulate: the set of each joint's current pick, and beside it each joint's next candidate
    let pool = rayon::ThreadPoolBuilder::new().num_threads(request.jobs.max(1)).build().map_err(|e| Error::flag("--jobs", e.to_string()))?;
    let mut pick = vec![0usize; n];
    let (mut rounds, mut verified, mut simulations) = (0, false, 0);
    let sizable: Vec<usize> = (0..n).filter(|&j| !joints[j].candidates.is_empty()).collect();
    let max_rounds = 40;
    // first pass: jump on the estimate, then walk back down; if the walked-down set fails together,
    // a second pass climbs from there one candidate at a time
    let mut extrapolate = true;
    'passes: loop {
    while rounds < max_rounds && sizable.iter().all(|&j| pick[j] < joints[j].ranked.len()) {
        rounds += 1;
        let current = picked(&joints, &pick);
        let mut sets: Vec<(Option<usize>, Vec<Option<usize>>)> = vec![(None, current.clone())];
        for &j in &sizable {
            if let Some(&next) = joints[j].ranked.get(pick[j] + 1) {
                let mut set = current.clone();
                set[j] = Some(next);
                sets.push((Some(j), set));
            }
        }
        let results: Vec<Result<Vec<JointRun>, Error>> = pool.install(|| sets.par_iter().map(|(_, set)| simulate_set(request, &joints, set)).collect());
        simulations += sets.len();
        let mut results = results.into_iter();
        let whole = results.next().expect("the whole set is always simulated")?;
        let mut failing = false;
        for &j in &sizable {
            let candidate = current[j].expect("every sizable joint has a pick in the loop");
            let check = check(candidate, &whole[j], joints[j].candidates[candidate].margin);
            if !check.passed {
                failing = true;
                // what fails in the full run is torque: the full run used the share s of what the
                // motor gave where the motion alone needs 1/headroom of it; a candidate of the same
                // motor passes only with the headroom scaled by s·(1 + m), so move past the others
                let failed = &joints[j].candidates[candidate];
                let used = check.peak_torque_share.max(if check.lost_steps > 0 { 1.0 } else { 0.0 });
                let scale = if extrapolate { (used * (1.0 + failed.margin)).max(1.0) } else { 0.0 };
                let (motor, needed) = (failed.motor.clone(), failed.torque_headroom * scale);
                let js = &joints[j];
                pick[j] += 1;
                while let Some(&next) = js.ranked.get(pick[j]) {
                    let c = &js.candidates[next];
                    if c.motor == motor && c.torque_headroom < needed {
                        pick[j] += 1;
                    } else {
                        break;
                    }
                }
            }
            joints[j].simulated.push(check);
        }
        for ((joint, set), result) in sets[1..].iter().zip(results) {
            let j = joint.expect("the others are one joint's next candidate");
            let candidate = set[j].expect("set above");
            let margin = joints[j].candidates[candidate].margin;
            joints[j].simulated.push(check(candidate, &result?[j], margin));
        }
        if !failing {
            verified = true;
            break;
        }
    }
    if verified && extrapolate {
        // the jumps above skipped candidates on an estimate: walk each joint back down while the
        // candidate ranked just before its choice passes in the full run (all in parallel), then check
        // the whole set once more (if the set no longer passes together, keep the one that did)
        let before = pick.clone();
        let mut open: Vec<usize> = sizable.iter().copied().filter(|&j| pick[j] > 0).collect();
        while !open.is_empty() {
            let current = picked(&joints, &pick);
            let probes: Vec<(usize, Vec<Option<usize>>)> = open
                .iter()
                .map(|&j| {
                    let mut set = current.clone();
                    set[j] = Some(joints[j].ranked[pick[j] - 1]);
                    (j, set)
                })
                .collect();
            let results: Vec<Result<Vec<JointRun>, Error>> = pool.install(|| probes.par_iter().map(|(_, set)| simulate_set(request, &joints, set)).collect());
            simulations += probes.len();
            let mut still = Vec::new();
            for ((j, set), result) in probes.into_iter().zip(results) {
                let candidate = set[j].expect("set above");
                let probe = check(candidate, &result?[j], joints[j].candidates[candidate].margin);
                let passed = probe.passed;
                joints[j].simulated.push(probe);
                if passed {
                    pick[j] -= 1;
                    if pick[j] > 0 {
                        still.push(j);
                    }
                }
            }
            open = still;
        }
        if pick != before {
            let set = picked(&joints, &pick);
            let whole = simulate_set(request, &joints, &set)?;
            simulations += 1;
            let checks: Vec<SimulatedCheck> = sizable.iter().map(|&j| {
                let c = set[j].expect("sizable");
                check(c, &whole[j], joints[j].candidates[c].margin)
            }).collect();
            let passed = checks.iter().all(|c| c.passed);
            for (&j, c) in sizable.iter().zip(checks) {
                joints[j].simulated.push(c);
            }
            if !passed {
                // climb from the walked-down set, one candidate at a time
                for &j in &sizable {
                    let c = joints[j].simulated.last().expect("pushed above");
                    if !c.passed {
                        pick[j] += 1;
                    }
                }
                verified = false;
                extrapolate = false;
                continue 'passes;
            }
        }
    }
    break;
    }
    for j in sizable {
        let js = &mut joints[j];
        js.chosen = js.ranked.get(pick[j]).copied();
        // the runner-up: the next candidate that passed its own simulation, else the next ranked
        js.runner_up = js.ranked.iter().skip(pick[j] + 1).copied().find(|&c| js.simulated.iter().any(|s| s.candidate == c && s.passed)).or_else(|| js.ranked.get(pick[j] + 1).copied());
        js.nearest_rejected = nearest_rejected(js);
        if let Some(c) = js.chosen {
            let chosen = js.candidates[c].clone();
            js.lowest_rms = js.ranked.iter().copied().filter(|&x| js.candidates[x].motor == chosen.motor).min_by(|&a, &b| js.candidates[a].rms_motor_torque.total_cmp(&js.candidates[b].rms_motor_torque));
            let drive = drive_train(&request.catalogue, &chosen.motor, &chosen.stages, chosen.ratio, request.efficiency)?;
            js.optimal_ratio = optimal_ratio(js.rms_load_torque, js.rms_acceleration, drive.shaft_inertia(), drive.gear.efficiency);
            let (guideline, whom) = inertia_ratio_guideline(request.catalogue.kind(&chosen.motor), request.catalogue.frame(&chosen.motor), request.open_loop());
            if chosen.inertia_ratio.is_some_and(|r| r > guideline) {
                js.inertia_ratio_above = Some((guideline, whom.to_string()));
            }
        }
    }
    // the chosen set's motion, checked for collisions at every control step (the commanded path
    // was checked before; the arm as it moves, with its tracking error, is checked here)
    let simulated_collisions = if collision.is_none() && joints.iter().any(|js| js.chosen.is_some()) {
        let set: Vec<Option<usize>> = joints.iter().map(|js| js.chosen).collect();
        simulations += request.motions.len();
        request
            .motions
            .iter()
            .map(|(name, config)| {
                let experiment = Experiment::with_motors(RunConfig { collisions: true, ..config.clone() }, request.model.clone(), Some(motor_set(request, &joints, &set)?))?;
                let summary = crate::sim::simulate(&experiment, &mut [], None)?;
                Ok((name.clone(), summary.collisions.unwrap_or_default()))
            })
            .collect::<Result<Vec<_>, Error>>()?
    } else {
        Vec::new()
    };
    let simulated_contact = simulated_collisions.iter().any(|(_, c)| c.first_contact.is_some());
    let drive_mass_kg = {
        let set: Vec<Option<usize>> = joints.iter().map(|js| js.chosen).collect();
        // (a fold from +0: an empty f64 sum is −0, which the report printed as "-0.000 kg")
        motor_set(request, &joints, &set)?.joints.iter().flatten().fold(0.0, |total, d| total + d.mass())
    };
    let mut report = SizeReport {
        model: model.name.clone(),
        motions: request.motions.iter().map(|(name, _)| name.clone()).collect(),
        payload_kg: request.payload_kg,
        margin: request.margin,
        margins: {
            let mut m: Vec<(String, f64)> = Vec::new();
            for motor in &request.motors {
                let kind = request.catalogue.kind(motor).to_string();
                if !m.iter().any(|(k, _)| *k == kind) {
                    m.push((kind, request.margin_for(motor)));
                }
            }
            m
        },
        efficiency: request.efficiency,
        microsteps: request.microsteps,
        motors: request.motors.clone(),
        joints,
        rounds,
        verified: verified && collision.is_none() && !simulated_contact,
        collision,
        simulated_collisions,
        simulations,
        duty_seconds: duty,
        duty_unchecked: request
            .motors
            .iter()
            .filter(|m| request.catalogue.drive_train(m).and_then(Result::ok).is_some_and(|d| d.continuous_torque.is_none() && d.heat.is_none()))
            .cloned()
            .collect(),
        arm_mass_kg: model.frames_mass(),
        drive_mass_kg,
        parts_in_urdf: !request.carry_parts,
        reductions: match &request.reductions {
            Reductions::Catalogue(names) => names.clone(),
            Reductions::Ideal(_) => Vec::new(),
        },
        weightless_reductions: match &request.reductions {
            Reductions::Catalogue(names) => names.iter().filter(|n| request.catalogue.reduction(n).is_some_and(|r| r.mass.is_none())).cloned().collect(),
            Reductions::Ideal(_) => Vec::new(),
        },
        bill_of_materials: Vec::new(),
    };
    report.bill_of_materials = report.bill_rows();
    Ok(report)
}

/// Each joint's candidate at its place `pick` in its ranking (None past the end, or with no candidates).
fn picked(joints: &[JointSizing], pick: &[usize]) -> Vec<Option<usize>> {
    joints.iter().zip(pick).map(|(js, &p)| js.ranked.get(p).copied()).collect()
}

/// One joint in the simulations of a set over every motion.
#[derive(Clone, Debug, Default)]
struct JointRun {
    /// Driven open loop as a stepper in some motion.
    stepped: bool,
    lost_steps: u64,
    peak_torque_share: f64,
    /// The divergence message, if a run diverged at this joint.
    diverged: Option<String>,
    /// Where it did worst, when the motion has several experiments: the first that lost steps, else
    /// the one with the largest torque share.
    worst_experiment: Option<String>,
    peak_winding_temperature: Option<f64>,
    peak_current: Option<f64>,
    rms_current: Option<f64>,
}

fn check(candidate: usize, run: &JointRun, margin: f64) -> SimulatedCheck {
    let allowed = 1.0 / (1.0 + margin);
    let inside = run.worst_experiment.as_ref().map_or(String::new(), |name| format!(" (in '{name}')"));
    let note = if let Some(message) = &run.diverged {
        Some(message.clone())
    } else if run.lost_steps > 0 {
        Some(format!("lost {} full steps{inside}", run.lost_steps))
    } else if run.peak_torque_share > allowed {
        Some(format!("used {:.0} % of the torque available at its speed (the margin allows {:.0} %){inside}", 100.0 * run.peak_torque_share, 100.0 * allowed))
    } else {
        None
    };
    SimulatedCheck { candidate, stepped: run.stepped, lost_steps: run.lost_steps, peak_torque_share: run.peak_torque_share, passed: note.is_none(), note, peak_winding_temperature: run.peak_winding_temperature, peak_current: run.peak_current, rms_current: run.rms_current }
}

/// The motor set of per-joint candidates (None: the joint keeps its URDF effort).
pub fn motor_set(request: &SizeRequest, joints: &[JointSizing], set: &[Option<usize>]) -> Result<MotorSet, Error> {
    let n = set.len();
    let mut motors = MotorSet::empty(n, "armscope size");
    if !request.carry_parts {
        motors.mounts = vec![crate::actuator::Mount::InUrdf; n];
    }
    for (j, choice) in set.iter().enumerate() {
        if let Some(c) = choice {
            let candidate = &joints[j].candidates[*c];
            motors.joints[j] = Some(drive_train(&request.catalogue, &candidate.motor, &candidate.stages, candidate.ratio, request.efficiency)?);
            motors.microsteps[j] = Some(request.microsteps);
        }
    }
    Ok(motors)
}

/// Simulate every motion with the set; per joint: full steps lost, peak torque share, and the
/// divergence message if the run diverged on this joint.
fn simulate_set(request: &SizeRequest, joints: &[JointSizing], set: &[Option<usize>]) -> Result<Vec<JointRun>, Error> {
    let n = set.len();
    let mut out = vec![JointRun::default(); n];
    let several = request.motions.len() > 1;
    for (name, config) in &request.motions {
        let motors = motor_set(request, joints, set)?;
        let experiment = Experiment::with_motors(config.clone(), request.model.clone(), Some(motors))?;
        let summary = crate::sim::simulate(&experiment, &mut [], None)?;
        let stepped = experiment.stepped_joints();
        for (j, run) in out.iter_mut().enumerate() {
            run.stepped |= stepped.get(j).copied().unwrap_or(false);
            let lost = summary.lost_steps.get(j).copied().unwrap_or(0);
            let share = summary.peak_torque_share.get(j).copied().unwrap_or(0.0);
            let first_loss = lost > 0 && run.lost_steps == 0;
            if several && (first_loss || (run.lost_steps == 0 && share > run.peak_torque_share)) {
                run.worst_experiment = Some(name.clone());
            }
            run.lost_steps += lost;
            run.peak_torque_share = run.peak_torque_share.max(share);
            if let Some(Some(w)) = summary.winding.get(j) {
                run.peak_winding_temperature = Some(run.peak_winding_temperature.unwrap_or(f64::NEG_INFINITY).max(w.peak_temperature));
            }
            if let Some(Some(servo)) = summary.servos.get(j) {
                run.peak_current = Some(run.peak_current.unwrap_or(0.0).max(servo.peak_current));
                run.rms_current = Some(run.rms_current.unwrap_or(0.0).max(servo.rms_current));
            }
        }
        if let crate::summary::RunStatus::Diverged { joint, message, .. } = &summary.status {
            if let Some(j) = request.model.joint_index(joint) {
                out[j].diverged = Some(if several { format!("'{name}': {message}") } else { message.clone() });
            }
        }
    }
    Ok(out)
}

/// The rejected candidates nearest the choice (see [`JointSizing::nearest_rejected`]).
fn nearest_rejected(js: &JointSizing) -> Vec<usize> {
    let Some(chosen) = js.chosen.or(js.ranked.first().copied()) else {
        // nothing feasible: the closest miss
        return (0..js.candidates.len()).min_by(|&a, &b| js.candidates[a].share.total_cmp(&js.candidates[b].share)).into_iter().collect();
    };
    let c = &js.candidates[chosen];
    let same_motor: Vec<usize> = (0..js.candidates.len()).filter(|&i| js.candidates[i].motor == c.motor).collect();
    let mut out = Vec::new();
    if let Some(&below) = same_motor.iter().rev().find(|&&i| js.candidates[i].ratio < c.ratio && !js.candidates[i].feasible()) {
        out.push(below);
    }
    if let Some(&above) = same_motor.iter().find(|&&i| js.candidates[i].ratio > c.ratio && !js.candidates[i].feasible()) {
        out.push(above);
    }
    // the next lighter motor, where it comes closest
    let lighter = js.candidates.iter().filter(|x| x.mass_kg < c.mass_kg).map(|x| x.mass_kg).fold(f64::NEG_INFINITY, f64::max);
    if let Some(best) = (0..js.candidates.len()).filter(|&i| js.candidates[i].mass_kg == lighter).min_by(|&a, &b| js.candidates[a].share.total_cmp(&js.candidates[b].share)) {
        out.push(best);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a pure inertia load τ = I·q̈ the motor's RMS torque through N is rms q̈·(I/(η·N) + J·N):
    /// least at N = √(I/(η·J)), which the formula gives from the RMS of torque and acceleration.
    #[test]
    fn the_optimal_ratio_minimises_the_rms_motor_torque_of_an_inertia_load() {
        let (inertia, rotor, efficiency, acceleration) = (0.02, 5.4e-6, 0.8, 3.0);
        let n = optimal_ratio(inertia * acceleration, acceleration, rotor, efficiency).unwrap();
        let rms_motor = |n: f64| acceleration * (inertia / (efficiency * n) + rotor * n);
        assert!((n - (inertia / (efficiency * rotor)).sqrt()).abs() < 1e-9);
        assert!(rms_motor(n) < rms_motor(n * 1.001) && rms_motor(n) < rms_motor(n / 1.001));
        assert_eq!(optimal_ratio(1.0, 1.0, 0.0, 0.9), None, "no rotor inertia, no optimum");
    }

    #[test]
    fn the_vendors_margins_and_inertia_guidelines_by_kind() {
        assert_eq!((vendor_margin("stepper", true), vendor_margin("stepper", false), vendor_margin("servo", true), vendor_margin("dc", false)), (0.5, 0.3, 0.3, 0.3));
        assert_eq!(inertia_ratio_guideline("stepper", Some("NEMA14"), true).0, 5.0);
        assert_eq!(inertia_ratio_guideline("stepper", Some("NEMA17"), true).0, 10.0);
        assert_eq!(inertia_ratio_guideline("servo", None, true).0, 30.0);
    }
}

