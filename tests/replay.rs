//! Replay of recorded motion: LeRobot datasets (v3.0 and v2.1) of known SO-101 motions, written
//! here as LeRobot writes them (30 fps, quantized to the encoder, degrees with per-joint signs and
//! offsets), replayed into the torque each joint needed and held against the exact inverse
//! dynamics of the true motion; a ROS 2 bag written by mcap-ros2-support; the errors a user meets.

mod common;

use armscope::model::{Model, load_urdf};
use armscope::motion::{JointMap, Source};
use armscope::replay::inverse::needed_torques;
use armscope::replay::{EpisodeReplay, ReplayOptions, Replayer, intervals_over};
use common::lerobot::{SO101_NAMES, Sines, Spec, Storage, so101_motions as motions};
use std::path::{Path, PathBuf};

fn so101() -> PathBuf {
    common::repo().join("tests/fixtures/robots/so101.urdf")
}

/// Signs and offsets per joint, as a user's calibration leaves them (the map must undo them).
const SIGNS: [f64; 5] = [1.0, -1.0, 1.0, -1.0, 1.0];
const OFFSETS: [f64; 5] = [0.05, -0.12, 0.3, 0.0, -0.2];

fn spec(episodes: usize, seconds: f64, model: &Model) -> Spec {
    let gripper = &model.joints[model.joint_index("gripper").unwrap()];
    let mut storage: Vec<Storage> = (0..5).map(|j| Storage::Degrees { sign: SIGNS[j], offset: OFFSETS[j] }).collect();
    storage.push(Storage::Range0To100 { lower: gripper.lower, upper: gripper.upper });
    Spec { fps: 30.0, frames: (seconds * 30.0) as usize + 1, episodes: (0..episodes).map(motions).collect(), storage, observed: None }
}

fn joint_map(dir: &Path) -> PathBuf {
    let mut text = String::new();
    for (j, name) in ["shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll"].iter().enumerate() {
        text += &format!("[joints.{name}]\ncolumn = \"{}\"\nunit = \"deg\"\nsign = {}\noffset = {}\n\n", SO101_NAMES[j], SIGNS[j], OFFSETS[j]);
    }
    text += "[joints.gripper]\ncolumn = \"gripper.pos\"\nunit = \"range_0_100\"\n";
    let path = dir.join("so101_map.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn replayer(payload: f64, map: &Path) -> Replayer {
    let model = load_urdf(&so101()).unwrap();
    let map = JointMap::load(map, &model).unwrap();
    Replayer::new(model, &ReplayOptions { payload, ..Default::default() }, map).unwrap()
}

/// The exact torques of the true motion at the frames, on the replay's model (payload included).
fn true_torques(model: &Model, motion: &[Sines], time: &[f64]) -> Vec<Vec<f64>> {
    let series = |f: &dyn Fn(&Sines, f64) -> f64| -> Vec<Vec<f64>> { motion.iter().map(|m| time.iter().map(|&t| f(m, t)).collect()).collect() };
    needed_torques(model, &series(&|m, t| m.q(t)), &series(&|m, t| m.qd(t)), &series(&|m, t| m.qdd(t)))
}

/// Per joint: the largest error over the frames 0.5 s from either end, and the bar there:
/// 2 % of the joint's peak torque + 5 mN·m.
fn errors(replay: &EpisodeReplay, truth: &[Vec<f64>]) -> Vec<(f64, f64)> {
    let time = &replay.motion.time;
    let end = *time.last().unwrap();
    let inside: Vec<usize> = (0..time.len()).filter(|&k| time[k] >= 0.5 && time[k] <= end - 0.5).collect();
    truth
        .iter()
        .zip(&replay.motion.needed)
        .map(|(exact, needed)| {
            let peak = inside.iter().map(|&k| exact[k].abs()).fold(0.0, f64::max);
            let worst = inside.iter().map(|&k| (needed[k] - exact[k]).abs()).fold(0.0, f64::max);
            (worst, 0.02 * peak + 0.005)
        })
        .collect()
}

fn check_dataset(root: &Path, episodes: usize, payload: f64, map: &Path) {
    let replayer = replayer(payload, map);
    let source = Source::open(root, None).unwrap();
    assert_eq!(source.episodes(), (0..episodes as i64).collect::<Vec<_>>());
    for e in 0..episodes {
        let episode = source.read(e as i64, "observation.state").unwrap();
        assert_eq!(episode.time.len(), 20 * 30 + 1);
        let replay = replayer.replay(&episode).unwrap();
        let truth = true_torques(&replayer.model, &motions(e), &episode.time);
        for (j, (worst, bar)) in errors(&replay, &truth).iter().enumerate() {
            assert!(worst <= bar, "{} episode {e}, payload {payload} kg, joint {}: error {worst:.4} N·m above the bar {bar:.4} N·m", root.display(), replayer.model.joints[j].name);
        }
    }
}

fn check_layout(write: fn(&Spec, &Path)) {
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&so101()).unwrap();
    let root = dir.path().join("so101");
    write(&spec(3, 20.0, &model), &root);
    let map = joint_map(dir.path());
    for payload in [0.0, 0.2] {
        check_dataset(&root, 3, payload, &map);
    }
}

