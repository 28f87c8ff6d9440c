//! Speed of the dynamics and the simulation loop on the box model. Reference timings
//! (../shared/reference/README.md, 2-core machine): Pinocchio ABA 1.28 µs, RNEA 0.63 µs,
//! CRBA 0.31 µs; MuJoCo 2.5 µs per step; the tutorial's 30 s default run 1.6 s.

use armscope::actuator::StepperOutput;
use armscope::config::RunConfig;
use armscope::dynamics::{Data, RneaManyData, aba, crba, forward_kinematics, gravity_and_bias_from_kinematics, rnea, rnea_many};
use armscope::experiment::Experiment;
use armscope::model::load_urdf;
use armscope::sim::simulate;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn urdf() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/smallrobot_arm.urdf")
}

fn state() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    (
        vec![0.3, -0.5, 0.8, -1.1, 0.6, 0.2],
        vec![0.4, 0.9, -1.2, 0.5, -2.0, 1.0],
        vec![1.0, -2.0, 0.5, 0.3, -0.2, 0.1],
    )
}

fn algorithms(c: &mut Criterion) {
    let model = load_urdf(&urdf()).unwrap();
    let mut data = Data::new(&model);
    let (q, v, tau) = state();
    c.bench_function("rnea", |b| b.iter(|| black_box(rnea(&model, &mut data, black_box(&q), black_box(&v), black_box(&tau))[0])));
    c.bench_function("crba", |b| b.iter(|| black_box(crba(&model, &mut data, black_box(&q))[(0, 0)])));
    c.bench_function("aba", |b| b.iter(|| black_box(aba(&model, &mut data, black_box(&q), black_box(&v), black_box(&tau))[0])));
}

/// A trajectory's inverse dynamics, 1000 states of the box model and of the SO-101 (six joints):
/// `rnea_many` (eight states in SIMD lanes where the processor has AVX-512, else four; and its
/// four lanes on their own) against a loop of `rnea`.
fn trajectory(c: &mut Criterion) {
    let so101 = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/robots/so101.urdf");
    let mut group = c.benchmark_group("trajectory_1000_states");
    for (robot, path) in [("box", urdf()), ("so101", so101)] {
        let model = load_urdf(&path).unwrap();
        let n = model.dof();
        let states = 1000;
        let wave = |i: usize, f: f64| (i as f64 * f).sin();
        let q: Vec<f64> = (0..states * n).map(|i| wave(i, 0.37)).collect();
        let v: Vec<f64> = (0..states * n).map(|i| 2.0 * wave(i, 0.71)).collect();
        let a: Vec<f64> = (0..states * n).map(|i| 5.0 * wave(i, 1.13)).collect();
        let mut tau = vec![0.0; states * n];
        let mut many = RneaManyData::new(&model);
        group.bench_function(format!("rnea_many/{robot}"), |b| {
            b.iter(|| {
                rnea_many(&model, &mut many, black_box(&q), black_box(&v), black_box(&a), &mut tau);
                black_box(tau[0])
            })
        });
        let mut four = RneaManyData::with_four_lanes(&model);
        group.bench_function(format!("rnea_many_four_lanes/{robot}"), |b| {
            b.iter(|| {
                rnea_many(&model, &mut four, black_box(&q), black_box(&v), black_box(&a), &mut tau);
                black_box(tau[0])
            })
        });
        let mut data = Data::new(&model);
        group.bench_function(format!("rnea_loop/{robot}"), |b| {
            b.iter(|| {
                for k in 0..states {
                    let row = k * n..(k + 1) * n;
                    tau[row.clone()].copy_from_slice(rnea(&model, &mut data, black_box(&q[row.clone()]), black_box(&v[row.clone()]), black_box(&a[row])));
                }
                black_box(tau[0])
            })
        });
    }
    group.finish();
}

/// One plant step including what it needs at the new state: kinematics, τ_g and C·v.
fn plant_step(b: &mut criterion::Bencher, model: &armscope::model::Model, data: &mut Data, plant: &mut dyn armscope::plant::Plant, q0: &[f64], v0: &[f64], u: &[f64]) {
    b.iter_batched_ref(
        || (q0.to_vec(), v0.to_vec()),
        |(q, v)| {
            forward_kinematics(model, data, q);
            gravity_and_bias_from_kinematics(model, data, v);
            plant.advance(model, data, u, q, v);
            black_box(q[0])
        },
        criterion::BatchSize::SmallInput,
    )
}

fn discrete_step(c: &mut Criterion) {
    let experiment = Experiment::prepare(RunConfig { urdf: urdf(), ..RunConfig::default() }).unwrap();
    let model = &*experiment.model;
    let mut data = Data::new(model);
    let mut plant = experiment.make_plant();
    let (q0, v0, u) = state();
    c.bench_function("discrete_step", |b| plant_step(b, model, &mut data, plant.as_mut(), &q0, &v0, &u));
}

