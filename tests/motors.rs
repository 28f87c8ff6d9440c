//! Motors and drive trains (`--motors FILE.toml`): the catalogue, the torque a joint gets at a speed
//! through its gearbox, servo mode (the tutorial's PD loop on that limit), the rotor in M, and what
//! the console, the summary and both recordings show of it.

mod common;

use armscope::actuator::{Catalogue, DcServo, DriveTrain, LossyGear, Motor, PullOut, Stepper, load_motor_file};
use armscope::config::RunConfig;
use armscope::dynamics::{Data, crba};
use armscope::experiment::Experiment;
use armscope::model::load_urdf;
use armscope::recorder::{Recorder, RunInfo};
use armscope::sample::Sample;
use armscope::sim::simulate;
use armscope::summary::Summary;

fn motors_file(name: &str) -> std::path::PathBuf {
    common::repo().join("assets/motors").join(name)
}

#[test]
fn every_catalogue_entry_loads_with_its_numbers() {
    let catalogue = Catalogue::load(&motors_file("catalogue.toml")).unwrap();
    for name in ["17HS4401", "23HS22-2804S", "STS3215-C018"] {
        let drive = catalogue.drive_train(name).expect("in the catalogue").unwrap_or_else(|e| panic!("{e}"));
        assert!(drive.motor.torque_at(0.0) > 0.0, "{name}");
    }
    let nema17 = catalogue.drive_train("17HS4401").unwrap().unwrap();
    assert_eq!((nema17.motor.torque_at(0.0), nema17.motor.rotor_inertia(), nema17.gear_ratio, nema17.efficiency(), nema17.rated_torque), (0.40, 5.4e-6, 1.0, 1.0, f64::INFINITY));
    // a gearmotor's own gearbox (gearbox_* fields) in a user's catalogue
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("geared.toml");
    std::fs::write(&path, "[geared]\nkind = \"servo\"\nstall_torque = 0.4\nno_load_speed = 100\ngearbox_ratio = 5\ngearbox_efficiency = 0.9\ngearbox_rated_torque = 9\n").unwrap();
    let geared = Catalogue::load(&path).unwrap().drive_train("geared").unwrap().unwrap();
    assert_eq!((geared.gear_ratio, geared.efficiency(), geared.rated_torque), (5.0, 0.9, 9.0), "the gearmotor's own 5:1 planetary");
}

/// The stepper's derived pull-out curve: holding torque up to the corner speed V/(2·L·I·200) rev/s
/// (12.6 rev/s for the 17HS4401 at 24 V), then falling as 1/speed; a table is interpolated; a servo's
/// line falls from stall to zero at its no-load speed.
#[test]
fn torque_speed_curves_follow_their_stated_formulas() {
    let stepper = Stepper { name: "s".into(), holding_torque: 0.4, rotor_inertia: 5.4e-6, step_angle_deg: 1.8, pull_out: PullOut::Derived { inductance: 2.8e-3, current: 1.7, supply_voltage: 24.0 }, damping: 0.0, detent_torque: 0.0 };
    let corner = 24.0 / (2.0 * 2.8e-3 * 1.7 * 200.0);
    assert!((stepper.corner_speed_rev_s().unwrap() - corner).abs() < 1e-12 && (corner - 12.605).abs() < 1e-3);
    let omega = |rev_s: f64| rev_s * 2.0 * std::f64::consts::PI;
    assert_eq!(stepper.torque_at(omega(0.99 * corner)), 0.4);
    assert!((stepper.torque_at(-omega(2.0 * corner)) - 0.2).abs() < 1e-12, "half the torque at twice the corner speed, either direction");
    let table = Stepper { pull_out: PullOut::Table(vec![(0.0, 0.4), (10.0, 0.2), (20.0, 0.05)]), ..stepper.clone() };
    assert!((table.torque_at(omega(5.0)) - 0.3).abs() < 1e-12 && (table.torque_at(omega(15.0)) - 0.125).abs() < 1e-12 && table.torque_at(omega(50.0)) == 0.05);
    let servo = DcServo { name: "v".into(), stall_torque: 2.94, no_load_speed: 4.71, rotor_inertia: 0.0 };
    assert_eq!((servo.torque_at(0.0), servo.torque_at(4.71), servo.torque_at(-10.0)), (2.94, 0.0, 0.0));
    assert!((servo.torque_at(2.355) - 1.47).abs() < 1e-12);
}

