//! Forward replay of ROS 2 bags (`replay BAG --forward`): a ros2_control arm records its joint states
//! and its trajectory controller's commands — the controller's state (its set point at each update)
//! or the trajectories it was sent. The follower is armscope's own simulated SO-101 (STS3215s through
//! their firmware loop, 0.2 kg at the tool) following known commands, its positions on the encoder's
//! lattice at 100 Hz, stamped since the epoch as a robot's clock stamps them. Replayed forward with
//! the same arm, the simulated follower meets the recorded one; with the payload left out, the gap
//! opens on the joint that carries it.

mod common;

use armscope::model::load_urdf;
use armscope::motion::{JointMap, Source};
use armscope::replay::forward::{ForwardOptions, ForwardReplay, forward};
use armscope::replay::{ReplayOptions, Replayer};
use armscope::ros2::Message;
use armscope::ros2::messages::{Header, JointState, Time};
use armscope::motion::commands::CommandSource;
use armscope::ros2::trajectory::{Float64MultiArray, JointTrajectory, JointTrajectoryControllerState, JointTrajectoryPoint};
use common::lerobot::Sines;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const PAYLOAD: f64 = 0.2;
const SECONDS: f64 = 6.0;
/// The robot's clock at the commands' start, ns since the epoch.
const EPOCH: i64 = 1_764_000_000_000_000_000;
/// The joint states recorded before the commands start (the arm waiting), s.
const LEAD_IN: f64 = 0.3;
const JOINTS: [&str; 6] = ["shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll", "gripper"];

fn so101() -> PathBuf {
    common::follower::so101()
}

fn motors() -> PathBuf {
    common::follower::so101_motors()
}

fn commands() -> Vec<Sines> {
    common::follower::so101_commands()
}

/// The "real" follower: the arm simulated along the exact commands with `payload` at the tool; its
/// positions every millisecond.
fn follower(dir: &Path, payload: f64) -> Vec<Vec<f64>> {
    common::follower::follow(dir, &commands(), payload, SECONDS)
}

/// How the bag carries the commands.
#[derive(Clone, Copy, PartialEq)]
enum CommandsAs {
    /// The controller's state at 200 Hz, its `reference` the exact commands; the gripper is another
    /// controller's (not recorded).
    ControllerState,
    /// A trajectory streamed at 30 Hz, zero-stamped (logged when sent): each message's first point
    /// is the command now, two more plan ahead to a goal 0.2 rad off that the next message replaces
    /// before it is reached.
    Trajectory,
    /// A forward position controller's Float64MultiArray at 100 Hz, its joints in the controller's
    /// order (not the joint states'): [`ARRAY_JOINTS`].
    PositionArray,
}

/// The forward controller's joint order in the `PositionArray` bag.
const ARRAY_JOINTS: [&str; 6] = ["gripper", "wrist_roll", "wrist_flex", "elbow_flex", "shoulder_lift", "shoulder_pan"];

fn nanos(t: f64) -> i64 {
    EPOCH + (t * 1e9).round() as i64
}

