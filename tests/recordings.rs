//! Recordings read back by readers independent of the code that wrote them: the `.mcap` through
//! the mcap crate (Foxglove's schemas through the official Foxglove types, armscope's own through
//! prost-reflect and the schema embedded in the file, as Foxglove decodes it), the
//! `.rrd` through Rerun's own decoder and chunk types (`common::rrd`), compared value by value with
//! the run's own per-step trace.

mod common;

use common::rrd::Rrd;
use common::{Table, read_csv, repo};
use foxglove::messages::{FrameTransforms, JointStates, PoseInFrame};
use prost::Message as _;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Run the armscope binary; returns (exit code, stdout, stderr).
fn armscope(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).args(args).current_dir(repo()).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

struct Run {
    _dir: tempfile::TempDir,
    rrd: PathBuf,
    mcap: PathBuf,
    trace: Table,
}

fn record(extra: &[&str]) -> Run {
    let dir = tempfile::tempdir().unwrap();
    let (rrd, mcap, trace) = (dir.path().join("run.rrd"), dir.path().join("run.mcap"), dir.path().join("trace.csv"));
    let mut args = vec!["run", "--quiet", "--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap(), "--trace", trace.to_str().unwrap()];
    args.extend_from_slice(extra);
    let (code, _, err) = armscope(&args);
    assert_eq!(code, 0, "{err}");
    Run { trace: read_csv(&trace), rrd, mcap, _dir: dir }
}

/// Every message of the file, by topic: (log time ns, schema name, encoding, payload).
fn mcap_messages(path: &Path) -> BTreeMap<String, Vec<(u64, String, String, Vec<u8>)>> {
    let bytes = std::fs::read(path).unwrap();
    let mut by_topic: BTreeMap<String, Vec<_>> = BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.expect("readable message");
        let schema = m.channel.schema.as_ref().map_or(String::new(), |s| s.name.clone());
        by_topic.entry(m.channel.topic.clone()).or_default().push((m.log_time, schema, m.channel.message_encoding.clone(), m.data.to_vec()));
    }
    by_topic
}

/// Every chunk's CRC of its records, then the data section's CRC (0: not computed).
fn chunk_and_data_crcs(path: &Path) -> Vec<u32> {
    let bytes = std::fs::read(path).unwrap();
    let mut crcs = Vec::new();
    for record in mcap::read::LinearReader::new(&bytes).unwrap() {
        match record.unwrap() {
            mcap::records::Record::Chunk { header, .. } => crcs.push(header.uncompressed_crc),
            mcap::records::Record::DataEnd(end) => crcs.push(end.data_section_crc),
            _ => {}
        }
    }
    assert!(crcs.len() >= 2, "chunks and the data end");
    crcs
}

fn col(trace: &Table, prefix: &str, j: usize) -> Vec<f64> {
    trace.column(&format!("{prefix}{}", j + 1))
}

