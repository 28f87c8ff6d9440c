//! Forward replay: an episode's commands (LeRobot's `action`, the leader's positions; a ROS 2 bag's
//! trajectory-controller set points) followed by the simulated arm through each joint's motor — a bus
//! servo through its firmware loop — and held against what the real follower did
//! (`observation.state`, the bag's joint states): the sim-to-real gap of the whole arm, per joint.

use super::at_rest::{AtRest, REST_BAND};
use super::{Replayer, following, inverse_replay, schedule};
use crate::config::RunConfig;
use crate::error::Error;
use crate::experiment::Experiment;
use crate::motion::Episode;
use crate::recorder::{Recorder, RunInfo};
use crate::sample::Sample;
use crate::summary::Summary;
use std::path::{Path, PathBuf};

/// The gap at which the simulated and the real follower are said to part, rad (3°: well above an
/// encoder's quantum and a servo's deadband, well below a missed motion).
pub const PARTS_ABOVE: f64 = 0.05;

/// One joint's tracking, real and simulated, and the gap between them, rad (m).
#[derive(Clone, Debug, serde::Serialize)]
pub struct JointGap {
    pub joint: String,
    /// Mean and largest |observed − commanded|: how the real follower tracked.
    pub real_tracking_mae: f64,
    pub real_tracking_max: f64,
    /// Mean and largest |simulated − commanded|: how the model tracked.
    pub sim_tracking_mae: f64,
    pub sim_tracking_max: f64,
    /// Mean and largest |simulated − observed|, and when the largest was, s.
    pub gap_mae: f64,
    pub gap_max: f64,
    pub gap_max_at: f64,
    /// The first time the gap exceeds [`PARTS_ABOVE`], s.
    pub parts_at: Option<f64>,
    /// False where the real joint stayed put while its commands swept (a servo off, a cable
    /// loose): its gap is no model's, and it is left out of the ranking and of identification.
    pub follows: bool,
    /// How far the commands and the real joint ranged, rad (m).
    pub commanded_sweep: f64,
    pub observed_sweep: f64,
    /// The part of the gap made where the commands and the real joint both stood still.
    pub at_rest: AtRest,
}

/// One episode replayed forward.
#[derive(Clone, Debug)]
pub struct ForwardReplay {
    pub label: String,
    /// The episode's frame times from its first frame, s.
    pub time: Vec<f64>,
    /// Per joint of the map, at every frame: commanded, observed and simulated positions.
    pub commanded: Vec<Vec<f64>>,
    pub observed: Vec<Vec<f64>>,
    pub simulated: Vec<Vec<f64>>,
    pub joints: Vec<JointGap>,
    /// The firmware protections the simulated servos tripped, by joint (a Feetech's overload or
    /// overcurrent): where the model's follower gave up.
    pub protection_trips: Vec<(String, crate::actuator::bus_servo::Trip)>,
    /// The recorded joints no command named: sent where the real joint was, not compared.
    pub uncommanded: Vec<String>,
    /// The command latency the model was given.
    pub latency: Latency,
    /// Per compared joint driven by a bus servo, its firmware's own command delay (the bus's and the
    /// firmware's, from the motor file), s: it adds to the latency.
    pub servo_delays: Vec<(String, f64)>,
    /// Where the commands' and the follower's positions passed a joint's URDF limit.
    pub past_limits: Vec<super::past_limits::PastLimit>,
}

/// What the run needs beyond the replayer: the motor file (required: the joints' servos), payload and
/// tool, and where to write the command schedule the run follows.
pub struct ForwardOptions {
    pub motors: PathBuf,
    pub payload: f64,
    pub tool: Option<String>,
    pub schedule: PathBuf,
    /// The recordings of the simulated arm, the real follower beside it (None: none).
    pub recordings: Option<super::recording::RecordingOutputs>,
    /// How long after its frame a command reaches the servos (None: the recording's frame period,
    /// a teleop loop's one frame).
    pub latency: Option<Latency>,
    /// Where to write the frames compared, command, real and simulated (None: nowhere).
    pub trace: Option<PathBuf>,
    /// The motor file's floor left out (a recording whose tool went through it: not its table).
    pub without_floor: bool,
    /// The joints (the model's coordinates) that do not follow their commands in another episode of
    /// the recording: taken as off in this one too where its commands do not sweep far enough to
    /// tell and the real joint stayed put.
    pub off_elsewhere: Vec<usize>,
}

