//! LeRobot datasets read right (issue 51 items 1–2): the body joints' unit decided from the values
//! where they decide it and asked for in one line where they do not; a calibration file turning a
//! range value into the motor's angle exactly; a real arm's poses a few degrees past its URDF's
//! limits followed to the limit with one notice, and a pose that cannot be the arm's refused.

mod common;

use armscope::model::load_urdf;
use common::lerobot::{Sines, Spec, Storage};
use std::path::{Path, PathBuf};
use std::process::Command;

fn so101() -> PathBuf {
    common::repo().join("tests/fixtures/robots/so101.urdf")
}

fn run(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).args(args).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).to_string(), String::from_utf8_lossy(&out.stderr).to_string())
}

/// Each body joint's calibrated range (ticks): 1400 ticks around 2048, elbow_flex's narrower so that
/// its motion runs into its ends, where LeRobot's range clamps.
const RANGES: [(f64, f64); 5] = [(1348.0, 2748.0), (1348.0, 2748.0), (1598.0, 2498.0), (1348.0, 2748.0), (1348.0, 2748.0)];

fn motions() -> Vec<Sines> {
    let s = |center: f64, a: f64, w: f64| Sines { center, terms: vec![(a, w, 0.0)] };
    vec![s(0.1, 0.6, 1.1), s(0.2, 0.7, 1.6), s(-0.3, 0.9, 1.7), s(0.0, 0.5, 2.1), s(0.0, 0.9, 0.9), s(0.8, 0.6, 1.9)]
}

fn write(dir: &Path, name: &str, body: impl Fn(usize) -> Storage, motion: Vec<Sines>) -> PathBuf {
    write_episodes(dir, name, body, vec![motion])
}

fn write_episodes(dir: &Path, name: &str, body: impl Fn(usize) -> Storage, episodes: Vec<Vec<Sines>>) -> PathBuf {
    let model = load_urdf(&so101()).unwrap();
    let gripper = &model.joints[model.joint_index("gripper").unwrap()];
    let mut storage: Vec<Storage> = (0..5).map(body).collect();
    storage.push(Storage::Range0To100 { lower: gripper.lower, upper: gripper.upper });
    let root = dir.join(name);
    Spec { fps: 30.0, frames: 121, episodes, storage, observed: None }.write_v3(&root);
    root
}

