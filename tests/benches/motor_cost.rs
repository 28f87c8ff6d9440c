//! What the tutorial's drive trains (`assets/motors/tutorial.toml`) cost a run, as a ratio to the
//! same run without motors: the runs taken in turn, again and again, each pair's ratio from the best
//! time of each. On a machine whose speed drifts by tens of percent within minutes, runs timed minutes
//! apart (criterion's groups) give ratios that scatter by ±10 %; timed in turn, they repeat within a
//! few percent. `cargo bench --bench motor_cost [ROUNDS]` (default 30).
//!
//! Beside them, what a motor file's `[floor]` costs: the SO-101 on its servos with 0.2 kg along its
//! default trajectory, against the same run with a table at z = 0.12 m, halfway down from where its
//! tool starts (0.187 m) to its lowest (0.053 m): the tool is on the table a fifth of the run, and
//! within reach of it (where the contact's Jacobian is taken) most of it.

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
    let so101_motors = std::fs::read_to_string(root.join("assets/motors/so101.toml")).expect("the SO-101's motor file");
    let table_file = std::env::temp_dir().join(format!("armscope-bench-table-{}.toml", std::process::id()));
    std::fs::write(&table_file, so101_motors + "\n[floor]\nheight = 0.12\n").expect("a motor file with a table");
    let so101 = RunConfig { urdf: root.join("tests/fixtures/robots/so101.urdf"), motors: Some(root.join("assets/motors/so101.toml")), payload: 0.2, ..RunConfig::default() };
    let so101_on_table = RunConfig { motors: Some(table_file.clone()), ..so101.clone() };
    let pairs = [
        ("--drive pd", "the run without motors", bare, pd),
        ("open-loop steppers", "the run without motors at their plant step", bare_at_stepper_step, steppers),
        ("the SO-101's servos with a table under the tool", "without the table", so101, so101_on_table),
    ];
    println!("the default run (30 s), with and without: best of {rounds} rounds, each pair in turn");
    for (with, without, config_without, config_with) in pairs {
        let experiment_without = Experiment::prepare(config_without).expect("the run without");
        let experiment_with = Experiment::prepare(config_with).expect("the run with");
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
    let _ = std::fs::remove_file(table_file);
}

fn time(experiment: &Experiment) -> Duration {
    let start = Instant::now();
    black_box(simulate(experiment, &mut [], None).expect("the run").steps);
    start.elapsed()
}
