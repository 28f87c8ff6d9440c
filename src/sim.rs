//! The simulation loop: controller and plant at the control rate, every sample to every recorder.

use crate::dynamics::{Data, body_poses, forward_kinematics, frame_pose, frame_pose_in, gravity_and_bias_from_kinematics, kinetic_energy_from_momenta, potential_energy_from_kinematics};
use crate::model::Model;
use crate::error::Error;
use crate::experiment::Experiment;
use crate::actuator::StepperOutput;
use crate::control::controller::ControlOutput;
use crate::recorder::{Recorder, RunInfo};
use crate::sample::Sample;
use crate::summary::{EnergyBalance, RunStatus, Summary, SummaryBuilder};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Run one experiment, feeding each recorder every sample. Returns the summary also when the run
/// was interrupted (`stop` set) or diverged (see [`Summary::status`]); recorders are finished in
/// every case, so their files are whole up to the last recorded sample.
pub fn simulate(experiment: &Experiment, recorders: &mut [&mut dyn Recorder], stop: Option<&AtomicBool>) -> Result<Summary, Error> {
    simulate_beside(experiment, recorders, stop, None)
}

/// A real arm's positions to record beside a simulated one (a forward replay's follower): per
/// coordinate, its samples at `time` (s from the run's start), None where it has none.
pub struct Observed {
    pub time: Vec<f64>,
    pub positions: Vec<Option<Vec<f64>>>,
}

impl Observed {
    /// Each coordinate's position at `t`, linear between samples (held past the ends; NaN where
    /// it has none).
    fn at(&self, t: f64, out: &mut [f64]) {
        let k = self.time.partition_point(|&s| s <= t);
        for (o, series) in out.iter_mut().zip(&self.positions) {
            *o = match series {
                None => f64::NAN,
                Some(p) if k == 0 => p[0],
                Some(p) if k >= self.time.len() => p[self.time.len() - 1],
                Some(p) => {
                    let (t0, t1) = (self.time[k - 1], self.time[k]);
                    p[k - 1] + (p[k] - p[k - 1]) * (t - t0) / (t1 - t0)
                }
            };
        }
    }
}

/// [`simulate`], recording `observed` (a real arm's positions) beside the simulated arm's.
pub fn simulate_beside(experiment: &Experiment, recorders: &mut [&mut dyn Recorder], stop: Option<&AtomicBool>, observed: Option<&Observed>) -> Result<Summary, Error> {
    simulate_loop(experiment, recorders, stop, observed, None, Keep::Everything)
}

/// A run for its joint positions alone (identification's candidates, run hundreds of times): the
/// same motion as [`simulate`]'s, with the energy audit's divergence check, but no statistics, no
/// tool poses and no figures of the drives and joints beside their torques (the samples'
/// `tool_position` and `tool_target` are zero; their saturation, torque limits, chatter, duty,
/// current, supply, limit and friction flags and winding temperatures stay at their start). Its
/// status: completed, interrupted or diverged.
pub fn simulate_positions(experiment: &Experiment, recorders: &mut [&mut dyn Recorder], stop: Option<&AtomicBool>) -> Result<RunStatus, Error> {
    Ok(simulate_loop(experiment, recorders, stop, None, None, Keep::Positions)?.status)
}

/// What a run keeps beside its motion.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Keep {
    /// The summary's statistics and the tool's poses.
    Everything,
    /// The joint positions alone.
    Positions,
}

/// [`simulate`] with `law` asking the joints' torques in place of the PD controller (through the
/// same motor limits, plant and recorders). A law's error stops the run at that step: the
/// recorders are finished with what was run, then the error is returned.
pub fn simulate_with_law(experiment: &Experiment, recorders: &mut [&mut dyn Recorder], stop: Option<&AtomicBool>, law: &mut dyn crate::control::law::TorqueLaw) -> Result<Summary, Error> {
    simulate_loop(experiment, recorders, stop, None, Some(law), Keep::Everything)
}