/// A bag of the follower's joint states (100 Hz, on the 4096-per-turn lattice, from LEAD_IN before
/// the commands) and its commands, written with armscope's CDR encoder and the definitions a rosbag2
/// recorder would store.
fn bag(dir: &Path, name: &str, follower: &[Vec<f64>], commands_as: CommandsAs) -> PathBuf {
    let path = dir.join(name);
    let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    let mut writer = mcap::WriteOptions::new().profile("ros2").create(file).unwrap();
    let channel = |writer: &mut mcap::Writer<_>, topic: &str, schema: &str| {
        let definition = armscope::ros2::definitions::full_definition(schema).unwrap();
        let id = writer.add_schema(schema, "ros2msg", definition.as_bytes()).unwrap();
        writer.add_channel(id, topic, "cdr", &BTreeMap::new()).unwrap()
    };
    let states = channel(&mut writer, "/joint_states", JointState::NAME);
    let controller = match commands_as {
        CommandsAs::ControllerState => channel(&mut writer, "/arm_controller/controller_state", JointTrajectoryControllerState::NAME),
        CommandsAs::Trajectory => channel(&mut writer, "/arm_controller/joint_trajectory", JointTrajectory::NAME),
        CommandsAs::PositionArray => channel(&mut writer, "/forward_position_controller/commands", Float64MultiArray::NAME),
    };
    // (log time, channel, message): written in log-time order as a recorder writes them
    let mut messages: Vec<(i64, u16, Vec<u8>)> = Vec::new();
    let tick = 2.0 * std::f64::consts::PI / 4096.0;
    let lead = (LEAD_IN * 100.0) as i64;
    for k in -lead..=(SECONDS * 100.0) as i64 {
        let t = k as f64 / 100.0;
        let q = &follower[(k.max(0) * 10) as usize];
        let stamp = nanos(t);
        let message = JointState { header: Header { stamp: Time::from_nanos(stamp as u64), frame_id: String::new() }, name: JOINTS.map(String::from).to_vec(), position: q.iter().map(|v| (v / tick).round() * tick).collect(), ..Default::default() };
        messages.push((stamp, states, message.to_bytes()));
    }
    let arm: Vec<String> = JOINTS[..5].iter().map(|s| s.to_string()).collect();
    let at = |t: f64, joints: usize| commands()[..joints].iter().map(|m| m.q(t)).collect::<Vec<f64>>();
    match commands_as {
        CommandsAs::ControllerState => {
            for k in 0..=(SECONDS * 200.0) as i64 {
                let t = k as f64 / 200.0;
                let stamp = nanos(t);
                let point = |positions: Vec<f64>| JointTrajectoryPoint { positions, ..Default::default() };
                let message = JointTrajectoryControllerState {
                    header: Header { stamp: Time::from_nanos(stamp as u64), frame_id: String::new() },
                    joint_names: arm.clone(),
                    reference: point(at(t, 5)),
                    desired: point(at(t, 5)),
                    feedback: point(follower[(t * 1e3).round() as usize][..5].to_vec()),
                    ..Default::default()
                };
                messages.push((stamp + 200_000, controller, message.to_bytes()));
            }
        }
        CommandsAs::Trajectory => {
            let last = (SECONDS * 30.0) as i64;
            for m in 0..=last {
                let t = m as f64 / 30.0;
                let ahead = |ms: u32| JointTrajectoryPoint { positions: at(t, 6).iter().map(|q| q + 0.2).collect(), time_from_start: Time { sec: 0, nanosec: ms * 1_000_000 }, ..Default::default() };
                let mut points = vec![JointTrajectoryPoint { positions: at(t, 6), ..Default::default() }];
                if m < last {
                    points.extend([ahead(50), ahead(100)]);
                }
                let message = JointTrajectory { header: Header::default(), joint_names: JOINTS.map(String::from).to_vec(), points };
                messages.push((nanos(t), controller, message.to_bytes()));
            }
        }
        CommandsAs::PositionArray => {
            for k in 0..=(SECONDS * 100.0) as i64 {
                let t = k as f64 / 100.0;
                let data = ARRAY_JOINTS.iter().map(|name| commands()[JOINTS.iter().position(|j| j == name).unwrap()].q(t)).collect();
                messages.push((nanos(t), controller, Float64MultiArray { data, ..Default::default() }.to_bytes()));
            }
        }
    }
    messages.sort_by_key(|(t, _, _)| *t);
    for (sequence, (log_time, channel_id, data)) in messages.iter().enumerate() {
        let header = mcap::records::MessageHeader { channel_id: *channel_id, sequence: sequence as u32, log_time: *log_time as u64, publish_time: *log_time as u64 };
        writer.write_to_known_channel(&header, data).unwrap();
    }
    writer.finish().unwrap();
    path
}

fn replay_forward(bag: &Path, dir: &Path, payload: f64, from: &CommandSource) -> (ForwardReplay, Vec<String>) {
    let model = load_urdf(&so101()).unwrap();
    let source = Source::open(bag, None).unwrap();
    let (commands, observed) = source.read_forward(0, "observation.state", from).unwrap();
    let map = JointMap::builtin(source.kind(), &model, &observed).expect("a bag's columns are named by joint");
    let replayer = Replayer::new(model, &ReplayOptions { payload, motors: Some(motors()), ..Default::default() }, map).unwrap();
    let options = ForwardOptions { motors: motors(), payload, tool: None, schedule: dir.join(format!("commands_{payload}.csv")), recordings: None, latency: Some(armscope::replay::forward::Latency::given(0.0, "a controller's set point")), trace: None, without_floor: false, off_elsewhere: Vec::new() };
    (forward(&replayer, &options, &commands, &observed).unwrap(), commands.notices)
}

fn gap(replay: &ForwardReplay, joint: &str) -> f64 {
    replay.joints.iter().find(|g| g.joint == joint).unwrap().gap_mae
}