fn calibration(dir: &Path) -> PathBuf {
    let names = ["shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll"];
    let mut records: Vec<String> = names.iter().zip(RANGES).enumerate().map(|(k, (n, (lo, hi)))| format!(r#""{n}": {{"id": {}, "drive_mode": 0, "homing_offset": 0, "range_min": {lo}, "range_max": {hi}}}"#, k + 1)).collect();
    records.push(r#""gripper": {"id": 6, "drive_mode": 0, "homing_offset": 0, "range_min": 2000, "range_max": 3400}"#.into());
    let path = dir.join("so101_follower.json");
    std::fs::write(&path, format!("{{{}}}", records.join(", "))).unwrap();
    path
}

fn trace_q(path: &Path) -> Vec<Vec<f64>> {
    let table = common::read_csv(path);
    table.rows.iter().map(|r| r[1..7].to_vec()).collect()
}

#[test]
fn a_range_dataset_is_read_as_a_range_and_its_calibration_gives_the_motors_angles() {
    let dir = tempfile::tempdir().unwrap();
    let root = write(dir.path(), "range", |j| Storage::RangeM100To100 { range_min: RANGES[j].0, range_max: RANGES[j].1 }, motions());
    let (root_s, urdf) = (root.to_str().unwrap(), so101());
    // no flag: the values at exactly ±100 (elbow_flex held at its calibrated ends) decide it, and
    // each range's width is read from the tick lattice of the values (LeRobot normalises whole ticks)
    let bare = dir.path().join("bare.csv");
    let (code, _, stderr) = run(&["replay", root_s, "--urdf", urdf.to_str().unwrap(), "--trace", bare.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0, "{stderr}");
    let notice = stderr.lines().find(|l| l.contains("the body joints read as LeRobot's RANGE_M100_100")).unwrap_or_else(|| panic!("{stderr}"));
    assert!(notice.contains("exactly at ±100") && notice.contains("tick lattice") && !notice.contains("approximate"), "{notice}");
    assert!(notice.contains("shoulder_pan 1400") && notice.contains("elbow_flex 900"), "{notice}");
    // with the calibration: each value is the motor's angle from its range's middle, the true motion
    // within the tick's quantum (360/4095°, 1.53 mrad) and the smoothing, where no end clamped it
    let cal = calibration(dir.path());
    let trace = dir.path().join("q.csv");
    let (code, _, stderr) = run(&["replay", root_s, "--urdf", urdf.to_str().unwrap(), "--calibration", cal.to_str().unwrap(), "--trace", trace.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains(&format!("angles from the middle of each motor's calibrated range in {}", cal.display())), "{stderr}");
    let q = trace_q(&trace);
    let truth = motions();
    for j in [0, 1, 3, 4] {
        let worst = q.iter().enumerate().map(|(k, row)| (row[j] - truth[j].q(k as f64 / 30.0)).abs()).fold(0.0, f64::max);
        assert!(worst < 2.5e-3, "joint {j}: {worst} rad from the true motion");
    }
    // the lattice's widths are the file's: the same angles to round-off (only hi − lo enters them)
    let from_lattice = trace_q(&bare);
    for (a, b) in from_lattice.iter().zip(&q) {
        for j in 0..5 {
            assert!((a[j] - b[j]).abs() < 1e-9, "{a:?} vs {b:?}");
        }
    }
    // the same calibration named by a joint map: the same angles, the gripper's 0…100 over its
    // limits in both (LeRobot gives it no angle, so its calibrated travel's middle is no URDF zero)
    let map = dir.path().join("map.toml");
    let mut text = format!("calibration = {:?}\n", cal.file_name().unwrap().to_str().unwrap());
    for (joint, unit) in [("shoulder_pan", "range_m100_100"), ("shoulder_lift", "range_m100_100"), ("elbow_flex", "range_m100_100"), ("wrist_flex", "range_m100_100"), ("wrist_roll", "range_m100_100"), ("gripper", "range_0_100")] {
        text += &format!("[joints.{joint}]\ncolumn = \"{joint}.pos\"\nunit = \"{unit}\"\n");
    }
    std::fs::write(&map, text).unwrap();
    let mapped = dir.path().join("mapped.csv");
    let (code, _, stderr) = run(&["replay", root_s, "--urdf", urdf.to_str().unwrap(), "--joint-map", map.to_str().unwrap(), "--trace", mapped.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0, "{stderr}");
    for (a, b) in trace_q(&mapped).iter().zip(&q) {
        for j in 0..6 {
            assert!((a[j] - b[j]).abs() < 1e-12, "{a:?} vs {b:?}");
        }
    }
    // a map holding only the calibration (a path from the map's folder) is the built-in map with it,
    // as --calibration: the unit still decided from the values and said, the same angles to the bit
    let maps = dir.path().join("maps");
    std::fs::create_dir(&maps).unwrap();
    let only = maps.join("calibration_only.toml");
    std::fs::write(&only, format!("calibration = \"../{}\"\n", cal.file_name().unwrap().to_str().unwrap())).unwrap();
    let from_map = dir.path().join("from_map.csv");
    let (code, _, stderr) = run(&["replay", root_s, "--urdf", urdf.to_str().unwrap(), "--joint-map", only.to_str().unwrap(), "--trace", from_map.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("the body joints read as LeRobot's RANGE_M100_100") && stderr.contains("angles from the middle of each motor's calibrated range in"), "{stderr}");
    assert_eq!(trace_q(&from_map), q);
    // it and --calibration both, or a map with neither joints nor a calibration: one line naming it
    let (code, _, stderr) = run(&["replay", root_s, "--urdf", urdf.to_str().unwrap(), "--joint-map", only.to_str().unwrap(), "--calibration", cal.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 2);
    assert!(stderr.trim_end().ends_with("names its calibration file itself (its 'calibration' field)") && stderr.contains("calibration_only.toml"), "{stderr}");
    let empty = maps.join("empty.toml");
    std::fs::write(&empty, "# to fill in\n").unwrap();
    let (code, _, stderr) = run(&["replay", root_s, "--urdf", urdf.to_str().unwrap(), "--joint-map", empty.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("empty.toml: neither [joints.NAME] entries nor a calibration file"), "{stderr}");
    // a joint that barely moves leaves too few values to tell its range: its limits, said approximate
    let mut still = motions();
    still[4] = Sines { center: 0.0, terms: vec![(0.004, 0.9, 0.0)] };
    let root = write(dir.path(), "still", |j| Storage::RangeM100To100 { range_min: RANGES[j].0, range_max: RANGES[j].1 }, still);
    let (code, _, stderr) = run(&["replay", root.to_str().unwrap(), "--urdf", urdf.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("mapped onto the URDF limits of wrist_roll (too few distinct values to tell the range): approximate") && stderr.contains("shoulder_pan 1400"), "{stderr}");
    // a calibration file of other motors: one line naming the file and the motor
    let other = dir.path().join("other.json");
    std::fs::write(&other, r#"{"joint_a": {"id": 1, "drive_mode": 0, "homing_offset": 0, "range_min": 0, "range_max": 4095}}"#).unwrap();
    let (code, _, stderr) = run(&["replay", root_s, "--urdf", urdf.to_str().unwrap(), "--calibration", other.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 2);
    let error: Vec<&str> = stderr.lines().filter(|l| l.starts_with("armscope: error:")).collect();
    assert!(error.len() == 1 && error[0].contains("other.json") && error[0].contains("no motor 'shoulder_pan'"), "{stderr}");
}

#[test]
fn a_dataset_whose_values_cannot_tell_its_unit_is_asked_for_it_in_one_line() {
    // small motions stored in degrees: within ±100, none at ±100 — degrees or a range alike
    let dir = tempfile::tempdir().unwrap();
    let root = write(dir.path(), "small", |_| Storage::Degrees { sign: 1.0, offset: 0.0 }, motions());
    let (root_s, urdf) = (root.to_str().unwrap(), so101());
    let (code, _, stderr) = run(&["replay", root_s, "--urdf", urdf.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 2);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains(root_s) && stderr.contains("cannot be told from the data") && stderr.contains("--units degrees or --units range"), "{stderr}");
    let (code, _, stderr) = run(&["replay", root_s, "--urdf", urdf.to_str().unwrap(), "--units", "degrees", "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0, "{stderr}");
    // a value beyond ±100 decides degrees
    let mut wide = motions();
    wide[0] = Sines { center: 0.5, terms: vec![(1.4, 1.1, 0.0)] };
    let root = write(dir.path(), "wide", |_| Storage::Degrees { sign: 1.0, offset: 0.0 }, wide);
    let (code, _, stderr) = run(&["replay", root.to_str().unwrap(), "--urdf", urdf.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("the body joints read as degrees: shoulder_pan.pos reaches"), "{stderr}");
}

#[test]
fn poses_past_a_urdf_limit_are_followed_to_it_and_impossible_ones_refused() {
    // elbow_flex's URDF limit is ±1.69 rad: a real arm's 3° past it is followed to the limit and
    // said once; 25° past it is no pose of this arm
    let dir = tempfile::tempdir().unwrap();
    let urdf = so101();
    let model = load_urdf(&urdf).unwrap();
    let limit = model.joints[model.joint_index("elbow_flex").unwrap()].upper;
    let mut past = motions();
    past[2] = Sines { center: limit - 0.3, terms: vec![(0.3 + 3f64.to_radians(), 1.0, 0.0)] };
    past[0] = Sines { center: 0.5, terms: vec![(1.4, 1.1, 0.0)] }; // degrees decided
    let root = write(dir.path(), "past", |_| Storage::Degrees { sign: 1.0, offset: 0.0 }, past.clone());
    let trace = dir.path().join("q.csv");
    let (code, _, stderr) = run(&["replay", root.to_str().unwrap(), "--urdf", urdf.to_str().unwrap(), "--trace", trace.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0, "{stderr}");
    let notice = stderr.lines().find(|l| l.contains("past the URDF's limits, followed to the limit")).unwrap_or_else(|| panic!("{stderr}"));
    // 3° at the peak, less the frames' miss of it and the degrees' quantum (0.09°)
    let by: f64 = notice.split("elbow_flex by up to ").nth(1).and_then(|r| r.split('°').next()).and_then(|x| x.parse().ok()).unwrap_or_else(|| panic!("{notice}"));
    assert!((2.8..=3.1).contains(&by) && notice.contains("episode 0"), "{notice}");
    assert!(trace_q(&trace).iter().all(|row| row[2] <= limit + 1e-12));
    // two episodes, 3° and 1° past it: one notice for the recording, its largest excess and where,
    // from either replay (forward: of the commands and the follower alike); the forward replay starts
    let mut less = past.clone();
    less[2].terms[0].0 = 0.3 + 1f64.to_radians();
    let root = write_episodes(dir.path(), "two", |_| Storage::Degrees { sign: 1.0, offset: 0.0 }, vec![less, past.clone()]);
    let motors = common::repo().join("assets/motors/so101.toml");
    for forward in [false, true] {
        let summary = dir.path().join("two.json");
        let mut args = vec!["replay", root.to_str().unwrap(), "--urdf", urdf.to_str().unwrap(), "--no-rrd", "--no-mcap", "--summary-json", summary.to_str().unwrap()];
        if forward {
            args.extend(["--forward", "--motors", motors.to_str().unwrap()]);
        }
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 0, "{stderr}");
        let notices: Vec<&str> = stderr.lines().filter(|l| l.contains("past the URDF's limits")).collect();
        assert_eq!(notices.len(), 1, "{stderr}");
        let by: f64 = notices[0].split("elbow_flex by up to ").nth(1).and_then(|r| r.split('°').next()).and_then(|x| x.parse().ok()).unwrap_or_else(|| panic!("{}", notices[0]));
        assert!(notices[0].contains("in 2 of 2 episodes") && (2.8..=3.1).contains(&by) && notices[0].contains("(episode 1, frame"), "forward {forward}: {}", notices[0]);
        // and each episode's in its JSON: 1° and 3° past, elbow_flex alone
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
        for episode in doc["episodes"].as_array().unwrap() {
            let past = episode["past_limits"].as_array().unwrap();
            let index = if forward { &episode["episode"] } else { &episode["index"] };
            let want = if *index == 0 { 1.0 } else { 3.0 };
            let excess = past[0]["excess"].as_f64().unwrap().to_degrees();
            assert!(past.len() == 1 && past[0]["joint"] == "elbow_flex" && (excess - want).abs() < 0.2, "forward {forward}: {episode}");
        }
    }
    past[2].terms[0].0 = 0.3 + 25f64.to_radians();
    let root = write(dir.path(), "impossible", |_| Storage::Degrees { sign: 1.0, offset: 0.0 }, past);
    let (code, _, stderr) = run(&["replay", root.to_str().unwrap(), "--urdf", urdf.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 2);
    let error: Vec<&str> = stderr.lines().filter(|l| l.starts_with("armscope: error:")).collect();
    assert!(error.len() == 1 && error[0].contains("episode 0: joint 'elbow_flex': frame") && error[0].contains("past its URDF range"), "{stderr}");
}

#[test]
fn a_wrist_roll_recorded_past_its_encoders_wrap_is_read_a_turn_round_and_both_replays_start() {
    // the wrist roll's full-turn encoder reads ±180° in degrees; the URDF spans −157.2°…162.8°: a
    // roll resting at −179° (tick 11) is +181°, 18.2° past the upper limit (as recorded, 21.8° past
    // the lower: more than the 20° refused)
    let dir = tempfile::tempdir().unwrap();
    let urdf = so101();
    let model = load_urdf(&urdf).unwrap();
    let mut resting = motions();
    resting[4] = Sines { center: (-179f64).to_radians(), terms: vec![] };
    let root = write(dir.path(), "roll", |_| Storage::Degrees { sign: 1.0, offset: 0.0 }, resting);
    let motors = common::repo().join("assets/motors/so101.toml");
    let trace = dir.path().join("q.csv");
    for forward in [false, true] {
        let mut args = vec!["replay", root.to_str().unwrap(), "--urdf", urdf.to_str().unwrap(), "--no-rrd", "--no-mcap"];
        if forward {
            args.extend(["--forward", "--motors", motors.to_str().unwrap()]);
        } else {
            args.extend(["--trace", trace.to_str().unwrap()]);
        }
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 0, "forward {forward}: {stderr}");
        let notice = stderr.lines().find(|l| l.contains("past the URDF's limits")).unwrap_or_else(|| panic!("{stderr}"));
        // the stored degrees' quantum is 0.09°
        let by: f64 = notice.split("wrist_roll by up to ").nth(1).and_then(|r| r.split('°').next()).and_then(|x| x.parse().ok()).unwrap_or_else(|| panic!("{notice}"));
        assert!((by - 18.2).abs() <= 0.1 && notice.contains("some of it read a turn round"), "forward {forward}: {notice}");
    }
    let upper = model.joints[model.joint_index("wrist_roll").unwrap()].upper;
    let rolls: Vec<f64> = trace_q(&trace).iter().map(|row| row[4]).collect();
    // at the upper limit, within the smoothing's round-off of a constant series
    assert!(rolls.iter().all(|&q| (q - upper).abs() < 1e-12), "the roll is followed to its upper limit {upper}: {rolls:?}");
}
