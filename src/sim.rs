//! The simulation loop: controller and plant at the control rate, every sample to every recorder.

use crate::dynamics::{Data, body_poses, forward_kinematics, frame_pose, frame_pose_in, gravity_and_bias_from_kinematics};
use crate::error::Error;
use crate::experiment::Experiment;
use crate::control::controller::ControlOutput;
use crate::recorder::{Recorder, RunInfo};
use crate::sample::Sample;
use crate::summary::{RunStatus, Summary, SummaryBuilder};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Run one experiment, feeding each recorder every sample. Returns the summary also when the run
/// was interrupted (`stop` set) or diverged (see [`Summary::status`]); recorders are finished in
/// every case, so their files are whole up to the last recorded sample.
pub fn simulate(experiment: &Experiment, recorders: &mut [&mut dyn Recorder], stop: Option<&AtomicBool>) -> Result<Summary, Error> {
    let model = &*experiment.model;
    let n = model.dof();
    let dt = experiment.dt();
    let mut data = Data::new(model);
    // where the command puts the arm (poses only), for the tool's target
    let mut command_poses = vec![crate::spatial::Pose::identity(); model.bodies.len()];
    let mut plant = experiment.make_plant();
    let controller = experiment.controller();
    let info = RunInfo {
        experiment,
        plant: plant.describe(),
        trajectory: experiment.trajectory.describe(),
        commanded_tool_path: if recorders.is_empty() { Vec::new() } else { experiment.commanded_tool_path(0.01) },
    };
    for r in recorders.iter_mut() {
        r.start(&info)?;
    }

    let (mut q, mut v) = experiment.initial_state();
    let (mut cmd, mut cmd_dot, mut u) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut saturated = vec![false; n];
    let mut torque_limit = vec![0.0; n];
    // stepper mode: the open-loop steppers, their load angles and lost steps
    let mut steppers = experiment.open_loop_steppers();
    let (mut load_angle, mut lost_steps, mut lost_events) = (vec![0.0; n], vec![0i64; n], Vec::new());
    let (mut chatter, mut previous_u, mut previous_saturated) = (vec![false; n], vec![0.0; n], vec![false; n]);
    let mut at_limit = vec![false; n];
    let joint_names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let mut stats = SummaryBuilder::new(joint_names, controller.effort.clone(), dt, experiment.config.settle_time).with_stepped_joints(experiment.stepped_joints());
    let started = Instant::now();
    let mut status = RunStatus::Completed;
    let mut audit = EnergyAudit::new(experiment);

    for k in 0..=experiment.steps {
        let t = k as f64 * dt;
        forward_kinematics(model, &mut data, &q);
        gravity_and_bias_from_kinematics(model, &mut data, &v);
        experiment.trajectory.sample(t, &mut cmd, &mut cmd_dot);
        controller.compute(&q, &v, &cmd, &cmd_dot, &data.gravity, ControlOutput { u: &mut u, saturated: &mut saturated, limit: &mut torque_limit });
        if let Some(s) = steppers.as_mut() {
            // no PD on a stepper joint: the driver steps to the command, the rotor follows as it can
            s.set_command(&cmd, &cmd_dot, dt);
            s.torques(&q, &v, &mut u);
            s.load_angles(&q, &mut load_angle);
            s.lost_steps(&mut lost_steps);
            for j in (0..n).filter(|&j| s.stepped[j]) {
                // past the peak of the torque–angle curve: the motor is giving all it can
                saturated[j] = load_angle[j].abs() > 90.0;
            }
        }
        for i in 0..n {
            // (a slipping stepper's torque swings sign with its lag: that is the motor, not the loop)
            let stepped = steppers.as_ref().is_some_and(|s| s.stepped[i]);
            chatter[i] = !stepped && k > 0 && u[i] * previous_u[i] < 0.0 && (saturated[i] || previous_saturated[i]);
            previous_u[i] = u[i];
            previous_saturated[i] = saturated[i];
        }
        body_poses(model, &cmd, &mut command_poses);
        let interrupted = stop.is_some_and(|s| s.load(Ordering::Relaxed));
        let sample = Sample {
            k,
            t,
            is_final: k == experiment.steps || interrupted,
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
            tool_position: frame_pose(model, &data, model.tool_frame).translation,
            tool_target: frame_pose_in(model, &command_poses, model.tool_frame).translation,
            body_pose: &data.body_pose,
        };
        stats.record(&sample);
        for r in recorders.iter_mut() {
            r.record(&sample)?;
        }
        if sample.is_final {
            if interrupted {
                status = RunStatus::Interrupted { time: t };
            }
            break;
        }
        let potential = audit.as_mut().map(|a| {
            a.remember(&v);
            a.potential_energy(model, &data)
        });
        match steppers.as_mut() {
            // the stepper torque follows the rotor within the control period: at every plant step
            Some(s) => plant.advance_driven(
                model,
                &mut data,
                &mut u,
                &mut |h, q, v, u| {
                    s.advance(h);
                    s.torques(q, v, u)
                },
                &mut q,
                &mut v,
            ),
            None => plant.advance(model, &mut data, &u, &mut q, &mut v),
        }
        if let Some(s) = steppers.as_mut() {
            s.update(&q, t + dt, &mut lost_events);
            for e in lost_events.drain(..) {
                stats.lost_steps(e);
            }
        }
        at_limit.copy_from_slice(plant.limit_active());
        if let Some(diverged) = divergence(experiment, &q, &v, t + dt) {
            status = diverged;
            break;
        }
        if let (Some(a), Some(pe)) = (audit.as_mut(), potential) {
            // the discrete step left M(q_k) in data.mass_matrix
            if let Some(diverged) = a.step(model, &data, pe, &u, &v, t + dt) {
                status = diverged;
                break;
            }
        }
    }
    let summary = stats.finish(status, started.elapsed().as_secs_f64());
    for r in recorders.iter_mut() {
        r.finish(&info, &summary)?;
    }
    Ok(summary)
}