/// The longest command latency accepted, s: a teleop loop slower than this is not one.
pub const MAX_LATENCY: f64 = 1.0;

/// `seconds` as a command latency, or the one line that refuses it (naming `--latency`).
pub fn check_latency(seconds: f64) -> Result<(), Error> {
    if (0.0..=MAX_LATENCY).contains(&seconds) {
        return Ok(());
    }
    Err(Error::flag("--latency", if seconds.is_finite() { format!("{seconds} s: a command latency is between 0 and {MAX_LATENCY} s") } else { format!("must be a number of seconds between 0 and {MAX_LATENCY}") }))
}

/// The latency a forward replay models and where it came from.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Latency {
    pub seconds: f64,
    /// Why that long ("one frame", "--latency", …).
    pub from: String,
}

impl Latency {
    pub fn given(seconds: f64, from: &str) -> Self {
        Self { seconds, from: from.to_string() }
    }
}

/// Follow `commands` on the simulated arm from where the real follower starts, and compare with
/// `observed`.
pub fn forward(replayer: &Replayer, options: &ForwardOptions, commands: &Episode, observed: &Episode) -> Result<ForwardReplay, Error> {
    let case = ForwardCase::prepare(replayer, commands, observed, &options.schedule, options.latency.clone(), &options.off_elsewhere)?;
    let setup = FollowSetup { payload: options.payload, tool: options.tool.as_deref(), offsets: None, without_floor: options.without_floor };
    // the motor file as the replayer read it, copied for each of the run's two experiments: reading
    // it and its catalogue again for each took a fifth of the replay's time (50 episodes of a real
    // SO-101: 1.2–1.3 s, then 0.93–0.96 s)
    let replay = match replayer.motors.as_deref().filter(|set| set.source == options.motors) {
        Some(set) => follow(&replayer.base_model, &case, &Drives::Made { file: &options.motors, make: &|| Ok(set.clone()) }, &setup, options.recordings.as_ref())?,
        None => follow(&replayer.base_model, &case, &Drives::File(&options.motors), &setup, options.recordings.as_ref())?,
    };
    if let Some(path) = &options.trace {
        super::trace::write_forward(path, &replay)?;
    }
    Ok(replay)
}

/// An episode made ready to be followed, as many times as asked (identification follows it once per
/// candidate): its commands and the real follower in the model's coordinates, its command schedule
/// written.
#[derive(Clone)]
pub struct ForwardCase {
    pub label: String,
    command: super::Motion,
    reality: super::Motion,
    /// The joints both commanded and recorded (compared), and those recorded only (sent where the
    /// real joint was).
    mapped: Vec<usize>,
    uncommanded: Vec<usize>,
    /// The compared joints that do not follow their commands, sent where the real joint was.
    held: Vec<usize>,
    latency: Latency,
    schedule: PathBuf,
    /// That schedule as read back: each run of the episode follows a copy (reading the file again
    /// for each of a candidate's runs was 1.7 % of its instructions).
    parsed: crate::control::trajectory::JointSchedule,
    /// Where the commands' or the follower's positions passed a joint's URDF limit, the largest
    /// excess per joint.
    past_limits: Vec<super::past_limits::PastLimit>,
}

