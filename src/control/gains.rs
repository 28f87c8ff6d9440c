//! Controller gains: the tutorial's for its box model, otherwise tuned from the mass matrix.

use crate::diagnose::analysis::{Linearization, LoopPlant, worst_radius};
use crate::model::Model;
use serde::Serialize;

/// The tutorial's gains for the SmallRobotArm box model (J1..J6).
pub const TUTORIAL_KP: [f64; 6] = [200.0, 300.0, 200.0, 120.0, 80.0, 30.0];
pub const TUTORIAL_KD: [f64; 6] = [12.0, 10.0, 4.5, 1.3, 0.4, 0.1];

#[derive(Clone, Debug, Serialize)]
pub struct Gains {
    pub kp: Vec<f64>,
    pub kd: Vec<f64>,
    /// Where they came from: "tutorial", "flags", "auto-tuned", or a mix.
    pub source: String,
    /// Effective inertia per joint (the smallest M_ii along the command) when auto-tuned.
    pub effective_inertia: Option<Vec<f64>>,
    /// The worst spectral radius of the sampled loop along the command, when auto-tuned.
    pub spectral_radius: Option<f64>,
}

/// Whether this is the tutorial's box model, whose gains are known.
pub fn is_tutorial_model(model: &Model) -> bool {
    model.name == "smallrobot_arm"
        && model.dof() == 6
        && model.joints.iter().enumerate().all(|(i, j)| j.name == format!("J{}", i + 1))
}

/// The loop's bandwidth to start from, per control period: ω_n·dt = 0.1 (poles near e^−0.1 ≈ 0.9).
const START_BANDWIDTH_PER_STEP: f64 = 0.1;
/// The gain margin: the loop must stay stable with both gains this many times larger (6 dB), so
/// that an arm a little lighter than its URDF, or a pose between the ones checked, is still stable.
pub const GAIN_MARGIN: f64 = 2.0;
/// How far the commanded error may go before the motor saturates: kp ≤ effort / this (rad or m).
const SATURATION_ERROR: f64 = 0.05;

/// Gains for any arm, stable for the sampled loop along the commanded motion with a margin. With
/// I_i the smallest M_ii over `poses` (the loop of joint i is fastest there), D_i its damping and a
/// bandwidth ω: kp_i = min(effort_i/0.05, I_i·ω² + D_i·ω), kd_i = 2·√(kp_i·I_i), starting at
/// ω = 0.1/dt; the sampled loop (plant, zero-order hold, damping, coupling through M) is linearized
/// at every pose as `armscope analyze` does, and ω is lowered by 0.7× until the loop with both
/// gains doubled is still stable at every pose (a gain margin of 2), or no less stable than with
/// them halved (what is unstable then is the plant's own, e.g. a passive joint that falls).
pub fn auto_tune(model: &Model, poses: &[Vec<f64>], dt: f64, feed_forward: bool, plant: LoopPlant) -> Gains {
    let n = model.dof();
    let lins: Vec<Linearization> = poses.iter().map(|q| Linearization::at(model, q)).collect();
    let inertia: Vec<f64> = (0..n).map(|i| lins.iter().map(|l| l.mass[(i, i)]).fold(f64::INFINITY, f64::min)).collect();
    let effort = model.effort_limits();
    let gains_at = |omega: f64| -> (Vec<f64>, Vec<f64>) {
        // I·ω² puts the loop at ω; D·ω does the same where the joint's damping dominates its inertia
        let kp: Vec<f64> = (0..n)
            .map(|i| if effort[i] > 0.0 { (effort[i] / SATURATION_ERROR).min(inertia[i] * omega * omega + model.joints[i].damping * omega) } else { 0.0 })
            .collect();
        let kd = kp.iter().zip(&inertia).map(|(&kp, &i)| 2.0 * (kp * i).sqrt()).collect();
        (kp, kd)
    };
    let scaled = |v: &[f64]| v.iter().map(|x| x * GAIN_MARGIN).collect::<Vec<_>>();
    let mut omega = START_BANDWIDTH_PER_STEP / dt;
    let (mut kp, mut kd) = gains_at(omega);
    let halved = |v: &[f64]| v.iter().map(|x| x / GAIN_MARGIN).collect::<Vec<_>>();
    for _ in 0..30 {
        let doubled = worst_radius(&lins, &scaled(&kp), &scaled(&kd), dt, feed_forward, plant);
        // stable with the margin; or what is unstable is not the controller's doing (a passive joint
        // falling, a mode the gains do not reach): larger gains make it no worse than smaller ones
        if doubled < 1.0 || doubled <= worst_radius(&lins, &halved(&kp), &halved(&kd), dt, feed_forward, plant) + 1e-9 {
            break;
        }
        omega *= 0.7;
        (kp, kd) = gains_at(omega);
    }
    let rho = worst_radius(&lins, &kp, &kd, dt, feed_forward, plant);
    Gains { kp, kd, source: "auto-tuned".into(), effective_inertia: Some(inertia), spectral_radius: Some(rho) }
}