fn simulate_loop(experiment: &Experiment, recorders: &mut [&mut dyn Recorder], stop: Option<&AtomicBool>, observed: Option<&Observed>, mut law: Option<&mut dyn crate::control::law::TorqueLaw>, keep: Keep) -> Result<Summary, Error> {
    let everything = keep == Keep::Everything;
    let model = &*experiment.model;
    let n = model.dof();
    let dt = experiment.dt();
    let mut data = Data::new(model);
    // where the command puts the arm (poses only), for the tool's target
    let mut command_poses = vec![crate::spatial::Pose::identity(); model.bodies.len()];
    let mut plant = experiment.make_plant();
    let controller = experiment.controller();
    let info = RunInfo {
        measured_effort: Vec::new(),
        observed_position: observed.map_or_else(Vec::new, |o| o.positions.iter().map(Option::is_some).collect()),
        experiment,
        plant: plant.describe(),
        trajectory: experiment.trajectory.describe(),
        commanded_tool_path: if recorders.is_empty() || !everything { Vec::new() } else { experiment.commanded_tool_path(0.01) },
        torque_axes: crate::recorder::shared::torque_axis::LazyAxes::of(experiment),
    };
    for r in recorders.iter_mut() {
        r.start(&info)?;
    }

    let (mut q, mut v) = experiment.initial_state();
    let mut observed_now = vec![f64::NAN; if observed.is_some() { n } else { 0 }];
    let (mut cmd, mut cmd_dot, mut u) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut saturated = vec![false; n];
    let mut torque_limit = vec![0.0; n];
    // stepper mode: the open-loop steppers, their load angles and lost steps
    let mut steppers = experiment.open_loop_steppers();
    let (mut load_angle, mut lost_steps, mut lost_events) = (vec![0.0; n], vec![0i64; n], Vec::new());
    // firmware mode: the servos driven by their own position loops, their duty, current and supply
    let mut servos = experiment.firmware_drives();
    let plant_step = experiment.plant.time_step().unwrap_or(dt);
    let (mut duty, mut current, mut supply) = if servos.is_some() { (vec![0.0; n], vec![0.0; n], vec![0.0; n]) } else { (Vec::new(), Vec::new(), Vec::new()) };
    let (mut chatter, mut previous_u, mut previous_saturated) = (vec![false; n], vec![0.0; n], vec![false; n]);
    let mut at_limit = vec![false; n];
    // friction torque and stuck flags: recorded only when some joint has friction (its URDF's or
    // its gearbox's)
    let has_friction = experiment.joint_has_friction().contains(&true);
    let (mut friction, mut stuck) = if has_friction { (vec![0.0; n], vec![false; n]) } else { (Vec::new(), Vec::new()) };
    let joint_names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let mut stats = SummaryBuilder::new(joint_names, controller.limits_at_rest(), dt, experiment.config.settle_time)
        .with_stepped_joints(experiment.stepped_joints())
        .with_friction(has_friction)
        .with_servos(experiment.servo_duty_limits());
    let started = Instant::now();
    let mut status = RunStatus::Completed;
    // a law's asked torques, and the error that stopped it
    let mut asked = vec![0.0; n];
    let mut law_error: Option<Error> = None;
    let mut audit = EnergyAudit::new(experiment);
    // the motors' windings, where their thermal data is known
    let mut heat = crate::actuator::thermal::RunHeat::new(&experiment.motor_heat(), dt);
    let no_temperatures: Vec<f64> = Vec::new();
    // the collision checks, every control step (flags only: the motion is not changed)
    let mut collision_check = experiment.collisions.as_ref().map(|c| (crate::collision::CollisionData::for_run(&c.shapes), crate::collision::StateCollisions::default(), crate::collision::RunLog::new(c)));

    for k in 0..=experiment.steps {
        let t = k as f64 * dt;
        forward_kinematics(model, &mut data, &q);
        gravity_and_bias_from_kinematics(model, &mut data, &v);
        experiment.trajectory.sample(t, &mut cmd, &mut cmd_dot);
        match law.as_deref_mut() {
            Some(law) => {
                let input = crate::control::law::LawInput { t, q: &q, v: &v, cmd: &cmd, cmd_dot: &cmd_dot, tau_g: &data.gravity };
                if let Err(e) = law.torque(&input, &mut asked) {
                    law_error = Some(e);
                }
                controller.apply(&asked, &q, &v, ControlOutput { u: &mut u, saturated: &mut saturated, limit: &mut torque_limit });
            }
            None => controller.compute(&q, &v, &cmd, &cmd_dot, &data.gravity, ControlOutput { u: &mut u, saturated: &mut saturated, limit: &mut torque_limit }),
        }
        if let Some(s) = steppers.as_mut() {
            // no PD on a stepper joint: the driver steps to the command, the rotor follows as it can
            s.control_step(&cmd, &cmd_dot, dt, &q, &v, StepperOutput { u: &mut u, limit: &mut torque_limit, saturated: &mut saturated, load_angle: &mut load_angle, lost_steps: &mut lost_steps });
        }
        if let Some(s) = servos.as_mut() {
            // no PD on a servo joint: its firmware's position loop sets the duty toward the command
            s.command(&cmd, &q, &v, plant_step, &mut u);
            if everything {
                s.outputs(&mut duty, &mut current, &mut supply);
                for j in (0..n).filter(|&j| s.driven[j]) {
                    saturated[j] = s.saturated(j);
                    torque_limit[j] = s.limit(j, u[j], v[j]);
                }
            }
        }
        if everything {
            for i in 0..n {
                // (a slipping stepper's torque swings sign with its lag: that is the motor, not the loop)
                let stepped = steppers.as_ref().is_some_and(|s| s.stepped[i]);
                chatter[i] = !stepped && k > 0 && u[i] * previous_u[i] < 0.0 && (saturated[i] || previous_saturated[i]);
                previous_u[i] = u[i];
                previous_saturated[i] = saturated[i];
            }
        }
        if everything {
            body_poses(model, &cmd, &mut command_poses);
        }
        let mut collided = None;
        if let (Some(c), Some((cd, state, log))) = (experiment.collisions.as_ref(), collision_check.as_mut()) {
            crate::collision::check_state(model, &c.shapes, &c.pairs, &c.world, cd, &data.body_pose, COLLISION_BAND, state);
            log.record(model, c, t, state);
            if experiment.config.stop_on_collision {
                collided = state.colliding().next().map(|p| RunStatus::Collided { time: t, link1: model.frames[p.a].name.clone(), link2: c.name(model, p.b).to_string() });
            }
        }
        let interrupted = stop.is_some_and(|s| s.load(Ordering::Relaxed)) || law_error.is_some();
        let sample = Sample {
            k,
            t,
            is_final: k == experiment.steps || interrupted || collided.is_some(),
            q: &q,
            v: &v,
            cmd: &cmd,
            cmd_dot: &cmd_dot,
            u: &u,
            tau_g: &data.gravity,
            saturated: &saturated,
            torque_limit: &torque_limit,
            load_angle: &load_angle,
            lost_steps: &lost_steps,
            chatter: &chatter,
            at_limit: &at_limit,
            friction: &friction,
            stuck: &stuck,
            winding_temperature: if heat.any() { &heat.winding_temperature } else { &no_temperatures },
            duty: &duty,
            current: &current,
            measured_effort: &[],
            observed_position: match observed {
                Some(o) => {
                    o.at(t, &mut observed_now);
                    &observed_now
                }
                None => &[],
            },
            supply: &supply,
            collisions: collision_check.as_ref().map_or(&[], |(_, state, _)| state.close.as_slice()),
            tool_position: if everything { frame_pose(model, &data, model.tool_frame).translation } else { Default::default() },
            tool_target: if everything { frame_pose_in(model, &command_poses, model.tool_frame).translation } else { Default::default() },
            body_pose: &data.body_pose,
        };
        if everything {
            stats.record(&sample);
        }
        for r in recorders.iter_mut() {
            r.record(&sample)?;
        }
        if sample.is_final {
            if interrupted {
                status = RunStatus::Interrupted { time: t };
            } else if let Some(c) = collided {
                status = c;
            }
            break;
        }
        if everything && heat.any() {
            // the motors carry this step's torque (a stepper's as it stood at the control step)
            heat.step(&u);
        }
        if let Some(a) = audit.as_mut() {
            // the loop's passes left the kinematics and body velocities and momenta at (q_k, q̇_k) in data
            if let Some(diverged) = a.period_start(model, &data, &v, t) {
                status = diverged;
                break;
            }
        }
        if steppers.is_none() && servos.is_none() && audit.is_none() {
            plant.advance(model, &mut data, &u, &mut q, &mut v);
        } else {
            // the stepper torque follows the rotor within the control period, a servo's follows
            // its back-EMF, and the audit books the work of every plant step: all see each plant
            // step's start
            let mut drive = |h: f64, q: &[f64], v: &[f64], u: &mut [f64]| {
                if let Some(s) = steppers.as_mut() {
                    s.plant_step(h, q, v, u);
                }
                if let Some(s) = servos.as_mut() {
                    s.plant_step(h, q, v, u);
                }
                if let Some(a) = audit.as_mut() {
                    a.plant_step(model, h, v, u);
                }
            };
            plant.advance_driven(model, &mut data, &mut u, &mut drive, &mut q, &mut v);
            if let Some(a) = audit.as_mut() {
                a.period_end(model, &v, plant.friction_work());
            }
        }
        if let Some(s) = steppers.as_mut() {
            s.update(&q, t + dt, &mut lost_events);
            for e in lost_events.drain(..) {
                stats.lost_steps(e);
            }
        }
        // (the limits' and the friction's flags, for the samples: they do not move the arm)
        if everything {
            at_limit.copy_from_slice(plant.limit_active());
            if has_friction {
                friction.copy_from_slice(plant.friction_torque());
                stuck.copy_from_slice(plant.stuck());
            }
        }
        if let Some(diverged) = divergence(experiment, &q, &v, t + dt) {
            status = diverged;
            break;
        }
    }
    let mut summary = stats.finish(status, started.elapsed().as_secs_f64());
    if heat.any() {
        summary.winding = heat.summary();
    }
    summary.collisions = collision_check.map(|(_, _, log)| log.finish());
    if let Some(s) = servos.as_ref() {
        for (servo, trip) in summary.servos.iter_mut().zip(s.trips(n)) {
            if let Some(servo) = servo {
                servo.protection_trip = trip;
            }
        }
    }
    if let Some(motors) = &experiment.motors {
        summary.drive_duty = motors
            .joints
            .iter()
            .enumerate()
            .map(|(j, d)| {
                d.as_ref().map(|d| crate::summary::DriveDuty {
                    rms_motor_torque: summary.rms_torque[j] / d.gear_ratio,
                    continuous_torque: d.continuous_torque,
                    cubic_mean_torque: summary.cubic_mean_torque[j],
                    rated_average_torque: d.rated_average_torque,
                })
            })
            .collect();
    }
    summary.energy_balance = audit.map(|a| EnergyBalance { created: a.created, work: a.work });
    for r in recorders.iter_mut() {
        r.finish(&info, &summary)?;
    }
    match law_error {
        Some(e) => Err(e),
        None => Ok(summary),
    }
}

