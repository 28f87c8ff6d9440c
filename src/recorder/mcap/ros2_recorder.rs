//! The MCAP recording in ROS 2's encoding (`--mcap-encoding ros2`): the file a rosbag2 writes, so
//! that `ros2 bag play` drives RViz, a `robot_state_publisher` or PlotJuggler with the run, and
//! rosbags, mcap-ros2-support and Rerun's MCAP importer read it as a bag. Header profile `ros2`,
//! every channel `cdr` with a `ros2msg` schema (the complete definition, [`crate::ros2::definitions`])
//! and rosbag2's `offered_qos_profiles` ([`crate::ros2::qos`]):
//!
//! | topic | type | when |
//! |---|---|---|
//! | `/joint_states` | sensor_msgs/msg/JointState | every control step: the coordinates' position, velocity, effort (the applied torque) |
//! | `/tf` | tf2_msgs/msg/TFMessage | the moving joints at the pose rate |
//! | `/tf_static` | tf2_msgs/msg/TFMessage | the fixed joints, once (latched) |
//! | `/robot_description` | std_msgs/msg/String | the URDF, once (latched) |
//! | `/tool/pose` | geometry_msgs/msg/PoseStamped | 50 Hz |
//! | `/tool/path`, `/tool/commanded_path`, `/robot/geometry` | visualization_msgs/msg/MarkerArray | as the Foxglove encoding's scenes |
//! | `/controller` | armscope_msgs/msg/ControllerTelemetry | every control step (joints and torque limits in the channel's metadata) |
//! | `/collisions`, `/collisions/contacts` | armscope_msgs/msg/CollisionState, MarkerArray | with collision checks |
//!
//! Header stamps are the messages' log times.

use super::McapOptions;
use super::collisions::{McapCollisions, TOPIC_COLLISIONS, TOPIC_CONTACTS};
use super::out::{Out, Topic, config_metadata, controller_metadata, open_sinks};
use super::scene::{JointTransform, LinkTransforms, ToolPath, color, line, scene_interval_s, table_entity};
use super::telemetry::ControllerTelemetry;
use crate::recorder::shared::output_file::Replaced;
use crate::recorder::{Recorder, RunInfo};
use crate::dynamics::frame_pose_in;
use crate::error::Error;
use crate::model::{Geometry, Model};
use crate::ros2::cdr::CdrWriter;
use crate::ros2::definitions::full_definition;
use crate::ros2::messages::{ColorRgba, Header, JointState, Marker, MarkerArray, Message, Pose, PoseStamped, Quaternion, StringMessage, TfMessage, Time, TransformStamped, Vector3};
use crate::ros2::qos::Qos;
use crate::sample::Sample;
use crate::spatial::Pose as SpatialPose;
use crate::summary::Summary;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

struct Channels {
    joint_states: Topic<()>,
    tf: Topic<()>,
    tf_static: Topic<()>,
    robot_description: Topic<()>,
    tool_pose: Topic<()>,
    tool_path: Topic<()>,
    commanded_path: Topic<()>,
    geometry: Topic<()>,
    controller: Topic<()>,
    collisions: Option<(Topic<()>, Topic<()>)>,
}

pub struct Ros2McapRecorder {
    options: McapOptions,
    path: PathBuf,
    notice: Option<fn(&str)>,
    out: Option<Out>,
    channels: Option<Channels>,
    start_ns: u64,
    model: Option<Arc<Model>>,
    joint_tfs: Vec<JointTransform>,
    tf: TfMessage,
    joint_state: JointState,
    telemetry: ControllerTelemetry,
    motors: Option<Arc<crate::actuator::MotorSet>>,
    geometry: MarkerArray,
    geometry_interval_s: i64,
    last_geometry_second: i64,
    tool_path: ToolPath,
    steps_per_tf: usize,
    steps_per_tool_pose: usize,
    steps_per_path_point: usize,
    collisions: Option<McapCollisions>,
    replaced: Option<Replaced>,
}

fn vector(v: &nalgebra::Vector3<f64>) -> Vector3 {
    Vector3 { x: v.x, y: v.y, z: v.z }
}

fn pose(p: &SpatialPose) -> Pose {
    let [x, y, z, w] = p.quaternion_xyzw();
    Pose { position: vector(&p.translation), orientation: Quaternion { x, y, z, w } }
}