#[test]
fn v3_dataset_needed_torques_match_the_true_motions_inverse_dynamics() {
    check_layout(Spec::write_v3);
}

#[test]
fn v21_dataset_needed_torques_match_the_true_motions_inverse_dynamics() {
    check_layout(Spec::write_v21);
}

#[test]
fn v3_dataset_in_one_row_group_needed_torques_match_the_true_motions_inverse_dynamics() {
    check_layout(Spec::write_v3_one_row_group);
}

/// A v3 file whose episodes share one row group (decoded once for all of them) reads every episode
/// as the file with a row group per episode does, to the bit, in any order and from several
/// threads at once.
#[test]
fn episodes_sharing_a_row_group_read_as_episodes_in_their_own() {
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&so101()).unwrap();
    let spec = spec(4, 3.0, &model);
    let (own, shared) = (dir.path().join("own"), dir.path().join("shared"));
    spec.write_v3(&own);
    spec.write_v3_one_row_group(&shared);
    let (own, shared) = (Source::open(&own, None).unwrap(), Source::open(&shared, None).unwrap());
    let read = |source: &Source, e: i64, feature: &str| {
        let episode = source.read(e, feature).unwrap();
        (episode.time, episode.columns.into_iter().map(|c| (c.name, c.values)).collect::<Vec<_>>())
    };
    let orders: [Vec<i64>; 2] = [vec![3, 1, 0, 2], vec![2, 0, 3, 1]];
    std::thread::scope(|scope| {
        for order in &orders {
            let (own, shared) = (&own, &shared);
            scope.spawn(move || {
                for &e in order {
                    for feature in ["observation.state", "action"] {
                        let expected = read(own, e, feature);
                        assert_eq!(expected.0.len(), 3 * 30 + 1);
                        assert_eq!(read(shared, e, feature), expected, "episode {e}, {feature}");
                    }
                }
            });
        }
    });
}

#[test]
fn the_intervals_shoulder_lift_needs_over_2_9_nm_are_found_to_a_frame() {
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&so101()).unwrap();
    let root = dir.path().join("so101_v3");
    spec(3, 20.0, &model).write_v3(&root);
    let replayer = replayer(0.2, &joint_map(dir.path()));
    let source = Source::open(&root, None).unwrap();
    let lift = replayer.model.joint_index("shoulder_lift").unwrap();
    let mut found = 0;
    for e in 0..3 {
        let episode = source.read(e, "observation.state").unwrap();
        let replay = replayer.replay(&episode).unwrap();
        let truth = true_torques(&replayer.model, &motions(e as usize), &episode.time);
        let threshold = vec![2.9; episode.time.len()];
        let end = *episode.time.last().unwrap();
        let inside = |i: &&armscope::replay::Interval| i.start >= 0.5 && i.end <= end - 0.5;
        let exact: Vec<_> = intervals_over(&episode.time, &truth[lift], &threshold).into_iter().filter(|i| inside(&i)).collect();
        let replayed: Vec<_> = intervals_over(&episode.time, &replay.motion.needed[lift], &threshold).into_iter().filter(|i| inside(&i)).collect();
        assert_eq!(exact.len(), replayed.len(), "episode {e}: intervals over 2.9 N·m, exact {exact:?}, replayed {replayed:?}");
        for (a, b) in exact.iter().zip(&replayed) {
            assert!(a.first.abs_diff(b.first) <= 1 && a.last.abs_diff(b.last) <= 1, "episode {e}: exact {a:?} vs replayed {b:?}");
        }
        found += exact.len();
    }
    assert!(found >= 3, "the motions must take shoulder_lift over 2.9 N·m to test this ({found} intervals)");
}