impl ForwardCase {
    /// Map and smooth the episode's commands and observations, and write the schedule the simulated
    /// servos follow (`latency` after each frame; None: one frame) to `schedule`; `off_elsewhere`:
    /// the joints that do not follow in another episode of the recording.
    pub fn prepare(replayer: &Replayer, commands: &Episode, observed: &Episode, schedule: &Path, latency: Option<Latency>, off_elsewhere: &[usize]) -> Result<Self, Error> {
        let model = &replayer.base_model;
        let mut command = inverse_replay(&replayer.model, &replayer.map.only_columns_of(commands), commands, &replayer.hold)?;
        let reality = inverse_replay(&replayer.model, &replayer.map, observed, &replayer.hold)?;
        if command.len() != reality.len() || command.time.iter().zip(&reality.time).any(|(a, b)| (a - b).abs() > 1e-9) {
            return Err(Error::flag(commands.label.clone(), format!("its commands ({} frames) and observations ({} frames) are not sampled at the same times", command.len(), reality.len())));
        }
        let n = model.dof();
        // a joint no command names (a bag's other controller) is sent where the real joint was
        let uncommanded: Vec<usize> = (0..n).filter(|&j| command.recorded[j].is_none() && reality.recorded[j].is_some()).collect();
        for &j in &uncommanded {
            command.q[j] = reality.q[j].clone();
        }
        let mapped: Vec<usize> = (0..n).filter(|&j| command.recorded[j].is_some() && reality.recorded[j].is_some()).collect();
        if mapped.is_empty() {
            return Err(Error::flag(commands.label.clone(), format!("its commands name none of the recorded joints (commands: {})", commands.column_names().join(", "))));
        }
        // a joint whose real follower stayed put while its commands swept (a servo off, a cable
        // loose) is sent where the real joint was, as one no command names: the joints beside it then
        // carry it where the real arm did (it is still held against its commands, as not following)
        let sweeps = following::sweeps(&command.recorded, &reality.recorded);
        let held: Vec<usize> = mapped.iter().copied().filter(|&j| matches!(sweeps[j], Some((c, o)) if !following::follows(c, o, off_elsewhere.contains(&j)))).collect();
        for &j in &held {
            command.q[j] = reality.q[j].clone();
        }
        // LeRobot's loop reads the follower, then the leader, then sends the action: frame t's command
        // reaches the servos after observation t, the bus and the firmware add theirs (the servos' own
        // command_delay)
        let latency = latency.unwrap_or_else(|| Latency::given(schedule::frame_period(&command), "one frame"));
        schedule::write_delayed(schedule, &command, latency.seconds)?;
        let parsed = crate::control::trajectory::JointSchedule::load(schedule, n)?;
        let past_limits = super::past_limits::largest_per_joint(command.past_limits.iter().chain(&reality.past_limits));
        Ok(Self { label: commands.label.clone(), command, reality, mapped, uncommanded, held, latency, schedule: schedule.to_path_buf(), parsed, past_limits })
    }

    /// Where the commands' and the follower's positions passed a joint's URDF limit (followed to it).
    pub fn past_limits(&self) -> &[super::past_limits::PastLimit] {
        &self.past_limits
    }

    /// The compared joints (the model's coordinates).
    pub fn compared(&self) -> &[usize] {
        &self.mapped
    }

    /// The compared joints that do not follow their commands (the real joint stayed put while they
    /// swept): the model holds them where the real one was.
    pub fn not_following(&self) -> &[usize] {
        &self.held
    }

    /// The commands as the model's joint positions (per coordinate, per frame).
    pub fn commanded(&self) -> &super::Motion {
        &self.command
    }

    /// The real follower's positions (per coordinate, per frame).
    pub fn real(&self) -> &super::Motion {
        &self.reality
    }

    /// The episode's frames.
    pub fn frames(&self) -> usize {
        self.command.len()
    }

    /// The episode's length, s.
    pub fn duration(&self) -> f64 {
        schedule::span(&self.command).0
    }
}

/// Where the simulated follower's drives come from: the motor file, or a motor set made afresh for
/// each experiment built (identification's candidates: the file's with other servo parameters).
pub enum Drives<'a> {
    File(&'a Path),
    Made { file: &'a Path, make: &'a (dyn Fn() -> Result<crate::actuator::MotorSet, Error> + Sync) },
}

/// What a follower is run with beyond its drives: the payload (kg) at the tool, per coordinate the
/// offset of the recording's angles from the arm's (None: none) — the arm runs at the recording's
/// poses plus their offset, and is compared with the recording less it — and whether the motor
/// file's floor is left out.
#[derive(Clone, Copy, Debug, Default)]
pub struct FollowSetup<'a> {
    pub payload: f64,
    pub tool: Option<&'a str>,
    pub offsets: Option<&'a [f64]>,
    /// The motor file's floor left out.
    pub without_floor: bool,
}

impl FollowSetup<'_> {
    fn offset(&self, j: usize) -> f64 {
        self.offsets.map_or(0.0, |o| o[j])
    }
}

