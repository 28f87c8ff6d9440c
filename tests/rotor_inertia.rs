//! Motors' rotors in the model: `<drake:rotor_inertia>` and `<drake:gear_ratio>` (or
//! `<mechanicalReduction>`) give each joint the reflected inertia J_r·N², added to M's diagonal as
//! Drake does. Checked against Drake 1.51 (`tests/fixtures/drake/`, made by its `make_rotor_fixture.py`):
//! the box model with a 5.4e-6 kg·m² rotor on every joint through 15:1 (J1–J3) and 5:1 (J4–J6).

mod common;

use armscope::dynamics::{Data, aba, bias_forces, crba, gravity_forces, kinetic_energy, rnea};
use armscope::model::{Model, load_urdf, load_urdf_str};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn fixture_dir() -> PathBuf {
    common::repo().join("tests/fixtures/drake")
}

fn fixture() -> Value {
    serde_json::from_str(&std::fs::read_to_string(fixture_dir().join("rotor_fixture.json")).unwrap()).unwrap()
}

fn rotor_model() -> Model {
    load_urdf(&fixture_dir().join("smallrobot_arm_rotors.urdf")).unwrap()
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn reflected_inertias_are_the_rotor_inertia_times_the_gear_ratio_squared_as_drake_computes_them() {
    let model = rotor_model();
    let want = numbers(&fixture()["meta"]["reflected_inertia"]);
    for (c, w) in model.armature.iter().zip(&want) {
        assert!((c - w).abs() <= 1e-18, "{c} vs Drake's {w}");
    }
    let ratios: Vec<f64> = model.actuators.iter().map(|a| a.gear_ratio).collect();
    assert_eq!(ratios, [15.0, 15.0, 15.0, 5.0, 5.0, 5.0]);
}

/// M agrees with Drake's CalcMassMatrix within 1e-9 (entries are ~1e-3 to 0.2 kg·m²; without the
/// rotors the diagonal would differ by up to 1.2e-3).
#[test]
fn mass_matrix_with_rotors_matches_drake() {
    let model = rotor_model();
    let bare = load_urdf(&common::box_urdf()).unwrap();
    let (mut data, mut bare_data) = (Data::new(&model), Data::new(&bare));
    for state in fixture()["mass_matrix"].as_array().unwrap() {
        let q = numbers(&state["q"]);
        let m = crba(&model, &mut data, &q).clone();
        let m_bare = crba(&bare, &mut bare_data, &q).clone();
        for (i, row) in state["M"].as_array().unwrap().iter().enumerate() {
            for (j, want) in numbers(row).iter().enumerate() {
                assert!((m[(i, j)] - want).abs() <= 1e-9, "M[{i},{j}] = {} vs Drake's {want}", m[(i, j)]);
            }
            assert!((m[(i, i)] - m_bare[(i, i)] - model.armature[i]).abs() < 1e-15, "the rotor adds J_r·N² to M[{i},{i}] only");
        }
    }
}

/// ABA (which adds the armature to each joint's articulated inertia) agrees with solving the CRBA's
/// M, and RNEA of ABA's q̈ gives back τ: the three algorithms see the same rotors.
#[test]
fn aba_crba_and_rnea_agree_with_rotors() {
    let model = rotor_model();
    let mut data = Data::new(&model);
    let (q, v, tau) = ([0.3, -0.5, 0.8, -1.1, 0.6, 0.2], [0.4, 0.9, -1.2, 0.5, -2.0, 1.0], [1.0, -2.0, 0.5, 0.3, -0.2, 0.1]);
    let m = crba(&model, &mut data, &q).clone();
    let rhs: Vec<f64> = (0..6).map(|i| tau[i] + gravity_forces(&model, &mut Data::new(&model), &q)[i] - bias_forces(&model, &mut Data::new(&model), &q, &v)[i]).collect();
    let want = m.clone().cholesky().unwrap().solve(&nalgebra::DVector::from_row_slice(&rhs));
    let qdd = aba(&model, &mut data, &q, &v, &tau).to_vec();
    for i in 0..6 {
        assert!((qdd[i] - want[i]).abs() <= 1e-10 * want.amax(), "q̈[{i}] {} vs {}", qdd[i], want[i]);
    }
    let back = rnea(&model, &mut data, &q, &v, &qdd).to_vec();
    for i in 0..6 {
        assert!((back[i] - tau[i]).abs() <= 1e-10, "RNEA(ABA) τ[{i}] {} vs {}", back[i], tau[i]);
    }
    // the kinetic energy from the bodies and rotors is ½ q̇ᵀ M q̇ with the rotors on M's diagonal
    let vd = nalgebra::DVector::from_row_slice(&v);
    let from_m = 0.5 * vd.dot(&(&m * &vd));
    let from_bodies = kinetic_energy(&model, &mut data, &q, &v);
    assert!((from_bodies - from_m).abs() <= 1e-12 * from_m, "kinetic energy {from_bodies} vs ½q̇ᵀMq̇ {from_m}");
}

/// A passive run (u = 0) from Drake's start pose reproduces Drake's discrete plant step by step:
/// q and q̇ after each of 400 steps within 1e-9 (the box model without rotors matches Drake to ~1e-12).
#[test]
fn passive_run_with_rotors_matches_drake_step_by_step() {
    let f = fixture();
    let q0: Vec<String> = numbers(&f["meta"]["q0"]).iter().map(|x| format!("{x:?}")).collect();
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("trace.csv");
    let urdf = fixture_dir().join("smallrobot_arm_rotors.urdf");
    let code = common::armscope(&[
        "run", "--urdf", urdf.to_str().unwrap(), "--q0", &q0.join(","), "--kp", "0", "--kd", "0", "--no-ff", "--duration", "0.4", "--quiet",
        "--trace", trace.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    let table = common::read_csv(&trace);
    let run = f["passive_run"].as_array().unwrap();
    assert_eq!(table.rows.len(), run.len() + 1, "a row per step, the first the initial state");
    let (mut worst_q, mut worst_v): (f64, f64) = (0.0, 0.0);
    for (k, drake) in run.iter().enumerate() {
        let row = &table.rows[k + 1];
        for (i, (q, v)) in numbers(&drake["q"]).iter().zip(numbers(&drake["v"])).enumerate() {
            let (q_ours, v_ours) = (row[table.col(&format!("q{}", i + 1))], row[table.col(&format!("qd{}", i + 1))]);
            worst_q = worst_q.max((q_ours - q).abs());
            worst_v = worst_v.max((v_ours - v).abs());
            assert!((q_ours - q).abs() <= 1e-9 && (v_ours - v).abs() <= 1e-9, "step {}: J{} q {q_ours} vs {q}, q̇ {v_ours} vs {v}", k + 1, i + 1);
        }
    }
    eprintln!("largest difference from Drake over 400 steps: q {worst_q:.1e} rad, q̇ {worst_v:.1e} rad/s");
    // the rotors matter: the same run without them leaves Drake's path
    let bare_trace = dir.path().join("bare.csv");
    let code = common::armscope(&[
        "run", "--urdf", common::box_urdf().to_str().unwrap(), "--q0", &q0.join(","), "--kp", "0", "--kd", "0", "--no-ff", "--duration", "0.4", "--quiet",
        "--trace", bare_trace.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    let bare = common::read_csv(&bare_trace);
    let last = run.len();
    let drift = (bare.rows[last][bare.col("q2")] - numbers(&run[last - 1]["q"])[1]).abs();
    assert!(drift > 1e-4, "without rotors J2 ends {drift} rad from Drake's (expected a visible difference)");
}

/// `<mechanicalReduction>` is the ratio where no `<drake:gear_ratio>` is given; bad values are errors
/// naming the transmission and the tag.
#[test]
fn mechanical_reduction_is_the_ratio_without_drake_gear_ratio_and_bad_values_are_named() {
    let urdf = |actuator: &str| {
        format!(
            r#"<robot name="t" xmlns:drake="http://drake.mit.edu"><link name="world"/><link name="a"><inertial><mass value="1"/><origin xyz="0.1 0 0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
<joint name="A" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="7" velocity="1"/></joint>
<transmission name="ta"><joint name="A"/><actuator name="ma">{actuator}</actuator></transmission></robot>"#
        )
    };
    let model = load_urdf_str(&urdf(r#"<mechanicalReduction>10</mechanicalReduction><drake:rotor_inertia value="2e-6"/>"#), Path::new("t.urdf")).unwrap();
    assert_eq!(model.actuators[0].gear_ratio, 10.0);
    assert!((model.armature[0] - 2e-4).abs() < 1e-18);
    let model = load_urdf_str(&urdf(r#"<mechanicalReduction>10</mechanicalReduction><drake:gear_ratio value="20"/><drake:rotor_inertia value="1e-6"/>"#), Path::new("t.urdf")).unwrap();
    assert_eq!(model.actuators[0].gear_ratio, 20.0, "Drake's own tag wins");
    for (bad, words) in [(r#"<drake:rotor_inertia value="-1"/>"#, "rotor_inertia value='-1'"), (r#"<drake:gear_ratio value="0"/>"#, "gear_ratio value='0'"), (r#"<drake:gear_ratio/>"#, "no value")] {
        let err = load_urdf_str(&urdf(bad), Path::new("t.urdf")).unwrap_err().to_string();
        assert!(err.contains("transmission 'ta'") && err.contains(words), "{err}");
    }
}
