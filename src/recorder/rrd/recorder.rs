//! Rerun recorder: every joint series at the control rate on the `sim_time` timeline, the arm in
//! 3D, the tool's trail and paths, the run's configuration and summary, and a blueprint. Columns
//! are buffered and sent as one chunk per entity and block (per-step `log` calls cost ~170 µs
//! here; a block of 4096 steps costs ~2.5 µs per step), to the `.rrd` and/or a live viewer.

use super::TIMELINE;
use super::blueprint::{blueprint, joint_color, rgb, send_blueprint};
use super::collisions::{CONTACT, RrdCollisions};
use super::column_pool::ColumnPool;
use super::columns::{Strips, float32_column, list_column, scalar_column, send_chunk_in_order, send_in_order};
use super::file::{FOOTER_UP_TO_SECONDS, RrdFile};
use super::geometry::{Recolour, log_geometry, quaternion_xyzw, transform};
use crate::recorder::shared::floor_plate::{TABLE_RGBA, TABLE_SIDE, floor_plate};
use super::markdown::{config_markdown, summary_markdown};
use crate::dynamics::frame_pose_in;
use crate::error::Error;
use crate::model::{Geometry, Model};
use crate::recorder::shared::overview::Overview;
use crate::recorder::shared::plot_colours::{CHATTER_RGB, CURRENT_RGB, FRICTION_RGB, GRAVITY_TORQUE_RGB, LIMIT_RGB, MEASURED_GAP_RGB, MEASURED_RGB, MOTOR_SPEED_RGB, SATURATED_RGB, STUCK_RGB, TARGET_RGB, observed_rgb};
use crate::recorder::{Recorder, RunInfo};
use crate::sample::Sample;
use crate::summary::Summary;
use rerun::external::arrow::buffer::OffsetBuffer;
use rerun::{RecordingStream, TimeColumn};
use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where the recording goes besides the file.
#[derive(Clone, Debug)]
pub enum LiveViewer {
    /// Start a viewer (`rerun` on the PATH) and stream to it.
    Spawn,
    /// Stream to a running viewer at this gRPC URL.
    Connect(String),
}

pub const DEFAULT_CONNECT_URL: &str = "rerun+http://127.0.0.1:9876/proxy";

#[derive(Clone, Debug, Default)]
pub struct RerunOptions {
    pub file: Option<PathBuf>,
    pub live: Option<LiveViewer>,
    /// The recording's name in the viewer.
    pub name: String,
    /// LZ4 the file's chunks (`--compress`): ~45 % smaller, more CPU.
    pub compress: bool,
}

/// One joint's per-step series. Series plotted together share an entity as instances of one row:
/// Rerun's cost is mostly per row, so this saves a third of it, and each of the blueprint's
/// per-joint views shows whole entities (clean legends).
struct JointColumns {
    /// `joints/<joint>/position`: [angle, target] per step.
    position: Vec<f64>,
    /// `joints/<joint>/torque`: [applied torque, gravity torque τ_g] per step.
    torque: Vec<f64>,
    /// `joints/<joint>/status`: [tracking error, saturated 0/1, chatter 0/1] per step.
    status: Vec<f64>,
    saturated_times: Vec<f64>,
    saturated_torque: Vec<f64>,
    /// `joints/<joint>/torque_limit` per step, [+limit, −limit], when the limit falls with speed
    /// (`--motors`); otherwise two lines spanning each block.
    limit: Vec<f64>,
    /// Stepper mode: `joints/<joint>/load_angle` (electrical degrees) and `joints/<joint>/lost_steps`
    /// (full steps lost so far) per step.
    load_angle: Vec<f64>,
    lost_steps: Vec<f64>,
    /// With `--motors`: `joints/<joint>/motor_speed`, the motor shaft's speed N·q̇ in rev/s, per step.
    motor_speed: Vec<f64>,
    /// With joint friction: `joints/<joint>/friction`, [friction torque, stuck 0/1] per step.
    friction: Vec<f64>,
    /// A motor with thermal data: `joints/<joint>/winding_temperature`, °C per step.
    winding: Vec<f64>,
    /// Firmware mode: `joints/<joint>/servo`, [PWM duty, motor current (A)] per step.
    servo: Vec<f64>,
    /// A replayed recording with measured effort: `joints/<joint>/measured_effort`, [measured effort,
    /// measured − model torque] per step.
    measured: Vec<f64>,
    /// A forward replay: `joints/<joint>/observed`, the real follower's position per step.
    observed: Vec<f64>,
}