fn rgba(c: &foxglove::messages::Color) -> ColorRgba {
    ColorRgba { r: c.r as f32, g: c.g as f32, b: c.b as f32, a: c.a as f32 }
}

fn fox_pose(p: &Option<foxglove::messages::Pose>) -> Pose {
    let Some(p) = p else { return Pose::default() };
    let t = p.position.unwrap_or_default();
    let q = p.orientation.unwrap_or(foxglove::messages::Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 });
    Pose { position: Vector3 { x: t.x, y: t.y, z: t.z }, orientation: Quaternion { x: q.x, y: q.y, z: q.z, w: q.w } }
}

fn size(v: &Option<foxglove::messages::Vector3>) -> Vector3 {
    v.as_ref().map_or(Vector3::default(), |v| Vector3 { x: v.x, y: v.y, z: v.z })
}

/// A Foxglove scene update as markers (the same shapes for RViz and Foxglove's ROS layers): each
/// entity's primitives in namespace = its id, numbered; a delete-all first where the update
/// deletes all; a line's width 3 mm (Foxglove's are in pixels).
fn markers_of(update: &foxglove::messages::SceneUpdate, stamp: Time) -> MarkerArray {
    let mut markers = Vec::new();
    if !update.deletions.is_empty() {
        markers.push(Marker { action: Marker::DELETEALL, ..Default::default() });
    }
    for e in &update.entities {
        let header = Header { stamp, frame_id: e.frame_id.clone() };
        let base = |id: usize, kind: i32| Marker { header: header.clone(), ns: e.id.clone(), id: id as i32, kind, frame_locked: e.frame_locked, ..Default::default() };
        let mut id = 0;
        let mut next = || {
            id += 1;
            id - 1
        };
        for c in &e.cubes {
            markers.push(Marker { pose: fox_pose(&c.pose), scale: size(&c.size), color: c.color.as_ref().map(rgba).unwrap_or_default(), ..base(next(), Marker::CUBE) });
        }
        for c in &e.cylinders {
            markers.push(Marker { pose: fox_pose(&c.pose), scale: size(&c.size), color: c.color.as_ref().map(rgba).unwrap_or_default(), ..base(next(), Marker::CYLINDER) });
        }
        for c in &e.spheres {
            markers.push(Marker { pose: fox_pose(&c.pose), scale: size(&c.size), color: c.color.as_ref().map(rgba).unwrap_or_default(), ..base(next(), Marker::SPHERE) });
        }
        for l in &e.lines {
            let points = l.points.iter().map(|p| Vector3 { x: p.x, y: p.y, z: p.z }).collect();
            markers.push(Marker { pose: fox_pose(&l.pose), scale: Vector3 { x: 0.003, y: 0.0, z: 0.0 }, color: l.color.as_ref().map(rgba).unwrap_or_default(), points, ..base(next(), Marker::LINE_STRIP) });
        }
    }
    MarkerArray { markers }
}

/// Each link's visuals as markers locked to the link: boxes, cylinders and spheres as themselves
/// (a capsule as its cylinder and two spheres), a mesh as a mesh resource at its file's URL.
fn geometry_markers(model: &Model) -> MarkerArray {
    let mut markers = Vec::new();
    for frame in &model.frames {
        for (k, v) in frame.visuals.iter().enumerate() {
            let c = v.rgba.unwrap_or([0.67, 0.67, 0.7, 1.0]);
            let base = Marker {
                header: Header { stamp: Time::default(), frame_id: frame.name.clone() },
                ns: frame.name.clone(),
                id: 10 * k as i32,
                pose: pose(&v.origin),
                color: ColorRgba { r: c[0], g: c[1], b: c[2], a: c[3] },
                frame_locked: true,
                ..Default::default()
            };
            let sized = |kind: i32, x: f64, y: f64, z: f64| Marker { kind, scale: Vector3 { x, y, z }, ..base.clone() };
            match &v.geometry {
                Geometry::Box { size } => markers.push(sized(Marker::CUBE, size[0], size[1], size[2])),
                Geometry::Cylinder { radius, length } => markers.push(sized(Marker::CYLINDER, 2.0 * radius, 2.0 * radius, *length)),
                Geometry::Sphere { radius } => markers.push(sized(Marker::SPHERE, 2.0 * radius, 2.0 * radius, 2.0 * radius)),
                Geometry::Capsule { radius, length } => {
                    markers.push(sized(Marker::CYLINDER, 2.0 * radius, 2.0 * radius, *length));
                    for (i, end) in [-0.5, 0.5].into_iter().enumerate() {
                        let cap = v.origin.compose(&SpatialPose::new(nalgebra::Matrix3::identity(), nalgebra::Vector3::new(0.0, 0.0, end * length)));
                        markers.push(Marker { id: base.id + 1 + i as i32, pose: pose(&cap), ..sized(Marker::SPHERE, 2.0 * radius, 2.0 * radius, 2.0 * radius) });
                    }
                }
                Geometry::Mesh { path, scale } => {
                    let absolute = std::fs::canonicalize(path).unwrap_or_else(|_| path.clone());
                    markers.push(Marker { mesh_resource: format!("file://{}", absolute.display()), mesh_use_embedded_materials: v.rgba.is_none(), ..sized(Marker::MESH_RESOURCE, scale[0], scale[1], scale[2]) });
                }
            }
        }
    }
    MarkerArray { markers }
}

