//! ROS 2's CDR as armscope reads and writes it, against a bag written by mcap-ros2-support
//! (`tests/fixtures/ros2/joint_tf_string.mcap`, made by `make_fixture.py` beside it): armscope's
//! decoder gets the values that script wrote, and armscope's encoder writes the same bytes for
//! them; and a run recorded with `--mcap-encoding ros2` as a ROS 2 reader sees it.

mod common;

use armscope::ros2::Message;
use armscope::ros2::messages::{Header, JointState, Pose, Quaternion, StringMessage, TfMessage, Time, TransformStamped, Vector3};
use std::collections::BTreeMap;

fn fixture() -> Vec<u8> {
    std::fs::read(common::repo().join("tests/fixtures/ros2/joint_tf_string.mcap")).unwrap()
}

/// Each topic's messages, as raw bytes.
fn messages(bytes: &[u8]) -> BTreeMap<String, Vec<Vec<u8>>> {
    let mut out: BTreeMap<String, Vec<Vec<u8>>> = BTreeMap::new();
    for m in mcap::MessageStream::new(bytes).unwrap() {
        let m = m.unwrap();
        out.entry(m.channel.topic.clone()).or_default().push(m.data.to_vec());
    }
    out
}

fn expected_joint_state() -> JointState {
    JointState {
        header: Header { stamp: Time { sec: 1700000000, nanosec: 123456789 }, frame_id: "base".into() },
        name: vec!["shoulder_pan".into(), "elbow_flex".into(), "wrist_roll".into()],
        position: vec![0.5, -1.25, 3.0e-7],
        velocity: vec![0.0, 2.5, -0.125],
        effort: vec![1.5, -0.75, 0.0625],
    }
}

fn expected_tf() -> TfMessage {
    let header = |frame: &str| Header { stamp: Time { sec: 1700000000, nanosec: 5 }, frame_id: frame.into() };
    TfMessage {
        transforms: vec![
            TransformStamped { header: header("world"), child_frame_id: "link1".into(), transform: Pose { position: Vector3 { x: 0.1, y: -0.2, z: 0.3 }, orientation: Quaternion { x: 0.0, y: 0.0, z: 0.38268343236508984, w: 0.9238795325112867 } } },
            TransformStamped { header: header("link1"), child_frame_id: "tool".into(), transform: Pose { position: Vector3 { x: 0.0, y: 0.0, z: 0.05 }, orientation: Quaternion::default() } },
        ],
    }
}

#[test]
fn armscope_decodes_what_mcap_ros2_support_wrote() {
    let m = messages(&fixture());
    assert_eq!(JointState::decode(&m["/joint_states"][0]).unwrap(), expected_joint_state());
    assert_eq!(TfMessage::decode(&m["/tf"][0]).unwrap(), expected_tf());
    assert_eq!(StringMessage::decode(&m["/robot_description"][0]).unwrap().data, "<robot name=\"fixture\"/>");
}

#[test]
fn armscope_encodes_the_same_bytes_as_mcap_ros2_support() {
    let m = messages(&fixture());
    assert_eq!(expected_joint_state().to_bytes(), m["/joint_states"][0]);
    assert_eq!(expected_tf().to_bytes(), m["/tf"][0]);
    assert_eq!(StringMessage { data: "<robot name=\"fixture\"/>".into() }.to_bytes(), m["/robot_description"][0]);
}

#[test]
fn the_fixtures_definitions_are_armscopes() {
    // the complete definitions mcap-ros2-support wrote (ROS 2 Humble's, spelled out by the script)
    // parse to the same fields as armscope's: compared line by line without separators and blank lines
    let bytes = fixture();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let lines = |text: &str| text.lines().filter(|l| !l.is_empty() && !l.starts_with("===")).map(str::to_string).collect::<std::collections::BTreeSet<_>>();
    for schema in summary.schemas.values() {
        let ours = armscope::ros2::definitions::full_definition(&schema.name).unwrap();
        assert_eq!(lines(std::str::from_utf8(&schema.data).unwrap()), lines(&ours), "{}", schema.name);
    }
}

#[test]
fn a_ros2_recording_is_a_rosbag2_bag() {
    // the default run for 0.2 s: profile ros2, every channel CDR with a ros2msg schema and QoS, and
    // /joint_states' values the trace's at every step
    let dir = tempfile::tempdir().unwrap();
    let (mcap_path, trace) = (dir.path().join("r.mcap"), dir.path().join("t.csv"));
    let code = common::armscope(&["run", "--quiet", "--duration", "0.2", "--mcap-encoding", "ros2", "--mcap", mcap_path.to_str().unwrap(), "--no-rrd", "--trace", trace.to_str().unwrap()]);
    assert_eq!(code, 0);
    let bytes = std::fs::read(&mcap_path).unwrap();
    // the header's profile: magic, then the header record (op 0x01, length, profile string)
    let profile_len = u32::from_le_bytes(bytes[17..21].try_into().unwrap()) as usize;
    assert_eq!(&bytes[21..21 + profile_len], b"ros2");
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    for channel in summary.channels.values() {
        assert_eq!(channel.message_encoding, "cdr", "{}", channel.topic);
        let schema = channel.schema.as_ref().unwrap();
        assert_eq!(schema.encoding, "ros2msg", "{}", channel.topic);
        assert_eq!(std::str::from_utf8(&schema.data).unwrap(), armscope::ros2::definitions::full_definition(&schema.name).unwrap());
        assert!(channel.metadata["offered_qos_profiles"].starts_with("- history: 1\n  depth: "), "{}", channel.topic);
    }
    let topics: Vec<&str> = summary.channels.values().map(|c| c.topic.as_str()).collect();
    for topic in ["/joint_states", "/tf", "/tf_static", "/robot_description", "/tool/pose", "/tool/path", "/tool/commanded_path", "/robot/geometry", "/controller"] {
        assert!(topics.contains(&topic), "{topic} in {topics:?}");
    }
    let table = common::read_csv(&trace);
    let m = messages(&bytes);
    let states: Vec<JointState> = m["/joint_states"].iter().map(|b| JointState::decode(b).unwrap()).collect();
    assert_eq!(states.len(), table.rows.len());
    for (state, row) in states.iter().zip(&table.rows) {
        assert_eq!(state.name, ["J1", "J2", "J3", "J4", "J5", "J6"]);
        assert_eq!(state.position, row[1..7]);
        assert_eq!(state.velocity, row[7..13]);
        assert_eq!(state.effort, row[25..31]);
    }
    // the header stamps are the log times
    let stream: Vec<_> = mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap()).filter(|m| m.channel.topic == "/joint_states").collect();
    for (m, state) in stream.iter().zip(&states) {
        assert_eq!(state.header.stamp.nanos() as u64, m.log_time);
    }
    // /controller's telemetry decodes back to the trace's torques
    let first = armscope::recorder::decode_controller_telemetry(&m["/controller"][1]).unwrap();
    assert_eq!(first.torque, table.rows[1][25..31]);
    assert_eq!(StringMessage::decode(&m["/robot_description"][0]).unwrap().data, std::fs::read_to_string(common::box_urdf()).unwrap());
}
