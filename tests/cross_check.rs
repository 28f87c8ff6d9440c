//! Algorithms checked against each other on random trees (serial and branched, revolute,
//! continuous, prismatic and fixed joints, arbitrary origins), not only the box model:
//! ABA = M⁻¹(τ + τ_g − C q̇) with M from CRBA and τ_g, C q̇ from RNEA; RNEA(q, q̇, ABA(τ)) = τ;
//! ½ q̇ᵀ M q̇ equals the bodies' kinetic energy; the Jacobian equals the derivative of forward
//! kinematics; the poses-only kinematics equals the full one.

mod common;

use armscope::dynamics::{Data, aba, bias_forces, body_poses, crba, forward_kinematics, frame_jacobian, frame_pose, frame_pose_in, frame_vertical_jacobian, gravity_and_bias_from_kinematics, gravity_forces, kinetic_energy, kinetic_energy_from_momenta, kinetic_energy_from_velocities, rnea};
use armscope::model::load_urdf_str;
use common::random_tree::{tree, urdf};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use std::path::Path;


fn state(n: usize) -> impl Strategy<Value = (Vec<f64>, Vec<f64>, Vec<f64>)> {
    (
        prop::collection::vec(-3.0..3.0f64, n),
        prop::collection::vec(-3.0..3.0f64, n),
        prop::collection::vec(-5.0..5.0f64, n),
    )
}