/// armscope_msgs/msg/ControllerTelemetry, field for field as its `.msg` (the same numbers as the
/// Foxglove encoding's protobuf message; flags as bools).
pub fn controller_telemetry(t: &ControllerTelemetry, out: &mut Vec<u8>) {
    let mut w = CdrWriter::new(out);
    let flags = |w: &mut CdrWriter, values: &[u32]| {
        w.length(values.len());
        for v in values {
            w.bool(*v != 0);
        }
    };
    w.f64(t.time);
    w.f64_sequence(&t.target);
    w.f64_sequence(&t.error);
    w.f64_sequence(&t.torque);
    w.f64_sequence(&t.tau_g);
    flags(&mut w, &t.saturated);
    flags(&mut w, &t.chatter);
    w.f64(t.tool_error);
    w.f64_sequence(&t.tool_position);
    w.f64_sequence(&t.torque_limit);
    w.f64_sequence(&t.load_angle);
    w.length(t.lost_steps.len());
    for v in &t.lost_steps {
        w.i64(*v);
    }
    w.f64_sequence(&t.motor_speed);
    w.f64_sequence(&t.friction);
    flags(&mut w, &t.stuck);
    w.f64_sequence(&t.winding_temperature);
    w.f64_sequence(&t.duty);
    w.f64_sequence(&t.current);
    w.f64_sequence(&t.supply);
    w.f64_sequence(&t.measured_effort);
    w.f64_sequence(&t.observed_position);
}

/// A `/controller` message of the ROS 2 encoding back (the comparison of finished runs reads it).
pub fn decode_controller_telemetry(bytes: &[u8]) -> Result<ControllerTelemetry, crate::ros2::CdrError> {
    let mut r = crate::ros2::CdrReader::new(bytes)?;
    let flags = |r: &mut crate::ros2::CdrReader| -> Result<Vec<u32>, crate::ros2::CdrError> {
        let n = r.length(1)?;
        (0..n).map(|_| r.bool().map(u32::from)).collect()
    };
    let time = r.f64()?;
    let (target, error, torque, tau_g) = (r.f64_sequence()?, r.f64_sequence()?, r.f64_sequence()?, r.f64_sequence()?);
    let (saturated, chatter) = (flags(&mut r)?, flags(&mut r)?);
    let tool_error = r.f64()?;
    let (tool_position, torque_limit, load_angle) = (r.f64_sequence()?, r.f64_sequence()?, r.f64_sequence()?);
    let n = r.length(8)?;
    let lost_steps = (0..n).map(|_| r.i64()).collect::<Result<_, _>>()?;
    let (motor_speed, friction) = (r.f64_sequence()?, r.f64_sequence()?);
    let stuck = flags(&mut r)?;
    let (winding_temperature, duty, current, supply) = (r.f64_sequence()?, r.f64_sequence()?, r.f64_sequence()?, r.f64_sequence()?);
    let (measured_effort, observed_position) = (r.f64_sequence()?, r.f64_sequence()?);
    Ok(ControllerTelemetry { time, target, error, torque, tau_g, saturated, chatter, tool_error, tool_position, torque_limit, load_angle, lost_steps, motor_speed, friction, stuck, winding_temperature, duty, current, supply, measured_effort, observed_position })
}