/// How close a pair must come to be measured exactly and reported (the near misses), m.
const COLLISION_BAND: f64 = 0.05;

/// Numerical energy audit of the discrete plant. Between control steps the arm's mechanical energy
/// E = ½ q̇ᵀM(q)q̇ + potential may change only by the work of the torques, the damping and the
/// friction over its plant steps (a stepper's torque changes at each). A numerically unstable plant creates energy that
/// nothing supplied; more than 1 J, and more than 1 % of all the work done on the arm so far, is
/// divergence. (On the box model's chattering default run the books balance to 5 mJ over 5 s; on the
/// mesh model's discrete run 540 J appear.)
struct EnergyAudit {
    /// The last plant step's start: its length, q̇ and torque (booked once the next state is known).
    step: Option<f64>,
    v_before: Vec<f64>,
    u_before: Vec<f64>,
    previous_energy: Option<f64>,
    /// Work over the control period under way, and the absolute work so far.
    period_work: f64,
    work: f64,
    created: f64,
}

impl EnergyAudit {
    /// Only for the discrete plant; the continuous plant controls its own error.
    fn new(experiment: &Experiment) -> Option<Self> {
        let n = experiment.model.dof();
        matches!(experiment.plant, crate::experiment::PlantSpec::Discrete { .. }).then(|| Self {
            step: None,
            v_before: vec![0.0; n],
            u_before: vec![0.0; n],
            previous_energy: None,
            period_work: 0.0,
            work: 0.0,
            created: 0.0,
        })
    }

