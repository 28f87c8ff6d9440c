//! One state's collision check (every active pair: broad phase, exact distance within 5 cm, contact
//! depth inside) on the box model (boxes) and the SmallRobotArm mesh model (STL meshes), at a fixed
//! set of random states within the limits — what `run --collisions` adds per control step:
//!
//!     cargo bench --bench collisions

use armscope::collision::{CollisionData, Collisions, StateCollisions, check_state};
use armscope::dynamics::{Data, forward_kinematics, frame_pose};
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
        let states: Vec<Vec<f64>> = (0..64).map(|_| model.joints.iter().map(|j| j.lower.max(-3.14) + (j.upper.min(3.14) - j.lower.max(-3.14)) * uniform()).collect()).collect();
        let mut data = Data::new(&model);
        let mut cd = CollisionData::new(&collisions.shapes);
        let mut out = StateCollisions::default();
        let mut k = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                k = (k + 1) % states.len();
                forward_kinematics(&model, &mut data, &states[k]);
                check_state(&model, &collisions.shapes, &collisions.pairs, &collisions.world, &mut cd, |f| frame_pose(&model, &data, f), 0.05, &mut out);
                black_box(out.close.len())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, checks);
criterion_main!(benches);
