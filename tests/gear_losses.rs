//! Gearbox losses as friction by the direction power flows (Modelica's LossyGear,
//! `actuator::LossyGear`): the holding band a back-driving load leaves the motor, a self-locking
//! drive that holds the arm with its motor off, and the energy books with the losses.

mod common;

use armscope::actuator::LossyGear;
use armscope::config::{DriveMode, RunConfig};
use armscope::dynamics::{Data, forward_kinematics, gravity_and_bias_from_kinematics};
use armscope::experiment::Experiment;
use armscope::model::{Model, load_urdf_str};
use armscope::plant::{ContinuousPlant, DiscretePlant, Plant, Tolerances};
use armscope::recorder::{Recorder, RunInfo};
use armscope::sample::Sample;
use armscope::sim::simulate;
use armscope::summary::Summary;
use std::path::Path;

/// A 1 kg mass 0.5 m from a horizontal axis, no joint friction, no damping.
fn pendulum() -> Model {
    let urdf = r#"<robot name="pendulum">
  <link name="world"/>
  <link name="bob"><inertial><origin xyz="0 0 -0.5"/><mass value="1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="swing" type="continuous"><parent link="world"/><child link="bob"/><axis xyz="0 1 0"/></joint>
</robot>"#;
    load_urdf_str(urdf, Path::new("pendulum.urdf")).unwrap()
}

/// Hold the motor's torque `u` for `seconds` from rest at `angle`; the final angle.
fn hold(model: &Model, plant: &mut dyn Plant, angle: f64, u: f64, seconds: f64) -> f64 {
    let mut data = Data::new(model);
    let (mut q, mut v) = (vec![angle], vec![0.0]);
    for _ in 0..(seconds / 1e-3).round() as usize {
        forward_kinematics(model, &mut data, &q);
        gravity_and_bias_from_kinematics(model, &mut data, &v);
        plant.advance(model, &mut data, &[u], &mut q, &mut v);
    }
    q[0]
}

/// The motor holds a load G that would back-drive it with any torque from η_b·G (the gear's
/// friction helps) to G/η (beyond, it drives the load up): at rest the joint is stuck exactly —
/// position bit for bit — anywhere in that band, in both plants; 0.1 % outside it, it moves, down
/// below the band and up above it.
#[test]
fn a_load_is_held_from_eta_b_to_one_over_eta_of_its_torque() {
    let model = pendulum();
    let gear = LossyGear { efficiency: 0.8, backdrive_efficiency: 0.5, breakaway_torque: 0.0, viscous: 0.0 };
    let angle: f64 = 0.6;
    // the weight's torque at the angle, pulling back towards 0
    let weight = 1.0 * model.gravity.norm() * 0.5 * angle.sin();
    let plants = || -> Vec<Box<dyn Plant>> {
        vec![Box::new(DiscretePlant::with_gears(&model, 1e-3, 1, &[Some(gear)])), Box::new(ContinuousPlant::with_gears(&model, 1e-3, Tolerances { rtol: 1e-10, atol: 1e-12 }, &[Some(gear)]))]
    };
    for mut plant in plants() {
        for share in [0.5 * 1.001, 0.8, 1.0, 1.2, 1.0 / 0.8 * 0.999] {
            let end = hold(&model, plant.as_mut(), angle, share * weight, 1.0);
            assert_eq!(end, angle, "{}: u = {share}·G holds", plant.describe());
            assert!(plant.stuck()[0]);
        }
    }
    for mut plant in plants() {
        assert!(hold(&model, plant.as_mut(), angle, 0.5 * 0.999 * weight, 0.3) < angle - 1e-4, "below η_b·G the load back-drives the motor");
    }
    for mut plant in plants() {
        assert!(hold(&model, plant.as_mut(), angle, 1.001 / 0.8 * weight, 0.3) > angle + 1e-4, "above G/η the motor lifts the load");
    }
}

/// The last sample's positions and stuck flags, and the first's positions.
#[derive(Default)]
struct Ends {
    first: Vec<f64>,
    last: Vec<f64>,
    stuck: Vec<bool>,
}