impl Ros2McapRecorder {
    pub fn new(options: McapOptions) -> Self {
        let path = options.file.clone().unwrap_or_else(|| PathBuf::from(format!("foxglove live at {}", options.live.as_deref().unwrap_or(""))));
        Self {
            options,
            path,
            notice: None,
            out: None,
            channels: None,
            start_ns: 0,
            model: None,
            joint_tfs: Vec::new(),
            tf: TfMessage::default(),
            joint_state: JointState::default(),
            telemetry: ControllerTelemetry::default(),
            motors: None,
            geometry: MarkerArray::default(),
            geometry_interval_s: 1,
            last_geometry_second: -1,
            tool_path: ToolPath::default(),
            steps_per_tf: 10,
            steps_per_tool_pose: 20,
            steps_per_path_point: 50,
            collisions: None,
            replaced: None,
        }
    }

    /// Where the user is told the live server's address.
    pub fn on_notice(&mut self, notice: fn(&str)) {
        self.notice = Some(notice);
    }

    fn err(&self, e: impl std::fmt::Display) -> Error {
        Error::output(&self.path, e)
    }

    fn stamp(&self, t: f64) -> u64 {
        self.start_ns + (t * 1e9).round() as u64
    }

    /// A channel of ROS 2 type `name` with `qos` and further `metadata`.
    fn channel(out: &mut Out, topic: &str, name: &str, qos: Qos, mut metadata: BTreeMap<String, String>) -> Result<Topic<()>, String> {
        let definition = full_definition(name).ok_or_else(|| format!("no definition of {name}"))?;
        metadata.insert("offered_qos_profiles".into(), qos.yaml());
        out.channel_of(topic, "cdr", Some(foxglove::Schema::new(name, "ros2msg", definition.into_bytes())), metadata, qos == Qos::Latched)
    }

    fn log(&mut self, which: impl Fn(&mut Channels) -> &mut Topic<()>, message: &impl Message, stamp: u64) -> Result<(), Error> {
        let path = self.path.clone();
        let (out, ch) = (self.out.as_mut().expect("started"), self.channels.as_mut().expect("started"));
        out.log_encoded(which(ch), |bytes| message.encode(bytes), stamp).map_err(|e| Error::output(&path, e))
    }
}