impl JointColumns {
    /// The columns sent at every block come from `pool` (see [`ColumnPool`]).
    fn with_capacity(n: usize, pool: &ColumnPool<f64>) -> Self {
        Self {
            position: pool.take(2 * n),
            torque: pool.take(2 * n),
            status: pool.take(3 * n),
            saturated_times: Vec::new(),
            saturated_torque: Vec::new(),
            limit: Vec::new(),
            load_angle: Vec::new(),
            lost_steps: Vec::new(),
            motor_speed: Vec::new(),
            friction: Vec::new(),
            winding: Vec::new(),
            servo: Vec::new(),
            measured: Vec::new(),
            observed: Vec::new(),
        }
    }

    fn clear(&mut self) {
        for c in [&mut self.position, &mut self.torque, &mut self.status, &mut self.saturated_times, &mut self.saturated_torque, &mut self.limit, &mut self.load_angle, &mut self.lost_steps, &mut self.motor_speed, &mut self.friction, &mut self.winding, &mut self.servo, &mut self.measured, &mut self.observed] {
            c.clear();
        }
    }
}

/// A link frame that moves: its entity and its world poses at the display rate.
struct MovingLink {
    frame: usize,
    entity: String,
    translations: Vec<[f32; 3]>,
    /// [x, y, z, w] per pose.
    rotations: Vec<[f32; 4]>,
}

pub struct RerunRecorder {
    options: RerunOptions,
    rec: Option<RecordingStream>,
    /// The `.rrd`, closed by `finish` once the stream is flushed.
    file: Option<RrdFile>,
    model: Option<Arc<Model>>,
    joint_names: Vec<String>,
    effort: Vec<f64>,
    /// Per joint: driven open loop (stepper mode): its load angle and lost steps are recorded.
    stepped: Vec<bool>,
    /// Per joint: driven by its servo's firmware (its duty and current are recorded).
    servo_driven: Vec<bool>,
    /// The motors of `--motors`: the torque limit falls with speed (recorded at every step), and
    /// each motor's shaft speed is recorded.
    motors: Option<Arc<crate::actuator::MotorSet>>,
    times: Vec<f64>,
    /// The first and last samples' times (the limit lines of a file span them).
    first_time: f64,
    last_time: f64,
    joints: Vec<JointColumns>,
    /// [x, y, z] per step.
    tool: Vec<f64>,
    tool_error: Vec<f64>,
    links: Vec<MovingLink>,
    /// When the links' poses were taken (every `steps_per_pose` steps and the last).
    pose_times: Vec<f64>,
    steps_per_pose: usize,
    trail: VecDeque<[f32; 3]>,
    /// The trail as it was at each of its updates in this block (sent with the block).
    trail_times: Vec<f64>,
    trail_strips: Strips,
    /// The whole tool path, thinned to at most `PATH_POINTS` (logged once, at the end).
    path: Overview<[f32; 3]>,
    steps_per_trail_point: usize,
    live: bool,
    last_flush: Instant,
    /// Messages for the user (no viewer found, …).
    pub notices: Vec<String>,
    notice_sink: Option<Box<dyn Fn(&str) + Send>>,
    /// Per joint: its motor has thermal data (its winding temperature is recorded).
    heated: Vec<bool>,
    /// Per joint: the samples carry a measured effort (a replayed bag's).
    measured: Vec<bool>,
    /// Per joint: the samples carry a real follower's position (a forward replay's).
    observed: Vec<bool>,
    /// With collision checks: what is in contact, drawn and plotted.
    collisions: Option<RrdCollisions>,
    /// Memory for the columns sent at every block, for their row ids and the trail's points.
    values_pool: ColumnPool<f64>,
    ids_pool: ColumnPool<[u8; 16]>,
    points_pool: ColumnPool<[f32; 3]>,
}

/// Steps per block in a file-only recording: ~4 s of simulation per chunk (fewer, larger chunks
/// cost less to encode; Rerun's store keeps chunks of up to 4096 rows).
const FILE_BLOCK_STEPS: usize = 4096;
/// Chunks waiting for the encoder at most, bytes (a block of chunks is ~5 MB).
const BYTES_IN_FLIGHT: u64 = 4 << 20;
/// A live viewer gets a block at least this often.
const LIVE_FLUSH: Duration = Duration::from_millis(40);
const TRAIL_SECONDS: f64 = 2.0;
/// Points of the whole tool path drawn at the end at most (every trail point up to 6.5 simulated
/// minutes; evenly thinned beyond: a drawing whose size must not grow with the run).
const PATH_POINTS: usize = 20_000;
const TRAIL_RATE_HZ: f64 = 50.0;

