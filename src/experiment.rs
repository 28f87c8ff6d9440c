//! A [`RunConfig`] checked and resolved against its model: everything the simulation loop needs.

use crate::config::{DriveMode, IntegratorKind, RunConfig};
use crate::control::controller::PdGravityController;
use crate::error::Error;
use crate::control::gains::{Gains, TUTORIAL_KD, TUTORIAL_KP, auto_tune, is_tutorial_model};
use crate::control::within_effort::{MOTION_LOAD, START_LOAD, carried_wave, holdable_pose, overloaded_by_weight};
use crate::plant::{JointFriction, ContinuousPlant, DiscretePlant, Plant, Tolerances};
use crate::actuator::{FirmwareDrives, MotorSet, OpenLoopSteppers, load_motor_file};
use crate::model::{LoadOptions, Model, load_urdf_with};
use crate::control::sampled_loop::LoopPlant;
use crate::control::trajectory::{Hold, JointSchedule, JointStep, JointWave, RampIn, Trajectory, Wave};
use nalgebra::Vector3;
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum PlantSpec {
    /// `substeps` plant steps of `time_step` per control period.
    Discrete { time_step: f64, substeps: usize },
    Continuous { rtol: f64, atol: f64 },
}

impl PlantSpec {
    /// The discrete plant's step, s; None for the continuous plant (its steps are its own).
    pub fn time_step(&self) -> Option<f64> {
        match *self {
            PlantSpec::Discrete { time_step, .. } => Some(time_step),
            PlantSpec::Continuous { .. } => None,
        }
    }
}

pub struct Experiment {
    pub config: RunConfig,
    pub model: Arc<Model>,
    pub gains: Gains,
    pub plant: PlantSpec,
    pub trajectory: Box<dyn Trajectory>,
    /// Number of control steps: the run records states k = 0..=steps.
    pub steps: usize,
    /// The start pose (`--q0`, or 0 clamped into each joint's range).
    pub start: Vec<f64>,
    /// The motors of `--motors`: each named joint's torque limit at its speed.
    pub motors: Option<Arc<MotorSet>>,
    /// Stepper mode (`--motors` with steppers, `--drive stepper`): the open-loop steppers at rest,
    /// energized where the command starts; `start` is that pose plus the sag at which each stepper
    /// carries its share of the weight. Each run drives a copy.
    pub steppers: Option<OpenLoopSteppers>,
    /// Firmware mode (`--motors` with servos that have a firmware model, `--drive native`): the
    /// joints their servos' position loops drive, at rest where the command starts, sagged under
    /// the weight. Each run drives a copy.
    pub servos: Option<FirmwareDrives>,
    /// The collision checks (`--collisions`, `--floor`, `--srdf`): the shapes and active pairs.
    pub collisions: Option<Arc<crate::collision::Collisions>>,
}

impl Experiment {
    /// Load the model named by the config and check every setting against it.
    pub fn prepare(config: RunConfig) -> Result<Self, Error> {
        let model = load_urdf_with(&config.urdf, LoadOptions { strict_inertia: config.strict_inertia })?;
        Self::with_model(config, model)
    }

    pub fn with_model(config: RunConfig, model: Model) -> Result<Self, Error> {
        let motors = match &config.motors {
            Some(path) => Some(load_motor_file(path, &model)?),
            None => None,
        };
        Self::with_motors(config, model, motors)
    }

    /// As [`Self::with_model`], with the motors given directly instead of by `config.motors` (which
    /// only names their file here): how `armscope size` tries candidate motor sets.
    pub fn with_motors(config: RunConfig, model: Model, motors: Option<MotorSet>) -> Result<Self, Error> {
        Self::build(config, model, motors, None)
    }

    /// As [`Self::with_motors`], following `schedule`: the one `config.trajectory` names, already
    /// read (a forward replay follows one episode's schedule once per candidate motor set).
    pub fn following(config: RunConfig, model: Model, motors: Option<MotorSet>, schedule: JointSchedule) -> Result<Self, Error> {
        if config.trajectory.is_none() {
            return Err(Error::flag("--trajectory", "a schedule to follow is given, but the configuration names none"));
        }
        Self::build(config, model, motors, Some(schedule))
    }