/// The experiment that follows `case`: the run starts at rest where the real follower starts (one
/// whose first frame is far from its leader's catches up, as the real one did), its servos holding
/// the goal at which they sag to that pose under the weight — the set-up sags the arm from the goal
/// it is given, so the goal is the pose less the sag there.
fn follower_experiment(model: &crate::model::Model, case: &ForwardCase, drives: &Drives, setup: &FollowSetup) -> Result<Experiment, Error> {
    let n = model.dof();
    let within = |j: usize, q: f64| {
        let (lowest, highest) = model.joints[j].range();
        q.clamp(lowest, highest)
    };
    let observed_start: Vec<f64> = case.reality.q.iter().enumerate().map(|(j, joint)| within(j, joint[0] + setup.offset(j))).collect();
    let motor_file = match drives {
        Drives::File(file) | Drives::Made { file, .. } => file.to_path_buf(),
    };
    let config_from = |start: &[f64]| RunConfig {
        urdf: model.source.clone(),
        motors: Some(motor_file.clone()),
        payload: setup.payload,
        tool: setup.tool.map(str::to_string),
        trajectory: Some(case.schedule.clone()),
        duration: case.duration(),
        q0: Some(start.iter().map(|q| format!("{q:?}")).collect::<Vec<_>>().join(",")),
        ..RunConfig::default()
    };
    let experiment_from = |start: &[f64]| -> Result<Experiment, Error> {
        let mut motors = match drives {
            Drives::File(file) => crate::actuator::load_motor_file(file, model)?,
            Drives::Made { make, .. } => make()?,
        };
        if setup.without_floor {
            motors.floor = None;
        }
        let mut experiment = Experiment::following(config_from(start), model.clone(), Some(motors), case.parsed.clone())?;
        if let Some(offsets) = setup.offsets {
            let inner = std::mem::replace(&mut experiment.trajectory, Box::new(crate::control::trajectory::Hold));
            experiment.trajectory = Box::new(crate::control::trajectory::Shifted { inner, offsets: offsets.to_vec() });
        }
        Ok(experiment)
    };
    let sagged = experiment_from(&observed_start)?.initial_state().0;
    let goal: Vec<f64> = (0..n).map(|j| within(j, 2.0 * observed_start[j] - sagged[j])).collect();
    experiment_from(&goal)
}

/// The sum over the frames and the joints `fitted` of |simulated − real| of `case` followed, run only
/// as far as it stays within `budget` (rad·frames): (the sum, false), or (a sum past the budget,
/// true) once stopped there. What identification ranks a candidate by, at a fraction of a whole
/// follow's cost for the candidates that cannot win.
pub fn gap_within(model: &crate::model::Model, case: &ForwardCase, drives: &Drives, setup: &FollowSetup, fitted: &[bool], budget: f64) -> Result<(f64, bool), Error> {
    let experiment = follower_experiment(model, case, drives, setup)?;
    let dt = experiment.dt();
    let t0 = case.command.time[0];
    let joints: Vec<usize> = case.mapped.iter().copied().filter(|&j| fitted[j]).collect();
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut watch = GapWatch {
        wanted: case.command.time.iter().map(|t| ((t - t0) / dt).round() as usize).collect(),
        observed: joints.iter().map(|&j| case.reality.recorded[j].clone().unwrap_or_default()).collect(),
        offsets: joints.iter().map(|&j| setup.offset(j)).collect(),
        joints,
        next: 0,
        sum: 0.0,
        budget,
        stop: &stop,
    };
    match crate::sim::simulate_positions(&experiment, &mut [&mut watch], Some(&stop))? {
        crate::summary::RunStatus::Completed => Ok((watch.sum, false)),
        crate::summary::RunStatus::Interrupted { .. } => Ok((watch.sum, true)),
        other => Err(Error::Diverged(format!("{}: the forward replay did not complete: {other:?}", case.label))),
    }
}

