//! Forward replay (`replay --forward`): a dataset whose follower is armscope's own simulated SO-101
//! (STS3215s through their firmware loop, 0.2 kg at the tool) following known commands, stored as
//! LeRobot stores it (30 fps, quantized degrees). Replayed forward with the same arm, the simulated
//! follower meets the recorded one to within the encoder's quantum and the commands' smoothing; with
//! the payload left out, the gap opens on the joints that carry it.

mod common;

use armscope::model::load_urdf;
use armscope::motion::{JointMap, Source};
use armscope::replay::forward::{ForwardOptions, forward};
use armscope::replay::{ReplayOptions, Replayer};
use common::lerobot::{Sines, Spec, Storage};
use std::path::{Path, PathBuf};

const PAYLOAD: f64 = 0.2;
const FRAMES: usize = 6 * 30 + 1;

fn so101() -> PathBuf {
    common::follower::so101()
}

fn motors() -> PathBuf {
    common::follower::so101_motors()
}

/// The "real" follower at the frames: the arm simulated along the exact commands with `payload`,
/// each reaching it a frame after it was recorded (LeRobot's loop reads the follower, then the leader,
/// then sends the action).
fn follower(dir: &Path, motion: &[Sines], payload: f64, motors: &Path) -> Vec<Vec<f64>> {
    follower_after(dir, motion, payload, motors, 1.0 / 30.0)
}

/// [`follower`] with the commands reaching its servos `latency` s after their frame.
fn follower_after(dir: &Path, motion: &[Sines], payload: f64, motors: &Path, latency: f64) -> Vec<Vec<f64>> {
    let every_ms = common::follower::follow_on(dir, motion, payload, 6.0, motors, latency);
    (0..FRAMES).map(|f| every_ms[(f as f64 / 30.0 / 1e-3).round() as usize].clone()).collect()
}

fn dataset(dir: &Path) -> PathBuf {
    dataset_of(dir, "so101_follow", &common::follower::so101_commands(), PAYLOAD, &motors())
}

fn dataset_of(dir: &Path, name: &str, motion: &[Sines], payload: f64, motors: &Path) -> PathBuf {
    let storage = so101_storage();
    let root = dir.join(name);
    Spec { fps: 30.0, frames: FRAMES, episodes: vec![motion.to_vec()], storage, observed: Some(vec![follower(dir, motion, payload, motors)]) }.write_v3(&root);
    root
}

/// How LeRobot stores the SO-101: the body joints in quantized degrees, the gripper 0…100 over its limits.
fn so101_storage() -> Vec<Storage> {
    let model = load_urdf(&so101()).unwrap();
    let gripper = &model.joints[model.joint_index("gripper").unwrap()];
    let mut storage: Vec<Storage> = (0..5).map(|_| Storage::Degrees { sign: 1.0, offset: 0.0 }).collect();
    storage.push(Storage::Range0To100 { lower: gripper.lower, upper: gripper.upper });
    storage
}

fn replay_forward(root: &Path, dir: &Path, payload: f64) -> armscope::replay::forward::ForwardReplay {
    replay_forward_on(root, dir, payload, &motors())
}

fn replay_forward_on(root: &Path, dir: &Path, payload: f64, motors: &Path) -> armscope::replay::forward::ForwardReplay {
    let model = load_urdf(&so101()).unwrap();
    let source = Source::open(root, None).unwrap();
    let observed = source.read(0, "observation.state").unwrap();
    let commands = source.read(0, "action").unwrap();
    let map = JointMap::builtin(source.kind(), &model, &observed).expect("the SO-101's built-in map");
    let replayer = Replayer::new(model, &ReplayOptions { payload, motors: Some(motors.to_path_buf()), ..Default::default() }, map).unwrap();
    let options = ForwardOptions { motors: motors.to_path_buf(), payload, tool: None, schedule: dir.join(format!("commands_{payload}.csv")), recordings: None, latency: None, trace: None, without_floor: false, off_elsewhere: Vec::new() };
    forward(&replayer, &options, &commands, &observed).unwrap()
}