    fn build(config: RunConfig, mut model: Model, motors: Option<MotorSet>, schedule: Option<JointSchedule>) -> Result<Self, Error> {
        // the URDF's own numbers first: its errors name the file
        crate::dynamics::check_solvable(&model)?;
        let positive = |flag: &str, value: f64| {
            if value.is_finite() && value > 0.0 { Ok(()) } else { Err(Error::flag(flag, format!("must be a positive number of seconds (got {value})"))) }
        };
        positive("--duration", config.duration)?;
        positive("--dt", config.dt)?;
        positive("--print-every", config.print_every)?;
        if !(config.settle_time >= 0.0) {
            return Err(Error::flag("--settle-time", "must not be negative"));
        }
        for (flag, v) in [("--freq", config.freq), ("--amp-deg", config.amp_deg), ("--test-angle", config.test_angle)] {
            if !v.is_finite() {
                return Err(Error::flag(flag, format!("must be a finite number (got {v})")));
            }
        }
        if config.no_gravity {
            model.gravity = Vector3::zeros();
        }
        apply_friction_scale(&config, &mut model)?;
        if let Some(tool) = &config.tool {
            model.set_tool_frame(tool).map_err(|m| Error::flag("--tool", m))?;
        }
        if !(config.payload >= 0.0 && config.payload.is_finite()) {
            return Err(Error::flag("--payload", format!("must be a mass in kg, not negative (got {})", config.payload)));
        }
        // the experiment is fitted to the robot as its URDF describes it (ranges, effort limits);
        // a payload and motors are then tried on it
        let mut start = start_pose(&config, &model)?;
        let trajectory: Box<dyn Trajectory> = match schedule {
            Some(schedule) => Box::new(schedule),
            None => trajectory(&config, &mut model, &mut start)?,
        };
        let mut model = model.with_payload(config.payload);
        if let Some(set) = &motors {
            install_drive_trains(&mut model, set)?;
        }
        // a payload (or the parts carried) heavy enough to swamp the joints' own inertias in
        // rounding leaves a plant that cannot be solved: said here, naming what made it so (without
        // either, the inertias are the URDF's, checked above)
        let added_mass = config.payload > 0.0 || motors.is_some();
        if added_mass
            && let Err(e) = crate::dynamics::check_solvable(&model)
        {
            return Err(if config.payload > 0.0 { Error::flag("--payload", format!("{:e} kg: {}", config.payload, e.kind)) } else { Error::flag("--motors", e.kind.to_string()) });
        }
        let motors = motors.map(Arc::new);
        let mut plant = plant_spec(&config)?;
        if motors.as_ref().is_some_and(|m| m.floor.is_some()) && matches!(plant, PlantSpec::Continuous { .. }) {
            return Err(Error::flag("--time-step", "0 (the continuous plant): the motor file's [floor] is a contact the discrete plant takes"));
        }
        let steppers = match &motors {
            Some(motors) if config.drive == DriveMode::Native && motors.has_steppers() => stepper_setup(&config, &mut model, motors, trajectory.as_ref(), &mut start, &mut plant),
            _ => None,
        };
        let servos = match &motors {
            Some(motors) if config.drive == DriveMode::Native => servo_setup(&config, &mut model, motors, &mut start, &mut plant)?,
            _ => None,
        };
        weight_notices(&mut model, &start);
        // every actuated joint left to a servo's firmware or an open-loop stepper: the PD drives none
        let pd_drives_none = (0..model.dof()).all(|j| !model.is_actuated(j) || servos.as_ref().is_some_and(|s| s.driven[j]) || steppers.as_ref().is_some_and(|s| s.stepped[j]));
        let gains = if pd_drives_none && config.kp.is_none() && config.kd.is_none() { Gains::no_pd_joint(model.dof()) } else { gains(&config, &model, &start, trajectory.as_ref(), &plant)? };
        let steps = (config.duration / config.dt - 1e-9).ceil() as usize;
        let mut config = config;
        if let Some(z) = config.floor.filter(|z| z.is_infinite()) {
            return Err(Error::flag("--floor", format!("must be a height in m (got {z})")));
        }
        if config.floor.is_some_and(f64::is_nan) {
            // at the base: the world height of the link the first joint hangs from
            let base = (!model.bodies.is_empty()).then(|| model.parent_link(0)).flatten().map(|f| &model.frames[f]);
            let z = base.map_or(0.0, |f| f.placement.translation.z);
            model.notices.push(format!("--floor: at the base's height, z = {z} m (of '{}')", base.map_or("the world", |f| f.name.as_str())));
            config.floor = Some(z);
        }
        let collisions = if config.collisions || config.floor.is_some() || config.srdf.is_some() || config.scene.is_some() {
            let (scene, notice) = crate::collision::Scene::from_flags(config.scene.as_deref(), config.floor)?;
            model.notices.extend(notice);
            let c = crate::collision::Collisions::new(&model, config.srdf.as_deref(), &scene)?;
            model.notices.extend(c.notices.iter().cloned());
            Some(Arc::new(c))
        } else {
            None
        };
        Ok(Self { config, model: Arc::new(model), gains, plant, trajectory, steps, start, motors, steppers, servos, collisions })
    }

    /// The PD controller, on the motors' limits with `--motors`; the joints an open-loop stepper or
    /// a servo's firmware drives are left to them.
    pub fn controller(&self) -> PdGravityController {
        let n = self.model.dof();
        let controller = PdGravityController::new(self.gains.kp.clone(), self.gains.kd.clone(), self.model.effort_limits(), (0..n).map(|i| self.model.is_actuated(i)).collect(), !self.config.no_ff);
        let controller = match &self.motors {
            Some(motors) => controller.with_motors(motors.clone(), self.start.clone()),
            None => controller,
        };
        let stepped = self.stepped_joints();
        controller.leaving(self.firmware_joints().iter().zip(&stepped).map(|(&a, &b)| a || b).collect())
    }

