//! `armscope identify --from DATASET`: an arm's servo parameters, command delay and payload from its
//! own teleoperated episodes, written as a motor file `run`, `replay` and `size` read.

use super::*;
use std::path::Path;
use crate::identify::arm::{ArmFitOptions, ArmObjective, ArmSpace, Payload, fit_arm};
use crate::motion::{Mapped, open_mapped};
use crate::replay::forward::{Drives, FollowSetup, ForwardCase, ForwardReplay, ForwardSummary, Latency, follow};
use crate::replay::{ReplayOptions, Replayer};

/// The flags of `identify --from`.
#[derive(Args, Debug)]
pub struct ArmArgs {
    /// Identify an arm from its own teleoperated episodes instead of a servo from bench logs: a
    /// LeRobot dataset (its `action` followed, its follower's `observation.state` matched) or a ROS 2
    /// bag with its controller's commands. Needs --urdf, --motors and --out FILE.toml.
    #[arg(long, value_name = "DATASET")]
    pub from: Option<PathBuf>,
    /// With --from: the arm's URDF.
    #[arg(long, value_name = "PATH", requires = "from")]
    pub urdf: Option<PathBuf>,
    /// With --from: the motor file to start from (each joint's servo; the catalogue's parameters).
    #[arg(long, value_name = "FILE", requires = "from")]
    pub motors: Option<PathBuf>,
    /// With --from: the episodes fitted to (default: all but --validate-episodes).
    #[arg(long, value_delimiter = ',', num_args = 1, requires = "from")]
    pub episode: Option<Vec<i64>>,
    /// With --from: episodes replayed with the fit, not fitted to (the gap reported on them).
    #[arg(long, value_delimiter = ',', num_args = 1, requires = "from")]
    pub validate_episodes: Vec<i64>,
    /// With --from: the follower's feature.
    #[arg(long, default_value = "observation.state")]
    pub feature: String,
    /// With --from: a joint map (see `replay --joint-map`).
    #[arg(long, value_name = "FILE", requires = "from")]
    pub joint_map: Option<PathBuf>,
    /// With --from: the body joints' unit (see `replay --units`).
    #[arg(long, value_enum, requires = "from")]
    pub units: Option<crate::motion::BodyUnits>,
    /// With --from: the follower's LeRobot calibration file (see `replay --calibration`).
    #[arg(long, value_name = "FILE", requires = "from")]
    pub calibration: Option<PathBuf>,
    /// With --from: the payload known to be at the tool, kg (0: none); by default it is fitted (0 to
    /// --payload-max kg).
    #[arg(long, value_name = "KG", requires = "from", allow_negative_numbers = true)]
    pub payload: Option<f64>,
    /// With --from: the heaviest payload searched, kg.
    #[arg(long, value_name = "KG", default_value_t = 0.5, conflicts_with = "payload")]
    pub payload_max: f64,
    /// With --from: the servo parameters fitted, by BAM's names (default: kt, error_gain_ratio,
    /// armature, friction_base, friction_viscous, command_delay; the load-dependent frictions stay
    /// the motor file's unless named).
    #[arg(long, value_delimiter = ',', num_args = 1, requires = "from")]
    pub fit_params: Option<Vec<String>>,
    /// With --from: fit each fitted joint's calibration offset too (the recording's zero against the
    /// URDF's, within ±0.15 rad).
    #[arg(long, requires = "from")]
    pub fit_offsets: bool,
    /// With --from: each fitted joint's servo its own parameters (by default the servos of one kind
    /// share theirs): more parameters, searched longer.
    #[arg(long, requires = "from")]
    pub per_joint: bool,
    /// With --from: the link whose origin is the tool.
    #[arg(long, value_name = "LINK", requires = "from")]
    pub tool: Option<String>,
    /// With --from: the joints whose gap is fitted (default: every compared joint but a gripper's,
    /// which closes on objects the simulation does not have, and one that does not follow).
    #[arg(long, value_delimiter = ',', num_args = 1, requires = "from")]
    pub fit_joints: Option<Vec<String>>,
    /// With --from: the teleop loop's latency, s (as `replay --forward --latency`; default one frame).
    #[arg(long, value_name = "SECONDS", requires = "from")]
    pub latency: Option<f64>,
    /// With --from: a search ends once its best gap has improved over this many generations by no
    /// more than a tenth of the recording's reading error and 1 % of the gap (default: a third of
    /// --generations; 0: every search runs all of them).
    #[arg(long, value_name = "GENERATIONS", requires = "from")]
    pub settled_after: Option<usize>,
    /// With --from: candidates run at once (default: every core).
    #[arg(long, requires = "from")]
    pub jobs: Option<usize>,
    /// With --from: no floor under the tool, even where the episodes show the real tool resting on
    /// one (by default a floor at the lowest it rested, written as the motor file's [floor]; a
    /// motor file that has a [floor] keeps its own).
    #[arg(long, requires = "from")]
    pub no_floor: bool,
}

