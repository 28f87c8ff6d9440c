//! `armscope model`: what armscope made of a URDF, and its dynamics at given states.

use super::*;

#[derive(Args, Debug)]
pub struct ModelArgs {
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// A JSON list of states by joint name, [{"q": {"J1": 0.1}, "v": {...}, "tau": {...}}, ...]:
    /// print the dynamics at each as JSON.
    #[arg(long, value_name = "FILE")]
    pub states: Option<PathBuf>,
    /// The model as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Refuse physically inconsistent link inertias (as Drake does) instead of a notice.
    #[arg(long)]
    pub strict_inertia: bool,
    /// A motor file: the model with its drive trains (their parts carried on the arm, their rotors
    /// on M's diagonal), as `run --motors` simulates it.
    #[arg(long, value_name = "FILE")]
    pub motors: Option<PathBuf>,
    /// Write the URDF with the drive trains' parts as links here (needs --motors), so any other
    /// library can check the model armscope simulates.
    #[arg(long, value_name = "FILE", requires = "motors")]
    pub urdf_out: Option<PathBuf>,
    /// The collision checks' set-up: each link's shapes and the active pairs (with --states: per
    /// state the pairs closer than 5 cm, negative inside, in the JSON).
    #[arg(long)]
    pub collisions: bool,
    /// An SRDF whose <disable_collisions> pairs are not checked (default: the one beside the URDF).
    #[arg(long, value_name = "FILE")]
    pub srdf: Option<PathBuf>,
    /// Write an SRDF of the active pairs that never (or always) touch over --samples random states,
    /// and the adjacent ones, as MoveIt's setup assistant does (implies --collisions).
    #[arg(long, value_name = "FILE")]
    pub srdf_out: Option<PathBuf>,
    /// A scene file (TOML: fixed objects, a floor, the payload's shape) checked with --collisions
    /// --states too (see `armscope run --scene`).
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// Random states for --srdf-out.
    #[arg(long, default_value_t = 10000)]
    pub samples: usize,
}


/// `armscope model`.
pub fn model(args: &ModelArgs) -> Result<i32, Error> {
    let mut model = crate::model::load_urdf_with(&args.urdf, crate::model::LoadOptions { strict_inertia: args.strict_inertia })?;
    crate::dynamics::check_solvable(&model)?;
    for notice in &model.notices {
        eprintln!("armscope: notice: {notice}");
    }
    if let Some(path) = &args.motors {
        let set = crate::actuator::load_motor_file(path, &model)?;
        let urdf_mass: f64 = model.frames_mass();
        let parts = crate::actuator::carried::install(&mut model, &set).map_err(|m| Error::flag("--motors", format!("{}: {m}", path.display())))?;
        let drive_mass: f64 = parts.iter().map(|p| p.part.mass).sum();
        eprintln!("armscope: {}: {} parts carried, {drive_mass:.3} kg: the arm's mass {urdf_mass:.3} kg → {:.3} kg", path.display(), parts.len(), urdf_mass + drive_mass);
        if let Some(out) = &args.urdf_out {
            let text = crate::actuator::carried::urdf_with_parts(&model.urdf_text, &parts, &model).map_err(|m| Error::flag("--urdf-out", m))?;
            std::fs::write(out, text).map_err(|e| Error::output(out, e))?;
            eprintln!("armscope: wrote {}", out.display());
        }
    }
    let collisions = if args.collisions || args.srdf.is_some() || args.srdf_out.is_some() || args.scene.is_some() {
        let (scene, _) = crate::collision::Scene::from_flags(args.scene.as_deref(), None)?;
        let c = crate::collision::Collisions::new(&model, args.srdf.as_deref(), &scene)?;
        for notice in &c.notices {
            eprintln!("armscope: notice: {notice}");
        }
        Some(c)
    } else {
        None
    };
    if let (Some(out), Some(c)) = (&args.srdf_out, &collisions) {
        let text = crate::collision::srdf::sampled(&model, c, args.samples);
        std::fs::write(out, &text).map_err(|e| Error::output(out, e))?;
        eprintln!("armscope: wrote {}: {} of {} active pairs never or always in contact over {} states", out.display(), text.matches("reason=\"Never\"").count() + text.matches("reason=\"Always\"").count(), c.pairs.len(), args.samples);
        return Ok(0);
    }
    if let Some(path) = &args.states {
        let text = std::fs::read_to_string(path).map_err(|e| Error::flag("--states", format!("{}: {e}", path.display())))?;
        let states: Vec<crate::inspect::State> = serde_json::from_str(&text).map_err(|e| Error::flag("--states", format!("{}: {e}", path.display())))?;
        let mut out = crate::inspect::dynamics_at(&model, &states)?;
        if let Some(c) = &collisions {
            out["collision_pairs"] = serde_json::json!(c.pairs.iter().map(|&(a, b)| [&model.frames[a].name, &model.frames[b].name]).collect::<Vec<_>>());
            let mut checker = c.checker(&model);
            for (s, json) in states.iter().zip(out["states"].as_array_mut().into_iter().flatten()) {
                let q: Vec<f64> = model.joints.iter().map(|j| s.q.get(&j.name).copied().unwrap_or(0.0)).collect();
                checker.check(&q, 0.05);
                json["collisions"] = serde_json::json!(checker.named().into_iter().map(|(a, b, d)| serde_json::json!({"link1": a, "link2": b, "distance": d})).collect::<Vec<_>>());
            }
        }
        println!("{out}");
    } else if let Some(c) = &collisions {
        let shapes = |f: usize| c.shapes.of_frame[f].len();
        println!("{} links with collision shapes, {} active pairs (of {} link pairs with shapes):", (0..model.frames.len()).filter(|&f| shapes(f) > 0).count(), c.pairs.len(), {
            let n = (0..model.frames.len()).filter(|&f| shapes(f) > 0).count();
            n * n.saturating_sub(1) / 2
        });
        for &(a, b) in &c.pairs {
            println!("  {} — {}", model.frames[a].name, model.frames[b].name);
        }
    } else if args.json {
        println!("{}", serde_json::to_string_pretty(&crate::inspect::describe(&model)).unwrap_or_default());
    } else {
        print!("{}", crate::inspect::table(&model));
    }
    Ok(0)
}