impl RerunRecorder {
    pub fn new(options: RerunOptions) -> Self {
        Self {
            options,
            rec: None,
            file: None,
            model: None,
            joint_names: Vec::new(),
            effort: Vec::new(),
            stepped: Vec::new(),
            servo_driven: Vec::new(),
            motors: None,
            times: Vec::new(),
            first_time: 0.0,
            last_time: 0.0,
            joints: Vec::new(),
            tool: Vec::new(),
            tool_error: Vec::new(),
            links: Vec::new(),
            pose_times: Vec::new(),
            steps_per_pose: 10,
            trail: VecDeque::new(),
            trail_times: Vec::new(),
            trail_strips: Strips::default(),
            path: Overview::new(PATH_POINTS),
            steps_per_trail_point: 20,
            live: false,
            last_flush: Instant::now(),
            notices: Vec::new(),
            notice_sink: None,
            heated: Vec::new(),
            measured: Vec::new(),
            observed: Vec::new(),
            collisions: None,
            values_pool: ColumnPool::default(),
            ids_pool: ColumnPool::default(),
            points_pool: ColumnPool::default(),
        }
    }

    /// Called with each notice as it happens (e.g. to print it).
    pub fn on_notice(&mut self, sink: impl Fn(&str) + Send + 'static) {
        self.notice_sink = Some(Box::new(sink));
    }

    fn err(&self, e: impl std::fmt::Display) -> Error {
        Error::output(&self.output_path(), e)
    }

    /// What error messages name: the file, or the viewer.
    fn output_path(&self) -> PathBuf {
        self.options.file.clone().unwrap_or_else(|| PathBuf::from("rerun viewer"))
    }

    /// The stream to the file and the live viewer; `duration` the run's simulated time (a long run's
    /// file goes without the footer, see [`FOOTER_UP_TO_SECONDS`]).
    fn open_stream(&mut self, duration: f64) -> Result<RecordingStream, Error> {
        use rerun::sink::{GrpcSink, LogSink};
        let mut sinks: Vec<Box<dyn LogSink>> = Vec::new();
        if let Some(path) = &self.options.file {
            let footer = duration <= FOOTER_UP_TO_SECONDS;
            if !footer {
                self.notices.push(format!(
                    "{}: no footer (Rerun's index of the chunks, kept in memory until the end: ~20 MB an hour) for a run over {} simulated minutes; `rerun rrd optimize {} -o OUT.rrd` adds one",
                    path.display(),
                    FOOTER_UP_TO_SECONDS / 60.0,
                    path.display()
                ));
            }
            let file = RrdFile::create(path, footer, self.options.compress).map_err(|e| Error::output(path, e))?;
            sinks.push(file.sink());
            self.file = Some(file);
        }
        match &self.options.live {
            None => {}
            Some(live) => {
                let url = match live {
                    LiveViewer::Connect(url) => Some(url.clone()),
                    LiveViewer::Spawn => match rerun::spawn(&rerun::SpawnOptions::default()) {
                        Ok(_) => Some(DEFAULT_CONNECT_URL.to_string()),
                        Err(e) => {
                            self.notices.push(format!(
                                "could not start the Rerun viewer ({e}); install it with `cargo install rerun-cli@0.36.3 --locked` or `pip install rerun-sdk==0.36.3`; writing the files only"
                            ));
                            None
                        }
                    },
                };
                if let Some(url) = url {
                    match viewer_reachable(&url) {
                        Ok(uri) => {
                            sinks.push(Box::new(GrpcSink::new(uri)));
                            self.live = true;
                        }
                        Err(why) => self.notices.push(format!("no Rerun viewer at {url} ({why}); writing the files only")),
                    }
                }
            }
        }
        if let Some(report) = &self.notice_sink {
            for n in &self.notices {
                report(n);
            }
        }
        if sinks.is_empty() {
            return Err(self.err("no Rerun viewer reachable and no file to write"));
        }
        rerun::RecordingStreamBuilder::new("armscope")
            .recording_name(self.options.name.clone())
            // the encoder is slower than the blocks arrive: what waits for it is bounded by this
            // (Rerun's default, 100 MiB, made a 10-minute run's memory 4× the 30 s run's)
            .batcher_config(rerun::log::ChunkBatcherConfig { max_bytes_in_flight: BYTES_IN_FLIGHT, ..rerun::log::ChunkBatcherConfig::DEFAULT })
            .set_sinks(sinks)
            .map_err(|e| self.err(e))
    }

