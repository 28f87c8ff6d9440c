//! `armscope trajectory`: a shape drawn with the tool, solved by IK into a joint schedule.

use super::*;

#[derive(Args, Debug)]
pub struct TrajectoryArgs {
    /// The shape, on a vertical plane in front of the arm.
    #[arg(value_enum)]
    pub shape: crate::control::ik::Shape,
    #[arg(long, value_name = "PATH", default_value = crate::config::DEFAULT_URDF)]
    pub urdf: PathBuf,
    /// Time to draw the shape, s.
    #[arg(long, default_value_t = 10.0)]
    pub duration: f64,
    /// Sample interval of the schedule, s.
    #[arg(long, default_value_t = 0.01)]
    pub step: f64,
    /// Half-width of the shape, m (default: a sixth of the arm's reach).
    #[arg(long)]
    pub size: Option<f64>,
    /// Centre of the shape "x,y,z" in m (default: 3/4 of the reach, at the tool's height).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub centre: Option<Vec<f64>>,
    /// Joints that move (numbers from 1 or names; default: the first three, the wrist locked at 0).
    #[arg(long, value_delimiter = ',', num_args = 1)]
    pub ik_joints: Option<Vec<String>>,
    /// Output prefix: writes PREFIX.csv and PREFIX.npy (default: recordings/trajectory_SHAPE).
    #[arg(long, value_name = "PREFIX")]
    pub out: Option<PathBuf>,
    /// Also check the path for a floor at this height (world z, m; self-collision is always checked).
    #[arg(long, value_name = "Z", allow_negative_numbers = true)]
    pub floor: Option<f64>,
    /// An SRDF whose disabled pairs are not checked (default: the one beside the URDF).
    #[arg(long, value_name = "FILE")]
    pub srdf: Option<PathBuf>,
    /// Also check the path against a scene file's objects, floor and payload shape (TOML; see
    /// `armscope run --scene`).
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
}


/// `armscope trajectory`.
pub fn trajectory(args: &TrajectoryArgs) -> Result<i32, Error> {
    use crate::control::ik::{default_drawing, solve_drawing};
    let model = crate::model::load_urdf(&args.urdf)?;
    if !(args.duration > 0.0 && args.step > 0.0 && args.step <= args.duration) {
        return Err(Error::flag("--step", "must be positive and at most --duration"));
    }
    let mut drawing = default_drawing(&model, args.shape);
    if let Some(size) = args.size {
        if !(size > 0.0 && size.is_finite()) {
            return Err(Error::flag("--size", format!("must be a positive length (got {size})")));
        }
        drawing.size = size;
    }
    if let Some(c) = &args.centre {
        if c.len() != 3 || c.iter().any(|x| !x.is_finite()) {
            return Err(Error::flag("--centre", "expected x,y,z in metres"));
        }
        drawing.centre = nalgebra::Vector3::new(c[0], c[1], c[2]);
    }
    let joints: Vec<usize> = match &args.ik_joints {
        Some(list) => list.iter().map(|j| crate::experiment::resolve_joint(j, &model).map_err(|_| Error::flag("--ik-joints", format!("no joint '{j}' in {}", model.source.display())))).collect::<Result<_, _>>()?,
        None => (0..model.dof().min(3)).collect(),
    };
    let (times, positions, targets) = solve_drawing(&model, &drawing, joints, args.duration, args.step).map_err(|m| Error::flag("trajectory", m))?;
    let shape = format!("{:?}", args.shape).to_lowercase();
    let prefix = args.out.clone().unwrap_or_else(|| PathBuf::from("recordings").join(format!("trajectory_{shape}")));
    let (csv, npy) = (prefix.with_extension("csv"), prefix.with_extension("npy"));
    crate::runner::create_parent(&csv)?;
    let n = model.dof();
    let mut text = std::iter::once("t".to_string()).chain((1..=n).map(|i| format!("q{i}"))).collect::<Vec<_>>().join(",") + "\n";
    let mut flat = Vec::with_capacity(times.len() * (n + 1));
    for (t, q) in times.iter().zip(&positions) {
        text += &std::iter::once(format!("{t:?}")).chain(q.iter().map(|x| format!("{x:?}"))).collect::<Vec<_>>().join(",");
        text += "\n";
        flat.push(*t);
        flat.extend_from_slice(q);
    }
    // the path checked for collisions before it is written: each sample's pairs in contact
    let (scene, floor_notice) = crate::collision::Scene::from_flags(args.scene.as_deref(), args.floor)?;
    let collisions = crate::collision::Collisions::new(&model, args.srdf.as_deref(), &scene)?;
    for notice in floor_notice.iter().chain(&collisions.notices) {
        eprintln!("armscope: notice: {notice}");
    }
    let mut first: Option<(f64, String, String, f64)> = None;
    let mut in_contact = 0;
    let mut closest: Option<(f64, String, String, f64)> = None;
    let mut checker = collisions.checker(&model);
    for (t, q) in times.iter().zip(&positions) {
        checker.check(q, 0.05);
        let close = checker.named();
        if let Some((a, b, d)) = close.first() {
            if closest.as_ref().is_none_or(|c| *d < c.3) {
                closest = Some((*t, a.clone(), b.clone(), *d));
            }
            if *d <= 0.0 {
                in_contact += 1;
                if first.is_none() {
                    first = Some((*t, a.clone(), b.clone(), *d));
                }
            }
        }
    }
    let checked = collisions.describe();
    match (&first, &closest) {
        (Some((t, a, b, _)), _) => eprintln!("armscope: notice: the path collides: first at t = {t:.3} s, {a} with {b}; {in_contact} of {} points in contact ({checked} checked)", times.len()),
        (None, Some((t, a, b, d))) => println!("collisions: none ({checked}); closest {a} — {b}, {:.1} mm at t = {t:.3} s", 1e3 * d),
        (None, None) => println!("collisions: none ({checked}), none closer than 5 cm"),
    }
    std::fs::write(&csv, text).map_err(|e| Error::output(&csv, e))?;
    std::fs::write(&npy, crate::npy::write_f64(times.len(), n + 1, &flat)).map_err(|e| Error::output(&npy, e))?;
    // check: every point by forward kinematics
    let mut ik = crate::control::ik::PositionIk::new(&model, vec![]);
    let worst = positions.iter().zip(&targets).map(|(q, p)| (ik.tool_position(q) - p).norm()).fold(0.0, f64::max);
    let c = drawing.centre;
    println!(
        "{shape}: {} points over {} s on the plane x = {:.3} m, centre ({:.3}, {:.3}, {:.3}) m, size {:.3} m; worst IK error {:.2e} m",
        times.len(), args.duration, c.x, c.x, c.y, c.z, drawing.size, worst
    );
    println!("wrote {} and {}\nfollow it: armscope run --urdf {} --trajectory {} --duration {}", csv.display(), npy.display(), args.urdf.display(), csv.display(), args.duration);
    Ok(0)
}
