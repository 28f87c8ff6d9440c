//! `armscope envelope`: how fast the arm can go, frequency × amplitude.

use super::*;

#[derive(Args, Debug)]
pub struct EnvelopeArgs {
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// Wave frequencies ω, rad/s (default: 10 values from 0.25 to 16, logarithmic).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub freqs: Option<Vec<f64>>,
    /// Wave amplitudes, degrees (default: 10 values from 5 to 60).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub amps: Option<Vec<f64>>,
    /// A payload at the tool, kg.
    #[arg(long, default_value_t = 0.0)]
    pub payload: f64,
    /// Gains (default: the model's, with kd made stable by `analyze` at the start pose).
    #[command(flatten)]
    pub gains: GainArgs,
    #[arg(long, default_value_t = 0.001)]
    pub dt: f64,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "recordings/envelope")]
    pub out: PathBuf,
    /// Cells simulated at once (default: all cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// The need is compared with what each motor gives at the joint's speed.
    #[command(flatten)]
    pub motors: MotorArgs,
}


/// `armscope envelope`.
pub fn envelope(args: &EnvelopeArgs) -> Result<i32, Error> {
    use crate::control::sampled_loop::{Linearization, LoopPlant, spectral_radius, stabilizing_kd};
    use crate::diagnose::envelope::sweep;
    let freqs = args.freqs.clone().unwrap_or_else(|| (0..10).map(|i| 0.25 * 64f64.powf(i as f64 / 9.0)).map(|f| (f * 100.0).round() / 100.0).collect());
    let amps = args.amps.clone().unwrap_or_else(|| (0..10).map(|i| 5.0 + 55.0 * i as f64 / 9.0).map(|a| a.round()).collect());
    if freqs.iter().chain(&amps).any(|x| !(x.is_finite() && *x > 0.0)) {
        return Err(Error::flag("--freqs/--amps", "values must be positive"));
    }
    let model = crate::model::load_urdf(&args.urdf)?;
    // the payload as `run --payload` carries it (the experiment checks it)
    let mut config = RunConfig { urdf: args.urdf.clone(), dt: args.dt, payload: args.payload, motors: args.motors.motors.clone(), drive: args.motors.drive, ..RunConfig::default() };
    args.gains.apply(&mut config);
    let probe = Experiment::with_model(config.clone(), model.clone())?;
    let (kp, kd) = probe.controller().effective_gains();
    // the loop as it runs: the probe's model has the motors' rotors on M's diagonal
    let lin = Linearization::at(&probe.model, &vec![0.0; model.dof()]);
    // with every joint left to its servo's firmware (or a stepper) there is no PD loop to stabilise
    let rho = if probe.gains.drives_a_joint() { spectral_radius(&lin.closed_loop(&kp, &kd, args.dt, true, LoopPlant::Discrete)).0 } else { 0.0 };
    if args.gains.kd.is_none() && rho >= 1.0 {
        let (kd, stable) = stabilizing_kd(&lin, &kp, &kd, args.dt, true, LoopPlant::Discrete);
        println!("gains {} are unstable at dt = {} ms (spectral radius {rho:.2}); using kd = {kd:.4?} (spectral radius {stable:.3})", probe.gains.source, args.dt * 1e3);
        config.kd = Some(kd);
    } else if rho >= 1.0 {
        println!("warning: the given gains are unstable at dt = {} ms (spectral radius {rho:.2}): saturation will include chatter", args.dt * 1e3);
    }
    let jobs = args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let started = std::time::Instant::now();
    let env = sweep(&config, &model, &freqs, &amps, jobs)?;
    std::fs::create_dir_all(&args.out).map_err(|e| Error::output(&args.out, e))?;
    let x_ticks: Vec<String> = freqs.iter().map(|f| format!("{f}")).collect();
    let y_ticks: Vec<String> = amps.iter().map(|a| format!("{a}")).collect();
    let mut files = Vec::new();
    let rrd_path = args.out.join("envelope.rrd");
    let rec = rerun::RecordingStreamBuilder::new("armscope-envelope").save(&rrd_path).map_err(|e| Error::output(&rrd_path, e))?;
    for (j, name) in env.joints.iter().enumerate() {
        if env.effort[j] == 0.0 {
            continue;
        }
        let values: Vec<Vec<f64>> = (0..amps.len()).map(|a| (0..freqs.len()).map(|f| env.cell(a, f).demand[j]).collect()).collect();
        let limit = if args.motors.motors.is_some() { "AT SPEED".to_string() } else { format!("{} NM", env.effort[j]) };
        let title = format!("{name} NEEDED TORQUE / LIMIT ({limit}){}", if args.payload > 0.0 { format!(", PAYLOAD {} KG", args.payload) } else { String::new() });
        let canvas = crate::canvas::heatmap(&title, "WAVE FREQUENCY (RAD/S)", &x_ticks, "AMPLITUDE (DEG)", &y_ticks, &values);
        let png = args.out.join(format!("envelope_{name}.png"));
        canvas.save_png(&png).map_err(|e| Error::output(&png, e))?;
        files.push(png);
        rec.log_static(format!("envelope/{name}"), &rerun::Image::from_rgb24(canvas.rgb.clone(), [canvas.width as u32, canvas.height as u32]))
            .map_err(|e| Error::output(&rrd_path, e))?;
    }
    let table = env.table((0.5, 30.0));
    let mut md = format!(
        "# speed envelope of {}\n\nNeeded torque = peak |τ| of the inverse dynamics of the commanded wave (what a perfect controller must supply), against the motor's limit. Simulated with kp = {:?}, kd = {:.4?}.\n\n{table}\n",
        model.name, env.kp, env.kd
    );
    md += "\nFastest frequency (rad/s) within the limit, per amplitude:\n\n| amplitude (°) |";
    for n in &env.joints {
        md += &format!(" {n} |");
    }
    md += "\n|---|";
    md += &"---|".repeat(env.joints.len());
    md += "\n";
    for (a, amp) in amps.iter().enumerate() {
        md += &format!("| {amp} |");
        for j in 0..env.joints.len() {
            md += &format!(" {} |", env.boundary(j)[a].map_or("none".into(), |f| format!("{f}")));
        }
        md += "\n";
    }
    rec.log_static("table", &rerun::TextDocument::from_markdown(md.clone())).map_err(|e| Error::output(&rrd_path, e))?;
    rec.flush_blocking().map_err(|e| Error::output(&rrd_path, e))?;
    files.push(rrd_path);
    for (name, text) in [("envelope.md", md.clone()), ("envelope.json", serde_json::to_string_pretty(&env).unwrap_or_default())] {
        let p = args.out.join(name);
        std::fs::write(&p, text).map_err(|e| Error::output(&p, e))?;
        files.push(p);
    }
    print!("{md}");
    println!("\n{} cells in {:.1} s; wrote {}", env.cells.len(), started.elapsed().as_secs_f64(), files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", "));
    Ok(0)
}
