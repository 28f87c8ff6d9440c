//! Telling torque demand from numerical chatter: the chatter statistic against Drake's reference
//! run, and `armscope analyze` against the reference README (spectral radius ≈ 3.58 at q = 0 with
//! the tutorial's gains at 1 kHz; stable at 10 kHz), with its suggested gains run for real.

mod common;

use common::{armscope, read_csv_gz, reference};
use serde_json::Value;
use std::process::Command;

const EFFORT: [f64; 6] = [8.0, 12.0, 8.0, 5.0, 3.0, 1.5];

/// Chatter % computed from a per-step table of torques, by the definition in the summary.
fn chatter_percent(u: &[Vec<f64>]) -> Vec<f64> {
    let steps = u.len();
    (0..6)
        .map(|j| {
            let flips = (1..steps)
                .filter(|&k| u[k][j] * u[k - 1][j] < 0.0 && (u[k][j].abs() == EFFORT[j] || u[k - 1][j].abs() == EFFORT[j]))
                .count();
            100.0 * flips as f64 / steps as f64
        })
        .collect()
}

#[test]
fn chatter_on_the_reference_default_run_is_at_least_90_percent_on_j2_to_j5_and_zero_on_j1() {
    let table = read_csv_gz(&reference("steps/default_10s_clean.csv.gz"));
    let u: Vec<Vec<f64>> = table.rows.iter().filter(|r| r[table.col("u1")].is_finite()).map(|r| (1..=6).map(|j| r[table.col(&format!("u{j}"))]).collect()).collect();
    let reference_chatter = chatter_percent(&u);
    assert!(reference_chatter[0] < 0.5, "J1 {reference_chatter:?}");
    for j in 1..5 {
        assert!(reference_chatter[j] >= 90.0, "J{} {reference_chatter:?}", j + 1);
    }
    // armscope's own statistic on the same run agrees with the one computed from Drake's torques
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("s.json");
    assert_eq!(armscope(&["run", "--quiet", "--duration", "10", "--summary-json", json.to_str().unwrap()]), 0);
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for j in 0..6 {
        let ours = doc["summary"]["chatter_percent"][j].as_f64().unwrap();
        assert!((ours - reference_chatter[j]).abs() < 0.5, "J{}: {ours} vs Drake's {}", j + 1, reference_chatter[j]);
    }
    // and the console says what it is
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).args(["run", "--duration", "4", "--no-rrd", "--no-mcap"]).current_dir(common::repo()).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("chatter (%)"), "{text}");
    assert!(text.contains("J3: saturated") && text.contains("mostly numerical chatter"), "{text}");
}

fn analyze(args: &[&str]) -> Value {
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).arg("analyze").args(args).arg("--json").current_dir(common::repo()).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn analyze_reports_the_reference_spectral_radius_and_stability() {
    let at_1khz = analyze(&[]);
    let rho = at_1khz["spectral_radius"].as_f64().unwrap();
    assert!((rho - 3.58).abs() <= 0.05, "spectral radius {rho}");
    assert_eq!(at_1khz["stable"], false);
    // the wrist joints drive it
    let p = &at_1khz["participation"];
    assert!(p["J5"].as_f64().unwrap() + p["J4"].as_f64().unwrap() > 0.5, "{p}");
    let largest = at_1khz["largest_stable_dt"].as_f64().unwrap();
    assert!(largest > 1e-4 && largest < 1e-3, "largest stable dt {largest}");
    let at_10khz = analyze(&["--dt", "0.0001"]);
    assert_eq!(at_10khz["stable"], true, "{at_10khz}");
    assert!(at_10khz["spectral_radius"].as_f64().unwrap() < 1.0);
}

#[test]
fn analyze_suggested_gains_run_without_chatter() {
    let doc = analyze(&[]);
    assert!(doc["stable_kd_spectral_radius"].as_f64().unwrap() < 1.0);
    let kd: Vec<String> = doc["stable_kd"].as_array().unwrap().iter().map(|k| format!("{}", k.as_f64().unwrap())).collect();
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("s.json");
    let kd = kd.join(",");
    assert_eq!(armscope(&["run", "--quiet", "--duration", "10", "--kd", &kd, "--summary-json", json.to_str().unwrap()]), 0);
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for j in 0..6 {
        let chatter = s["summary"]["chatter_percent"][j].as_f64().unwrap();
        assert!(chatter < 0.1, "J{} chatter {chatter}% with kd {kd}", j + 1);
    }
}