fn whole_run(c: &mut Criterion) {
    let experiment = Experiment::prepare(RunConfig { urdf: urdf(), ..RunConfig::default() }).unwrap();
    let mut group = c.benchmark_group("run");
    group.sample_size(20);
    group.bench_function("default_30s_no_recording", |b| {
        b.iter(|| black_box(simulate(&experiment, &mut [], None).unwrap().steps))
    });
    group.finish();
}

/// Larger trees (tests/fixtures/robots/, from example-robot-data 6.0.0): Baxter (17 coordinates, 19
/// moving joints with its mimic fingers), the Allegro hand (16), Tiago (48). Reference: Pinocchio
/// in C++ on the same URDFs (.ci/bench-reference), MuJoCo's rollout.
fn large_trees(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/robots");
    for file in ["baxter.urdf", "allegro_right_hand.urdf", "tiago.urdf"] {
        let experiment = Experiment::prepare(RunConfig { urdf: dir.join(file), ..RunConfig::default() }).unwrap();
        let model = &*experiment.model;
        let n = model.dof();
        let mut data = Data::new(model);
        // a state away from every limit: each joint at 0.3 of its range, or 0.3 rad
        let q: Vec<f64> = model.joints.iter().map(|j| if j.lower.is_finite() && j.upper.is_finite() { j.lower + 0.3 * (j.upper - j.lower) } else { 0.3 }).collect();
        let v: Vec<f64> = (0..n).map(|i| -1.0 + 2.0 * i as f64 / n as f64).collect();
        let tau: Vec<f64> = v.iter().map(|x| -x).collect();
        let name = file.trim_end_matches(".urdf");
        let mut group = c.benchmark_group(format!("{name}_{n}dof"));
        if !model.has_mimic() {
            group.bench_function("aba", |b| b.iter(|| black_box(aba(model, &mut data, black_box(&q), black_box(&v), black_box(&tau))[0])));
        }
        group.bench_function("rnea", |b| b.iter(|| black_box(rnea(model, &mut data, black_box(&q), black_box(&v), black_box(&tau))[0])));
        group.bench_function("crba", |b| b.iter(|| black_box(crba(model, &mut data, black_box(&q))[(0, 0)])));
        let mut plant = experiment.make_plant();
        let u = vec![0.0; n];
        group.bench_function("discrete_step", |b| plant_step(b, model, &mut data, plant.as_mut(), &q, &v, &u));
        group.finish();
    }
}

/// With motors (`--motors assets/motors/tutorial.toml`): one control step of the loop's work, as
/// `sim::simulate` does it — kinematics, τ_g and C·q̇, the controller (PD on the speed-dependent
/// limit; as steppers, the open-loop steppers' command, torque, load angle and limit at the control
/// step, then their torque again at the plant step), one plant step — against the same without
/// motors. Stepper mode's run takes more plant steps per control period (chosen for the stiffest
/// stepper), which `motors_run_*` shows whole, beside the run without motors at the same plant
/// step; here it takes one, so that the control step's share is all in it (the worst case).
fn motors(c: &mut Criterion) {
    let urdf = urdf();
    let motors = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/motors/tutorial.toml");
    let cases = [
        ("without_motors", RunConfig { urdf: urdf.clone(), ..RunConfig::default() }),
        ("servo_mode", RunConfig { urdf: urdf.clone(), motors: Some(motors.clone()), drive: armscope::config::DriveMode::Pd, ..RunConfig::default() }),
        ("stepper_mode_one_plant_step", RunConfig { urdf: urdf.clone(), motors: Some(motors.clone()), time_step: Some(0.001), ..RunConfig::default() }),
    ];
    let mut group = c.benchmark_group("motors_step");
    for (name, config) in cases {
        let experiment = Experiment::prepare(config).unwrap();
        let model = &*experiment.model;
        let mut data = Data::new(model);
        let mut plant = experiment.make_plant();
        let controller = experiment.controller();
        let mut steppers = experiment.open_loop_steppers();
        let (q0, v0, _) = state();
        let (cmd, cmd_dot) = (vec![0.1; 6], vec![0.2; 6]);
        let (mut u, mut sat, mut limit, mut load_angle, mut lost) = (vec![0.0; 6], vec![false; 6], vec![0.0; 6], vec![0.0; 6], vec![0i64; 6]);
        let mut events = Vec::new();
        group.bench_function(name, |b| {
            b.iter_batched_ref(
                || (q0.clone(), v0.clone()),
                |(q, v)| {
                    forward_kinematics(model, &mut data, q);
                    gravity_and_bias_from_kinematics(model, &mut data, v);
                    controller.compute(q, v, &cmd, &cmd_dot, &data.gravity, armscope::control::controller::ControlOutput { u: &mut u, saturated: &mut sat, limit: &mut limit });
                    match steppers.as_mut() {
                        Some(s) => {
                            s.control_step(&cmd, &cmd_dot, 0.001, q, v, StepperOutput { u: &mut u, limit: &mut limit, saturated: &mut sat, load_angle: &mut load_angle, lost_steps: &mut lost });
                            plant.advance_driven(model, &mut data, &mut u, &mut |h, q, v, u| s.plant_step(h, q, v, u), q, v);
                            s.update(q, 0.0, &mut events);
                            events.clear();
                        }
                        None => plant.advance(model, &mut data, &u, q, v),
                    }
                    black_box(q[0])
                },
                criterion::BatchSize::SmallInput,
            )
        });
    }
    group.finish();
    let mut group = c.benchmark_group("motors_run");
    group.sample_size(10);
    let steppers = RunConfig { urdf: urdf.clone(), motors: Some(motors.clone()), ..RunConfig::default() };
    // the steppers' run takes the plant step the stiffest stepper needs: the same run without
    // motors at that step is what a plant step of it costs without them
    let stepper_plant_step = Experiment::prepare(steppers.clone()).unwrap().plant.time_step().expect("the default plant is discrete");
    for (name, config) in [
        ("default_30s_without_motors", RunConfig { urdf: urdf.clone(), ..RunConfig::default() }),
        ("default_30s_servo_mode", RunConfig { urdf: urdf.clone(), motors: Some(motors.clone()), drive: armscope::config::DriveMode::Pd, ..RunConfig::default() }),
        ("default_30s_without_motors_at_the_steppers_plant_step", RunConfig { urdf: urdf.clone(), time_step: Some(stepper_plant_step), ..RunConfig::default() }),
        ("default_30s_stepper_mode", steppers),
    ] {
        let experiment = Experiment::prepare(config).unwrap();
        group.bench_function(name, |b| b.iter(|| black_box(simulate(&experiment, &mut [], None).unwrap().steps)));
    }
    group.finish();
}