#[test]
fn the_same_arm_replayed_forward_meets_its_follower_and_a_missing_payload_opens_the_gap() {
    let dir = tempfile::tempdir().unwrap();
    let root = dataset(dir.path());
    let same = replay_forward(&root, dir.path(), PAYLOAD);
    let without = replay_forward(&root, dir.path(), 0.0);
    assert_eq!(same.joints.len(), 6);
    assert!(same.protection_trips.is_empty(), "{:?}", same.protection_trips);
    // the encoder's quantum (2π/4096 = 1.5 mrad) on the recorded follower, and the 30 fps commands'
    // smoothing: the same arm meets its follower within 2 mrad on average, where the follower itself
    // lags its commands by far more
    for g in &same.joints[..5] {
        assert!(g.gap_mae < 2e-3, "{}: the same arm parts from its follower by {:.2} mrad on average", g.joint, g.gap_mae * 1e3);
        assert!(g.parts_at.is_none(), "{}: parts at {:?}", g.joint, g.parts_at);
    }
    let lift = |r: &armscope::replay::forward::ForwardReplay| r.joints.iter().find(|g| g.joint == "shoulder_lift").unwrap().clone();
    assert!(lift(&same).real_tracking_mae > 5.0 * lift(&same).gap_mae, "the follower's own lag ({:.2} mrad) dwarfs the model's gap ({:.2} mrad)", lift(&same).real_tracking_mae * 1e3, lift(&same).gap_mae * 1e3);
    // 0.2 kg left out: the servos that hold it sag less in the model than in reality
    assert!(lift(&without).gap_mae > 3.0 * lift(&same).gap_mae + 1e-3, "shoulder_lift: gap {:.2} mrad without the payload, {:.2} with it", lift(&without).gap_mae * 1e3, lift(&same).gap_mae * 1e3);
}

#[test]
fn a_follower_whose_shoulder_gives_up_is_met_by_a_model_that_gives_up_with_it() {
    // The follower holds 1 kg at reach: its shoulder cannot, its duty is full, and Feetech's overload
    // protection trips 2 s on (80 % held 2 s, then 20 %). Replayed forward with the same arm the
    // model's shoulder trips too, and follows the real one down. (On BAM's 12 V servo: on the
    // catalogue's fit of real logs the servo gives the datasheet's 2.94 N·m at about 31 % duty, and
    // its duty stays below the 80 % that starts the overload timer.)
    let dir = tempfile::tempdir().unwrap();
    let still = |center: f64| Sines { center, terms: vec![(0.02, 0.5, 0.0)] };
    let hold = vec![still(0.0), still(0.0), still(0.0), still(0.0), still(0.0), still(0.8)];
    let bam = common::follower::so101_motors_bam12v();
    let root = dataset_of(dir.path(), "so101_overloaded", &hold, 1.0, &bam);
    let replay = replay_forward_on(&root, dir.path(), 1.0, &bam);
    let trips: Vec<&str> = replay.protection_trips.iter().map(|(joint, _)| joint.as_str()).collect();
    assert_eq!(trips, ["shoulder_lift"]);
    let trip = replay.protection_trips[0].1;
    assert_eq!(trip.kind, armscope::actuator::bus_servo::TripKind::Overload);
    assert!((trip.time - trip.since - 2.0).abs() < 1e-9);
    let lift = replay.joints.iter().find(|g| g.joint == "shoulder_lift").unwrap();
    // the real follower fell far from its command, and the model with it
    assert!(lift.real_tracking_max > 0.3, "the follower fell {:.0} mrad", lift.real_tracking_max * 1e3);
    assert!(lift.gap_mae < 0.1 * lift.real_tracking_mae, "gap {:.1} mrad vs the fall {:.1} mrad", lift.gap_mae * 1e3, lift.real_tracking_mae * 1e3);
    assert!(armscope::replay::forward::text(&replay).contains("shoulder_lift: in the model its overload protection trips at t ="));
}


