//! `armscope run`: one experiment (its flags are `crate::flags::RunArgs`) and its default name.

use super::*;

/// A file-name-safe name for a run, from the flags that differ from the tutorial's defaults.
pub fn default_run_name(config: &RunConfig) -> String {
    let d = RunConfig::default();
    let mut parts: Vec<String> = Vec::new();
    if config.urdf != d.urdf {
        parts.push(config.urdf.file_stem().map_or("model".into(), |s| s.to_string_lossy().to_string()));
    }
    if config.hold {
        parts.push("static".into());
    }
    if let Some(j) = &config.test_joint {
        parts.push(format!("test-joint-{j}"));
    }
    if config.no_ff {
        parts.push("no-ff".into());
    }
    if config.no_gravity {
        parts.push("no-gravity".into());
    }
    if config.freq != d.freq {
        parts.push(format!("freq{}", config.freq));
    }
    if config.amp_deg != d.amp_deg {
        parts.push(format!("amp{}", config.amp_deg));
    }
    if config.kp.is_some() || config.kd.is_some() || config.auto_tune {
        parts.push("gains".into());
    }
    if config.time_step == Some(0.0) || config.integrator == Some(IntegratorKind::Continuous) {
        parts.push("continuous".into());
    } else if let Some(h) = config.time_step {
        parts.push(format!("h{h}"));
    }
    if config.dt != d.dt {
        parts.push(format!("dt{}", config.dt));
    }
    if config.payload != d.payload {
        parts.push(format!("payload{}", config.payload));
    }
    if config.friction_scale != d.friction_scale {
        parts.push(format!("friction{}", config.friction_scale));
    }
    if config.duration != d.duration {
        parts.push(format!("{}s", config.duration));
    }
    if parts.is_empty() {
        parts.push("default".into());
    }
    crate::runner::file_safe(&parts.join("_"))
}

/// `armscope run`.
pub fn run(args: &RunArgs) -> Result<i32, Error> {
    let config = args.config();
    let name = args.name.clone().unwrap_or_else(|| default_run_name(&config));
    let experiment = Experiment::prepare(config)?;
    for notice in &experiment.model.notices {
        eprintln!("armscope: notice: {notice}");
    }
    if let Some(f) = args.realtime {
        if !(f.is_finite() && f > 0.0) {
            return Err(Error::flag("--realtime", format!("must be a positive factor (got {f})")));
        }
    }
    let (rrd_path, mcap_path) = args.files.paths(&name);
    let live = if args.spawn {
        Some(LiveViewer::Spawn)
    } else {
        args.connect.clone().map(LiveViewer::Connect)
    };

    let outputs = Outputs {
        name: name.clone(),
        console: (!args.quiet).then(|| Box::new(std::io::stdout()) as Box<dyn std::io::Write + Send>),
        rrd: rrd_path.clone(),
        mcap: mcap_path.clone(),
        live,
        foxglove: args.foxglove.clone(),
        realtime: args.realtime,
        csv: args.csv.clone(),
        trace: args.trace.clone(),
        summary_json: args.summary_json.clone(),
        compress: args.compress,
        mcap_encoding: args.mcap_encoding,
        notice: Some(|n| eprintln!("armscope: notice: {n}")),
        recorders: Vec::new(),
        law: None,
    };
    install_interrupt_handler();
    INTERRUPTED.store(false, Ordering::SeqCst);
    let summary = run_experiment(&experiment, outputs, Some(&INTERRUPTED))?;
    if !args.quiet {
        let mut files = Vec::new();
        if let Some(p) = &rrd_path {
            files.push(format!("  {}   open in Rerun: rerun {}", p.display(), p.display()));
        }
        if let Some(p) = &mcap_path {
            files.push(format!("  {}  open in Foxglove: Open local file… → {}", p.display(), p.display()));
        }
        if !files.is_empty() {
            println!("\nRecordings{}:\n{}", if matches!(summary.status, RunStatus::Completed) { "" } else { " (complete up to the last step simulated)" }, files.join("\n"));
        }
    }
    match summary.status {
        RunStatus::Diverged { message, .. } => Err(Error::Diverged(message)),
        RunStatus::Interrupted { .. } => Ok(130),
        RunStatus::Collided { .. } => Ok(4),
        RunStatus::Completed => Ok(0),
    }
}