    /// At control step k: books E_k against E_{k−1} and the work in between.
    fn period_start(&mut self, model: &Model, data: &Data, v: &[f64], time: f64) -> Option<RunStatus> {
        let energy = kinetic_energy_from_momenta(model, data, v) + potential_energy_from_kinematics(model, data);
        if let Some(previous) = self.previous_energy {
            self.created += energy - previous - self.period_work;
        }
        self.previous_energy = Some(energy);
        self.period_work = 0.0;
        if self.created > 1.0 && self.created > 0.01 * self.work {
            let fastest = (0..v.len()).max_by(|&a, &b| v[a].abs().total_cmp(&v[b].abs())).unwrap_or(0);
            let joint = model.joints[fastest].name.clone();
            let message = format!(
                "simulation diverged at t = {time:.3} s: the discrete plant created {:.1} J of energy that no torque supplied \
                 (joint {joint} at q̇ = {:.3e}); the plant is numerically unstable for this model, gains and step: \
                 try the continuous plant with --time-step 0",
                self.created, v[fastest]
            );
            return Some(RunStatus::Diverged { joint, time, message });
        }
        None
    }

    /// At the start of a plant step of length h from q̇ with torque u: books the previous plant step.
    fn plant_step(&mut self, model: &Model, h: f64, v: &[f64], u: &[f64]) {
        self.book(model, v);
        self.step = Some(h);
        self.v_before.copy_from_slice(v);
        self.u_before.copy_from_slice(u);
    }

