//! Replay benches: one 20 s episode at 30 fps (read from a v3.0 dataset, smoothed, inverse dynamics,
//! verdict; the bar is under 10 ms) and a 500-episode dataset on two threads (the bar is under 10 s),
//! with a row group per episode (as LeRobot records) and all in one (as a conversion writes).
//! The datasets are written here (tests/common/lerobot.rs): SO-101 motions in LeRobot's layout.

#[path = "../common/lerobot.rs"]
#[allow(dead_code)]
mod lerobot;

use armscope::model::load_urdf;
use armscope::motion::{JointMap, Source};
use armscope::replay::{ReplayOptions, Replayer, replay_episodes};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use lerobot::{Spec, Storage, so101_motions as motions};

fn dataset(root: &std::path::Path, episodes: usize) -> Replayer {
    dataset_written(root, episodes, Spec::write_v3)
}

fn dataset_written(root: &std::path::Path, episodes: usize, write: fn(&Spec, &std::path::Path)) -> Replayer {
    let urdf = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/robots/so101.urdf");
    let model = load_urdf(&urdf).unwrap();
    let gripper = &model.joints[5];
    let mut storage = vec![Storage::Degrees { sign: 1.0, offset: 0.0 }; 5];
    storage.push(Storage::Range0To100 { lower: gripper.lower, upper: gripper.upper });
    write(&Spec { fps: 30.0, frames: 601, episodes: (0..episodes).map(motions).collect(), storage, observed: None }, root);
    let source = Source::open(root, None).unwrap();
    let map = JointMap::builtin(source.kind(), &model, &source.read(0, "observation.state").unwrap()).unwrap();
    Replayer::new(model, &ReplayOptions { payload: 0.2, ..Default::default() }, map).unwrap()
}

fn replay(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("so101_3");
    let replayer = dataset(&root, 3);
    let source = Source::open(&root, None).unwrap();
    let episode = source.read(1, "observation.state").unwrap();
    let mut group = c.benchmark_group("replay");
    group.bench_function("episode_20s_30fps_in_memory", |b| b.iter(|| black_box(replayer.replay(&episode).unwrap().verdicts.len())));
    group.bench_function("episode_20s_30fps_read_and_replayed", |b| b.iter(|| black_box(replay_episodes(&replayer, &source, &[1], "observation.state", 1, &|_, _| Ok(())).unwrap().len())));
    group.finish();

    let root = dir.path().join("so101_500");
    let replayer = dataset(&root, 500);
    let source = Source::open(&root, None).unwrap();
    let all = source.episodes();
    let mut group = c.benchmark_group("replay_dataset");
    group.sample_size(10);
    group.bench_function("500_episodes_20s_2_threads", |b| b.iter(|| black_box(replay_episodes(&replayer, &source, &all, "observation.state", 2, &|_, _| Ok(())).unwrap().len())));
    // the same episodes in one row group (a converted or aggregated v3 file): decoded once for all
    let root = dir.path().join("so101_500_one_row_group");
    let replayer = dataset_written(&root, 500, Spec::write_v3_one_row_group);
    group.bench_function("500_episodes_20s_one_row_group_2_threads", |b| {
        b.iter(|| {
            // opened afresh each time, as a run opens it: nothing decoded carried over
            let source = Source::open(&root, None).unwrap();
            black_box(replay_episodes(&replayer, &source, &all, "observation.state", 2, &|_, _| Ok(())).unwrap().len())
        })
    });
    group.finish();
}

criterion_group!(benches, replay);
criterion_main!(benches);
