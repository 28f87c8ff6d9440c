//! The trajectory lab: IK schedules that put the tool within 0.5 mm of every target (checked by
//! forward kinematics, independently of the IK), file formats, and following a schedule.

mod common;

use armscope::dynamics::{Data, forward_kinematics, frame_pose};
use armscope::control::ik::{Shape, default_drawing, solve_drawing};
use armscope::model::load_urdf;
use armscope::control::trajectory::{JointSchedule, Trajectory};
use common::{armscope, read_csv, repo};

#[test]
fn every_schedule_point_puts_the_tool_within_half_a_millimetre_of_its_target() {
    for urdf in ["assets/smallrobot_arm.urdf", "assets/smallrobotarm/smallrobotarm.urdf"] {
        let model = load_urdf(&repo().join(urdf)).unwrap();
        let mut data = Data::new(&model);
        for shape in [Shape::Sine, Shape::Circle, Shape::Triangle] {
            let drawing = default_drawing(&model, shape);
            let (times, positions, targets) = solve_drawing(&model, &drawing, vec![0, 1, 2], 10.0, 0.01).unwrap();
            assert_eq!(times.len(), 1001);
            for (q, target) in positions.iter().zip(&targets) {
                assert_eq!(&q[3..], &vec![0.0; model.dof() - 3][..], "wrist locked at 0");
                forward_kinematics(&model, &mut data, q);
                let p = frame_pose(&model, &data, model.tool_frame).translation;
                assert!((p - target).norm() < 0.5e-3, "{urdf} {shape:?}: {:.3e} m", (p - target).norm());
                // the target lies on the drawing plane, within the shape's size of its centre
                assert!((target.x - drawing.centre.x).abs() < 1e-12 && (target - drawing.centre).norm() <= drawing.size * 1.0001);
            }
        }
    }
}

#[test]
fn trajectory_command_writes_csv_and_npy_that_run_follows() {
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("circle");
    assert_eq!(armscope(&["trajectory", "circle", "--duration", "2", "--step", "0.02", "--out", prefix.to_str().unwrap()]), 0);
    let csv = read_csv(&prefix.with_extension("csv"));
    assert_eq!(csv.header, ["t", "q1", "q2", "q3", "q4", "q5", "q6"]);
    assert_eq!(csv.rows.len(), 101);
    let model = load_urdf(&common::box_urdf()).unwrap();
    let from_csv = JointSchedule::load(&prefix.with_extension("csv"), 6).unwrap();
    let from_npy = JointSchedule::load(&prefix.with_extension("npy"), 6).unwrap();
    assert_eq!(from_csv.times, from_npy.times);
    for k in 0..from_csv.times.len() {
        assert_eq!(from_csv.row(k), from_npy.row(k), "CSV and .npy hold the same schedule (row {k})");
    }
    // following it: the command passes through the schedule's points
    let trace = dir.path().join("trace.csv");
    assert_eq!(armscope(&["run", "--quiet", "--trajectory", prefix.with_extension("npy").to_str().unwrap(), "--duration", "2", "--trace", trace.to_str().unwrap()]), 0);
    let t = read_csv(&trace);
    for (k, row) in csv.rows.iter().enumerate().step_by(10) {
        let step = (row[0] / 0.001).round() as usize;
        for j in 1..=6 {
            let cmd = t.rows[step][t.col(&format!("cmd{j}"))];
            assert!((cmd - row[j]).abs() < 1e-12, "row {k} joint {j}: {cmd} vs {}", row[j]);
        }
    }
    let _ = model;
    // a schedule with the wrong number of joints is refused with the file named
    let short = dir.path().join("short.csv");
    std::fs::write(&short, "t,q1,q2\n0,0,0\n1,0.1,0.2\n").unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--trajectory", short.to_str().unwrap(), "--no-rrd", "--no-mcap"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--trajectory") && err.contains("short.csv") && err.contains("columns"), "{err}");
    // an unreachable shape is a clear error
    assert_eq!(armscope(&["trajectory", "circle", "--centre", "2,0,0.2", "--out", prefix.to_str().unwrap()]), 2);
}

#[test]
fn schedule_velocity_command_is_the_derivative_of_the_position_command() {
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("sine");
    assert_eq!(armscope(&["trajectory", "sine", "--duration", "4", "--out", prefix.to_str().unwrap()]), 0);
    let s = JointSchedule::load(&prefix.with_extension("csv"), 6).unwrap();
    let (mut q, mut qd, mut a, mut b, mut tmp) = (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
    for t in [0.5, 1.2345, 2.0, 3.9] {
        s.sample(t, &mut q, &mut qd);
        s.sample(t + 1e-6, &mut a, &mut tmp);
        s.sample(t - 1e-6, &mut b, &mut tmp);
        for j in 0..6 {
            assert!((qd[j] - (a[j] - b[j]) / 2e-6).abs() < 1e-4 * (1.0 + qd[j].abs()), "t {t} joint {j}");
        }
    }
}
