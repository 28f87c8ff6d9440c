//! `armscope size --from DATASET`: the drives for every recorded episode at once. A LeRobot dataset of
//! two known SO-101 motions (written here as LeRobot writes them, read through the built-in SO-101
//! map) is sized as the envelope of its episodes: at least what either episode gets alone, verified by
//! simulating the arm along each episode's smoothed motion.

mod common;

use common::lerobot::{Sines, Spec, Storage};
use serde_json::Value;
use std::path::{Path, PathBuf};

// one servo at ideal ratios: the choice is the smallest ratio that carries the motion with the margin
const CANDIDATES: &str = "STS3215-C001";

fn so101() -> PathBuf {
    common::repo().join("tests/fixtures/robots/so101.urdf")
}

/// A gentle motion (episode 0) and a larger, faster one (episode 1) of every joint, 6 s at 30 fps,
/// stored as LeRobot's so101_new_calib stores them (degrees, the gripper 0–100 over its range).
fn dataset(root: &Path) -> Spec {
    let model = armscope::model::load_urdf(&so101()).unwrap();
    let gripper = &model.joints[model.joint_index("gripper").unwrap()];
    let motion = |scale: f64, speed: f64| -> Vec<Sines> {
        let s = |center: f64, a: f64, w: f64| Sines { center, terms: vec![(a * scale, w * speed, 0.3)] };
        vec![s(0.0, 0.4, 1.0), s(0.2, 0.3, 0.8), s(-0.3, 0.3, 1.1), s(0.0, 0.3, 1.3), s(0.0, 0.5, 0.9), s(0.8, 0.3, 1.0)]
    };
    let mut storage: Vec<Storage> = (0..5).map(|_| Storage::Degrees { sign: 1.0, offset: 0.0 }).collect();
    storage.push(Storage::Range0To100 { lower: gripper.lower, upper: gripper.upper });
    let spec = Spec { fps: 30.0, frames: 6 * 30 + 1, episodes: vec![motion(1.0, 1.0), motion(1.5, 1.9)], storage, observed: None };
    spec.write_v3(root);
    spec
}

/// Run `armscope size --from` on the dataset (with `extra` flags); its report (size.json).
fn size_from(dataset: &Path, out: &Path, extra: &[&str]) -> Value {
    let args: Vec<String> = ["armscope", "size", "--urdf", so101().to_str().unwrap(), "--from", dataset.to_str().unwrap()]
        .iter()
        .chain(extra)
        .chain(&["--units", "degrees", "--payload", "0.1", "--parts-in-urdf", "--candidates", CANDIDATES, "--ratios", "1-20", "--efficiency", "0.9", "--out", out.to_str().unwrap()])
        .map(|s| s.to_string())
        .collect();
    assert_eq!(armscope::cli::main_with_args(args), 0, "size --from {extra:?} must find a verified set");
    serde_json::from_str(&std::fs::read_to_string(out.join("size.json")).unwrap()).unwrap()
}

#[test]
fn a_dataset_is_sized_for_the_envelope_of_its_episodes() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("so101_pick");
    let spec = dataset(&root);
    let gentle = size_from(&root, &dir.path().join("gentle"), &["--episode", "0"]);
    let large = size_from(&root, &dir.path().join("large"), &["--episode", "1"]);
    let both = size_from(&root, &dir.path().join("both"), &[]);
    for report in [&gentle, &large, &both] {
        assert_eq!(report["verified"], Value::Bool(true), "the chosen set passes the full run of every episode it was sized for");
    }
    // on paper, every drive's headroom in torque and in speed over the motion is the smaller of the two
    // episodes' (the envelope; the RMS and heat checks are over both in a row, the duty they make)
    let key = |c: &Value| format!("{} {}", c["motor"], c["total_ratio"]);
    let mut compared = 0;
    for j in 0..6 {
        let name = both["joints"][j]["joint"].as_str().unwrap().to_string();
        for field in ["torque_headroom", "speed_headroom"] {
            let headroom_in = |report: &Value| -> std::collections::HashMap<String, f64> {
                report["joints"][j]["candidates"].as_array().unwrap().iter().filter_map(|c| Some((key(c), c[field].as_f64()?))).collect()
            };
            let (g, l) = (headroom_in(&gentle), headroom_in(&large));
            for (drive, headroom) in headroom_in(&both) {
                let (Some(hg), Some(hl)) = (g.get(&drive), l.get(&drive)) else { continue };
                let envelope = hg.min(*hl);
                assert!((headroom - envelope).abs() <= 1e-9 * envelope.max(1.0), "{name} {drive} {field}: {headroom} with both episodes, {hg} and {hl} alone");
                compared += 1;
            }
        }
    }
    assert!(compared >= 2 * 6 * 10, "drives compared: {compared}");
    // the larger, faster episode is the one that binds (else the envelope shows nothing): the direct
    // drive has a fifth less torque to spare in it on some joint
    let direct = |report: &Value, j: usize| report["joints"][j]["candidates"].as_array().unwrap().iter().find(|c| c["total_ratio"] == 1.0).and_then(|c| c["torque_headroom"].as_f64()).unwrap();
    assert!((0..6).any(|j| direct(&large, j) < direct(&gentle, j) / 1.2), "the large episode binds somewhere");
    let motions: Vec<&str> = both["motions"].as_array().unwrap().iter().map(|m| m.as_str().unwrap()).collect();
    assert_eq!(motions, ["episode 0", "episode 1"]);
    // each episode was followed as its smoothed motion, written where the report is
    for (e, motion) in spec.episodes.iter().enumerate() {
        let path = dir.path().join(format!("both/episodes/episode_{e}.csv"));
        let text = std::fs::read_to_string(&path).unwrap_or_else(|_| panic!("{} written", path.display()));
        let rows: Vec<Vec<f64>> = text.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
        assert_eq!(rows.len(), spec.frames, "a row per frame");
        assert_eq!(rows[0][0], 0.0, "time from the episode's first frame");
        // 0.5 s from either end the smoothed angles lie within the encoder's quantum (2π/4096 = 1.5 mrad)
        // of the true motion; the gripper's 0–100 is coarser (its range over 100 steps of float32)
        for row in rows.iter().filter(|r| r[0] >= 0.5 && r[0] <= 5.5) {
            for (j, truth) in motion.iter().take(5).enumerate() {
                let error = (row[1 + j] - truth.q(row[0])).abs();
                assert!(error < 1.5e-3, "episode {e}, joint {j} at t = {}: {error:.2e} rad from the true motion", row[0]);
            }
        }
    }
}

#[test]
fn recorded_motion_flags_need_from_and_bad_episodes_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("so101_pick");
    dataset(&root);
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope")).args(args).current_dir(dir.path()).output().unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let urdf = so101();
    let (code, err) = run(&["size", "--urdf", urdf.to_str().unwrap(), "--episode", "1"]);
    assert_eq!(code, Some(2));
    assert!(err.trim().lines().count() == 1 && err.contains("--episode") && err.contains("--from"), "{err}");
    let (code, err) = run(&["size", "--urdf", urdf.to_str().unwrap(), "--from", root.to_str().unwrap(), "--episode", "7", "--parts-in-urdf"]);
    assert_eq!(code, Some(2));
    let line = err.lines().last().unwrap_or_default();
    assert!(line.contains('7') && line.contains("episode"), "names the missing episode: {err}");
    let (code, err) = run(&["size", "--from", root.to_str().unwrap(), "--trajectory", "x.csv"]);
    assert_eq!(code, Some(2), "--from and --trajectory are two motions: {err}");
}