/// An episode shorter than this (s) holds too little motion to identify from.
const SHORTEST_EPISODE: f64 = 2.0;

/// Default of `--generations` with --from.
const GENERATIONS: usize = 60;

/// `--settled-after` by default: this fraction of the generations (as the bench fit's searches end
/// once their best has not moved for a third of theirs). A search's best can stand still for a
/// dozen generations while CMA-ES adapts its distribution, then fall on: on a simulated SO-101
/// (`tests/identify_arm.rs`) searches stood 10–20 generations at 0.66, 2.17 and 2.75 mrad before
/// reaching the 0.42 of the truth, and on the real SO-101's shared episodes one stood 33 at 9.09
/// mrad, then found 0.36 (its readings' error: 0.38) in its last 15 of 60 — where the fit keeps
/// another search's end.
const SETTLED_AFTER_FRACTION: usize = 3;

/// Searches run by default when the payload is fitted, each from the motor file's parameters with its own
/// seed. A load at the tool trades against the servos' holding stiffness along a ridge an arm's
/// episodes leave nearly flat: on the real SO-101's two shared episodes, seven seeds ended between
/// no payload at ×0.36 the catalogue's stiffness and 81 g at ×0.55, five of them within 0.17 mrad of
/// each other (the readings' own error there: 0.38 mrad), and one search lands on either end. Of
/// three, the one nearest the catalogue's servo is kept (`fit_arm`); three searches take up to three
/// times one's time (12 s each on those 25 s of episodes, on two cores).
const SEARCHES_WITH_PAYLOAD: usize = 3;

/// The motion the search runs on at most, s: whole episodes, spread over the training ones, up to
/// this long (the fit's cost grows with the motion each candidate replays; the fit is then reported
/// on every training episode). The real SO-101's two shared episodes are 24.8 s; on the second real
/// arm's 50 episodes of 10 s the fit searched on two of them follows all 50 within 5.66 mrad mean,
/// on three (up to 30 s) within 5.63, the readings' error being 0.38: the third episode cost half
/// as much again (53 s against 30 s on two cores in one hour) for 0.03 mrad.
const SEARCH_SECONDS: f64 = 25.0;

/// The training episodes the search runs on: all if they are short enough together, else whole
/// episodes evenly spread over them up to [`SEARCH_SECONDS`] (at least one).
fn searched(durations: &[f64]) -> Vec<usize> {
    let total: f64 = durations.iter().sum();
    if total <= SEARCH_SECONDS {
        return (0..durations.len()).collect();
    }
    let mut order: Vec<usize> = Vec::new();
    // a stride over the list, then every stride's neighbours: spread before dense
    let n = durations.len();
    let wanted = ((SEARCH_SECONDS / (total / n as f64)).floor() as usize).clamp(1, n);
    let stride = n as f64 / wanted as f64;
    for k in 0..wanted {
        order.push(((k as f64 + 0.5) * stride).floor() as usize);
    }
    let mut chosen = Vec::new();
    let mut seconds = 0.0;
    for i in order {
        if chosen.is_empty() || seconds + durations[i] <= SEARCH_SECONDS {
            seconds += durations[i];
            chosen.push(i);
        }
    }
    chosen
}

