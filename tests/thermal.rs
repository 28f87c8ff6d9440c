//! Motor heat in a run (issue 21 item 3): the two-node winding model of a catalogue motor with
//! thermal data, integrated in `run`, in the summary and in both recordings; RMS torque per joint.

mod common;

use armscope::actuator::thermal::{AMBIENT_TEMPERATURE, MotorHeat, ThermalData};
use armscope::recorder::ControllerTelemetry;
use common::rrd::Rrd;
use common::{box_urdf, read_csv, repo};
use prost::Message as _;
use std::path::Path;
use std::process::Command;

/// The catalogue's maxon EC 45 flat 30 W (assets/motors/catalogue.toml, from its datasheet).
const EC45: ThermalData = ThermalData { winding_to_housing: 3.96, housing_to_ambient: 5.7, winding_time_constant: 11.5, motor_time_constant: 251.0, resistance_25: 4.83, max_winding_temperature: 125.0 };
const EC45_TORQUE_CONSTANT: f64 = 0.051;
const RATIO: f64 = 100.0;

/// A motor file giving the box model's shoulder (J2) the EC 45 flat through a 100:1 reduction.
fn motor_file(dir: &Path) -> String {
    let path = dir.join("thermal.toml");
    std::fs::write(&path, format!("[joints.J2]\nmotor = \"EC45flat-30W-24V\"\ngear_ratio = {RATIO}\nefficiency = 0.9\n")).unwrap();
    path.to_str().unwrap().to_string()
}

fn run(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).args(args).current_dir(repo()).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into_owned() + &String::from_utf8_lossy(&out.stdout))
}

