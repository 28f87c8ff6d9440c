//! Agreement with Drake/Pinocchio on `tests/fixtures/reference/dynamics_fixtures.json`: 21 states of the
//! box model. Drake and Pinocchio agree with each other to ~1e-15 on M, τ_g, C·v, pose and
//! Jacobian and to ~2.5e-11 on q̈, so 1e-9 (absolute; relative for q̈) leaves room only for
//! round-off.

mod common;

use armscope::dynamics::{Data, aba, bias_forces, crba, forward_kinematics, frame_jacobian, frame_pose, gravity_and_bias_from_kinematics, gravity_forces};
use armscope::plant::DiscretePlant;
use armscope::model::{Model, load_urdf};
use nalgebra::DMatrix;
use serde_json::Value;

const TOL: f64 = 1e-9;

fn fixtures() -> Value {
    let path = common::reference("dynamics_fixtures.json");
    serde_json::from_str(&std::fs::read_to_string(&path).expect("fixtures")).expect("json")
}

fn vec_of(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
}

fn mat_of(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().expect("rows").iter().map(vec_of).collect()
}

fn model() -> Model {
    load_urdf(&common::box_urdf()).expect("box model loads")
}

fn assert_close(what: &str, label: &str, got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what} length");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!((g - w).abs() <= tol, "{label}: {what}[{i}] = {g}, reference {w}, |diff| {} > {tol}", (g - w).abs());
    }
}

fn for_each_state(mut check: impl FnMut(&str, &Value)) {
    let f = fixtures();
    let states = f["states"].as_array().expect("states");
    assert_eq!(states.len(), 21, "fixture count");
    for s in states {
        check(s["label"].as_str().unwrap(), s);
    }
}

#[test]
fn mass_matrix_matches_reference() {
    let model = model();
    let mut data = Data::new(&model);
    for_each_state(|label, s| {
        let m = crba(&model, &mut data, &vec_of(&s["q"])).clone();
        for (i, row) in mat_of(&s["M"]).iter().enumerate() {
            let got: Vec<f64> = (0..6).map(|j| m[(i, j)]).collect();
            assert_close(&format!("M row {i}"), label, &got, row, TOL);
        }
    });
}

#[test]
fn gravity_forces_match_reference() {
    let model = model();
    let mut data = Data::new(&model);
    for_each_state(|label, s| {
        let g = gravity_forces(&model, &mut data, &vec_of(&s["q"])).to_vec();
        assert_close("tau_g", label, &g, &vec_of(&s["tau_g"]), TOL);
    });
}

#[test]
fn coriolis_bias_matches_reference() {
    let model = model();
    let mut data = Data::new(&model);
    for_each_state(|label, s| {
        let cv = bias_forces(&model, &mut data, &vec_of(&s["q"]), &vec_of(&s["v"])).to_vec();
        assert_close("Cv", label, &cv, &vec_of(&s["Cv"]), TOL);
        // the combined pass the simulation loop uses gives both at once
        gravity_and_bias_from_kinematics(&model, &mut data, &vec_of(&s["v"]));
        assert_close("tau_g (combined pass)", label, &data.gravity, &vec_of(&s["tau_g"]), TOL);
    });
}

fn assert_relative(what: &str, label: &str, got: &[f64], want: &[f64]) {
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        let scale = w.abs().max(1.0);
        assert!((g - w).abs() <= TOL * scale, "{label}: {what}[{i}] = {g}, reference {w}, relative diff {}", (g - w).abs() / scale);
    }
}

#[test]
fn forward_dynamics_matches_reference_with_and_without_damping() {
    let model = model();
    let mut data = Data::new(&model);
    for_each_state(|label, s| {
        let (q, v, tau) = (vec_of(&s["q"]), vec_of(&s["v"]), vec_of(&s["tau"]));
        let qdd = aba(&model, &mut data, &q, &v, &tau).to_vec();
        assert_relative("qdd_no_damping", label, &qdd, &vec_of(&s["qdd_no_damping"]));
        let damped: Vec<f64> = tau.iter().zip(&v).zip(&model.joints).map(|((t, v), j)| t - j.damping * v).collect();
        let qdd = aba(&model, &mut data, &q, &v, &damped).to_vec();
        assert_relative("qdd_with_damping", label, &qdd, &vec_of(&s["qdd_with_damping"]));
    });
}

