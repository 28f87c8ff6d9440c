//! `armscope size`: the chosen motors carry the motion in a full stepper-mode run, the nearest one
//! it rejected does not; and the choice is monotone in payload and in speed.

mod common;

use armscope::config::RunConfig;
use armscope::experiment::Experiment;
use armscope::sim::simulate;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The steppers of the built-in catalogue (the SmallRobotArm runs open-loop steppers).
const STEPPERS: &str = "17HS4401,17HS19-2004S1,23HS22-2804S";
const MARGIN: f64 = 0.3;

/// Run `armscope size` on the box model; returns its report (size.json) and the motor file.
fn size(dir: &Path, freq: f64, payload: f64) -> (Value, PathBuf) {
    size_with(dir, &format!("size_f{freq}_p{payload}"), &["--freq", &freq.to_string(), "--payload", &payload.to_string()])
}

/// `armscope size` on the box model with the steppers and the margin, and the motion of `motion`.
fn size_with(dir: &Path, label: &str, motion: &[&str]) -> (Value, PathBuf) {
    let out = dir.join(label);
    let motors = out.join("chosen.toml");
    let args: Vec<String> = ["armscope", "size", "--urdf", common::box_urdf().to_str().unwrap()]
        .iter()
        .chain(motion)
        // the box model's link masses hold its motors (as assets/motors/tutorial.toml says): not carried again
        .chain(&["--candidates", STEPPERS, "--ratios", "1-50", "--parts-in-urdf", "--margin", &MARGIN.to_string(), "--out", out.to_str().unwrap(), "--motors-out", motors.to_str().unwrap()])
        .map(|s| s.to_string())
        .collect();
    assert_eq!(armscope::cli::main_with_args(args), 0, "size must find a verified set");
    let report: Value = serde_json::from_str(&std::fs::read_to_string(out.join("size.json")).unwrap()).unwrap();
    for j in 1..=6 {
        assert!(out.join(format!("size_J{j}.png")).exists(), "the chart of J{j}");
    }
    assert!(out.join("size.rrd").exists() && out.join("size.md").exists());
    (report, motors)
}

/// The box model run in stepper mode with a motor file, the motion and payload of the sizing.
fn run(motors: &Path, freq: f64, payload: f64) -> armscope::summary::Summary {
    let config = RunConfig { urdf: common::box_urdf(), motors: Some(motors.to_path_buf()), freq, payload, ..RunConfig::default() };
    let experiment = Experiment::prepare(config).unwrap();
    assert!(experiment.stepper_mode());
    simulate(&experiment, &mut [], None).unwrap()
}

fn chosen(joint: &Value) -> &Value {
    &joint["candidates"][joint["chosen"].as_u64().expect("a choice") as usize]
}

/// The bar: the tutorial's wave at ω = 1.2 rad/s with 0.5 kg at the tool. The recommended file,
/// run with `run --motors` (stepper mode), loses no step on any joint and stays within the margin
/// (every joint uses at most 1/(1 + m) of the torque its motor gives at its speed, from the settle
/// time on). For every joint, the next smaller ratio of the chosen motor — the nearest candidate
/// rejected below — run the same way, loses steps or uses more than the margin allows on that joint.
#[test]
fn the_recommended_set_carries_the_motion_and_the_next_smaller_ratio_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let (freq, payload) = (1.2, 0.5);
    let (report, motors) = size(dir.path(), freq, payload);
    assert_eq!(report["verified"], Value::Bool(true));
    let summary = run(&motors, freq, payload);
    let allowed = 1.0 / (1.0 + MARGIN);
    for j in 0..6 {
        assert_eq!(summary.lost_steps[j], 0, "J{}: lost steps with the chosen motors", j + 1);
        assert!(summary.peak_torque_share[j] <= allowed, "J{}: used {:.3} of its torque, the margin allows {allowed:.3}", j + 1, summary.peak_torque_share[j]);
    }
    let text = std::fs::read_to_string(&motors).unwrap();
    let file: toml::Table = text.parse().unwrap();
    let mut checked = 0;
    for (j, joint) in report["joints"].as_array().unwrap().iter().enumerate() {
        let best = chosen(joint);
        let ratio = best["ratio"].as_f64().unwrap();
        if ratio <= 1.0 {
            continue; // a direct drive: no smaller ratio to try
        }
        // the next smaller ratio of the same motor was rejected (the ranking takes the smallest that fits)
        let below = joint["candidates"].as_array().unwrap().iter().find(|c| c["motor"] == best["motor"] && c["ratio"].as_f64() == Some(ratio - 1.0)).unwrap();
        assert!(below["share"].as_f64().unwrap() > 1.0 || joint["simulated"].as_array().unwrap().iter().any(|s| s["passed"] == Value::Bool(false)), "J{}: {ratio} − 1 fits yet was not chosen", j + 1);
        let name = joint["joint"].as_str().unwrap();
        let mut smaller = file.clone();
        smaller["joints"][name]["gear_ratio"] = toml::Value::Float(ratio - 1.0);
        let path = dir.path().join(format!("smaller_{name}.toml"));
        std::fs::write(&path, toml::to_string(&smaller).unwrap()).unwrap();
        let s = run(&path, freq, payload);
        assert!(
            s.lost_steps[j] > 0 || s.peak_torque_share[j] > allowed,
            "J{} at {}:1 (one below the choice) neither lost steps nor exceeded the margin: {:.3} used",
            j + 1,
            ratio - 1.0,
            s.peak_torque_share[j]
        );
        checked += 1;
    }
    assert!(checked >= 4, "most joints need a reduction: {checked} checked");
}

