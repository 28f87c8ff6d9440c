//! What the tutorial's drive trains (`assets/motors/tutorial.toml`) cost a run, as a ratio to the
//! same run without motors: the runs taken in turn, again and again, each pair's ratio from the best
//! time of each. On a machine whose speed drifts by tens of percent within minutes, runs timed minutes
//! apart (criterion's groups) give ratios that scatter by ±10 %; timed in turn, they repeat within a
//! few percent. `cargo bench --bench motor_cost [ROUNDS]` (default 30).

use armscope::config::{DriveMode, RunConfig};
use armscope::experiment::Experiment;
use armscope::sim::simulate;
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

fn main() {
    let rounds: usize = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(30);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let urdf = root.join("assets/smallrobot_arm.urdf");
    let motors = root.join("assets/motors/tutorial.toml");
    let bare = RunConfig { urdf: urdf.clone(), ..RunConfig::default() };
    let pd = RunConfig { motors: Some(motors.clone()), drive: DriveMode::Pd, ..bare.clone() };
    let steppers = RunConfig { motors: Some(motors), ..bare.clone() };
    // the steppers' run takes the plant step its stiffest stepper needs: the run without motors at
    // that step is what its plant steps cost without them
    let stepper_plant_step = Experiment::prepare(steppers.clone()).expect("the tutorial's steppers").plant.time_step().expect("the default plant is discrete");
    let bare_at_stepper_step = RunConfig { time_step: Some(stepper_plant_step), ..bare.clone() };
    let pairs = [
        ("--drive pd", "the run without motors", bare, pd),
        ("open-loop steppers", "the run without motors at their plant step", bare_at_stepper_step, steppers),
    ];
    println!("30 s default run, the tutorial's drive trains against none: best of {rounds} rounds, each pair in turn");
    for (with, without, config_without, config_with) in pairs {
        let experiment_without = Experiment::prepare(config_without).expect("the box model");
        let experiment_with = Experiment::prepare(config_with).expect("the tutorial's drive trains");
        let (mut best_without, mut best_with) = (Duration::MAX, Duration::MAX);
        for _ in 0..rounds {
            best_without = best_without.min(time(&experiment_without));
            best_with = best_with.min(time(&experiment_with));
        }
        println!(
            "  {with}: {:.1} ms, {without}: {:.1} ms — {:.2}×",
            best_with.as_secs_f64() * 1e3,
            best_without.as_secs_f64() * 1e3,
            best_with.as_secs_f64() / best_without.as_secs_f64()
        );
    }
}

fn time(experiment: &Experiment) -> Duration {
    let start = Instant::now();
    black_box(simulate(experiment, &mut [], None).expect("the run").steps);
    start.elapsed()
}