#[test]
fn mcap_has_the_channels_schemas_and_per_step_messages_and_equals_the_trace() {
    let run = record(&["--duration", "1.5", "--no-rrd"]);
    let steps = run.trace.rows.len();
    assert_eq!(steps, 1501);
    let topics = mcap_messages(&run.mcap);
    // the 3D poses at the display rate, 100 Hz: every 10th step and the last
    let pose_steps = (steps - 1).div_ceil(10) + 1;
    let expect = [
        ("/tf", "foxglove.FrameTransforms", "protobuf", Some(pose_steps)),
        ("/joint_states", "foxglove.JointStates", "protobuf", Some(steps)),
        ("/controller", "armscope.ControllerTelemetry", "protobuf", Some(steps)),
        // the pose at the display rate of the path, 50 Hz: every 20th step and the last
        ("/tool/pose", "foxglove.PoseInFrame", "protobuf", Some(steps.div_ceil(20))),
        ("/robot/geometry", "foxglove.SceneUpdate", "protobuf", None),
        ("/tool/path", "foxglove.SceneUpdate", "protobuf", None),
        ("/tool/commanded_path", "foxglove.SceneUpdate", "protobuf", Some(1)),
        // the ROS convention by which Foxglove's URDF layer and Rerun's MCAP importer find the robot
        ("/robot_description", "std_msgs/msg/String", "cdr", Some(1)),
    ];
    for (topic, schema, encoding, count) in expect {
        let msgs = topics.get(topic).unwrap_or_else(|| panic!("no {topic}"));
        assert_eq!(msgs[0].1, schema, "{topic} schema");
        assert_eq!(msgs[0].2, encoding, "{topic} encoding");
        // the per-step topics carry one message per step (/tf per pose step, with the fixed joints
        // once a second on top)
        if let Some(n) = count {
            let per_step = if topic == "/tf" { msgs.iter().filter(|m| FrameTransforms::decode(&m.3[..]).unwrap().transforms.len() == 6).count() } else { msgs.len() };
            assert_eq!(per_step, n, "{topic} messages");
        }
    }
    let description = armscope::recorder::decode_robot_description(&topics["/robot_description"][0].3).expect("CDR std_msgs/String");
    assert_eq!(description, std::fs::read_to_string(repo().join("assets/smallrobot_arm.urdf")).unwrap(), "the URDF text");
    let schema_names: Vec<String> = topics.values().map(|m| m[0].1.clone()).collect();
    assert!(schema_names.iter().all(|n| !n.contains("::")), "schema names without Rust paths: {schema_names:?}");
    // timestamps: start time + simulation time, exactly one control period apart
    let controller = &topics["/controller"];
    let t0 = controller[0].0;
    for (k, m) in controller.iter().enumerate() {
        assert_eq!(m.0 - t0, k as u64 * 1_000_000, "log time of step {k}");
    }
    // decoded through the schema the file carries (as Foxglove does), the values equal the trace
    let bytes = std::fs::read(&run.mcap).unwrap();
    let schema = mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap()).find(|m| m.channel.topic == "/controller").unwrap().channel.schema.clone().unwrap();
    assert_eq!(schema.encoding, "protobuf");
    let pool = prost_reflect::DescriptorPool::decode(&schema.data[..]).expect("a FileDescriptorSet");
    let descriptor = pool.get_message_by_name(&schema.name).expect("the schema names its message");
    for (k, m) in controller.iter().enumerate() {
        let v = prost_reflect::DynamicMessage::decode(descriptor.clone(), &m.3[..]).unwrap();
        let list = |field: &str| v.get_field_by_name(field).unwrap().as_list().unwrap().to_vec();
        assert_eq!(v.get_field_by_name("time").unwrap().as_f64().unwrap(), run.trace.rows[k][0]);
        let tool: Vec<f64> = list("tool_position").iter().map(|x| x.as_f64().unwrap()).collect();
        assert_eq!(tool, ["x", "y", "z"].map(|a| run.trace.rows[k][run.trace.col(a)]), "tool position step {k}");
        for j in 0..6 {
            let get = |field: &str| list(field)[j].as_f64().unwrap();
            assert_eq!(get("target"), col(&run.trace, "cmd", j)[k], "target J{} step {k}", j + 1);
            assert_eq!(get("torque"), col(&run.trace, "u", j)[k]);
            assert_eq!(get("tau_g"), col(&run.trace, "tau_g", j)[k]);
            assert_eq!(get("error"), col(&run.trace, "cmd", j)[k] - col(&run.trace, "q", j)[k]);
            let effort = [8.0, 12.0, 8.0, 5.0, 3.0, 1.5][j];
            assert_eq!(list("saturated")[j].as_u32().unwrap() == 1, col(&run.trace, "u", j)[k].abs() == effort);
        }
    }
    for (k, m) in topics["/joint_states"].iter().enumerate() {
        let js = JointStates::decode(&m.3[..]).unwrap();
        assert_eq!(js.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>(), ["J1", "J2", "J3", "J4", "J5", "J6"]);
        for (j, state) in js.joints.iter().enumerate() {
            assert_eq!(state.position, Some(col(&run.trace, "q", j)[k]));
            assert_eq!(state.velocity, Some(col(&run.trace, "qd", j)[k]));
            assert_eq!(state.effort, Some(col(&run.trace, "u", j)[k]));
        }
    }
    for (i, m) in topics["/tool/pose"].iter().enumerate() {
        let k = ((m.0 - t0) / 1_000_000) as usize;
        assert!(k % 20 == 0 || k == steps - 1, "pose {i} at step {k}");
        let p = PoseInFrame::decode(&m.3[..]).unwrap().pose.unwrap().position.unwrap();
        for (got, name) in [(p.x, "x"), (p.y, "y"), (p.z, "z")] {
            assert_eq!(got, run.trace.rows[k][run.trace.col(name)], "tool {name} step {k}");
        }
    }
    // chaining /tf from world to tool_link reproduces the tool position (the transforms are right)
    let fixed = FrameTransforms::decode(&topics["/tf"].iter().find(|m| FrameTransforms::decode(&m.3[..]).unwrap().transforms.len() != 6).unwrap().3[..]).unwrap();
    assert_eq!(fixed.transforms[0].parent_frame_id, "world");
    assert_eq!(fixed.transforms[0].child_frame_id, "base_link");
    let moving: Vec<_> = topics["/tf"].iter().filter(|m| FrameTransforms::decode(&m.3[..]).unwrap().transforms.len() == 6).collect();
    for m in &moving {
        let k = ((m.0 - t0) / 1_000_000) as usize;
        assert!(k % 10 == 0 || k == steps - 1, "/tf at step {k}");
    }
    let last = moving.last().unwrap();
    assert_eq!(((last.0 - t0) / 1_000_000) as usize, steps - 1, "the last step's pose is there");
    let tf = FrameTransforms::decode(&last.3[..]).unwrap();
    let chain: Vec<(&str, &str)> = tf.transforms.iter().map(|t| (t.parent_frame_id.as_str(), t.child_frame_id.as_str())).collect();
    assert_eq!(chain, [("base_link", "carrier_link"), ("carrier_link", "upper_arm_link"), ("upper_arm_link", "forearm_link"), ("forearm_link", "wrist1_link"), ("wrist1_link", "wrist2_link"), ("wrist2_link", "tool_link")]);
    let mut pose = nalgebra::Isometry3::identity();
    for t in &tf.transforms {
        let (tr, r) = (t.translation.unwrap(), t.rotation.unwrap());
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(r.w, r.x, r.y, r.z));
        pose *= nalgebra::Isometry3::from_parts(nalgebra::Translation3::new(tr.x, tr.y, tr.z), q);
    }
    let k = run.trace.rows.len() - 1;
    for (a, name) in ["x", "y", "z"].iter().enumerate() {
        let want = run.trace.rows[k][run.trace.col(name)];
        assert!((pose.translation.vector[a] - want).abs() < 1e-12, "tf chain {name}: {} vs {want}", pose.translation.vector[a]);
    }
    // chunks stored as they are (`--compress` zstds them, see below); configuration and summary as metadata
    let bytes = std::fs::read(&run.mcap).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("summary section");
    assert!(!summary.chunk_indexes.is_empty());
    assert!(summary.chunk_indexes.iter().all(|c| c.compression.is_empty()));
    // the stepper and motor fields are left empty in a run without steppers or motors (as friction's)
    let schema_data = mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap()).find(|m| m.channel.topic == "/controller").unwrap().channel.schema.clone().unwrap();
    let pool = prost_reflect::DescriptorPool::decode(&schema_data.data[..]).unwrap();
    let telemetry = prost_reflect::DynamicMessage::decode(pool.get_message_by_name(&schema_data.name).unwrap(), &topics["/controller"][0].3[..]).unwrap();
    for (field, len) in [("torque", 6), ("torque_limit", 6), ("load_angle", 0), ("lost_steps", 0), ("motor_speed", 0), ("friction", 0)] {
        assert_eq!(telemetry.get_field_by_name(field).unwrap().as_list().unwrap().len(), len, "/controller.{field}");
    }
    // Foxglove refuses to preload a file with a chunk that has no message index
    assert!(summary.chunk_indexes.iter().all(|c| !c.message_index_offsets.is_empty()), "a chunk without message indexes");
    let names: Vec<String> = summary.metadata_indexes.iter().map(|m| m.name.clone()).collect();
    assert_eq!(names, ["armscope.config", "armscope.summary"]);
    let config = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert!(config.metadata["start_time_unix_ns"].parse::<u64>().unwrap() == t0);
    assert!(config.metadata["config"].contains("\"duration\":1.5"));
    let done = mcap::read::metadata(&bytes, &summary.metadata_indexes[1]).unwrap();
    assert!(done.metadata["summary"].contains("\"saturation_percent\""));
}