    pub fn make_plant(&self) -> Box<dyn Plant> {
        let gears = self.gears();
        match self.plant {
            PlantSpec::Discrete { time_step, substeps } => {
                let plant = DiscretePlant::with_friction(&self.model, time_step, substeps, self.joint_friction());
                match self.floor_contact() {
                    Some(floor) => Box::new(plant.with_floor(floor, self.model.dof())),
                    None => Box::new(plant),
                }
            }
            PlantSpec::Continuous { rtol, atol } => {
                Box::new(ContinuousPlant::with_gears(&self.model, self.config.dt, Tolerances { rtol, atol }, &gears))
            }
        }
    }

    /// The floor under the arm's tool from the motor file's `[floor]` (not the collision checks'
    /// `--floor`): the plant's contact, the recordings' table.
    pub fn floor_contact(&self) -> Option<crate::plant::FloorContact> {
        self.motors.as_ref().and_then(|m| m.floor)
    }

    /// Per coordinate, its motor's thermal data and gear ratio (`--motors`, where the catalogue
    /// gives the motor's thermal data; None elsewhere).
    pub fn motor_heat(&self) -> Vec<Option<(crate::actuator::thermal::WindingHeat, f64)>> {
        self.motors.as_ref().map_or_else(|| vec![None; self.model.dof()], |m| m.heat())
    }

    /// Per coordinate, the gearbox losses of the joint's drive train (`--motors`; None without).
    pub fn gears(&self) -> Vec<Option<crate::actuator::LossyGear>> {
        self.motors.as_ref().map_or_else(|| vec![None; self.model.dof()], |m| m.gears())
    }

    /// Each joint's friction: the URDF's, its gearbox's losses, its servo's (firmware mode).
    pub fn joint_friction(&self) -> JointFriction {
        let friction = JointFriction::new(&self.model, &self.gears());
        match &self.servos {
            Some(s) => friction.with_servos(&s.frictions(self.model.dof())),
            None => friction,
        }
    }

    /// Per coordinate: whether the joint has friction — the URDF's, its gearbox's losses or its
    /// servo's.
    pub fn joint_has_friction(&self) -> Vec<bool> {
        let friction = self.joint_friction();
        (0..self.model.dof()).map(|i| friction.has(i)).collect()
    }

    /// The firmware-driven servos for one run of this experiment (a fresh copy).
    pub fn firmware_drives(&self) -> Option<FirmwareDrives> {
        self.servos.clone()
    }

    /// Per joint driven by its servo's firmware, the servo's duty limit (None elsewhere).
    pub fn servo_duty_limits(&self) -> Vec<Option<f64>> {
        let mut out = vec![None; self.model.dof()];
        if let Some(s) = &self.servos {
            for (j, servo, _) in s.servos() {
                out[j] = Some(servo.firmware.family.max_duty);
            }
        }
        out
    }

    /// Per joint: driven by its servo's firmware.
    pub fn firmware_joints(&self) -> Vec<bool> {
        self.servos.as_ref().map_or_else(|| vec![false; self.model.dof()], |s| s.driven.clone())
    }

    /// Whether stepper joints run open loop.
    pub fn stepper_mode(&self) -> bool {
        self.steppers.is_some()
    }

    /// The open-loop steppers for one run of this experiment (a fresh copy at rest).
    pub fn open_loop_steppers(&self) -> Option<OpenLoopSteppers> {
        self.steppers.clone()
    }

    /// Per joint: driven open loop by a stepper.
    pub fn stepped_joints(&self) -> Vec<bool> {
        self.steppers.as_ref().map_or_else(|| vec![false; self.model.dof()], |s| s.stepped.clone())
    }

    /// The start state: the start pose (`--q0`, or every joint at 0 clamped into its range), at rest.
    pub fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        (self.start.clone(), vec![0.0; self.model.dof()])
    }

    pub fn dt(&self) -> f64 {
        self.config.dt
    }

    /// Where the command puts the tool over the run (forward kinematics of the command), sampled
    /// every `interval` seconds: the shape the recordings draw as the commanded path. A command
    /// that repeats itself is drawn over one period (the rest would retrace it), and at most
    /// `COMMANDED_PATH_POINTS` points are drawn (the interval widens): a drawing, whose size must
    /// not grow with the run.
    pub fn commanded_tool_path(&self, interval: f64) -> Vec<Vector3<f64>> {
        const COMMANDED_PATH_POINTS: usize = 20_000;
        let model = &*self.model;
        let n = model.dof();
        let mut poses = vec![crate::spatial::Pose::identity(); model.bodies.len()];
        let (mut cmd, mut cmd_dot) = (vec![0.0; n], vec![0.0; n]);
        let span = first_period(self.trajectory.as_ref(), self.config.duration);
        let samples = ((span / interval).ceil() as usize).min(COMMANDED_PATH_POINTS);
        let interval = span / samples.max(1) as f64;
        (0..=samples)
            .map(|i| {
                self.trajectory.sample((i as f64 * interval).min(span), &mut cmd, &mut cmd_dot);
                crate::dynamics::body_poses(model, &cmd, &mut poses);
                crate::dynamics::frame_pose_in(model, &poses, model.tool_frame).translation
            })
            .collect()
    }
}