fn case() -> impl Strategy<Value = (String, (Vec<f64>, Vec<f64>, Vec<f64>))> {
    tree(9).prop_flat_map(|links| {
        let n = links.iter().filter(|l| l.kind != "fixed").count();
        (Just(urdf(&links)), state(n))
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, .. ProptestConfig::default() })]

    #[test]
    fn aba_equals_inverse_mass_matrix_times_forces((text, (q, v, tau)) in case()) {
        let model = load_urdf_str(&text, Path::new("random.urdf")).expect("generated URDF loads");
        let n = model.dof();
        let mut data = Data::new(&model);
        let m = crba(&model, &mut data, &q).clone();
        prop_assert!((&m - m.transpose()).abs().max() < 1e-12, "M symmetric");
        let g = DVector::from_vec(gravity_forces(&model, &mut data, &q).to_vec());
        let cv = DVector::from_vec(bias_forces(&model, &mut data, &q, &v).to_vec());
        let rhs = DVector::from_vec(tau.clone()) + g - cv;
        let expected = m.clone().cholesky().expect("M positive definite").solve(&rhs);
        let qdd = DVector::from_vec(aba(&model, &mut data, &q, &v, &tau).to_vec());
        // relative to the size of the answer: M is well conditioned for these bodies, so 1e-8 is round-off
        let scale = expected.abs().max().max(1.0);
        prop_assert!((&qdd - &expected).abs().max() <= 1e-8 * scale, "ABA {qdd} vs M⁻¹(τ − bias) {expected}");
        prop_assert_eq!(qdd.len(), n);
    }

    #[test]
    fn rnea_inverts_aba((text, (q, v, tau)) in case()) {
        let model = load_urdf_str(&text, Path::new("random.urdf")).unwrap();
        let mut data = Data::new(&model);
        let qdd = aba(&model, &mut data, &q, &v, &tau).to_vec();
        let back = rnea(&model, &mut data, &q, &v, &qdd).to_vec();
        let scale = tau.iter().chain(&back).fold(1.0f64, |a, b| a.max(b.abs()));
        for (b, t) in back.iter().zip(&tau) {
            prop_assert!((b - t).abs() <= 1e-9 * scale, "RNEA(ABA(τ)) = {back:?}, τ = {tau:?}");
        }
    }

    #[test]
    fn kinetic_energy_from_mass_matrix_equals_sum_over_bodies((text, (q, v, _tau)) in case()) {
        let model = load_urdf_str(&text, Path::new("random.urdf")).unwrap();
        let mut data = Data::new(&model);
        let m = crba(&model, &mut data, &q).clone();
        let vd = DVector::from_vec(v.clone());
        let from_m = 0.5 * vd.dot(&(&m * &vd));
        let from_bodies = kinetic_energy(&model, &mut data, &q, &v);
        prop_assert!((from_m - from_bodies).abs() <= 1e-10 * from_m.abs().max(1.0), "½q̇ᵀMq̇ {from_m} vs bodies {from_bodies}");
        // and from the velocities RNEA's forward pass leaves
        rnea(&model, &mut data, &q, &v, &vec![0.0; v.len()]);
        let after_rnea = kinetic_energy_from_velocities(&model, &data, &v);
        prop_assert!((from_m - after_rnea).abs() <= 1e-10 * from_m.abs().max(1.0));
        // and from the momenta the simulation loop's gravity-and-bias pass leaves: the same
        // products summed in the same order, so the same bits (the energy audit relies on it)
        forward_kinematics(&model, &mut data, &q);
        gravity_and_bias_from_kinematics(&model, &mut data, &v);
        let (from_momenta, from_velocities) = (kinetic_energy_from_momenta(&model, &data, &v), kinetic_energy_from_velocities(&model, &data, &v));
        prop_assert_eq!(from_momenta.to_bits(), from_velocities.to_bits());
    }

    #[test]
    fn poses_only_kinematics_equals_forward_kinematics((text, (q, _v, _tau)) in case()) {
        let model = load_urdf_str(&text, Path::new("random.urdf")).unwrap();
        let mut data = Data::new(&model);
        forward_kinematics(&model, &mut data, &q);
        let mut poses = vec![armscope::spatial::Pose::identity(); model.dof()];
        body_poses(&model, &q, &mut poses);
        for f in 0..model.frames.len() {
            let (a, b) = (frame_pose(&model, &data, f), frame_pose_in(&model, &poses, f));
            prop_assert!(a.translation == b.translation && a.rotation == b.rotation, "frame {f}");
        }
    }

    #[test]
    fn jacobian_is_the_derivative_of_forward_kinematics((text, (q, v, _tau)) in case()) {
        let model = load_urdf_str(&text, Path::new("random.urdf")).unwrap();
        let mut data = Data::new(&model);
        let n = model.dof();
        let tool = model.tool_frame;
        forward_kinematics(&model, &mut data, &q);
        let mut jac = DMatrix::zeros(6, n);
        frame_jacobian(&model, &data, tool, &mut jac);
        // the floor contact's vertical row alone is that row of the Jacobian, bit for bit
        let mut vertical = vec![f64::NAN; n];
        frame_vertical_jacobian(&model, &data, tool, &frame_pose(&model, &data, tool).translation, &mut vertical);
        for (c, z) in vertical.iter().enumerate() {
            prop_assert_eq!(z.to_bits(), jac[(5, c)].to_bits(), "coordinate {}", c);
        }
        let twist = &jac * DVector::from_vec(v.clone());
        let eps = 1e-6;
        let at = |s: f64, data: &mut Data| {
            let qs: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q + s * v).collect();
            forward_kinematics(&model, data, &qs);
            frame_pose(&model, data, tool)
        };
        let (plus, minus) = (at(eps, &mut data), at(-eps, &mut data));
        let velocity = (plus.translation - minus.translation) / (2.0 * eps);
        // ω from the rotation change: (R₊ − R₋)/2ε · Rᵀ is skew(ω)
        let dr = (plus.rotation - minus.rotation) / (2.0 * eps) * ((plus.rotation + minus.rotation) * 0.5).transpose();
        let omega = nalgebra::Vector3::new(dr[(2, 1)], dr[(0, 2)], dr[(1, 0)]);
        for r in 0..3 {
            prop_assert!((twist[r] - omega[r]).abs() < 1e-5, "angular row {r}: {} vs {}", twist[r], omega[r]);
            prop_assert!((twist[r + 3] - velocity[r]).abs() < 1e-5, "linear row {r}: {} vs {}", twist[r + 3], velocity[r]);
        }
    }
}

#[test]
fn box_model_aba_equals_inverse_mass_matrix_at_many_states() {
    let model = armscope::model::load_urdf(&common::box_urdf()).unwrap();
    let mut data = Data::new(&model);
    for k in 0..200 {
        let x = k as f64;
        let q: Vec<f64> = (0..6).map(|i| (x * 0.37 + i as f64 * 1.3).sin() * 2.0).collect();
        let v: Vec<f64> = (0..6).map(|i| (x * 0.11 + i as f64 * 0.7).cos() * 3.0).collect();
        let tau: Vec<f64> = (0..6).map(|i| (x * 0.23 - i as f64).sin() * 4.0).collect();
        let m = crba(&model, &mut data, &q).clone();
        let g = DVector::from_vec(gravity_forces(&model, &mut data, &q).to_vec());
        let cv = DVector::from_vec(bias_forces(&model, &mut data, &q, &v).to_vec());
        let expected = m.cholesky().unwrap().solve(&(DVector::from_vec(tau.clone()) + g - cv));
        let qdd = aba(&model, &mut data, &q, &v, &tau);
        for i in 0..6 {
            assert!((qdd[i] - expected[i]).abs() <= 1e-9 * expected[i].abs().max(1.0), "state {k} joint {i}");
        }
    }
}