/// `--compress`: the same recordings, smaller (LZ4 in the `.rrd`, zstd in the `.mcap`'s chunks),
/// read back to the same values.
#[test]
fn compressed_recordings_are_smaller_and_hold_the_same_data() {
    let (plain, packed) = (record(&["--duration", "1"]), record(&["--duration", "1", "--compress"]));
    let size = |p: &Path| std::fs::metadata(p).unwrap().len() as f64;
    // (measured: the .rrd 0.59×, the .mcap 0.64× on this run; 0.54× and 0.64× on the 30 s run)
    assert!(size(&packed.rrd) < 0.8 * size(&plain.rrd), "rrd {} vs {}", size(&packed.rrd), size(&plain.rrd));
    assert!(size(&packed.mcap) < 0.8 * size(&plain.mcap), "mcap {} vs {}", size(&packed.mcap), size(&plain.mcap));
    let summary = mcap::Summary::read(&std::fs::read(&packed.mcap).unwrap()).unwrap().expect("summary section");
    assert!(!summary.chunk_indexes.is_empty() && summary.chunk_indexes.iter().all(|c| c.compression == "zstd"));
    // CRCs with --compress (the mcap crate checks them as it reads, below), none without
    assert_eq!(chunk_and_data_crcs(&packed.mcap).iter().filter(|&&c| c == 0).count(), 0);
    assert!(chunk_and_data_crcs(&plain.mcap).iter().all(|&c| c == 0));
    let (a, b) = (mcap_messages(&plain.mcap), mcap_messages(&packed.mcap));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    // /controller's payloads bit for bit (the other topics' stamps carry each run's wall-clock start)
    let payloads = |m: &BTreeMap<String, Vec<(u64, String, String, Vec<u8>)>>| m["/controller"].iter().map(|x| x.3.clone()).collect::<Vec<_>>();
    assert!(payloads(&a) == payloads(&b));
    for (topic, messages) in &a {
        assert_eq!(messages.len(), b[topic].len(), "{topic}");
    }
    let (a, b) = (Rrd::open(&plain.rrd), Rrd::open(&packed.rrd));
    assert!(b.verify_errors.is_empty(), "{:?}", b.verify_errors);
    for entity in ["/joints/J2/position", "/joints/J4/torque", "/tool/position"] {
        assert_eq!(a.series(entity), b.series(entity), "{entity}");
    }
}