fn plant_spec(config: &RunConfig) -> Result<PlantSpec, Error> {
    let continuous_by_step = config.time_step == Some(0.0);
    let kind = match (config.integrator, continuous_by_step) {
        (Some(IntegratorKind::Discrete), true) => {
            return Err(Error::flag("--time-step", "0 selects the continuous plant; it contradicts --integrator discrete"));
        }
        (Some(kind), _) => kind,
        (None, true) => IntegratorKind::Continuous,
        (None, false) => IntegratorKind::Discrete,
    };
    match kind {
        IntegratorKind::Continuous => {
            for (flag, v) in [("--rtol", config.rtol), ("--atol", config.atol)] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(Error::flag(flag, format!("must be a positive number (got {v})")));
                }
            }
            Ok(PlantSpec::Continuous { rtol: config.rtol, atol: config.atol })
        }
        IntegratorKind::Discrete => {
            let h = config.time_step.unwrap_or(config.dt);
            if !(h.is_finite() && h > 0.0) {
                return Err(Error::flag("--time-step", format!("must be positive, or 0 for the continuous plant (got {h})")));
            }
            let ratio = config.dt / h;
            let substeps = ratio.round();
            if substeps < 1.0 || (ratio - substeps).abs() > 1e-9 * ratio {
                return Err(Error::flag("--time-step", format!("{h} s must divide the control period --dt {} s a whole number of times", config.dt)));
            }
            Ok(PlantSpec::Discrete { time_step: config.dt / substeps, substeps: substeps as usize })
        }
    }
}

/// The start pose: `--q0` (a list in joint order, or NAME=VALUE pairs), the other joints at 0
/// clamped into their ranges.
fn start_pose(config: &RunConfig, model: &Model) -> Result<Vec<f64>, Error> {
    let mut q: Vec<f64> = model.joints.iter().map(|j| 0f64.clamp(j.lower, j.upper)).collect();
    let Some(spec) = &config.q0 else { return Ok(q) };
    let fail = |m: String| Error::flag("--q0", m);
    let items: Vec<&str> = spec.split(',').map(str::trim).filter(|s| !s.is_empty()).collect();
    let number = |text: &str| text.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| fail(format!("'{text}' is not a finite number")));
    if items.iter().any(|i| i.contains('=')) {
        for item in items {
            let (name, value) = item.split_once('=').ok_or_else(|| fail(format!("'{item}' is not NAME=VALUE (give all as pairs or none)")))?;
            let j = model.joint_index(name.trim()).ok_or_else(|| fail(format!("no moving joint '{}' (joints: {})", name.trim(), model.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(", "))))?;
            q[j] = number(value.trim())?;
        }
    } else {
        if items.len() != model.dof() {
            return Err(fail(format!("expected {} values (one per joint, or NAME=VALUE pairs), got {}", model.dof(), items.len())));
        }
        for (qi, item) in q.iter_mut().zip(items) {
            *qi = number(item)?;
        }
    }
    for (j, &v) in model.joints.iter().zip(&q) {
        if v < j.lower || v > j.upper {
            return Err(fail(format!("joint '{}' at {v} is outside its range [{}, {}]", j.name, j.lower, j.upper)));
        }
    }
    Ok(q)
}

/// The command. The default start pose (no `--q0`) and the default wave (no `--amp-deg`, `--freq`)
/// are fitted to the URDF's effort limits as well as its ranges: the start moved to a pose the
/// motors can hold, the wave scaled to what they can carry, each with a notice (`within_effort`).
/// The tutorial's box model needs neither.
fn trajectory(config: &RunConfig, model: &mut Model, start: &mut Vec<f64>) -> Result<Box<dyn Trajectory>, Error> {
    if let Some(path) = &config.trajectory {
        if config.hold || config.test_joint.is_some() {
            return Err(Error::flag("--trajectory", "cannot be combined with --static or --test-joint"));
        }
        return Ok(Box::new(JointSchedule::load(path, model.dof())?));
    }
    if let Some(spec) = &config.test_joint {
        if config.hold {
            return Err(Error::flag("--test-joint", "cannot be combined with --static"));
        }
        let joint = resolve_joint(spec, model)?;
        return Ok(Box::new(JointStep { joint, joint_name: model.joints[joint].name.clone(), angle: config.test_angle }));
    }
    if config.hold {
        return Ok(Box::new(Hold));
    }
    if config.q0.is_none() {
        hold_default_start(model, start);
    }
    let fitted = if !config.wave_as_asked {
        carried_default_wave(model, start, config.amp_deg, config.freq)
    } else {
        JointWave::fitted(model, start, config.amp_deg, config.freq)
    };
    let wave: Box<dyn Trajectory> = if fitted.is_uniform_about_zero(config.amp_deg.to_radians()) {
        // the tutorial's wave exactly (the box model)
        Box::new(Wave { amplitude_rad: config.amp_deg.to_radians(), omega: config.freq })
    } else {
        Box::new(fitted)
    };
    if is_tutorial_model(model) {
        // the tutorial's start (the wave's jump at t = 0 included), checked against Drake
        return Ok(wave);
    }
    // any other arm: the command starts where the arm does, at rest, and blends into the wave
    Ok(Box::new(RampIn::new(wave, start.clone())))
}