#[test]
fn the_builtin_so101_map_reads_lerobots_own_convention() {
    // LeRobot's kinematics: degrees straight onto so101_new_calib's joints, the gripper 0…100
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&so101()).unwrap();
    let mut spec = spec(1, 20.0, &model);
    for s in spec.storage.iter_mut().take(5) {
        *s = Storage::Degrees { sign: 1.0, offset: 0.0 };
    }
    let root = dir.path().join("so101");
    spec.write_v3(&root);
    let source = Source::open(&root, None).unwrap();
    let episode = source.read(0, "observation.state").unwrap();
    let map = JointMap::builtin(source.kind(), &model, &episode).expect("the SO-101's map is built in");
    let replayer = Replayer::new(model, &ReplayOptions::default(), map).unwrap();
    let replay = replayer.replay(&episode).unwrap();
    let truth = true_torques(&replayer.model, &motions(0), &episode.time);
    for (j, (worst, bar)) in errors(&replay, &truth).iter().enumerate() {
        assert!(worst <= bar, "joint {j}: {worst} > {bar}");
    }
}

#[test]
fn the_trace_has_a_row_per_sample_in_the_models_joint_order() {
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&so101()).unwrap();
    let root = dir.path().join("so101");
    spec(1, 4.0, &model).write_v21(&root);
    let map = joint_map(dir.path());
    let trace = dir.path().join("trace.csv");
    let json = dir.path().join("summary.json");
    let code = common::armscope(&["replay", root.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--joint-map", map.to_str().unwrap(), "--trace", trace.to_str().unwrap(), "--summary-json", json.to_str().unwrap(), "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0);
    let table = common::read_csv(&trace);
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll", "gripper"]);
    assert_eq!(table.header, armscope::replay::trace::header(6));
    assert_eq!(table.rows.len(), 4 * 30 + 1);
    // t from the episode's first sample; q the true motion to the smoothing's accuracy
    let t = table.column("t");
    assert_eq!(t[0], 0.0);
    assert!((t[30] - 1.0).abs() < 1e-12);
    let truth = motions(0);
    for (k, &tk) in t.iter().enumerate().filter(|(_, t)| **t >= 0.5 && **t <= 3.5) {
        for j in 0..6 {
            let q = table.rows[k][1 + j];
            // the quantum: 360/4095° on the body joints, 1/1400 of the gripper's travel
            assert!((q - truth[j].q(tk)).abs() < 2e-3, "joint {j} at {tk} s: {q} vs {}", truth[j].q(tk));
        }
    }
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(doc["episodes"].as_array().unwrap().len(), 1);
    assert_eq!(doc["episodes"][0]["joints"].as_array().unwrap().len(), 6);
}

fn error_of(result: Result<impl std::fmt::Debug, armscope::Error>) -> String {
    let message = result.expect_err("must fail").to_string();
    assert!(!message.contains('\n'), "one line: {message}");
    message
}

