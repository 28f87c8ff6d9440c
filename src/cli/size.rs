//! `armscope size`: which motor and which gear ratio, per joint, for the motion you want.

use super::*;
use crate::actuator::Catalogue;
use crate::sizing::screening::{Reductions, SizeRequest, size as size_joints};

#[derive(Args, Debug)]
pub struct SizeArgs {
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// The motion: the wave (as `run`), …
    #[command(flatten)]
    pub wave: WaveArgs,
    /// The motion: a joint schedule (CSV or .npy, as `run --trajectory`) instead of the wave.
    #[arg(long, value_name = "FILE")]
    pub trajectory: Option<PathBuf>,
    /// The motion: every experiment of a batch manifest (each must pass; their `motors` are replaced).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["trajectory"])]
    pub manifest: Option<PathBuf>,
    /// The motion: every recorded episode of a LeRobot dataset, ROS 2 bag or CSV (as `replay`),
    /// smoothed and followed as a joint schedule; the drives must carry them all (their envelope).
    #[arg(long, value_name = "SOURCE", conflicts_with_all = ["trajectory", "manifest"])]
    pub from: Option<PathBuf>,
    /// With --from: which episodes, and how the recording's columns map to the joints.
    #[command(flatten)]
    pub recorded: crate::flags::RecordedMotionArgs,
    /// Simulated time of the wave or schedule, s (default: the schedule's length, or as `run`).
    #[arg(long, value_name = "SECONDS")]
    pub duration: Option<f64>,
    #[arg(long, default_value_t = RunConfig::default().dt)]
    pub dt: f64,
    /// Initial joint positions (as `run --q0`).
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    pub q0: Option<String>,
    /// The link whose origin is the tool tip (where the payload sits).
    #[arg(long, value_name = "LINK")]
    pub tool: Option<String>,
    /// A payload at the tool, kg.
    #[arg(long, default_value_t = 0.0)]
    pub payload: f64,
    /// Check the motion against a scene file's objects, floor and payload shape too (TOML; see
    /// `armscope run --scene`). Self-collision is always checked.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// Check the motion against a floor at this height (world z, m; without a value, at the base's).
    #[arg(long, value_name = "Z", num_args = 0..=1, default_missing_value = "NaN", allow_negative_numbers = true)]
    pub floor: Option<f64>,
    /// An SRDF whose <disable_collisions> pairs are not checked (default: the one beside the URDF).
    #[arg(long, value_name = "FILE")]
    pub srdf: Option<PathBuf>,
    /// A catalogue of your own, on top of the built-in assets/motors/catalogue.toml (its entries
    /// added, or replacing built-in ones of the same name).
    #[arg(long, value_name = "FILE")]
    pub catalogue: Option<PathBuf>,
    /// Only these catalogue motors (comma list; default: every motor with a mass).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub candidates: Option<Vec<String>>,
    /// Only these catalogue reductions (comma list; default: every one whose efficiency is
    /// published), each at its own ratios, beside a direct drive.
    #[arg(long, value_delimiter = ',', num_args = 1, conflicts_with = "ratios")]
    pub reductions: Option<Vec<String>>,
    /// Catalogue stages per drive train: 1 (a reduction or none), or 2 (also every reduction
    /// followed by a belt).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub stages: u8,
    /// Instead of the catalogue's reductions, ideal ones at these ratios (your own gearing): a range
    /// `1-50` (whole numbers), `1-50:0.5` (a step), a list `5,10,15`, or mixed; `JOINT=SPEC` for
    /// one joint (repeat the flag).
    #[arg(long, value_name = "SPEC")]
    pub ratios: Vec<String>,
    /// Headroom on torque and on speed: 0.3 asks for 30 % more than the motion needs (default: the
    /// vendors' per motor kind, 50 % for an open-loop stepper, 30 % for a servo).
    #[arg(long)]
    pub margin: Option<f64>,
    /// Efficiency of the ideal reductions of `--ratios` (a direct drive, ratio 1, is 100 %).
    #[arg(long, default_value_t = 0.9)]
    pub efficiency: f64,
    /// Microsteps of the stepper drivers.
    #[arg(long, default_value_t = 32)]
    pub microsteps: u32,
    /// native: steppers open loop and servos by their firmware (default, as the real arm); pd: the
    /// PD controller on their limits, in the verifying simulations.
    #[arg(long, value_enum, default_value = "native")]
    pub drive: crate::config::DriveMode,
    /// Output folder: size.md, size.json, size.rrd, size_JOINT.png, motors.toml.
    #[arg(long, value_name = "DIR", default_value = "recordings/size")]
    pub out: PathBuf,
    /// Also write the chosen set as a motor file here (for `run --motors`).
    #[arg(long, value_name = "FILE")]
    pub motors_out: Option<PathBuf>,
    /// Simulations at once (default: all cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// The URDF's link masses already include the drive trains (a CAD export with the motors in
    /// it): do not carry the candidates' parts on the arm.
    #[arg(long)]
    pub parts_in_urdf: bool,
    /// How long the motion goes on, hours, for the thermal check of motors with thermal data
    /// (default: the motion's own duration).
    #[arg(long, value_name = "HOURS")]
    pub duty: Option<f64>,
}