/// Move the default start pose (each joint's 0 in its range) where the URDF's motors can hold the
/// arm, if they cannot there.
fn hold_default_start(model: &mut Model, start: &mut Vec<f64>) {
    let over = overloaded_by_weight(model, start, START_LOAD);
    if over.is_empty() {
        return;
    }
    let needs = over.iter().map(|&(j, tau, e)| format!("{} {tau:.3} N·m of its {e}", model.joints[j].name)).collect::<Vec<_>>().join(", ");
    let Some(held) = holdable_pose(model, start, START_LOAD) else {
        model.notices.push(format!("the default start pose (each joint's 0 in its range) takes more than the motors give ({needs}) and no pose nearby takes less: starting there (--q0 starts elsewhere)"));
        return;
    };
    let moved = model.joints.iter().zip(held.iter().zip(start.iter())).filter(|(_, (h, s))| (*h - *s).abs() > 1e-4).map(|(j, (h, _))| format!("{}={h:.3}", j.name)).collect::<Vec<_>>().join(",");
    model.notices.push(format!(
        "the default start pose (each joint's 0 in its range) takes more than the motors give ({needs}): starting nearby, where the weight takes at most {:.0} % of every joint's effort: --q0 {moved} (--q0 starts elsewhere)",
        100.0 * START_LOAD
    ));
    *start = held;
}

/// The default wave, scaled down if the URDF's motors cannot carry it at full size.
fn carried_default_wave(model: &mut Model, start: &[f64], amp_deg: f64, freq: f64) -> JointWave {
    let (wave, share, worst) = carried_wave(model, start, amp_deg, freq, MOTION_LOAD);
    if let Some((j, tau, e)) = worst {
        model.notices.push(format!(
            "the default wave at full size ({amp_deg}°) takes more than the motors give ({} {tau:.3} N·m of its {e}): scaled to {:.0} % ({:.1}°), where the motion needs at most {:.0} % of every joint's effort (--amp-deg and --freq set the wave as asked)",
            model.joints[j].name,
            100.0 * share,
            share * amp_deg,
            100.0 * MOTION_LOAD
        ));
    }
    wave
}

/// A joint given by number (1-based, as J1..J6) or by name.
pub fn resolve_joint(spec: &str, model: &Model) -> Result<usize, Error> {
    let names = || model.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(", ");
    if let Ok(number) = spec.trim().parse::<usize>() {
        if (1..=model.dof()).contains(&number) {
            return Ok(number - 1);
        }
        return Err(Error::flag("--test-joint", format!("joint number {number} is out of range 1..{} for {}", model.dof(), model.source.display())));
    }
    model.joint_index(spec.trim()).ok_or_else(|| {
        Error::flag("--test-joint", format!("no moving joint '{spec}' in {} (joints: {})", model.source.display(), names()))
    })
}

fn gains(config: &RunConfig, model: &Model, start: &[f64], trajectory: &dyn Trajectory, plant: &PlantSpec) -> Result<Gains, Error> {
    let n = model.dof();
    let base = if is_tutorial_model(model) && !config.auto_tune {
        Gains { kp: TUTORIAL_KP.to_vec(), kd: TUTORIAL_KD.to_vec(), source: "tutorial".into(), effective_inertia: None, spectral_radius: None, bandwidth: None, damping_ratio: None }
    } else {
        // the poses the command goes through: the start and 24 along its first period (or the run)
        let mut poses = vec![start.to_vec()];
        poses.extend(along_first_period(config, model, trajectory, 0..24, 24).into_iter().map(|(pose, _)| pose));
        let loop_plant = match plant {
            PlantSpec::Discrete { .. } => LoopPlant::Discrete,
            PlantSpec::Continuous { .. } => LoopPlant::Continuous,
        };
        auto_tune(model, &poses, config.dt, !config.no_ff, loop_plant)
    };
    let expand = |flag: &str, values: &Option<Vec<f64>>, default: Vec<f64>| -> Result<(Vec<f64>, bool), Error> {
        match values {
            None => Ok((default, false)),
            Some(v) => {
                if let Some(bad) = v.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
                    return Err(Error::flag(flag, format!("gains must be finite and not negative (got {bad})")));
                }
                match v.len() {
                    1 => Ok((vec![v[0]; n], true)),
                    len if len == n => Ok((v.clone(), true)),
                    len => Err(Error::flag(flag, format!("expected 1 value or {n} (one per joint), got {len}"))),
                }
            }
        }
    };
    let (kp, kp_given) = expand("--kp", &config.kp, base.kp.clone())?;
    let (kd, kd_given) = expand("--kd", &config.kd, base.kd.clone())?;
    let source = match (kp_given, kd_given) {
        (true, true) => "flags".to_string(),
        (false, false) => base.source.clone(),
        (true, false) => format!("kp from flags, kd {}", base.source),
        (false, true) => format!("kp {}, kd from flags", base.source),
    };
    Ok(Gains { kp, kd, source, ..base })
}