#[test]
fn bad_datasets_get_one_line_naming_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&so101()).unwrap();
    let root = dir.path().join("so101");
    spec(2, 2.0, &model).write_v3(&root);
    let source = Source::open(&root, None).unwrap();
    // an episode that does not exist
    let m = error_of(source.read(7, "observation.state"));
    assert!(m.contains("--episode") && m.contains('7') && m.contains("0 to 1"), "{m}");
    // a feature (column group) that is not there
    let m = error_of(source.read(0, "observation.effort"));
    assert!(m.contains("observation.effort") && m.contains("observation.state"), "{m}");
    // a column the map names that the dataset lacks
    let map_path = dir.path().join("map.toml");
    std::fs::write(&map_path, "[joints.shoulder_pan]\ncolumn = \"shoulder_pan.position\"\nunit = \"deg\"\n").unwrap();
    let map = JointMap::load(&map_path, &model).unwrap();
    let episode = source.read(0, "observation.state").unwrap();
    let m = error_of(map.apply(&model, &episode));
    assert!(m.contains("shoulder_pan.position") && m.contains("shoulder_pan.pos"), "{m}");
    // a joint the URDF does not have
    std::fs::write(&map_path, "[joints.elbow]\ncolumn = \"elbow_flex.pos\"\nunit = \"deg\"\n").unwrap();
    let m = error_of(JointMap::load(&map_path, &model));
    assert!(m.contains("map.toml") && m.contains("'elbow'") && m.contains("elbow_flex"), "{m}");
    // a unit it does not know
    std::fs::write(&map_path, "[joints.elbow_flex]\ncolumn = \"elbow_flex.pos\"\nunit = \"grad\"\n").unwrap();
    let m = error_of(JointMap::load(&map_path, &model));
    assert!(m.contains("map.toml") && m.contains("grad"), "{m}");
}

#[test]
fn timestamps_that_do_not_increase_are_named() {
    use arrow::array::{ArrayRef, Float32Array, RecordBatch};
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&so101()).unwrap();
    let root = dir.path().join("so101");
    spec(1, 2.0, &model).write_v21(&root);
    // rewrite the episode with frame 10's timestamp equal to frame 9's
    let path = root.join("data/chunk-000/episode_000000.parquet");
    let file = std::fs::File::open(&path).unwrap();
    let batch = parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(file).unwrap().build().unwrap().next().unwrap().unwrap();
    let mut stamps: Vec<f32> = (0..batch.num_rows()).map(|f| f as f32 / 30.0).collect();
    stamps[10] = stamps[9];
    let mut columns: Vec<ArrayRef> = batch.columns().to_vec();
    columns[2] = std::sync::Arc::new(Float32Array::from(stamps));
    let batch = RecordBatch::try_new(batch.schema(), columns).unwrap();
    let mut writer = parquet::arrow::ArrowWriter::try_new(std::fs::File::create(&path).unwrap(), batch.schema(), None).unwrap();
    writer.write(&batch).unwrap();
    writer.close().unwrap();
    let source = Source::open(&root, None).unwrap();
    let m = error_of(source.read(0, "observation.state"));
    assert!(m.contains("episode_000000.parquet") && m.contains("timestamps do not increase at sample 10") && m.contains("timestamp"), "{m}");
}

#[test]
fn without_a_map_for_its_columns_the_replay_asks_for_one() {
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&so101()).unwrap();
    let root = dir.path().join("so101");
    spec(1, 2.0, &model).write_v3(&root);
    // the box model's joints are not the SO-101's columns
    let code = common::armscope(&["replay", root.to_str().unwrap(), "--urdf", common::box_urdf().to_str().unwrap()]);
    assert_eq!(code, 2);
}

/// The ROS 2 bag `tests/fixtures/ros2/joint_states_effort.mcap`, written by mcap-ros2-support
/// (`make_joint_states.py` beside it): the SO-101 at 100 Hz for 8 s, positions on the encoder's
/// 4096-per-turn lattice, effort = the true motion's inverse dynamics (Pinocchio) + friction
/// 0.04·sign(q̇) + 0.02·q̇ N·m on every joint.
#[test]
fn a_ros2_bag_replays_to_the_same_accuracy_and_keeps_its_measured_effort() {
    let bag = common::repo().join("tests/fixtures/ros2/joint_states_effort.mcap");
    let model = load_urdf(&so101()).unwrap();
    let source = Source::open(&bag, None).unwrap();
    let episode = source.read(0, "").unwrap();
    assert_eq!(episode.time.len(), 801);
    let map = JointMap::builtin(source.kind(), &model, &episode).expect("a bag's columns are named by joint");
    let replayer = Replayer::new(model, &ReplayOptions::default(), map).unwrap();
    let replay = replayer.replay(&episode).unwrap();
    let truth = true_torques(&replayer.model, &bag_motions(), &episode.time);
    for (j, (worst, bar)) in errors(&replay, &truth).iter().enumerate() {
        assert!(worst <= bar, "joint {}: {worst} > {bar}", replayer.model.joints[j].name);
    }
    // the measured effort is kept beside the model's torque: their difference is the friction
    for j in 0..6 {
        let measured = replay.motion.measured[j].as_ref().expect("effort recorded");
        let friction: Vec<f64> = episode.time.iter().map(|&t| {
            let v = bag_motions()[j].qd(t);
            0.04 * v.signum() + 0.02 * v
        }).collect();
        let end = *episode.time.last().unwrap();
        for k in (0..episode.time.len()).filter(|&k| episode.time[k] >= 0.5 && episode.time[k] <= end - 0.5) {
            // Pinocchio's and armscope's inverse dynamics of the same motion agree to 1e-9 N·m
            assert!((measured[k] - truth[j][k] - friction[k]).abs() < 1e-6, "joint {j} sample {k}: measured {} vs exact {} + friction {}", measured[k], truth[j][k], friction[k]);
        }
    }
}