/// `JOINT=SPEC` or `SPEC`, where SPEC is `A-B`, `A-B:STEP`, a number, or a comma list of these.
pub fn parse_ratios(specs: &[String], joints: &[String]) -> Result<Vec<Vec<f64>>, Error> {
    let fail = |m: String| Error::flag("--ratios", m);
    let mut all: Option<Vec<f64>> = None;
    let mut per_joint: Vec<Option<Vec<f64>>> = vec![None; joints.len()];
    // clap splits nothing here: a spec may itself be a comma list
    for spec in specs {
        let (target, list) = match spec.split_once('=') {
            Some((name, list)) => {
                let j = joints.iter().position(|n| n == name.trim()).ok_or_else(|| fail(format!("no moving joint '{}' (joints: {})", name.trim(), joints.join(", "))))?;
                (Some(j), list)
            }
            None => (None, spec.as_str()),
        };
        let mut ratios = Vec::new();
        for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let number = |t: &str| t.trim().parse::<f64>().ok().filter(|x| x.is_finite() && *x >= 1.0).ok_or_else(|| fail(format!("'{t}' in '{spec}' is not a ratio ≥ 1")));
            match item.split_once('-') {
                Some((a, rest)) => {
                    let (b, step) = match rest.split_once(':') {
                        Some((b, step)) => (number(b)?, step.trim().parse::<f64>().ok().filter(|s| s.is_finite() && *s > 0.0).ok_or_else(|| fail(format!("step '{step}' in '{spec}' must be positive")))?),
                        None => (number(rest)?, 1.0),
                    };
                    let a = number(a)?;
                    if b < a || (b - a) / step > 10_000.0 {
                        return Err(fail(format!("range '{item}' must go up, in at most 10000 steps")));
                    }
                    let mut r = a;
                    while r <= b + 1e-9 {
                        ratios.push((r * 1e9).round() / 1e9);
                        r += step;
                    }
                }
                None => ratios.push(number(item)?),
            }
        }
        if ratios.is_empty() {
            return Err(fail(format!("'{spec}' gives no ratio")));
        }
        ratios.sort_by(f64::total_cmp);
        ratios.dedup();
        match target {
            Some(j) => per_joint[j] = Some(ratios),
            None => all = Some(ratios),
        }
    }
    let all = all.unwrap_or_else(|| (1..=50).map(f64::from).collect());
    Ok(per_joint.into_iter().map(|r| r.unwrap_or_else(|| all.clone())).collect())
}

/// The simulated time: `--duration`, else a schedule's own length (held after its end, it would
/// stop dead), else `run`'s default.
fn duration(args: &SizeArgs) -> Result<f64, Error> {
    if let Some(d) = args.duration {
        return Ok(d);
    }
    match &args.trajectory {
        Some(path) => {
            let dof = crate::model::load_urdf(&args.urdf)?.dof();
            Ok(crate::control::trajectory::JointSchedule::load(path, dof)?.duration())
        }
        None => Ok(RunConfig::default().duration),
    }
}