/// `--friction SCALE` on every joint's Coulomb friction; a notice for each joint whose friction is
/// more than its motor's effort (its motor can never move it: Allegro's URDF gives its fingers 5–12
/// N·m against 0.7 N·m — left as the URDF says, `--friction 0` runs without).
fn apply_friction_scale(config: &RunConfig, model: &mut Model) -> Result<(), Error> {
    let scale = config.friction_scale;
    if !(scale >= 0.0 && scale.is_finite()) {
        return Err(Error::flag("--friction", format!("must be a factor ≥ 0 on the URDF's joint friction (got {scale})")));
    }
    for joint in &mut model.joints {
        joint.friction *= scale;
    }
    let effort = model.effort_limits();
    let stuck: Vec<String> = model.joints.iter().zip(&effort).filter(|(j, e)| j.friction > 0.0 && j.friction >= **e && **e > 0.0).map(|(j, e)| format!("{} ({} ≥ {e})", j.name, j.friction)).collect();
    if !stuck.is_empty() {
        model.notices.push(format!(
            "joint friction (N·m) at least the joint's effort limit, so its motor can never move it: {} (as the URDF says; --friction 0 runs without friction)",
            stuck.join(", ")
        ));
    }
    Ok(())
}

/// A joint whose motor cannot carry the arm's weight at the start pose saturates from the first step
/// on, whatever the controller does: say so before the run, naming the joint and both torques.
fn weight_notices(model: &mut Model, start: &[f64]) {
    for (j, tau_g, effort) in overloaded_by_weight(model, start, 1.0) {
        let name = model.joints[j].name.clone();
        model.notices.push(format!(
            "joint '{name}': holding the start pose against gravity takes {tau_g:.3} N·m, more than its {effort} N·m: it cannot hold the arm there and will sag (an arm whose real counterbalance springs its URDF leaves out? --q0 starts elsewhere)"
        ));
    }
}

/// The drive trains on the arm: each joint's motor (its effort at rest, its rotor's J·N² on M's
/// diagonal) and its parts as bodies (unless the motor file says the URDF has them), with one notice
/// of what was added where.
fn install_drive_trains(model: &mut Model, set: &MotorSet) -> Result<(), Error> {
    let before = crate::actuator::carried::moving_mass(model);
    let parts = crate::actuator::carried::install(model, set).map_err(|m| Error::flag("--motors", format!("{}: {m}", set.source.display())))?;
    let unweighed: Vec<String> = set
        .joints
        .iter()
        .enumerate()
        .filter(|(j, d)| d.as_ref().is_some_and(|d| d.parts.iter().all(|p| p.name != d.motor.name())) && set.mounts[*j] != crate::actuator::Mount::InUrdf)
        .map(|(j, d)| format!("{} ({})", model.joints[j].name, d.as_ref().map_or("", |d| d.motor.name())))
        .collect();
    if !parts.is_empty() {
        let on: Vec<String> = parts.iter().map(|p| format!("{} {:.3} kg on {}", p.part.name, p.part.mass, if p.link.is_empty() { "the world" } else { &p.link })).collect();
        model.notices.push(format!(
            "drive trains carried on the arm ({}): the moving mass {:.3} → {:.3} kg{}",
            on.join(", "),
            before,
            crate::actuator::carried::moving_mass(model),
            if unweighed.is_empty() { String::new() } else { format!("; motors without a published mass, not carried: {}", unweighed.join(", ")) }
        ));
    } else if !unweighed.is_empty() {
        model.notices.push(format!("motors without a published mass, not carried on the arm: {}", unweighed.join(", ")));
    }
    Ok(())
}

