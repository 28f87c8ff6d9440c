//! What `armscope size` reports beside its choice (issue 21 items 4 and 5): the vendors' margin per
//! motor kind, the load-to-rotor inertia ratio with a notice above the guideline, the feasible drive
//! with the lowest RMS motor torque, and a bill of materials.

mod common;

use serde_json::Value;
use std::path::Path;


fn size(dir: &Path, label: &str, extra: &[&str]) -> (Value, String) {
    std::fs::write(dir.join("pendulum.urdf"), common::LEVEL_PENDULUM).unwrap();
    let out = dir.join(label);
    let args: Vec<String> = ["armscope", "size", "--urdf", dir.join("pendulum.urdf").to_str().unwrap(), "--freq", "1", "--amp-deg", "20", "--duration", "10", "--parts-in-urdf", "--out", out.to_str().unwrap()]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .collect();
    assert_eq!(armscope::cli::main_with_args(args), 0);
    (serde_json::from_str(&std::fs::read_to_string(out.join("size.json")).unwrap()).unwrap(), std::fs::read_to_string(out.join("size.md")).unwrap())
}

/// Without `--margin` an open-loop stepper is rated with 50 % and a servo with 30 % (the vendors');
/// `--drive pd` closes the stepper's loop (30 %); `--margin` sets one for all.
#[test]
fn the_margin_is_the_vendors_for_each_motor_kind_unless_given() {
    let dir = tempfile::tempdir().unwrap();
    let margins = |report: &Value| -> Vec<(String, f64)> {
        report["joints"][0]["candidates"].as_array().unwrap().iter().map(|c| (c["motor"].as_str().unwrap().to_string(), c["margin"].as_f64().unwrap())).collect()
    };
    let candidates = ["--candidates", "17HS4401,XM430-W350", "--reductions", "GT2-belt"];
    let (open, md) = size(dir.path(), "open", &candidates);
    assert!(margins(&open).iter().all(|(m, x)| *x == if m == "17HS4401" { 0.5 } else { 0.3 }), "{:?}", margins(&open));
    assert!(md.contains("stepper 50 %") && md.contains("servo 30 %"), "the report states them");
    let (closed, _) = size(dir.path(), "closed", &[&candidates[..], &["--drive", "pd"]].concat());
    assert!(margins(&closed).iter().all(|(_, x)| *x == 0.3));
    let (given, _) = size(dir.path(), "given", &[&candidates[..], &["--margin", "0.2"]].concat());
    assert!(margins(&given).iter().all(|(_, x)| *x == 0.2));
}

