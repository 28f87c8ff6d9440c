//! The parts carry their own weight (issue 21 item 2): a drive train's motor and reductions are
//! bodies on the arm — on the parent link of their joint at its origin by default, on another link
//! where the motor file mounts them, nowhere when the URDF already has them — and `model --urdf-out`
//! writes that arm as a URDF any library loads.

mod common;

use armscope::actuator::{carried, load_motor_file};
use armscope::dynamics::{Data, crba, gravity_forces};
use armscope::model::{Model, load_urdf};
use std::path::{Path, PathBuf};

const G: f64 = 9.81;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The box model with the motor file's drive trains installed, as `run --motors` simulates it.
fn with_motors(motors: &Path) -> Model {
    let mut model = load_urdf(&common::box_urdf()).unwrap();
    let set = load_motor_file(motors, &model).unwrap();
    carried::install(&mut model, &set).unwrap();
    model
}

/// Deterministic states within the box model's limits.
fn states(n: usize, count: usize) -> Vec<Vec<f64>> {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count).map(|_| (0..n).map(|_| 4.0 * next() - 2.0).collect()).collect()
}

const MOTORS: &str = "[joints.J2]\nmotor = \"17HS19-2004S1\"\nreduction = \"NPS015\"\ngear_ratio = 10\n\n\
[joints.J3]\nmotor = \"17HS4401\"\ngear_ratio = 15\n\n\
[joints.J4]\nmotor = \"XM430-W350\"\n\n\
[joints.J5]\nmotor = \"17HS4401\"\ngear_ratio = 5\nmount_link = \"forearm_link\"\nmount_xyz = [0.1, 0.0, 0.03]\n";