    fn log_static_scene(&mut self, rec: &RecordingStream, model: &Model) -> Result<(), Error> {
        rec.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP()).map_err(|x| self.err(x))?;
        for (f, frame) in model.frames.iter().enumerate() {
            let e = |err: rerun::RecordingStreamError| self.err(err);
            let entity = link_entity(&frame.name);
            // a link on no body is fixed in the world: its placement is its pose
            if frame.body.is_none() {
                rec.log_static(entity.as_str(), &transform(&frame.placement)).map_err(e)?;
            }
            for (i, visual) in frame.visuals.iter().enumerate() {
                let path = format!("{entity}/visual_{i}");
                let mut t = transform(&visual.origin);
                if let Geometry::Mesh { scale, .. } = &visual.geometry {
                    t = t.with_scale([scale[0] as f32, scale[1] as f32, scale[2] as f32]);
                }
                rec.log_static(path.as_str(), &t).map_err(|x| self.err(x))?;
                let color = visual.rgba.map(|c| rerun::Color::from_unmultiplied_rgba((c[0] * 255.0) as u8, (c[1] * 255.0) as u8, (c[2] * 255.0) as u8, (c[3] * 255.0) as u8));
                // a COLLADA mesh without a URDF colour keeps its materials' colours (untinted)
                let collada = matches!(&visual.geometry, Geometry::Mesh { path, .. } if crate::model::mesh_file::is_collada(path));
                let color = color.unwrap_or(if collada { rerun::Color::WHITE } else { rerun::Color::from_rgb(170, 170, 180) });
                // a checked link turns red in contact: its colour is then temporal, not static
                let highlighted = self.collisions.as_ref().is_some_and(|c| c.checked(f));
                let kind = match log_geometry(rec, &path, &visual.geometry, (!highlighted).then_some(color)) {
                    Ok(kind) => kind,
                    // a mesh that cannot be read leaves its link undrawn, not the run unrecorded
                    Err(why) if matches!(visual.geometry, Geometry::Mesh { .. }) => {
                        let notice = format!("link '{}': {why}; its visual is not drawn in the .rrd", frame.name);
                        if let Some(report) = &self.notice_sink {
                            report(&notice);
                        }
                        self.notices.push(notice);
                        continue;
                    }
                    Err(why) => return Err(self.err(why)),
                };
                if let (true, Some(c)) = (highlighted, self.collisions.as_mut()) {
                    c.register(f, Recolour { path, kind, colour: color });
                }
            }
        }
        if let Some(c) = self.collisions.as_mut() {
            let tool = link_entity(&model.frames[model.tool_frame].name);
            if let Err(m) = c.log_world(rec, &tool) {
                return Err(self.err(m));
            }
        }
        Ok(())
    }

    /// The names, colours and widths of the series this run records (a series it does not
    /// record gets no style: an entity with a style alone is an empty entry in the viewer's tree,
    /// and every entity costs the file's footer).
    fn log_series_styles(&self, rec: &RecordingStream, friction: bool) -> Result<(), Error> {
        let e = |err: rerun::RecordingStreamError| self.err(err);
        let (grey, red) = (rgb(TARGET_RGB), rgb(LIMIT_RGB));
        for (j, name) in self.joint_names.iter().enumerate() {
            let base = format!("joints/{name}");
            let c = joint_color(j);
            let lines = |names: &[String], colors: &[rerun::Color], widths: &[f32]| {
                rerun::SeriesLines::new().with_names(names.iter().cloned()).with_colors(colors.iter().copied()).with_widths(widths.iter().copied())
            };
            let styles = [
                ("position", lines(&[format!("{name} angle (rad)"), format!("{name} target (rad)")], &[c, grey], &[2.0, 1.0])),
                ("torque", lines(&[format!("{name} torque (N·m)"), format!("{name} τ_g (N·m)")], &[c, rgb(GRAVITY_TORQUE_RGB)], &[1.5, 1.0])),
                (
                    "status",
                    lines(&[format!("{name} error (rad)"), format!("{name} saturated (0/1)"), format!("{name} chatter (0/1)")], &[c, red, rgb(CHATTER_RGB)], &[1.5, 1.0, 1.0]),
                ),
                // "effort" is the URDF's constant; with --motors the limit falls with speed
                ("torque_limit", {
                    let word = if self.motors.is_some() { "limit" } else { "effort" };
                    lines(&[format!("{name} +{word}"), format!("{name} −{word}")], &[red, red], &[1.0, 1.0])
                }),
                ("load_angle", lines(&[format!("{name} load angle (electrical °; ±90 peak torque, ±180 slip)")], &[c], &[1.5])),
                ("lost_steps", lines(&[format!("{name} lost steps (full)")], &[red], &[2.0])),
                ("motor_speed", lines(&[format!("{name} motor speed (rev/s)")], &[rgb(MOTOR_SPEED_RGB)], &[1.0])),
                ("friction", lines(&[format!("{name} friction (N·m)"), format!("{name} stuck (0/1)")], &[rgb(FRICTION_RGB), rgb(STUCK_RGB)], &[1.0, 1.0])),
                ("winding_temperature", lines(&[format!("{name} winding (°C)")], &[c], &[1.5])),
                ("servo", lines(&[format!("{name} PWM duty (−1 … 1)"), format!("{name} current (A)")], &[c, rgb(CURRENT_RGB)], &[1.5, 1.0])),
                ("measured_effort", lines(&[format!("{name} measured effort (N·m)"), format!("{name} measured − model (N·m)")], &[rgb(MEASURED_RGB), rgb(MEASURED_GAP_RGB)], &[1.5, 1.0])),
                ("observed", lines(&[format!("{name} real follower (rad)")], &[rgb(observed_rgb(j))], &[1.5])),
            ];
            let has_motor = self.motors.as_ref().is_some_and(|m| m.joints.get(j).is_some_and(Option::is_some));
            let recorded = |leaf: &str| match leaf {
                "load_angle" | "lost_steps" => self.stepped[j],
                "motor_speed" => has_motor,
                "friction" => friction,
                "winding_temperature" => self.heated[j],
                "servo" => self.servo_driven[j],
                "measured_effort" => self.measured[j],
                "observed" => self.observed[j],
                _ => true,
            };
            for (leaf, style) in styles.into_iter().filter(|(leaf, _)| recorded(leaf)) {
                rec.log_static(format!("{base}/{leaf}"), &style).map_err(e)?;
            }
            rec.log_static(
                format!("{base}/saturated_torque"),
                &rerun::SeriesPoints::new()
                    .with_names([format!("{name} saturated")])
                    .with_colors([rgb(SATURATED_RGB)])
                    .with_markers([rerun::components::MarkerShape::Circle])
                    .with_marker_sizes([1.5]),
            )
            .map_err(e)?;
        }
        rec.log_static(
            "tool/position",
            &rerun::SeriesLines::new()
                .with_names(["tool x (m)", "tool y (m)", "tool z (m)"])
                .with_colors([rerun::Color::from_rgb(220, 60, 60), rerun::Color::from_rgb(60, 170, 60), rerun::Color::from_rgb(60, 90, 220)]),
        )
        .map_err(e)?;
        rec.log_static("tool_error", &rerun::SeriesLines::new().with_names(["tool tip error |p − p_cmd| (m)"]).with_colors([rerun::Color::from_rgb(230, 60, 60)])).map_err(e)?;
        if self.collisions.is_some() {
            rec.log_static("collisions/in_contact", &rerun::SeriesLines::new().with_names(["pairs in contact"]).with_colors([CONTACT])).map_err(e)?;
            rec.log_static("collisions/min_distance", &rerun::SeriesLines::new().with_names(["closest pair distance (m; < 0: overlap)"]).with_colors([rerun::Color::from_rgb(60, 90, 220)])).map_err(e)?;
        }
        Ok(())
    }

    /// Sends the block's series; the poses too when they fill a chunk of their own, when a live
    /// viewer waits for them, or at the end (`all`).
    fn flush_block(&mut self, all: bool) -> Result<(), Error> {
        let Some(rec) = self.rec.clone() else { return Ok(()) };
        if self.times.is_empty() {
            return Ok(());
        }
        let time = TimeColumn::new_duration_secs(TIMELINE, self.times.iter().copied());
        let steps = self.times.len();
        // room for a block like this one: a file's are all of FILE_BLOCK_STEPS, a live viewer's a few
        // steps each (a lent vector's unused room is memory Rerun does not count as in flight)
        let capacity = steps + 1;
        // the list offsets of a column of `width` values per row: the same for every such column
        let offsets: [OffsetBuffer<i32>; 3] = std::array::from_fn(|w| OffsetBuffer::from_lengths(std::iter::repeat_n(w + 1, steps)));
        // the every-step columns move into Arrow and the recorder goes on in vectors from the pool
        let (pool, ids) = (&self.values_pool, &self.ids_pool);
        let lend = |values: &mut Vec<f64>, width: usize| {
            debug_assert_eq!(values.len(), width * steps);
            let full = std::mem::replace(values, pool.take(width * capacity));
            vec![list_column(pool.buffer(full), offsets[width - 1].clone(), rerun::Scalars::descriptor_scalars())]
        };
        let out = self.output_path();
        let send = |entity: &str, time: TimeColumn, columns: Vec<rerun::SerializedComponentColumn>| send_chunk_in_order(&rec, entity, time, columns, ids).map_err(|x| Error::output(&out, x));
        let scalars = |values: &[f64], width: usize| vec![scalar_column(values, width)];
        for (j, name) in self.joint_names.iter().enumerate() {
            let c = &mut self.joints[j];
            let base = format!("joints/{name}");
            for (leaf, values, width) in [("position", &mut c.position, 2), ("torque", &mut c.torque, 2), ("status", &mut c.status, 3)] {
                send(&format!("{base}/{leaf}"), time.clone(), lend(values, width))?;
            }
            if self.motors.as_ref().is_some_and(|m| m.joints[j].is_some()) {
                send(&format!("{base}/motor_speed"), time.clone(), scalars(&c.motor_speed, 1))?;
            }
            if !c.friction.is_empty() {
                send(&format!("{base}/friction"), time.clone(), scalars(&c.friction, 2))?;
            }
            if !c.winding.is_empty() {
                send(&format!("{base}/winding_temperature"), time.clone(), scalars(&c.winding, 1))?;
            }
            if self.servo_driven[j] {
                send(&format!("{base}/servo"), time.clone(), scalars(&c.servo, 2))?;
            }
            if self.measured[j] {
                send(&format!("{base}/measured_effort"), time.clone(), scalars(&c.measured, 2))?;
            }
            if self.observed[j] {
                send(&format!("{base}/observed"), time.clone(), scalars(&c.observed, 1))?;
            }
            if self.stepped[j] {
                send(&format!("{base}/load_angle"), time.clone(), scalars(&c.load_angle, 1))?;
                send(&format!("{base}/lost_steps"), time.clone(), scalars(&c.lost_steps, 1))?;
            }
            if !c.saturated_times.is_empty() {
                let times = TimeColumn::new_duration_secs(TIMELINE, c.saturated_times.iter().copied());
                send(&format!("{base}/saturated_torque"), times, scalars(&c.saturated_torque, 1))?;
            }
            // the limits: at every step when they fall with speed, else as lines spanning each block
            // for a live viewer (they grow with the run; a file gets them once, `limit_lines`)
            let effort = self.effort[j];
            if self.motors.is_some() {
                send(&format!("{base}/torque_limit"), time.clone(), scalars(&c.limit, 2))?;
            } else if effort.is_finite() && self.live {
                let ends = TimeColumn::new_duration_secs(TIMELINE, [self.times[0], self.times[steps - 1]]);
                send(&format!("{base}/torque_limit"), ends, scalars(&[effort, -effort, effort, -effort], 2))?;
            }
        }
        send("tool/position", time.clone(), lend(&mut self.tool, 3))?;
        send("tool_error", time.clone(), lend(&mut self.tool_error, 1))?;
        if let Some(c) = &self.collisions {
            send("collisions/in_contact", time.clone(), scalars(&c.count, 1))?;
            send("collisions/min_distance", time.clone(), scalars(&c.min_distance, 1))?;
        }
        if !self.trail_strips.is_empty() {
            let times = TimeColumn::new_duration_secs(TIMELINE, self.trail_times.iter().copied());
            send("world/tool/trail", times, vec![self.trail_strips.take_column(&self.points_pool)])?;
        }
        let send_poses = !self.pose_times.is_empty() && (all || self.live || self.pose_times.len() >= FILE_BLOCK_STEPS);
        if send_poses {
            let pose_time = TimeColumn::new_duration_secs(TIMELINE, self.pose_times.iter().copied());
            for link in &self.links {
                let poses = vec![
                    float32_column::<rerun::components::Translation3D>(link.translations.as_flattened(), rerun::Transform3D::descriptor_translation()),
                    float32_column::<rerun::components::RotationQuat>(link.rotations.as_flattened(), rerun::Transform3D::descriptor_quaternion()),
                ];
                send(link.entity.as_str(), pose_time.clone(), poses)?;
            }
        }
        self.times.clear();
        for j in &mut self.joints {
            j.clear();
        }
        self.tool.clear();
        self.tool_error.clear();
        if let Some(c) = self.collisions.as_mut() {
            c.flush(&rec).map_err(|x| self.err(x))?;
        }
        self.trail_times.clear();
        if send_poses {
            self.pose_times.clear();
            for link in &mut self.links {
                link.translations.clear();
                link.rotations.clear();
            }
        }
        if self.live {
            let _ = rec.flush_async();
        }
        self.last_flush = Instant::now();
        Ok(())
    }

    /// A file's ±limit lines without `--motors`, each spanning the whole run, sent once at its end:
    /// a chunk of two rows per joint and block cost as much to encode as a full one, and a seventh
    /// of the file's chunks were those (a live viewer gets them with every block instead).
    fn limit_lines(&self, rec: &RecordingStream) -> Result<(), Error> {
        if self.live || self.motors.is_some() {
            return Ok(());
        }
        let ends = TimeColumn::new_duration_secs(TIMELINE, [self.first_time, self.last_time]);
        for (name, &effort) in self.joint_names.iter().zip(&self.effort).filter(|(_, e)| e.is_finite()) {
            send_in_order(rec, &format!("joints/{name}/torque_limit"), ends.clone(), [scalar_column(&[effort, -effort, effort, -effort], 2)]).map_err(|x| self.err(x))?;
        }
        Ok(())
    }
}

