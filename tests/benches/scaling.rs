//! How recording cost grows with the simulated duration: the default run with both files for 30 s,
//! 10 min and 1 h, each in a fresh process of its own (this program runs itself with `--one
//! SECONDS`), reporting wall time, bytes per simulated second of each file, and the process's peak
//! resident memory (VmHWM). Linear growth shows as constant bytes/s and wall/s, and a flat peak.
//!
//!     cargo bench --bench scaling                 # 30 s, 600 s, 3600 s
//!     cargo bench --bench scaling -- 30 300       # other durations
//!     cargo bench --bench scaling -- ros2 30 300  # the MCAP in ROS 2's encoding

use armscope::runner::{Outputs, run_experiment};
use armscope::config::RunConfig;
use armscope::experiment::Experiment;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Peak resident memory of this process so far, MB (Linux).
fn peak_memory_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kb = status.lines().find_map(|l| l.strip_prefix("VmHWM:")).and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok());
    kb.map_or(f64::NAN, |kb| kb / 1024.0)
}

/// One run, in this process: prints `seconds wall rrd_bytes mcap_bytes peak_mb`.
fn one(seconds: f64, ros2: bool) {
    armscope::allocator::return_freed_memory_soon();
    let dir = tempfile::tempdir().unwrap();
    let urdf = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/smallrobot_arm.urdf");
    let experiment = Experiment::prepare(RunConfig { urdf, duration: seconds, ..RunConfig::default() }).unwrap();
    let (rrd, mcap) = (dir.path().join("run.rrd"), dir.path().join("run.mcap"));
    let started = Instant::now();
    let mcap_encoding = if ros2 { armscope::recorder::McapEncoding::Ros2 } else { armscope::recorder::McapEncoding::Foxglove };
    let outputs = Outputs { name: "scaling".into(), rrd: Some(rrd.clone()), mcap: Some(mcap.clone()), mcap_encoding, ..Outputs::default() };
    run_experiment(&experiment, outputs, None).unwrap();
    let wall = started.elapsed().as_secs_f64();
    let size = |p: &Path| std::fs::metadata(p).unwrap().len();
    println!("{seconds} {wall} {} {} {}", size(&rrd), size(&mcap), peak_memory_mb());
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).filter(|a| a != "--bench").collect();
    let ros2 = args.first().is_some_and(|a| a == "ros2");
    if ros2 {
        args.remove(0);
    }
    if let [flag, seconds] = &args[..] {
        if flag == "--one" {
            one(seconds.parse().unwrap(), ros2);
            return;
        }
    }
    let durations: Vec<f64> = if args.is_empty() { vec![30.0, 600.0, 3600.0] } else { args.iter().filter_map(|a| a.parse().ok()).collect() };
    println!("| simulated | wall | wall per simulated s | .rrd | .rrd per simulated s | .mcap | .mcap per simulated s | peak memory |");
    println!("|---|---|---|---|---|---|---|---|");
    for seconds in durations {
        let mut command = Command::new(std::env::current_exe().unwrap());
        if ros2 {
            command.arg("ros2");
        }
        let out = command.args(["--one", &seconds.to_string()]).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8_lossy(&out.stdout);
        let v: Vec<f64> = text.split_whitespace().map(|x| x.parse().unwrap()).collect();
        let (wall, rrd, mcap, peak) = (v[1], v[2], v[3], v[4]);
        println!(
            "| {seconds} s | {wall:.2} s | {:.2} ms | {:.0} MB | {:.3} MB | {:.0} MB | {:.3} MB | {peak:.0} MB |",
            wall / seconds * 1e3,
            rrd / 1e6,
            rrd / seconds / 1e6,
            mcap / 1e6,
            mcap / seconds / 1e6
        );
    }
}