/// Through a gearbox: η·N·T_motor(N·ω), capped by the gearbox's rating; the rotor seen at the joint is J_r·N².
#[test]
fn a_drive_train_multiplies_torque_divides_speed_and_is_capped_by_its_rating() {
    let servo = DcServo { name: "v".into(), stall_torque: 1.0, no_load_speed: 100.0, rotor_inertia: 2e-6 };
    let drive = DriveTrain::new(Box::new(servo), 10.0, 0.8, 7.0);
    assert_eq!(drive.torque_limit(0.0), 7.0, "0.8·10·1 = 8 N·m, rated 7");
    assert!((drive.torque_limit(5.0) - 4.0).abs() < 1e-12, "motor at 50 rad/s gives 0.5 N·m: 0.8·10·0.5");
    assert_eq!(drive.torque_limit(10.0), 0.0, "the motor's no-load speed reached at the joint's 10 rad/s");
    assert!((drive.reflected_inertia() - 2e-4).abs() < 1e-18);
    assert!((drive.speed_at_fraction(0.5) - 5.625).abs() < 1e-9, "3.5 N·m at 1 − 3.5/8 of 10 rad/s");
}

#[test]
fn bad_motor_files_get_one_line_naming_the_file_the_joint_and_the_field() {
    let model = load_urdf(&common::box_urdf()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("[joints.J9]\nmotor = \"17HS4401\"\n", vec!["joint 'J9'", "no moving joint"]),
        ("[joints.J1]\nmotor = \"NOPE\"\n", vec!["joint 'J1'", "no motor 'NOPE'", "17HS4401"]),
        ("[joints.J1]\nmotor = \"17HS4401\"\ngear_ratio = -3\n", vec!["joint 'J1'", "field 'gear_ratio'", "positive"]),
        ("[joints.J1]\nmotor = \"17HS4401\"\nefficiency = 1.5\n", vec!["joint 'J1'", "field 'efficiency'", "(0, 1]"]),
        ("[joints.J1]\nmotor = \"17HS4401\"\ngear_ration = 3\n", vec!["joint 'J1'", "unknown field 'gear_ration'"]),
        ("[joints.J1]\nmotor = \"17HS4401\"\nbackdrive_efficiency = 1.2\n", vec!["joint 'J1'", "field 'backdrive_efficiency'", "at most 1", "self-locking"]),
        ("[joints.J1]\nmotor = \"17HS4401\"\nbreakaway_torque = -0.1\n", vec!["joint 'J1'", "field 'breakaway_torque'", "negative"]),
        ("[motors.M]\nkind = \"servo\"\nstall_torque = 1\nno_load_speed = 9\ngearbox_viscous = \"a lot\"\n[joints.J1]\nmotor = \"M\"\n", vec!["motor 'M'", "field 'gearbox_viscous'", "number"]),
        ("[joints.J1]\ngear_ratio = 3\n", vec!["joint 'J1'", "field 'motor'", "missing"]),
        ("[motors.M]\nkind = \"stepper\"\nholding_torque = 0.4\nstep_angle = 1.8\n[joints.J1]\nmotor = \"M\"\n", vec!["motor 'M'", "field 'inductance'", "missing"]),
        ("[motors.M]\nkind = \"brushless\"\n[joints.J1]\nmotor = \"M\"\n", vec!["motor 'M'", "field 'kind'", "'brushless'"]),
        ("[joints.J1\n", vec!["m.toml"]),
    ];
    for (text, words) in cases {
        let path = dir.path().join("m.toml");
        std::fs::write(&path, text).unwrap();
        let err = load_motor_file(&path, &model).unwrap_err().to_string();
        assert!(!err.contains('\n'), "one line: {err}");
        assert!(err.starts_with("--motors: ") && err.contains("m.toml"), "{err}");
        for w in words {
            assert!(err.contains(w), "'{w}' missing from: {err}");
        }
    }
}

