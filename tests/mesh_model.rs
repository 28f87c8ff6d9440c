//! The generated SmallRobotArm mesh model: assets in sync with their generator, transmissions,
//! `package://` meshes, a missing mesh, auto-tuned gains, and the discrete plant's divergence.

mod common;

use armscope::model::load_urdf;
use common::repo;
use std::process::Command;

fn mesh_urdf() -> std::path::PathBuf {
    repo().join("assets/smallrobotarm/smallrobotarm.urdf")
}

#[test]
fn committed_assets_are_what_the_generator_writes() {
    let dir = tempfile::tempdir().unwrap();
    armscope::meshgen::write_smallrobotarm(dir.path()).unwrap();
    let committed = repo().join("assets/smallrobotarm");
    assert_eq!(std::fs::read_to_string(dir.path().join("smallrobotarm.urdf")).unwrap(), std::fs::read_to_string(committed.join("smallrobotarm.urdf")).unwrap());
    for entry in std::fs::read_dir(dir.path().join("meshes")).unwrap() {
        let name = entry.unwrap().file_name();
        assert_eq!(std::fs::read(dir.path().join("meshes").join(&name)).unwrap(), std::fs::read(committed.join("meshes").join(&name)).unwrap(), "{name:?}");
    }
}

#[test]
fn mesh_model_has_transmissions_meshes_and_the_tutorials_proportions() {
    let model = load_urdf(&mesh_urdf()).unwrap();
    assert!(model.notices.iter().any(|n| n.contains("root link 'base' is not attached to 'world'")));
    assert_eq!(model.dof(), 6);
    let motors: Vec<(&str, &str, f64, f64)> = model.actuators.iter().map(|a| (a.name.as_str(), model.joints[a.joint].name.as_str(), a.effort, a.gear_ratio)).collect();
    assert_eq!(motors, [("motor1", "J1", 100.0, 4.8), ("motor2", "J2", 50.0, 4.0), ("motor3", "J3", 30.0, 5.0), ("motor4", "J4", 20.0, 2.8), ("motor5", "J5", 10.0, 2.1)]);
    assert!(!model.is_actuated(5), "J6 has no transmission");
    let total: f64 = model.joints.iter().map(|j| j.inertia.mass).sum::<f64>() + 0.782;
    assert!((total - 2.27).abs() < 0.01, "total mass {total}");
    // effective inertias of the distal joints are of the tutorial's order (3e-5 and 6e-6)
    let gains = armscope::control::gains::auto_tune(&model, &[vec![0.0; 6]], 0.001, true, armscope::control::sampled_loop::LoopPlant::Discrete);
    let inertia = gains.effective_inertia.unwrap();
    assert!(inertia[3] > 1e-5 && inertia[3] < 6e-5, "J4 {}", inertia[3]);
    assert!(inertia[4] > 2e-6 && inertia[4] < 1.2e-5, "J5 {}", inertia[4]);
    // every visual is a mesh resolved from package://smallrobotarm/…
    let meshes: Vec<_> = model.frames.iter().flat_map(|f| &f.visuals).collect();
    assert_eq!(meshes.len(), 7);
    for v in meshes {
        match &v.geometry {
            armscope::model::Geometry::Mesh { path, .. } => assert!(path.is_file() && path.starts_with(repo().join("assets/smallrobotarm/meshes")), "{}", path.display()),
            other => panic!("not a mesh: {other:?}"),
        }
    }
}

#[test]
fn relative_and_missing_mesh_paths() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("parts")).unwrap();
    std::fs::copy(repo().join("assets/smallrobotarm/meshes/link4.stl"), dir.path().join("parts/arm.stl")).unwrap();
    let urdf = |mesh: &str| {
        format!(
            r#"<robot name="m"><link name="world"/><link name="a"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
<visual><geometry><mesh filename="{mesh}" scale="2 2 2"/></geometry></visual></link>
<joint name="J1" type="continuous"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/></joint></robot>"#
        )
    };
    let path = dir.path().join("m.urdf");
    std::fs::write(&path, urdf("parts/arm.stl")).unwrap();
    let model = load_urdf(&path).unwrap();
    assert!(matches!(&model.frames[1].visuals[0].geometry, armscope::model::Geometry::Mesh { scale, .. } if *scale == [2.0; 3]));
    // a missing mesh: a one-line notice naming the link and the mesh, and the run goes on
    std::fs::write(&path, urdf("package://m/parts/nothing.stl")).unwrap();
    let model = load_urdf(&path).unwrap();
    let notice = model.notices.iter().find(|n| n.contains("nothing.stl")).expect("a notice");
    assert!(notice.contains("link 'a'") && notice.contains("mesh 'package://m/parts/nothing.stl' not found"), "{notice}");
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).args(["run", "--urdf", path.to_str().unwrap(), "--no-rrd", "--no-mcap", "--duration", "0.1", "--static"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().filter(|l| l.contains("nothing.stl")).count(), 1, "{err}");
}