/// The inertia ratio is the load's M_jj over the rotor's J·N² (the reductions' input inertia with
/// it): for the pendulum, (1e-4 + 0.153²)/((5.4e-6 + 1.19e-5)·51²) on a 17HS4401 + DYD-14-051. The
/// chosen drive's ratio above 10:1 (an open-loop NEMA17) gets a notice; the lowest-RMS feasible drive
/// of the chosen motor has no feasible sibling with less RMS torque; the bill of materials lists
/// each joint's parts and their total.
#[test]
fn inertia_ratio_lowest_rms_and_the_bill_of_materials() {
    let dir = tempfile::tempdir().unwrap();
    let (report, md) = size(dir.path(), "bom", &["--candidates", "17HS4401", "--reductions", "DYD-14-051,NEMA17-PG27,GT2-belt,CricketDrive-MK2"]);
    let joint = &report["joints"][0];
    let load = 1e-4 + 0.153f64.powi(2);
    let dyd = joint["candidates"].as_array().unwrap().iter().find(|c| c["reduction"] == "DYD-14-051").unwrap();
    let expected = load / ((5.4e-6 + 1.19e-5) * 51.0 * 51.0);
    assert!((dyd["inertia_ratio"].as_f64().unwrap() / expected - 1.0).abs() < 1e-6, "{} vs {expected}", dyd["inertia_ratio"]);
    let chosen = &joint["candidates"][joint["chosen"].as_u64().unwrap() as usize];
    let ratio = chosen["inertia_ratio"].as_f64().unwrap();
    assert_eq!(joint["inertia_ratio_above"].is_null(), ratio <= 10.0, "a notice exactly above the guideline ({ratio})");
    if ratio > 10.0 {
        assert!(md.contains("above the 10:1 guideline for an open-loop NEMA17–34 stepper"));
    }
    let lowest = joint["lowest_rms"].as_u64().unwrap() as usize;
    let rms = |c: &Value| c["rms_motor_torque"].as_f64().unwrap();
    let feasible: Vec<&Value> = joint["ranked"].as_array().unwrap().iter().map(|i| &joint["candidates"][i.as_u64().unwrap() as usize]).collect();
    assert!(feasible.iter().all(|c| rms(c) >= rms(&joint["candidates"][lowest])));
    let bom = &md[md.find("## Bill of materials").expect("a bill of materials")..];
    assert!(bom.contains("| lift | 17HS4401 |") && bom.contains("To order: 1 × 17HS4401"), "{bom}");
    let mass = chosen["mass_kg"].as_f64().unwrap();
    assert!((report["drive_mass_kg"].as_f64().unwrap() - mass).abs() < 1e-12 && bom.contains(&format!("{mass:.3} kg in all")));
}

/// A simulated candidate's lost steps are counted, and reported, only where the joint was driven
/// open loop as a stepper: a servo, or a stepper under PD (`--drive pd`), cannot lose steps, and the
/// report no longer says of each that it lost none.
#[test]
fn lost_steps_are_reported_only_for_a_stepper_driven_open_loop() {
    let dir = tempfile::tempdir().unwrap();
    let stepped = |report: &Value| -> Vec<bool> { report["joints"][0]["simulated"].as_array().unwrap().iter().map(|s| s["stepped"].as_bool().unwrap()).collect() };
    for (label, extra, open_loop) in [("servo", &["--candidates", "XM430-W350"][..], false), ("stepper", &["--candidates", "17HS4401"][..], true), ("stepper-pd", &["--candidates", "17HS4401", "--drive", "pd"][..], false)] {
        let (report, md) = size(dir.path(), label, &[extra, &["--reductions", "DYD-14-051,NEMA17-PG27,GT2-belt,CricketDrive-MK2"]].concat());
        let flags = stepped(&report);
        assert!(!flags.is_empty() && flags.iter().all(|&s| s == open_loop), "{label}: {flags:?}");
        assert_eq!(md.contains("0 lost steps"), open_loop, "{label}: {md}");
        assert!(md.contains("% of its torque"), "{label}: the torque share is reported either way");
    }
}

/// A sizing that finds no drive for a joint fails (non-zero exit) and its report still states the
/// chosen drive trains' mass as 0.000 kg, not "-0.000" (an empty f64 sum is −0).
#[test]
fn a_sizing_with_nothing_chosen_reports_no_negative_mass() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("pendulum.urdf"), common::LEVEL_PENDULUM).unwrap();
    let out = dir.path().join("none");
    let urdf = dir.path().join("pendulum.urdf");
    // a bare 17HS4401 on a belt cannot carry the level pendulum's 1.5 N·m
    let args = ["armscope", "size", "--urdf", urdf.to_str().unwrap(), "--freq", "1", "--amp-deg", "20", "--duration", "10", "--parts-in-urdf", "--out", out.to_str().unwrap(), "--candidates", "17HS4401", "--reductions", "GT2-belt"];
    assert_ne!(armscope::cli::main_with_args(args.iter().map(|s| s.to_string()).collect::<Vec<_>>()), 0);
    let md = std::fs::read_to_string(out.join("size.md")).unwrap();
    assert!(md.contains("the chosen drive trains 0.000 kg") && !md.contains("-0.000"), "{md}");
}