impl Recorder for Ros2McapRecorder {
    fn start(&mut self, run: &RunInfo) -> Result<(), Error> {
        let e = run.experiment;
        let model = &*e.model;
        let (sinks, replaced) = open_sinks(&self.options, "ros2", &self.path, self.notice)?;
        self.replaced = replaced;
        let mut out = Out::new(sinks);
        let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
        self.start_ns = now.as_nanos() as u64;
        let meta = config_metadata(run, self.start_ns, "log time = header stamp = start_time_unix_ns + simulation time (s) × 1e9");
        out.write_metadata("armscope.config", meta).map_err(|err| self.err(err))?;
        let controller_meta = controller_metadata(run);
        let stream = Qos::Stream { depth: 10 };
        let channels = (|| -> Result<Channels, String> {
            Ok(Channels {
                robot_description: Self::channel(&mut out, "/robot_description", StringMessage::NAME, Qos::Latched, BTreeMap::new())?,
                tf_static: Self::channel(&mut out, "/tf_static", TfMessage::NAME, Qos::Latched, BTreeMap::new())?,
                tf: Self::channel(&mut out, "/tf", TfMessage::NAME, Qos::Stream { depth: 100 }, BTreeMap::new())?,
                joint_states: Self::channel(&mut out, "/joint_states", JointState::NAME, stream, BTreeMap::new())?,
                controller: Self::channel(&mut out, "/controller", "armscope_msgs/msg/ControllerTelemetry", stream, controller_meta)?,
                tool_pose: Self::channel(&mut out, "/tool/pose", PoseStamped::NAME, stream, BTreeMap::new())?,
                tool_path: Self::channel(&mut out, "/tool/path", MarkerArray::NAME, stream, BTreeMap::new())?,
                commanded_path: Self::channel(&mut out, "/tool/commanded_path", MarkerArray::NAME, Qos::Latched, BTreeMap::new())?,
                geometry: Self::channel(&mut out, "/robot/geometry", MarkerArray::NAME, Qos::Latched, BTreeMap::new())?,
                collisions: match e.collisions {
                    Some(_) => Some((
                        Self::channel(&mut out, TOPIC_COLLISIONS, "armscope_msgs/msg/CollisionState", stream, BTreeMap::new())?,
                        Self::channel(&mut out, TOPIC_CONTACTS, MarkerArray::NAME, Qos::Latched, BTreeMap::new())?,
                    )),
                    None => None,
                },
            })
        })()
        .map_err(|err| self.err(err))?;
        self.channels = Some(channels);
        self.out = Some(out);
        let steps_per = |period: f64| ((period / e.config.dt).round() as usize).max(1);
        self.steps_per_path_point = steps_per(0.05);
        self.steps_per_tool_pose = steps_per(0.02);
        self.steps_per_tf = crate::recorder::steps_per_pose(e.config.dt);
        let links = LinkTransforms::of(model);
        let header = |parent: &str| Header { stamp: Time::default(), frame_id: parent.to_string() };
        self.tf = TfMessage { transforms: links.moving.iter().map(|((parent, child), _)| TransformStamped { header: header(parent), child_frame_id: child.clone(), transform: Pose::default() }).collect() };
        self.joint_tfs = links.moving.into_iter().map(|(_, tf)| tf).collect();
        let t0 = self.stamp(0.0);
        let stamp0 = Time::from_nanos(t0);
        let tf_static = TfMessage {
            transforms: links.fixed.iter().map(|((parent, child), p)| TransformStamped { header: Header { stamp: stamp0, frame_id: parent.clone() }, child_frame_id: child.clone(), transform: pose(p) }).collect(),
        };
        // the coordinates only: a robot_state_publisher works out the joints that mimic them
        self.joint_state = JointState {
            header: Header::default(),
            name: model.joints.iter().map(|j| j.name.clone()).collect(),
            position: vec![0.0; model.dof()],
            velocity: vec![0.0; model.dof()],
            effort: vec![0.0; model.dof()],
        };
        let n = model.dof();
        let has_friction = e.joint_has_friction().contains(&true);
        let stepped = e.stepped_joints().contains(&true);
        let per_joint = |recorded: bool| if recorded { vec![0.0; n] } else { Vec::new() };
        self.telemetry = ControllerTelemetry {
            target: vec![0.0; n],
            error: vec![0.0; n],
            torque: vec![0.0; n],
            tau_g: vec![0.0; n],
            saturated: vec![0; n],
            chatter: vec![0; n],
            tool_position: Vec::with_capacity(3),
            torque_limit: vec![0.0; n],
            load_angle: per_joint(stepped),
            lost_steps: if stepped { vec![0; n] } else { Vec::new() },
            motor_speed: per_joint(e.motors.is_some()),
            friction: per_joint(has_friction),
            stuck: if has_friction { vec![0; n] } else { Vec::new() },
            duty: per_joint(e.servos.is_some()),
            current: per_joint(e.servos.is_some()),
            supply: per_joint(e.servos.is_some()),
            measured_effort: Vec::new(),
            ..Default::default()
        };
        self.motors = e.motors.clone();
        self.model = Some(e.model.clone());
        self.geometry = geometry_markers(model);
        if let Some(floor) = e.floor_contact() {
            // the table the tool rests on (the motor file's [floor])
            let table = foxglove::messages::SceneUpdate { deletions: vec![], entities: vec![table_entity(floor.height)] };
            self.geometry.markers.extend(markers_of(&table, stamp0).markers);
        }
        self.collisions = e.collisions.clone().map(|c| McapCollisions::new(e.model.clone(), c));
        if let Some(c) = &self.collisions {
            let world = foxglove::messages::SceneUpdate { deletions: vec![], entities: c.world_entities() };
            self.geometry.markers.extend(markers_of(&world, stamp0).markers);
        }
        let mut bytes = Vec::new();
        self.geometry.encode(&mut bytes);
        self.geometry_interval_s = scene_interval_s(bytes.len());

        self.log(|c| &mut c.robot_description, &StringMessage { data: model.urdf_text.clone() }, t0)?;
        self.log(|c| &mut c.tf_static, &tf_static, t0)?;
        let points: Vec<foxglove::messages::Point3> = run.commanded_tool_path.iter().map(|p| foxglove::messages::Point3 { x: p.x, y: p.y, z: p.z }).collect();
        let commanded = foxglove::messages::SceneUpdate {
            deletions: vec![],
            entities: vec![foxglove::messages::SceneEntity { frame_id: "world".into(), id: "commanded".into(), lines: vec![line(points, color([0.6, 0.6, 0.6, 1.0]), 1.5)], ..Default::default() }],
        };
        self.log(|c| &mut c.commanded_path, &markers_of(&commanded, stamp0), t0)?;
        self.out.as_mut().expect("started").spawn().map_err(|e| Error::output(&self.path, e))
    }