/// Firmware mode's set-up: the servo joints start at rest at the start pose, sagged by the error at
/// which each position loop carries its weight there (the closed form, friction aside), their
/// firmware's goal the start pose; the discrete plant only (the servos' friction budgets are its).
/// None without such servos.
fn servo_setup(config: &RunConfig, model: &mut Model, motors: &MotorSet, start: &mut [f64], plant: &mut PlantSpec) -> Result<Option<FirmwareDrives>, Error> {
    let Some(drives) = FirmwareDrives::new(motors, start, config.dt) else { return Ok(None) };
    if matches!(plant, PlantSpec::Continuous { .. }) {
        return Err(Error::flag("--time-step", format!("0 (the continuous plant): the joints driven by their servos' firmware ({}) need the discrete plant, which takes their friction budgets; --drive pd runs them on the continuous plant as torque sources", names(model, &drives.driven))));
    }
    let held = start.to_vec();
    let mut data = crate::dynamics::Data::new(model);
    let mut unheld = Vec::new();
    for _ in 0..5 {
        let tau_g = crate::dynamics::gravity_forces(model, &mut data, start).to_vec();
        unheld.clear();
        for (j, sag) in drives.rest_sag(&tau_g) {
            match sag {
                Some(sag) => start[j] = (held[j] + sag).clamp(model.joints[j].lower, model.joints[j].upper),
                None => unheld.push(model.joints[j].name.clone()),
            }
        }
    }
    let sags: Vec<String> = drives.servos().map(|(j, servo, _)| format!("{} {:.2} mrad (P gain {})", model.joints[j].name, 1e3 * (start[j] - held[j]), servo.firmware.kp)).collect();
    model.notices.push(format!("firmware mode: {} driven by their servos' position loops (not the PD controller), starting at rest at the start pose, sagged under the weight: {}", names(model, &drives.driven), sags.join(", ")));
    if !unheld.is_empty() {
        model.notices.push(format!("firmware mode: at full duty the servos of {} cannot hold the weight at the start", unheld.join(", ")));
    }
    if let PlantSpec::Discrete { substeps, .. } = *plant {
        // the firmware ticks and the back-EMF is evaluated at each plant step's start: the step
        // must resolve the position loop's oscillation and the back-EMF's damping (ω_n·h, h·c/I ≤ 0.2)
        let inertia = inertia_diagonal(model, start);
        let rate = drives.stiffness_and_damping().iter().map(|&(j, k, c)| (k / inertia[j]).sqrt().max(c / inertia[j])).fold(0.0, f64::max);
        let needed = ((rate * config.dt / 0.2).ceil() as usize).max(1);
        if needed > substeps {
            let step_ms = config.dt / needed as f64 * 1e3;
            match config.time_step {
                Some(_) => model.notices.push(format!("firmware mode: --time-step {} ms is longer than the stiffest servo's loop allows ({step_ms:.4} ms for ω_n·h, h·c/I ≤ 0.2)", config.dt / substeps as f64 * 1e3)),
                None => {
                    *plant = PlantSpec::Discrete { time_step: config.dt / needed as f64, substeps: needed };
                    model.notices.push(format!("firmware mode: plant step {step_ms:.4} ms ({needed} per control period), short enough for the stiffest servo's loop and back-EMF (ω_n·h, h·c/I ≤ 0.2); --time-step sets another"));
                }
            }
        }
    }
    Ok(Some(drives))
}

fn names(model: &Model, which: &[bool]) -> String {
    model.joints.iter().zip(which).filter(|(_, w)| **w).map(|(j, _)| j.name.as_str()).collect::<Vec<_>>().join(", ")
}

/// Stepper mode's set-up: the stepper joints start where the command starts (unless `--q0`), held at
/// the load angle that carries their weight (into `start`); the plant step is made short enough for
/// the stiffest stepper (unless `--time-step`, then a notice if it is too long). Returns the steppers
/// at rest, energized at the command's start.
fn stepper_setup(config: &RunConfig, model: &mut Model, motors: &MotorSet, trajectory: &dyn Trajectory, start: &mut Vec<f64>, plant: &mut PlantSpec) -> Option<OpenLoopSteppers> {
    if config.q0.is_none() {
        // an open-loop stepper cannot jump: the arm starts where the command starts
        let (mut cmd, mut cmd_dot) = (vec![0.0; model.dof()], vec![0.0; model.dof()]);
        trajectory.sample(0.0, &mut cmd, &mut cmd_dot);
        // and so do the other joints with motors: a servo leaping to its command would kick the steppers
        for (j, joint) in model.joints.iter().enumerate() {
            if motors.joints[j].is_some() {
                start[j] = cmd[j].clamp(joint.lower, joint.upper);
            }
        }
        model.notices.push("stepper mode: the joints with motors start where the command starts (an open-loop stepper cannot jump); --q0 sets another start".into());
    }
    let energized = start.clone();
    let mut data = crate::dynamics::Data::new(model);
    let load = crate::dynamics::gravity_forces(model, &mut data, &energized).to_vec();
    let steppers = OpenLoopSteppers::new(motors, &energized, &inertia_diagonal(model, &energized), &load)?;
    // at rest, held: each stepper lags by the load angle that carries the weight
    let mut sagged = energized.clone();
    for _ in 0..5 {
        let tau_g = crate::dynamics::gravity_forces(model, &mut data, &sagged).to_vec();
        for (j, sag) in steppers.rest_sag(&tau_g) {
            sagged[j] = energized[j] + sag.unwrap_or(0.0);
        }
    }
    let biggest = (0..model.dof()).map(|j| (sagged[j] - energized[j]).abs()).fold(0.0, f64::max);
    *start = sagged;
    model.notices.push(format!("stepper mode: the arm starts at rest, held by its steppers, each lagging by the load angle that carries its weight (at most {biggest:.2e} rad at a joint)"));
    generator_lag_notices(&steppers, model, trajectory, config, motors);
    if let PlantSpec::Discrete { substeps, .. } = *plant {
        let needed = stepper_substeps(&steppers, model, trajectory, start, config);
        if needed > substeps {
            let step_ms = config.dt / needed as f64 * 1e3;
            match config.time_step {
                Some(_) => model.notices.push(format!(
                    "stepper mode: --time-step {} ms is longer than the stiffest stepper joint's oscillation allows ({step_ms:.4} ms for ω_n·h ≤ 0.2): its lost steps are not to be trusted",
                    config.dt / substeps as f64 * 1e3
                )),
                None => {
                    *plant = PlantSpec::Discrete { time_step: config.dt / needed as f64, substeps: needed };
                    model.notices.push(format!(
                        "stepper mode: plant step {step_ms:.4} ms ({needed} per control period), short enough for the stiffest stepper joint's oscillation and damping (ω_n·h, h·c/I ≤ 0.2); --time-step sets another"
                    ));
                }
            }
        }
    }
    Some(steppers)
}