    /// After the control period's last plant step, at q̇_{k+1}; the friction's work over the period
    /// (≤ 0) from the plant.
    fn period_end(&mut self, model: &Model, v: &[f64], friction_work: f64) {
        self.book(model, v);
        self.period_work += friction_work;
        self.work += friction_work.abs();
    }

    /// The work of the held torque and the damping over the last plant step, at its mean speed.
    fn book(&mut self, model: &Model, v_after: &[f64]) {
        let Some(h) = self.step.take() else { return };
        let mut work = 0.0;
        for i in 0..v_after.len() {
            let mean = 0.5 * (self.v_before[i] + v_after[i]);
            work += h * (self.u_before[i] - model.joints[i].damping * mean) * mean;
        }
        self.period_work += work;
        self.work += work.abs();
    }
}

/// Divergence: a state that is not finite, a joint that swept (nearly) its whole range within one
/// control period (a limited joint banging from limit to limit: the plant's numbers, not physics),
/// or a joint faster than `--divergence-speed`.
fn divergence(experiment: &Experiment, q: &[f64], v: &[f64], time: f64) -> Option<RunStatus> {
    let limit = experiment.config.divergence_speed;
    let dt = experiment.config.dt;
    let joints = &experiment.model.joints;
    let sweeps = |i: usize| {
        let range = joints[i].upper - joints[i].lower;
        // a joint that does not move sweeps nothing, whatever its range (a zero-width one included)
        range.is_finite() && v[i] != 0.0 && v[i].abs() * dt >= 0.9 * range
    };
    let bad = (0..q.len()).find(|&i| !q[i].is_finite() || !v[i].is_finite() || v[i].abs() > limit || sweeps(i))?;
    let joint = joints[bad].name.clone();
    let what = if !q[bad].is_finite() || !v[bad].is_finite() {
        "is no longer finite".to_string()
    } else if sweeps(bad) {
        format!("swept its whole range in one {} ms control period", dt * 1e3)
    } else {
        format!("exceeded {limit:.0e} rad/s")
    };
    let message = format!(
        "simulation diverged at t = {time:.3} s: joint {joint} {what} (q = {:.3e}, q̇ = {:.3e}); \
         the plant is numerically unstable for this model, gains and step: try the continuous plant with --time-step 0",
        q[bad], v[bad]
    );
    Some(RunStatus::Diverged { joint, time, message })
}