/// Holding the arm still, the shoulder's motor carries a constant current; after 10 motor time
/// constants (e^−10 of the rise left: < 0.01 K) its winding sits at the closed-form steady state
/// T_amb + (R_th1 + R_th2)·I²·R(T), within the bar's 0.5 K.
#[test]
fn a_motor_holding_a_constant_torque_settles_at_the_closed_form_temperature() {
    let dir = tempfile::tempdir().unwrap();
    let summary_path = dir.path().join("summary.json");
    let duration = (10.0 * EC45.motor_time_constant).to_string();
    let (code, out) = run(&["run", "--quiet", "--urdf", box_urdf().to_str().unwrap(), "--motors", &motor_file(dir.path()), "--static", "--duration", &duration, "--no-rrd", "--no-mcap", "--summary-json", summary_path.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}");
    let summary: serde_json::Value = serde_json::from_str::<serde_json::Value>(&std::fs::read_to_string(&summary_path).unwrap()).unwrap()["summary"].clone();
    let holding = summary["rms_torque"][1].as_f64().unwrap();
    assert!(holding > 1.0, "the shoulder holds the arm: {holding} N·m");
    let current = holding / (RATIO * EC45_TORQUE_CONSTANT);
    let alpha = 0.0039;
    let gain = (EC45.winding_to_housing + EC45.housing_to_ambient) * current * current * EC45.resistance_25;
    let closed_form = (AMBIENT_TEMPERATURE + gain * (1.0 - 25.0 * alpha)) / (1.0 - gain * alpha);
    let winding = &summary["winding"][1];
    let peak = winding["peak_temperature"].as_f64().unwrap();
    assert!((peak - closed_form).abs() < 0.5, "winding {peak} °C vs the closed form {closed_form} °C");
    assert!((winding["steady_temperature"].as_f64().unwrap() - closed_form).abs() < 1e-6, "{winding} vs {closed_form}");
    assert!(winding["time_to_limit"].is_null(), "{closed_form} °C is below the 125 °C limit: never");
    // the other joints have no motor with thermal data, and the console says so
    assert!(summary["winding"][0].is_null());
}

/// Both recordings carry the winding temperature of the torque the motor actually gave: an
/// independent integration of the trace's J2 torque, step by step, equals the `.rrd`'s and the
/// `.mcap`'s series; the summary's RMS torque is the trace's.
#[test]
fn recordings_carry_the_winding_temperature_of_the_torque_the_motor_gave() {
    let dir = tempfile::tempdir().unwrap();
    let (rrd, mcap, trace, summary_path) = (dir.path().join("t.rrd"), dir.path().join("t.mcap"), dir.path().join("trace.csv"), dir.path().join("s.json"));
    let (code, out) = run(&[
        "run", "--urdf", box_urdf().to_str().unwrap(), "--motors", &motor_file(dir.path()), "--duration", "12",
        "--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap(), "--trace", trace.to_str().unwrap(), "--summary-json", summary_path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("winding peak (°C)") && out.contains("not thermally checked"), "{out}");
    let trace = read_csv(&trace);
    let u = trace.column("u2");
    let mut heat = MotorHeat::new(EC45, AMBIENT_TEMPERATURE, 1e-3);
    let mut expected = Vec::with_capacity(u.len());
    for &torque in &u {
        expected.push(heat.winding_temperature());
        heat.step(torque.abs() / (RATIO * EC45_TORQUE_CONSTANT));
    }
    assert!(expected.last().unwrap() - AMBIENT_TEMPERATURE > 5.0, "the shoulder's winding warms: {:?}", expected.last());
    let recorded: Vec<f64> = Rrd::open(&rrd).series("/joints/J2/winding_temperature").into_iter().map(|(_, v)| v[0]).collect();
    assert_eq!(recorded.len(), expected.len());
    let bytes = std::fs::read(&mcap).unwrap();
    let telemetry: Vec<f64> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/controller")
        .map(|m| ControllerTelemetry::decode(&m.data[..]).unwrap().winding_temperature[1])
        .collect();
    assert_eq!(telemetry.len(), expected.len());
    for (k, want) in expected.iter().enumerate() {
        assert!((recorded[k] - want).abs() < 1e-9, "rrd step {k}: {} vs {want}", recorded[k]);
        assert!((telemetry[k] - want).abs() < 1e-9, "mcap step {k}: {} vs {want}", telemetry[k]);
    }
    // RMS over the control steps (the last sample's torque is never applied)
    let summary: serde_json::Value = serde_json::from_str::<serde_json::Value>(&std::fs::read_to_string(&summary_path).unwrap()).unwrap()["summary"].clone();
    for j in 0..6 {
        let u = trace.column(&format!("u{}", j + 1));
        let steps = &u[..u.len() - 1];
        let rms = (steps.iter().map(|x| x * x).sum::<f64>() / steps.len() as f64).sqrt();
        assert!((summary["rms_torque"][j].as_f64().unwrap() - rms).abs() < 1e-9 * rms.max(1.0), "J{} RMS", j + 1);
    }
    let peak = summary["winding"][1]["peak_temperature"].as_f64().unwrap();
    assert_eq!(peak, expected.iter().copied().fold(f64::MIN, f64::max));
}

/// A catalogue entry with part of a thermal model is refused with one line naming the file, the
/// motor and the missing field.
#[test]
fn a_partial_thermal_model_is_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("mine.toml"), "[hot]\nkind = \"dc\"\nstall_torque = 0.2\nno_load_speed = 400\nrotor_inertia = 1e-6\ntorque_constant = 0.05\nterminal_resistance = 2\nthermal_resistance_winding_housing = 3\nthermal_resistance_housing_ambient = 5\nthermal_time_constant_winding = 10\nmax_winding_temperature = 125\n").unwrap();
    std::fs::write(dir.path().join("motors.toml"), "catalogue = \"mine.toml\"\n[joints.J2]\nmotor = \"hot\"\ngear_ratio = 50\n").unwrap();
    let (code, out) = run(&["run", "--quiet", "--urdf", box_urdf().to_str().unwrap(), "--motors", dir.path().join("motors.toml").to_str().unwrap(), "--duration", "0.1", "--no-rrd", "--no-mcap"]);
    assert_ne!(code, 0);
    let line = out.lines().find(|l| l.contains("error")).unwrap_or_else(|| panic!("{out}"));
    assert!(line.contains("mine.toml") && line.contains("motor 'hot'") && line.contains("'thermal_time_constant_motor' is missing"), "{line}");
    assert!(!out.contains("panicked"));
}

/// The run's summary gives each motor's duty against its catalogue ratings: the RMS of u/N against
/// the continuous rating (the STS3215-C018's 0.98 N·m), the cubic mean of |u| against the gearbox's
/// rated average torque (the NPS015's 21 N·m at 5:1). Held still (`--static`) u is constant, so the
/// cubic mean equals the RMS to rounding; in a wave it lies between the RMS and the peak (power means).
#[test]
fn the_summary_rates_each_drive_against_its_continuous_and_average_ratings() {
    let dir = tempfile::tempdir().unwrap();
    let motors = dir.path().join("duty.toml");
    std::fs::write(&motors, "in_urdf = true\n[joints.J2]\nmotor = \"17HS19-2004S1\"\nreduction = \"NPS015\"\ngear_ratio = 5\n[joints.J5]\nmotor = \"STS3215-C018\"\n").unwrap();
    let urdf = box_urdf();
    for (label, motion) in [("static", vec!["--static"]), ("wave", vec![])] {
        let summary_path = dir.path().join(format!("{label}.json"));
        let args: Vec<&str> = ["run", "--quiet", "--urdf", urdf.to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--drive", "pd", "--duration", "5", "--no-rrd", "--no-mcap", "--summary-json", summary_path.to_str().unwrap()].into_iter().chain(motion).collect();
        let (code, out) = run(&args);
        assert_eq!(code, 0, "{out}");
        let root: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&summary_path).unwrap()).unwrap();
        let s = &root["summary"];
        let duty = &s["drive_duty"];
        assert!(duty[0].is_null() && duty[2].is_null(), "joints without a motor have none");
        let (j2, j5) = (&duty[1], &duty[4]);
        assert_eq!((j2["rated_average_torque"].as_f64(), j2["continuous_torque"].as_f64()), (Some(21.0), None));
        assert_eq!((j5["continuous_torque"].as_f64(), j5["rated_average_torque"].as_f64()), (Some(0.98), None));
        let rms = s["rms_torque"][1].as_f64().unwrap();
        assert!((j2["rms_motor_torque"].as_f64().unwrap() - rms / 5.0).abs() < 1e-12, "u/N at the motor's shaft");
        let (cubic, peak) = (j2["cubic_mean_torque"].as_f64().unwrap(), s["peak_abs_torque"][1].as_f64().unwrap());
        assert!(cubic >= rms - 1e-12 && cubic <= peak + 1e-12, "{label}: rms {rms} ≤ cubic {cubic} ≤ peak {peak}");
        if label == "static" {
            assert!((cubic / rms - 1.0).abs() < 1e-3, "held still: cubic mean {cubic} = RMS {rms}");
        }
    }
}

