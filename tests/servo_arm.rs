//! Serial-bus servos on an arm, driven by their own firmware: the SO-101 on its STS3215s holding
//! against gravity as the position loop's closed form says, the joints whose duty saturates under a
//! payload and the current they draw, and a one-joint arm against the testbench's exact step.

mod common;

use armscope::actuator::bus_servo::firmware::XL330;
use armscope::actuator::bus_servo::{FrictionModel, ServoFriction, ServoParams};
use armscope::config::RunConfig;
use armscope::experiment::Experiment;
use armscope::testbench::synthetic::{Bench, Trajectory, record};
use armscope::testbench::{ReplayOptions, Step, rollout};
use std::process::Command;

fn so101() -> std::path::PathBuf {
    common::repo().join("tests/fixtures/robots/so101.urdf")
}

fn so101_motors() -> std::path::PathBuf {
    common::repo().join("assets/motors/so101.toml")
}

fn run(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).args(args).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).to_string(), String::from_utf8_lossy(&out.stderr).to_string())
}

#[test]
fn a_held_servo_sags_as_its_position_loops_closed_form_says() {
    // At rest a servo's loop gives k_t·V·e_g·k_p·e/R for an error e; held still, that and gravity
    // differ by no more than the friction the servo's model can give at rest (M1: K_c, the STS3215's
    // 0.196 N·m). The SO-101 with 0.3 kg at the tool, every joint held at 0 for 2 s.
    let config = RunConfig { urdf: so101(), motors: Some(so101_motors()), payload: 0.3, hold: true, duration: 2.0, ..RunConfig::default() };
    let experiment = Experiment::prepare(config).unwrap();
    let servos = experiment.servos.as_ref().expect("firmware mode");
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("trace.csv");
    let mut recorder = armscope::recorder::Trace::new(trace.clone());
    let summary = armscope::sim::simulate(&experiment, &mut [&mut recorder], None).unwrap();
    assert_eq!(summary.status, armscope::summary::RunStatus::Completed);
    let table = common::read_csv(&trace);
    let last = table.rows.last().unwrap();
    let n = experiment.model.dof();
    let mut checked = 0;
    for (j, servo, ratio) in servos.servos() {
        assert_eq!(ratio, 1.0);
        let (q, v, tau_g) = (last[1 + j], last[1 + n + j], last[1 + 5 * n + j]);
        assert_eq!(v, 0.0, "{}: held still by friction", experiment.model.joints[j].name);
        let error = 0.0 - q;
        let loop_torque = servo.kt * servo.supply * servo.firmware.duty_per_rad() * error / servo.resistance;
        let band = servo.friction.base;
        assert!((loop_torque + tau_g).abs() <= band + 1e-9, "{}: loop {loop_torque} vs gravity {tau_g}, band {band}", experiment.model.joints[j].name);
        if tau_g.abs() > 2.0 * band {
            // a loaded joint's sag is the closed form's within the band's share of it
            let closed_form = -tau_g * servo.resistance / (servo.kt * servo.supply * servo.firmware.duty_per_rad());
            let slack = band * servo.resistance / (servo.kt * servo.supply * servo.firmware.duty_per_rad());
            assert!((error - closed_form).abs() <= slack + 1e-12, "{}: error {error} vs {closed_form} ± {slack}", experiment.model.joints[j].name);
            checked += 1;
        }
    }
    assert!(checked >= 2, "the shoulder and the elbow carry the payload");
}