/// Captures every sample's torque, limit, speed and saturation flag.
#[derive(Default)]
struct Capture {
    rows: Vec<(Vec<f64>, Vec<f64>, Vec<f64>, Vec<bool>)>,
}

impl Recorder for Capture {
    fn start(&mut self, _: &RunInfo) -> Result<(), armscope::error::Error> {
        Ok(())
    }
    fn record(&mut self, s: &Sample) -> Result<(), armscope::error::Error> {
        if !s.is_final {
            self.rows.push((s.u.to_vec(), s.torque_limit.to_vec(), s.v.to_vec(), s.saturated.to_vec()));
        }
        Ok(())
    }
    fn finish(&mut self, _: &RunInfo, _: &Summary) -> Result<(), armscope::error::Error> {
        Ok(())
    }
}

/// Servo mode (`--drive pd`: the PD loop on the steppers' pull-out curve) on the tutorial's motor
/// file with a fast wave: at every step the limit is what the
/// motor gives at the joint's speed in the direction of the torque (N·T before the gearbox's losses,
/// which the plant applies as friction), the applied torque never exceeds it, and a step is
/// flagged saturated exactly when the torque sits at the limit; the limit does fall (J2, J3 at least
/// 5 % below their 15 × 0.59 = 8.85 N·m at rest), and the summary reports the lowest. The summary's
/// limit at rest is the motor's too: N·T, or the rating over η (J6: 1.5/0.9).
#[test]
fn servo_mode_clips_to_the_speed_dependent_limit_at_every_step() {
    let config = RunConfig { urdf: common::box_urdf(), motors: Some(motors_file("tutorial.toml")), drive: armscope::config::DriveMode::Pd, duration: 6.0, freq: 3.0, ..RunConfig::default() };
    let experiment = Experiment::prepare(config).unwrap();
    let motors = experiment.motors.clone().expect("motors");
    let mut capture = Capture::default();
    let summary = simulate(&experiment, &mut [&mut capture], None).unwrap();
    let mut lowest = [f64::INFINITY; 6];
    for (u, limit, v, saturated) in &capture.rows {
        for j in 0..6 {
            let (low, high) = motors.joints[j].as_ref().unwrap().torque_range(v[j]);
            let want = if u[j] >= 0.0 { high } else { -low };
            assert_eq!(limit[j], want, "J{} limit at q̇ = {}", j + 1, v[j]);
            assert!(u[j].abs() <= limit[j], "J{}: |u| {} > limit {}", j + 1, u[j], limit[j]);
            if saturated[j] {
                assert_eq!(u[j].abs(), limit[j]);
            }
            lowest[j] = lowest[j].min(limit[j]);
        }
    }
    assert!(lowest[1] < 0.95 * 8.85 && lowest[2] < 0.95 * 8.85, "the limit falls with speed: {lowest:?}");
    assert_eq!(summary.lowest_torque_limit, lowest.to_vec());
    for (got, want) in summary.effort_limit.iter().zip([8.85, 8.85, 8.85, 2.0, 2.0, 1.5 / 0.9]) {
        assert!((got - want).abs() < 1e-12, "limit at rest {got} vs {want}");
    }
}

/// The motor file's rotors join the mass matrix: J_r·N² on the diagonal (the 17HS19-2004S1's
/// 8.2e-6 kg·m² behind 15:1 is 1.845e-3 kg·m²; the 17HS4401's 5.4e-6 behind 5:1, 1.35e-4).
#[test]
fn the_motor_files_rotors_are_in_the_mass_matrix() {
    let bare = Experiment::prepare(RunConfig { urdf: common::box_urdf(), ..RunConfig::default() }).unwrap();
    let with = Experiment::prepare(RunConfig { urdf: common::box_urdf(), motors: Some(motors_file("tutorial.toml")), ..RunConfig::default() }).unwrap();
    let q = [0.3, -0.5, 0.8, -1.1, 0.6, 0.2];
    let m0 = crba(&bare.model, &mut Data::new(&bare.model), &q).clone();
    let m1 = crba(&with.model, &mut Data::new(&with.model), &q).clone();
    for i in 0..6 {
        let want = if i < 3 { 8.2e-6 * 225.0 } else { 5.4e-6 * 25.0 };
        assert!((m1[(i, i)] - m0[(i, i)] - want).abs() < 1e-15, "J{}", i + 1);
    }
}