#[test]
fn a_bags_trajectory_controller_commands_drive_the_arm_to_its_recorded_follower() {
    let dir = tempfile::tempdir().unwrap();
    let real = follower(dir.path(), PAYLOAD);
    for commands_as in [CommandsAs::ControllerState, CommandsAs::Trajectory, CommandsAs::PositionArray] {
        let (name, from) = match commands_as {
            CommandsAs::ControllerState => ("controller_state.mcap", CommandSource::default()),
            CommandsAs::Trajectory => ("joint_trajectory.mcap", CommandSource::default()),
            CommandsAs::PositionArray => ("position_array.mcap", CommandSource { topic: None, joints: Some(ARRAY_JOINTS.map(String::from).to_vec()) }),
        };
        let path = bag(dir.path(), name, &real, commands_as);
        let (same, notices) = replay_forward(&path, dir.path(), PAYLOAD, &from);
        // the gripper is another controller's in the controller-state bag: sent where the real one
        // was, and not compared
        let compared = if commands_as == CommandsAs::ControllerState { 5 } else { 6 };
        assert_eq!(same.joints.len(), compared, "{name}");
        assert_eq!(same.uncommanded, if compared == 5 { vec!["gripper".to_string()] } else { vec![] }, "{name}");
        // the joint states before the commands start are left out: the replay starts with them
        assert_eq!(same.time.len(), (SECONDS * 100.0) as usize + 1, "{name}");
        assert!(notices.iter().any(|n| n.contains(&format!("{} of /joint_states's samples lie outside the commands", (LEAD_IN * 100.0) as usize))), "{name}: {notices:?}");
        // the encoder's quantum (1.5 mrad) on the recorded follower and the commands' sampling: the
        // same arm meets its follower within 2 mrad on average, as a LeRobot episode's does
        for g in &same.joints[..5] {
            assert!(g.gap_mae < 2e-3, "{name}: {} parts from its follower by {:.2} mrad on average", g.joint, g.gap_mae * 1e3);
            assert!(g.parts_at.is_none(), "{name}: {} parts at {:?}", g.joint, g.parts_at);
        }
        let lift = same.joints.iter().find(|g| g.joint == "shoulder_lift").unwrap();
        assert!(lift.real_tracking_mae > 5.0 * lift.gap_mae, "{name}: the follower's own lag ({:.2} mrad) dwarfs the model's gap ({:.2} mrad)", lift.real_tracking_mae * 1e3, lift.gap_mae * 1e3);
        match commands_as {
            CommandsAs::ControllerState => {
                assert!(notices.iter().any(|n| n.contains("JointTrajectoryControllerState's reference")), "{notices:?}");
                assert!(notices.iter().any(|n| n.contains("no command for gripper")), "{notices:?}");
            }
            CommandsAs::PositionArray => {
                assert!(notices.iter().any(|n| n.contains("Float64MultiArrays for gripper, wrist_roll") && n.contains("each held until the next")), "{notices:?}");
                // in the controller's order, each joint got its own command
                let exact: Vec<f64> = same.time.iter().map(|&t| commands()[0].q(t)).collect();
                assert!(same.commanded[0].iter().zip(&exact).all(|(c, e)| (c - e).abs() < 1e-12), "shoulder_pan's command is the array's last value");
            }
            CommandsAs::Trajectory => {
                // the look-ahead points each newer message replaces were never followed
                let commanded_lift = &same.commanded[1];
                let exact: Vec<f64> = same.time.iter().map(|&t| commands()[1].q(t)).collect();
                let worst = commanded_lift.iter().zip(&exact).map(|(c, e)| (c - e).abs()).fold(0.0, f64::max);
                assert!(worst < 1e-3, "shoulder_lift's command strays {worst} rad from the stream's first points");
            }
        }
    }
    // 0.2 kg left out: the shoulder that holds it sags less in the model than in reality
    let path = dir.path().join("controller_state.mcap");
    let (same, _) = replay_forward(&path, dir.path(), PAYLOAD, &CommandSource::default());
    let (without, _) = replay_forward(&path, dir.path(), 0.0, &CommandSource::default());
    assert!(gap(&without, "shoulder_lift") > 3.0 * gap(&same, "shoulder_lift") + 1e-3, "shoulder_lift: gap {:.2} mrad without the payload, {:.2} with it", gap(&without, "shoulder_lift") * 1e3, gap(&same, "shoulder_lift") * 1e3);
}

