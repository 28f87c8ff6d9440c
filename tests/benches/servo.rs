//! Servo benches: replaying a 6 s bench log (BAM's explicit step, armscope's exact one; the bar is
//! under 5 ms) and identifying a servo from 8 logs (the bar for 60 real logs is under 60 s on 2 cores). The logs are
//! made here (a known XL330-like servo on BAM's bench, its positions rounded to the encoder): BAM's
//! real logs are not in the repository; `.ci/servo-vs-bam.py` times `armscope identify` on the 8 it
//! can read.

use armscope::actuator::bus_servo::firmware::XL330;
use armscope::actuator::bus_servo::{FrictionModel, ServoFriction, ServoParams};
use armscope::identify::{FitOptions, Space, fit};
use armscope::testbench::synthetic::{Bench, Trajectory, record};
use armscope::testbench::{ReplayOptions, Step, mae};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn servo() -> ServoParams {
    let friction = ServoFriction {
        model: FrictionModel::M6,
        base: 0.01,
        viscous: 0.006,
        stribeck: 0.01,
        stribeck_speed: 0.3,
        stribeck_exponent: 2.0,
        load_motor: 0.25,
        load_external: 0.05,
        load_motor_stribeck: 0.1,
        load_external_stribeck: 0.08,
        load_motor_quad: 0.005,
        load_external_quad: 0.004,
        ..Default::default()
    };
    ServoParams { family: XL330, kt: 0.35, resistance: 2.8, armature: 0.002, q_offset: 0.02, friction, error_gain_ratio: 1.0, max_velocity: f64::INFINITY, supply_resistance: 0.0, motor_voltage_limit: f64::INFINITY, command_delay: 0.0 }
}

fn replay(c: &mut Criterion) {
    let params = servo();
    let log = record(&params, &Bench::default(), Trajectory::SinSin, &ReplayOptions::default());
    let mut group = c.benchmark_group("testbench_6s_log");
    group.bench_function("bam_step", |b| b.iter(|| black_box(mae(&log, &params, &ReplayOptions::default()))));
    group.bench_function("exact_step_5_per_row", |b| b.iter(|| black_box(mae(&log, &params, &ReplayOptions { step: Step::Exact, ..Default::default() }))));
    // what `identify`'s first stage replays: the commands delayed by a fraction of a row, as a
    // fitted delay is (12.3 ms: 2.46 of these 5 ms rows; K-Scale's STS3215 fit 34.9 ms at 10 ms
    // rows), and the state reset every second (200 rows)
    let delayed = ServoParams { command_delay: 0.0123, ..params };
    let windows = ReplayOptions { reset_rows: Some(200), ..Default::default() };
    group.bench_function("bam_step_delayed_windowed", |b| b.iter(|| black_box(mae(&log, &delayed, &windows))));
    group.finish();
}

fn identify(c: &mut Criterion) {
    let params = servo();
    let options = ReplayOptions::default();
    let logs: Vec<_> = [100.0, 400.0].iter().flat_map(|&kp| Trajectory::ALL.map(|t| record(&params, &Bench { kp, ..Default::default() }, t, &options))).collect();
    let mut group = c.benchmark_group("identify");
    group.sample_size(10);
    group.bench_function("m6_8_logs_default_search", |b| b.iter(|| black_box(fit(&Space::new(XL330, FrictionModel::M6, false, false, true), &logs, options, &FitOptions::default(), &|_| {}).unwrap().loss)));
    group.finish();
}

criterion_group!(benches, replay, identify);
criterion_main!(benches);
