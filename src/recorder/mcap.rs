//! MCAP recorder for Foxglove: joint transforms, link geometry, joint states, controller telemetry,
//! the tool's pose and path, the URDF, and the run's configuration and summary as metadata.
//! Timestamps are simulation time offset by the wall-clock start of the run (in the metadata).
//!
//! The foxglove SDK provides the well-known schemas and their encoders; the mcap crate writes the
//! file directly (the SDK's sink machinery costs more per message than the encoding itself), on a
//! thread of its own (see `Out`).

use super::foxglove_live::FoxgloveLive;
use super::mcap_out::{Out, Sinks, Topic, ZSTD_LEVEL, zstd_level};
use super::overview::Overview;
use super::robot_description::RobotDescription;
use super::step_messages::JointStatesLayout;
use super::telemetry::ControllerTelemetry;
use super::{Recorder, RunInfo};
use crate::error::Error;
use crate::model::{Geometry, JointKind, Model};
use crate::sample::Sample;
use crate::dynamics::frame_pose_in;
use crate::spatial::{Pose, rotation_about_axis};
use crate::summary::Summary;
use foxglove::messages::{
    Color, CubePrimitive, CylinderPrimitive, FrameTransform, FrameTransforms, JointState, JointStates, LinePrimitive, ModelPrimitive,
    Point3, PoseInFrame, Quaternion, SceneEntity, SceneUpdate, SpherePrimitive, Timestamp, Vector3,
};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::PathBuf;

pub const TOPIC_TF: &str = "/tf";
pub const TOPIC_SCENE: &str = "/robot/geometry";
pub const TOPIC_JOINT_STATES: &str = "/joint_states";
pub const TOPIC_CONTROLLER: &str = "/controller";
pub const TOPIC_TOOL_POSE: &str = "/tool/pose";
pub const TOPIC_TOOL_PATH: &str = "/tool/path";
pub const TOPIC_COMMANDED_PATH: &str = "/tool/commanded_path";
pub const TOPIC_ROBOT_DESCRIPTION: &str = "/robot_description";


struct Channels {
    tf: Topic<FrameTransforms>,
    scene: Topic<SceneUpdate>,
    joint_states: Topic<JointStates>,
    controller: Topic<ControllerTelemetry>,
    tool_pose: Topic<PoseInFrame>,
    tool_path: Topic<SceneUpdate>,
    commanded_path: Topic<SceneUpdate>,
    robot_description: Topic<RobotDescription>,
    /// With collision checks: each step's state, and the links and objects in contact.
    collisions: Option<(Topic<super::mcap_collisions::CollisionState>, Topic<SceneUpdate>)>,
}

/// How the MCAP's messages are encoded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum McapEncoding {
    /// Foxglove's well-known protobuf schemas (Foxglove's 3D, plot and URDF panels as they are).
    #[default]
    Foxglove,
    /// ROS 2's: CDR with ros2msg schemas, the ros2 profile, rosbag2's QoS (`ros2 bag play`, RViz,
    /// PlotJuggler, rosbags, Rerun's MCAP importer).
    Ros2,
}

/// Where the MCAP recorder's messages go: a file, live Foxglove clients, or both.
#[derive(Clone, Debug, Default)]
pub struct McapOptions {
    pub file: Option<PathBuf>,
    /// `HOST:PORT` to serve the Foxglove WebSocket protocol at.
    pub live: Option<String>,
    /// zstd the file's chunks (`--compress`): ~35 % smaller, more CPU.
    pub compress: bool,
}

pub struct McapRecorder {
    options: McapOptions,
    /// What error messages name: the file, or the live address.
    path: PathBuf,
    /// Told where the live server listens.
    notice: Option<fn(&str)>,
    out: Option<Out>,
    channels: Option<Channels>,
    start_ns: u64,
    /// One per moving joint, in the order of `tf_msg.transforms`.
    joint_tfs: Vec<JointTransform>,
    tf_msg: FrameTransforms,
    /// The transforms of fixed joints (constant; sent with the geometry, once a simulated second).
    fixed_tf_msg: FrameTransforms,
    /// `/joint_states`: its layout and a step's values.
    joint_states: JointStatesLayout,
    joint_values: Vec<f64>,
    telemetry: ControllerTelemetry,
    scene: SceneUpdate,
    model: Option<std::sync::Arc<Model>>,
    steps_per_path_point: usize,
    steps_per_tool_pose: usize,
    steps_per_tf: usize,
    tool_path: ToolPath,
    last_scene_second: i64,
    /// Per joint, its motor's gear ratio from `--motors` (0: no motor file entry).
    motors: Option<std::sync::Arc<crate::actuator::MotorSet>>,
    /// Simulated seconds between republished geometries: 1 for small scenes, longer for big meshes.
    scene_interval_s: i64,
    collisions: Option<super::mcap_collisions::McapCollisions>,
    /// The last run's file at this path, freed meanwhile on another thread.
    replaced: Option<super::output_file::Replaced>,
}