/// A step generator accelerates no faster than its bound: where the command accelerates faster, the
/// joint falls behind its command without losing a step — say so, or the tracking error reads as a fault.
fn generator_lag_notices(steppers: &OpenLoopSteppers, model: &mut Model, trajectory: &dyn Trajectory, config: &RunConfig, motors: &MotorSet) {
    const PARTS: usize = 64;
    let samples = along_first_period(config, model, trajectory, 0..PARTS + 1, PARTS);
    let interval = first_period(trajectory, config.duration) / PARTS as f64;
    for (j, bound) in steppers.generator_accelerations() {
        let peak = samples.windows(2).map(|w| ((w[1].1[j] - w[0].1[j]) / interval).abs()).fold(0.0, f64::max);
        if peak > bound {
            let whose = if motors.acceleration[j].is_some() { "the motor file's `acceleration`" } else { "by default half of what its motor spares beyond the weight; the motor file's `acceleration` sets it" };
            model.notices.push(format!(
                "stepper mode: joint '{}': the command accelerates at up to {peak:.3} rad/s², its step generator at most {bound:.3} rad/s² ({whose}): the joint will lag its command",
                model.joints[j].name
            ));
        }
    }
}

/// Plant steps per control period that keep every stepper joint's oscillation about its stable
/// position (stiffness η·N²·T_H·N_r against M_ii) resolved, ω_n·h ≤ 0.2, and its explicit damping,
/// h·c/I ≤ 0.2, over the poses the command passes (M_ii smallest there); and that let the field
/// turn at most 1/32 of an electrical period (11°) per plant step at the command's top speed (a real driver
/// steps continuously: bigger jumps ring the rotor in step with the plant).
fn stepper_substeps(steppers: &OpenLoopSteppers, model: &Model, trajectory: &dyn Trajectory, pose: &[f64], config: &RunConfig) -> usize {
    let n = model.dof();
    let mut inertia = inertia_diagonal(model, pose);
    let mut top_speed = vec![0.0f64; n];
    for (pose, cmd_dot) in along_first_period(config, model, trajectory, 0..33, 32) {
        for (m, x) in inertia.iter_mut().zip(inertia_diagonal(model, &pose)) {
            *m = m.min(x);
        }
        for (t, v) in top_speed.iter_mut().zip(&cmd_dot) {
            *t = t.max(v.abs());
        }
    }
    let omega = steppers.stiffness().iter().map(|&(j, k)| (k / inertia[j]).sqrt()).fold(0.0, f64::max);
    let rate = steppers.damping().iter().map(|&(j, c)| c / inertia[j]).fold(0.0, f64::max);
    let by_dynamics = omega.max(rate) * config.dt / 0.2;
    let by_field = steppers.electrical_speed(&top_speed) * config.dt / (std::f64::consts::TAU / 32.0);
    (by_dynamics.max(by_field).ceil() as usize).max(1)
}

/// The span of a command worth sampling: its first period, or the whole run if shorter or not periodic.
fn first_period(trajectory: &dyn Trajectory, duration: f64) -> f64 {
    trajectory.period().map_or(duration, |p| p.min(duration))
}

/// The command at times span·i/`parts` for i in `points`, span its first period (or the whole run,
/// if shorter or not periodic): each pose clamped into the joints' ranges, and the commanded speed.
fn along_first_period(config: &RunConfig, model: &Model, trajectory: &dyn Trajectory, points: std::ops::Range<usize>, parts: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    let n = model.dof();
    let span = first_period(trajectory, config.duration);
    let (mut cmd, mut cmd_dot) = (vec![0.0; n], vec![0.0; n]);
    points
        .map(|i| {
            trajectory.sample(span * i as f64 / parts as f64, &mut cmd, &mut cmd_dot);
            (cmd.iter().zip(&model.joints).map(|(&c, j)| c.clamp(j.lower, j.upper)).collect(), cmd_dot.clone())
        })
        .collect()
}

/// The mass matrix's diagonal at `q` (each joint's inertia with the others held).
fn inertia_diagonal(model: &Model, q: &[f64]) -> Vec<f64> {
    let mut data = crate::dynamics::Data::new(model);
    let m = crate::dynamics::crba(model, &mut data, q);
    (0..model.dof()).map(|j| m[(j, j)]).collect()
}