/// `identify --from`.
pub fn identify_arm(args: &IdentifyArgs, dataset: &Path) -> Result<i32, Error> {
    let arm = &args.arm;
    let urdf = arm.urdf.as_ref().ok_or_else(|| Error::flag("--from", "needs --urdf: the arm's URDF"))?;
    let motors = arm.motors.as_ref().ok_or_else(|| Error::flag("--from", "needs --motors: the motor file to start from"))?;
    if arm.payload.is_some_and(|m| !(m.is_finite() && m >= 0.0)) {
        return Err(Error::flag("--payload", "must be a mass of 0 kg or more"));
    }
    let fit_payload = arm.payload.is_none();
    if !(arm.payload_max.is_finite() && arm.payload_max > 0.0) {
        return Err(Error::flag("--payload-max", "must be a positive mass, kg"));
    }
    if let Some(latency) = arm.latency {
        crate::replay::forward::check_latency(latency)?;
    }
    let generations = args.generations.unwrap_or(GENERATIONS);
    if generations == 0 {
        return Err(Error::flag("--generations", "must be at least 1"));
    }
    if args.population == 1 {
        return Err(Error::flag("--population", "must be at least 2 (or 0 for CMA-ES's default)"));
    }
    let started = std::time::Instant::now();
    let model = crate::model::load_urdf(urdf)?;
    for notice in &model.notices {
        eprintln!("armscope: notice: {notice}");
    }
    let reading = crate::motion::Reading { units: arm.units, calibration: arm.calibration.as_deref() };
    let opened = match open_mapped(dataset, None, None, &arm.feature, arm.joint_map.as_deref(), reading, &model)? {
        Mapped::Ready(r) => r,
        Mapped::NeedsMap { template } => {
            println!("{template}");
            return Err(super::replay::needs_map(dataset, urdf));
        }
    };
    for notice in &opened.notices {
        eprintln!("armscope: notice: {notice}");
    }
    let known = |flag: &str, list: &[i64]| -> Result<(), Error> {
        match list.iter().find(|e| !opened.episodes.contains(e)) {
            Some(e) => Err(Error::flag(flag, format!("episode {e}: not in {} (episodes: {})", dataset.display(), opened.episodes.iter().map(i64::to_string).collect::<Vec<_>>().join(", ")))),
            None => Ok(()),
        }
    };
    known("--validate-episodes", &arm.validate_episodes)?;
    let train: Vec<i64> = match &arm.episode {
        Some(list) => {
            known("--episode", list)?;
            if let Some(e) = list.iter().find(|e| arm.validate_episodes.contains(e)) {
                return Err(Error::flag("--validate-episodes", format!("episode {e} is also fitted to (--episode): held out means not fitted to")));
            }
            list.clone()
        }
        None => opened.episodes.iter().copied().filter(|e| !arm.validate_episodes.contains(e)).collect(),
    };
    if train.is_empty() {
        return Err(Error::flag("--episode", format!("no episode of {} left to fit to", dataset.display())));
    }
    let replayer = Replayer::new(model.clone(), &ReplayOptions { payload: 0.0, tool: arm.tool.clone(), motors: Some(motors.clone()) }, opened.map)?;
    let scratch = tempfile::Builder::new().prefix("armscope-identify-").tempdir().map_err(|e| Error::output(&std::env::temp_dir(), e))?;
    let latency = arm.latency.map(|s| Latency::given(s, "--latency"));
    let jobs = arm.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())).max(1);
    // a joint off in one episode is taken as off in another that does not sweep it, as replay
    // --forward takes it
    let surveyed: Vec<i64> = train.iter().chain(&arm.validate_episodes).copied().collect();
    let survey = if surveyed.len() > 1 { crate::replay::survey::survey(&replayer, &opened.source, &surveyed, &arm.feature, &Default::default(), None, jobs)? } else { Default::default() };
    for notice in survey.off.iter().filter_map(|o| o.notice(&model)) {
        eprintln!("armscope: notice: {notice}");
    }
    let off_joints = survey.off_joints();
    // an episode's case, or (`first`) that of its first seconds
    let prepare_part = |index: i64, first: Option<f64>| -> Result<ForwardCase, Error> {
        let (commands, observed) = opened.source.read_forward(index, &arm.feature, &Default::default())?;
        let (commands, observed, schedule) = match first {
            Some(seconds) => (commands.first_seconds(seconds), observed.first_seconds(seconds), format!("episode_{index}_first.csv")),
            None => (commands, observed, format!("episode_{index}.csv")),
        };
        let case = ForwardCase::prepare(&replayer, &commands, &observed, &scratch.path().join(schedule), latency.clone(), &off_joints)?;
        if case.duration() < SHORTEST_EPISODE {
            return Err(Error::flag(commands.label.clone(), format!("{:.2} s long: too short to identify from (at least {SHORTEST_EPISODE} s of motion)", case.duration())));
        }
        Ok(case)
    };
    let prepare = |index: i64| prepare_part(index, None);
    let train_cases = train.iter().map(|&e| prepare(e)).collect::<Result<Vec<_>, _>>()?;
    let validate_cases = arm.validate_episodes.iter().map(|&e| prepare(e)).collect::<Result<Vec<_>, _>>()?;
    if let Some(notice) = crate::replay::past_limits::notice(&model, train_cases.iter().chain(&validate_cases).map(|c| c.past_limits())) {
        eprintln!("armscope: notice: {notice}");
    }

    // the joints fitted: every compared one but a gripper's and one that does not follow
    let compared: Vec<usize> = train_cases[0].compared().to_vec();
    let name = |j: usize| model.joints[j].name.clone();
    let still: Vec<usize> = compared.iter().copied().filter(|&j| train_cases.iter().any(|c| c.not_following().contains(&j))).collect();
    let mut left_out: Vec<(String, String)> = Vec::new();
    let fitted: Vec<usize> = match &arm.fit_joints {
        Some(list) => {
            let mut fitted = Vec::new();
            for joint in list {
                let j = model.joint_index(joint).ok_or_else(|| Error::flag("--fit-joints", format!("no joint '{joint}' in {} (joints: {})", urdf.display(), model.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(", "))))?;
                if !compared.contains(&j) {
                    return Err(Error::flag("--fit-joints", format!("joint '{joint}': {} records no command and follower for it", dataset.display())));
                }
                fitted.push(j);
            }
            fitted
        }
        None => compared
            .iter()
            .copied()
            .filter(|&j| {
                let n = name(j).to_lowercase();
                if n.contains("gripper") || n.contains("jaw") {
                    left_out.push((name(j), "a gripper: it closes on objects the simulation does not have (--fit-joints fits it)".into()));
                    false
                } else if still.contains(&j) {
                    left_out.push((name(j), "it does not follow its commands (the real joint stayed put while they swept)".into()));
                    false
                } else {
                    true
                }
            })
            .collect(),
    };
    for (joint, why) in &left_out {
        eprintln!("armscope: notice: {joint} left out of the fit: {why}");
    }
    let start_set = crate::actuator::load_motor_file(motors, &model)?;
    let keys: Vec<&str> = match &arm.fit_params {
        Some(list) => {
            let known = crate::identify::arm::fittable(&start_set, &fitted);
            for key in list {
                if !known.contains(&key.as_str()) {
                    return Err(Error::flag("--fit-params", format!("'{key}' is not a parameter of the fitted joints' servos (they have: {})", known.join(", "))));
                }
            }
            list.iter().map(String::as_str).collect()
        }
        None => crate::identify::arm::ARM_KEYS.to_vec(),
    };
    let joint_names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let catalogue = crate::actuator::catalogue::motor_file_catalogue(motors)?;
    // the supply on which each of the catalogue's servos of the kind's family holds as stiff
    let as_stiff_on = |kind: &crate::identify::arm::ServoKind, stiffness: f64| match start_set.joints[kind.joints[0]].as_ref().and_then(|d| d.servo.as_ref()) {
        Some(servo) => crate::identify::equivalent_supply::equivalent_supplies(&catalogue, &servo.name, servo.supply, stiffness),
        None => Vec::new(),
    };
    let searched_payload = arm.payload.map_or(Payload::Fitted { most: arm.payload_max }, Payload::Known);
    let space = ArmSpace::new(&start_set, &fitted, &keys, searched_payload, arm.fit_offsets, arm.per_joint.then_some(joint_names.as_slice()));
    // the table the real tool rested on, where the episodes show one
    // (the replayer's model has --tool's frame, checked when it was built)
    let tool_frame = replayer.model.tool_frame;
    let touch = if arm.no_floor || start_set.floor.is_some() { None } else { crate::identify::floor::touched(&model, tool_frame, &train_cases) };
    if let Some(t) = &touch {
        eprintln!(
            "armscope: notice: the real tool ('{}') rested at its lowest, z = {:.4} to {:.4} m by episode, in {} frames while its commands asked it lower (to {:.4} m): a floor under it at z = {:.4} m, written as the motor file's [floor] (--no-floor: none)",
            model.frames[tool_frame].name,
            t.height,
            t.highest,
            t.frames,
            t.commanded_lowest,
            t.height
        );
    }
    let floor = touch.map(|t| crate::plant::FloorContact { frame: tool_frame, height: t.height });
    if space.is_empty() {
        return Err(Error::flag("--fit-params", "nothing left to fit"));
    }
    if space.kinds.is_empty() {
        return Err(Error::flag("--motors", format!("{}: no fitted joint has a servo with a firmware model (identify --from fits bus servos' parameters)", motors.display())));
    }
    let mut is_fitted = vec![false; model.dof()];
    for &j in &fitted {
        is_fitted[j] = true;
    }
    let durations: Vec<f64> = train_cases.iter().map(ForwardCase::duration).collect();
    let chosen = searched(&durations);
    // an episode longer than the search's motion (a bag is one recording) is searched on its first
    // part: its start is where the real follower starts, as the whole episode's
    let mut search_cases = Vec::with_capacity(chosen.len());
    for &i in &chosen {
        search_cases.push(if durations[i] > SEARCH_SECONDS { prepare_part(train[i], Some(SEARCH_SECONDS))? } else { train_cases[i].clone() });
    }
    let searched_seconds: f64 = search_cases.iter().map(ForwardCase::duration).sum();
    let total_seconds: f64 = durations.iter().sum();
    if chosen.len() < train_cases.len() || searched_seconds < total_seconds {
        let what = match chosen[..] {
            [i] if durations[i] > SEARCH_SECONDS => format!("the first {searched_seconds:.0} s of episode {}", train[i]),
            _ => format!("episodes {}", chosen.iter().map(|&i| train[i].to_string()).collect::<Vec<_>>().join(", ")),
        };
        eprintln!(
            "armscope: notice: the search runs on {what} ({searched_seconds:.0} s of the training episodes' {total_seconds:.0} s: a fit's cost grows with the motion it replays); the fit is reported on all of them"
        );
    }
    let objective = ArmObjective { model: &model, drives: &start_set, tool: arm.tool.as_deref(), space: &space, cases: &search_cases, fitted: is_fitted.clone(), floor };
    let searches = match args.searches {
        0 if fit_payload => SEARCHES_WITH_PAYLOAD,
        0 => 1,
        n => n,
    };
    let reading_error = crate::identify::arm::reading_error(&search_cases, &is_fitted);
    let options = ArmFitOptions { population: args.population, generations, seed: args.seed, searches, indistinct: reading_error, settled_after: arm.settled_after.unwrap_or(generations / SETTLED_AFTER_FRACTION), jobs, ..ArmFitOptions::default() };
    if fit_payload {
        eprintln!(
            "armscope: notice: the payload at the tool is fitted too (0 to {} kg; --payload KG for a known one){}",
            arm.payload_max,
            if searches > 1 { format!(", in {searches} searches: of those whose gaps the recording cannot tell apart, the one nearest the motor file's servos is kept") } else { String::new() }
        );
    }
    let bar = super::identify::generations_bar((searches * generations) as u64, args.quiet);
    let progress = |generation: usize, best: f64| {
        bar.set_position(generation as u64);
        bar.set_message(format!("best {:.2} mrad", 1e3 * best));
    };
    let found = fit_arm(&objective, &options, &progress)?;
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();

    let servo_files = write_motor_file(&args.out, motors, &model, &start_set, &space, dataset, &train, &found, floor)?;
    // the file as written, replayed: what `replay --forward --motors FILE` will give
    let payload = found.payload;
    let replay_with = |cases: &[ForwardCase]| -> Result<Vec<ForwardReplay>, Error> { cases.iter().map(|c| follow(&model, c, &Drives::File(&args.out), &FollowSetup { payload, tool: arm.tool.as_deref(), offsets: arm.fit_offsets.then_some(found.offsets.as_slice()), without_floor: false }, None)).collect() };
    let trained = replay_with(&train_cases)?;
    let validated = replay_with(&validate_cases)?;
    let fitted_names: Vec<String> = fitted.iter().map(|&j| name(j)).collect();
    let mean_gap = |replays: &[ForwardReplay]| -> Option<f64> {
        let gaps: Vec<f64> = replays.iter().flat_map(|r| r.joints.iter().filter(|g| fitted_names.contains(&g.joint)).map(|g| g.gap_mae)).collect();
        (!gaps.is_empty()).then(|| gaps.iter().sum::<f64>() / gaps.len() as f64)
    };
    if !args.quiet {
        println!(
            "{} fitted to {} episode(s) of {} on {} in {seconds:.1} s ({} candidates): mean gap {:.2} mrad (the motor file's parameters: {:.2})",
            space.kinds.iter().map(|k| k.name.as_str()).collect::<Vec<_>>().join(", "),
            train.len(),
            dataset.display(),
            fitted_names.join(", "),
            found.evaluations,
            1e3 * found.loss,
            1e3 * found.start_loss
        );
        for (kind, p) in space.kinds.iter().zip(&found.params) {
            println!(
                "  {}: command delay {:.1} ms, k_t {:.4} N·m/A, error gain ×{:.3}, armature {:.3e} kg·m², friction base {:.4} N·m, viscous {:.4} N·m·s/rad",
                kind.name,
                1e3 * p.command_delay,
                p.kt,
                p.error_gain_ratio,
                p.armature,
                p.friction.get("friction_base").unwrap_or(0.0),
                p.friction.get("friction_viscous").unwrap_or(0.0)
            );
            let strength = crate::identify::arm::Strength::of(p, &kind.start);
            println!(
                "    against the motor file's: holding stiffness ×{:.2} (k_t × error gain / R: the loop's torque per error), stall torque ×{:.2} (k_t / R){}",
                strength.holding_stiffness,
                strength.stall_torque,
                strength.verdict().map_or(String::new(), |v| format!(": {v}"))
            );
            let supplies = as_stiff_on(kind, strength.holding_stiffness);
            if !supplies.is_empty() {
                println!("    that stiffness from the catalogue's servos at the same firmware gain (by their datasheets' stall torque per volt): {}", crate::identify::equivalent_supply::text(&supplies));
            }
        }
        if fit_payload {
            println!("  payload {:.3} kg at the tool (not in the motor file, which holds the servos and the floor: `replay --forward --payload {:.3}` replays these episodes as fitted)", found.payload, found.payload);
        }
        if found.searches.len() > 1 {
            println!(
                "  {} searches ended at {}; gaps within the recording's reading error ({:.2} mrad) are not told apart: kept the one whose servos hold nearest the motor file's (search {})",
                found.searches.len(),
                found
                    .searches
                    .iter()
                    .map(|s| {
                        let settled = if s.generations < generations { format!("; settled after {} generations", s.generations) } else { String::new() };
                        format!("{:.2} mrad ({:.0} g, ×{}{settled})", 1e3 * s.loss, 1e3 * s.payload, s.holding_stiffness.iter().map(|h| format!("{h:.2}")).collect::<Vec<_>>().join("/"))
                    })
                    .collect::<Vec<_>>()
                    .join(", "),
                1e3 * reading_error,
                found.kept + 1
            );
        }
        if let Some(floor) = floor {
            println!("  a floor under '{}' at z = {:.4} m (where the real tool rested at its lowest)", model.frames[floor.frame].name, floor.height);
        }
        if arm.fit_offsets {
            println!("  calibration offsets (the arm's angle less the recording's): {}", fitted.iter().map(|&j| format!("{} {:+.1} mrad", name(j), 1e3 * found.offsets[j])).collect::<Vec<_>>().join(", "));
        }
        for r in trained.iter().chain(&validated) {
            let held = validated.iter().any(|v| v.label == r.label);
            println!("{}{}", if held { "held out: " } else { "fitted to: " }, crate::replay::forward::text(r).trim_end());
        }
        if let Some(gap) = mean_gap(&validated) {
            println!("mean gap on the held-out episodes: {:.2} mrad", 1e3 * gap);
        }
        println!("wrote {} ({})", args.out.display(), servo_files.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
    }
    if let Some(path) = &args.summary_json {
        let kinds: Vec<serde_json::Value> = space.kinds.iter().zip(&found.params).map(|(k, p)| {
                let strength = crate::identify::arm::Strength::of(p, &k.start);
                serde_json::json!({ "servo": k.name, "joints": k.joints.iter().map(|&j| name(j)).collect::<Vec<_>>(), "params": p.to_json(), "against_start": strength, "as_stiff_on": as_stiff_on(k, strength.holding_stiffness) })
            })
            .collect();
        let documents = |replays: &[ForwardReplay], episodes: &[i64]| -> Vec<serde_json::Value> { replays.iter().zip(episodes).map(|(r, &e)| ForwardSummary::of(e, r, Vec::new()).document).collect() };
        let doc = serde_json::json!({
            "from": dataset.display().to_string(),
            "motor_file": args.out.display().to_string(),
            "train_episodes": train,
            "validate_episodes": arm.validate_episodes,
            "fitted_joints": fitted_names,
            "left_out": left_out.iter().map(|(j, why)| serde_json::json!({ "joint": j, "why": why })).collect::<Vec<_>>(),
            "payload_kg": payload,
            "payload_fitted": fit_payload,
            "searches": found.searches,
            "kept_search": found.kept,
            "reading_error_rad": reading_error,
            "floor": touch.map(|t| serde_json::json!({ "link": model.frames[tool_frame].name, "height_m": t.height, "highest_rest_m": t.highest, "resting_frames": t.frames, "commanded_lowest_m": t.commanded_lowest })),
            "offsets_rad": arm.fit_offsets.then(|| fitted.iter().map(|&j| (name(j), found.offsets[j])).collect::<std::collections::BTreeMap<_, _>>()),
            "servos": kinds,
            "start_gap_rad": found.start_loss,
            "gap_rad": found.loss,
            "searched_episodes": chosen.iter().map(|&i| train[i]).collect::<Vec<_>>(),
            "searched_seconds": searched_seconds,
            "train_gap_rad": mean_gap(&trained),
            "validate_gap_rad": mean_gap(&validated),
            "evaluations": found.evaluations,
            "seconds": seconds,
            "train": documents(&trained, &train),
            "validate": documents(&validated, &arm.validate_episodes),
        });
        let text = serde_json::to_string_pretty(&doc).map_err(|e| Error::output(path, e))?;
        crate::runner::create_parent(path)?;
        std::fs::write(path, text + "\n").map_err(|e| Error::output(path, e))?;
    }
    Ok(0)
}

