//! `armscope run` outputs: the tutorial CSV, the JSON summary, position limits in a whole run.

mod common;

use common::{armscope, read_csv};
use serde_json::Value;

#[test]
fn tutorial_csv_has_the_initial_state_and_one_row_per_print_interval() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("out.csv");
    let trace = dir.path().join("trace.csv");
    assert_eq!(armscope(&["run", "--quiet", "--duration", "3", "--print-every", "0.5", "--csv", csv.to_str().unwrap(), "--trace", trace.to_str().unwrap()]), 0);
    let table = read_csv(&csv);
    assert_eq!(table.header, ["t", "q1", "q2", "q3", "q4", "q5", "q6", "x", "y", "z"]);
    let times: Vec<f64> = table.column("t");
    assert_eq!(times, vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]);
    assert_eq!(&table.rows[0][1..7], &[0.0; 6], "first row is the initial state");
    assert_eq!(&table.rows[0][7..], &[0.62, 0.0, 0.26], "tool at q = 0");
    // every value in a row belongs to the same instant: the trace row at that step holds the same numbers
    let full = read_csv(&trace);
    for row in &table.rows {
        let k = (row[0] / 0.001).round() as usize;
        for (name, value) in table.header.iter().zip(row) {
            assert_eq!(full.rows[k][full.col(name)], *value, "{name} at t = {}", row[0]);
        }
    }
}

#[test]
fn summary_json_holds_the_console_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("summary.json");
    let trace = dir.path().join("trace.csv");
    assert_eq!(armscope(&["run", "--quiet", "--duration", "4", "--summary-json", json.to_str().unwrap(), "--trace", trace.to_str().unwrap()]), 0);
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let s = &doc["summary"];
    assert_eq!(s["status"]["state"], "completed");
    assert_eq!(s["steps"], 4000);
    assert_eq!(s["error_window_start"], 2.0);
    // recompute the statistics from the per-step trace
    let t = read_csv(&trace);
    for j in 0..6 {
        let (q, cmd, u) = (t.column(&format!("q{}", j + 1)), t.column(&format!("cmd{}", j + 1)), t.column(&format!("u{}", j + 1)));
        let window: Vec<f64> = (2000..=4000).map(|k| (cmd[k] - q[k]).abs()).collect();
        let max = window.iter().cloned().fold(0.0, f64::max);
        let rms = (window.iter().map(|e| e * e).sum::<f64>() / window.len() as f64).sqrt();
        assert!((s["max_abs_error"][j].as_f64().unwrap() - max).abs() < 1e-12);
        assert!((s["rms_error"][j].as_f64().unwrap() - rms).abs() < 1e-12);
        let effort = [8.0, 12.0, 8.0, 5.0, 3.0, 1.5][j];
        // a clipped torque sits exactly at the limit
        let saturated = (0..4000).filter(|&k| u[k].abs() == effort).count();
        let pct = s["saturation_percent"][j].as_f64().unwrap();
        assert!((pct - 100.0 * saturated as f64 / 4000.0).abs() < 1e-9, "J{}: {pct} %", j + 1);
        // and over the control steps from t = 2 s on
        let after = (2000..4000).filter(|&k| u[k].abs() == effort).count();
        let pct_after = s["saturation_after_settle_percent"][j].as_f64().unwrap();
        assert!((pct_after - 100.0 * after as f64 / 2000.0).abs() < 1e-9, "J{}: {pct_after} % after 2 s", j + 1);
    }
    // the words: saturation all at the start is the catching up, not the motion's demand
    let mut summary: armscope::summary::Summary = serde_json::from_value(s.clone()).unwrap();
    summary.chatter_percent = vec![0.0; 6];
    summary.saturation_percent[0] = 5.0;
    summary.saturation_after_settle_percent[0] = Some(0.1);
    let verdict = summary.saturation_verdicts().into_iter().find(|v| v.starts_with("J1:")).unwrap();
    assert!(verdict.contains("catching up with the command at the start"), "{verdict}");
    summary.saturation_after_settle_percent[0] = Some(3.0);
    let verdict = summary.saturation_verdicts().into_iter().find(|v| v.starts_with("J1:")).unwrap();
    assert!(verdict.contains("real torque demand"), "{verdict}");
    assert!(s["tool_range"]["x"]["max"].as_f64().unwrap() >= 0.62 - 1e-12);
    assert_eq!(doc["gains"]["source"], "tutorial");
}

#[test]
fn a_joint_commanded_past_its_limit_stops_there_and_is_counted() {
    // J2's limit is ±2.4435 rad; command 3 rad
    for plant in [&["--dt", "0.001"][..], &["--time-step", "0"][..]] {
        let dir = tempfile::tempdir().unwrap();
        let trace = dir.path().join("trace.csv");
        let json = dir.path().join("s.json");
        let mut args = vec!["run", "--quiet", "--duration", "3", "--test-joint", "J2", "--test-angle", "3.0", "--kp", "400", "--kd", "20"];
        args.extend_from_slice(plant);
        args.extend_from_slice(&["--trace", trace.to_str().unwrap(), "--summary-json", json.to_str().unwrap()]);
        assert_eq!(armscope(&args), 0);
        let q2 = read_csv(&trace).column("q2");
        let max = q2.iter().cloned().fold(f64::MIN, f64::max);
        assert!(max <= 2.4435, "{plant:?}: J2 reached {max}");
        assert!(max > 2.4435 - 1e-6, "{plant:?}: J2 should reach its limit, got {max}");
        let doc: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let hits = doc["summary"]["limit_hits"][1].as_u64().unwrap();
        assert!(hits > 100, "{plant:?}: J2 limit hits {hits}");
        assert_eq!(doc["summary"]["limit_hits"][0], 0);
    }
}

#[test]
fn sub_stepped_plant_converges_to_the_continuous_plant() {
    // Semi-implicit Euler is first order: ten 0.1 ms plant steps per 1 ms control period must land
    // closer to the continuous plant (same held torques) than one 1 ms step does. Over 0.3 s, before
    // the unstable loop amplifies round-off.
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| {
        let path = dir.path().join(name);
        let mut args = vec!["run", "--quiet", "--duration", "0.3", "--trace", path.to_str().unwrap()];
        args.extend_from_slice(extra);
        assert_eq!(armscope(&args), 0);
        read_csv(&path)
    };
    let continuous = run("c.csv", &["--time-step", "0", "--rtol", "1e-10"]);
    let coarse = run("h1.csv", &[]);
    let fine = run("h01.csv", &["--time-step", "0.0001"]);
    let max_diff = |a: &common::Table| {
        (1..=6)
            .flat_map(|j| {
                let name = format!("q{j}");
                a.column(&name).into_iter().zip(continuous.column(&name)).map(|(x, y)| (x - y).abs()).collect::<Vec<_>>()
            })
            .fold(0.0, f64::max)
    };
    let (e_coarse, e_fine) = (max_diff(&coarse), max_diff(&fine));
    assert!(e_fine < 0.5 * e_coarse, "0.1 ms plant error {e_fine:e} vs 1 ms plant error {e_coarse:e}");
}