    fn record(&mut self, s: &Sample) -> Result<(), Error> {
        let stamp = self.stamp(s.t);
        let time = Time::from_nanos(stamp);
        let model = self.model.clone().expect("started");
        if s.k.is_multiple_of(self.steps_per_tf) || s.is_final {
            for (m, tf) in self.tf.transforms.iter_mut().zip(&self.joint_tfs) {
                m.header.stamp = time;
                m.transform = pose(&tf.pose(&model.bodies[tf.joint], model.couplings[tf.joint].position(s.q)));
            }
            let tf = std::mem::take(&mut self.tf);
            self.log(|c| &mut c.tf, &tf, stamp)?;
            self.tf = tf;
        }
        let js = &mut self.joint_state;
        js.header.stamp = time;
        js.position.copy_from_slice(s.q);
        js.velocity.copy_from_slice(s.v);
        js.effort.copy_from_slice(s.u);
        let js = std::mem::take(&mut self.joint_state);
        self.log(|c| &mut c.joint_states, &js, stamp)?;
        self.joint_state = js;
        self.telemetry.fill(s, self.motors.as_deref());
        {
            let path = self.path.clone();
            let (out, ch) = (self.out.as_mut().expect("started"), self.channels.as_mut().expect("started"));
            let tel = &self.telemetry;
            out.log_encoded(&mut ch.controller, |bytes| controller_telemetry(tel, bytes), stamp).map_err(|e| Error::output(&path, e))?;
        }
        if let Some(c) = self.collisions.as_mut() {
            let update = c.record(s, foxglove::messages::Timestamp::new((stamp / 1_000_000_000) as u32, (stamp % 1_000_000_000) as u32));
            let state = crate::ros2::messages::CollisionState { time: c.state.time, in_contact: c.state.in_contact, min_distance: c.state.min_distance, pairs: c.state.pairs.clone(), distances: c.state.distances.clone() };
            if let Some(update) = update {
                let markers = markers_of(&update, time);
                self.log(|ch| &mut ch.collisions.as_mut().expect("with collisions").1, &markers, stamp)?;
            }
            self.log(|ch| &mut ch.collisions.as_mut().expect("with collisions").0, &state, stamp)?;
        }
        if s.k.is_multiple_of(self.steps_per_tool_pose) || s.is_final {
            let tool = frame_pose_in(&model, s.body_pose, model.tool_frame);
            self.log(|c| &mut c.tool_pose, &PoseStamped { header: Header { stamp: time, frame_id: "world".into() }, pose: pose(&tool) }, stamp)?;
        }
        let second = s.t.floor() as i64;
        if self.last_geometry_second < 0 || second >= self.last_geometry_second + self.geometry_interval_s {
            self.last_geometry_second = second;
            for m in &mut self.geometry.markers {
                m.header.stamp = time;
            }
            let geometry = std::mem::take(&mut self.geometry);
            self.log(|c| &mut c.geometry, &geometry, stamp)?;
            self.geometry = geometry;
        }
        if s.k.is_multiple_of(self.steps_per_path_point) || s.is_final {
            let p = s.tool_position;
            self.tool_path.push(foxglove::messages::Point3 { x: p.x, y: p.y, z: p.z });
            if (self.tool_path.piece_full() || s.is_final)
                && let Some(update) = self.tool_path.take_update(foxglove::messages::Timestamp::new((stamp / 1_000_000_000) as u32, (stamp % 1_000_000_000) as u32))
            {
                let markers = markers_of(&update, time);
                self.log(|c| &mut c.tool_path, &markers, stamp)?;
            }
        }
        Ok(())
    }

    fn finish(&mut self, _run: &RunInfo, summary: &Summary) -> Result<(), Error> {
        self.channels = None;
        if let Some(out) = self.out.take() {
            out.finish(summary).map_err(|e| self.err(e))?;
        }
        self.replaced = None;
        Ok(())
    }
}