/// Numerical energy audit of the discrete plant. Over a step the arm's mechanical energy
/// E = ½ q̇ᵀM(q)q̇ + potential may change only by the work of the held torque and the damping. A
/// numerically unstable plant creates energy that nothing supplied; more than 1 J, and more than
/// 1 % of all the work done on the arm so far, is divergence. (On the box model's chattering default
/// run the books balance to 5 mJ over 5 s; on the mesh model's discrete run 540 J appear.)
struct EnergyAudit {
    dt: f64,
    gravity: nalgebra::Vector3<f64>,
    v_before: Vec<f64>,
    previous_energy: Option<f64>,
    previous_work: f64,
    created: f64,
    work: f64,
}

impl EnergyAudit {
    /// Only for the discrete plant with one step per control period (its step computes M(q_k)); the
    /// continuous plant controls its own error.
    fn new(experiment: &Experiment) -> Option<Self> {
        match experiment.plant {
            crate::experiment::PlantSpec::Discrete { substeps: 1, .. } => Some(Self {
                dt: experiment.dt(),
                gravity: experiment.model.gravity,
                v_before: vec![0.0; experiment.model.dof()],
                previous_energy: None,
                previous_work: 0.0,
                created: 0.0,
                work: 0.0,
            }),
            _ => None,
        }
    }

    fn potential_energy(&self, model: &crate::model::Model, data: &Data) -> f64 {
        model.bodies.iter().enumerate().map(|(i, j)| -j.inertia.mass * self.gravity.dot(&data.body_pose[i].transform_point(&j.inertia.com))).sum()
    }

    fn remember(&mut self, v: &[f64]) {
        self.v_before.copy_from_slice(v);
    }

    /// After the step from (q_k, v_k) to v_{k+1}: books the energy at step k and the work over it.
    fn step(&mut self, model: &crate::model::Model, data: &Data, potential: f64, u: &[f64], v_after: &[f64], time: f64) -> Option<RunStatus> {
        let m = &data.mass_matrix;
        let n = model.dof();
        let mut kinetic = 0.0;
        for i in 0..n {
            let mut row = 0.0;
            for j in 0..n {
                row += m[(i, j)] * self.v_before[j];
            }
            kinetic += 0.5 * self.v_before[i] * row;
        }
        let energy = kinetic + potential;
        if let Some(previous) = self.previous_energy {
            self.created += energy - previous - self.previous_work;
        }
        self.previous_energy = Some(energy);
        let mut work = 0.0;
        for i in 0..n {
            let mean = 0.5 * (self.v_before[i] + v_after[i]);
            work += self.dt * (u[i] - model.joints[i].damping * mean) * mean;
        }
        self.previous_work = work;
        self.work += work.abs();
        if self.created > 1.0 && self.created > 0.01 * self.work {
            let fastest = (0..n).max_by(|&a, &b| v_after[a].abs().total_cmp(&v_after[b].abs())).unwrap_or(0);
            let joint = model.joints[fastest].name.clone();
            let message = format!(
                "simulation diverged at t = {time:.3} s: the discrete plant created {:.1} J of energy that no torque supplied \
                 (joint {joint} at q̇ = {:.3e}); the plant is numerically unstable for this model, gains and step: \
                 try the continuous plant with --time-step 0",
                self.created, v_after[fastest]
            );
            return Some(RunStatus::Diverged { joint, time, message });
        }
        None
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