fn viewer_reachable(url: &str) -> Result<rerun::external::re_uri::ProxyUri, String> {
    let uri: rerun::external::re_uri::RedapUri = url.parse().map_err(|e| format!("{e}"))?;
    let rerun::external::re_uri::RedapUri::Proxy(proxy) = uri else {
        return Err("not a proxy URL like rerun+http://HOST:PORT/proxy".into());
    };
    let origin = &proxy.origin;
    let address = format!("{}:{}", origin.host, origin.port);
    let addrs = std::net::ToSocketAddrs::to_socket_addrs(&address).map_err(|e| e.to_string())?;
    for a in addrs {
        if std::net::TcpStream::connect_timeout(&a, Duration::from_millis(500)).is_ok() {
            return Ok(proxy);
        }
    }
    Err("connection refused".into())
}

fn link_entity(name: &str) -> String {
    format!("world/robot/{name}")
}

impl Recorder for RerunRecorder {
    fn start(&mut self, run: &RunInfo) -> Result<(), Error> {
        let e = run.experiment;
        let model = &*e.model;
        let rec = self.open_stream(e.config.duration)?;
        self.joint_names = model.joints.iter().map(|j| j.name.clone()).collect();
        self.effort = e.controller().effort;
        self.stepped = e.stepped_joints();
        self.servo_driven = e.firmware_joints();
        self.heated = e.motor_heat().iter().map(Option::is_some).collect();
        self.measured = (0..model.dof()).map(|j| run.measured_effort.get(j).copied().unwrap_or(false)).collect();
        self.observed = (0..model.dof()).map(|j| run.observed_position.get(j).copied().unwrap_or(false)).collect();
        self.motors = e.motors.clone();
        let cap = FILE_BLOCK_STEPS + 1;
        self.times = Vec::with_capacity(cap);
        self.joints = (0..model.dof()).map(|_| JointColumns::with_capacity(cap, &self.values_pool)).collect();
        self.tool = self.values_pool.take(3 * cap);
        self.tool_error = self.values_pool.take(cap);
        self.links = model
            .frames
            .iter()
            .enumerate()
            .filter(|(_, f)| f.body.is_some())
            .map(|(frame, f)| MovingLink { frame, entity: link_entity(&f.name), translations: Vec::with_capacity(cap), rotations: Vec::with_capacity(cap) })
            .collect();
        self.model = Some(e.model.clone());
        self.collisions = e.collisions.clone().map(|c| RrdCollisions::new(e.model.clone(), c));
        self.steps_per_trail_point = ((1.0 / TRAIL_RATE_HZ) / e.config.dt).round().max(1.0) as usize;
        self.steps_per_pose = crate::recorder::steps_per_pose(e.config.dt);

        // the layout: a live viewer needs it now (scaled by the motion's torque); a file gets it at
        // the end, scaled by what the run did as well
        if self.live {
            let (layout, torque_ranges) = blueprint(&self.joint_names, &self.stepped, &self.servo_driven, &self.heated, self.collisions.is_some(), run.torque_axes(), "");
            send_blueprint(&rec, &layout, &torque_ranges).map_err(|x| self.err(x))?;
        }
        self.log_static_scene(&rec, model)?;
        if let Some(floor) = e.floor_contact() {
            // the table the tool rests on (the motor file's [floor])
            let (plate, pose) = floor_plate(floor.height, TABLE_SIDE);
            rec.log_static("world/floor", &transform(&pose)).map_err(|x| self.err(x))?;
            log_geometry(&rec, "world/floor", &plate, Some(rerun::Color::from_unmultiplied_rgba(TABLE_RGBA[0], TABLE_RGBA[1], TABLE_RGBA[2], TABLE_RGBA[3]))).map_err(|x| self.err(x))?;
        }
        self.log_series_styles(&rec, e.joint_has_friction().contains(&true))?;
        rec.log_static("config", &rerun::TextDocument::from_markdown(config_markdown(run))).map_err(|x| self.err(x))?;
        let commanded: Vec<[f32; 3]> = run.commanded_tool_path.iter().map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect();
        // a command that holds still has no path to draw
        let spread = commanded.iter().any(|p| (0..3).any(|a| (p[a] - commanded[0][a]).abs() > 1e-4));
        if spread {
            rec.log_static(
                "world/tool/commanded_path",
                &rerun::LineStrips3D::new([commanded]).with_colors([rerun::Color::from_rgb(120, 120, 120)]).with_radii([0.0015]),
            )
            .map_err(|x| self.err(x))?;
        }
        // the tip is the tool link's origin: a static point under its entity moves with it
        rec.log_static(
            format!("{}/tip", link_entity(&model.frames[model.tool_frame].name)),
            &rerun::Points3D::new([[0.0f32, 0.0, 0.0]]).with_radii([0.006]).with_colors([rerun::Color::from_rgb(230, 40, 40)]),
        )
        .map_err(|x| self.err(x))?;
        rec.log_static("world/tool/trail", &rerun::LineStrips3D::update_fields().with_colors([rerun::Color::from_rgb(230, 60, 60)]).with_radii([0.002]))
            .map_err(|x| self.err(x))?;
        self.rec = Some(rec);
        self.last_flush = Instant::now();
        Ok(())
    }