/// The motions to size for: the wave or schedule of the flags, or every experiment of the manifest.
fn motions(args: &SizeArgs) -> Result<Vec<(String, RunConfig)>, Error> {
    let duration = duration(args)?;
    let base = RunConfig {
        urdf: args.urdf.clone(),
        freq: args.wave.freq(),
        amp_deg: args.wave.amp_deg(),
        // sized for the motion asked, whatever the URDF's own motors could carry
        wave_as_asked: true,
        trajectory: args.trajectory.clone(),
        duration,
        dt: args.dt,
        q0: args.q0.clone(),
        tool: args.tool.clone(),
        payload: args.payload,
        drive: args.drive,
        // servo candidates under PD: gains tuned to the arm with their rotors (the tutorial's gains
        // chatter on the box model's wrist at 1 kHz, and a chattering servo shakes the steppers)
        auto_tune: true,
        scene: args.scene.clone(),
        floor: args.floor,
        srdf: args.srdf.clone(),
        ..RunConfig::default()
    };
    if let Some(source) = &args.from {
        return recorded_motions(args, source, base);
    }
    let Some(path) = &args.manifest else {
        let name = if args.trajectory.is_some() { "trajectory".to_string() } else { format!("wave ω = {} rad/s, {}°, {duration} s", args.wave.freq(), args.wave.amp_deg()) };
        return Ok(vec![(name, base)]);
    };
    let manifest = crate::batch::load_manifest(path)?;
    let mut out = Vec::new();
    for e in &manifest.experiments {
        let run = crate::batch::run_args(e).map_err(|m| Error::flag(format!("manifest {}", path.display()), format!("experiment '{}': {m}", e.name)))?;
        let mut config = run.config();
        if config.motors.take().is_some() {
            eprintln!("armscope: notice: manifest experiment '{}': its motors are replaced by the candidates being sized", e.name);
        }
        config.drive = args.drive;
        if config.kp.is_none() && config.kd.is_none() {
            config.auto_tune = true;
        }
        if args.payload > 0.0 {
            config.payload = args.payload;
        }
        config.scene = config.scene.or_else(|| args.scene.clone());
        config.floor = config.floor.or(args.floor);
        config.srdf = config.srdf.or_else(|| args.srdf.clone());
        out.push((e.name.clone(), config));
    }
    let urdf = &out[0].1.urdf;
    if let Some((name, other)) = out.iter().find(|(_, c)| &c.urdf != urdf) {
        return Err(Error::flag(format!("manifest {}", path.display()), format!("experiment '{name}' uses {} but the first uses {}: size one arm at a time", other.urdf.display(), urdf.display())));
    }
    Ok(out)
}

/// `--from SOURCE`: each episode replayed (smoothed as `replay` smooths it) and written as a joint
/// schedule into OUT/episodes/, then followed from its first pose for its own length.
fn recorded_motions(args: &SizeArgs, source: &std::path::Path, base: RunConfig) -> Result<Vec<(String, RunConfig)>, Error> {
    use crate::motion::{Mapped, open_mapped};
    use crate::replay::{ReplayOptions, Replayer, inverse_replay, schedule};
    let model = crate::model::load_urdf(&args.urdf)?;
    let recorded = &args.recorded;
    let mapped = match open_mapped(source, recorded.topic.as_deref(), recorded.episode.as_deref(), &recorded.feature, recorded.joint_map.as_deref(), recorded.reading(), &model)? {
        Mapped::Ready(r) => {
            for notice in &r.notices {
                eprintln!("armscope: notice: {notice}");
            }
            r
        }
        Mapped::NeedsMap { template } => {
            println!("{template}");
            return Err(super::replay::needs_map(source, &args.urdf));
        }
    };
    let replayer = Replayer::new(model, &ReplayOptions { payload: 0.0, tool: args.tool.clone(), motors: None }, mapped.map)?;
    eprintln!("armscope: joint map: {}", replayer.map.source);
    let dir = args.out.join("episodes");
    std::fs::create_dir_all(&dir).map_err(|e| Error::output(&dir, e))?;
    let several = mapped.episodes.len() > 1 || mapped.source.kind() == crate::motion::SourceKind::LeRobot;
    let mut out = Vec::new();
    let mut past = Vec::new();
    for index in mapped.episodes {
        // the smoothed motion alone: no motor is held against it here
        let motion = inverse_replay(&replayer.model, &replayer.map, &mapped.source.read(index, &recorded.feature)?, &replayer.hold)?;
        for notice in &motion.notices {
            eprintln!("armscope: notice: {notice}");
        }
        past.push(motion.past_limits.clone());
        let path = dir.join(if several { format!("episode_{index}.csv") } else { "recording.csv".to_string() });
        schedule::write(&path, &motion)?;
        let (length, first_pose) = schedule::span(&motion);
        let q0 = first_pose.iter().map(|q| format!("{q:?}")).collect::<Vec<_>>().join(",");
        let name = if several { format!("episode {index}") } else { "recording".to_string() };
        out.push((name, RunConfig { trajectory: Some(path), duration: args.duration.unwrap_or(length), q0: Some(q0), ..base.clone() }));
    }
    if let Some(notice) = crate::replay::past_limits::notice(&replayer.model, past.iter().map(Vec::as_slice)) {
        eprintln!("armscope: notice: {notice}");
    }
    Ok(out)
}