/// An open-loop stepper's driver sets its current whatever the load: a stepper with thermal data (a
/// user's catalogue; none is published for the built-in ones) heats the same on the loaded shoulder
/// (J2) as on the unloaded wrist roll (J6), and settles at the closed form with I the set current:
/// T_amb + (R_th1 + R_th2)·I²·R(T), R per phase (the two microstepping phases' currents square to I²).
#[test]
fn a_stepper_heats_by_its_set_current_whatever_the_load() {
    let dir = tempfile::tempdir().unwrap();
    let data = ThermalData { winding_to_housing: 2.0, housing_to_ambient: 6.0, winding_time_constant: 3.0, motor_time_constant: 20.0, resistance_25: 1.5, max_winding_temperature: 130.0 };
    std::fs::write(
        dir.path().join("mine.toml"),
        format!(
            "[hot_stepper]\nkind = \"stepper\"\nholding_torque = 0.4\nrotor_inertia = 5.4e-6\nstep_angle = 1.8\ncurrent = 1.7\ninductance = 2.8e-3\nsupply_voltage = 24\nterminal_resistance = {}\nthermal_resistance_winding_housing = {}\nthermal_resistance_housing_ambient = {}\nthermal_time_constant_winding = {}\nthermal_time_constant_motor = {}\nmax_winding_temperature = {}\n",
            data.resistance_25, data.winding_to_housing, data.housing_to_ambient, data.winding_time_constant, data.motor_time_constant, data.max_winding_temperature
        ),
    )
    .unwrap();
    let motors = dir.path().join("motors.toml");
    std::fs::write(&motors, "catalogue = \"mine.toml\"\nin_urdf = true\n[joints.J2]\nmotor = \"hot_stepper\"\ngear_ratio = 50\n[joints.J6]\nmotor = \"hot_stepper\"\ngear_ratio = 5\n").unwrap();
    let summary_path = dir.path().join("s.json");
    let (code, out) = run(&["run", "--quiet", "--urdf", box_urdf().to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--drive", "pd", "--static", "--duration", "600", "--no-rrd", "--no-mcap", "--summary-json", summary_path.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}");
    let root: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&summary_path).unwrap()).unwrap();
    let w = &root["summary"]["winding"];
    let (j2, j6) = (w[1]["peak_temperature"].as_f64().unwrap(), w[5]["peak_temperature"].as_f64().unwrap());
    assert_eq!(j2, j6, "the same set current, the same heat, loaded or not");
    let steady = data.steady_winding_temperature(1.7, AMBIENT_TEMPERATURE).unwrap();
    // 600 s is 30 motor time constants (the coupled nodes and R(T) slow the rise beyond τ_s)
    assert!((j2 - steady).abs() < 0.01, "{j2} vs the closed form {steady}");
}