#[test]
fn forward_replay_from_the_command_line_writes_its_findings_and_needs_a_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let root = dataset(dir.path());
    let json = dir.path().join("forward.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["replay", root.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--motors", motors().to_str().unwrap(), "--payload", "0.2", "--units", "degrees", "--forward", "--summary-json", json.to_str().unwrap(), "--trace", "frames.csv"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("shoulder_lift") && stdout.contains("gap model − real"), "{stdout}");
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(doc["episodes"][0]["joints"].as_array().unwrap().len(), 6);
    assert!(doc["episodes"][0]["joints"][1]["gap_mae"].as_f64().unwrap() < 2e-3);
    // the frames compared, as --trace writes them: a row per frame, each joint's command, real and
    // simulated position, from which the report's mean gap follows exactly
    let trace = std::fs::read_to_string(dir.path().join("frames.csv")).unwrap();
    let mut lines = trace.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 1 + 3 * 6);
    assert_eq!((header[0], header[2], header[8], header[14]), ("t", "command_shoulder_lift", "real_shoulder_lift", "model_shoulder_lift"));
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), FRAMES);
    assert!((rows[FRAMES - 1][0] - (FRAMES - 1) as f64 / 30.0).abs() < 1e-6, "t from the first frame");
    let gap: f64 = rows.iter().map(|r| (r[14] - r[8]).abs()).sum::<f64>() / FRAMES as f64;
    assert!((gap - doc["episodes"][0]["joints"][1]["gap_mae"].as_f64().unwrap()).abs() < 1e-15, "the trace's gap {gap} is the report's");
    // the recordings: the simulated arm as a run records it, the real follower beside it — at each
    // frame's time exactly the recorded (mapped) position, between frames on the line between them
    let (rrd, mcap) = (dir.path().join("recordings/forward_so101_follow_episode_0.rrd"), dir.path().join("recordings/forward_so101_follow_episode_0.mcap"));
    let model = load_urdf(&so101()).unwrap();
    let lift = model.joint_index("shoulder_lift").unwrap();
    let observed = Source::open(&root, None).unwrap().read(0, "observation.state").unwrap();
    let map = JointMap::builtin(Source::open(&root, None).unwrap().kind(), &model, &observed).unwrap();
    let follower = map.apply(&model, &observed).unwrap()[lift].clone().unwrap();
    let file = common::rrd::Rrd::open(&rrd);
    assert!(file.verify_errors.is_empty(), "{:?}", file.verify_errors);
    let series = file.series("/joints/shoulder_lift/observed");
    assert_eq!(series.len(), file.series("/joints/shoulder_lift/position").len());
    for (t, v) in &series {
        let frame = t * 30.0;
        let (f, w) = (frame.floor() as usize, frame - frame.floor());
        let expected = if f + 1 < FRAMES { follower[f] + w * (follower[f + 1] - follower[f]) } else { follower[FRAMES - 1] };
        assert!((v[0] - expected).abs() < 1e-9, "t = {t}: {} against the follower's {expected}", v[0]);
    }
    assert!(series.iter().filter(|(t, _)| (t * 30.0 - (t * 30.0).round()).abs() < 1e-9).count() >= FRAMES / 3, "frames on the step grid");
    let controller: Vec<f64> = common::controller_messages(&mcap).iter().map(|m| m.observed_position[lift]).collect();
    assert_eq!(controller.len(), series.len());
    assert!(controller.iter().zip(&series).all(|(a, (_, b))| (a - b[0]).abs() < 1e-12), "/controller.observed_position is the .rrd's");
    // a bag of joint states alone holds no commands to follow
    let bag = common::repo().join("tests/fixtures/ros2/joint_states_effort.mcap");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["replay", bag.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--motors", motors().to_str().unwrap(), "--forward", "--no-rrd", "--no-mcap"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.lines().last().unwrap().contains("--forward"), "{err}");
    // without motors there is nothing to follow the commands
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope")).args(["replay", root.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--forward"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn a_datasets_episodes_are_replayed_forward_together_the_widest_gap_first_and_recorded() {
    // two episodes of the same commands: in episode 0 the follower carried the 0.2 kg the replay is
    // told of, in episode 1 it carried 0.5 kg — the model misses episode 1 by more
    let dir = tempfile::tempdir().unwrap();
    let storage = so101_storage();
    let motion = common::follower::so101_commands();
    let root = dir.path().join("so101_two_loads");
    let observed = vec![follower(dir.path(), &motion, PAYLOAD, &motors()), follower(dir.path(), &motion, 0.5, &motors())];
    Spec { fps: 30.0, frames: FRAMES, episodes: vec![motion.clone(), motion], storage, observed: Some(observed) }.write_v3(&root);
    let json = dir.path().join("forward.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["replay", root.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--motors", motors().to_str().unwrap(), "--payload", "0.2", "--units", "degrees", "--forward", "--jobs", "2", "--no-rrd", "--summary-json", json.to_str().unwrap()])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let order: Vec<i64> = doc["episodes"].as_array().unwrap().iter().map(|e| e["episode"].as_i64().unwrap()).collect();
    assert_eq!(order, [1, 0], "the widest gap first");
    let lift_gap = |e: usize| doc["episodes"][e]["joints"][1]["gap_mae"].as_f64().unwrap();
    assert!(lift_gap(0) > 3.0 * lift_gap(1), "shoulder_lift: {:.2} mrad with 0.5 kg carried, {:.2} with the 0.2 kg told", lift_gap(0) * 1e3, lift_gap(1) * 1e3);
    assert!(stdout.find("episode 1 (widest gap").unwrap() < stdout.find("episode 0 (widest gap").unwrap(), "{stdout}");
    assert!(stdout.contains("recorded: episode 1, the widest gap"), "{stdout}");
    assert!(dir.path().join("recordings/forward_so101_two_loads_episode_1.mcap").exists());
    assert!(!dir.path().join("recordings/forward_so101_two_loads_episode_0.mcap").exists());
}

