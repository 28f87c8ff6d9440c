//! `armscope size` carries the parts it chooses (issue 21 item 2): each joint is sized on the arm
//! carrying the drive trains already chosen beyond it, and the choice is the same as sizing the arm
//! whose URDF has those parts in it (`--parts-in-urdf`).

mod common;

use serde_json::Value;
use std::path::Path;

fn size(out: &Path, urdf: &Path, extra: &[&str]) -> Value {
    let args: Vec<String> = ["armscope", "size", "--urdf", urdf.to_str().unwrap(), "--out", out.to_str().unwrap()].iter().chain(extra).map(|s| s.to_string()).collect();
    assert_eq!(armscope::cli::main_with_args(args), 0, "a verified set");
    serde_json::from_str(&std::fs::read_to_string(out.join("size.json")).unwrap()).unwrap()
}

fn chosen(report: &Value, j: usize) -> &Value {
    let joint = &report["joints"][j];
    &joint["candidates"][joint["chosen"].as_u64().expect("a choice") as usize]
}

/// The SmallRobotArm mesh model, its default wave, from the whole catalogue: with the
/// parts carried the shoulder (J2) needs more than without — its chosen drive has less torque to
/// spare on the same motion — and the report's arm weighs its URDF plus the chosen parts. Writing
/// the chosen parts into the URDF (`model --motors --urdf-out`) and sizing that with
/// `--parts-in-urdf` chooses the same drive for every joint.
#[test]
fn the_shoulder_carries_the_parts_beyond_it_and_the_choice_is_the_urdfs() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = common::repo().join("assets/smallrobotarm/smallrobotarm.urdf");
    let carried = size(&dir.path().join("carried"), &urdf, &[]);
    let bare = size(&dir.path().join("bare"), &urdf, &["--parts-in-urdf"]);
    // the same candidate on both sides: the one chosen with the parts carried
    let c = chosen(&carried, 1);
    let same = bare["joints"][1]["candidates"].as_array().unwrap().iter().find(|x| x["motor"] == c["motor"] && x["reduction"] == c["reduction"] && x["ratio"] == c["ratio"]).unwrap();
    let (with, without) = (c["torque_headroom"].as_f64().unwrap(), same["torque_headroom"].as_f64().unwrap());
    assert!(with < without, "J2 needs more with the parts carried: {with} vs {without} to spare");
    let drive_mass = carried["drive_mass_kg"].as_f64().unwrap();
    assert!(drive_mass > 0.0 && (carried["arm_mass_kg"].as_f64().unwrap() - 2.27).abs() < 0.01);

    let motors = dir.path().join("carried/motors.toml");
    let with_parts = dir.path().join("with_parts.urdf");
    let code = armscope::cli::main_with_args(["armscope", "model", "--urdf", urdf.to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--urdf-out", with_parts.to_str().unwrap()]);
    assert_eq!(code, 0);
    let again = size(&dir.path().join("again"), &with_parts, &["--parts-in-urdf"]);
    for j in 0..5 {
        let (a, b) = (chosen(&carried, j), chosen(&again, j));
        assert_eq!((&a["motor"], &a["reduction"], &a["ratio"]), (&b["motor"], &b["reduction"], &b["ratio"]), "J{}", j + 1);
    }
}
