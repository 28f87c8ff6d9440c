//! Coulomb friction with exact stiction, in both plants: a pendulum that must not move, one that
//! must come to rest where the energy balance puts it, and a 6-joint arm whose every discrete step
//! must equal the exact solution of the box-constrained update, found here independently by trying
//! every stick/slide pattern.

mod common;

use armscope::dynamics::{Data, crba_from_kinematics, forward_kinematics, gravity_and_bias_from_kinematics};
use armscope::model::{Model, load_urdf_str};
use armscope::plant::{ContinuousPlant, DiscretePlant, Plant, Tolerances};
use nalgebra::{DMatrix, DVector};
use std::path::Path;

const MASS: f64 = 1.0;
const LENGTH: f64 = 0.5;

/// A 1 kg point-like mass 0.5 m below a horizontal axis, Coulomb friction `friction` N·m, no damping.
fn pendulum(friction: f64) -> Model {
    let urdf = format!(
        r#"<robot name="pendulum">
  <link name="world"/>
  <link name="bob"><inertial><origin xyz="0 0 -{LENGTH}"/><mass value="{MASS}"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="swing" type="continuous"><parent link="world"/><child link="bob"/><axis xyz="0 1 0"/>
    <dynamics damping="0" friction="{friction}"/></joint>
</robot>"#
    );
    load_urdf_str(&urdf, Path::new("pendulum.urdf")).unwrap()
}

/// m·g·l, the largest torque of the bob's weight.
fn weight_torque(model: &Model) -> f64 {
    MASS * model.gravity.norm() * LENGTH
}

/// Where a pendulum released at rest at `angle` comes to rest: each half swing from a turning
/// point θa ends at the turning point θb where the potential lost equals the friction's work,
/// m·g·l·(cos θb − cos θa) = F·|θa − θb|; it stops at the first turning point where the weight's
/// torque m·g·l·|sin θ| is within F.
fn analytic_rest_angle(mgl: f64, friction: f64, angle: f64) -> f64 {
    let mut a = angle;
    while mgl * a.sin().abs() > friction {
        // by symmetry, swing from |a| > 0 towards negative angles, then mirror
        let (sign, from) = (a.signum(), a.abs());
        let lost = |b: f64| mgl * (b.cos() - from.cos()) - friction * (from - b);
        // the half swing's centre (weight and friction balance) has energy to spare, −from has not
        let (mut lo, mut hi) = (-from, (friction / mgl).asin());
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if lost(mid) < 0.0 { lo = mid } else { hi = mid }
        }
        a = sign * 0.5 * (lo + hi);
    }
    a
}

/// Run the plant from rest at `angle` for `seconds` with no torque; the angle at every 1 ms.
fn release(model: &Model, plant: &mut dyn Plant, angle: f64, seconds: f64) -> Vec<f64> {
    let mut data = Data::new(model);
    let (mut q, mut v, u) = (vec![angle], vec![0.0], vec![0.0]);
    let mut angles = vec![angle];
    for _ in 0..(seconds / 1e-3).round() as usize {
        forward_kinematics(model, &mut data, &q);
        gravity_and_bias_from_kinematics(model, &mut data, &v);
        plant.advance(model, &mut data, &u, &mut q, &mut v);
        angles.push(q[0]);
    }
    angles
}

fn continuous(model: &Model) -> ContinuousPlant {
    ContinuousPlant::new(model, 1e-3, Tolerances { rtol: 1e-11, atol: 1e-13 })
}

#[test]
fn a_pendulum_held_by_its_friction_does_not_move_at_all() {
    // weight's torque at 0.3 rad: 1.45 N·m, friction 1.5 N·m: it sticks, in both plants, exactly
    let model = pendulum(1.5);
    let angle: f64 = 0.3;
    assert!(weight_torque(&model) * angle.sin() < 1.5);
    for (name, mut plant) in [("discrete", Box::new(DiscretePlant::new(&model, 1e-3, 1)) as Box<dyn Plant>), ("continuous", Box::new(continuous(&model)))] {
        let angles = release(&model, plant.as_mut(), angle, 20.0);
        assert!(angles.iter().all(|&a| a == angle), "{name}: the pendulum moved to {}", angles.iter().fold(angle, |m, &a| if (a - angle).abs() > (m - angle).abs() { a } else { m }));
        assert!(plant.stuck()[0], "{name}: not reported stuck");
        // the friction holds exactly the weight's torque, m·g·l·sin θ
        let holding = weight_torque(&model) * angle.sin();
        assert!((plant.friction_torque()[0] - holding).abs() < 1e-12, "{name}: friction {} N·m, weight {holding}", plant.friction_torque()[0]);
    }
}