/// Points of the tool path at most in one piece (a piece every half simulated second at 20 Hz).
const PATH_PIECE_POINTS: usize = 10;
/// Points of the path's overview at most.
const PATH_OVERVIEW_POINTS: usize = 512;

/// The tool's path, published incrementally: each message carries the new piece (its own entity,
/// kept, so that playing the file draws the whole path, each point published once) and an overview
/// of everything so far thinned to at most `PATH_OVERVIEW_POINTS` (one entity, replaced), which is
/// what a viewer shows after seeking (it shows a topic's latest message). So the topic's size grows
/// linearly with the duration.
pub(super) struct ToolPath {
    /// The points since the last piece, starting with the last piece's last point (no gap).
    piece: Vec<Point3>,
    pieces: usize,
    overview: Overview<Point3>,
}

impl Default for ToolPath {
    fn default() -> Self {
        Self { piece: Vec::new(), pieces: 0, overview: Overview::new(PATH_OVERVIEW_POINTS) }
    }
}

impl ToolPath {
    pub(super) fn push(&mut self, p: Point3) {
        self.overview.push(p);
        self.piece.push(p);
    }

    /// Whether a piece is due (`PATH_PIECE_POINTS` new points).
    pub(super) fn piece_full(&self) -> bool {
        self.piece.len() > PATH_PIECE_POINTS
    }

    /// The message with the new piece and the overview; starts the next piece.
    pub(super) fn take_update(&mut self, timestamp: Timestamp) -> Option<SceneUpdate> {
        if self.piece.len() < 2 {
            return None;
        }
        let red = color([1.0, 0.25, 0.2, 1.0]);
        let last = *self.piece.last().expect("two points");
        let piece = std::mem::replace(&mut self.piece, vec![last]);
        let mut overview = self.overview.points().to_vec();
        if overview.last() != Some(&last) {
            overview.push(last);
        }
        let entity = |id: String, points: Vec<Point3>, thickness: f64| SceneEntity {
            timestamp: Some(timestamp),
            frame_id: "world".into(),
            id,
            lines: vec![line(points, red, thickness)],
            ..Default::default()
        };
        self.pieces += 1;
        Some(SceneUpdate { deletions: vec![], entities: vec![entity(format!("path-{}", self.pieces), piece, 3.0), entity("path-overview".into(), overview, 2.0)] })
    }
}