/// The bag's true motion (the same numbers as `make_joint_states.py`).
fn bag_motions() -> Vec<Sines> {
    motions(1)
}

#[test]
fn the_replay_records_the_arm_needed_and_available_torques_like_a_run() {
    let dir = tempfile::tempdir().unwrap();
    let bag = common::repo().join("tests/fixtures/ros2/joint_states_effort.mcap");
    let motors = common::repo().join("assets/motors/so101.toml");
    let (rrd, mcap, trace) = (dir.path().join("r.rrd"), dir.path().join("r.mcap"), dir.path().join("t.csv"));
    let code = common::armscope(&["replay", bag.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--payload", "0.5", "--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap(), "--trace", trace.to_str().unwrap()]);
    assert_eq!(code, 0);
    let table = common::read_csv(&trace);
    let rows = table.rows.len();
    let file = common::rrd::Rrd::open(&rrd);
    assert!(file.verify_errors.is_empty(), "{:?}", file.verify_errors);
    // every sample's needed torque is the run's torque series, at the sample's time
    let torque = file.series("/joints/shoulder_lift/torque");
    assert_eq!(torque.len(), rows);
    let tau = table.column("tau2");
    let t = table.column("t");
    for (k, (time, values)) in torque.iter().enumerate() {
        assert!((time - t[k]).abs() < 1e-9 && (values[0] - tau[k]).abs() < 1e-5 * tau[k].abs().max(1.0), "sample {k}");
    }
    assert_eq!(file.series("/joints/shoulder_lift/torque_limit").len(), rows);
    // the bag's measured effort beside the model's torque, and their difference (the friction and
    // model error the arm really has), at every sample
    let episode = Source::open(&bag, None).unwrap().read(0, "observation.state").unwrap();
    let effort = &episode.effort.iter().find(|c| c.name == "shoulder_lift").expect("the bag has effort").values;
    let measured = file.series("/joints/shoulder_lift/measured_effort");
    assert_eq!(measured.len(), rows);
    for (k, (_, values)) in measured.iter().enumerate() {
        assert!((values[0] - effort[k]).abs() < 1e-9, "sample {k}: measured {} against the bag's {}", values[0], effort[k]);
        assert!((values[1] - (effort[k] - tau[k])).abs() < 1e-5 * tau[k].abs().max(1.0), "sample {k}: measured − model");
    }
    // the MCAP holds a joint state per sample, and the measured effort in /controller
    let bytes = std::fs::read(&mcap).unwrap();
    let count = mcap::MessageStream::new(&bytes).unwrap().filter(|m| m.as_ref().unwrap().channel.topic == "/joint_states").count();
    assert_eq!(count, rows);
    let lift = so101_joint_index("shoulder_lift");
    let controller: Vec<f64> = common::controller_messages(&mcap).iter().map(|m| m.measured_effort[lift]).collect();
    assert_eq!(controller.len(), rows);
    assert!(controller.iter().zip(effort).all(|(a, b)| (a - b).abs() < 1e-9), "/controller.measured_effort is the bag's effort");
}

fn so101_joint_index(name: &str) -> usize {
    load_urdf(&so101()).unwrap().joint_index(name).unwrap()
}

