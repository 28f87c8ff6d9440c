//! What real robot descriptions contain and Pinocchio and Drake load, in generated URDFs: massless
//! frame links, inconsistent inertias (a notice, or an error with --strict-inertia), a moving joint
//! that moves nothing (an error naming it), 0..0 limit placeholders, transmissions and mimics on
//! fixed joints, meshes that are missing or found through ROS's package paths, xacro files.

mod common;

use armscope::dynamics::{Data, crba};
use armscope::model::{Geometry, LoadOptions, Model, load_urdf_str, load_urdf_str_with};
use std::path::Path;
use std::process::Command;

fn inertial(mass: f64, ixx: f64, iyy: f64, izz: f64) -> String {
    format!(r#"<inertial><mass value="{mass}"/><inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>"#)
}

/// world ─weld─ base ─J1 (z)─ upper ─J2 (y)─ fore, and whatever `extra` adds.
fn arm(fore_inertial: &str, j2_limits: &str, extra: &str) -> String {
    format!(
        r#"<robot name="t"><link name="world"/><link name="base">{base}</link><link name="upper">{upper}</link><link name="fore">{fore_inertial}</link>
<joint name="weld" type="fixed"><parent link="world"/><child link="base"/></joint>
<joint name="J1" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="5" velocity="1"/></joint>
<joint name="J2" type="revolute"><origin xyz="0 0 0.2"/><parent link="upper"/><child link="fore"/><axis xyz="0 1 0"/><limit {j2_limits} effort="5" velocity="1"/></joint>
{extra}</robot>"#,
        base = inertial(1.0, 0.01, 0.01, 0.01),
        upper = inertial(1.0, 0.01, 0.01, 0.01),
    )
}

const GOOD_FORE: &str = r#"<inertial><origin xyz="0.1 0 0"/><mass value="0.5"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial>"#;
const LIMITS: &str = r#"lower="-1" upper="1""#;

fn load(text: &str) -> Model {
    load_urdf_str(text, Path::new("t.urdf")).unwrap_or_else(|e| panic!("{e}"))
}

fn mass_matrix_at_zero(model: &Model) -> nalgebra::DMatrix<f64> {
    let mut data = Data::new(model);
    let q = vec![0.0; model.dof()];
    crba(model, &mut data, &q);
    data.mass_matrix.clone()
}

#[test]
fn massless_frame_links_on_fixed_joints_load_without_a_word() {
    let tool = r#"<link name="tool_frame"/><link name="camera"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
<joint name="tool_joint" type="fixed"><origin xyz="0.3 0 0"/><parent link="fore"/><child link="tool_frame"/></joint>
<joint name="camera_joint" type="fixed"><parent link="upper"/><child link="camera"/></joint>"#;
    let model = load(&arm(GOOD_FORE, LIMITS, tool));
    assert_eq!(model.dof(), 2);
    assert_eq!(model.frames[model.tool_frame].name, "tool_frame", "the deepest leaf is the tool");
    assert!(model.notices.iter().all(|n| !n.contains("tool_frame") && !n.contains("camera")), "{:?}", model.notices);
}

#[test]
fn a_massless_link_between_moving_joints_is_fine_when_the_subtree_has_inertia() {
    // J2 moves a massless link; J3 hangs a mass from it: J2 still moves something
    let extra = format!(
        r#"<link name="hand">{}</link><joint name="J3" type="revolute"><origin xyz="0.2 0 0"/><parent link="fore"/><child link="hand"/><axis xyz="1 0 0"/><limit {LIMITS} effort="1" velocity="1"/></joint>"#,
        inertial(0.2, 1e-4, 1e-4, 1e-4)
    );
    let model = load(&arm(&inertial(0.0, 0.0, 0.0, 0.0), LIMITS, &extra));
    let m = mass_matrix_at_zero(&model);
    assert!(m.clone().cholesky().is_some(), "M positive definite: {m}");
}

#[test]
fn a_joint_that_moves_nothing_is_an_error_naming_the_joint_and_link() {
    let err = load_urdf_str(&arm(&inertial(0.0, 0.0, 0.0, 0.0), LIMITS, ""), Path::new("t.urdf")).unwrap_err().to_string();
    assert!(err.starts_with("t.urdf: ") && err.contains("joint 'J2'") && err.contains("link 'fore'") && err.contains("moves nothing"), "{err}");
    // a point mass on the axis has no inertia about it either
    let on_axis = r#"<inertial><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>"#;
    let err = load_urdf_str(&arm(on_axis, LIMITS, ""), Path::new("t.urdf")).unwrap_err().to_string();
    assert!(err.contains("joint 'J2'"), "{err}");
}

#[test]
fn inconsistent_inertias_are_a_notice_and_the_urdfs_numbers_are_used_unless_strict() {
    // a thin rod along x: zero about its own axis (not positive definite), moved about y
    let rod = r#"<inertial><origin xyz="0.1 0 0"/><mass value="0.5"/><inertia ixx="0" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial>"#;
    // the triangle inequality broken (izz > ixx + iyy), as exporters write for sensor mounts
    let triangle = r#"<inertial><origin xyz="0.1 0 0"/><mass value="0.5"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.005"/></inertial>"#;
    for (inertia, what) in [(rod, "not positive definite"), (triangle, "triangle inequality")] {
        let text = arm(inertia, LIMITS, "");
        let model = load(&text);
        let notice = model.notices.iter().find(|n| n.contains("link 'fore'")).unwrap_or_else(|| panic!("no notice: {:?}", model.notices));
        assert!(notice.contains(what) && notice.contains("--strict-inertia"), "{notice}");
        // the URDF's numbers, unchanged
        let izz = armscope::model::load_urdf_str(&text, Path::new("t.urdf")).unwrap().joints[1].inertia.inertia_com[(2, 2)];
        assert_eq!(izz, if what == "triangle inequality" { 0.005 } else { 0.002 });
        assert!(mass_matrix_at_zero(&model).cholesky().is_some());
        let strict = load_urdf_str_with(&text, Path::new("t.urdf"), LoadOptions { strict_inertia: true }).unwrap_err().to_string();
        assert!(strict.contains("link 'fore'") && strict.contains(what), "{strict}");
    }
}

#[test]
fn zero_width_limits_are_a_placeholder_for_unlimited_and_never_a_divergence() {
    let model = load(&arm(GOOD_FORE, r#"lower="0" upper="0""#, ""));
    assert!(model.joints[1].lower.is_infinite() && model.joints[1].upper.is_infinite());
    assert!(model.notices.iter().any(|n| n.contains("joint 'J2'") && n.contains("unlimited")), "{:?}", model.notices);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("zero.urdf");
    std::fs::write(&path, arm(GOOD_FORE, r#"lower="0" upper="0""#, "")).unwrap();
    for extra in [&["--static"][..], &["--kp", "0", "--kd", "0", "--no-ff"][..]] {
        let out = Command::new(env!("CARGO_BIN_EXE_armscope"))
            .args(["run", "--quiet", "--duration", "0.5", "--no-rrd", "--no-mcap", "--urdf", path.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    }
}

#[test]
fn transmissions_and_mimics_on_joints_that_do_not_move_are_ignored_with_a_notice() {
    let extra = r#"<link name="finger"/><joint name="finger_joint" type="fixed"><parent link="fore"/><child link="finger"/><mimic joint="J2"/></joint>
<transmission name="finger_trans"><joint name="finger_joint"/><actuator name="finger_motor"/></transmission>
<transmission name="ghost_trans"><joint name="no_such_joint"/><actuator name="ghost"/></transmission>
<transmission name="j2_trans"><joint name="J2"/><actuator name="m2"><mechanicalReduction>4</mechanicalReduction></actuator></transmission>"#;
    let model = load(&arm(GOOD_FORE, LIMITS, extra));
    let has = |a: &str, b: &str| model.notices.iter().any(|n| n.contains(a) && n.contains(b));
    assert!(has("finger_trans", "fixed joint") && has("ghost_trans", "does not have") && has("finger_joint", "<mimic>"), "{:?}", model.notices);
    // J2's motor from its transmission; J1, without one, driven directly with its URDF effort
    assert_eq!(model.actuators.len(), 2);
    assert_eq!((model.actuators[1].joint, model.actuators[1].gear_ratio), (1, 4.0));
    assert_eq!((model.actuators[0].joint, model.actuators[0].effort), (0, 5.0));
    assert!(has("'J1'", "driven directly"), "{:?}", model.notices);
}

/// A two-finger gripper on J2's link: `right` mimics `left` with multiplier −1 and offset 0.01; `tip`
/// mimics `right` (a chain: q_tip = 2·q_right = −2·q_left − 0.02... + its own offset).
fn gripper_arm() -> String {
    let finger = |name: &str, child: &str, y: f64, mimic: &str, damping: f64| {
        format!(
            r#"<link name="{child}">{}</link><joint name="{name}" type="prismatic"><origin xyz="0.2 {y} 0"/><parent link="fore"/><child link="{child}"/><axis xyz="0 1 0"/><limit lower="-0.05" upper="0.05" effort="20" velocity="1"/><dynamics damping="{damping}"/>{mimic}</joint>"#,
            inertial(0.1, 1e-4, 1e-4, 1e-4)
        )
    };
    let extra = finger("left", "left_finger", 0.02, "", 0.5)
        + &finger("right", "right_finger", -0.02, r#"<mimic joint="left" multiplier="-1" offset="0.01"/>"#, 0.3)
        + &format!(
            r#"<link name="tip">{}</link><joint name="tip_joint" type="revolute"><origin xyz="0.03 0 0"/><parent link="right_finger"/><child link="tip"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/><dynamics damping="0.2"/><mimic joint="right" multiplier="2" offset="0.1"/></joint>"#,
            inertial(0.05, 1e-5, 1e-5, 1e-5)
        );
    arm(GOOD_FORE, LIMITS, &extra)
}

#[test]
fn mimic_joints_follow_their_master_and_the_coordinates_are_the_independent_joints() {
    let model = load(&gripper_arm());
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["J1", "J2", "left"], "the coordinates are the independent joints");
    assert_eq!(model.bodies.len(), 5);
    let coupling = |name: &str| model.couplings[model.bodies.iter().position(|b| b.name == name).unwrap()];
    let (right, tip) = (coupling("right"), coupling("tip_joint"));
    assert_eq!((right.coordinate, right.multiplier, right.offset), (2, -1.0, 0.01));
    // q_tip = 2·q_right + 0.1 = 2·(−q_left + 0.01) + 0.1
    assert_eq!((tip.coordinate, tip.multiplier), (2, -2.0));
    assert!((tip.offset - 0.12).abs() < 1e-15);
    // D_r = GᵀDG: left's own 0.5 + (−1)²·0.3 + (−2)²·0.2
    assert!((model.joints[2].damping - 1.6).abs() < 1e-12, "{}", model.joints[2].damping);
    let has = |a: &str| model.notices.iter().any(|n| n.contains(a));
    assert!(has("joint 'right' mimics 'left' (q = -1·q + 0.01)") && has("joint 'tip_joint' mimics 'left'"), "{:?}", model.notices);
}

/// The coordinates' dynamics equal the full tree's projected through the coupling: with G the
/// body-from-coordinate Jacobian (q_bodies = G·q + offset), M = GᵀM_full G, τ_g = Gᵀτ_g,full,
/// C·v = Gᵀ(C·v)_full; and ABA's q̈ solves M q̈ = τ + τ_g − C·v. The full tree is the same URDF with
/// the `<mimic>` tags removed, evaluated at the bodies' positions and velocities.
#[test]
fn mimic_dynamics_are_the_full_trees_projected_through_the_coupling() {
    use armscope::dynamics::{aba, bias_forces, forward_kinematics, frame_pose, gravity_forces};
    let coupled = load(&gripper_arm());
    let full = load(&gripper_arm().replace(r#"<mimic joint="left" multiplier="-1" offset="0.01"/>"#, "").replace(r#"<mimic joint="right" multiplier="2" offset="0.1"/>"#, ""));
    assert_eq!((coupled.dof(), full.dof()), (3, 5));
    // full coordinates in body order: J1, J2, left, right, tip_joint; G maps the 3 coordinates onto them
    let g = nalgebra::DMatrix::from_row_slice(5, 3, &[1., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., -1., 0., 0., -2.]);
    let offset = nalgebra::DVector::from_row_slice(&[0., 0., 0., 0.01, 0.12]);
    let (mut dc, mut df) = (Data::new(&coupled), Data::new(&full));
    for (q, v, tau) in [([0.3, -0.7, 0.02], [0.5, -1.0, 0.3], [0.1, 2.0, -1.0]), ([-1.5, 0.4, -0.04], [-0.2, 0.8, -0.6], [0.0, 0.0, 0.5])] {
        let (qv, vv) = (nalgebra::DVector::from_row_slice(&q), nalgebra::DVector::from_row_slice(&v));
        let q_full: Vec<f64> = (&g * &qv + &offset).iter().copied().collect();
        let v_full: Vec<f64> = (&g * &vv).iter().copied().collect();
        let m_full = crba(&full, &mut df, &q_full).clone();
        let m_want = g.transpose() * &m_full * &g;
        let m_got = crba(&coupled, &mut dc, &q).clone();
        assert!((&m_got - &m_want).amax() <= 1e-14 * m_want.amax(), "M\n{m_got}\n{m_want}");
        let tg_want = g.transpose() * nalgebra::DVector::from_column_slice(gravity_forces(&full, &mut df, &q_full));
        let tg_got = nalgebra::DVector::from_column_slice(gravity_forces(&coupled, &mut dc, &q));
        assert!((&tg_got - &tg_want).amax() <= 1e-14 * tg_want.amax(), "τ_g {tg_got} {tg_want}");
        let cv_want = g.transpose() * nalgebra::DVector::from_column_slice(bias_forces(&full, &mut df, &q_full, &v_full));
        let cv_got = nalgebra::DVector::from_column_slice(bias_forces(&coupled, &mut dc, &q, &v));
        assert!((&cv_got - &cv_want).amax() <= 1e-13 * cv_want.amax().max(1e-3), "C·v {cv_got} {cv_want}");
        let rhs = nalgebra::DVector::from_row_slice(&tau) + &tg_want - &cv_want;
        let qdd_want = m_want.clone().cholesky().unwrap().solve(&rhs);
        let qdd_got = nalgebra::DVector::from_column_slice(aba(&coupled, &mut dc, &q, &v, &tau));
        assert!((&qdd_got - &qdd_want).amax() <= 1e-10 * qdd_want.amax(), "q̈ {qdd_got} {qdd_want}");
        // every link is drawn where the full tree puts it
        forward_kinematics(&coupled, &mut dc, &q);
        forward_kinematics(&full, &mut df, &q_full);
        for f in 0..coupled.frames.len() {
            let (a, b) = (frame_pose(&coupled, &dc, f), frame_pose(&full, &df, f));
            assert!((a.translation - b.translation).amax() < 1e-15 && (a.rotation - b.rotation).amax() < 1e-15, "link {}", coupled.frames[f].name);
        }
    }
}

#[test]
fn a_mimic_robot_runs_by_default_without_chatter_with_one_column_per_coordinate() {
    let (code, summary, stderr) = run_summary(&gripper_arm(), &["--duration", "3"]);
    assert_eq!(code, 0, "{stderr}");
    let chatter = summary["summary"]["chatter_percent"].as_array().unwrap();
    assert_eq!(chatter.len(), 3, "one column per coordinate");
    assert!(chatter.iter().all(|c| c.as_f64().unwrap() < 5.0), "{chatter:?}");
}

#[test]
fn a_missing_mesh_is_a_notice_and_the_link_is_drawn_from_its_collision_shape_or_inertia() {
    let dir = tempfile::tempdir().unwrap();
    let visual = |mesh: &str| format!(r#"<visual><geometry><mesh filename="{mesh}"/></geometry></visual>"#);
    let fore = format!("{GOOD_FORE}{}<collision><origin xyz=\"0.1 0 0\"/><geometry><box size=\"0.2 0.03 0.03\"/></geometry></collision>", visual("package://arm_description/meshes/fore.stl"));
    let text = arm(&fore, LIMITS, "").replace(r#"<link name="upper">"#, &format!(r#"<link name="upper">{}"#, visual("meshes/upper.dae")));
    let path = dir.path().join("t.urdf");
    std::fs::write(&path, &text).unwrap();
    let model = armscope::model::load_urdf(&path).unwrap();
    let frame = |name: &str| &model.frames[model.frame_index(name).unwrap()];
    assert!(matches!(frame("fore").visuals[..], [armscope::model::Visual { geometry: Geometry::Box { size: [0.2, 0.03, 0.03] }, .. }]), "collision box");
    // no collision shape: a box of the link's inertia (1 kg, 0.01 kg·m² about each axis: a cube of side √0.06)
    let Geometry::Box { size } = frame("upper").visuals[0].geometry else { panic!("inertia box") };
    assert!(size.iter().all(|s| (s - 0.06f64.sqrt()).abs() < 1e-9), "{size:?}");
    for mesh in ["package://arm_description/meshes/fore.stl", "meshes/upper.dae"] {
        assert!(model.notices.iter().any(|n| n.contains(mesh) && n.contains("not found")), "{mesh}: {:?}", model.notices);
    }
    // found through ROS_PACKAGE_PATH, as ROS finds it: a run in another process with that path set
    let packages = tempfile::tempdir().unwrap();
    let meshes = packages.path().join("arm_description/meshes");
    std::fs::create_dir_all(&meshes).unwrap();
    std::fs::copy(common::repo().join("assets/smallrobotarm/meshes/link2.stl"), meshes.join("fore.stl")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--duration", "0.1", "--no-rrd", "--no-mcap", "--quiet", "--urdf", path.to_str().unwrap()])
        .env("ROS_PACKAGE_PATH", packages.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(!err.contains("fore.stl") && err.contains("upper.dae"), "fore.stl found, upper.dae still missing: {err}");
}

#[test]
fn a_texture_without_a_filename_is_ignored_with_a_notice() {
    // iCub's and Romeo's exporters write `<texture />` in every material; urdfdom accepts it
    let visual = r#"<visual><geometry><box size="0.1 0.1 0.1"/></geometry><material name="grey"><color rgba="0.5 0.5 0.5 1"/><texture /></material></visual>"#;
    let text = arm(GOOD_FORE, LIMITS, "").replace(r#"<link name="upper">"#, &format!(r#"<link name="upper">{visual}"#));
    let model = load(&text.replace("</robot>", &format!(r#"<material name="skin"><texture/></material></robot>"#)));
    assert_eq!(model.dof(), 2);
    let said: Vec<&String> = model.notices.iter().filter(|n| n.contains("<texture>")).collect();
    assert!(said.len() == 1 && said[0].contains("2 <texture>"), "{:?}", model.notices);
    // a texture with its file is no notice
    let with_file = load(&arm(GOOD_FORE, LIMITS, r#"<material name="m"><texture filename="skin.png"/></material>"#));
    assert!(!with_file.notices.iter().any(|n| n.contains("texture")), "{:?}", with_file.notices);
}

#[test]
fn a_xacro_file_gets_one_line_saying_how_to_expand_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("arm.urdf.xacro");
    std::fs::write(&path, r#"<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="x"><xacro:property name="l" value="1"/></robot>"#).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).args(["run", "--urdf", path.to_str().unwrap()]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("arm.urdf.xacro") && err.contains("xacro") && err.contains("expand"), "{err}");
}

/// A small hobby arm as exporters write it: a heavy shoulder, a wrist of a few grams with joint
/// damping, and a prismatic finger with a 4 cm range; limits 0..0 on the wrist roll.
fn hobby_arm() -> String {
    format!(
        r#"<robot name="hobby"><link name="world"/><link name="base">{base}</link><link name="shoulder">{shoulder}</link><link name="upper">{upper}</link>
<link name="wrist">{wrist}</link><link name="finger">{finger}</link>
<joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
<joint name="pan" type="revolute"><parent link="base"/><child link="shoulder"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="3" velocity="5"/></joint>
<joint name="lift" type="revolute"><origin xyz="0 0 0.05"/><parent link="shoulder"/><child link="upper"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="4" velocity="5"/></joint>
<joint name="roll" type="revolute"><origin xyz="0.15 0 0"/><parent link="upper"/><child link="wrist"/><axis xyz="1 0 0"/><limit lower="0" upper="0" effort="0.5" velocity="5"/><dynamics damping="0.05"/></joint>
<joint name="grip" type="prismatic"><origin xyz="0.03 0 0"/><parent link="wrist"/><child link="finger"/><axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="5" velocity="0.1"/></joint>
</robot>"#,
        base = inertial(1.0, 1e-3, 1e-3, 1e-3),
        shoulder = inertial(0.2, 1e-4, 1e-4, 1e-4),
        upper = r#"<inertial><origin xyz="0.07 0 0"/><mass value="0.15"/><inertia ixx="2e-5" ixy="0" ixz="0" iyy="3e-4" iyz="0" izz="3e-4"/></inertial>"#,
        wrist = inertial(0.01, 1e-6, 1e-6, 1e-6),
        finger = inertial(0.005, 1e-7, 1e-7, 1e-7),
    )
}

fn run_summary(urdf: &str, extra: &[&str]) -> (i32, serde_json::Value, String) {
    let dir = tempfile::tempdir().unwrap();
    let (path, json) = (dir.path().join("arm.urdf"), dir.path().join("s.json"));
    std::fs::write(&path, urdf).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--quiet", "--no-rrd", "--no-mcap", "--urdf", path.to_str().unwrap(), "--summary-json", json.to_str().unwrap()])
        .args(extra)
        .output()
        .unwrap();
    let doc = std::fs::read_to_string(&json).ok().and_then(|t| serde_json::from_str(&t).ok()).unwrap_or(serde_json::Value::Null);
    (out.status.code().unwrap_or(-1), doc, String::from_utf8_lossy(&out.stderr).into())
}

#[test]
fn the_default_experiment_on_any_arm_is_stable_tracks_and_fits_the_joint_ranges() {
    // auto-tuned gains, stable along the command with a gain margin of 2
    let (code, doc, err) = run_summary(&hobby_arm(), &["--duration", "10"]);
    assert_eq!(code, 0, "{err}");
    let s = &doc["summary"];
    for j in 0..4 {
        let chatter = s["chatter_percent"][j].as_f64().unwrap();
        let error = s["max_abs_error"][j].as_f64().unwrap();
        assert!(chatter < 5.0, "joint {j}: chatter {chatter} %");
        // a 30° (5 cm) wave after 2 s of settling: within 1 % of the amplitude
        assert!(error < 0.005, "joint {j}: max error {error}");
    }
    assert!(doc["gains"]["spectral_radius"].as_f64().unwrap() < 1.0, "{}", doc["gains"]);
    // the prismatic finger's 4 cm range: a swing of a quarter of it (1 cm), inside the range
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("t.csv");
    let (code, _, err) = run_summary(&hobby_arm(), &["--duration", "13", "--trace", trace.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let t = common::read_csv(&trace);
    let grip: Vec<f64> = t.column("cmd4").into_iter().filter(|v| v.is_finite()).collect();
    let (lo, hi) = grip.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    assert!((hi - lo - 0.02).abs() < 1e-3 && lo >= 0.0 && hi <= 0.04, "finger command [{lo}, {hi}]");
    let q: Vec<f64> = t.column("q4");
    assert!(q.iter().all(|&v| (-1e-9..=0.04 + 1e-9).contains(&v)), "the finger stays in its range");
}

#[test]
fn q0_sets_the_start_pose_by_list_or_by_name_and_bad_values_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("t.csv");
    let (code, _, err) = run_summary(&hobby_arm(), &["--duration", "0.01", "--static", "--q0", "lift=0.5,grip=0.02", "--trace", trace.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let t = common::read_csv(&trace);
    assert_eq!([t.rows[0][t.col("q1")], t.rows[0][t.col("q2")], t.rows[0][t.col("q4")]], [0.0, 0.5, 0.02]);
    let (code, _, err) = run_summary(&hobby_arm(), &["--duration", "0.01", "--q0", "0.1,-0.2,0,0.01", "--trace", trace.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(common::read_csv(&trace).rows[0][1..5], [0.1, -0.2, 0.0, 0.01]);
    for (q0, needle) in [("lift=3", "outside its range"), ("elbow=1", "no moving joint 'elbow'"), ("1,2", "expected 4 values"), ("lift=x", "'x' is not a finite number")] {
        let (code, _, err) = run_summary(&hobby_arm(), &["--duration", "0.01", "--q0", q0]);
        assert_eq!(code, 2, "{q0}: {err}");
        assert!(err.contains("--q0") && err.contains(needle), "{q0}: {err}");
    }
}

#[test]
fn a_differential_transmission_is_a_notice_and_its_joints_are_driven_directly() {
    let extra = r#"<transmission name="wrist_trans"><joint name="J1"/><joint name="J2"/><actuator name="a"/><actuator name="b"/></transmission>"#;
    let model = load(&arm(GOOD_FORE, LIMITS, extra));
    assert!(model.notices.iter().any(|n| n.contains("wrist_trans") && n.contains("2 joints")), "{:?}", model.notices);
    let mut driven: Vec<usize> = model.actuators.iter().map(|a| a.joint).collect();
    driven.sort();
    assert_eq!(driven, [0, 1]);
    assert_eq!(model.effort_limits(), [5.0, 5.0]);
}

/// An arm that cannot hold its start pose against gravity is told so before the run, per joint with
/// both torques: Baxter's shoulders (s1) need 56.4 N·m at every joint's 0, their URDF allows 50 (the
/// real arm carries counterbalance springs the URDF leaves out); no other joint of it, and nothing on
/// the tutorial's arm, whose J2 needs 4.43 of its 12 N·m.
#[test]
fn an_arm_that_cannot_hold_the_start_pose_asked_for_is_told_so_per_joint() {
    use armscope::config::RunConfig;
    use armscope::experiment::Experiment;
    // each joint's 0, asked for: Baxter's shoulders hold the arm out on springs its URDF leaves out
    let baxter = Experiment::prepare(RunConfig { urdf: common::repo().join("tests/fixtures/robots/baxter.urdf"), q0: Some("right_s1=0".into()), ..RunConfig::default() }).unwrap();
    assert_eq!(baxter.start, vec![0.0; baxter.model.dof()]);
    let said: Vec<&String> = baxter.model.notices.iter().filter(|n| n.contains("against gravity")).collect();
    assert_eq!(said.len(), 2, "{said:?}");
    for (notice, joint) in said.iter().zip(["right_s1", "left_s1"]) {
        assert!(notice.contains(&format!("joint '{joint}'")) && notice.contains("56.4") && notice.contains("50 N·m"), "{notice}");
    }
    let tutorial = Experiment::prepare(RunConfig { urdf: common::box_urdf(), ..RunConfig::default() }).unwrap();
    assert!(!tutorial.model.notices.iter().any(|n| n.contains("against gravity") || n.contains("default")), "{:?}", tutorial.model.notices);
}

#[test]
fn the_default_experiment_starts_where_the_urdfs_motors_hold_the_arm_and_asks_what_they_carry() {
    use armscope::config::RunConfig;
    use armscope::control::within_effort::{MOTION_LOAD, START_LOAD};
    use armscope::control::demand::required_torque;
    use armscope::experiment::Experiment;
    let urdf = common::repo().join("tests/fixtures/robots/baxter.urdf");
    let baxter = Experiment::prepare(RunConfig { urdf: urdf.clone(), ..RunConfig::default() }).unwrap();
    let model = &baxter.model;
    let effort = model.effort_limits();
    // the start: the weight takes at most 60 % of each motor (at each joint's 0 the shoulders need 56.4 of 50)
    let tau_g = armscope::dynamics::gravity_forces(model, &mut armscope::dynamics::Data::new(model), &baxter.start).to_vec();
    for j in 0..model.dof() {
        if model.is_actuated(j) && effort[j] > 0.0 {
            assert!(tau_g[j].abs() <= START_LOAD * effort[j] + 1e-9, "{}: {} of {}", model.joints[j].name, tau_g[j], effort[j]);
        }
    }
    let s1 = model.joint_index("right_s1").unwrap();
    assert!(baxter.start[s1] > 0.5, "the shoulder lowers the arm: {}", baxter.start[s1]);
    // only the joints that take the shoulders' load move (the wrists and fingers stay at 0)
    let moved: Vec<&str> = (0..model.dof()).filter(|&j| baxter.start[j] != 0.0).map(|j| model.joints[j].name.as_str()).collect();
    assert!(moved.iter().all(|n| ["right_s1", "right_e1", "left_s1", "left_e1"].contains(n)), "{moved:?}");
    let notice = model.notices.iter().find(|n| n.contains("default start pose")).expect("a notice");
    assert!(notice.contains("right_s1 56.424 N·m of its 50") && notice.contains("--q0 right_s1="), "{notice}");
    // the wave: scaled until the motion needs at most 80 % of each joint's effort, and no smaller than that needs
    let peak = required_torque(model, baxter.trajectory.as_ref(), 4.0 * std::f64::consts::PI, 0.01);
    let worst = (0..model.dof()).filter(|&j| model.is_actuated(j)).map(|j| peak[j] / effort[j]).fold(0.0, f64::max);
    assert!(worst <= MOTION_LOAD + 0.005 && worst > MOTION_LOAD - 0.05, "the motion needs {worst} of the effort");
    assert!(model.notices.iter().any(|n| n.contains("default wave") && n.contains("scaled to")), "{:?}", model.notices);
    // and the run tracks it: small error, no chatter, on every joint
    let (code, doc, err) = {
        let dir = tempfile::tempdir().unwrap();
        let json = dir.path().join("s.json");
        let out = Command::new(env!("CARGO_BIN_EXE_armscope"))
            .args(["run", "--quiet", "--no-rrd", "--no-mcap", "--duration", "10", "--urdf", urdf.to_str().unwrap(), "--summary-json", json.to_str().unwrap()])
            .output()
            .unwrap();
        (out.status.code(), serde_json::from_str::<serde_json::Value>(&std::fs::read_to_string(&json).unwrap()).unwrap(), String::from_utf8_lossy(&out.stderr).to_string())
    };
    assert_eq!(code, Some(0), "{err}");
    // what was assumed is in the record, not only on the console
    let notices: Vec<&str> = doc["notices"].as_array().unwrap().iter().filter_map(|n| n.as_str()).collect();
    assert!(notices.iter().any(|n| n.contains("default start pose")) && notices.iter().any(|n| n.contains("default wave")), "{notices:?}");
    let s = &doc["summary"];
    for j in 0..model.dof() {
        let (error, chatter) = (s["max_abs_error"][j].as_f64().unwrap(), s["chatter_percent"][j].as_f64().unwrap());
        // 0.4 mrad measured (the shoulders fell 0.76 rad from each joint's 0)
        assert!(error < 0.005 && chatter < 5.0, "{}: max error {error} rad, chatter {chatter} %", model.joints[j].name);
    }
    // asked for, the experiment is run as asked
    let asked = Experiment::prepare(RunConfig { urdf: urdf.clone(), q0: Some("right_s1=0.1".into()), amp_deg: 20.0, wave_as_asked: true, ..RunConfig::default() }).unwrap();
    assert_eq!(asked.start[s1], 0.1);
    assert!(!asked.model.notices.iter().any(|n| n.contains("default")), "{:?}", asked.model.notices);
    // from the command line: either wave flag, even at the default value, runs the wave as asked
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--no-rrd", "--no-mcap", "--duration", "0.01", "--amp-deg", "30", "--urdf", urdf.to_str().unwrap()])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && err.contains("default start pose") && !err.contains("default wave"), "{err}");
}

#[test]
fn a_mode_that_needs_soft_gains_softens_only_its_own_joints() {
    // Tiago's wrist rolls arm_5 and arm_7 are aligned at arm_6 = 0 with a light link between them:
    // their relative motion is a light mode the sampled derivative term destabilizes. One bandwidth
    // for all joints was lowered 35× for it (head and fingers 0.09 rad off); per joint, the rest keep theirs
    let urdf = std::fs::read_to_string(common::repo().join("tests/fixtures/robots/tiago.urdf")).unwrap();
    // (without the URDF's 1 N·m joint friction here: a PD loop stops within F/kp of its target,
    // checked below)
    let (code, doc, err) = run_summary(&urdf, &["--duration", "10", "--friction", "0"]);
    assert_eq!(code, 0, "{err}");
    let (s, gains) = (&doc["summary"], &doc["gains"]);
    assert!(gains["spectral_radius"].as_f64().unwrap() < 1.0, "{gains}");
    let names: Vec<&str> = s["joints"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
    for (j, name) in names.iter().enumerate() {
        let (error, chatter) = (s["max_abs_error"][j].as_f64().unwrap(), s["chatter_percent"][j].as_f64().unwrap());
        // 5.9 mrad measured at worst (arm_7), 1–2 mrad on the rest
        assert!(error < 0.01 && chatter < 5.0, "{name}: max error {error}, chatter {chatter} %");
    }
    let at = |key: &str, name: &str| gains[key][names.iter().position(|n| *n == name).unwrap()].as_f64().unwrap();
    let inertia = |name: &str| gains["effective_inertia"][names.iter().position(|n| *n == name).unwrap()].as_f64().unwrap();
    let damping_ratio = |name: &str| at("kd", name) / (2.0 * (at("kp", name) * inertia(name)).sqrt());
    assert!(damping_ratio("arm_5_joint") < 0.5 && damping_ratio("arm_7_joint") < 0.5, "the wrist rolls are softened");
    assert!((damping_ratio("head_1_joint") - 1.0).abs() < 1e-9 && at("kp", "head_1_joint") > 50.0, "the head keeps its gains: kp {}", at("kp", "head_1_joint"));

    // with the URDF's friction (1 N·m on the torso, head and arm joints): a joint held by friction
    // stays until the PD's kp·error exceeds F, so each may lag by up to F/kp more
    let (code, with_friction, err) = run_summary(&urdf, &["--duration", "10"]);
    assert_eq!(code, 0, "{err}");
    let model = armscope::model::load_urdf_str(&urdf, std::path::Path::new("tiago.urdf")).unwrap();
    let s = &with_friction["summary"];
    for (j, name) in names.iter().enumerate() {
        let friction = model.joints[j].friction;
        let error = s["max_abs_error"][j].as_f64().unwrap();
        assert!(error < 0.01 + friction / at("kp", name), "{name}: max error {error} with {friction} N·m friction, kp {}", at("kp", name));
    }
    assert!(s["stuck_percent"].as_array().unwrap().iter().any(|p| p.as_f64().unwrap() > 0.0), "some joint sticks on the way");
}
