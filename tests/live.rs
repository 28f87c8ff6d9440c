//! Live streams, received as a viewer would receive them while the run goes: Foxglove's WebSocket
//! protocol read by a plain WebSocket client (the protocol's JSON and binary frames parsed here),
//! and Rerun's gRPC stream received by Rerun's own in-process server.

mod common;

use foxglove::messages::{FrameTransforms, JointStates};
use prost::Message as _;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::net::TcpListener;
use std::process::{Child, Command};
use std::time::{Duration, Instant};
use tungstenite::client::IntoClientRequest;

/// A port nobody listens on right now.
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// Kills the run if the test fails before it ends.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn spawn_run(args: &[&str]) -> Running {
    let dir = tempfile::tempdir().unwrap();
    Running(Command::new(env!("CARGO_BIN_EXE_armscope")).arg("run").args(args).current_dir(dir.path()).spawn().unwrap())
}

type Socket = tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<std::net::TcpStream>>;

fn connect_foxglove(port: u16) -> Socket {
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let mut request = format!("ws://127.0.0.1:{port}/").into_client_request().unwrap();
        request.headers_mut().insert("sec-websocket-protocol", "foxglove.sdk.v1".parse().unwrap());
        match tungstenite::connect(request) {
            Ok((socket, response)) => {
                assert_eq!(response.headers()["sec-websocket-protocol"], "foxglove.sdk.v1");
                if let tungstenite::stream::MaybeTlsStream::Plain(tcp) = socket.get_ref() {
                    tcp.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
                }
                return socket;
            }
            Err(_) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(50)),
            Err(e) => panic!("no Foxglove server on port {port}: {e}"),
        }
    }
}

#[test]
fn foxglove_clients_get_the_mcaps_channels_and_messages_live() {
    let port = free_port();
    let address = format!("127.0.0.1:{port}");
    // paced, so that the run is still going while the client subscribes
    let _run = spawn_run(&["--quiet", "--duration", "4", "--realtime", "1", "--no-rrd", "--no-mcap", "--foxglove", &address]);
    let mut socket = connect_foxglove(port);

    // serverInfo, then the advertised channels
    let mut channels: BTreeMap<u64, (String, String, String)> = BTreeMap::new();
    while channels.len() < 8 {
        let msg = socket.read().expect("server messages");
        if let tungstenite::Message::Text(text) = msg {
            let v: Value = serde_json::from_str(&text).unwrap();
            if v["op"] == "advertise" {
                for c in v["channels"].as_array().unwrap() {
                    let field = |k: &str| c[k].as_str().unwrap().to_string();
                    channels.insert(c["id"].as_u64().unwrap(), (field("topic"), field("schemaName"), field("encoding")));
                }
            }
        }
    }
    let topics: BTreeMap<&str, (&str, &str)> = channels.values().map(|(t, s, e)| (t.as_str(), (s.as_str(), e.as_str()))).collect();
    let expected = [
        ("/tf", ("foxglove.FrameTransforms", "protobuf")),
        ("/robot/geometry", ("foxglove.SceneUpdate", "protobuf")),
        ("/joint_states", ("foxglove.JointStates", "protobuf")),
        ("/controller", ("armscope.ControllerTelemetry", "protobuf")),
        ("/tool/pose", ("foxglove.PoseInFrame", "protobuf")),
        ("/tool/path", ("foxglove.SceneUpdate", "protobuf")),
        ("/tool/commanded_path", ("foxglove.SceneUpdate", "protobuf")),
        ("/robot_description", ("std_msgs/msg/String", "cdr")),
    ];
    assert_eq!(topics, expected.into_iter().collect(), "the MCAP's channels, with the same schemas and encodings");

    // subscribe to every channel, subscription id = channel id
    let subscriptions: Vec<Value> = channels.keys().map(|id| serde_json::json!({ "id": id, "channelId": id })).collect();
    socket.send(tungstenite::Message::Text(serde_json::json!({ "op": "subscribe", "subscriptions": subscriptions }).to_string().into())).unwrap();

    // binary frames: opcode 1, subscription id (u32), log time (u64), payload
    let mut by_topic: BTreeMap<String, Vec<(u64, Vec<u8>)>> = BTreeMap::new();
    let deadline = Instant::now() + Duration::from_secs(20);
    while by_topic.get("/controller").map_or(0, Vec::len) < 300 || !by_topic.contains_key("/robot_description") {
        assert!(Instant::now() < deadline, "messages so far: {:?}", by_topic.iter().map(|(t, m)| (t, m.len())).collect::<Vec<_>>());
        let tungstenite::Message::Binary(data) = socket.read().expect("message data") else { continue };
        assert_eq!(data[0], 1, "message data opcode");
        let subscription = u32::from_le_bytes(data[1..5].try_into().unwrap()) as u64;
        let time = u64::from_le_bytes(data[5..13].try_into().unwrap());
        by_topic.entry(channels[&subscription].0.clone()).or_default().push((time, data[13..].to_vec()));
    }
    // the URDF reached a client that subscribed after it was published (latched)
    let description = armscope::recorder::decode_robot_description(&by_topic["/robot_description"][0].1).expect("a CDR std_msgs/String");
    assert!(description.contains("<robot") && description.contains("upper_arm_link"));
    // consecutive control steps, 1 ms apart in log time, decoded as Foxglove decodes them
    let controller = &by_topic["/controller"];
    for pair in controller.windows(2) {
        assert_eq!(pair[1].0 - pair[0].0, 1_000_000, "one control period between messages");
    }
    let joints = JointStates::decode(&by_topic["/joint_states"][0].1[..]).unwrap();
    assert_eq!(joints.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>(), ["J1", "J2", "J3", "J4", "J5", "J6"]);
    let tf = by_topic["/tf"].iter().map(|m| FrameTransforms::decode(&m.1[..]).unwrap()).find(|t| t.transforms.len() == 6).expect("moving joints' transforms");
    let children: BTreeSet<&str> = tf.transforms.iter().map(|t| t.child_frame_id.as_str()).collect();
    assert!(children.contains("tool_link"));
}

