//! One state's collision check (every active pair: broad phase, exact distance within 5 cm, contact
//! depth inside) on the box model (boxes) and the SmallRobotArm mesh model (STL meshes), at a fixed
//! set of random states within the limits — what `run --collisions` adds per control step:
//!
//!     cargo bench --bench collisions

use armscope::collision::{CollisionData, Collisions, StateCollisions, check_state};
use armscope::dynamics::{Data, forward_kinematics};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn checks(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut group = c.benchmark_group("collision_check");
    for (name, urdf) in [("box_model", "assets/smallrobot_arm.urdf"), ("smallrobotarm_meshes", "assets/smallrobotarm/smallrobotarm.urdf")] {
        let model = armscope::model::load_urdf(&root.join(urdf)).unwrap();
        let collisions = Collisions::new(&model, None, &Default::default()).unwrap();
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let states: Vec<Vec<f64>> = (0..64).map(|_| model.joints.iter().map(|j| j.lower.max(-std::f64::consts::PI) + (j.upper.min(std::f64::consts::PI) - j.lower.max(-std::f64::consts::PI)) * uniform()).collect()).collect();
        let mut data = Data::new(&model);
        let mut cd = CollisionData::new(&collisions.shapes);
        let mut out = StateCollisions::default();
        let mut k = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                k = (k + 1) % states.len();
                forward_kinematics(&model, &mut data, &states[k]);
                check_state(&model, &collisions.shapes, &collisions.pairs, &collisions.world, &mut cd, &data.body_pose, 0.05, &mut out);
                black_box(out.close.len())
            })
        });
    }
    group.finish();
}

/// The bar: a run checked at every control step against the same run unchecked (no
/// recorders). The box model's default wave (3 s), the SmallRobotArm mesh model's (3 s), and the
/// Panda (meshes, its SRDF) on a ±90° wave when example-robot-data is installed where the CI puts it
/// (ARMSCOPE_PANDA_URDF overrides).
fn runs(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut group = c.benchmark_group("run_3s");
    group.sample_size(10);
    let panda = std::env::var("ARMSCOPE_PANDA_URDF").map(std::path::PathBuf::from).unwrap_or_else(|_| {
        std::path::PathBuf::from(std::env::var("HOME").unwrap_or_default()).join(".cache/armscope-corpus-venv/lib/python3.11/site-packages/cmeel.prefix/share/example-robot-data/robots/panda_description/urdf/panda.urdf")
    });
    let mut models = vec![("box_model", root.join("assets/smallrobot_arm.urdf"), 30.0), ("smallrobotarm_meshes", root.join("assets/smallrobotarm/smallrobotarm.urdf"), 30.0)];
    if panda.is_file() {
        models.push(("panda", panda, 90.0));
    }
    for (name, urdf, amp) in models {
        for checked in [false, true] {
            let config = armscope::config::RunConfig { urdf: urdf.clone(), duration: 3.0, amp_deg: amp, collisions: checked, ..Default::default() };
            let experiment = armscope::experiment::Experiment::prepare(config).unwrap();
            group.bench_function(format!("{name}/{}", if checked { "checked" } else { "unchecked" }), |b| b.iter(|| black_box(armscope::sim::simulate(&experiment, &mut [], None).unwrap().peak_abs_torque.len())));
        }
    }
    group.finish();
}

criterion_group!(benches, checks, runs);
criterion_main!(benches);