    fn record(&mut self, s: &Sample) -> Result<(), Error> {
        if s.k == 0 {
            self.first_time = s.t;
        }
        self.last_time = s.t;
        self.times.push(s.t);
        for (j, c) in self.joints.iter_mut().enumerate() {
            let flag = |b: bool| if b { 1.0 } else { 0.0 };
            c.position.extend_from_slice(&[s.q[j], s.cmd[j]]);
            c.torque.extend_from_slice(&[s.u[j], s.tau_g[j]]);
            if self.motors.is_some() {
                c.limit.extend_from_slice(&[s.torque_limit[j], -s.torque_limit[j]]);
            }
            if let Some(speed) = self.motors.as_ref().and_then(|m| m.motor_speed(j, s.v[j])) {
                c.motor_speed.push(speed);
            }
            if self.stepped[j] {
                c.load_angle.push(s.load_angle[j]);
                c.lost_steps.push(s.lost_steps[j] as f64);
            }
            c.status.extend_from_slice(&[s.tracking_error(j), flag(s.saturated[j]), flag(s.chatter[j])]);
            if !s.friction.is_empty() {
                c.friction.extend_from_slice(&[s.friction[j], flag(s.stuck[j])]);
            }
            if self.heated[j] {
                c.winding.push(s.winding_temperature[j]);
            }
            if self.measured[j] {
                let measured = s.measured_effort[j];
                c.measured.extend_from_slice(&[measured, measured - s.u[j]]);
            }
            if self.observed[j] {
                c.observed.push(s.observed_position[j]);
            }
            if self.servo_driven[j] {
                c.servo.extend_from_slice(&[s.duty[j], s.current[j]]);
            }
            if s.saturated[j] {
                c.saturated_times.push(s.t);
                c.saturated_torque.push(s.u[j]);
            }
        }
        let p = s.tool_position;
        self.tool.extend_from_slice(&[p.x, p.y, p.z]);
        self.tool_error.push(s.tool_error());
        if let Some(c) = self.collisions.as_mut() {
            c.record(s);
        }
        let tip = [p.x as f32, p.y as f32, p.z as f32];
        if s.k.is_multiple_of(self.steps_per_pose) || s.is_final {
            let model = self.model.as_deref().expect("started");
            self.pose_times.push(s.t);
            for link in &mut self.links {
                let pose = frame_pose_in(model, s.body_pose, link.frame);
                let t = pose.translation;
                link.translations.push([t.x as f32, t.y as f32, t.z as f32]);
                link.rotations.push(quaternion_xyzw(&pose));
            }
        }
        if s.k.is_multiple_of(self.steps_per_trail_point) {
            self.trail.push_back(tip);
            let keep = (TRAIL_SECONDS * TRAIL_RATE_HZ) as usize;
            while self.trail.len() > keep {
                self.trail.pop_front();
            }
            self.path.push(tip);
            self.trail_times.push(s.t);
            self.trail_strips.push(self.trail.iter().copied(), &self.points_pool);
        }
        let due = self.times.len() >= FILE_BLOCK_STEPS || (self.live && self.last_flush.elapsed() >= LIVE_FLUSH) || s.is_final;
        if due {
            self.flush_block(s.is_final)?;
        }
        Ok(())
    }