impl McapRecorder {
    pub fn new(options: McapOptions) -> Self {
        let path = options.file.clone().unwrap_or_else(|| PathBuf::from(format!("foxglove live at {}", options.live.as_deref().unwrap_or(""))));
        Self {
            options,
            path,
            notice: None,
            out: None,
            channels: None,
            start_ns: 0,
            joint_tfs: Vec::new(),
            tf_msg: FrameTransforms::default(),
            fixed_tf_msg: FrameTransforms::default(),
            joint_states: JointStatesLayout::new(&[]),
            joint_values: Vec::new(),
            telemetry: ControllerTelemetry::default(),
            scene: SceneUpdate::default(),
            model: None,
            steps_per_path_point: 20,
            steps_per_tool_pose: 20,
            steps_per_tf: 10,
            tool_path: ToolPath::default(),
            last_scene_second: -1,
            motors: None,
            scene_interval_s: 1,
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

    fn timestamp(&self, t: f64) -> Timestamp {
        let ns = self.stamp(t);
        Timestamp::new((ns / 1_000_000_000) as u32, (ns % 1_000_000_000) as u32)
    }

    fn publish_path(&mut self, t: f64) -> Result<(), Error> {
        let Some(update) = self.tool_path.take_update(self.timestamp(t)) else { return Ok(()) };
        let stamp = self.stamp(t);
        let (out, ch) = (self.out.as_mut().expect("started"), self.channels.as_mut().expect("started"));
        out.log(&mut ch.tool_path, &update, stamp).map_err(|e| Error::output(&self.path, e))
    }
}

/// A moving joint's child link in its parent link: `before` ∘ motion(q) ∘ `after`, where `before`
/// takes the parent link to the joint frame and `after` the joint's body to the child link.
/// Built from the URDF's own origins rather than from world poses, so what the URDF has exactly
/// (zero offsets, an axis along z) stays exact: protobuf then leaves the zeros out, a third of /tf.
pub(super) struct JointTransform {
    pub(super) joint: usize,
    before: Pose,
    after: Pose,
}

/// Every link in its parent link ("world" → the root when the root is not "world"), by (parent,
/// child) name: those a moving joint turns, and the fixed ones with their constant pose.
pub(super) struct LinkTransforms {
    pub(super) moving: Vec<((String, String), JointTransform)>,
    pub(super) fixed: Vec<((String, String), Pose)>,
}

impl LinkTransforms {
    pub(super) fn of(model: &Model) -> Self {
        let pairs = model.frames.iter().enumerate().filter(|(_, f)| f.parent_frame.is_some() || f.name != "world");
        // a link moves relative to its parent when its joint is a moving joint (the child's body's joint)
        let (moving, fixed): (Vec<_>, Vec<_>) = pairs.partition(|(_, f)| f.parent_frame.is_some_and(|p| model.frames[p].body != f.body));
        let name_of = |f: Option<usize>| f.map_or("world".to_string(), |i| model.frames[i].name.clone());
        // a parent link's placement on its body (the world's: identity)
        let placement_of = |f: Option<usize>| f.map_or(Pose::identity(), |p| model.frames[p].placement);
        let names = |parent: Option<usize>, child: usize| (name_of(parent), name_of(Some(child)));
        Self {
            moving: moving
                .iter()
                .map(|(c, f)| {
                    let joint = f.body.expect("a moving link has a body");
                    (names(f.parent_frame, *c), JointTransform { joint, before: placement_of(f.parent_frame).inverse().compose(&model.bodies[joint].placement), after: f.placement })
                })
                .collect(),
            // links on the same body (or on the world) keep their relative pose: P_parent⁻¹ ∘ P_child
            fixed: fixed.iter().map(|(c, f)| (names(f.parent_frame, *c), placement_of(f.parent_frame).inverse().compose(&f.placement))).collect(),
        }
    }
}

impl JointTransform {
    pub(super) fn pose(&self, model_joint: &crate::model::Joint, q: f64) -> Pose {
        let motion = match model_joint.kind {
            JointKind::Revolute | JointKind::Continuous => Pose::new(rotation_about_axis(&model_joint.axis, q), nalgebra::Vector3::zeros()),
            JointKind::Prismatic => Pose::new(nalgebra::Matrix3::identity(), model_joint.axis * q),
        };
        self.before.compose(&motion).compose(&self.after)
    }
}

fn set_transform(m: &mut FrameTransform, pose: &Pose, ts: Option<Timestamp>) {
    m.timestamp = ts;
    m.translation = Some(vec3(&pose.translation));
    m.rotation = Some(quaternion(pose));
}

pub(super) fn color(c: [f32; 4]) -> Color {
    Color { r: c[0] as f64, g: c[1] as f64, b: c[2] as f64, a: c[3] as f64 }
}

/// A line strip `thickness` pixels wide at any zoom.
pub(super) fn line(points: Vec<Point3>, color: Color, thickness: f64) -> LinePrimitive {
    LinePrimitive { r#type: 0, thickness, scale_invariant: true, points, color: Some(color), ..Default::default() }
}

fn vec3(v: &nalgebra::Vector3<f64>) -> Vector3 {
    Vector3 { x: v.x, y: v.y, z: v.z }
}

fn quaternion(pose: &Pose) -> Quaternion {
    let [x, y, z, w] = pose.quaternion_xyzw();
    Quaternion { x, y, z, w }
}

fn fox_pose(pose: &Pose) -> foxglove::messages::Pose {
    foxglove::messages::Pose { position: Some(vec3(&pose.translation)), orientation: Some(quaternion(pose)) }
}

fn media_type(path: &std::path::Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
        Some("stl") => "model/stl",
        Some("obj") => "model/obj",
        Some("dae") => "model/vnd.collada+xml",
        Some("glb") => "model/gltf-binary",
        _ => "model/gltf+json",
    }
}

/// How often the geometry is republished: once a simulated second, but at most
/// [`SCENE_BYTES_PER_SECOND`] on average — a robot drawn from meshes (a Panda's are 7 MB) is
/// republished every few minutes instead of every second, which would have been most of its file.
pub(super) fn scene_interval_s(scene_bytes: usize) -> i64 {
    (scene_bytes as f64 / SCENE_BYTES_PER_SECOND).ceil().max(1.0) as i64
}

/// The geometry's share of the MCAP, bytes per simulated second (the whole file is ~450 kB/s).
pub const SCENE_BYTES_PER_SECOND: f64 = 20_000.0;

/// One scene entity per link with visuals, locked to the link's frame.
fn scene_from_model(model: &Model) -> Result<SceneUpdate, (PathBuf, std::io::Error)> {
    let mut entities = Vec::new();
    for frame in &model.frames {
        if frame.visuals.is_empty() {
            continue;
        }
        let mut entity = SceneEntity { frame_id: frame.name.clone(), id: frame.name.clone(), frame_locked: true, ..Default::default() };
        for v in &frame.visuals {
            let c = color(v.rgba.unwrap_or([0.67, 0.67, 0.7, 1.0]));
            let pose = Some(fox_pose(&v.origin));
            match &v.geometry {
                Geometry::Box { size } => entity.cubes.push(CubePrimitive { pose, size: Some(Vector3 { x: size[0], y: size[1], z: size[2] }), color: Some(c) }),
                Geometry::Cylinder { radius, length } => entity.cylinders.push(CylinderPrimitive {
                    pose,
                    size: Some(Vector3 { x: 2.0 * radius, y: 2.0 * radius, z: *length }),
                    bottom_scale: 1.0,
                    top_scale: 1.0,
                    color: Some(c),
                }),
                Geometry::Capsule { radius, length } => {
                    entity.cylinders.push(CylinderPrimitive {
                        pose,
                        size: Some(Vector3 { x: 2.0 * radius, y: 2.0 * radius, z: *length }),
                        bottom_scale: 1.0,
                        top_scale: 1.0,
                        color: Some(c),
                    });
                    for end in [-0.5, 0.5] {
                        let cap = v.origin.compose(&Pose::new(nalgebra::Matrix3::identity(), nalgebra::Vector3::new(0.0, 0.0, end * length)));
                        entity.spheres.push(SpherePrimitive { pose: Some(fox_pose(&cap)), size: Some(Vector3 { x: 2.0 * radius, y: 2.0 * radius, z: 2.0 * radius }), color: Some(c) });
                    }
                }
                Geometry::Sphere { radius } => entity.spheres.push(SpherePrimitive { pose, size: Some(Vector3 { x: 2.0 * radius, y: 2.0 * radius, z: 2.0 * radius }), color: Some(c) }),
                Geometry::Mesh { path, scale } => {
                    let data = std::fs::read(path).map_err(|e| (path.clone(), e))?;
                    entity.models.push(ModelPrimitive {
                        pose,
                        scale: Some(Vector3 { x: scale[0], y: scale[1], z: scale[2] }),
                        color: Some(c),
                        override_color: v.rgba.is_some(),
                        url: String::new(),
                        media_type: media_type(path).into(),
                        data: data.into(),
                    });
                }
            }
        }
        entities.push(entity);
    }
    Ok(SceneUpdate { deletions: vec![], entities })
}

impl Recorder for McapRecorder {
    fn start(&mut self, run: &RunInfo) -> Result<(), Error> {
        let e = run.experiment;
        let model = &*e.model;
        let (sinks, replaced) = open_sinks(&self.options, "", &self.path, self.notice)?;
        self.replaced = replaced;
        let mut out = Out::new(sinks);
        let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
        self.start_ns = now.as_nanos() as u64;
        // the configuration first: written later, it would close a chunk holding only schemas and
        // channels, a chunk without message indexes, which Foxglove refuses to preload
        let meta = super::mcap_out::config_metadata(run, self.start_ns, "log time = start_time_unix_ns + simulation time (s) × 1e9");
        out.write_metadata("armscope.config", meta).map_err(|err| self.err(err))?;
        let none = BTreeMap::new;
        let controller_meta = super::mcap_out::controller_metadata(run);
        let channels = (|| -> Result<Channels, String> {
            Ok(Channels {
                tf: out.channel(TOPIC_TF, none(), false)?,
                scene: out.channel(TOPIC_SCENE, none(), true)?,
                joint_states: out.channel(TOPIC_JOINT_STATES, none(), false)?,
                controller: out.channel(TOPIC_CONTROLLER, controller_meta, false)?,
                tool_pose: out.channel(TOPIC_TOOL_POSE, none(), false)?,
                tool_path: out.channel(TOPIC_TOOL_PATH, none(), false)?,
                commanded_path: out.channel(TOPIC_COMMANDED_PATH, none(), true)?,
                robot_description: out.channel(TOPIC_ROBOT_DESCRIPTION, none(), true)?,
                collisions: match e.collisions {
                    Some(_) => Some((out.channel(super::mcap_collisions::TOPIC_COLLISIONS, none(), false)?, out.channel(super::mcap_collisions::TOPIC_CONTACTS, none(), true)?)),
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
        self.steps_per_tf = super::steps_per_pose(e.config.dt);

        let links = LinkTransforms::of(model);
        let transform = |(parent, child): &(String, String)| FrameTransform { timestamp: None, parent_frame_id: parent.clone(), child_frame_id: child.clone(), translation: None, rotation: None };
        self.tf_msg = FrameTransforms { transforms: links.moving.iter().map(|(names, _)| transform(names)).collect() };
        self.joint_tfs = links.moving.into_iter().map(|(_, tf)| tf).collect();
        self.fixed_tf_msg = FrameTransforms {
            transforms: links
                .fixed
                .iter()
                .map(|(names, pose)| {
                    let mut m = transform(names);
                    set_transform(&mut m, pose, None);
                    m
                })
                .collect(),
        };
        self.model = Some(run.experiment.model.clone());
        // the coordinates (position, velocity, effort), then the joints that mimic them (position and
        // velocity only)
        let coordinates = model.joints.iter().map(|j| JointState { name: j.name.clone(), position: Some(0.0), velocity: Some(0.0), effort: Some(0.0), ..Default::default() });
        let mimics = model.mimic_bodies().map(|(_, b, _)| JointState { name: b.name.clone(), position: Some(0.0), velocity: Some(0.0), ..Default::default() });
        self.joint_states = JointStatesLayout::new(&coordinates.chain(mimics).collect::<Vec<_>>());
        self.joint_values = Vec::with_capacity(self.joint_states.values());
        let n = model.dof();
        let has_friction = run.experiment.joint_has_friction().contains(&true);
        // a run records only what it has, as with friction: the stepper fields when some joint is
        // driven open loop, the motor speeds with `--motors` (zeros at every step were a seventh
        // of the file's messages)
        let stepped = e.stepped_joints().contains(&true);
        let per_joint = |recorded: bool| if recorded { vec![0.0; n] } else { Vec::new() };
        self.telemetry = ControllerTelemetry {
            time: 0.0,
            target: vec![0.0; n],
            error: vec![0.0; n],
            torque: vec![0.0; n],
            tau_g: vec![0.0; n],
            saturated: vec![0; n],
            chatter: vec![0; n],
            tool_error: 0.0,
            tool_position: Vec::with_capacity(3),
            torque_limit: vec![0.0; n],
            load_angle: per_joint(stepped),
            lost_steps: if stepped { vec![0; n] } else { Vec::new() },
            motor_speed: per_joint(e.motors.is_some()),
            friction: if has_friction { vec![0.0; n] } else { Vec::new() },
            stuck: if has_friction { vec![0; n] } else { Vec::new() },
            winding_temperature: Vec::new(),
            duty: per_joint(e.servos.is_some()),
            current: per_joint(e.servos.is_some()),
            supply: per_joint(e.servos.is_some()),
            measured_effort: Vec::new(),
            observed_position: Vec::new(),
        };
        self.motors = e.motors.clone();
        self.scene = scene_from_model(model).map_err(|(path, err)| Error::output(&path, err))?;
        self.collisions = e.collisions.clone().map(|c| super::mcap_collisions::McapCollisions::new(e.model.clone(), c));
        if let Some(c) = &self.collisions {
            // the scene's objects and the payload, republished with the robot's geometry
            self.scene.entities.extend(c.world_entities());
        }
        let scene_bytes = foxglove::Encode::encoded_len(&self.scene).unwrap_or(0);
        self.scene_interval_s = scene_interval_s(scene_bytes);

        let t0 = self.stamp(0.0);
        let path = self.path.clone();
        let fail = |e: String| Error::output(&path, e);
        {
            let (out, ch) = (self.out.as_mut().unwrap(), self.channels.as_mut().unwrap());
            out.log(&mut ch.robot_description, &RobotDescription { data: model.urdf_text.clone() }, t0).map_err(fail)?;
        }
        let points: Vec<Point3> = run.commanded_tool_path.iter().map(|p| Point3 { x: p.x, y: p.y, z: p.z }).collect();
        let commanded = SceneEntity {
            timestamp: Some(self.timestamp(0.0)),
            frame_id: "world".into(),
            id: "commanded".into(),
            lines: vec![line(points, color([0.6, 0.6, 0.6, 1.0]), 1.5)],
            ..Default::default()
        };
        let (out, ch) = (self.out.as_mut().unwrap(), self.channels.as_mut().unwrap());
        out.log(&mut ch.commanded_path, &SceneUpdate { deletions: vec![], entities: vec![commanded] }, t0).map_err(fail)?;

        self.out.as_mut().expect("started").spawn().map_err(|e| Error::output(&self.path, e))
    }

    fn record(&mut self, s: &Sample) -> Result<(), Error> {
        let stamp = self.stamp(s.t);
        let timestamp = self.timestamp(s.t);
        let ts = Some(timestamp);
        let model = self.model.as_ref().expect("started");
        let pose_step = s.k.is_multiple_of(self.steps_per_tf) || s.is_final;
        if pose_step {
            for (m, tf) in self.tf_msg.transforms.iter_mut().zip(&self.joint_tfs) {
                set_transform(m, &tf.pose(&model.bodies[tf.joint], model.couplings[tf.joint].position(s.q)), ts);
            }
        }
        // /joint_states' values in its layout's order
        self.joint_values.clear();
        for j in 0..s.q.len() {
            self.joint_values.extend_from_slice(&[s.q[j], s.v[j], s.u[j]]);
        }
        for (_, _, coupling) in model.mimic_bodies() {
            self.joint_values.extend_from_slice(&[coupling.position(s.q), coupling.multiplier * s.v[coupling.coordinate]]);
        }
        self.telemetry.fill(s, self.motors.as_deref());
        let path = &self.path;
        let fail = |e: String| Error::output(path, e);
        let (out, ch) = (self.out.as_mut().expect("started"), self.channels.as_mut().expect("started"));
        // the 3D poses at the display rate (every step's joint positions are in /joint_states)
        if pose_step {
            out.log(&mut ch.tf, &self.tf_msg, stamp).map_err(fail)?;
        }
        // (the two per-step messages encoded by hand, as prost would)
        out.log_encoded(&mut ch.joint_states, |bytes| self.joint_states.encode(ts.as_ref(), &self.joint_values, bytes), stamp).map_err(fail)?;
        out.log_encoded(&mut ch.controller, |bytes| super::step_messages::controller_telemetry(&self.telemetry, bytes), stamp).map_err(fail)?;
        if let (Some(c), Some((state, contacts))) = (self.collisions.as_mut(), ch.collisions.as_mut()) {
            if let Some(update) = c.record(s, timestamp) {
                out.log(contacts, &update, stamp).map_err(fail)?;
            }
            out.log(state, &c.state, stamp).map_err(fail)?;
        }
        // the tool pose at a display rate, 50 Hz (every step's tool position is in /controller)
        if s.k.is_multiple_of(self.steps_per_tool_pose) || s.is_final {
            let tool = frame_pose_in(model, s.body_pose, model.tool_frame);
            out.log(&mut ch.tool_pose, &PoseInFrame { timestamp: ts, frame_id: "world".into(), pose: Some(fox_pose(&tool)) }, stamp).map_err(fail)?;
        }
        // the geometry again every few simulated seconds, so a viewer that seeks always has it
        let second = s.t.floor() as i64;
        if self.last_scene_second < 0 || second >= self.last_scene_second + self.scene_interval_s {
            self.last_scene_second = second;
            for entity in &mut self.scene.entities {
                entity.timestamp = ts;
            }
            out.log(&mut ch.scene, &self.scene, stamp).map_err(fail)?;
            if !self.fixed_tf_msg.transforms.is_empty() {
                for m in &mut self.fixed_tf_msg.transforms {
                    m.timestamp = ts;
                }
                out.log(&mut ch.tf, &self.fixed_tf_msg, stamp).map_err(fail)?;
            }
        }
        if s.k.is_multiple_of(self.steps_per_path_point) || s.is_final {
            let p = s.tool_position;
            self.tool_path.push(Point3 { x: p.x, y: p.y, z: p.z });
            if self.tool_path.piece_full() || s.is_final {
                self.publish_path(s.t)?;
            }
        }
        Ok(())
    }

    fn finish(&mut self, run: &RunInfo, summary: &Summary) -> Result<(), Error> {
        // the Foxglove layout for this model, beside the recording, its torque plots scaled by the
        // commanded motion and by what the run's drives settled to
        if let Some(path) = &self.options.file {
            let settled = |i: usize| summary.peak_abs_torque_after_settle.get(i).copied().flatten();
            let axes: Vec<_> = run.torque_axes().iter().enumerate().map(|(i, axis)| axis.after_run(settled(i))).collect();
            write_layout(run, path, &axes)?;
        }
        let mut meta = BTreeMap::new();
        meta.insert("summary".into(), serde_json::to_string(summary).unwrap_or_default());
        meta.insert("status".into(), serde_json::to_string(&summary.status).unwrap_or_default());
        self.channels = None;
        if let Some(mut out) = self.out.take() {
            out.close().map_err(|e| self.err(e))?;
            out.write_metadata("armscope.summary", meta).map_err(|e| self.err(e))?;
            let sinks = out.sinks();
            if let Some(file) = &mut sinks.file {
                file.finish().map_err(|e| self.err(e))?;
            }
            if let Some(live) = &mut sinks.live {
                live.stop();
            }
        }
        self.replaced = None;
        Ok(())
    }
}

/// The sinks of a recording: its file (the last one at its path freed meanwhile, see
/// `create_replacing`), written with `profile` in the MCAP header ("": none; "ros2"), and the live
/// Foxglove server, with `notice` told where it listens. Errors name `path_for_errors`.
pub(super) fn open_sinks(options: &McapOptions, profile: &str, path_for_errors: &std::path::Path, notice: Option<fn(&str)>) -> Result<(Sinks, Option<super::output_file::Replaced>), Error> {
    let mut replaced = None;
    let file = match &options.file {
        Some(path) => {
            let (file, old) = super::output_file::create_replacing(path).map_err(|err| Error::output(path_for_errors, err))?;
            replaced = Some(old);
            Some(file)
        }
        None => None,
    };
    // zstd (with --compress) on the writer thread (`Out`): zstd's own worker threads cost more
    // than they save here
    let write_options = mcap::WriteOptions::new()
        .compression(options.compress.then_some(mcap::Compression::Zstd))
        .compression_level(zstd_level(ZSTD_LEVEL))
        .compression_threads(0)
        // within zstd's window at this level, so no block takes its slower "external
        // dictionary" path (−5 % of the writer's work at the same size)
        .chunk_size(Some(512 * 1024))
        // CRCs with --compress only: the crate checksums every record field by field as it
        // writes it, twice (5 % of the run's instructions), and the data section's CRC needs
        // the chunks' (the default is rosbag2's "fastwrite": chunks as they are, no CRCs;
        // readers skip a zero CRC)
        .calculate_chunk_crcs(options.compress)
        .calculate_data_section_crc(options.compress)
        .profile(profile)
        .library(if profile == "ros2" { format!("armscope {} (ROS 2 CDR, mcap-rust)", env!("CARGO_PKG_VERSION")) } else { format!("armscope {} (foxglove-sdk schemas, mcap-rust)", env!("CARGO_PKG_VERSION")) });
    // zstd hands its output over in pieces of up to 128 KiB: gathered here, a chunk (~200 KiB
    // compressed) takes a write call or two
    let file = file.map(|file| write_options.create(BufWriter::with_capacity(1 << 20, file))).transpose().map_err(|err| Error::output(path_for_errors, err))?;
    let live = match &options.live {
        Some(address) => {
            let live = FoxgloveLive::start(address).map_err(|err| Error::flag("--foxglove", err))?;
            if let Some(notice) = notice {
                notice(&format!("Foxglove live at ws://{} (Foxglove: Open connection → Foxglove WebSocket)", live.address()));
            }
            Some(live)
        }
        None => None,
    };
    Ok((Sinks { file, live }, replaced))
}

/// The Foxglove layout for the run, beside its recording `mcap`.
fn write_layout(run: &RunInfo, mcap: &std::path::Path, torque_axes: &[super::torque_axis::TorqueAxis]) -> Result<(), Error> {
    let e = run.experiment;
    let stepped = e.stepped_joints();
    let heated: Vec<bool> = e.motor_heat().iter().map(Option::is_some).collect();
    let plots = super::foxglove_layout::RunPlots {
        motors: e.motors.is_some(),
        friction: e.joint_has_friction().contains(&true),
        stepped: &stepped,
        measured: &run.measured_effort,
        observed: &run.observed_position,
        torque_axes,
        heated: &heated,
        collisions: e.collisions.is_some(),
    };
    let layout = super::foxglove_layout::layout_for_run(&e.model, &e.initial_state().0, &plots);
    let layout_path = super::foxglove_layout::layout_path(mcap);
    std::fs::write(&layout_path, serde_json::to_string_pretty(&layout).unwrap_or_default()).map_err(|err| Error::output(&layout_path, err))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcap::records::MessageHeader;

    /// Primitive shapes (a few kB) once a simulated second; a 7 MB mesh scene (a Panda) every 350 s,
    /// so the geometry stays at most 20 kB per simulated second of the file.
    #[test]
    fn geometry_is_republished_at_a_bounded_byte_rate() {
        assert_eq!(scene_interval_s(0), 1);
        assert_eq!(scene_interval_s(3_000), 1);
        assert_eq!(scene_interval_s(7_000_000), 350);
        for bytes in [25_000, 1_000_000, 7_000_000] {
            assert!(bytes as f64 / scene_interval_s(bytes) as f64 <= SCENE_BYTES_PER_SECOND);
        }
    }

    /// The same telemetry-like messages, written with zstd at `level`: the file's size.
    fn mcap_size(level: u32) -> usize {
        let options = mcap::WriteOptions::new().compression(Some(mcap::Compression::Zstd)).compression_level(level).compression_threads(0);
        let mut writer = options.create(std::io::Cursor::new(Vec::new())).unwrap();
        let channel = writer.add_channel(0, "/data", "binary", &BTreeMap::new()).unwrap();
        for k in 0..20_000u32 {
            // text with numbers, like a log line: repetitive enough that how hard zstd looks shows
            let data = format!("step {k} joint J{} angle {:.4} target {:.4}", k % 6 + 1, (k as f64 * 1e-3).sin(), (k as f64 * 1e-3).cos()).into_bytes();
            let header = MessageHeader { channel_id: channel, sequence: k, log_time: k as u64, publish_time: k as u64 };
            writer.write_to_known_channel(&header, &data).unwrap();
        }
        writer.finish().unwrap();
        writer.into_inner().into_inner().len()
    }

    #[test]
    fn negative_zstd_levels_reach_zstd_through_mcap() {
        // on this data level −3 writes 1.25× the bytes of level 1; the default level (3), level 1
        // itself, or zstd's highest (22) write 0.8–1.02×: whichever mcap made of −3 shows
        let (fast, level_1) = (mcap_size(zstd_level(ZSTD_LEVEL)), mcap_size(1));
        assert!(fast as f64 > 1.15 * level_1 as f64, "level {ZSTD_LEVEL}: {fast} bytes, level 1: {level_1}");
    }
}