/// The SO-101 holding its arm out, swaying slowly: shoulder_lift's load rises and falls with its
/// angle.
fn a_long_hold_at_reach() -> Vec<Sines> {
    let s = |center: f64, terms: &[(f64, f64, f64)]| Sines { center, terms: terms.to_vec() };
    vec![s(0.0, &[(0.1, 0.7, 0.0)]), s(0.6, &[(0.6, 0.5, std::f64::consts::FRAC_PI_2)]), s(0.0, &[(0.1, 0.9, 1.0)]), s(0.0, &[(0.1, 1.1, 0.0)]), s(0.0, &[]), s(0.8, &[(0.2, 0.6, 0.0)])]
}

#[test]
fn a_feetech_protection_trips_where_the_exact_motion_trips_it() {
    // With the SO-101's STS3215s and 1 kg at the tool, shoulder_lift needs more than its servo's
    // datasheet line for stretches of seconds: its firmware's duty is full there, and Feetech's
    // overload protection (80 % for 2 s, factory settings) trips. The replay finds the trip where
    // the exact motion's torques put it, to a frame, and from then on holds the joint to the 20 %
    // duty the protection leaves.
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&so101()).unwrap();
    let root = dir.path().join("hold");
    let mut spec = spec(1, 12.0, &model);
    spec.episodes = vec![a_long_hold_at_reach()];
    spec.write_v3(&root);
    let map = JointMap::load(&joint_map(dir.path()), &model).unwrap();
    // BAM's 12 V servo (on the catalogue's fit of real logs the servo gives the datasheet's
    // 2.94 N·m at about 31 % duty, and its duty stays below the 80 % that starts the overload timer)
    let options = ReplayOptions { payload: 1.0, motors: Some(common::repo().join("tests/fixtures/motors/so101_bam12v.toml")), ..Default::default() };
    let replayer = Replayer::new(model, &options, map).unwrap();
    let episode = Source::open(&root, None).unwrap().read(0, "observation.state").unwrap();
    let replay = replayer.replay(&episode).unwrap();
    let lift = replayer.model.joint_index("shoulder_lift").unwrap();
    let load = replay.verdicts[lift].servo.expect("a servo model");
    let trip = load.protection_trip.expect("shoulder_lift trips its overload protection");
    assert_eq!(trip.kind, armscope::actuator::bus_servo::TripKind::Overload);

    // the exact motion's duty: the same servo model on the true torques and speeds
    let time = &episode.time;
    let truth = true_torques(&replayer.model, &a_long_hold_at_reach(), time);
    let drive = replayer.motors.as_ref().unwrap().joints[lift].as_ref().unwrap();
    let servo = drive.servo.as_ref().unwrap();
    let (mut duty, mut current) = (Vec::new(), Vec::new());
    for (k, &t) in time.iter().enumerate() {
        let (d, i) = armscope::replay::verdict::servo_demand(drive, truth[lift][k], a_long_hold_at_reach()[lift].qd(t)).unwrap();
        duty.push(d);
        current.push(i);
    }
    let exact = servo.firmware.protection.first_trip(time, &duty, &current).expect("the exact motion trips it");
    let frame = 1.0 / 30.0;
    assert!((trip.since - exact.since).abs() <= frame + 1e-9 && (trip.time - exact.time).abs() <= frame + 1e-9, "replayed {trip:?} vs exact {exact:?}");
    assert!(exact.since > 0.5, "the load must build up inside the episode to test this ({exact:?})");
    // from the trip on the joint has what 20 % duty gives: it is over its limit from there
    let verdict = &replay.verdicts[lift];
    let k_trip = time.iter().position(|&t| t >= trip.time).unwrap();
    let limited = drive.available_at_duty(replay.motion.needed[lift][k_trip], replay.motion.qd[lift][k_trip], 0.2);
    assert!((replay.available[lift][k_trip] - limited).abs() < 1e-12);
    assert!(verdict.over.iter().any(|i| i.first <= k_trip && i.last > k_trip), "over from the trip on: {:?}", verdict.over);
    let text = armscope::replay::report::episode_text(&replayer, &armscope::replay::report::EpisodeSummary::of(&replay, Some(0)));
    assert!(text.contains(&format!("shoulder_lift: its overload protection trips at t = {:.2} s", trip.time)), "{text}");
}
