//! Cost of recording: the whole 30 s default run with no files, with the .rrd, with the .mcap (in
//! Foxglove's encoding and in ROS 2's) and with both (as `armscope run` writes them: each recorder
//! on its own thread). The recording
//! overhead per step is (t_recorded − t_bare) / 30 000. Reference: the tutorial takes 1.6 s for the
//! same run while recording only every 0.5 s.

use armscope::config::RunConfig;
use armscope::experiment::Experiment;
use armscope::recorder::{McapOptions, McapRecorder, Recorder, RerunOptions, RerunRecorder, Ros2McapRecorder, Threaded};
use armscope::sim::simulate;
use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;
use std::time::Duration;

// as the armscope binary (src/main.rs)
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Which MCAP, if any.
#[derive(Clone, Copy, PartialEq)]
enum Mcap {
    None,
    Foxglove,
    Ros2,
}

fn run(experiment: &Experiment, dir: &Path, rrd: bool, mcap: Mcap) -> usize {
    let mut recorders: Vec<Box<dyn Recorder>> = Vec::new();
    let mut threaded = Threaded::new(Duration::from_millis(20));
    if rrd {
        let options = RerunOptions { file: Some(dir.join("bench.rrd")), live: None, name: "bench".into(), compress: false };
        threaded = threaded.with(RerunRecorder::new(options));
    }
    let options = McapOptions { file: Some(dir.join("bench.mcap")), live: None, compress: false };
    match mcap {
        Mcap::None => {}
        Mcap::Foxglove => threaded = threaded.with(McapRecorder::new(options)),
        Mcap::Ros2 => threaded = threaded.with(Ros2McapRecorder::new(options)),
    }
    if !threaded.is_empty() {
        recorders.push(Box::new(threaded));
    }
    let mut refs: Vec<&mut dyn Recorder> = recorders.iter_mut().map(|r| r.as_mut() as &mut dyn Recorder).collect();
    simulate(experiment, &mut refs, None).unwrap().steps
}

fn recording(c: &mut Criterion) {
    armscope::allocator::return_freed_memory_soon();
    let urdf = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/smallrobot_arm.urdf");
    let experiment = Experiment::prepare(RunConfig { urdf, ..RunConfig::default() }).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut group = c.benchmark_group("run_30s");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(8));
    for (name, rrd, mcap) in [("no_files", false, Mcap::None), ("rrd", true, Mcap::None), ("mcap", false, Mcap::Foxglove), ("mcap_ros2", false, Mcap::Ros2), ("rrd_and_mcap", true, Mcap::Foxglove), ("rrd_and_mcap_ros2", true, Mcap::Ros2)] {
        group.bench_function(name, |b| b.iter(|| run(&experiment, dir.path(), rrd, mcap)));
    }
    group.finish();
    // file size per simulated second, printed for the notes
    for (label, mcap) in [("", Mcap::Foxglove), (" (ROS 2)", Mcap::Ros2)] {
        run(&experiment, dir.path(), true, mcap);
        for f in ["bench.rrd", "bench.mcap"] {
            let bytes = std::fs::metadata(dir.path().join(f)).unwrap().len();
            println!("{f}{label}: {:.2} MB per simulated second", bytes as f64 / 30.0 / 1e6);
        }
    }
}

criterion_group!(benches, recording);
criterion_main!(benches);
