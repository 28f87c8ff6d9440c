//! `armscope replay`: a recorded motion (LeRobot dataset, ROS 2 bag, armscope `.mcap`, CSV) into
//! the torque each joint needed, held against what its motor gives.

use super::*;
use crate::motion::{Mapped, open_mapped};
use crate::replay::{ReplayOptions, Replayer, replay_episodes, report};

#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// The recording: a LeRobot dataset folder (v2.1 or v3.0), a ROS 2 bag or armscope recording
    /// (.mcap with sensor_msgs/msg/JointState or foxglove.JointStates), or a CSV (`t` and a column
    /// per joint, SI units).
    #[arg(value_name = "SOURCE")]
    pub source: PathBuf,
    /// The arm's URDF.
    #[arg(long, value_name = "PATH")]
    pub urdf: PathBuf,
    #[command(flatten)]
    pub recorded: crate::flags::RecordedMotionArgs,
    /// A payload at the tool, kg.
    #[arg(long, default_value_t = 0.0)]
    pub payload: f64,
    /// The link whose origin is the tool (where the payload sits; default: the deepest link).
    #[arg(long, value_name = "LINK")]
    pub tool: Option<String>,
    /// A motor file: each joint's motor and gearbox (the torque it gives at speed, the rotor's
    /// reflected inertia, the winding's heat); without it, the URDF's effort limits.
    #[arg(long, value_name = "FILE")]
    pub motors: Option<PathBuf>,
    /// Write `t,q1..qN,qd1..qN,qdd1..qN,tau1..tauN` per sample; with --forward, per frame each
    /// joint's command, real and simulated position, `t,command_J..,real_J..,model_J..` (several
    /// episodes: one file each, `STEM_episode_N.csv`).
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    /// Write every episode's findings as JSON.
    #[arg(long, value_name = "FILE")]
    pub summary_json: Option<PathBuf>,
    /// The recordings of the episode (several: of the most loaded one; NAME:
    /// replay_SOURCE[_episode_N]; with --forward, of the widest gap, forward_SOURCE[_episode_N]).
    #[command(flatten)]
    pub files: crate::flags::RecordingFiles,
    /// The MCAP's encoding, as `run --mcap-encoding`.
    #[arg(long, value_enum, default_value_t = crate::recorder::McapEncoding::Foxglove)]
    pub mcap_encoding: crate::recorder::McapEncoding,
    /// Episodes at once (default: all cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Forward replay instead: drive the simulated arm with each episode's commands (a dataset's
    /// `action`, a bag's trajectory controller) through each joint's motor (a bus servo through its
    /// firmware loop; needs --motors), starting where the commands start, and compare it with what
    /// the follower did (--feature, by default `observation.state`; a bag's joint states): the
    /// tracking of reality and of the model, and the gap between them.
    #[arg(long, requires = "motors")]
    pub forward: bool,
    /// With --forward on a ROS 2 bag: the commands' topic, a trajectory controller's state
    /// (control_msgs/msg/JointTrajectoryControllerState: its set point), the trajectories it was
    /// sent (trajectory_msgs/msg/JointTrajectory) or a forward command controller's positions
    /// (std_msgs/msg/Float64MultiArray, with --command-joints); default: the only one, a controller
    /// state first, then a trajectory.
    #[arg(long, value_name = "TOPIC", requires = "forward")]
    pub command_topic: Option<String>,
    /// With --forward on a bag whose commands are Float64MultiArrays: the joints they hold, in the
    /// controller's order (comma list, as the joint states name them).
    #[arg(long, value_name = "JOINTS", value_delimiter = ',', num_args = 1, requires = "forward")]
    pub command_joints: Option<Vec<String>>,
    /// With --forward: how long after its frame a command reaches the simulated servos, s (0–1;
    /// default: the recording's frame period, the teleop loop's one frame: LeRobot's loop reads the
    /// follower, then the leader, then sends the action). The servos' own bus and firmware delay is
    /// their parameters' `command_delay`, on top of this.
    #[arg(long, value_name = "SECONDS", requires = "forward")]
    pub latency: Option<f64>,
}

