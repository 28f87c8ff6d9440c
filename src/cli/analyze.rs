//! `armscope analyze`: is the sampled control loop stable, and with which gains and dt.

use super::*;

#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// Control period, s.
    #[arg(long, default_value_t = 0.001)]
    pub dt: f64,
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kp: Option<Vec<f64>>,
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub kd: Option<Vec<f64>>,
    #[arg(long)]
    pub auto_tune: bool,
    #[arg(long)]
    pub no_ff: bool,
    #[arg(long)]
    pub no_gravity: bool,
    /// The pose to linearize at, one angle per joint (default: all 0, the start pose).
    #[arg(long, value_delimiter = ',', num_args = 1, allow_negative_numbers = true)]
    pub pose: Option<Vec<f64>>,
    /// Also linearize at 12 poses along one period of the default wave (--freq/--amp-deg as `run`),
    /// and suggest kd that is stable at all of them (inertia changes with pose).
    #[arg(long)]
    pub along_command: bool,
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub freq: f64,
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub amp_deg: f64,
    /// The plant in the loop.
    #[arg(long, value_enum, default_value = "discrete")]
    pub plant: crate::diagnose::analysis::LoopPlant,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}


/// `armscope analyze`.
pub fn analyze(args: &AnalyzeArgs) -> Result<i32, Error> {
    use crate::diagnose::analysis::{Linearization, LoopPlant, largest_stable_period, spectral_radius, stabilizing_kd_over, worst_radius};
    let config = RunConfig {
        urdf: args.urdf.clone(),
        dt: args.dt,
        kp: args.kp.clone(),
        kd: args.kd.clone(),
        auto_tune: args.auto_tune,
        no_ff: args.no_ff,
        no_gravity: args.no_gravity,
        ..RunConfig::default()
    };
    let experiment = Experiment::prepare(config)?;
    let model = &*experiment.model;
    let n = model.dof();
    let pose = args.pose.clone().unwrap_or_else(|| vec![0.0; n]);
    if pose.len() != n || pose.iter().any(|x| !x.is_finite()) {
        return Err(Error::flag("--pose", format!("expected {n} finite angles, one per joint")));
    }
    let (kp, kd) = experiment.controller().effective_gains();
    let ff = !args.no_ff;
    let h = args.dt;
    // the given pose first, then (--along-command) poses along the wave
    let poses: Vec<Vec<f64>> = if args.along_command {
        let wave = crate::control::trajectory::Wave { amplitude_rad: args.amp_deg.to_radians(), omega: args.freq };
        let period = 2.0 * std::f64::consts::PI / args.freq.abs().max(1e-6);
        let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
        std::iter::once(pose.clone())
            .chain((0..12).map(|i| {
                crate::control::trajectory::Trajectory::sample(&wave, period * i as f64 / 12.0, &mut q, &mut qd);
                q.clone()
            }))
            .collect()
    } else {
        vec![pose.clone()]
    };
    let lins: Vec<Linearization> = poses.iter().map(|p| Linearization::at(model, p)).collect();
    let lin = &lins[0];
    let (rho, participation) = spectral_radius(&lin.closed_loop(&kp, &kd, h, ff, args.plant));
    let stable = rho < 1.0;
    let largest_dt = largest_stable_period(lin, &kp, &kd, h, ff, args.plant);
    let worst = worst_radius(&lins, &kp, &kd, h, ff, args.plant);
    let (stable_kd, stable_rho) = stabilizing_kd_over(&lins, &kp, &kd, h, ff, args.plant);
    let names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let mut drivers: Vec<(String, f64)> = names.iter().cloned().zip(participation.iter().copied()).collect();
    drivers.sort_by(|a, b| b.1.total_cmp(&a.1));
    let kd_list = stable_kd.iter().map(|k| format!("{:.4}", k)).collect::<Vec<_>>().join(",");
    let plant_name = match args.plant {
        LoopPlant::Discrete => "discrete",
        LoopPlant::Continuous => "continuous",
    };
    let run_hint = format!(
        "armscope run --urdf {}{} --kp {} --kd {kd_list}{}",
        args.urdf.display(),
        if args.plant == LoopPlant::Continuous { " --time-step 0" } else { "" },
        kp.iter().map(|k| format!("{k}")).collect::<Vec<_>>().join(","),
        if args.dt != 0.001 { format!(" --dt {}", args.dt) } else { String::new() }
    );
    if args.json {
        let doc = serde_json::json!({
            "model": model.name, "urdf": args.urdf, "pose": pose, "dt": h, "plant": args.plant, "feed_forward": ff,
            "kp": kp, "kd": kd, "gains": experiment.gains.source,
            "spectral_radius": rho, "stable": stable,
            "poses": poses.len(), "worst_spectral_radius_over_poses": worst,
            "participation": names.iter().zip(&participation).map(|(n, p)| (n.clone(), *p)).collect::<std::collections::BTreeMap<_, _>>(),
            "largest_stable_dt": largest_dt,
            "stable_kd": if stable_rho < 1.0 { Some(&stable_kd) } else { None },
            "stable_kd_spectral_radius": stable_rho,
            "run_with_stable_kd": (stable_rho < 1.0).then_some(&run_hint),
        });
        println!("{}", serde_json::to_string_pretty(&doc).unwrap_or_default());
        return Ok(0);
    }
    println!("sampled closed loop of {} at pose {:?}, dt = {} ms, {plant_name} plant, gains {}:", model.name, pose, h * 1e3, experiment.gains.source);
    println!("  kp = {kp:?}\n  kd = {kd:?}");
    if stable {
        println!("  spectral radius {rho:.3}: STABLE (a small disturbance decays by {rho:.3}× per control step)");
    } else {
        println!("  spectral radius {rho:.3}: UNSTABLE (a small disturbance grows {rho:.2}× per control step, until the torque limits clip it into chatter)");
        println!("  driven by: {}", drivers.iter().filter(|d| d.1 > 0.02).map(|(n, p)| format!("{n} {:.0}%", 100.0 * p)).collect::<Vec<_>>().join(", "));
    }
    if args.along_command {
        println!("  worst spectral radius over {} poses along the wave: {worst:.3}", poses.len());
    }
    match largest_dt {
        Some(d) if d >= h => println!("  these gains are stable at this dt"),
        Some(d) => println!("  largest stable dt for these gains: {:.4} ms (run with --dt {:.6})", d * 1e3, d),
        None => println!("  these gains are unstable even at 1 µs"),
    }
    if stable_rho < 1.0 {
        println!("  stable derivative gains at dt = {} ms (kp unchanged): kd = [{kd_list}], spectral radius {stable_rho:.3}", h * 1e3);
        println!("  run with them: {run_hint}");
    } else {
        println!("  no kd scaling makes this loop stable at dt = {} ms (best spectral radius {stable_rho:.3}): lower kp or dt", h * 1e3);
    }
    Ok(0)
}