#[test]
fn forward_replay_of_a_bag_from_the_command_line_names_its_recordings_and_its_topic() {
    let dir = tempfile::tempdir().unwrap();
    let real = follower(dir.path(), PAYLOAD);
    let path = bag(dir.path(), "arm_run.mcap", &real, CommandsAs::ControllerState);
    let (urdf, motor_file) = (so101(), motors());
    let armscope = |extra: &[&str]| {
        let mut args = vec!["replay", path.to_str().unwrap(), "--urdf", urdf.to_str().unwrap(), "--motors", motor_file.to_str().unwrap(), "--payload", "0.2", "--forward"];
        args.extend(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_armscope")).args(&args).current_dir(dir.path()).output().unwrap()
    };
    let json = dir.path().join("forward.json");
    let out = armscope(&["--summary-json", json.to_str().unwrap(), "--no-rrd"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("shoulder_lift") && stdout.contains("gap model − real"), "{stdout}");
    assert!(stdout.contains("gripper: no command; sent where the real joint was, not compared"), "{stdout}");
    assert!(stderr.contains("commands from control_msgs/msg/JointTrajectoryControllerState's reference on /arm_controller/controller_state"), "{stderr}");
    assert!(dir.path().join("recordings/forward_arm_run.mcap").exists());
    // the schedule the simulated arm followed, beside its recordings: t and a column per joint
    let schedule = common::read_csv(&dir.path().join("recordings/forward_arm_run_commands.csv"));
    assert_eq!((schedule.header.len(), schedule.column("t").len()), (7, 601));
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(doc["episodes"][0]["joints"][1]["gap_mae"].as_f64().unwrap() < 2e-3);
    assert_eq!(doc["episodes"][0]["uncommanded"], serde_json::json!(["gripper"]));
    // a topic with no commands on it, and a bag with none at all: one line naming the flag
    let out = armscope(&["--command-topic", "/joint_states", "--no-rrd", "--no-mcap"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.lines().last().unwrap().contains("--command-topic") && err.contains("/arm_controller/controller_state"), "{err}");
    let states_only = common::repo().join("tests/fixtures/ros2/joint_states_effort.mcap");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["replay", states_only.to_str().unwrap(), "--urdf", so101().to_str().unwrap(), "--motors", motors().to_str().unwrap(), "--forward", "--no-rrd", "--no-mcap"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("--forward") && err.contains("JointTrajectoryControllerState"), "{err}");
}

/// `tests/fixtures/ros2/controller_commands.mcap`, written by mcap-ros2-support (`make_commands.py`
/// beside it): the same set points as Foxy's, Humble's and Jazzy's controller states lay them out
/// (each with its own schema) and as a zero-stamped trajectory stream, with the wrong fields
/// (`feedback`, `actual`) one radian off.
#[test]
fn every_distributions_controller_state_and_a_trajectory_give_the_set_points_an_independent_writer_wrote() {
    let path = common::repo().join("tests/fixtures/ros2/controller_commands.mcap");
    let Source::Bag(bag) = Source::open(&path, None).unwrap() else { panic!("a bag") };
    let epoch = 1_764_000_000_000_000_000i64;
    for (topic, what) in [
        ("/foxy_controller/controller_state", "JointTrajectoryControllerState's desired"),
        ("/humble_controller/controller_state", "JointTrajectoryControllerState's desired"),
        ("/jazzy_controller/controller_state", "JointTrajectoryControllerState's reference"),
        ("/arm_controller/joint_trajectory", "JointTrajectory's points"),
        ("/forward_position_controller/commands", "Float64MultiArrays for wrist_roll, wrist_flex"),
    ] {
        // the array's joints in its controller's order (reversed), as the user gives them
        let array = topic.starts_with("/forward");
        let joints: Vec<String> = if array { JOINTS[..5].iter().rev().map(|s| s.to_string()).collect() } else { JOINTS[..5].iter().map(|s| s.to_string()).collect() };
        let commands = armscope::motion::commands::read(&bag, &CommandSource { topic: Some(topic.to_string()), joints: array.then(|| joints.clone()) }).unwrap();
        assert!(commands.what.contains(what), "{topic}: {}", commands.what);
        assert_eq!(commands.joints, joints, "{topic}");
        assert_eq!(commands.stamps.len(), 201, "{topic}");
        for (k, &stamp) in commands.stamps.iter().enumerate() {
            // stamped (or, zero-stamped, logged) every 10 ms from the epoch
            assert_eq!(stamp, epoch + k as i64 * 10_000_000, "{topic}");
            let t = (stamp - epoch) as f64 * 1e-9;
            for (c, joint) in commands.positions.iter().enumerate() {
                let j = JOINTS.iter().position(|name| *name == commands.joints[c]).unwrap();
                let set_point = 0.1 * j as f64 + 0.3 * (1.3 * t + j as f64).sin();
                assert!((joint[k] - set_point).abs() < 1e-12, "{topic}: joint {j} at {t} s: {} against {set_point}", joint[k]);
            }
        }
    }
    // five command topics: which one is for the user to say
    let err = armscope::motion::commands::read(&bag, &CommandSource::default()).unwrap_err().to_string();
    assert!(err.contains("--command-topic") && err.contains("several command topics"), "{err}");
    // an array names no joints: without them, or with too few, one line naming the flag
    let arrays = |joints: Option<Vec<String>>| armscope::motion::commands::read(&bag, &CommandSource { topic: Some("/forward_position_controller/commands".into()), joints }).unwrap_err().to_string();
    assert!(arrays(None).contains("--command-joints"), "{}", arrays(None));
    let too_few = arrays(Some(vec!["shoulder_pan".into()]));
    assert!(too_few.contains("--command-joints") && too_few.contains("sends 5 positions"), "{too_few}");
}