#[test]
fn a_released_pendulum_comes_to_rest_where_the_energy_balance_puts_it() {
    let friction = 0.4;
    let model = pendulum(friction);
    let mgl = weight_torque(&model);
    for angle in [1.2, -0.9, 2.5] {
        let expected = analytic_rest_angle(mgl, friction, angle);
        assert!(mgl * expected.sin().abs() <= friction);
        // continuous: the swings integrated to 1e-11, each turning point an event — within 1e-6 rad
        let angles = release(&model, &mut continuous(&model), angle, 15.0);
        let rest = *angles.last().unwrap();
        eprintln!("from {angle}: analytic rest {expected:.9}, continuous {:+.2e} rad off", rest - expected);
        assert!((rest - expected).abs() < 1e-6, "continuous from {angle}: rest at {rest}, energy balance {expected} ({:.2e} rad off)", rest - expected);
        // at rest for good: the last second does not move at all
        assert!(angles[angles.len() - 1000..].iter().all(|&a| a == rest), "continuous from {angle}: still creeping");

        // discrete: the 1 ms step's own discretization of the same answer (a few tens of µrad) …
        let mut plant = DiscretePlant::new(&model, 1e-3, 1);
        let angles = release(&model, &mut plant, angle, 15.0);
        let rest = *angles.last().unwrap();
        eprintln!("from {angle}: discrete (h = 1 ms) {:+.2e} rad off", rest - expected);
        // (measured 0.8–1.9 µrad: the 1 ms step's O(h) error in the energy of each swing)
        assert!((rest - expected).abs() < 1e-5, "discrete from {angle}: rest at {rest}, energy balance {expected}");
        assert!(angles[angles.len() - 1000..].iter().all(|&a| a == rest), "discrete from {angle}: still creeping");
        // … and exactly the discrete update's: from each state of the run, v⁺ = sgn(b)·max(|b| − hF,
        // 0)/M and q⁺ = q + h·v⁺ with b = M·v + h·τ_g (one joint: no C·v), written out here
        let mut data = Data::new(&model);
        let mut plant = DiscretePlant::new(&model, 1e-3, 1);
        let (h, mut q, mut v) = (1e-3, vec![angle], vec![0.0]);
        for k in 0..15_000 {
            forward_kinematics(&model, &mut data, &q);
            gravity_and_bias_from_kinematics(&model, &mut data, &v);
            crba_from_kinematics(&model, &mut data);
            let m = data.mass_matrix[(0, 0)];
            let b = m * v[0] + h * data.gravity[0];
            let v_next = b.signum() * (b.abs() - h * friction).max(0.0) / m;
            let q_next = q[0] + h * v_next;
            plant.advance(&model, &mut data, &[0.0], &mut q, &mut v);
            assert!((v[0] - v_next).abs() <= 1e-12 && (q[0] - q_next).abs() <= 1e-15, "discrete from {angle}, step {k}: v⁺ {} q⁺ {} against the scalar update's {v_next} {q_next}", v[0], q[0]);
            assert_eq!(v[0] == 0.0, v_next == 0.0, "step {k}: stuck in one, not the other");
        }
    }
}

/// The box model with Coulomb friction `friction[i]` on joint i.
fn box_model_with_friction(friction: &[f64]) -> Model {
    let text = std::fs::read_to_string(common::box_urdf()).unwrap();
    let mut joint = 0;
    let mut out = String::new();
    for line in text.lines() {
        if line.contains("<dynamics") && line.contains("friction=\"0\"") {
            out += &line.replace("friction=\"0\"", &format!("friction=\"{}\"", friction[joint]));
            joint += 1;
        } else {
            out += line;
        }
        out.push('\n');
    }
    assert_eq!(joint, friction.len(), "the box model's joints each have a <dynamics friction=\"0\"/>");
    load_urdf_str(&out, &common::box_urdf()).unwrap()
}