#[test]
fn rrd_holds_every_joint_series_with_one_row_per_step_equal_to_the_trace() {
    let run = record(&["--duration", "1.2", "--no-mcap"]);
    let rrd = Rrd::open(&run.rrd);
    let steps = run.trace.rows.len();
    let t = run.trace.column("t");
    for j in 0..6 {
        let name = format!("J{}", j + 1);
        let (q, cmd, u, tau_g) = (col(&run.trace, "q", j), col(&run.trace, "cmd", j), col(&run.trace, "u", j), col(&run.trace, "tau_g", j));
        let effort = [8.0, 12.0, 8.0, 5.0, 3.0, 1.5][j];
        let saturated = |k: usize| if u[k].abs() == effort { 1.0 } else { 0.0 };
        // each entity: its series per step, in instance order
        let expected: [(&str, Box<dyn Fn(usize) -> Vec<f64>>); 3] = [
            ("position", Box::new(|k| vec![q[k], cmd[k]])),
            ("torque", Box::new(|k| vec![u[k], tau_g[k]])),
            ("status", Box::new(|k| vec![cmd[k] - q[k], saturated(k)])),
        ];
        for (leaf, want) in expected {
            let got = rrd.series(&format!("/joints/{name}/{leaf}"));
            assert_eq!(got.len(), steps, "{name}/{leaf}: one row per step");
            for (k, (time, values)) in got.iter().enumerate() {
                assert!((time - t[k]).abs() < 1e-9, "{name}/{leaf} time {time} vs {}", t[k]);
                let want = want(k);
                assert_eq!(values[..want.len()], want[..], "{name}/{leaf} at step {k}");
            }
        }
    }
    let tool = rrd.series("/tool/position");
    for (a, axis) in ["x", "y", "z"].iter().enumerate() {
        assert_eq!(tool.iter().map(|r| r.1[a]).collect::<Vec<_>>(), run.trace.column(axis), "tool {axis}");
    }
    // a series the run does not record gets no entity (no steppers, motors, friction or heat here)
    let entities = rrd.entities();
    for leaf in ["load_angle", "lost_steps", "motor_speed", "friction", "winding_temperature"] {
        assert!(!entities.keys().any(|e| e.ends_with(&format!("/{leaf}"))), "{leaf}: {:?}", entities.keys().collect::<Vec<_>>());
    }
    assert!(entities.contains_key("/joints/J1/torque_limit") && entities.contains_key("/joints/J1/saturated_torque"));
    // the ±effort lines span the whole run, two rows (a live viewer gets them block by block)
    for (j, effort) in [8.0, 12.0, 8.0, 5.0, 3.0, 1.5].into_iter().enumerate() {
        let lines = rrd.series(&format!("/joints/J{}/torque_limit", j + 1));
        assert_eq!(lines.len(), 2, "J{}", j + 1);
        for ((time, values), want) in lines.iter().zip([t[0], t[steps - 1]]) {
            assert!((time - want).abs() < 1e-9 && *values == [effort, -effort], "J{}: {lines:?}", j + 1);
        }
    }
}