/// `armscope size`.
pub fn size(args: &SizeArgs) -> Result<i32, Error> {
    if !(args.payload >= 0.0 && args.payload.is_finite()) {
        return Err(Error::flag("--payload", "must be a mass in kg, not negative"));
    }
    if let Some(margin) = args.margin.filter(|m| !(*m >= 0.0 && m.is_finite())) {
        return Err(Error::flag("--margin", format!("must be a fraction ≥ 0, e.g. 0.3 for 30 % (got {margin})")));
    }
    if !(args.efficiency > 0.0 && args.efficiency <= 1.0) {
        return Err(Error::flag("--efficiency", format!("must be in (0, 1] (got {})", args.efficiency)));
    }
    if let Some(hours) = args.duty {
        if !(hours > 0.0 && hours.is_finite()) {
            return Err(Error::flag("--duty", format!("must be a positive number of hours (got {hours})")));
        }
    }
    if !(1..=1024).contains(&args.microsteps) {
        return Err(Error::flag("--microsteps", "must be 1 to 1024"));
    }
    if args.from.is_none() {
        let r = &args.recorded;
        let stray = [(r.episode.is_some(), "--episode"), (r.joint_map.is_some(), "--joint-map"), (r.topic.is_some(), "--topic"), (r.feature != "observation.state", "--feature")];
        if let Some((_, flag)) = stray.iter().find(|(set, _)| *set) {
            return Err(Error::flag(*flag, "only with --from SOURCE (a recorded motion to size for)"));
        }
    }
    let motions = motions(args)?;
    let first = &motions[0].1;
    let model = crate::model::load_urdf(&first.urdf)?;
    crate::dynamics::check_solvable(&model)?;
    for notice in &model.notices {
        eprintln!("armscope: notice: {notice}");
    }
    let catalogue = match &args.catalogue {
        Some(path) => Catalogue::with_user_file(path)?,
        None => Catalogue::load(std::path::Path::new(crate::actuator::catalogue::DEFAULT_CATALOGUE))?,
    };
    let catalogue_path = catalogue.source.clone();
    let motors: Vec<String> = match &args.candidates {
        Some(names) => {
            for name in names {
                if !catalogue.entries.contains_key(name) {
                    return Err(Error::flag("--candidates", format!("no motor '{name}' in {} (known: {})", catalogue_path.display(), catalogue.names())));
                }
                if catalogue.mass(name).is_none() {
                    return Err(Error::flag("--candidates", format!("motor '{name}' in {} has no 'mass': sizing ranks by mass", catalogue_path.display())));
                }
            }
            names.clone()
        }
        None => {
            // a variant (the same motor, other identified parameters) is tried when named
            let (with, without): (Vec<String>, Vec<String>) = catalogue.entries.keys().filter(|name| catalogue.variant_of(name).is_none()).cloned().partition(|name| catalogue.mass(name).is_some());
            if !without.is_empty() {
                // one line for all, as for the reductions below (it was a line a motor: 17 with the built-in catalogue)
                eprintln!("armscope: notice: motors left out, no mass published in {} (sizing ranks by mass): {}", catalogue_path.display(), without.join(", "));
            }
            with
        }
    };
    let mut motors = motors;
    motors.sort_by(|a, b| catalogue.mass(a).unwrap_or(0.0).total_cmp(&catalogue.mass(b).unwrap_or(0.0)).then(a.cmp(b)));
    if motors.is_empty() {
        return Err(Error::flag("--candidates", format!("no motor with a mass in {}", catalogue_path.display())));
    }
    let joint_names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let reductions = if !args.ratios.is_empty() {
        Reductions::Ideal(parse_ratios(&args.ratios, &joint_names)?)
    } else {
        match &args.reductions {
            Some(names) => {
                for name in names {
                    let r = catalogue.reduction(name).ok_or_else(|| Error::flag("--reductions", format!("no reduction '{name}' in the catalogue (known: {})", catalogue.reduction_names())))?;
                    if !r.sizable() {
                        eprintln!("armscope: notice: reduction '{name}' publishes no efficiency: sized as lossless, an optimistic bound");
                    }
                }
                Reductions::Catalogue(names.clone())
            }
            None => {
                let (with, without): (Vec<String>, Vec<String>) = catalogue.reductions.keys().cloned().partition(|name| catalogue.reductions[name].sizable());
                if !without.is_empty() {
                    eprintln!("armscope: notice: reductions left out, no efficiency published: {} (name them in --reductions to size them lossless)", without.join(", "));
                }
                Reductions::Catalogue(with)
            }
        }
    };
    let jobs = args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let started = std::time::Instant::now();
    let request = SizeRequest { motions, model, payload_kg: args.payload, catalogue, motors, reductions, margin: args.margin, efficiency: args.efficiency, microsteps: args.microsteps, jobs, duty: args.duty.map(|hours| hours * 3600.0), carry_parts: !args.parts_in_urdf, max_stages: args.stages as usize };
    let report = size_joints(&request)?;

    std::fs::create_dir_all(&args.out).map_err(|e| Error::output(&args.out, e))?;
    let md = report.markdown();
    let custom_catalogue = args.catalogue.as_ref().map(|p| std::fs::canonicalize(p).unwrap_or(p.clone()).display().to_string());
    let motor_file = report.motor_file(custom_catalogue.as_deref());
    let mut files = Vec::new();
    let rrd_path = args.out.join("size.rrd");
    let rec = rerun::RecordingStreamBuilder::new("armscope-size").save(&rrd_path).map_err(|e| Error::output(&rrd_path, e))?;
    for (j, js) in report.joints.iter().enumerate() {
        if js.candidates.is_empty() {
            continue;
        }
        let canvas = report.chart(j);
        let png = args.out.join(format!("size_{}.png", crate::runner::file_safe(&js.joint)));
        canvas.save_png(&png).map_err(|e| Error::output(&png, e))?;
        files.push(png);
        rec.log_static(format!("size/{}", js.joint), &rerun::Image::from_rgb24(canvas.rgb.clone(), [canvas.width as u32, canvas.height as u32])).map_err(|e| Error::output(&rrd_path, e))?;
    }
    rec.log_static("table", &rerun::TextDocument::from_markdown(md.clone())).map_err(|e| Error::output(&rrd_path, e))?;
    rec.flush_blocking().map_err(|e| Error::output(&rrd_path, e))?;
    files.push(rrd_path);
    let json = serde_json::to_string_pretty(&report).map_err(|e| Error::output(&args.out.join("size.json"), e))?;
    let mut outputs = vec![(args.out.join("size.md"), md.clone()), (args.out.join("size.json"), json), (args.out.join("motors.toml"), motor_file.clone())];
    if let Some(p) = &args.motors_out {
        outputs.push((p.clone(), motor_file));
    }
    for (path, text) in outputs {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, e))?;
        }
        std::fs::write(&path, text).map_err(|e| Error::output(&path, e))?;
        files.push(path);
    }
    print!("{md}");
    if args.manifest.is_none() && args.from.is_none() && report.joints.iter().any(|j| j.chosen.is_some()) {
        // the verifying simulation as a command (servo joints ran with gains tuned to their rotors)
        let servos = report.joints.iter().filter_map(|j| j.chosen.map(|c| &j.candidates[c])).any(|c| request.catalogue.drive_train(&c.motor).is_some_and(|d| d.is_ok_and(|d| d.motor.as_stepper().is_none())));
        let path = args.motors_out.clone().unwrap_or_else(|| args.out.join("motors.toml"));
        let mut command = format!("armscope run --motors {}", path.display());
        if args.urdf != PathBuf::from(crate::config::DEFAULT_URDF) {
            command += &format!(" --urdf {}", args.urdf.display());
        }
        match &args.trajectory {
            Some(t) => command += &format!(" --trajectory {}", t.display()),
            None => command += &format!(" --freq {} --amp-deg {}", args.wave.freq(), args.wave.amp_deg()),
        }
        let duration = request.motions[0].1.duration;
        if args.manifest.is_none() && duration != RunConfig::default().duration {
            command += &format!(" --duration {duration}");
        }
        if args.payload > 0.0 {
            command += &format!(" --payload {}", args.payload);
        }
        if let Some(q0) = &args.q0 {
            command += &format!(" --q0 {q0}");
        }
        if let Some(tool) = &args.tool {
            command += &format!(" --tool {tool}");
        }
        if args.dt != RunConfig::default().dt {
            command += &format!(" --dt {}", args.dt);
        }
        if servos {
            command += " --auto-tune";
        }
        println!("\nTo watch it: {command}");
    }
    println!("\nsized in {:.1} s; wrote {}", started.elapsed().as_secs_f64(), files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", "));
    let every_joint_fits = report.joints.iter().all(|j| j.candidates.is_empty() || j.chosen.is_some());
    Ok(if report.verified && every_joint_fits { 0 } else { 1 })
}