/// `armscope replay`.
pub fn replay(args: &ReplayArgs) -> Result<i32, Error> {
    let model = crate::model::load_urdf(&args.urdf)?;
    let recorded = &args.recorded;
    let (source, episodes, map) = match open_mapped(&args.source, recorded.topic.as_deref(), recorded.episode.as_deref(), &recorded.feature, recorded.joint_map.as_deref(), recorded.reading(), &model)? {
        Mapped::Ready(r) => {
            for notice in &r.notices {
                eprintln!("armscope: notice: {notice}");
            }
            (r.source, r.episodes, r.map)
        }
        Mapped::NeedsMap { template } => {
            println!("{template}");
            return Err(needs_map(&args.source, &args.urdf));
        }
    };
    let options = ReplayOptions { payload: args.payload, tool: args.tool.clone(), motors: args.motors.clone() };
    let replayer = Replayer::new(model, &options, map)?;
    if args.forward {
        return forward(args, &replayer, &source, &episodes);
    }
    for notice in &replayer.model.notices {
        eprintln!("armscope: notice: {notice}");
    }
    eprintln!("armscope: joint map: {}", replayer.map.source);
    let jobs = args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let several = episodes.len() > 1;
    let wants_recordings = !(args.files.no_rrd && args.files.no_mcap);
    let dataset = source.kind() == crate::motion::SourceKind::LeRobot;
    let stem = args.source.file_stem().map_or("recording".into(), |s| s.to_string_lossy().into_owned());
    // the recordings of one episode: recordings/replay_SOURCE[_episode_N].rrd/.mcap unless told
    let record = |index: i64, replay: &crate::replay::EpisodeReplay| -> Result<(), Error> {
        let name = crate::runner::file_safe(&if dataset { format!("replay_{stem}_episode_{index}") } else { format!("replay_{stem}") });
        let (rrd, mcap) = args.files.paths(&name);
        let outputs = crate::replay::recording::RecordingOutputs { rrd, mcap, mcap_encoding: args.mcap_encoding, name };
        crate::replay::recording::record(&replayer, replay, &outputs)?;
        for path in outputs.rrd.iter().chain(&outputs.mcap) {
            eprintln!("armscope: wrote {}", path.display());
        }
        Ok(())
    };
    let each = |index: i64, replay: &crate::replay::EpisodeReplay| -> Result<(), Error> {
        if let Some(path) = &args.trace {
            let path = if several { trace_path(path, index) } else { path.clone() };
            crate::replay::trace::write(&path, &replay.motion)?;
        }
        // a lone episode is recorded as it is replayed; of several, the most loaded once known
        if !several && wants_recordings {
            record(index, replay)?;
        }
        Ok(())
    };
    let summaries = replay_episodes(&replayer, &source, &episodes, &recorded.feature, jobs, &each)?;
    for s in &summaries {
        for notice in &s.notices {
            eprintln!("armscope: notice: {notice}");
        }
    }
    if let Some(notice) = crate::replay::past_limits::notice(&replayer.model, summaries.iter().map(|s| s.past_limits.as_slice())) {
        eprintln!("armscope: notice: {notice}");
    }
    if several {
        print!("{}", report::ranking_text(&summaries));
        println!("\nthe most loaded:");
    }
    if let Some(worst) = summaries.first() {
        print!("{}", report::episode_text(&replayer, worst));
        if several && wants_recordings {
            // the most loaded episode again, whole (the batch kept only its findings)
            let index = worst.index.unwrap_or(0);
            record(index, &replayer.replay(&source.read(index, &recorded.feature)?)?)?;
        }
    }
    if let Some(path) = &args.summary_json {
        let doc = report::summary_json(&replayer, &args.source.display().to_string(), &summaries);
        let text = serde_json::to_string_pretty(&doc).map_err(|e| Error::output(path, e))?;
        std::fs::write(path, text + "\n").map_err(|e| Error::output(path, e))?;
    }
    Ok(0)
}