#[test]
fn rrd_poses_every_moving_link_at_the_display_rate_as_the_simulated_arm() {
    use armscope::dynamics::{body_poses, frame_pose_in};
    let run = record(&["--duration", "0.4", "--no-mcap"]);
    let rrd = Rrd::open(&run.rrd);
    let model = armscope::model::load_urdf(&repo().join("assets/smallrobot_arm.urdf")).unwrap();
    let q: Vec<Vec<f64>> = (0..6).map(|j| col(&run.trace, "q", j)).collect();
    let mut poses = vec![armscope::spatial::Pose::identity(); model.joints.len()];
    let moving: Vec<usize> = (0..model.frames.len()).filter(|&f| model.frames[f].body.is_some()).collect();
    assert_eq!(moving.len(), 6);
    let rows: Vec<_> = moving
        .iter()
        .map(|&f| {
            let entity = format!("/world/robot/{}", model.frames[f].name);
            (rrd.component(&entity, "Transform3D:translation"), rrd.component(&entity, "Transform3D:quaternion"))
        })
        .collect();
    // every 10th step (100 Hz) and the last
    let steps = run.trace.rows.len();
    let pose_steps: Vec<usize> = (0..steps).filter(|&k| k % 10 == 0 || k == steps - 1).collect();
    for (i, &k) in pose_steps.iter().enumerate() {
        body_poses(&model, &q.iter().map(|c| c[k]).collect::<Vec<_>>(), &mut poses);
        for (&f, (translations, rotations)) in moving.iter().zip(&rows) {
            let want = frame_pose_in(&model, &poses, f);
            let name = &model.frames[f].name;
            assert_eq!((translations.len(), rotations.len()), (pose_steps.len(), pose_steps.len()), "{name}: one pose per display step");
            assert!((translations[i].0 - run.trace.rows[k][0]).abs() < 1e-9, "{name}: pose {i} at step {k}");
            // stored as float32: 1e-6 is a few float32 ulps at these sizes (< 1 m, unit quaternions)
            let (t, r) = (&translations[i].1, &rotations[i].1);
            for a in 0..3 {
                assert!((t[a] - want.translation[a]).abs() < 1e-6, "{name} translation {a} at step {k}: {} vs {}", t[a], want.translation[a]);
            }
            let [x, y, z, w] = want.quaternion_xyzw();
            // q and −q are the same rotation
            let sign = (r[0] * x + r[1] * y + r[2] * z + r[3] * w).signum();
            for (got, want) in r.iter().zip([x, y, z, w]) {
                assert!((got - sign * want).abs() < 1e-6, "{name} rotation (x, y, z, w) at step {k}: {r:?} vs {:?}", [x, y, z, w]);
            }
        }
    }
}

