//! `armscope envelope`: the torque a motion needs, by inverse dynamics, checked against physics
//! that can be worked out by hand, and the sweep's outputs.

mod common;

use armscope::config::RunConfig;
use armscope::dynamics::{Data, gravity_forces};
use armscope::control::demand::required_torque;
use armscope::diagnose::envelope::sweep;
use armscope::model::load_urdf;
use armscope::control::trajectory::{Trajectory, Wave};
use common::{armscope, box_urdf};

#[test]
fn a_slow_wave_needs_the_gravity_torque_and_j1_needs_grow_with_frequency() {
    let model = load_urdf(&box_urdf()).unwrap();
    // quasi-static: the need is the largest |τ_g| along the commanded poses
    let slow = Wave { amplitude_rad: 0.3, omega: 1e-3 };
    let need = required_torque(&model, &slow, 2.0, 0.001);
    let mut data = Data::new(&model);
    let (mut q, mut qd) = (vec![0.0; 6], vec![0.0; 6]);
    let mut gravity_peak = vec![0.0f64; 6];
    for k in 0..=2000 {
        slow.sample(k as f64 * 0.001, &mut q, &mut qd);
        for (p, g) in gravity_peak.iter_mut().zip(gravity_forces(&model, &mut data, &q)) {
            *p = p.max(g.abs());
        }
    }
    for j in 0..6 {
        assert!((need[j] - gravity_peak[j]).abs() < 1e-3, "J{}: {} vs τ_g {}", j + 1, need[j], gravity_peak[j]);
    }
    // J1's axis is vertical: its need is inertial, growing with ω (about ω² for a small, slow wave)
    let j1 = |omega: f64| required_torque(&model, &Wave { amplitude_rad: 0.2, omega }, 2.0 * std::f64::consts::PI / omega, 0.001)[0];
    let (a, b) = (j1(1.0), j1(2.0));
    assert!(b > 3.0 * a && b < 5.0 * a, "J1 need at ω = 1: {a}, ω = 2: {b}");
    // a payload at the tool adds its weight times its lever arm to J2 at the stretched pose
    let heavy = model.clone().with_payload(0.5);
    let still = Wave { amplitude_rad: 0.0, omega: 1.0 };
    let (base, loaded) = (required_torque(&model, &still, 0.1, 0.001), required_torque(&heavy, &still, 0.1, 0.001));
    assert!((loaded[1] - base[1] - 0.5 * 9.81 * 0.62).abs() < 1e-9, "J2: {} → {}", base[1], loaded[1]);
}

#[test]
fn beyond_the_envelope_the_stable_loop_saturates_for_real_and_inside_it_does_not() {
    let model = load_urdf(&box_urdf()).unwrap();
    let config = RunConfig { urdf: box_urdf(), kd: Some(vec![12.0, 14.1254, 0.4297, 0.0016, 0.3733, 0.1]), ..RunConfig::default() };
    let env = sweep(&config, &model, &[0.5, 12.0], &[10.0, 60.0], 2).unwrap();
    let inside = env.cell(0, 0);
    let outside = env.cell(1, 1);
    for j in 0..6 {
        assert!(inside.required[j] < env.effort[j], "J{} needs {} at a slow small wave", j + 1, inside.required[j]);
        assert!(inside.chatter_percent[j] < 0.5, "no chatter with stable gains: J{} {}", j + 1, inside.chatter_percent[j]);
    }
    let over: Vec<usize> = (0..6).filter(|&j| outside.required[j] > env.effort[j]).collect();
    assert!(!over.is_empty(), "a fast, large wave exceeds some motor: {:?}", outside.required);
    for &j in &over {
        assert!(outside.saturation_percent[j] > 1.0, "J{} needs {} > {} and saturates in simulation", j + 1, outside.required[j], env.effort[j]);
    }
}

#[test]
fn envelope_command_writes_heatmaps_recording_and_table() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("env");
    assert_eq!(armscope(&["envelope", "--freqs", "0.5,2,8", "--amps", "10,30", "--payload", "0.2", "--out", out.to_str().unwrap()]), 0);
    for j in 1..=6 {
        let png = std::fs::read(out.join(format!("envelope_J{j}.png"))).unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }
    let md = std::fs::read_to_string(out.join("envelope.md")).unwrap();
    assert!(md.contains("| J2 | 12 |") && md.contains("margin"), "{md}");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("envelope.json")).unwrap()).unwrap();
    assert_eq!(json["cells"].as_array().unwrap().len(), 6);
    assert_eq!(json["payload_kg"], 0.2);
    assert!(out.join("envelope.rrd").metadata().unwrap().len() > 0);
}

/// Without motors a cell's demand is its need over the constant effort; with `--motors` it is the
/// need over what the drive gives at the speed of that instant — driving at most its torque at rest
/// (the effort, η·N·T), braking at most N·T/η_b (the gear's friction helps hold a back-driving
/// load: the effort/(η·η_b), 1/0.81 of it on the tutorial's 90 % gearboxes) — so never below the
/// need over that, and at the need over the limit at speed for a fast wave.
#[test]
fn the_demand_is_the_need_over_the_limit_at_speed() {
    let model = armscope::model::load_urdf(&common::box_urdf()).unwrap();
    let plain = RunConfig { urdf: common::box_urdf(), ..RunConfig::default() };
    let env = sweep(&plain, &model, &[0.5, 8.0], &[30.0], 2).unwrap();
    for c in &env.cells {
        for j in 0..6 {
            assert!((c.demand[j] - c.required[j] / env.effort[j]).abs() <= 1e-12 * c.demand[j].max(1.0));
        }
    }
    let motors = RunConfig { motors: Some(common::repo().join("assets/motors/tutorial.toml")), drive: armscope::config::DriveMode::Pd, ..plain };
    let env = sweep(&motors, &model, &[0.5, 8.0], &[30.0], 2).unwrap();
    for c in &env.cells {
        for j in 0..6 {
            assert!(c.demand[j] >= 0.81 * c.required[j] / env.effort[j] - 1e-12, "J{} at ω = {}", j + 1, c.freq);
        }
    }
    // at t = 0 of the fast wave (J1 at its top speed, 4.2 rad/s: its motor at 10 rev/s) the demand is
    // at least the need of that instant over the limit at that speed
    let experiment = armscope::experiment::Experiment::prepare(RunConfig { freq: 8.0, amp_deg: 30.0, ..motors.clone() }).unwrap();
    let drives = experiment.motors.clone().unwrap();
    let wave = Wave { amplitude_rad: 30f64.to_radians(), omega: 8.0 };
    let (mut q, mut v, mut v1, mut v0) = (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
    wave.sample(1e-5, &mut q, &mut v1);
    wave.sample(-1e-5, &mut q, &mut v0);
    wave.sample(0.0, &mut q, &mut v);
    let a: Vec<f64> = (0..6).map(|j| (v1[j] - v0[j]) / 2e-5).collect();
    let tau = armscope::dynamics::rnea(&experiment.model, &mut Data::new(&experiment.model), &q, &v, &a).to_vec();
    let fast = &env.cells[1];
    for j in 0..6 {
        let need = tau[j] + experiment.model.joints[j].damping * v[j];
        let instant = need.abs() / drives.joints[j].as_ref().unwrap().available(need, v[j]);
        assert!(fast.demand[j] >= instant * (1.0 - 1e-6), "J{}: demand {} below the need at t = 0 over the limit there, {instant}", j + 1, fast.demand[j]);
    }
}