/// A motor "strength" to compare choices: the motor's mass (what is bought), then the torque the
/// joint gets at rest (the ratio).
fn strength(joint: &Value) -> (f64, f64) {
    let c = chosen(joint);
    (c["mass_kg"].as_f64().unwrap(), c["torque_at_rest"].as_f64().unwrap())
}

/// A heavier payload never gets a weaker recommendation on any joint, and a slower wave never a
/// stronger one (the lightest motor, then the smallest ratio that keeps the margin: both only grow
/// with what the motion needs).
#[test]
fn the_recommendation_is_monotone_in_payload_and_in_speed() {
    let dir = tempfile::tempdir().unwrap();
    let by_payload: Vec<Value> = [0.0, 0.5, 1.0].iter().map(|&p| size(dir.path(), 1.2, p).0).collect();
    let by_speed: Vec<Value> = [0.3, 0.6, 1.2].iter().map(|&f| size(dir.path(), f, 0.5).0).collect();
    for j in 0..6 {
        let p: Vec<(f64, f64)> = by_payload.iter().map(|r| strength(&r["joints"][j])).collect();
        assert!(p.windows(2).all(|w| w[1] >= w[0]), "J{}: heavier payload, weaker choice: {p:?}", j + 1);
        let s: Vec<(f64, f64)> = by_speed.iter().map(|r| strength(&r["joints"][j])).collect();
        assert!(s.windows(2).all(|w| w[1] >= w[0]), "J{}: slower wave, stronger choice: {s:?}", j + 1);
    }
    // and it does respond: the heaviest payload needs more than none on the shoulder
    assert!(strength(&by_payload[2]["joints"][1]) > strength(&by_payload[0]["joints"][1]));
}

/// `--trajectory`: a joint schedule that samples the wave every millisecond (followed by cubic Hermite
/// interpolation) is the same motion, and gets the same motors: per joint the same motor, and the
/// same ratio or one next to it (the schedule's acceleration is the interpolation's, piecewise linear,
/// within 1e-4 of the wave's at 1 ms).
#[test]
fn a_schedule_sampling_the_wave_is_sized_as_the_wave() {
    let dir = tempfile::tempdir().unwrap();
    let (freq, payload, duration) = (1.2, 0.5, 10.0);
    let wave = Experiment::prepare(RunConfig { urdf: common::box_urdf(), freq, duration, ..RunConfig::default() }).unwrap();
    let mut csv = String::from("t,q1,q2,q3,q4,q5,q6\n");
    let (mut q, mut qd) = (vec![0.0; 6], vec![0.0; 6]);
    for k in 0..=(duration * 1000.0) as usize {
        let t = k as f64 * 1e-3;
        wave.trajectory.sample(t, &mut q, &mut qd);
        csv += &format!("{t},{}\n", q.iter().map(|x| format!("{x:e}")).collect::<Vec<_>>().join(","));
    }
    let schedule = dir.path().join("wave.csv");
    std::fs::write(&schedule, csv).unwrap();
    let (d, p) = (duration.to_string(), payload.to_string());
    let (by_wave, _) = size_with(dir.path(), "wave", &["--freq", &freq.to_string(), "--payload", &p, "--duration", &d]);
    let (by_schedule, motors) = size_with(dir.path(), "schedule", &["--trajectory", schedule.to_str().unwrap(), "--payload", &p, "--duration", &d]);
    assert_eq!(by_schedule["verified"], Value::Bool(true));
    for j in 0..6 {
        let (a, b) = (chosen(&by_wave["joints"][j]), chosen(&by_schedule["joints"][j]));
        assert_eq!(a["motor"], b["motor"], "J{}", j + 1);
        let (ra, rb) = (a["ratio"].as_f64().unwrap(), b["ratio"].as_f64().unwrap());
        assert!((ra - rb).abs() <= 1.0, "J{}: {ra}:1 for the wave, {rb}:1 for its schedule", j + 1);
    }
    // and the file it wrote carries the schedule in a full run
    let config = RunConfig { urdf: common::box_urdf(), motors: Some(motors), trajectory: Some(schedule), duration, payload, ..RunConfig::default() };
    let summary = simulate(&Experiment::prepare(config).unwrap(), &mut [], None).unwrap();
    assert_eq!(summary.lost_steps, [0; 6]);
}