#[test]
fn a_foxglove_address_that_is_taken_is_a_clear_error() {
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let address = taken.local_addr().unwrap().to_string();
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).args(["run", "--quiet", "--duration", "0.1", "--no-rrd", "--no-mcap", "--foxglove", &address]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--foxglove") && err.contains(&address), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
}

#[test]
fn a_rerun_viewer_receives_the_run_live() {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build().unwrap();
    let _guard = runtime.enter();
    let port = free_port();
    let addr: std::net::SocketAddr = format!("127.0.0.1:{port}").parse().unwrap();
    let (_shutdown_tx, shutdown) = re_grpc_server::shutdown::shutdown();
    let (rx, _proxy) = re_grpc_server::spawn_with_recv(addr, Default::default(), shutdown);
    let url = format!("rerun+http://127.0.0.1:{port}/proxy");
    let status = Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--quiet", "--duration", "0.5", "--no-rrd", "--no-mcap", "--connect", &url])
        .current_dir(tempfile::tempdir().unwrap().path())
        .status()
        .unwrap();
    assert!(status.success());
    // every step of J2's angle and target arrives, in the stream's chunks
    let mut rows = 0;
    let mut entities = BTreeSet::new();
    let deadline = Instant::now() + Duration::from_secs(20);
    let wanted = ["/world/robot/upper_arm_link", "/tool/position", "/config"];
    while (rows < 501 || !wanted.iter().all(|e| entities.contains(*e))) && Instant::now() < deadline {
        let Ok(msg) = rx.recv_timeout(Duration::from_millis(200)) else { continue };
        let Some(re_log_channel::DataSourceMessage::LogMsg(re_log_types::LogMsg::ArrowMsg(store, arrow))) = msg.into_data() else { continue };
        if !store.is_recording() {
            continue;
        }
        let chunk = re_chunk::Chunk::from_arrow_msg(&arrow).unwrap();
        entities.insert(chunk.entity_path().to_string());
        if chunk.entity_path().to_string() == "/joints/J2/position" && !chunk.is_static() {
            rows += chunk.num_rows();
        }
    }
    assert_eq!(rows, 501, "one row per control step of a 0.5 s run");
    for entity in wanted {
        assert!(entities.contains(entity), "{entity} in the live stream: {entities:?}");
    }
}