/// Follow `case` on the simulated arm (`model`) through `drives` with `setup`, and compare with the
/// real follower; the run's recordings where asked.
pub fn follow(model: &crate::model::Model, case: &ForwardCase, drives: &Drives, setup: &FollowSetup, recordings: Option<&super::recording::RecordingOutputs>) -> Result<ForwardReplay, Error> {
    let (command, reality) = (&case.command, &case.reality);
    let experiment = follower_experiment(model, case, drives, setup)?;
    let dt = experiment.dt();
    let t0 = command.time[0];
    let time: Vec<f64> = command.time.iter().map(|t| t - t0).collect();
    let mut capture = Capture::at_steps(time.iter().map(|t| (t / dt).round() as usize).collect());
    let mut files = recordings.map_or_else(|| Ok(Vec::new()), |r| r.open())?;
    let mut recorders: Vec<&mut dyn Recorder> = vec![&mut capture];
    recorders.extend(files.iter_mut().map(|r| &mut **r as &mut dyn Recorder));
    // the real follower as recorded (before smoothing), beside the simulated one
    let follower = crate::sim::Observed { time: reality.time.iter().map(|t| t - t0).collect(), positions: reality.recorded.clone() };
    let summary = crate::sim::simulate_beside(&experiment, &mut recorders, None, Some(&follower))?;
    drop(recorders);
    if !matches!(summary.status, crate::summary::RunStatus::Completed) {
        return Err(Error::Diverged(format!("{}: the forward replay did not complete: {:?}", case.label, summary.status)));
    }
    let simulated_at = capture.finish();
    let (mut commanded, mut observed, mut simulated, mut joints) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for &j in &case.mapped {
        let c: Vec<f64> = command.recorded[j].clone().unwrap_or_default();
        let o: Vec<f64> = reality.recorded[j].clone().unwrap_or_default();
        let s: Vec<f64> = simulated_at.iter().map(|q| q[j] - setup.offset(j)).collect();
        joints.push(JointGap::of(&model.joints[j].name, &time, &c, &o, &s, !case.held.contains(&j)));
        commanded.push(c);
        observed.push(o);
        simulated.push(s);
    }
    let protection_trips = summary.servos.iter().enumerate().filter_map(|(j, s)| Some((model.joints[j].name.clone(), s.as_ref()?.protection_trip?))).collect();
    let uncommanded = case.uncommanded.iter().map(|&j| model.joints[j].name.clone()).collect();
    let servo_delays = match &experiment.motors {
        Some(motors) => case.mapped.iter().filter_map(|&j| Some((model.joints[j].name.clone(), motors.joints[j].as_ref()?.servo.as_ref()?.command_delay))).collect(),
        None => Vec::new(),
    };
    Ok(ForwardReplay { label: case.label.clone(), time, commanded, observed, simulated, joints, protection_trips, uncommanded, latency: case.latency.clone(), servo_delays, past_limits: case.past_limits.clone() })
}

impl JointGap {
    /// The figures of one joint from its commanded, observed and simulated positions at `time`.
    fn of(joint: &str, time: &[f64], c: &[f64], o: &[f64], s: &[f64], follows: bool) -> Self {
        let stats = |a: &[f64], b: &[f64]| -> (f64, f64, usize) {
            let mut worst = (0.0f64, 0usize);
            let mut sum = 0.0;
            for k in 0..a.len() {
                let e = (a[k] - b[k]).abs();
                sum += e;
                if e > worst.0 {
                    worst = (e, k);
                }
            }
            (sum / a.len() as f64, worst.0, worst.1)
        };
        let (real_mae, real_max, _) = stats(o, c);
        let (sim_mae, sim_max, _) = stats(s, c);
        let (gap_mae, gap_max, at) = stats(s, o);
        let parts_at = (0..time.len()).find(|&k| (s[k] - o[k]).abs() > PARTS_ABOVE).map(|k| time[k]);
        let (commanded_sweep, observed_sweep) = (following::sweep(c), following::sweep(o));
        JointGap {
            joint: joint.to_string(),
            real_tracking_mae: real_mae,
            real_tracking_max: real_max,
            sim_tracking_mae: sim_mae,
            sim_tracking_max: sim_max,
            gap_mae,
            gap_max,
            gap_max_at: time[at],
            parts_at,
            follows,
            commanded_sweep,
            observed_sweep,
            at_rest: AtRest::of(time, c, o, s),
        }
    }
}

/// The run's joint positions at the control steps nearest the episode's frames (only those: memory
/// goes with the frames, not with the control rate).
struct Capture {
    /// Per frame, its control step (non-decreasing).
    wanted: Vec<usize>,
    q: Vec<Vec<f64>>,
    last: Vec<f64>,
}

impl Capture {
    fn at_steps(wanted: Vec<usize>) -> Self {
        Self { q: Vec::with_capacity(wanted.len()), wanted, last: Vec::new() }
    }