    fn finish(&mut self, run: &RunInfo, summary: &Summary) -> Result<(), Error> {
        self.flush_block(true)?;
        let Some(rec) = self.rec.take() else { return Ok(()) };
        self.limit_lines(&rec)?;
        // the layout, its torque plots scaled by what the run's drives settled to as well: sent
        // now to a file, again to a live viewer where the scale changed (its second layout)
        let settled = |i: usize| summary.peak_abs_torque_after_settle.get(i).copied().flatten();
        let axes: Vec<_> = run.torque_axes().iter().enumerate().map(|(i, axis)| axis.after_run(settled(i))).collect();
        if !self.live || axes != run.torque_axes() {
            let (layout, torque_ranges) = blueprint(&self.joint_names, &self.stepped, &self.servo_driven, &self.heated, self.collisions.is_some(), &axes, "");
            send_blueprint(&rec, &layout, &torque_ranges).map_err(|x| self.err(x))?;
        }
        if self.path.points().len() > 1 {
            rec.log_static("world/tool/path", &rerun::LineStrips3D::new([self.path.points().to_vec()]).with_colors([rerun::Color::from_rgb(230, 60, 60)]).with_radii([0.001]))
                .map_err(|x| self.err(x))?;
        }
        rec.log_static("summary", &rerun::TextDocument::from_markdown(summary_markdown(summary))).map_err(|x| self.err(x))?;
        rec.flush_blocking().map_err(|x| self.err(x))?;
        drop(rec);
        if let Some(file) = self.file.take() {
            file.close().map_err(|e| Error::output(file.path(), e))?;
        }
        Ok(())
    }
}