/// A 7-joint serial arm (1 kg, 0.2 m links, axes alternating z, y) with Coulomb friction `friction`
/// on every joint.
fn seven_joint_arm(friction: f64) -> armscope::model::Model {
    let mut urdf = String::from("<robot name=\"seven\"><link name=\"base\"/>");
    for i in 1..=7 {
        let axis = if i % 2 == 1 { "0 0 1" } else { "0 1 0" };
        let parent = if i == 1 { "base".to_string() } else { format!("l{}", i - 1) };
        urdf += &format!(
            "<link name=\"l{i}\"><inertial><origin xyz=\"0 0 0.1\"/><mass value=\"1\"/><inertia ixx=\"0.004\" iyy=\"0.004\" izz=\"0.001\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\
             <joint name=\"j{i}\" type=\"revolute\"><parent link=\"{parent}\"/><child link=\"l{i}\"/><origin xyz=\"0 0 {}\"/><axis xyz=\"{axis}\"/>\
             <limit lower=\"-3\" upper=\"3\" effort=\"50\" velocity=\"3\"/><dynamics damping=\"0.1\" friction=\"{friction}\"/></joint>",
            if i == 1 { 0.0 } else { 0.2 }
        );
    }
    urdf += "</robot>";
    armscope::model::load_urdf_str(&urdf, Path::new("seven.urdf")).unwrap()
}

/// The discrete step on a 7-joint arm without friction, and with friction on every joint: every
/// joint sliding (small F, moving), every joint stuck (F above what acts on it, at rest), and a mix.
/// Issue 22's bar: friction costs at most 30 % more per step.
fn friction(c: &mut Criterion) {
    let q = vec![0.3, -0.5, 0.8, -1.1, 0.6, 0.2, -0.4];
    let moving = vec![0.4, 0.9, -1.2, 0.5, -2.0, 1.0, 0.7];
    let u = vec![0.0; 7];
    let mut group = c.benchmark_group("friction_7_joints");
    for (name, friction, v) in [("none", 0.0, &moving), ("all_sliding", 0.05, &moving), ("all_stuck", 50.0, &vec![0.0; 7]), ("mixed", 2.0, &moving)] {
        let model = seven_joint_arm(friction);
        let mut data = Data::new(&model);
        let mut plant = armscope::plant::DiscretePlant::new(&model, 1e-3, 1);
        group.bench_function(name, |b| plant_step(b, &model, &mut data, &mut plant, &q, v, &u));
    }
    group.finish();
}

criterion_group!(benches, algorithms, trajectory, discrete_step, whole_run, large_trees, motors, friction);
criterion_main!(benches);