/// Write the motor file `out`: `motors`' own, every joint of a fitted servo kind pointed at that
/// kind's parameters (`OUT_STEM.KIND.json`, beside it), the files it names made absolute so that it
/// reads from anywhere. Returns the parameter files written.
#[allow(clippy::too_many_arguments)]
fn write_motor_file(out: &Path, motors: &Path, model: &crate::model::Model, set: &crate::actuator::MotorSet, space: &ArmSpace, dataset: &Path, train: &[i64], found: &crate::identify::arm::ArmFit, floor: Option<crate::plant::FloorContact>) -> Result<Vec<PathBuf>, Error> {
    use toml::Value;
    let fail = |m: String| Error::flag(motors.display().to_string(), m);
    let text = crate::builtin::read_to_string(motors).map_err(|e| fail(format!("cannot read: {e}")))?;
    let mut table: toml::Table = text.parse().map_err(|e: toml::de::Error| fail(e.message().to_string()))?;
    let here = motors.parent().filter(|p| !p.as_os_str().is_empty()).map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let absolute = |file: &str| -> String { std::path::absolute(here.join(file)).unwrap_or_else(|_| here.join(file)).display().to_string() };
    if let Some(Value::String(c)) = table.get("catalogue").cloned() {
        table.insert("catalogue".into(), Value::String(absolute(&c)));
    }
    crate::runner::create_parent(out)?;
    let stem = out.file_stem().map_or("identified".into(), |s| s.to_string_lossy().into_owned());
    let out_dir = out.parent().filter(|p| !p.as_os_str().is_empty()).map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let mut written = Vec::new();
    let mut file_of_kind = Vec::new();
    for (kind, p) in space.kinds.iter().zip(&found.params) {
        let name = format!("{stem}.{}.json", crate::runner::file_safe(&kind.name));
        let path = out_dir.join(&name);
        std::fs::write(&path, serde_json::to_string_pretty(&p.to_json()).unwrap_or_default() + "\n").map_err(|e| Error::output(&path, e))?;
        written.push(path);
        file_of_kind.push(name);
    }
    let joints = match table.get_mut("joints") {
        Some(Value::Table(t)) => t,
        _ => return Err(fail("no [joints] table: identify --from writes the servos' parameters into it".into())),
    };
    for (key, entry) in joints.iter_mut() {
        let Value::Table(entry) = entry else { continue };
        let kind = model.joint_index(key).and_then(|j| {
            let servo = set.joints[j].as_ref().and_then(|d| d.servo.as_ref())?;
            space.kinds.iter().position(|k| k.drives(j, &servo.name))
        });
        match kind {
            Some(k) => {
                entry.insert("servo_params".into(), Value::String(file_of_kind[k].clone()));
            }
            None => {
                if let Some(Value::String(f)) = entry.get("servo_params").cloned() {
                    entry.insert("servo_params".into(), Value::String(absolute(&f)));
                }
            }
        }
    }
    if let Some(floor) = floor {
        let mut t = toml::Table::new();
        t.insert("height".into(), Value::Float(floor.height));
        t.insert("link".into(), Value::String(model.frames[floor.frame].name.clone()));
        table.insert("floor".into(), Value::Table(t));
    }
    let header = format!(
        "# Identified by `armscope identify --from {}` on episode(s) {} of it, from {}: the mean gap between the\n# simulated and the real follower {:.2} mrad ({:.2} with the parameters started from). Each servo's parameters are\n# in the file its servo_params names.{}\n",
        dataset.display(),
        train.iter().map(i64::to_string).collect::<Vec<_>>().join(", "),
        motors.display(),
        1e3 * found.loss,
        1e3 * found.start_loss,
        if floor.is_some() { " [floor]: the table the real tool rested on in those episodes, at the lowest it rested." } else { "" }
    );
    let body = toml::to_string(&table).map_err(|e| fail(e.to_string()))?;
    std::fs::write(out, header + &body).map_err(|e| Error::output(out, e))?;
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::{SEARCH_SECONDS, searched};

    #[test]
    fn the_search_runs_on_whole_episodes_spread_over_the_training_ones_up_to_its_length() {
        // the real SO-101's two shared episodes (12.40 and 12.43 s): both
        assert_eq!(searched(&[12.40, 12.43]), [0, 1]);
        // the second real arm's 50 episodes of 10 s: two, from either half
        let fifty = [10.0; 50];
        let chosen = searched(&fifty);
        assert_eq!(chosen, [12, 37]);
        assert!(chosen.iter().map(|&i| fifty[i]).sum::<f64>() <= SEARCH_SECONDS);
        // an episode longer than the whole length: that one alone, whole
        assert_eq!(searched(&[4.0, 60.0, 3.0]).len(), 1);
    }
}