    /// Per frame, the positions there; frames past the run's last step get its last positions.
    fn finish(mut self) -> Vec<Vec<f64>> {
        while self.q.len() < self.wanted.len() {
            self.q.push(self.last.clone());
        }
        self.q
    }
}

impl Recorder for Capture {
    fn start(&mut self, _run: &RunInfo) -> Result<(), Error> {
        Ok(())
    }
    fn record(&mut self, sample: &Sample) -> Result<(), Error> {
        while self.q.len() < self.wanted.len() && self.wanted[self.q.len()] <= sample.k {
            self.q.push(sample.q.to_vec());
        }
        self.last.clear();
        self.last.extend_from_slice(sample.q);
        Ok(())
    }
    fn finish(&mut self, _run: &RunInfo, _summary: &Summary) -> Result<(), Error> {
        Ok(())
    }
}

/// The running gap of a follower at the episode's frames, stopping the run once it passes its budget.
struct GapWatch<'a> {
    /// Per frame, its control step (non-decreasing).
    wanted: Vec<usize>,
    joints: Vec<usize>,
    /// Per watched joint and frame, the real follower; and the joint's offset.
    observed: Vec<Vec<f64>>,
    offsets: Vec<f64>,
    next: usize,
    sum: f64,
    budget: f64,
    stop: &'a std::sync::atomic::AtomicBool,
}

impl Recorder for GapWatch<'_> {
    fn start(&mut self, _run: &RunInfo) -> Result<(), Error> {
        Ok(())
    }
    fn record(&mut self, sample: &Sample) -> Result<(), Error> {
        while self.next < self.wanted.len() && self.wanted[self.next] <= sample.k {
            for (w, &j) in self.joints.iter().enumerate() {
                self.sum += (sample.q[j] - self.offsets[w] - self.observed[w][self.next]).abs();
            }
            self.next += 1;
        }
        if self.sum > self.budget {
            self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        Ok(())
    }
    fn finish(&mut self, _run: &RunInfo, _summary: &Summary) -> Result<(), Error> {
        Ok(())
    }
}

/// The forward replay as a person reads it: a row per joint, mrad (mm on a prismatic joint).
pub fn text(replay: &ForwardReplay) -> String {
    let mut out = format!("{}: the simulated arm following its commands, against the real follower (mrad)\n", replay.label);
    let from = if replay.latency.from == "--latency" { "--latency".to_string() } else { format!("{}; --latency sets another", replay.latency.from) };
    out += &format!("  commands reach the model's servos {:.1} ms after their frame ({from}){}; tracking measured against the commands as recorded\n", replay.latency.seconds * 1e3, servo_delays_text(&replay.servo_delays));
    out += &format!("  {:<16} {:>18} {:>18} {:>22}  {}\n", "joint", "real tracking", "model tracking", "gap model − real", "parts (gap > 50 mrad)");
    out += &format!("  {:<16} {:>18} {:>18} {:>22}\n", "", "mean / max", "mean / max", "mean / max (at)");
    for g in &replay.joints {
        if !g.follows {
            out += &format!("  {:<16} does not follow its commands: they sweep {:.0}°, the real joint moved {:.1}° (a servo off, a cable loose?); the model's held where the real one was, left out of the ranking\n", g.joint, g.commanded_sweep.to_degrees(), g.observed_sweep.to_degrees());
            continue;
        }
        let parts = g.parts_at.map_or("never".to_string(), |t| format!("at {t:.2} s"));
        out += &format!(
            "  {:<16} {:>8.1} / {:>7.1} {:>8.1} / {:>7.1} {:>8.1} / {:>6.1} ({:>5.2} s)  {parts}\n",
            g.joint,
            g.real_tracking_mae * 1e3,
            g.real_tracking_max * 1e3,
            g.sim_tracking_mae * 1e3,
            g.sim_tracking_max * 1e3,
            g.gap_mae * 1e3,
            g.gap_max * 1e3,
            g.gap_max_at
        );
    }
    // said where rest makes half the gap or more, and the gap is more than a resting leader's jitter
    for g in replay.joints.iter().filter(|g| g.follows && g.gap_mae >= REST_BAND && g.at_rest.gap_part >= 0.5 * g.gap_mae) {
        out += &format!(
            "  {}: {:.1} of the {:.1} mrad mean gap made at rest ({:.1} s with the commands and the real joint still: the real joint {:.1} mrad from its commands, the model {:.1}): the model misses what holds the arm at rest (friction, a stop, a contact, a load), not how it moves\n",
            g.joint,
            g.at_rest.gap_part * 1e3,
            g.gap_mae * 1e3,
            g.at_rest.seconds,
            g.at_rest.real_offset * 1e3,
            g.at_rest.sim_offset * 1e3
        );
    }
    for joint in &replay.uncommanded {
        out += &format!("  {joint}: no command; sent where the real joint was, not compared\n");
    }
    for (joint, trip) in &replay.protection_trips {
        out += &format!("  {joint}: in the model {}\n", trip.describe());
    }
    out
}

