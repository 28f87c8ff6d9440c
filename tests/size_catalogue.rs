//! `armscope size` over the catalogue's real reductions (issue 21 items 1 and 4): each motor with no
//! reduction or with a catalogue reduction that fits it, at the ratios it comes in; the reduction's
//! input speed and rated average (cubic-mean) torque checked beside its repeated peak.

mod common;

use serde_json::Value;
use std::path::Path;

fn size(dir: &Path, label: &str, args: &[&str]) -> Value {
    let out = dir.join(label);
    let all: Vec<String> = ["armscope", "size"].iter().chain(args).chain(&["--out", out.to_str().unwrap()]).map(|s| s.to_string()).collect();
    assert_eq!(armscope::cli::main_with_args(all), 0, "size finds a verified set");
    serde_json::from_str(&std::fs::read_to_string(out.join("size.json")).unwrap()).unwrap()
}

/// Sizing the box model's wave over the built-in catalogue: every candidate is a motor alone (ratio
/// 1) or a motor with a catalogue reduction at one of its own ratios that fits it (a bus servo only
/// with a belt, a NEMA17 gearbox only on a NEMA17); the chosen set's motor file names the reductions
/// and runs as sized.
#[test]
fn size_chooses_real_reductions_at_their_own_ratios() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = common::box_urdf();
    let report = size(dir.path(), "box", &["--urdf", urdf.to_str().unwrap(), "--duration", "5", "--payload", "0.3"]);
    let catalogue = armscope::actuator::Catalogue::load(&common::repo().join("assets/motors/catalogue.toml")).unwrap();
    let mut reductions_chosen = 0;
    for joint in report["joints"].as_array().unwrap() {
        for c in joint["candidates"].as_array().unwrap() {
            let (motor, ratio) = (c["motor"].as_str().unwrap(), c["ratio"].as_f64().unwrap());
            match c["reduction"].as_str() {
                None => assert_eq!(ratio, 1.0, "{motor}: without a reduction, a direct drive"),
                Some(r) => {
                    let red = catalogue.reduction(r).unwrap();
                    assert!(red.ratios.contains(&ratio), "{motor} + {r} at {ratio}: not one of its ratios {:?}", red.ratios);
                    assert!(catalogue.fits(motor, r), "{motor} + {r}: does not fit");
                    assert!(red.efficiency.is_some(), "{r}: sized without a published efficiency");
                }
            }
        }
        let chosen = &joint["candidates"][joint["chosen"].as_u64().expect("a choice") as usize];
        reductions_chosen += chosen["reduction"].is_string() as usize;
    }
    assert!(reductions_chosen >= 3, "most joints need a reduction");
    let motors = dir.path().join("box/motors.toml");
    let text = std::fs::read_to_string(&motors).unwrap();
    assert!(text.contains("reduction = "), "{text}");
    let model = armscope::model::load_urdf(&urdf).unwrap();
    let set = armscope::actuator::load_motor_file(&motors, &model).unwrap();
    assert!(set.joints.iter().flatten().any(|d| !d.reductions.is_empty()));
}


/// A bare motor (1 N·m, 100 rad/s) with two reductions of the same 10:1: one whose input may turn
/// only 20 rad/s, one whose rated average torque (1 N·m) is below the 1.5 N·m the pendulum holds
/// most of the time while its repeated peak (10 N·m) is not. A ±5° wave at 0.5 rad/s turns the motor
/// at most 10 × 0.087 × 0.5 = 0.44 rad/s; a ±60° wave at 2 rad/s, 10 × 1.05 × 2 = 21 rad/s, beyond
/// the 20 the slow gear's input allows.
fn catalogue() -> String {
    "[bare]\nkind = \"dc\"\nstall_torque = 1.0\nno_load_speed = 100\nmass = 0.1\n\n\
     [slow]\nkind = \"planetary\"\nratios = [10]\nefficiency = 0.9\nmax_input_speed = 20\nmass = 0.1\n\n\
     [weak]\nkind = \"planetary\"\nratios = [10]\nefficiency = 0.9\nrated_torque = 1.0\nrepeated_peak_torque = 10\nmass = 0.2\n\n\
     [strong]\nkind = \"planetary\"\nratios = [10]\nefficiency = 0.9\nrated_torque = 3.0\nrepeated_peak_torque = 10\nmass = 0.3\n"
        .to_string()
}

fn candidate<'a>(report: &'a Value, reduction: &str) -> &'a Value {
    report["joints"][0]["candidates"].as_array().unwrap().iter().find(|c| c["reduction"] == reduction).unwrap_or_else(|| panic!("{reduction} in {report}"))
}