/// `model --motors F --urdf-out X`: X, loaded as any URDF, has the mass matrix (with the rotors'
/// armature, which no URDF field holds, added to its diagonal) and the gravity torques armscope
/// simulates with F, to 1e-12 at 20 states; its mass is the URDF's plus every drive train's.
#[test]
fn the_written_urdf_holds_the_masses_armscope_simulates() {
    let dir = tempfile::tempdir().unwrap();
    let motors = write(dir.path(), "motors.toml", MOTORS);
    let out = dir.path().join("with_parts.urdf");
    let code = armscope::cli::main_with_args(["armscope", "model", "--urdf", common::box_urdf().to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--urdf-out", out.to_str().unwrap()]);
    assert_eq!(code, 0);
    let simulated = with_motors(&motors);
    let written = load_urdf(&out).unwrap();
    let plain = load_urdf(&common::box_urdf()).unwrap();
    // 17HS19-2004S1 0.39 + NPS015 1.8 + 17HS4401 0.28 + XM430-W350 0.082 + 17HS4401 0.28
    let drive_mass = 0.39 + 1.8 + 0.28 + 0.082 + 0.28;
    assert!((written.frames_mass() - plain.frames_mass() - drive_mass).abs() < 1e-12, "{} vs {} + {drive_mass}", written.frames_mass(), plain.frames_mass());
    let (mut a, mut b) = (Data::new(&simulated), Data::new(&written));
    for q in states(6, 20) {
        let m_sim = crba(&simulated, &mut a, &q).clone();
        let mut m_written = crba(&written, &mut b, &q).clone();
        for (i, j) in simulated.armature.iter().enumerate() {
            m_written[(i, i)] += j;
        }
        assert!((&m_sim - &m_written).amax() < 1e-12, "M differs by {:e} at {q:?}", (&m_sim - &m_written).amax());
        let (g_sim, g_written) = (gravity_forces(&simulated, &mut a, &q).to_vec(), gravity_forces(&written, &mut b, &q).to_vec());
        for (x, y) in g_sim.iter().zip(&g_written) {
            assert!((x - y).abs() < 1e-12, "τ_g {g_sim:?} vs {g_written:?}");
        }
    }
}

/// At the box model's zero pose (the upper arm level along x), a 17HS4401 (0.28 kg) on J3 sits on
/// the upper arm at J3's origin, 0.22 m out from J2: J2's gravity torque grows by exactly
/// 0.28·g·0.22 and J1's and J3's do not change (it is not beyond J3, and J1's axis is vertical).
/// Mounted on the forearm 0.1 m out instead, it loads J3 by 0.28·g·0.1 and J2 by 0.28·g·0.32.
/// With `in_urdf` nothing changes but the rotor on M's diagonal.
#[test]
fn a_motor_weighs_on_the_joints_it_rides_beyond() {
    let dir = tempfile::tempdir().unwrap();
    let plain = load_urdf(&common::box_urdf()).unwrap();
    let q = vec![0.0; 6];
    let tau = |model: &Model| gravity_forces(model, &mut Data::new(model), &q).to_vec();
    let base = tau(&plain);
    let m = 0.28;
    let at_joint = tau(&with_motors(&write(dir.path(), "a.toml", "[joints.J3]\nmotor = \"17HS4401\"\n")));
    assert!(((at_joint[1] - base[1]).abs() - m * G * 0.22).abs() < 1e-12, "J2: {} → {}", base[1], at_joint[1]);
    assert!((at_joint[0] - base[0]).abs() < 1e-12 && (at_joint[2] - base[2]).abs() < 1e-12);
    let mounted = tau(&with_motors(&write(dir.path(), "b.toml", "[joints.J3]\nmotor = \"17HS4401\"\nmount_link = \"forearm_link\"\nmount_xyz = [0.1, 0, 0]\n")));
    assert!(((mounted[2] - base[2]).abs() - m * G * 0.1).abs() < 1e-12 && ((mounted[1] - base[1]).abs() - m * G * 0.32).abs() < 1e-12);
    let in_urdf = with_motors(&write(dir.path(), "c.toml", "in_urdf = true\n[joints.J3]\nmotor = \"17HS4401\"\n"));
    assert_eq!(tau(&in_urdf), base);
    assert_eq!(in_urdf.armature[2], 5.4e-6, "the rotor is still on M's diagonal");
}

/// A motor with a NEMA frame and a length is a solid cylinder along its joint's axis: about the
/// axis m·r²/2, across m·(3r² + L²)/12 (r from the frame's 1.7-inch flange, L the body length).
#[test]
fn a_stepper_is_a_solid_cylinder_along_its_axis() {
    let catalogue = armscope::actuator::Catalogue::load(&common::repo().join("assets/motors/catalogue.toml")).unwrap();
    let drive = catalogue.drive_train("17HS4401").unwrap().unwrap();
    let part = &drive.parts[0];
    let (d, l) = part.cylinder.unwrap();
    assert!((d - 1.7 * 0.0254).abs() < 1e-15 && (l - 0.040).abs() < 1e-15);
    let i = part.inertia(&nalgebra::Vector3::y());
    let r2 = (d / 2.0) * (d / 2.0);
    assert!((i.inertia_com[(1, 1)] - 0.28 * r2 / 2.0).abs() < 1e-18);
    assert!((i.inertia_com[(0, 0)] - 0.28 * (3.0 * r2 + l * l) / 12.0).abs() < 1e-18 && i.inertia_com[(0, 0)] == i.inertia_com[(2, 2)]);
    let servo = catalogue.drive_train("XM430-W350").unwrap().unwrap();
    assert_eq!(servo.parts[0].cylinder, None, "no published dimensions: a point mass");
    let geared = catalogue.drive_train("17HS4401").unwrap().unwrap().then_reduction(catalogue.reduction("NPS015").unwrap(), 5.0).unwrap();
    assert!((geared.mass() - (0.28 + 1.8)).abs() < 1e-15, "the motor and its reduction");
}

/// Bad mounts get one line naming the file, the joint and the field.
#[test]
fn bad_mounts_name_the_joint_and_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&common::box_urdf()).unwrap();
    for (text, field) in [("mount_xyz = [0, 0]\nmount_link = \"forearm_link\"\n", "mount_xyz"), ("mount_xyz = [0, 0, 0]\n", "mount_xyz"), ("in_urdf = 1\n", "in_urdf"), ("in_urdf = true\nmount_link = \"forearm_link\"\n", "in_urdf")] {
        let path = write(dir.path(), "bad.toml", &format!("[joints.J3]\nmotor = \"17HS4401\"\n{text}"));
        let e = load_motor_file(&path, &model).unwrap_err().to_string();
        assert!(!e.contains('\n') && e.contains("bad.toml") && e.contains("joint 'J3'") && e.contains(field), "{text}: {e}");
    }
    let path = write(dir.path(), "nolink.toml", "[joints.J3]\nmotor = \"17HS4401\"\nmount_link = \"nowhere\"\n");
    let config = armscope::config::RunConfig { motors: Some(path), duration: 0.1, ..Default::default() };
    let e = armscope::experiment::Experiment::prepare(config).err().expect("refused").to_string();
    assert!(!e.contains('\n') && e.contains("nolink.toml") && e.contains("'nowhere'") && e.contains("J3"), "{e}");
}