/// The servos' own command delay after the latency, as the report's first line says it ("" where
/// no compared joint is a bus servo's).
fn servo_delays_text(delays: &[(String, f64)]) -> String {
    let (lowest, highest) = delays.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (_, d)| (lo.min(*d), hi.max(*d)));
    if delays.is_empty() {
        String::new()
    } else if highest - lowest < 5e-5 {
        format!(", the servos act on them {:.1} ms later (their command_delay)", highest * 1e3)
    } else {
        format!(", the servos act on them {:.1}–{:.1} ms later (their command_delay)", lowest * 1e3, highest * 1e3)
    }
}

/// One episode's forward replay as a batch keeps it: its findings, not its frames.
#[derive(Clone, Debug)]
pub struct ForwardSummary {
    pub index: i64,
    /// The largest mean gap of any joint, rad (m): how far the model misses this episode.
    pub widest_gap: f64,
    /// [`text`] of the replay.
    pub text: String,
    /// The episode's findings as `--summary-json` writes them.
    pub document: serde_json::Value,
    /// What reading the episode assumed, one line each.
    pub notices: Vec<String>,
    /// Where its commands' and its follower's positions passed a joint's URDF limit (said once for
    /// the recording).
    pub past_limits: Vec<super::past_limits::PastLimit>,
}

impl ForwardSummary {
    pub fn of(index: i64, replay: &ForwardReplay, notices: Vec<String>) -> Self {
        let trips: Vec<serde_json::Value> = replay.protection_trips.iter().map(|(joint, trip)| serde_json::json!({ "joint": joint, "trip": trip })).collect();
        let servo_delays: serde_json::Map<String, serde_json::Value> = replay.servo_delays.iter().map(|(joint, d)| (joint.clone(), serde_json::json!(d))).collect();
        let document = serde_json::json!({ "episode": index, "latency_s": replay.latency.seconds, "latency_from": replay.latency.from, "servo_command_delay_s": servo_delays, "joints": replay.joints, "protection_trips": trips, "uncommanded": replay.uncommanded, "past_limits": replay.past_limits });
        let widest_gap = replay.joints.iter().filter(|g| g.follows).map(|g| g.gap_mae).fold(0.0, f64::max);
        Self { index, widest_gap, text: text(replay), document, notices, past_limits: replay.past_limits.clone() }
    }
}

/// Replay `episodes` of `source` forward on `jobs` threads, each reduced to its summary as it goes
/// (`options` gives an episode's; its recordings, if any, are written as it runs). The summaries
/// come back the widest gap first.
pub fn forward_episodes(
    replayer: &Replayer,
    source: &crate::motion::Source,
    episodes: &[i64],
    feature: &str,
    commands: &crate::motion::commands::CommandSource,
    jobs: usize,
    options: &(dyn Fn(i64) -> ForwardOptions + Sync),
) -> Result<Vec<ForwardSummary>, Error> {
    let mut summaries = super::over_episodes(episodes, jobs, |index| {
        let (commands, observed) = source.read_forward(index, feature, commands)?;
        let replay = forward(replayer, &options(index), &commands, &observed)?;
        Ok(ForwardSummary::of(index, &replay, commands.notices))
    })?;
    summaries.sort_by(|a, b| b.widest_gap.total_cmp(&a.widest_gap));
    Ok(summaries)
}

/// Where the command schedule of the recording `name` (`forward_SOURCE[_episode_N]`) is written
/// beside its other outputs.
pub fn schedule_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}_commands.csv"))
}