#[test]
fn tool_pose_and_jacobian_match_reference() {
    let model = model();
    assert_eq!(model.frames[model.tool_frame].name, "tool_link");
    let mut data = Data::new(&model);
    let mut jac = DMatrix::zeros(6, 6);
    for_each_state(|label, s| {
        forward_kinematics(&model, &mut data, &vec_of(&s["q"]));
        let pose = frame_pose(&model, &data, model.tool_frame);
        assert_close("tool_pos_W", label, pose.translation.as_slice(), &vec_of(&s["tool_pos_W"]), TOL);
        for (i, row) in mat_of(&s["tool_R_W"]).iter().enumerate() {
            let got: Vec<f64> = (0..3).map(|j| pose.rotation[(i, j)]).collect();
            assert_close(&format!("tool_R_W row {i}"), label, &got, row, TOL);
        }
        frame_jacobian(&model, &data, model.tool_frame, &mut jac);
        for (i, row) in mat_of(&s["J_tool_W"]).iter().enumerate() {
            let got: Vec<f64> = (0..6).map(|j| jac[(i, j)]).collect();
            assert_close(&format!("J_tool_W row {i}"), label, &got, row, TOL);
        }
    });
}

#[test]
fn discrete_step_matches_drake_and_stops_at_limits() {
    let model = model();
    let mut data = Data::new(&model);
    let mut plant = DiscretePlant::new(&model, 0.001, 1);
    let mut limited_states = 0;
    for_each_state(|label, s| {
        let step = &s["discrete_step"];
        assert_eq!(step["dt"].as_f64(), Some(0.001));
        let (mut q, mut v) = (vec_of(&s["q"]), vec_of(&s["v"]));
        let u = vec_of(&step["u"]);
        forward_kinematics(&model, &mut data, &q);
        gravity_and_bias_from_kinematics(&model, &mut data, &v);
        plant.step(&model, &mut data, &u, &mut q, &mut v);
        if step["equals_formula_B"].as_bool().unwrap() {
            assert_close("q_next", label, &q, &vec_of(&step["q_next"]), TOL);
            assert_close("v_next", label, &v, &vec_of(&step["v_next"]), TOL);
        } else {
            // Drake's SAP adds a compliant limit constraint here; the joint must not pass its limit.
            limited_states += 1;
            for name in step["joint_limit_in_sap_window"].as_array().unwrap() {
                let j = model.joint_index(name.as_str().unwrap()).unwrap();
                let joint = &model.joints[j];
                assert!(q[j] <= joint.upper && q[j] >= joint.lower, "{label}: {} at {} passed its limit", joint.name, q[j]);
                let drake_q = vec_of(&step["q_next"])[j];
                assert!((q[j] - drake_q).abs() < 1e-3, "{label}: {} at {} vs Drake {drake_q}", joint.name, q[j]);
            }
        }
    });
    assert_eq!(limited_states, 1, "the fixture has one limit-engaged state");
}

/// `armscope model --states` (what the corpus check compares with Pinocchio) gives, by joint name,
/// the reference's M, τ_g, C·v and q̈ with and without damping at every fixture state.
#[test]
fn model_subcommand_reports_the_reference_dynamics_by_joint_name() {
    let f = fixtures();
    let names: Vec<String> = f["meta"]["joint_order"].as_array().unwrap().iter().map(|n| n.as_str().unwrap().to_string()).collect();
    let states: Vec<Value> = f["states"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let by_name = |key: &str| -> serde_json::Map<String, Value> { names.iter().cloned().zip(vec_of(&s[key]).into_iter().map(Value::from)).collect() };
            serde_json::json!({ "q": by_name("q"), "v": by_name("v"), "tau": by_name("tau") })
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let states_file = dir.path().join("states.json");
    std::fs::write(&states_file, serde_json::to_string(&states).unwrap()).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["model", "--urdf", common::box_urdf().to_str().unwrap(), "--states", states_file.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "armscope model: {}", String::from_utf8_lossy(&out.stderr));
    let got: Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let order: Vec<&str> = got["joints"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
    assert_eq!(order, names.iter().map(String::as_str).collect::<Vec<_>>());
    let mut checked = 0;
    for_each_state(|label, s| {
        let mine = &got["states"][checked];
        for (i, row) in mat_of(&s["M"]).iter().enumerate() {
            assert_close(&format!("M row {i}"), label, &vec_of(&mine["M"][i]), row, TOL);
        }
        assert_close("tau_g", label, &vec_of(&mine["tau_g"]), &vec_of(&s["tau_g"]), TOL);
        assert_close("Cv", label, &vec_of(&mine["Cv"]), &vec_of(&s["Cv"]), TOL);
        for key in ["qdd_no_damping", "qdd_with_damping"] {
            let want = vec_of(&s[key]);
            let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            assert_close(key, label, &vec_of(&mine[key]), &want, TOL * scale);
        }
        assert!(mine["link_poses"].as_object().unwrap().len() >= 7, "{label}: a pose for every link");
        checked += 1;
    });
}
