//! Whole runs through `armscope run --trace` against Drake's per-step records in
//! `tests/fixtures/reference/steps/`. The reference README: an independent implementation of the same
//! discrete update stays within 3e-9 rad of the clean runs over 10 s (the loop is unstable, so
//! round-off grows), hence the 1e-6 bound; continuous integrations agree to ~1e-8 rad until ~2 s,
//! hence 1e-5 over the first 2 s.

mod common;

use common::{Table, armscope, read_csv, read_csv_gz, reference};

fn trace(args: &[&str]) -> Table {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("trace.csv");
    let mut argv = vec!["run", "--quiet", "--trace", path.to_str().unwrap()];
    argv.extend_from_slice(args);
    assert_eq!(armscope(&argv), 0, "armscope run {args:?}");
    read_csv(&path)
}

/// max over rows (t ≤ until) and joints of |q − q_ref|; rows are matched by step index.
fn max_q_diff(ours: &Table, theirs: &Table, until: f64) -> (f64, usize) {
    let mut worst = (0.0, 0);
    let rows = theirs.rows.len().min(ours.rows.len());
    for k in 0..rows {
        let t = theirs.rows[k][theirs.col("t")];
        if t > until + 1e-12 {
            break;
        }
        // rows align by step index (the reference's t carries ~1e-12 of its own rounding)
        assert!((ours.rows[k][ours.col("t")] - t).abs() < 1e-9, "row {k}: time {} vs {t}", ours.rows[k][0]);
        for j in 1..=6 {
            let name = format!("q{j}");
            let d = (ours.rows[k][ours.col(&name)] - theirs.rows[k][theirs.col(&name)]).abs();
            if d > worst.0 {
                worst = (d, k);
            }
        }
    }
    worst
}

fn check_trace_columns(ours: &Table) {
    let expected = armscope::recorder::Trace::header(6);
    assert_eq!(ours.header, expected);
}

#[test]
fn default_wave_matches_drake_discrete_plant_over_10_s() {
    let theirs = read_csv_gz(&reference("steps/default_10s_clean.csv.gz"));
    let ours = trace(&["--duration", "10"]);
    check_trace_columns(&ours);
    assert_eq!(ours.rows.len(), theirs.rows.len(), "one row per step plus the final state");
    let (d, k) = max_q_diff(&ours, &theirs, 10.0);
    assert!(d <= 1e-6, "max |Δq| = {d:e} at step {k}");
    // the first step's torque, gravity and tool position agree to round-off
    for name in ["u1", "u2", "u3", "u4", "u5", "u6", "tau_g2", "tau_g3", "x", "y", "z"] {
        let (a, b) = (ours.rows[0][ours.col(name)], theirs.rows[0][theirs.col(name)]);
        assert!((a - b).abs() < 1e-12, "{name} at t=0: {a} vs {b}");
    }
}

#[test]
fn no_feed_forward_matches_drake_over_5_s() {
    let theirs = read_csv_gz(&reference("steps/noff_5s_clean.csv.gz"));
    let ours = trace(&["--duration", "5", "--no-ff"]);
    assert_eq!(ours.rows.len(), theirs.rows.len());
    let (d, k) = max_q_diff(&ours, &theirs, 5.0);
    assert!(d <= 1e-6, "max |Δq| = {d:e} at step {k}");
}

#[test]
fn continuous_plant_matches_drake_rk3_over_first_2_s() {
    let theirs = read_csv_gz(&reference("steps/default_10s_continuous.csv.gz"));
    let ours = trace(&["--duration", "2", "--time-step", "0"]);
    let (d, k) = max_q_diff(&ours, &theirs, 2.0);
    assert!(d <= 1e-5, "max |Δq| = {d:e} at step {k}");
    // the same plant chosen by name
    let by_name = trace(&["--duration", "0.5", "--integrator", "continuous"]);
    let (d, _) = max_q_diff(&by_name, &theirs, 0.5);
    assert!(d <= 1e-5, "--integrator continuous: max |Δq| = {d:e}");
}

#[test]
fn static_run_holds_the_start_pose_exactly_for_10_s() {
    let ours = trace(&["--duration", "10", "--static"]);
    assert_eq!(ours.rows.len(), 10001);
    for row in &ours.rows {
        for j in 1..=6 {
            let q = row[ours.col(&format!("q{j}"))];
            assert!(q.abs() <= 1e-12, "t = {}: q{j} = {q}", row[0]);
        }
    }
}

#[test]
fn trace_rows_are_consistent_instants() {
    // u is computed from the row's own q, qd, cmd and tau_g: u = kp(cmd − q) + kd(cmd_dot − qd) − tau_g, clipped
    let ours = trace(&["--duration", "0.2"]);
    let kp = armscope::control::gains::TUTORIAL_KP;
    let kd = armscope::control::gains::TUTORIAL_KD;
    let effort = [8.0, 12.0, 8.0, 5.0, 3.0, 1.5];
    for row in &ours.rows {
        for j in 0..6 {
            let c = |n: &str| row[ours.col(&format!("{n}{}", j + 1))];
            let raw = kp[j] * (c("cmd") - c("q")) + kd[j] * (c("cmd_dot") - c("qd")) - c("tau_g");
            assert!((c("u") - raw.clamp(-effort[j], effort[j])).abs() < 1e-12);
        }
    }
}
