//! MCAP recorder for Foxglove: joint transforms, link geometry, joint states, controller telemetry,
//! the tool's pose and path, the URDF, and the run's configuration and summary as metadata.
//! Timestamps are simulation time offset by the wall-clock start of the run (in the metadata).
//!
//! The foxglove SDK provides the well-known schemas and their encoders; the mcap crate writes the
//! file directly (the SDK's sink machinery costs more per message than the encoding itself), on a
//! thread of its own (see `Out`).

use super::collisions::{CollisionState, McapCollisions, TOPIC_COLLISIONS, TOPIC_CONTACTS};
use super::layout::{RunPlots, layout_for_run, layout_path};
use super::out::{Out, Topic, config_metadata, controller_metadata, open_sinks};
use super::robot_description::RobotDescription;
use super::scene::{JointTransform, LinkTransforms, ToolPath, color, fox_pose, line, scene_from_model, scene_interval_s, set_transform, table_entity};
use super::step_messages::JointStatesLayout;
use super::telemetry::ControllerTelemetry;
use super::McapOptions;
use super::{TOPIC_COMMANDED_PATH, TOPIC_CONTROLLER, TOPIC_JOINT_STATES, TOPIC_ROBOT_DESCRIPTION, TOPIC_SCENE, TOPIC_TF, TOPIC_TOOL_PATH, TOPIC_TOOL_POSE};
use crate::recorder::shared::output_file::Replaced;
use crate::recorder::shared::torque_axis::TorqueAxis;
use crate::recorder::{Recorder, RunInfo};
use crate::dynamics::frame_pose_in;
use crate::error::Error;
use crate::model::Model;
use crate::sample::Sample;
use crate::summary::Summary;
use foxglove::messages::{FrameTransform, FrameTransforms, JointState, JointStates, Point3, PoseInFrame, SceneEntity, SceneUpdate, Timestamp};
use std::collections::BTreeMap;
use std::path::PathBuf;

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
    collisions: Option<(Topic<CollisionState>, Topic<SceneUpdate>)>,
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
    collisions: Option<McapCollisions>,
    /// The last run's file at this path, freed meanwhile on another thread.
    replaced: Option<Replaced>,
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
        let meta = config_metadata(run, self.start_ns, "log time = start_time_unix_ns + simulation time (s) × 1e9");
        out.write_metadata("armscope.config", meta).map_err(|err| self.err(err))?;
        let none = BTreeMap::new;
        let controller_meta = controller_metadata(run);
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
                    Some(_) => Some((out.channel(TOPIC_COLLISIONS, none(), false)?, out.channel(TOPIC_CONTACTS, none(), true)?)),
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
        if let Some(floor) = e.floor_contact() {
            // the table the tool rests on (the motor file's [floor])
            self.scene.entities.push(table_entity(floor.height));
        }
        self.collisions = e.collisions.clone().map(|c| McapCollisions::new(e.model.clone(), c));
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
        self.channels = None;
        if let Some(out) = self.out.take() {
            out.finish(summary).map_err(|e| self.err(e))?;
        }
        self.replaced = None;
        Ok(())
    }
}

/// The Foxglove layout for the run, beside its recording `mcap`.
fn write_layout(run: &RunInfo, mcap: &std::path::Path, torque_axes: &[TorqueAxis]) -> Result<(), Error> {
    let e = run.experiment;
    let stepped = e.stepped_joints();
    let heated: Vec<bool> = e.motor_heat().iter().map(Option::is_some).collect();
    let plots = RunPlots {
        motors: e.motors.is_some(),
        friction: e.joint_has_friction().contains(&true),
        stepped: &stepped,
        measured: &run.measured_effort,
        observed: &run.observed_position,
        torque_axes,
        heated: &heated,
        collisions: e.collisions.is_some(),
    };
    let layout = layout_for_run(&e.model, &e.initial_state().0, &plots);
    let layout_path = layout_path(mcap);
    std::fs::write(&layout_path, serde_json::to_string_pretty(&layout).unwrap_or_default()).map_err(|err| Error::output(&layout_path, err))
}