impl Recorder for Ends {
    fn start(&mut self, _: &RunInfo) -> Result<(), armscope::error::Error> {
        Ok(())
    }
    fn record(&mut self, s: &Sample) -> Result<(), armscope::error::Error> {
        if self.first.is_empty() {
            self.first = s.q.to_vec();
        }
        self.last = s.q.to_vec();
        self.stuck = s.stuck.to_vec();
        Ok(())
    }
    fn finish(&mut self, _: &RunInfo, _: &Summary) -> Result<(), armscope::error::Error> {
        Ok(())
    }
}

/// A motor file of the user's own: a small DC motor on every joint of the box model through a 30:1
/// gear described by `reduction` (motor-file fields).
fn motor_file(dir: &Path, name: &str, reduction: &str) -> std::path::PathBuf {
    let joints: String = (1..=6).map(|j| format!("[joints.J{j}]\nmotor = \"M\"\ngear_ratio = 30\n{reduction}\n")).collect();
    let file = dir.join(name);
    std::fs::write(&file, format!("[motors.M]\nkind = \"servo\"\nstall_torque = 0.5\nno_load_speed = 300\nrotor_inertia = 1e-7\n{joints}")).unwrap();
    file
}

/// The box model on `motors` with the motor off (zero gains, no feed-forward), from a pose.
fn motor_off(motors: std::path::PathBuf, duration: f64, time_step: Option<f64>) -> RunConfig {
    RunConfig {
        urdf: common::box_urdf(),
        motors: Some(motors),
        drive: DriveMode::Pd,
        hold: true,
        no_ff: true,
        kp: Some(vec![0.0; 6]),
        kd: Some(vec![0.0; 6]),
        q0: Some("0.2,0.5,-0.6,0.3,0.4,0".into()),
        duration,
        time_step,
        ..RunConfig::default()
    }
}

/// The motor-off run through gears of efficiency η and η_b: its first and last samples.
fn motor_off_run(dir: &Path, efficiency: f64, backdrive: f64, time_step: Option<f64>) -> Ends {
    let file = motor_file(dir, &format!("gear_{efficiency}_{backdrive}.toml"), &format!("efficiency = {efficiency}\nbackdrive_efficiency = {backdrive}"));
    let experiment = Experiment::prepare(motor_off(file, 2.0, time_step)).unwrap();
    let mut ends = Ends::default();
    simulate(&experiment, &mut [&mut ends], None).unwrap();
    ends
}

/// A self-locking drive (a worm, η_b < 0) cannot be back-driven: with its motor off it holds the
/// arm where it is, every joint stuck and not a bit of drift, in both plants; the same arm on an
/// efficient gear (η = η_b = 0.9) falls (J2, at 0.5 rad, carries most of the arm's weight).
#[test]
fn a_self_locking_drive_holds_the_arm_with_its_motor_off_and_an_efficient_one_lets_it_fall() {
    let dir = tempfile::tempdir().unwrap();
    for time_step in [None, Some(0.0)] {
        let worm = motor_off_run(dir.path(), 0.4, -0.3, time_step);
        assert_eq!(worm.last, worm.first, "time step {time_step:?}: the worm holds");
        assert!(worm.stuck.iter().all(|&s| s), "every joint stuck: {:?}", worm.stuck);
        let efficient = motor_off_run(dir.path(), 0.9, 0.9, time_step);
        assert!((efficient.last[1] - efficient.first[1]).abs() > 0.1, "time step {time_step:?}: the efficient drive lets J2 fall: {:?} → {:?}", efficient.first, efficient.last);
    }
}

/// The energy audit books the gear's losses (its Coulomb and viscous friction) with the URDF's
/// damping: the arm falling through efficient gears with breakaway and viscous friction, motor off,
/// balances to 1 % of the work (the bar of the friction runs).
#[test]
fn the_energy_audit_books_the_gear_losses_and_balances() {
    let dir = tempfile::tempdir().unwrap();
    let file = motor_file(dir.path(), "lossy.toml", "efficiency = 0.9\nbreakaway_torque = 0.2\nviscous = 0.05");
    let config = motor_off(file, 3.0, None);
    let experiment = Experiment::prepare(config).unwrap();
    let summary = simulate(&experiment, &mut [], None).unwrap();
    let books = summary.energy_balance.unwrap();
    assert!(books.work > 0.1 && books.created.abs() < 0.01 * books.work, "{books:?}");
    assert!(summary.peak_friction_torque[1] >= 0.2 - 1e-12, "the breakaway holds J2 back: {:?}", summary.peak_friction_torque);
}