/// `--manifest`: every experiment must pass. A slow wave with a heavy tool and a fast wave with none
/// ask different joints for different things; the set sized for both is on every joint at least as
/// strong as the set sized for either alone, and carries each of them in a full run (no lost steps,
/// within the margin); a rejection names the experiment where it fell short.
#[test]
fn a_manifest_is_sized_for_every_experiment_in_it() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = dir.path().join("both.toml");
    std::fs::write(&manifest, "name = \"both\"\n\n[[experiment]]\nname = \"slow-heavy\"\nfreq = 0.3\npayload = 1.0\nduration = 10\n\n[[experiment]]\nname = \"fast\"\nfreq = 1.2\nduration = 10\n").unwrap();
    let (slow, _) = size_with(dir.path(), "slow", &["--freq", "0.3", "--payload", "1.0", "--duration", "10"]);
    let (fast, _) = size_with(dir.path(), "fast", &["--freq", "1.2", "--duration", "10"]);
    let (both, motors) = size_with(dir.path(), "both", &["--manifest", manifest.to_str().unwrap()]);
    assert_eq!(both["verified"], Value::Bool(true));
    for j in 0..6 {
        let (s, f, b) = (strength(&slow["joints"][j]), strength(&fast["joints"][j]), strength(&both["joints"][j]));
        assert!(b >= s && b >= f, "J{}: both {b:?}, slow-heavy alone {s:?}, fast alone {f:?}", j + 1);
    }
    let allowed = 1.0 / (1.0 + MARGIN);
    for (freq, payload) in [(0.3, 1.0), (1.2, 0.0)] {
        let config = RunConfig { urdf: common::box_urdf(), motors: Some(motors.clone()), freq, payload, duration: 10.0, ..RunConfig::default() };
        let summary = simulate(&Experiment::prepare(config).unwrap(), &mut [], None).unwrap();
        for j in 0..6 {
            assert_eq!(summary.lost_steps[j], 0, "J{} at ω = {freq}", j + 1);
            assert!(summary.peak_torque_share[j] <= allowed, "J{} at ω = {freq}: {:.3}", j + 1, summary.peak_torque_share[j]);
        }
    }
    let md = std::fs::read_to_string(dir.path().join("both/size.md")).unwrap();
    assert!(md.contains("slow-heavy") && md.contains("fast"), "the report names the experiments");
    assert!(md.contains(" of 'slow-heavy'") || md.contains(" of 'fast'"), "a rejection says in which experiment it fell short:\n{md}");
}

/// Ratio specs: ranges, steps, lists and per-joint overrides; bad ones name the flag.
#[test]
fn ratio_specs_parse_and_bad_ones_name_the_flag() {
    let joints: Vec<String> = ["J1", "J2"].iter().map(|s| s.to_string()).collect();
    let r = armscope::cli::parse_ratios(&["1-3".into(), "J2=5,10-11:0.5".into()], &joints).unwrap();
    assert_eq!(r[0], vec![1.0, 2.0, 3.0]);
    assert_eq!(r[1], vec![5.0, 10.0, 10.5, 11.0]);
    for bad in ["0.5-3", "5-2", "J9=1-2", "x"] {
        let e = armscope::cli::parse_ratios(&[bad.into()], &joints).unwrap_err().to_string();
        assert!(e.contains("--ratios"), "{bad}: {e}");
    }
}