#[test]
fn a_follower_whose_commands_arrive_late_is_met_once_the_replay_is_told_the_latency() {
    // the "real" follower's commands reach it 100 ms (3 frames) after their frame: the default one
    // frame's replay parts from it on a fast joint; --latency 0.1 meets it within the encoder's quantum
    let dir = tempfile::tempdir().unwrap();
    let storage = so101_storage();
    let motion = common::follower::so101_commands();
    let root = dir.path().join("so101_late");
    let observed = vec![follower_after(dir.path(), &motion, PAYLOAD, &motors(), 0.1)];
    Spec { fps: 30.0, frames: FRAMES, episodes: vec![motion], storage, observed: Some(observed) }.write_v3(&root);
    let (urdf, motor_file) = (so101(), motors());
    let replay = |latency: Option<&str>| {
        let json = dir.path().join("late.json");
        let mut args = vec!["replay", root.to_str().unwrap(), "--urdf", urdf.to_str().unwrap(), "--motors", motor_file.to_str().unwrap(), "--payload", "0.2", "--units", "degrees", "--forward", "--no-rrd", "--no-mcap", "--summary-json", json.to_str().unwrap()];
        if let Some(l) = latency {
            args.extend(["--latency", l]);
        }
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope")).args(&args).current_dir(dir.path()).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        (String::from_utf8_lossy(&out.stdout).to_string(), doc["episodes"][0].clone())
    };
    let (text, one_frame) = replay(None);
    assert!(text.contains("commands reach the model's servos 33.3 ms after their frame (one frame; --latency sets another)"), "{text}");
    assert!((one_frame["latency_s"].as_f64().unwrap() - 1.0 / 30.0).abs() < 1e-6);
    // the servos' own delay after it, the catalogue's STS3215's (34.9 ms, from bench logs), said too
    assert!(text.contains("(one frame; --latency sets another), the servos act on them 34.9 ms later (their command_delay)"), "{text}");
    let catalogue = armscope::actuator::Catalogue::load(Path::new(armscope::actuator::catalogue::DEFAULT_CATALOGUE)).unwrap();
    let delay = catalogue.servo_params("STS3215-C018").unwrap().unwrap().command_delay;
    assert_eq!(one_frame["servo_command_delay_s"]["elbow_flex"].as_f64(), Some(delay));
    let (text, told) = replay(Some("0.1"));
    assert!(text.contains("100.0 ms after their frame (--latency)"), "{text}");
    let gap = |doc: &serde_json::Value, j: usize| doc["joints"][j]["gap_mae"].as_f64().unwrap();
    for j in 0..5 {
        assert!(gap(&told, j) < 2e-3, "joint {j}: {:.2} mrad with the latency told", gap(&told, j) * 1e3);
    }
    // shoulder_pan swings at 0.6 rad/s: 67 ms untold is about 40 mrad of it
    assert!(gap(&one_frame, 0) > 10.0 * gap(&told, 0), "shoulder_pan: {:.2} mrad a frame late, {:.2} told", gap(&one_frame, 0) * 1e3, gap(&told, 0) * 1e3);
    // the tracking figures keep their meaning: each follower against the command as recorded
    let tracking = |doc: &serde_json::Value| doc["joints"][0]["real_tracking_mae"].as_f64().unwrap();
    assert_eq!(tracking(&told), tracking(&one_frame));
    // a latency no teleop loop has: one line naming the flag
    for bad in ["--latency=-0.01", "--latency=2", "--latency=NaN"] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
            .args(["replay", root.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--motors", motors().to_str().unwrap(), "--units", "degrees", "--forward", "--no-rrd", "--no-mcap", bad])
            .current_dir(dir.path())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        let lines: Vec<&str> = err.lines().filter(|l| !l.starts_with("armscope: notice")).collect();
        assert!(lines.len() == 1 && lines[0].contains("--latency") && !lines[0].contains("NaN") && !lines[0].contains("inf"), "{err}");
    }
}

#[test]
fn a_payload_left_out_of_an_arm_holding_still_is_a_gap_made_at_rest_and_said_so() {
    // The follower holds one pose with 0.2 kg at the tool; the model, without it, sags less. The
    // frames are still (commands and follower, but for any first settling), so the gap is made at rest,
    // and the report says the model misses what holds the arm, not how it moves.
    let dir = tempfile::tempdir().unwrap();
    let pose: Vec<Sines> = common::follower::so101_commands().iter().map(|s| Sines { center: s.center, terms: Vec::new() }).collect();
    let held = dataset_of(dir.path(), "so101_hold", &pose, PAYLOAD, &motors());
    let without = replay_forward(&held, dir.path(), 0.0);
    let lift = without.joints.iter().find(|g| g.joint == "shoulder_lift").unwrap();
    assert!(lift.gap_mae > 2e-3, "shoulder_lift: the payload left out opens only {:.2} mrad", lift.gap_mae * 1e3);
    // the episode's frames, a frame period each, less any first settling
    assert!(lift.at_rest.seconds > 5.0 && lift.at_rest.seconds <= FRAMES as f64 / 30.0 + 1e-9, "{:?}", lift.at_rest);
    assert!(lift.at_rest.gap_part > 0.9 * lift.gap_mae && lift.at_rest.gap_part <= lift.gap_mae + 1e-15, "{:?} of {}", lift.at_rest, lift.gap_mae);
    // the real follower (with the payload) rests further from its commands than the model
    assert!(lift.at_rest.real_offset > lift.at_rest.sim_offset + 2e-3, "{:?}", lift.at_rest);
    let text = armscope::replay::forward::text(&without);
    assert!(text.lines().any(|l| l.starts_with("  shoulder_lift: ") && l.contains("mean gap made at rest")), "{text}");
    // the same payload left out of a moving arm: a gap made in motion, nothing at rest
    let moving = replay_forward(&dataset(dir.path()), dir.path(), 0.0);
    let lift = moving.joints.iter().find(|g| g.joint == "shoulder_lift").unwrap();
    assert_eq!(lift.at_rest.seconds, 0.0, "{:?}", lift.at_rest);
    assert!(!armscope::replay::forward::text(&moving).contains("made at rest"));
}

#[test]
fn a_joint_that_does_not_follow_is_held_in_the_model_where_the_real_one_stayed() {
    // The follower's wrist roll is off: it stays where it started while its commands sweep ±0.6 rad.
    // The "real" follower is the arm simulated with its roll held there. Replayed forward, the
    // roll is named as not following and the model's roll is held where the real one stayed (it
    // would otherwise sweep its commands), so the joints beside it are met as the same arm meets
    // them: within the encoder's quantum and the commands' smoothing.
    let dir = tempfile::tempdir().unwrap();
    let commands = common::follower::so101_commands();
    let mut stuck = commands.clone();
    stuck[4] = Sines { center: commands[4].q(0.0), terms: Vec::new() };
    let root = dir.path().join("so101_roll_off");
    let observed = vec![follower(dir.path(), &stuck, PAYLOAD, &motors())];
    Spec { fps: 30.0, frames: FRAMES, episodes: vec![commands], storage: so101_storage(), observed: Some(observed) }.write_v3(&root);
    let replay = replay_forward(&root, dir.path(), PAYLOAD);
    let roll = replay.joints.iter().position(|g| g.joint == "wrist_roll").unwrap();
    assert!(!replay.joints[roll].follows && replay.joints[roll].commanded_sweep > 1.0, "{:?}", replay.joints[roll]);
    let (lowest, highest) = replay.simulated[roll].iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &q| (lo.min(q), hi.max(q)));
    // the encoder's quantum, 2π/4096 = 1.53 mrad
    assert!(highest - lowest < 1.53e-3, "the model's roll swept {:.2} mrad", (highest - lowest) * 1e3);
    for g in replay.joints.iter().filter(|g| g.joint != "wrist_roll" && g.joint != "gripper") {
        assert!(g.follows && g.gap_mae < 2e-3, "{}: {:.2} mrad from the follower", g.joint, g.gap_mae * 1e3);
    }
    let text = armscope::replay::forward::text(&replay);
    assert!(text.contains("wrist_roll       does not follow its commands") && text.contains("the model's held where the real one was"), "{text}");
}