#[test]
fn gains_stable_along_the_wave_run_the_whole_wave_without_chatter() {
    let doc = analyze(&["--along-command"]);
    assert_eq!(doc["poses"], 13);
    assert!(doc["worst_spectral_radius_over_poses"].as_f64().unwrap() >= doc["spectral_radius"].as_f64().unwrap());
    assert!(doc["stable_kd_spectral_radius"].as_f64().unwrap() < 1.0);
    let kd = doc["stable_kd"].as_array().unwrap().iter().map(|k| format!("{}", k.as_f64().unwrap())).collect::<Vec<_>>().join(",");
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("s.json");
    assert_eq!(armscope(&["run", "--quiet", "--duration", "20", "--kd", &kd, "--summary-json", json.to_str().unwrap()]), 0);
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for j in 0..6 {
        assert!(s["summary"]["chatter_percent"][j].as_f64().unwrap() < 0.1, "J{}", j + 1);
        assert!(s["summary"]["max_abs_error"][j].as_f64().unwrap() < 1e-3, "J{} tracks", j + 1);
    }
}

/// `analyze --motors FILE`: the loop as `run --motors FILE --drive pd` runs it, the rotors' J_r·N²
/// on M's diagonal (1.8e-3 kg·m² behind J1–J3's 15:1 — more than the box model's wrist links). The
/// tutorial's gains chatter J4 on most steps on the tutorial's motors; the derivative gains `analyze
/// --motors --along-command` suggests stop it (under 2 % on every joint: what is left, 1.7 % on J1,
/// is a burst while J2 catches up with the wave's start, 0.45 rad away, saturated at its 8.85 N·m). Without `--motors` the suggestion
/// ignores the rotors and is another one. The gearboxes are made lossless here: the linearization
/// leaves friction out, and the tutorial's 90 % gearboxes' friction (10 % of the motor's torque,
/// as Coulomb friction) holds J4 still where the lossless loop chatters.
#[test]
fn analyze_with_motors_suggests_gains_that_run_the_motors_without_chatter() {
    let dir = tempfile::tempdir().unwrap();
    let tutorial = std::fs::read_to_string(common::repo().join("assets/motors/tutorial.toml")).unwrap();
    assert!(tutorial.contains("efficiency = 0.9"));
    let motors = dir.path().join("lossless.toml");
    std::fs::write(&motors, tutorial.replace("efficiency = 0.9", "efficiency = 1.0")).unwrap();
    let motors = motors.to_str().unwrap();
    let run = |kd: Option<&str>| {
        let dir = tempfile::tempdir().unwrap();
        let json = dir.path().join("s.json");
        let mut args = vec!["run", "--quiet", "--duration", "10", "--motors", motors, "--drive", "pd", "--summary-json", json.to_str().unwrap()];
        if let Some(kd) = kd {
            args.extend(["--kd", kd]);
        }
        assert_eq!(armscope(&args), 0);
        let s: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        (0..6).map(|j| s["summary"]["chatter_percent"][j].as_f64().unwrap()).collect::<Vec<f64>>()
    };
    let tutorial = run(None);
    assert!(tutorial[3] > 50.0, "the tutorial gains chatter J4 on the motors: {tutorial:?}");

    let doc = analyze(&["--motors", motors, "--along-command"]);
    assert!(doc["spectral_radius"].as_f64().unwrap() > 1.0, "the tutorial gains are unstable with the rotors");
    // the report says which friction its linearization leaves out: none on lossless gears, every
    // joint's on the tutorial's 90 % ones
    assert_eq!(doc["friction_left_out"].as_object().unwrap().len(), 0);
    let lossy = analyze(&["--motors", common::repo().join("assets/motors/tutorial.toml").to_str().unwrap()]);
    let left_out = lossy["friction_left_out"].as_object().unwrap();
    assert!(left_out.len() == 6 && left_out["J4"].as_str().unwrap().contains("η 0.9"), "{left_out:?}");
    assert!(doc["stable_kd_spectral_radius"].as_f64().unwrap() < 1.0);
    assert!(doc["run_with_stable_kd"].as_str().unwrap().contains("--motors") && doc["run_with_stable_kd"].as_str().unwrap().contains("--drive pd"));
    let kd: Vec<f64> = doc["stable_kd"].as_array().unwrap().iter().map(|k| k.as_f64().unwrap()).collect();
    let listed = kd.iter().map(|k| format!("{k}")).collect::<Vec<_>>().join(",");
    let suggested = run(Some(&listed));
    assert!(suggested.iter().all(|&c| c < 2.0), "chatter with kd {listed}: {suggested:?}");

    let bare: Vec<f64> = analyze(&["--along-command"])["stable_kd"].as_array().unwrap().iter().map(|k| k.as_f64().unwrap()).collect();
    assert!(kd.iter().zip(&bare).any(|(a, b)| (a - b).abs() > 0.1 * a.abs().max(b.abs())), "with rotors {kd:?}, without {bare:?}");
}