/// The exact solution of (M + hD)·v⁺ = b + h·τ_f, |τ_f,i| ≤ F_i, τ_f,i = −F_i·sgn(v⁺_i) where
/// v⁺_i ≠ 0, found by trying all 3ⁿ stick/slide patterns (the solution is unique: at most one
/// pattern is consistent, up to ties at the boundary between two).
fn every_pattern(a: &DMatrix<f64>, b: &DVector<f64>, hf: &[f64]) -> DVector<f64> {
    let n = b.len();
    let mut best: Option<(f64, DVector<f64>)> = None;
    for code in 0..3usize.pow(n as u32) {
        // pattern: −1, 0 (stuck), +1 per joint
        let pattern: Vec<i32> = (0..n).map(|i| (code / 3usize.pow(i as u32) % 3) as i32 - 1).collect();
        let free: Vec<usize> = (0..n).filter(|&i| pattern[i] != 0).collect();
        let mut v = DVector::zeros(n);
        if !free.is_empty() {
            let a_ff = DMatrix::from_fn(free.len(), free.len(), |r, c| a[(free[r], free[c])]);
            let rhs = DVector::from_fn(free.len(), |r, _| b[free[r]] - hf[free[r]] * pattern[free[r]] as f64);
            let Some(x) = a_ff.cholesky().map(|c| c.solve(&rhs)) else { continue };
            for (r, &i) in free.iter().enumerate() {
                v[i] = x[r];
            }
        }
        // how far this pattern is from consistent: a sliding joint moving against its direction, a
        // stuck one needing more than its friction
        let g = b - a * &v;
        let mut violation = 0.0_f64;
        for i in 0..n {
            violation = violation.max(match pattern[i] {
                0 => (g[i].abs() - hf[i]).max(0.0),
                s => (-(v[i] * s as f64)).max(0.0),
            });
        }
        if best.as_ref().is_none_or(|(w, _)| violation < *w) {
            best = Some((violation, v));
        }
    }
    let (violation, v) = best.unwrap();
    assert!(violation < 1e-12, "no consistent pattern: best violates by {violation:e}");
    v
}

/// The discrete step's A = M + hD and b = M·v + h·(u + τ_g − C·v) at (q, v), written out from the
/// model's M, τ_g and C·v; `data` is left with the kinematics the plant's step needs.
fn discrete_problem(model: &Model, data: &mut Data, h: f64, q: &[f64], v: &[f64], u: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
    let n = model.dof();
    forward_kinematics(model, data, q);
    gravity_and_bias_from_kinematics(model, data, v);
    crba_from_kinematics(model, data);
    let mut a = data.mass_matrix.clone();
    for i in 0..n {
        a[(i, i)] += h * model.joints[i].damping;
    }
    let b = &data.mass_matrix * DVector::from_column_slice(v) + h * DVector::from_fn(n, |i, _| u[i] + data.gravity[i] - data.bias[i]);
    (a, b)
}

#[test]
fn every_discrete_step_of_an_arm_with_friction_is_the_exact_box_constrained_solution() {
    // friction on all six joints, sized so that along the fall some joints stick while others slide
    // (the shoulder against its weight, the wrist rolls held), and stick–slip changes as it moves
    let friction = [0.3, 1.2, 0.6, 0.05, 0.08, 0.01];
    let model = box_model_with_friction(&friction);
    let n = model.dof();
    let h = 1e-3;
    let mut plant = DiscretePlant::new(&model, h, 1);
    let mut data = Data::new(&model);
    let mut q = vec![0.2, 0.5, -0.6, 0.3, 0.4, 0.0];
    let mut v = vec![0.0; n];
    let u = vec![0.0; n];
    let (mut stuck_steps, mut sliding_steps, mut changes) = (0, 0, 0);
    let mut previous_stuck = vec![false; n];
    for k in 0..600 {
        let (a, b) = discrete_problem(&model, &mut data, h, &q, &v, &u);
        let hf: Vec<f64> = friction.iter().map(|f| h * f).collect();
        let exact = every_pattern(&a, &b, &hf);
        let scale = exact.amax().max(1e-3);
        plant.advance(&model, &mut data, &u, &mut q, &mut v);
        for i in 0..n {
            assert!((v[i] - exact[i]).abs() <= 1e-12 * scale, "step {k}, joint {i}: v⁺ = {} against the exact {}", v[i], exact[i]);
            assert!(!plant.limit_active()[i], "step {k}: joint {i} reached a limit; the pattern search has none");
            let stuck = plant.stuck()[i];
            if stuck {
                assert_eq!(v[i], 0.0, "step {k}: joint {i} stuck but moving");
                stuck_steps += 1;
            } else {
                sliding_steps += 1;
            }
            changes += (stuck != previous_stuck[i]) as usize;
            previous_stuck[i] = stuck;
        }
    }
    // the test is only as good as its mix: both kinds of joint, and stick–slip transitions
    assert!(stuck_steps > 300 && sliding_steps > 300 && changes >= 4, "stuck {stuck_steps}, sliding {sliding_steps} joint-steps, {changes} changes");
}