/// The limit at every step is in both recordings: the .rrd's `joints/J2/torque_limit` per step, the
/// MCAP's `/controller` `torque_limit` field; and the console lists the motors.
#[test]
fn recordings_and_console_show_the_speed_dependent_limit() {
    let dir = tempfile::tempdir().unwrap();
    let (rrd, mcap) = (dir.path().join("m.rrd"), dir.path().join("m.mcap"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--urdf", common::box_urdf().to_str().unwrap(), "--motors", motors_file("tutorial.toml").to_str().unwrap(), "--drive", "pd", "--duration", "1", "--freq", "3"])
        .args(["--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("motors (") && stdout.contains("17HS19-2004S1") && stdout.contains("17HS4401") && stdout.contains("lowest limit (N·m)"), "{stdout}");
    let limits = common::rrd::Rrd::open(&rrd).series("/joints/J2/torque_limit");
    assert_eq!(limits.len(), 1001, "one row per step");
    // (the motor's torque at the joint before the gearbox's losses: at most 15 × 0.59 = 8.85 N·m)
    assert!(limits.iter().all(|(_, v)| v.len() == 2 && v[0] == -v[1] && v[0] > 0.0 && v[0] <= 8.85 + 1e-12));
    assert!(limits.iter().any(|(_, v)| v[0] < 0.98 * 8.85), "the limit falls somewhere in the run");
    // the motor's shaft speed, N·q̇ in rev/s, at every step
    let speed = common::rrd::Rrd::open(&rrd).series("/joints/J2/motor_speed");
    assert_eq!(speed.len(), 1001);
    assert!(speed.iter().any(|(_, s)| s[0].abs() > 1.0), "15:1 turns the motor at several rev/s");
    let bytes = std::fs::read(&mcap).unwrap();
    let mut count = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap()).filter(|m| m.channel.topic == "/controller") {
        let schema = m.channel.schema.clone().unwrap();
        let pool = prost_reflect::DescriptorPool::decode(&schema.data[..]).unwrap();
        let v = prost_reflect::DynamicMessage::decode(pool.get_message_by_name(&schema.name).unwrap(), &m.data[..]).unwrap();
        let list = v.get_field_by_name("torque_limit").unwrap().as_list().unwrap().to_vec();
        assert_eq!(list.len(), 6);
        assert_eq!(v.get_field_by_name("motor_speed").unwrap().as_list().unwrap().len(), 6);
        count += 1;
    }
    assert_eq!(count, 1001);
}

#[test]
fn the_motor_files_are_built_into_the_binary() {
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .current_dir(dir.path())
        .args(["run", "--motors", "assets/motors/tutorial.toml", "--duration", "0.2", "--no-rrd", "--no-mcap", "--quiet"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

/// The SO-100 (example-robot-data's URDF) with its Feetech STS3215 servos (`assets/motors/so100.toml`):
/// each servo is driven by its own firmware (the catalogue's firmware model), or with `--drive pd`
/// by the PD loop on its torque–speed line; either way every joint is limited to the servo's
/// 2.94 N·m stall torque instead of the URDF's 35 N·m, and the run is stable (no chatter).
#[test]
fn the_so100_runs_on_its_sts3215_servos() {
    let urdf = common::repo().join("tests/fixtures/robots/so100.urdf");
    for drive in [armscope::config::DriveMode::Native, armscope::config::DriveMode::Pd] {
        let experiment = Experiment::prepare(RunConfig { urdf: urdf.clone(), motors: Some(motors_file("so100.toml")), duration: 5.0, drive, ..RunConfig::default() }).unwrap();
        assert!(!experiment.stepper_mode(), "servos are not steppers");
        assert_eq!(experiment.servos.is_some(), drive == armscope::config::DriveMode::Native, "{drive:?}");
        let summary = simulate(&experiment, &mut [], None).unwrap();
        assert!(matches!(summary.status, armscope::summary::RunStatus::Completed));
        for (j, limit) in summary.effort_limit.iter().enumerate() {
            assert!((limit - 2.94).abs() < 1e-12, "{}: {limit}", summary.joints[j]);
            assert!(summary.peak_abs_torque[j] <= 2.94 + 1e-12);
            assert!(summary.chatter_percent[j] < 5.0, "{drive:?} {}: chatter {}", summary.joints[j], summary.chatter_percent[j]);
        }
    }
}

/// A DC servo gives its line T_s·(1 − |ω|/ω₀) with the motion but brakes with its stall torque
/// against it (Isaac Lab's DCMotor, clipped at the stall torque): pushed past its no-load speed it
/// still holds back instead of giving nothing. A stepper's pull-out curve holds both ways.
#[test]
fn a_servo_brakes_with_its_stall_torque_and_a_stepper_is_symmetric() {
    let catalogue = Catalogue::load(&motors_file("catalogue.toml")).unwrap();
    let servo = catalogue.drive_train("STS3215-C018").unwrap().unwrap(); // 2.94 N·m, 4.712 rad/s
    let (lowest, highest) = servo.torque_range(4.712 / 2.0);
    assert!((highest - 1.47).abs() < 1e-9, "half the no-load speed: half the stall torque with the motion, got {highest}");
    assert!((lowest + 2.94).abs() < 1e-12, "braking: the stall torque, got {lowest}");
    let (lowest, highest) = servo.torque_range(-10.0);
    assert_eq!((lowest, highest), (0.0, 2.94), "past the no-load speed backwards: nothing with the motion, all of it against");
    assert_eq!(servo.available(1.0, 10.0), 0.0, "with the motion past the no-load speed: nothing");
    assert_eq!(servo.available(-1.0, 10.0), 2.94, "against it: the stall torque");
    let stepper = catalogue.drive_train("17HS4401").unwrap().unwrap().followed_by(10.0, LossyGear::with_efficiency(0.9), f64::INFINITY);
    for speed in [0.0, 3.0, -3.0, 40.0] {
        // the range is the motor's, before the gearbox's losses (the plant takes those as friction)
        let (lowest, highest) = stepper.torque_range(speed);
        assert_eq!(-lowest, highest);
        assert!((0.9 * highest - stepper.torque_limit(speed)).abs() < 1e-12);
    }
}

/// What reaches the joint through a lossy gear (η 0.8, η_b 0.5, breakaway 0.1 N·m, viscous 0.01):
/// driving η·N·T − F_b − c·|q̇|, braking N·T/η_b + F_b + c·|q̇| (the friction helps hold), at rest a
/// torque counts as driving; a self-locking gear holds what its rating allows.
#[test]
fn a_lossy_gear_gives_less_driving_and_more_braking() {
    let servo = || Box::new(DcServo { name: "v".into(), stall_torque: 1.0, no_load_speed: 100.0, rotor_inertia: 0.0 });
    let gear = LossyGear { efficiency: 0.8, backdrive_efficiency: 0.5, breakaway_torque: 0.1, viscous: 0.01 };
    let drive = DriveTrain::with_gear(servo(), 10.0, gear, f64::INFINITY);
    // at 2 rad/s the motor turns at 20 rad/s: 0.8 N·m with the motion, its 1 N·m stall braking
    assert!((drive.available(1.0, 2.0) - (0.8 * 8.0 - 0.1 - 0.02)).abs() < 1e-12);
    assert!((drive.available(-1.0, 2.0) - (10.0 / 0.5 + 0.1 + 0.02)).abs() < 1e-12);
    assert!((drive.available(1.0, 0.0) - (0.8 * 10.0 - 0.1)).abs() < 1e-12);
    let worm = DriveTrain::with_gear(servo(), 10.0, LossyGear { backdrive_efficiency: -0.2, ..gear }, 30.0);
    assert_eq!(worm.available(-1.0, 2.0), 30.0);
    assert!((worm.available(1.0, 2.0) - (0.8 * 8.0 - 0.1 - 0.02)).abs() < 1e-12);
}