#[test]
fn a_reduction_is_rejected_for_its_input_speed_and_for_its_average_torque() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("pendulum.urdf"), common::LEVEL_PENDULUM).unwrap();
    std::fs::write(dir.path().join("catalogue.toml"), catalogue()).unwrap();
    let (urdf, cat) = (dir.path().join("pendulum.urdf"), dir.path().join("catalogue.toml"));
    let common_args = ["--urdf", urdf.to_str().unwrap(), "--catalogue", cat.to_str().unwrap(), "--candidates", "bare", "--reductions", "slow,weak,strong", "--duration", "10", "--drive", "pd"];
    // slow and small: the light "slow" gear carries it (its input turns well below 20 rad/s), but the
    // pendulum held level most of the time loads "weak" beyond its rated average torque
    let gentle: Vec<&str> = common_args.iter().copied().chain(["--freq", "0.5", "--amp-deg", "5"]).collect();
    let report = size(dir.path(), "gentle", &gentle);
    assert!(candidate(&report, "slow")["shortfall"].is_null(), "{}", candidate(&report, "slow"));
    let weak = candidate(&report, "weak");
    assert_eq!(weak["shortfall"]["reason"], "gearbox_average", "{weak}");
    let need = weak["shortfall"]["need"].as_f64().unwrap();
    // the cubic mean of |τ| over a ±5° swing about level: within 1 % of 1.5 N·m, times the 1.3 margin
    assert!((need / 1.3 - 1.5).abs() < 0.02, "cubic mean {need} / 1.3");
    assert!(candidate(&report, "strong")["shortfall"].is_null());
    // fast and wide: the motor turns at least 10 × 60° × π/180 × 2 ≈ 21 rad/s, × 1.3 with the margin
    let fast: Vec<&str> = common_args.iter().copied().chain(["--freq", "2", "--amp-deg", "60"]).collect();
    let out = dir.path().join("fast");
    let all: Vec<String> = ["armscope", "size"].iter().chain(&fast).chain(&["--out", out.to_str().unwrap()]).map(|s| s.to_string()).collect();
    armscope::cli::main_with_args(all);
    let report: Value = serde_json::from_str(&std::fs::read_to_string(out.join("size.json")).unwrap()).unwrap();
    let slow = candidate(&report, "slow");
    assert_eq!(slow["shortfall"]["reason"], "input_speed", "{slow}");
    let (speed, limit) = (slow["shortfall"]["motor_speed"].as_f64().unwrap(), slow["shortfall"]["limit"].as_f64().unwrap());
    assert_eq!(limit, 20.0);
    // the joint's top speed is the wave's A·ω, or more where the quarter-period ramp into it blends
    let joint_speed = speed / (1.3 * 10.0);
    let wave_speed = 60f64.to_radians() * 2.0;
    assert!(joint_speed >= wave_speed - 1e-3 && joint_speed < 1.5 * wave_speed, "top motor speed with the margin: {speed}");
}

/// `--stages 2`: beside one reduction, every reduction followed by a belt; each such candidate's
/// first stage fits the motor, its second is a belt, its ratio is the product; the motor file of the
/// choice lists the stages and loads.
#[test]
fn two_stage_trains_are_a_reduction_then_a_belt() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = common::box_urdf();
    let report = size(dir.path(), "two", &["--urdf", urdf.to_str().unwrap(), "--duration", "5", "--candidates", "17HS4401,17HS08-1004S", "--stages", "2", "--parts-in-urdf"]);
    let catalogue = armscope::actuator::Catalogue::load(&common::repo().join("assets/motors/catalogue.toml")).unwrap();
    let mut two = 0;
    for joint in report["joints"].as_array().unwrap() {
        for c in joint["candidates"].as_array().unwrap() {
            let Some(stages) = c["stages"].as_array().filter(|s| s.len() == 2) else { continue };
            two += 1;
            let (first, belt) = (stages[0][0].as_str().unwrap(), stages[1][0].as_str().unwrap());
            assert!(catalogue.fits(c["motor"].as_str().unwrap(), first) && catalogue.reduction(belt).unwrap().kind == "belt");
            let product = stages[0][1].as_f64().unwrap() * stages[1][1].as_f64().unwrap();
            assert!((c["ratio"].as_f64().unwrap() - product).abs() < 1e-9 * product);
        }
    }
    assert!(two > 100, "{two} two-stage candidates");
    let model = armscope::model::load_urdf(&urdf).unwrap();
    armscope::actuator::load_motor_file(&dir.path().join("two/motors.toml"), &model).unwrap();
}