#[test]
fn the_summary_names_the_servos_at_full_duty_and_their_current() {
    // the SO-101 lifting 0.3 kg: shoulder_lift stepped 1.2 rad, beyond the 0.37 rad its P gain of 16
    // turns into full duty (BAM's 12 V servo: its error gain; the real-log fit's is 0.77 of it)
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("summary.json");
    let (code, stdout, stderr) = run(&[
        "run", "--urdf", so101().to_str().unwrap(), "--motors", common::follower::so101_motors_bam12v().to_str().unwrap(), "--payload", "0.3", "--test-joint", "shoulder_lift",
        "--test-angle", "1.2", "--duration", "3", "--no-rrd", "--no-mcap", "--summary-json", json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("firmware mode: shoulder_pan, shoulder_lift, elbow_flex, wrist_flex, wrist_roll, gripper driven by their servos' position loops"), "{stderr}");
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let servos = summary["summary"]["servos"].as_array().unwrap();
    let full: Vec<f64> = servos.iter().map(|s| s["full_duty_percent"].as_f64().unwrap()).collect();
    assert!(full[1] > 0.0 && full.iter().enumerate().all(|(j, &f)| j == 1 || f == 0.0), "only shoulder_lift at full duty: {full:?}");
    let lift = &servos[1];
    let (peak, rms) = (lift["peak_current"].as_f64().unwrap(), lift["rms_current"].as_f64().unwrap());
    // at full duty from rest the current is the supply over the resistance, within the datasheet's
    // line: 2.94 N·m / k_t
    let servo = armscope::actuator::Catalogue::load(std::path::Path::new(armscope::builtin::DEFAULT_CATALOGUE)).unwrap().drive_train("STS3215-C018-BAM12V").unwrap().unwrap().servo.unwrap();
    assert!(peak <= 2.94 / servo.kt + 1e-9 && peak > 0.5 * 2.94 / servo.kt, "peak {peak} A");
    assert!(rms > 0.0 && rms < peak);
    let line = stdout.lines().find(|l| l.contains("shoulder_lift: its servo at full duty")).unwrap_or_else(|| panic!("{stdout}"));
    assert!(line.contains(&format!("drawing up to {peak:.2} A")), "{line}");
    // every joint is its servo's: the PD controller drives none, and no gains are tuned for it
    assert_eq!(summary["gains"]["source"], armscope::control::gains::NO_PD_JOINT, "{}", summary["gains"]);
    assert!(summary["gains"]["spectral_radius"].is_null() && summary["gains"]["kp"].as_array().unwrap().iter().all(|k| k.as_f64() == Some(0.0)));
    assert!(stdout.contains("  controller: none (the PD drives no joint") && !stdout.contains("auto-tuned"), "{stdout}");
    // with --drive pd the PD drives them on the servos' torque lines: its gains tuned
    let (code, stdout, stderr) = run(&[
        "run", "--urdf", so101().to_str().unwrap(), "--motors", common::follower::so101_motors_bam12v().to_str().unwrap(), "--drive", "pd", "--duration", "0.1", "--no-rrd", "--no-mcap",
        "--summary-json", json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(summary["gains"]["source"], "auto-tuned", "{}", summary["gains"]);
    assert!(stdout.contains("  controller: PD + gravity feed-forward"), "{stdout}");
}

#[test]
fn a_one_joint_arm_steps_as_the_testbench_does() {
    // The arm's discrete plant with a servo on a pendulum and the testbench's exact step integrate
    // the same law (the firmware ticking each plant step, the back-EMF explicit, the Coulomb budget
    // a band solved exactly, the viscous part implicit): the same trajectory to rounding.
    let friction = ServoFriction { model: FrictionModel::M3, base: 0.01, viscous: 0.006, load: 0.2, ..Default::default() };
    let params = ServoParams { family: XL330, kt: 0.35, resistance: 2.8, armature: 0.002, q_offset: 0.0, friction, error_gain_ratio: 1.0, max_velocity: f64::INFINITY, supply_resistance: 0.0, motor_voltage_limit: f64::INFINITY, command_delay: 0.0 };
    let dir = tempfile::tempdir().unwrap();
    // a 0.49 kg point 0.1 m down the pendulum (a tiny rotational inertia about its centre for the
    // loader), hanging at q = 0 from a horizontal axis
    let urdf = dir.path().join("pendulum.urdf");
    std::fs::write(&urdf, r#"<robot name="bench"><link name="world"/>
  <link name="arm"><inertial><origin xyz="0 0 -0.1"/><mass value="0.49"/><inertia ixx="1e-12" iyy="1e-12" izz="1e-12" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="servo" type="revolute"><parent link="world"/><child link="arm"/><axis xyz="0 1 0"/><limit lower="-3.1" upper="3.1" effort="10" velocity="10"/></joint></robot>"#).unwrap();
    // the servo as a motor of the file's own: its firmware model only, no datasheet line to clip it
    let mut toml = String::from("in_urdf = true\n[joints.servo]\nmotor = \"BENCH\"\n[motors.BENCH]\nkind = \"servo\"\n[motors.BENCH.firmware]\n");
    toml += "source = \"the test's known servo\"\nfamily = \"xl330\"\nkp = 400\nsupply_voltage = 7.4\n";
    for (key, value) in params.to_json().as_object().unwrap() {
        if key != "actuator" {
            toml += &format!("{key} = {value}\n");
        }
    }
    let motors = dir.path().join("motors.toml");
    std::fs::write(&motors, toml).unwrap();
    let trace = dir.path().join("trace.csv");
    let (code, _, stderr) = run(&["run", "--urdf", urdf.to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--test-joint", "servo", "--test-angle", "1.0", "--duration", "2", "--trace", trace.to_str().unwrap(), "--no-rrd", "--no-mcap", "--quiet"]);
    assert_eq!(code, 0, "{stderr}");
    let arm = common::read_csv(&trace);
    // the same goal and bench as a log at the arm's 1 ms, stepped once a row, on the arm's gravity
    let mut log = record(&params, &Bench { dt: 0.001, duration: 2.0, vin: 7.4, ..Default::default() }, Trajectory::SinSin, &ReplayOptions::default());
    for e in &mut log.entries {
        (e.goal, e.enabled, e.position, e.speed) = (1.0, true, 0.0, 0.0);
    }
    let options = ReplayOptions { step: Step::Exact, substeps: 1, gravity: 9.81, ..Default::default() };
    let bench = rollout(&log, &params, &options);
    let worst = arm.rows.iter().zip(&bench.position).map(|(row, q)| (row[1] - q).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-9, "largest gap {worst} rad");
}

#[test]
fn servos_need_the_discrete_plant_and_their_settings_a_firmware() {
    let (code, _, stderr) = run(&["run", "--urdf", so101().to_str().unwrap(), "--motors", so101_motors().to_str().unwrap(), "--time-step", "0", "--duration", "0.1", "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 2);
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.contains("notice:")).collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(lines[0].contains("--time-step: 0 (the continuous plant)") && lines[0].contains("need the discrete plant"), "{}", lines[0]);
    let dir = tempfile::tempdir().unwrap();
    let motors = dir.path().join("m.toml");
    std::fs::write(&motors, "in_urdf = true\n[joints.shoulder_lift]\nmotor = \"STS3250\"\nkp = 16\n").unwrap();
    let (code, _, stderr) = run(&["run", "--urdf", so101().to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--duration", "0.1", "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("joint 'shoulder_lift': field 'kp' sets a servo's firmware, but motor 'STS3250' has no firmware model") && stderr.lines().count() == 1, "{stderr}");
    // --drive pd: the same servos as torque sources under the PD controller, on any plant
    let (code, _, stderr) = run(&["run", "--urdf", so101().to_str().unwrap(), "--motors", so101_motors().to_str().unwrap(), "--drive", "pd", "--time-step", "0", "--duration", "0.1", "--no-rrd", "--no-mcap", "--quiet"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("firmware mode"));
}

#[test]
fn a_firmware_current_limit_holds_the_current_and_says_so() {
    // the motor file's current_limit narrows the duty so that |i| ≤ 0.5 A (BAM's limiter): the
    // shoulder lifting 0.3 kg draws 0.5 A at most, and the run says the servo is at its limit
    let dir = tempfile::tempdir().unwrap();
    let motors = dir.path().join("m.toml");
    std::fs::write(&motors, "in_urdf = true\n[joints.shoulder_lift]\nmotor = \"STS3215-C018\"\nkp = 16\ncurrent_limit = 0.5\n").unwrap();
    let json = dir.path().join("s.json");
    let (code, stdout, stderr) = run(&[
        "run", "--urdf", so101().to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--payload", "0.3", "--test-joint", "shoulder_lift", "--test-angle", "1.2",
        "--duration", "3", "--no-rrd", "--no-mcap", "--summary-json", json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let lift = &summary["summary"]["servos"][1];
    assert!(lift["peak_current"].as_f64().unwrap() <= 0.5 + 1e-9, "{lift}");
    assert!(summary["summary"]["saturation_percent"][1].as_f64().unwrap() > 50.0);
    assert!(stdout.contains("shoulder_lift: its servo at its current limit"), "{stdout}");
}

/// Shoulder_lift's duty and position at every control step.
#[derive(Default)]
struct ShoulderLog {
    rows: Vec<(f64, f64, f64)>,
}

impl armscope::recorder::Recorder for ShoulderLog {
    fn start(&mut self, _: &armscope::recorder::RunInfo) -> Result<(), armscope::error::Error> {
        Ok(())
    }
    fn record(&mut self, s: &armscope::sample::Sample) -> Result<(), armscope::error::Error> {
        self.rows.push((s.t, s.duty[1], s.q[1]));
        Ok(())
    }
    fn finish(&mut self, _: &armscope::recorder::RunInfo, _: &armscope::summary::Summary) -> Result<(), armscope::error::Error> {
        Ok(())
    }
}

fn held_with_a_kilogram(motors: &std::path::Path) -> (armscope::summary::Summary, ShoulderLog) {
    let config = RunConfig { urdf: so101(), motors: Some(motors.to_path_buf()), payload: 1.0, hold: true, duration: 5.0, ..RunConfig::default() };
    let experiment = Experiment::prepare(config).unwrap();
    let mut log = ShoulderLog::default();
    let summary = armscope::sim::simulate(&experiment, &mut [&mut log], None).unwrap();
    (summary, log)
}

#[test]
fn a_feetech_overload_protection_trips_after_its_time_and_leaves_its_protective_duty() {
    // Feetech's factory settings: a duty of 80 % or more for 2 s limits the servo to 20 %. The
    // SO-101 holding 1 kg at reach: shoulder_lift's loop asks for full duty and cannot hold; 2 s
    // after its duty first reached 80 % the protection trips, and the shoulder, at 20 %, falls on.
    // (BAM's 12 V servo: on the catalogue's fit of real logs the servo gives the datasheet's
    // 2.94 N·m at about 31 % duty, and its duty stays below the 80 % that starts the overload timer)
    let bam = common::follower::so101_motors_bam12v();
    let (summary, log) = held_with_a_kilogram(&bam);
    let trip = summary.servos[1].as_ref().unwrap().protection_trip.expect("shoulder_lift trips");
    assert_eq!(trip.kind, armscope::actuator::bus_servo::TripKind::Overload);
    assert!((trip.time - trip.since - 2.0).abs() < 1e-9, "{trip:?}");
    // the duty first reached 80 % at the control step the timer started from (plant steps within it)
    let first_over = log.rows.iter().find(|r| r.1.abs() >= 0.8).unwrap().0;
    assert!((first_over - trip.since).abs() <= 1e-3 + 1e-9, "first at {first_over}, timer from {}", trip.since);
    assert!(log.rows.iter().filter(|r| r.0 < trip.time).all(|r| r.1.abs() <= 0.97 + 1e-12));
    assert!(log.rows.iter().filter(|r| r.0 > trip.time + 1e-3).all(|r| r.1.abs() <= 0.2 + 1e-12), "20 % once tripped");
    assert!(summary.servos.iter().enumerate().all(|(j, s)| j == 1 || s.as_ref().is_none_or(|s| s.protection_trip.is_none())));
    assert!(summary.saturation_verdicts().iter().any(|v| v.starts_with("shoulder_lift: its overload protection trips at t =") && v.contains("at most 20 % duty")));

    // with Overload_Torque at 100 % (above the 97 % its PWM reaches) it never trips, and the
    // shoulder, still at full duty, ends higher than the tripped one
    let dir = tempfile::tempdir().unwrap();
    let motors = dir.path().join("m.toml");
    let text = std::fs::read_to_string(&bam).unwrap().replace("[joints.shoulder_lift]\nmotor = \"STS3215-C018-BAM12V\"\nkp = 16", "[joints.shoulder_lift]\nmotor = \"STS3215-C018-BAM12V\"\nkp = 16\noverload_torque = 100");
    std::fs::write(&motors, text).unwrap();
    let (untripped, log_untripped) = held_with_a_kilogram(&motors);
    assert!(untripped.servos[1].as_ref().unwrap().protection_trip.is_none());
    let (fell, held) = (log.rows.last().unwrap().2, log_untripped.rows.last().unwrap().2);
    assert!(fell > held + 0.05, "tripped {fell} rad vs untripped {held} rad");
}

#[test]
fn protection_registers_are_checked_and_set_in_their_units() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = so101();
    let attempt = |body: &str| {
        let motors = dir.path().join("p.toml");
        std::fs::write(&motors, format!("in_urdf = true\n[joints.shoulder_lift]\n{body}\n")).unwrap();
        run(&["run", "--urdf", urdf.to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--duration", "0.01", "--no-rrd", "--no-mcap"])
    };
    let (code, _, stderr) = attempt("motor = \"STS3215-C018\"\noverload_torque = 101");
    assert_ne!(code, 0);
    assert!(stderr.contains("field 'overload_torque' must be a whole register value from 0 to 100 (got 101)"), "{stderr}");
    let (code, _, stderr) = attempt("motor = \"XL330-M288\"\nprotection_current = 250");
    assert_ne!(code, 0);
    assert!(stderr.contains("field 'protection_current' sets a Feetech protection register, but motor 'XL330-M288' has no firmware model with protections"), "{stderr}");
    // LeRobot's gripper settings: Protection_Current 250 (1.625 A), Overload_Torque 25
    let motors = dir.path().join("ok.toml");
    std::fs::write(&motors, "in_urdf = true\n[joints.shoulder_lift]\nmotor = \"STS3215-C018\"\nprotection_current = 250\noverload_torque = 25\nprotection_time = 50\n").unwrap();
    let set = armscope::actuator::load_motor_file(&motors, &armscope::model::load_urdf(&urdf).unwrap()).unwrap();
    let p = set.joints[1].as_ref().unwrap().servo.as_ref().unwrap().firmware.protection;
    let (overload, overcurrent) = (p.overload.unwrap(), p.overcurrent.unwrap());
    assert!((overcurrent.current - 1.625).abs() < 1e-12 && (overload.threshold - 0.25).abs() < 1e-12 && (overload.time - 0.5).abs() < 1e-12);
    assert!((overload.protective - 0.2).abs() < 1e-12 && (overcurrent.time - 2.0).abs() < 1e-12, "the others keep the factory's");
}

/// Every sample's joint positions and speeds, its tool position, and its servos' duty and torque
/// limits.
#[derive(Default)]
struct Motion {
    states: Vec<(Vec<f64>, Vec<f64>)>,
    tool: Vec<[f64; 3]>,
    drive: Vec<(Vec<f64>, Vec<f64>)>,
}

impl armscope::recorder::Recorder for Motion {
    fn start(&mut self, _: &armscope::recorder::RunInfo) -> Result<(), armscope::error::Error> {
        Ok(())
    }
    fn record(&mut self, s: &armscope::sample::Sample) -> Result<(), armscope::error::Error> {
        self.states.push((s.q.to_vec(), s.v.to_vec()));
        self.tool.push([s.tool_position.x, s.tool_position.y, s.tool_position.z]);
        self.drive.push((s.duty.to_vec(), s.torque_limit.to_vec()));
        Ok(())
    }
    fn finish(&mut self, _: &armscope::recorder::RunInfo, _: &armscope::summary::Summary) -> Result<(), armscope::error::Error> {
        Ok(())
    }
}

#[test]
fn a_positions_only_run_moves_exactly_as_the_full_run() {
    // identification runs each candidate for its joint positions alone (no statistics, no tool
    // poses, no drive figures): the motion must be the full run's to the bit, the SO-101 on its servos carrying 0.2 kg
    // along its default trajectory
    let config = RunConfig { urdf: so101(), motors: Some(so101_motors()), payload: 0.2, duration: 1.5, ..RunConfig::default() };
    let experiment = Experiment::prepare(config).unwrap();
    assert!(experiment.servos.is_some(), "firmware mode");
    let (mut full, mut lean) = (Motion::default(), Motion::default());
    let summary = armscope::sim::simulate(&experiment, &mut [&mut full], None).unwrap();
    let status = armscope::sim::simulate_positions(&experiment, &mut [&mut lean], None).unwrap();
    assert_eq!(summary.status, armscope::summary::RunStatus::Completed);
    assert_eq!(status, summary.status);
    assert_eq!(full.states.len(), experiment.steps + 1);
    assert_eq!(lean.states, full.states, "the same motion, bit for bit");
    let moved = full.states.iter().map(|(q, _)| (q[1] - full.states[0].0[1]).abs()).fold(0.0, f64::max);
    assert!(moved > 0.05, "the shoulder moved {moved} rad");
    // the full run's tool moves; the positions-only run's samples carry none
    assert!(full.tool.iter().any(|p| p != &full.tool[0]));
    assert!(lean.tool.iter().all(|p| p == &[0.0; 3]));
    // nor the servos' duty and torque limits, which the full run's show
    assert!(full.drive.iter().any(|(duty, limit)| duty.iter().any(|&d| d != 0.0) && limit.iter().all(|&l| l > 0.0)));
    assert!(lean.drive.iter().all(|(duty, limit)| duty.iter().chain(limit).all(|&x| x == 0.0)));
}

#[test]
fn a_floor_holds_the_tool_on_it_and_a_floor_out_of_reach_changes_nothing() {
    // the SO-101 on its servos with 0.2 kg along its default trajectory; a floor under the tool
    // halfway down from where it starts to its lowest stops it there, the tool resting on it while
    // the commands ask lower. The floor gives like a stiff spring (5e4 N/m): the SO-101's servos
    // press its tool with at most about 12 N (the shoulder's 2.94 N·m stall torque over its 0.25 m
    // reach), which sinks it 0.24 mm: never a millimetre below, resting within one
    let dir = tempfile::tempdir().unwrap();
    let with_floor = |height: Option<f64>| {
        let motors = dir.path().join("m.toml");
        let text = std::fs::read_to_string(so101_motors()).unwrap();
        std::fs::write(&motors, match height {
            Some(z) => text + &format!("\n[floor]\nheight = {z:?}\n"),
            None => text,
        })
        .unwrap();
        let config = RunConfig { urdf: so101(), motors: Some(motors), payload: 0.2, duration: 3.0, ..RunConfig::default() };
        let experiment = Experiment::prepare(config).unwrap();
        let mut motion = Motion::default();
        let summary = armscope::sim::simulate(&experiment, &mut [&mut motion], None).unwrap();
        assert_eq!(summary.status, armscope::summary::RunStatus::Completed, "the energy audit passes");
        motion
    };
    let free = with_floor(None);
    let start = free.tool[0][2];
    let lowest = free.tool.iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
    assert!(start - lowest > 5e-3, "the tool goes {} mm down", (start - lowest) * 1e3);
    let table = 0.5 * (start + lowest);
    let held = with_floor(Some(table));
    let held_lowest = held.tool.iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
    assert!(held_lowest >= table - 1e-3, "never below the table: {held_lowest} against {table} (free {lowest}, start {start})");
    let resting = held.tool.iter().filter(|p| (p[2] - table).abs() < 1e-3).count();
    assert!(resting >= 100, "on the table for {resting} ms");
    // a floor a metre under the arm: the same motion to the bit
    let far = with_floor(Some(lowest - 1.0));
    assert_eq!(far.states, free.states);
}

/// The motor file's table is drawn where the plant has it, in the `.rrd` and in both encodings of
/// the MCAP: a 0.8 m plate with its top at the floor's height (to float32 round-off in the `.rrd`,
/// exactly in the MCAP's float64 poses).
#[test]
fn a_motor_files_table_is_drawn_at_its_height_in_every_recording() {
    use armscope::ros2::Message;
    use prost::Message as _;
    let dir = tempfile::tempdir().unwrap();
    let height = -0.0217;
    let motors = dir.path().join("table.toml");
    std::fs::write(&motors, std::fs::read_to_string(so101_motors()).unwrap() + &format!("\n[floor]\nheight = {height:?}\n")).unwrap();
    let (rrd, mcap, ros2) = (dir.path().join("t.rrd"), dir.path().join("t.mcap"), dir.path().join("t-ros2.mcap"));
    let urdf = so101();
    let recorded = |extra: &[&str]| {
        let mut args = vec!["run", "--urdf", urdf.to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--duration", "0.05"];
        args.extend_from_slice(extra);
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 0, "{stderr}");
    };
    recorded(&["--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap()]);
    recorded(&["--no-rrd", "--mcap", ros2.to_str().unwrap(), "--mcap-encoding", "ros2"]);

    let file = common::rrd::Rrd::open(&rrd);
    let half = file.static_numbers("/world/floor", "Boxes3D:half_sizes");
    assert_eq!(half.len(), 3, "one box");
    assert!((half[0] - 0.4).abs() < 1e-6 && (half[1] - 0.4).abs() < 1e-6, "0.8 m wide: {half:?}");
    let centre = file.static_numbers("/world/floor", "Transform3D:translation");
    assert!((centre[2] + half[2] - height).abs() < 1e-6, "its top at the floor: centre {centre:?}, half {half:?}");

    let first_geometry = |path: &std::path::Path| {
        let bytes = std::fs::read(path).unwrap();
        mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap()).find(|m| m.channel.topic == "/robot/geometry").expect("the geometry").data.to_vec()
    };
    let scene = foxglove::messages::SceneUpdate::decode(&first_geometry(&mcap)[..]).unwrap();
    let table = scene.entities.iter().find(|e| e.id == "floor").expect("the table in the scene");
    assert_eq!((table.frame_id.as_str(), table.cubes.len()), ("world", 1));
    let (size, pose) = (table.cubes[0].size.as_ref().unwrap(), table.cubes[0].pose.as_ref().unwrap());
    assert_eq!((size.x, size.y), (0.8, 0.8));
    assert!((pose.position.as_ref().unwrap().z + size.z / 2.0 - height).abs() < 1e-12);

    let markers = armscope::ros2::messages::MarkerArray::decode(&first_geometry(&ros2)).unwrap();
    let table: Vec<_> = markers.markers.iter().filter(|m| m.ns == "floor").collect();
    assert_eq!(table.len(), 1, "one marker for the table");
    assert_eq!((table[0].header.frame_id.as_str(), table[0].scale.x, table[0].scale.y), ("world", 0.8, 0.8));
    assert!((table[0].pose.position.z + table[0].scale.z / 2.0 - height).abs() < 1e-12);
}

#[test]
fn a_bad_floor_is_refused_in_one_line_naming_its_field() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = so101();
    let attempt = |floor: &str, extra: &[&str]| {
        let motors = dir.path().join("f.toml");
        std::fs::write(&motors, std::fs::read_to_string(so101_motors()).unwrap() + "\n[floor]\n" + floor + "\n").unwrap();
        let mut args = vec!["run", "--urdf", urdf.to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--duration", "0.01", "--no-rrd", "--no-mcap"];
        args.extend_from_slice(extra);
        run(&args)
    };
    for (floor, extra, expected) in [
        ("height = \"low\"", &[][..], "[floor]: field 'height' must be a height in m (world z)"),
        ("height = 0.0\nlink = \"table_link\"", &[][..], "[floor]: field 'link' 'table_link' is no link of"),
        ("height = 0.0\nfriction = 0.5", &[][..], "[floor]: unknown field 'friction'"),
        ("height = 0.0", &["--time-step", "0"][..], "--time-step: 0 (the continuous plant): the motor file's [floor] is a contact the discrete plant takes"),
    ] {
        let (code, _, stderr) = attempt(floor, extra);
        assert_ne!(code, 0, "{floor}");
        let errors: Vec<&str> = stderr.lines().filter(|l| !l.starts_with("armscope: notice")).collect();
        assert!(errors.len() == 1 && errors[0].contains(expected), "{floor}: {stderr}");
    }
}