#[test]
fn a_joint_off_in_one_episode_is_taken_as_off_where_another_does_not_sweep_it() {
    // The follower's wrist roll is off in both episodes of a recording: in episode 0 its commands
    // sweep ±0.6 rad, in episode 1 ±0.025 (under 5°: too little to tell from that episode alone).
    // Replayed together, episode 1's roll is taken as not following too (said in one notice) and
    // held where the real one stayed; replayed alone, episode 1's roll is taken as following, and
    // the model's roll moves with its commands away from the real one.
    let dir = tempfile::tempdir().unwrap();
    let wide = common::follower::so101_commands();
    let mut small = wide.clone();
    small[4] = Sines { center: 0.0, terms: vec![(0.025, 1.1, 0.3)] };
    let stuck = |commands: &[Sines]| {
        let mut stuck = commands.to_vec();
        stuck[4] = Sines { center: commands[4].q(0.0), terms: Vec::new() };
        stuck
    };
    let followers = vec![follower(dir.path(), &stuck(&wide), PAYLOAD, &motors()), follower(dir.path(), &stuck(&small), PAYLOAD, &motors())];
    let both = dir.path().join("so101_roll_off_twice");
    Spec { fps: 30.0, frames: FRAMES, episodes: vec![wide, small.clone()], storage: so101_storage(), observed: Some(followers.clone()) }.write_v3(&both);
    let alone = dir.path().join("so101_roll_small_alone");
    Spec { fps: 30.0, frames: FRAMES, episodes: vec![small], storage: so101_storage(), observed: Some(vec![followers[1].clone()]) }.write_v3(&alone);
    let run = |root: &Path, name: &str| {
        let json = dir.path().join(format!("{name}.json"));
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
            .args(["replay", root.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--motors", motors().to_str().unwrap(), "--payload", "0.2", "--units", "degrees", "--forward", "--no-rrd", "--no-mcap", "--summary-json", json.to_str().unwrap()])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        (String::from_utf8_lossy(&out.stderr).to_string(), doc)
    };
    let roll_of = |doc: &serde_json::Value, episode: i64| -> serde_json::Value {
        let episode = doc["episodes"].as_array().unwrap().iter().find(|e| e["episode"] == episode).unwrap();
        episode["joints"].as_array().unwrap().iter().find(|j| j["joint"] == "wrist_roll").unwrap().clone()
    };
    let (stderr, doc) = run(&both, "both");
    let notices: Vec<&str> = stderr.lines().filter(|l| l.contains("taken as not following there too")).collect();
    assert_eq!(notices.len(), 1, "{stderr}");
    assert!(notices[0].contains("wrist_roll does not follow its commands in episode 0; in episode 1 its commands sweep less than 5°"), "{stderr}");
    let roll = roll_of(&doc, 1);
    assert!(roll["follows"] == false && roll["commanded_sweep"].as_f64().unwrap() < 0.087, "{roll}");
    // held where the real one stayed: within the encoder's quantum, 2π/4096 = 1.53 mrad
    assert!(roll["gap_mae"].as_f64().unwrap() < 1.53e-3, "{roll}");
    assert!(roll_of(&doc, 0)["follows"] == false);
    let (stderr, doc) = run(&alone, "alone");
    assert!(!stderr.contains("taken as not following"), "{stderr}");
    let roll = roll_of(&doc, 0);
    assert!(roll["follows"] == true && roll["gap_mae"].as_f64().unwrap() > 5e-3, "{roll}");
}

#[test]
fn a_motor_files_floor_the_recorded_tool_went_through_is_left_out_and_said_so() {
    // The same arm's follower swinging freely, replayed with a motor file whose [floor] (another
    // set-up's table) lies 10 mm above the lowest its tool went: that floor is not this recording's
    // table, and the replay leaves it out, saying so in one notice; the follower is then met as the
    // same arm meets it. A floor the tool stayed above is kept.
    let dir = tempfile::tempdir().unwrap();
    let motion = common::follower::so101_commands();
    let root = dataset_of(dir.path(), "so101_swing", &motion, PAYLOAD, &motors());
    let model = load_urdf(&so101()).unwrap();
    let tool = model.frames.iter().position(|f| f.name == "gripper_frame_link").unwrap();
    let mut data = armscope::dynamics::Data::new(&model);
    let lowest = follower(dir.path(), &motion, PAYLOAD, &motors())
        .iter()
        .map(|q| {
            armscope::dynamics::forward_kinematics(&model, &mut data, q);
            armscope::dynamics::frame_pose(&model, &data, tool).translation.z
        })
        .fold(f64::INFINITY, f64::min);
    let replay = |name: &str, height: f64| {
        let file = dir.path().join(format!("{name}.toml"));
        std::fs::write(&file, std::fs::read_to_string(motors()).unwrap() + &format!("\n[floor]\nheight = {height:?}\nlink = \"gripper_frame_link\"\n")).unwrap();
        let json = dir.path().join(format!("{name}.json"));
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
            .args(["replay", root.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--motors", file.to_str().unwrap(), "--payload", "0.2", "--units", "degrees", "--forward", "--no-rrd", "--no-mcap", "--summary-json", json.to_str().unwrap()])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let widest = doc["episodes"][0]["joints"].as_array().unwrap()[..5].iter().map(|j| j["gap_mae"].as_f64().unwrap()).fold(0.0, f64::max);
        (String::from_utf8_lossy(&out.stderr).to_string(), widest)
    };
    let (stderr, widest) = replay("another_table", lowest + 0.01);
    let notices: Vec<&str> = stderr.lines().filter(|l| l.contains("[floor]")).collect();
    assert!(notices.len() == 1 && notices[0].contains("is not this recording's table: the real tool ('gripper_frame_link') goes ") && notices[0].ends_with(" mm below it in episode 0; replayed without it"), "{stderr}");
    // 10 mm, read through the encoder's quanta (1.53 mrad a joint: under 1 mm at the tool's reach)
    let depth: f64 = notices[0].split(" goes ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!((depth - 10.0).abs() < 1.0, "{depth} mm");
    assert!(widest < 2e-3, "the follower missed by {:.2} mrad with the floor left out", widest * 1e3);
    // 1 mm under the lowest the tool went: its table, kept (never touched)
    let (stderr, widest) = replay("its_table", lowest - 0.001);
    assert!(stderr.contains("rests on a floor at z =") && !stderr.contains("not this recording's table"), "{stderr}");
    assert!(widest < 2e-3, "{:.2} mrad", widest * 1e3);
}