#[test]
fn transmissions_define_the_actuators_and_bad_ones_are_named() {
    // A: effort 7 (driven directly when B has a transmission); with effort 0, passive
    let model_with_a_effort = |extra: &str, a_effort: &str| {
        format!(
            r#"<robot name="t"><link name="world"/><link name="a"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
<link name="b"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
<joint name="A" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="{a_effort}" velocity="1"/></joint>
<joint name="B" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="3" velocity="1"/></joint>
{extra}</robot>"#
        )
    };
    let model = |extra: &str| model_with_a_effort(extra, "7");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.urdf");
    std::fs::write(&path, model(r#"<transmission name="tb"><joint name="B"/><actuator name="mb"><mechanicalReduction>3.5</mechanicalReduction></actuator></transmission>"#)).unwrap();
    let m = load_urdf(&path).unwrap();
    assert_eq!(m.actuators.len(), 2);
    assert_eq!((m.actuators[1].name.as_str(), m.actuators[1].joint, m.actuators[1].effort, m.actuators[1].gear_ratio), ("mb", 1, 3.0, 3.5));
    assert_eq!(m.effort_limits(), [7.0, 3.0], "A, without a transmission, is driven directly with its URDF effort");
    assert!(m.notices.iter().any(|n| n.contains("joints 'A' have no <transmission>: each is driven directly")), "{:?}", m.notices);
    std::fs::write(&path, model_with_a_effort(r#"<transmission name="tb"><joint name="B"/><actuator name="mb"/></transmission>"#, "0")).unwrap();
    let m = load_urdf(&path).unwrap();
    assert_eq!(m.effort_limits(), [0.0, 3.0], "A, with neither a transmission nor an effort limit, is passive");
    assert!(m.notices.iter().any(|n| n.contains("joints 'A' have neither a <transmission> nor an effort limit: passive")), "{:?}", m.notices);
    std::fs::write(&path, model("")).unwrap();
    assert_eq!(load_urdf(&path).unwrap().actuators.len(), 2, "no transmissions: one actuator per joint");
    // a transmission on a joint the URDF does not have: named in a notice, and ignored
    std::fs::write(&path, model(r#"<transmission name="tx"><joint name="Z"/><actuator name="m"/></transmission>"#)).unwrap();
    let m = load_urdf(&path).unwrap();
    assert!(m.notices.iter().any(|n| n.contains("transmission 'tx'") && n.contains("joint 'Z'")), "{:?}", m.notices);
    assert_eq!(m.actuators.len(), 2, "no transmission left: one actuator per joint");
}

#[test]
fn mesh_model_runs_on_the_continuous_plant_with_auto_tuned_gains() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("s.json");
    let out = Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--urdf", mesh_urdf().to_str().unwrap(), "--time-step", "0", "--duration", "2", "--no-rrd", "--no-mcap", "--summary-json", json.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("auto-tuned gains") && stdout.contains("I (kg·m²)"), "{stdout}");
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(doc["summary"]["status"]["state"], "completed");
    assert_eq!(doc["gains"]["source"], "auto-tuned");
    assert_eq!(doc["gains"]["effective_inertia"].as_array().unwrap().len(), 6);
}

/// The gains of the tutorial's rule, which earlier versions auto-tuned with and which the discrete
/// plant cannot hold for this model's light wrist: kp = min(effort/0.05, 0.5·(1.5/dt)²·I),
/// kd = 1.6·√(kp·I), I = M_ii at q = 0 (dt = 1 ms). As `--kp`, `--kd` lists.
fn tutorial_rule_gains(urdf: &std::path::Path) -> (String, String) {
    let model = load_urdf(urdf).unwrap();
    let mut data = armscope::dynamics::Data::new(&model);
    let m = armscope::dynamics::crba(&model, &mut data, &vec![0.0; model.dof()]).clone();
    let effort = model.effort_limits();
    let kp: Vec<f64> = (0..model.dof()).map(|i| (effort[i] / 0.05).min(0.5 * 1500.0f64.powi(2) * m[(i, i)])).collect();
    let kd: Vec<f64> = kp.iter().enumerate().map(|(i, kp)| 1.6 * (kp * m[(i, i)]).sqrt()).collect();
    let list = |v: &[f64]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(",");
    (list(&kp), list(&kd))
}

/// The mesh model with motors that are not clipped (no transmissions, `effort="0"`): the
/// tutorial's gain rule puts the semi-implicit discrete loop of the light wrist joints past
/// stability (|z| ≈ 1.35 per step for one joint alone); within a few steps the joints bang from
/// limit to limit, which the loop reports as divergence.
#[test]
fn discrete_plant_divergence_is_caught_named_and_the_files_are_finished() {
    let dir = tempfile::tempdir().unwrap();
    let (text, meshes) = armscope::meshgen::smallrobotarm();
    let unclipped: String = text
        .lines()
        .filter(|l| !l.contains("transmission") && !l.contains("<type>") && !l.contains("hardwareInterface") && !l.contains("<actuator"))
        .map(|l| match l.find(" effort=") {
            // no effort limit: an unclipped motor
            Some(at) if l.contains("<limit") => format!("{} effort=\"0\" velocity=\"3\"/>", &l[..at]),
            _ => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    let pkg = dir.path().join("smallrobotarm");
    std::fs::create_dir_all(pkg.join("meshes")).unwrap();
    for (name, bytes) in meshes {
        std::fs::write(pkg.join("meshes").join(name), bytes).unwrap();
    }
    let path = pkg.join("unclipped.urdf");
    std::fs::write(&path, unclipped).unwrap();
    let (rrd, mcap) = (dir.path().join("d.rrd"), dir.path().join("d.mcap"));
    let (kp, kd) = tutorial_rule_gains(&path);
    let out = Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--quiet", "--urdf", path.to_str().unwrap(), "--duration", "5", "--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap(), "--kp", &kp, "--kd", &kd])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    let line = stderr.lines().find(|l| l.contains("diverged")).expect("divergence message");
    assert!(line.contains("joint J") && line.contains("t = ") && line.contains("--time-step 0"), "{line}");
    // the recordings are finished up to the divergence
    let bytes = std::fs::read(&mcap).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("MCAP closed properly");
    let done = mcap::read::metadata(&bytes, &summary.metadata_indexes[1]).unwrap();
    assert!(done.metadata["status"].contains("diverged"));
    assert!(rrd.metadata().unwrap().len() > 0);
}

/// The mesh model as specified (clipped motors) on the discrete plant with the tutorial rule's gains:
/// the energy audit catches the numerically unstable plant within milliseconds; the same model on
/// the continuous plant runs on.
#[test]
fn mesh_model_on_the_discrete_plant_is_caught_as_divergent() {
    let dir = tempfile::tempdir().unwrap();
    let (rrd, mcap) = (dir.path().join("m.rrd"), dir.path().join("m.mcap"));
    let (kp, kd) = tutorial_rule_gains(&mesh_urdf());
    let out = Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--quiet", "--urdf", mesh_urdf().to_str().unwrap(), "--duration", "10", "--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap(), "--kp", &kp, "--kd", &kd])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    let line = stderr.lines().find(|l| l.contains("diverged")).expect("divergence message");
    assert!(line.contains("created") && line.contains("J of energy") && line.contains("joint J") && line.contains("--time-step 0"), "{line}");
    let t: f64 = line.split("t = ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!(t < 0.1, "caught at t = {t}");
    let bytes = std::fs::read(&mcap).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("MCAP closed properly");
    assert!(mcap::read::metadata(&bytes, &summary.metadata_indexes[1]).unwrap().metadata["status"].contains("diverged"));
    assert!(rrd.metadata().unwrap().len() > 0);
}