#[test]
fn rrd_has_the_3d_scene_configuration_summary_and_blueprint_and_passes_rerun_verify() {
    let run = record(&["--duration", "0.5", "--no-mcap"]);
    let rrd = Rrd::open(&run.rrd);
    let entities = rrd.entities();
    for entity in ["/config", "/summary", "/world/robot/upper_arm_link", "/world/robot/upper_arm_link/visual_0", "/world/robot/tool_link/tip", "/world/tool/trail", "/world/tool/commanded_path", "/world/tool/path"] {
        assert!(entities.contains_key(entity), "entity {entity} missing from the recording");
    }
    assert_eq!(rrd.blueprints, 1, "the file carries its layout");
    assert!(entities.values().any(|e| e.components.contains_key("Boxes3D:half_sizes")), "link geometry");
    assert!(rrd.verify_errors.is_empty(), "what rerun rrd verify checks: {:?}", rrd.verify_errors);
    assert!(rrd.verified_columns > 100, "Rerun's components were checked: {}", rrd.verified_columns);
}

#[test]
fn an_interrupted_run_leaves_both_files_readable_up_to_that_point() {
    let dir = tempfile::tempdir().unwrap();
    let (rrd, mcap) = (dir.path().join("cut.rrd"), dir.path().join("cut.mcap"));
    // paced to real time so that it is still running when interrupted
    let mut child = Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--quiet", "--duration", "30", "--realtime", "1", "--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap()])
        .spawn()
        .unwrap();
    // interrupt once the recording is under way (the MCAP has its first chunk or the header at least)
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    while mcap.metadata().map_or(true, |m| m.len() == 0) && std::time::Instant::now() < deadline {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    std::thread::sleep(std::time::Duration::from_millis(1000));
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "interrupted runs exit with 130");
    let topics = mcap_messages(&mcap);
    let n = topics["/controller"].len();
    assert!(n > 100 && n < 20_000, "{n} steps recorded before the interrupt");
    let bytes = std::fs::read(&mcap).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("the MCAP was closed properly");
    let done = mcap::read::metadata(&bytes, &summary.metadata_indexes[1]).unwrap();
    assert!(done.metadata["status"].contains("interrupted"));
    let rrd = Rrd::open(&rrd);
    assert_eq!(rrd.series("/joints/J2/position").len(), n, "the .rrd holds the same steps as the .mcap");
    assert!(rrd.verify_errors.is_empty(), "what rerun rrd verify checks: {:?}", rrd.verify_errors);
}