#[test]
fn without_friction_the_discrete_step_is_the_frictionless_update() {
    // F = 0 everywhere: v⁺ = (M + hD)⁻¹ b, as before friction existed (bit for bit: no friction
    // law is set up, and the solve is the plain one)
    let model = box_model_with_friction(&[0.0; 6]);
    let n = model.dof();
    let h = 1e-3;
    let mut plant = DiscretePlant::new(&model, h, 1);
    let mut data = Data::new(&model);
    let (mut q, mut v, u) = (vec![0.2, 0.5, -0.6, 0.3, 0.4, 0.0], vec![0.1; 6], vec![0.0; 6]);
    for _ in 0..100 {
        let (a, b) = discrete_problem(&model, &mut data, h, &q, &v, &u);
        let want = a.cholesky().unwrap().solve(&b);
        plant.advance(&model, &mut data, &u, &mut q, &mut v);
        for i in 0..n {
            assert!((v[i] - want[i]).abs() <= 1e-12 * want.amax(), "joint {i}");
        }
        assert!(plant.friction_torque().iter().all(|&f| f == 0.0) && plant.friction_work() == 0.0);
    }
}

fn run_summary(urdf: &str, extra: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let (path, json) = (dir.path().join("arm.urdf"), dir.path().join("s.json"));
    std::fs::write(&path, urdf).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--quiet", "--no-rrd", "--no-mcap", "--urdf", path.to_str().unwrap(), "--summary-json", json.to_str().unwrap()])
        .args(extra)
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

#[test]
fn the_energy_audit_books_the_friction_and_balances() {
    // the box model released from a pose with friction on every joint (no torque): the arm falls,
    // sticks and slips; its mechanical energy must fall by exactly the work booked (damping and
    // friction), up to the step's own error
    let text = std::fs::read_to_string(common::box_urdf()).unwrap().replace("friction=\"0\"", "friction=\"0.4\"");
    let doc = run_summary(&text, &["--static", "--kp", "0", "--kd", "0", "--no-ff", "--q0", "0.2,0.5,-0.6,0.3,0.4,0", "--duration", "5"]);
    let s = &doc["summary"];
    let (created, work) = (s["energy_balance"]["created"].as_f64().unwrap(), s["energy_balance"]["work"].as_f64().unwrap());
    // 0.3 % of the work measured without friction on this fall; the same bar with it
    assert!(work > 0.1 && created.abs() < 0.01 * work, "created {created} J against {work} J of work");
    let stuck: Vec<f64> = s["stuck_percent"].as_array().unwrap().iter().map(|p| p.as_f64().unwrap()).collect();
    assert!(stuck.iter().any(|&p| p > 50.0) && stuck.iter().any(|&p| p < 50.0), "some joints stick, some move: {stuck:?}");
    // and --friction 0 runs the same URDF without any
    let doc = run_summary(&text, &["--static", "--kp", "0", "--kd", "0", "--no-ff", "--q0", "0.2,0.5,-0.6,0.3,0.4,0", "--duration", "1", "--friction", "0"]);
    assert!(doc["summary"].get("stuck_percent").is_none(), "no friction, no stuck series");
}

#[test]
fn an_arm_starts_on_its_command() {
    // the SO-100 (example-robot-data): its default wave's command used to start 0.5 rad away from
    // the arm, and the shoulder's PD spiked to 20 N·m catching up, on a joint whose motion needs
    // 0.25. Now the command starts at the arm, at rest: no saturation anywhere, and no joint's torque
    // over the run exceeds what the motion itself asks after the first second by more than a third
    let text = std::fs::read_to_string(common::repo().join("tests/fixtures/robots/so100.urdf")).unwrap();
    let doc = run_summary(&text, &["--duration", "10"]);
    let s = &doc["summary"];
    for j in 0..s["joints"].as_array().unwrap().len() {
        let name = s["joints"][j].as_str().unwrap();
        let (whole, after) = (s["peak_abs_torque"][j].as_f64().unwrap(), s["peak_abs_torque_after_settle"][j].as_f64().unwrap());
        assert_eq!(s["saturation_percent"][j].as_f64().unwrap(), 0.0, "{name} saturates");
        assert!(whole <= 1.34 * after + 0.01, "{name}: peak {whole} N·m over the run, {after} after the first second");
    }
    assert!(doc["command"].as_str().unwrap().contains("brought in from the start pose"), "{}", doc["command"]);
}