/// `replay --forward`: each episode's commands through the simulated arm's motors, against the follower.
fn forward(args: &ReplayArgs, replayer: &Replayer, source: &crate::motion::Source, episodes: &[i64]) -> Result<i32, Error> {
    use crate::replay::forward::{ForwardOptions, Latency, forward, forward_episodes, schedule_path};
    let motors = args.motors.clone().ok_or_else(|| Error::flag("--forward", "needs --motors: the servos that follow the commands"))?;
    if let Some(latency) = args.latency {
        crate::replay::forward::check_latency(latency)?;
    }
    let jobs = args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let commands = crate::motion::commands::CommandSource { topic: args.command_topic.clone(), joints: args.command_joints.clone() };
    // read once before the replay: the joints off in some episode (a servo off, a cable loose), and
    // whether the real tool went through the motor file's floor — then the table its arm stood on
    // was another, and the recording is replayed without it
    let floor = replayer.motors.as_ref().and_then(|m| m.floor);
    // (a lone episode without a floor has nothing to survey: a bag is read once)
    let survey = if episodes.len() > 1 || floor.is_some() { crate::replay::survey::survey(replayer, source, episodes, &args.recorded.feature, &commands, floor, jobs)? } else { Default::default() };
    for notice in survey.off.iter().filter_map(|o| o.notice(&replayer.base_model)) {
        eprintln!("armscope: notice: {notice}");
    }
    let off_joints = survey.off_joints();
    let mut without_floor = false;
    if let Some(floor) = floor {
        let tool = &replayer.base_model.frames[floor.frame].name;
        match survey.through_floor {
            Some(through) => {
                without_floor = true;
                let others = if through.episodes > 1 { format!(" (and {} more)", through.episodes - 1) } else { String::new() };
                eprintln!(
                    "armscope: notice: {}: its [floor] at z = {:.4} m is not this recording's table: the real tool ('{tool}') goes {:.1} mm below it in episode {}{others}; replayed without it",
                    motors.display(),
                    floor.height,
                    through.depth * 1e3,
                    through.episode
                );
            }
            None => eprintln!("armscope: notice: {}: the simulated tool ('{tool}') rests on a floor at z = {:.4} m (its [floor]: a contact without friction; the arm's own links pass through it)", motors.display(), floor.height),
        }
    }
    // the command schedules go where the recordings go
    let dir = args.files.folder();
    std::fs::create_dir_all(&dir).map_err(|e| Error::output(&dir, e))?;
    // the recordings of one episode: recordings/forward_SOURCE[_episode_N].rrd/.mcap unless told
    let wants_recordings = !(args.files.no_rrd && args.files.no_mcap);
    let dataset = source.kind() == crate::motion::SourceKind::LeRobot;
    let stem = args.source.file_stem().map_or("recording".into(), |s| s.to_string_lossy().into_owned());
    let name_of = |index: i64| crate::runner::file_safe(&if dataset { format!("forward_{stem}_episode_{index}") } else { format!("forward_{stem}") });
    let outputs = |index: i64| {
        let name = name_of(index);
        let (rrd, mcap) = args.files.paths(&name);
        crate::replay::recording::RecordingOutputs { rrd, mcap, mcap_encoding: args.mcap_encoding, name }
    };
    // a lone episode is recorded as it is replayed; of several, the one the model misses most, again
    let several = episodes.len() > 1;
    let options = |index: i64, record: bool| ForwardOptions {
        motors: motors.clone(),
        payload: args.payload,
        tool: args.tool.clone(),
        schedule: schedule_path(&dir, &name_of(index)),
        recordings: (record && wants_recordings).then(|| outputs(index)),
        // a teleop dataset's action reaches the servos a frame late; a bag's set point is what its
        // controller acted on then
        latency: match args.latency {
            Some(seconds) => Some(Latency::given(seconds, "--latency")),
            None if dataset => None,
            None => Some(Latency::given(0.0, "a controller's set point, acted on when recorded")),
        },
        trace: args.trace.as_ref().map(|path| if several { trace_path(path, index) } else { path.clone() }),
        without_floor,
        off_elsewhere: off_joints.clone(),
    };
    let wrote = |options: &ForwardOptions| {
        for path in options.recordings.iter().flat_map(|r| r.rrd.iter().chain(&r.mcap)) {
            eprintln!("armscope: wrote {}", path.display());
        }
    };
    let summaries = forward_episodes(replayer, source, episodes, &args.recorded.feature, &commands, jobs, &|index| options(index, !several))?;
    for s in &summaries {
        for notice in &s.notices {
            eprintln!("armscope: notice: {notice}");
        }
    }
    if let Some(notice) = crate::replay::past_limits::notice(&replayer.model, summaries.iter().map(|s| s.past_limits.as_slice())) {
        eprintln!("armscope: notice: {notice}");
    }
    if !several {
        wrote(&options(episodes[0], true));
    }
    for s in &summaries {
        if several {
            println!("episode {} (widest gap {:.1} mrad mean)", s.index, s.widest_gap * 1e3);
        }
        print!("{}", s.text);
    }
    if let (true, true, Some(widest)) = (several, wants_recordings, summaries.first()) {
        println!("recorded: episode {}, the widest gap ({:.1} mrad mean on its worst joint)", widest.index, widest.widest_gap * 1e3);
        // its trace was written with its summary
        let options = ForwardOptions { trace: None, ..options(widest.index, true) };
        let (commands, observed) = source.read_forward(widest.index, &args.recorded.feature, &commands)?;
        forward(replayer, &options, &commands, &observed)?;
        wrote(&options);
    }
    let documents: Vec<&serde_json::Value> = summaries.iter().map(|s| &s.document).collect();
    if let Some(path) = &args.summary_json {
        let doc = serde_json::json!({ "source": args.source.display().to_string(), "forward": true, "parts_above_rad": crate::replay::forward::PARTS_ABOVE, "episodes": documents });
        let text = serde_json::to_string_pretty(&doc).map_err(|e| Error::output(path, e))?;
        std::fs::write(path, text + "\n").map_err(|e| Error::output(path, e))?;
    }
    Ok(0)
}

/// The one-line error when no joint map is known for a recording (its template printed above it).
pub fn needs_map(source: &std::path::Path, urdf: &std::path::Path) -> Error {
    Error::flag("--joint-map", format!("needed: armscope knows no map from {}'s columns to {}'s joints; a template is printed above", source.display(), urdf.display()))
}

/// `trace.csv` → `trace_episode_7.csv`.
pub fn trace_path(path: &std::path::Path, index: i64) -> PathBuf {
    let stem = path.file_stem().map_or("trace".into(), |s| s.to_string_lossy().into_owned());
    let ext = path.extension().map_or("csv".into(), |e| e.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}_episode_{index}.{ext}"))
}