#[test]
fn no_viewer_listening_is_reported_and_the_files_are_still_written() {
    let dir = tempfile::tempdir().unwrap();
    let (rrd, mcap) = (dir.path().join("a.rrd"), dir.path().join("a.mcap"));
    let (code, _, err) = armscope(&["run", "--quiet", "--duration", "0.2", "--connect", "rerun+http://127.0.0.1:9/proxy", "--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("no Rerun viewer at rerun+http://127.0.0.1:9/proxy"), "{err}");
    assert!(rrd.metadata().unwrap().len() > 0 && mcap.metadata().unwrap().len() > 0);
    // --spawn with no viewer on the PATH
    let out = Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--quiet", "--duration", "0.2", "--spawn", "--rrd", rrd.to_str().unwrap(), "--no-mcap"])
        .current_dir(repo())
        .env("PATH", "/nonexistent")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("could not start the Rerun viewer") && err.contains("install"), "{err}");
    assert_eq!(Rrd::open(&rrd).series("/joints/J1/position").len(), 201);
}

#[test]
fn a_run_prints_where_its_recordings_are_and_how_to_open_them() {
    let dir = tempfile::tempdir().unwrap();
    let rrd = dir.path().join("x.rrd");
    let (code, out, _) = armscope(&["run", "--duration", "0.1", "--rrd", rrd.to_str().unwrap(), "--no-mcap"]);
    assert_eq!(code, 0);
    assert!(out.contains(&format!("open in Rerun: rerun {}", rrd.display())), "{out}");
}

#[test]
fn realtime_paces_simulated_time_to_the_wall_clock() {
    // 1.5 s of simulation at 3× real time cannot finish in less than 0.5 s (it takes ~40 ms unpaced)
    let started = std::time::Instant::now();
    let (code, _, err) = armscope(&["run", "--quiet", "--duration", "1.5", "--realtime", "3", "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 0, "{err}");
    let wall = started.elapsed().as_secs_f64();
    assert!(wall >= 0.5, "paced run took {wall} s");
    let (code, _, err) = armscope(&["run", "--quiet", "--realtime", "0", "--no-rrd", "--no-mcap"]);
    assert_eq!(code, 2);
    assert!(err.contains("--realtime"), "{err}");
}

#[test]
fn mcap_tool_path_comes_in_pieces_each_point_once_with_a_bounded_overview_for_seeking() {
    use foxglove::messages::SceneUpdate;
    // 30 s at 20 Hz: 601 path points, more than the overview keeps (512), so it is thinned
    let run = record(&["--duration", "30", "--no-rrd"]);
    let topics = mcap_messages(&run.mcap);
    let mut drawn: Vec<[f64; 3]> = Vec::new();
    let mut ids = std::collections::BTreeSet::new();
    let mut last_overview = Vec::new();
    for (i, m) in topics["/tool/path"].iter().enumerate() {
        let update = SceneUpdate::decode(&m.3[..]).unwrap();
        let [piece, overview] = &update.entities[..] else { panic!("a piece and the overview in message {i}") };
        assert!(ids.insert(piece.id.clone()), "piece {} published once", piece.id);
        assert_eq!(overview.id, "path-overview");
        let points: Vec<[f64; 3]> = piece.lines[0].points.iter().map(|p| [p.x, p.y, p.z]).collect();
        assert!(points.len() <= 11, "a piece is at most half a second at 20 Hz");
        // each piece starts where the last one ended (no gap), and adds only new points
        if let Some(end) = drawn.last() {
            assert_eq!(points[0], *end, "piece {i} starts at the previous end");
            drawn.extend_from_slice(&points[1..]);
        } else {
            drawn.extend_from_slice(&points);
        }
        last_overview = overview.lines[0].points.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>();
        assert!(last_overview.len() <= 513, "the overview stays bounded: {}", last_overview.len());
        assert_eq!(last_overview.last(), points.last(), "the overview reaches the newest point");
    }
    // the pieces together are the tool's position every 50 ms and at the end, each once
    let want: Vec<[f64; 3]> = (0..run.trace.rows.len())
        .filter(|&k| k % 50 == 0 || k == run.trace.rows.len() - 1)
        .map(|k| ["x", "y", "z"].map(|a| run.trace.rows[k][run.trace.col(a)]))
        .collect();
    assert_eq!(drawn, want);
    // the overview is a thinning of the path: every point of it is a path point, first to last
    assert_eq!(last_overview.first(), want.first());
    assert!(last_overview.len() > 256 && last_overview.iter().all(|p| want.contains(p)));
}

/// The commanded path the recordings draw does not grow with the run: the default wave repeats
/// every 2π/ω, so an hour's path is one period's (a closed loop, every 10 ms: 1257 points), as the
/// 30 s run's; a command that does not repeat (a step) is drawn with at most 20,000 points.
#[test]
fn the_commanded_path_drawn_is_bounded_whatever_the_duration() {
    use armscope::config::RunConfig;
    use armscope::experiment::Experiment;
    let path = |extra: fn(&mut RunConfig)| {
        let mut config = RunConfig { urdf: common::box_urdf(), duration: 3600.0, ..RunConfig::default() };
        extra(&mut config);
        Experiment::prepare(config).unwrap().commanded_tool_path(0.01)
    };
    let hour = path(|_| {});
    let short = path(|c| c.duration = 30.0);
    assert_eq!(hour.len(), short.len());
    assert_eq!(hour.len(), (std::f64::consts::TAU / 0.5 / 0.01).ceil() as usize + 1);
    assert!((hour[0] - hour[hour.len() - 1]).norm() < 1e-12, "one whole period: the loop closes");
    let stepped = path(|c| c.test_joint = Some("2".into()));
    assert!(stepped.len() <= 20_001, "{}", stepped.len());
}

/// The torque plots are scaled to the motion's own torque (issue 22): with a limit far above what
/// the motion needs, each joint's view spans the motion (its settled peak fills at least half of
/// it and stays inside) and names the limit it leaves off the plot; the MCAP's Foxglove layout
/// gives each joint's plot the same range. With the tutorial's limits, a joint whose run settles
/// to a quarter or more of its limit (the tutorial's chattering J2–J5) shows ±1.1·limit, the
/// others (J1, J6) their motion.
#[test]
fn torque_plots_are_scaled_to_the_motions_own_torque_next_to_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = std::fs::read_to_string(common::box_urdf()).unwrap();
    let strong = dir.path().join("strong.urdf");
    let effort = with_effort(&urdf, "1000");
    std::fs::write(&strong, effort).unwrap();
    // the tutorial's gains rely on its limits to catch up with its command stably: the strong arm
    // gets gains tuned to it
    for (model, limits, gains) in [(strong.to_str().unwrap().to_string(), [1000.0; 6], Some("--auto-tune")), (common::box_urdf().to_str().unwrap().to_string(), [8.0, 12.0, 8.0, 5.0, 3.0, 1.5], None)] {
        let run = record(&[&["--urdf", &model, "--duration", "4"][..], gains.as_slice()].concat());
        let mut in_view = [0, 0];
        let views = Rrd::open(&run.rrd).view_axis_ranges();
        let layout: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(run.mcap.with_extension("layout.json")).unwrap()).unwrap();
        for (j, &limit) in limits.iter().enumerate() {
            let name = format!("J{}", j + 1);
            let (title, range) = views.iter().find(|(title, _)| title.starts_with(&format!("{name} torque"))).unwrap_or_else(|| panic!("{name}'s torque view in {views:?}"));
            let [lo, hi] = range.unwrap_or_else(|| panic!("{title}: no y range"));
            assert_eq!(lo, -hi);
            let panel = &layout["configById"][format!("Plot!torque{j}")];
            assert_eq!(panel["maxYValue"].as_f64(), Some(hi), "{name}: the Foxglove plot spans the same");
            let settled: f64 = col(&run.trace, "u", j).iter().zip(run.trace.column("t")).filter(|(_, t)| *t >= 2.0).map(|(u, _)| u.abs()).fold(0.0, f64::max);
            in_view[title.ends_with("vs ±limit") as usize] += 1;
            if title.ends_with("vs ±limit") {
                assert!((hi - 1.1 * limit).abs() < 1e-9, "{title}: ±{hi} for a limit of {limit}");
            } else {
                assert_eq!(title, &format!("{name} torque (limit ±{limit} N·m)"));
                assert!(limit > 4.0 * settled, "{title}: a limit left off the plot is more than 4× the settled {settled} N·m");
                assert!(settled <= hi / 1.5 + 1e-12 && settled >= 0.5 * hi, "{title}: the settled peak {settled} N·m fills ±{hi}");
            }
        }
        assert_eq!(in_view, if gains.is_some() { [6, 0] } else { [2, 4] }, "{model}: plots without and with their limit");
    }
}

/// `urdf` with every joint's effort limit set to `effort`.
fn with_effort(urdf: &str, effort: &str) -> String {
    let mut out = String::new();
    let mut rest = urdf;
    while let Some(at) = rest.find("effort=\"") {
        let value_start = at + "effort=\"".len();
        let value_end = value_start + rest[value_start..].find('"').unwrap();
        out.push_str(&rest[..value_start]);
        out.push_str(effort);
        rest = &rest[value_end..];
    }
    out.push_str(rest);
    out
}
