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
}


/// `armscope model`.
pub fn model(args: &ModelArgs) -> Result<i32, Error> {
    let model = crate::model::load_urdf_with(&args.urdf, crate::model::LoadOptions { strict_inertia: args.strict_inertia })?;
    for notice in &model.notices {
        eprintln!("armscope: notice: {notice}");
    }
    if let Some(path) = &args.states {
        let text = std::fs::read_to_string(path).map_err(|e| Error::flag("--states", format!("{}: {e}", path.display())))?;
        let states: Vec<crate::inspect::State> = serde_json::from_str(&text).map_err(|e| Error::flag("--states", format!("{}: {e}", path.display())))?;
        println!("{}", crate::inspect::dynamics_at(&model, &states)?);
    } else if args.json {
        println!("{}", serde_json::to_string_pretty(&crate::inspect::describe(&model)).unwrap_or_default());
    } else {
        print!("{}", crate::inspect::table(&model));
    }
    Ok(0)
}
