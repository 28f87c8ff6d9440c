//! `armscope size` over the whole built-in catalogue (56 motors, 22 reductions) on the SmallRobotArm
//! mesh model with 0.5 kg at the tool, its default wave, the parts carried, on all cores — the issue's
//! bar is under 60 s on 2 cores. One sizing per sample (screening every motor × reduction × ratio of
//! every joint, then the verifying simulations):
//!
//!     cargo bench --bench sizing

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;

fn sizing(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::env::set_current_dir(root).unwrap();
    let out = tempfile::tempdir().unwrap();
    let urdf = root.join("assets/smallrobotarm/smallrobotarm.urdf");
    let args: Vec<String> = ["armscope", "size", "--urdf", urdf.to_str().unwrap(), "--payload", "0.5", "--out", out.path().to_str().unwrap()].iter().map(|s| s.to_string()).collect();
    let mut group = c.benchmark_group("size");
    group.sample_size(10);
    group.bench_function("smallrobotarm_whole_catalogue_0.5kg", |b| b.iter(|| assert_eq!(armscope::cli::main_with_args(args.clone()), 0)));
    group.finish();
}

criterion_group!(benches, sizing);
criterion_main!(benches);
