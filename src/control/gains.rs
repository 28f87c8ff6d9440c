//! Controller gains: the tutorial's for its box model, otherwise tuned from the mass matrix.

use crate::control::sampled_loop::{Linearization, LoopPlant, modes_over, worst_radius};
use crate::model::Model;
use serde::Serialize;

/// The tutorial's gains for the SmallRobotArm box model (J1..J6).
pub const TUTORIAL_KP: [f64; 6] = [200.0, 300.0, 200.0, 120.0, 80.0, 30.0];
pub const TUTORIAL_KD: [f64; 6] = [12.0, 10.0, 4.5, 1.3, 0.4, 0.1];

#[derive(Clone, Debug, Serialize)]
pub struct Gains {
    pub kp: Vec<f64>,
    pub kd: Vec<f64>,
    /// Where they came from: "tutorial", "flags", "auto-tuned", a mix, or [`NO_PD_JOINT`].
    pub source: String,
    /// Effective inertia per joint (the smallest M_ii along the command) when auto-tuned.
    pub effective_inertia: Option<Vec<f64>>,
    /// The worst spectral radius of the sampled loop along the command, when auto-tuned.
    pub spectral_radius: Option<f64>,
    /// Per joint, when auto-tuned: the loop's bandwidth ω (rad/s) and damping ratio ζ.
    pub bandwidth: Option<Vec<f64>>,
    pub damping_ratio: Option<Vec<f64>>,
}

/// The source of the gains of a run whose every actuated joint is driven by its servo's firmware
/// or an open-loop stepper: the PD controller drives none, so none are tuned.
pub const NO_PD_JOINT: &str = "none: every joint is driven by its servo's firmware or a stepper";

impl Gains {
    /// No gains, for a run whose PD controller drives no joint ([`NO_PD_JOINT`]).
    pub fn no_pd_joint(n: usize) -> Self {
        Self { kp: vec![0.0; n], kd: vec![0.0; n], source: NO_PD_JOINT.into(), effective_inertia: None, spectral_radius: None, bandwidth: None, damping_ratio: None }
    }

    /// Whether the PD controller drives any joint with these gains.
    pub fn drives_a_joint(&self) -> bool {
        self.source != NO_PD_JOINT
    }
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

/// How many times the bandwidths may be lowered in all: each lowering takes one or more joints 0.7×
/// (from 100 rad/s at 1 kHz to 2.8 rad/s is ten).
const MAX_LOWERINGS: usize = 60;
/// A joint takes part in an unstable mode when its share is at least this fraction of the largest.
const PART_OF_MODE: f64 = 0.25;
/// The least damping ratio the derivative gain is lowered to before the bandwidth is.
const MIN_DAMPING_RATIO: f64 = 0.25;

/// Gains for any arm, stable for the sampled loop along the commanded motion with a margin. With
/// I_i the smallest M_ii over `poses` (the loop of joint i is fastest there), D_i its damping, a
/// bandwidth ω_i and a damping ratio ζ_i: kp_i = min(effort_i/0.05, I_i·ω_i² + D_i·ω_i),
/// kd_i = 2·ζ_i·√(kp_i·I_i), starting at ω_i = 0.1/dt, ζ_i = 1. The sampled loop (plant, zero-order
/// hold, damping, coupling through M) is linearized at every pose as `armscope analyze` does, and
/// while the loop with both gains doubled is unstable at some pose (a gain margin of 2), the joints
/// that take part in its unstable modes (all of them at once: a large tree has several) — only
/// they: a wrist at its singularity (two roll axes aligned, a light link between them) must be
/// soft, the head and the fingers need not be — get 0.7× the damping ratio (down to 0.25) if that
/// makes the loop more stable, else 0.7× the bandwidth. It stops when the loop is stable with the
/// margin, or no less stable than with the gains halved (what is unstable then is the plant's own,
/// e.g. a passive joint that falls).
pub fn auto_tune(model: &Model, poses: &[Vec<f64>], dt: f64, feed_forward: bool, plant: LoopPlant) -> Gains {
    let n = model.dof();
    let lins: Vec<Linearization> = poses.iter().map(|q| Linearization::at(model, q)).collect();
    let inertia: Vec<f64> = (0..n).map(|i| lins.iter().map(|l| l.mass[(i, i)]).fold(f64::INFINITY, f64::min)).collect();
    let effort = model.effort_limits();
    let gains_at = |omega: &[f64], zeta: &[f64]| -> (Vec<f64>, Vec<f64>) {
        // I·ω² puts the loop at ω; D·ω does the same where the joint's damping dominates its inertia
        let kp: Vec<f64> = (0..n)
            .map(|i| if effort[i] > 0.0 { (effort[i] / SATURATION_ERROR).min(inertia[i] * omega[i] * omega[i] + model.joints[i].damping * omega[i]) } else { 0.0 })
            .collect();
        let kd = (0..n).map(|i| 2.0 * zeta[i] * (kp[i] * inertia[i]).sqrt()).collect();
        (kp, kd)
    };
    let scaled = |v: &[f64], factor: f64| v.iter().map(|x| x * factor).collect::<Vec<_>>();
    // the loop with both gains doubled: its worst radius, and the joints of every mode unstable at
    // some pose (a large tree has several at once: Centauro's four legs and two arms)
    let with_margin = |kp: &[f64], kd: &[f64]| -> (f64, Vec<usize>) {
        let (radius, modes) = modes_over(&lins, &scaled(kp, GAIN_MARGIN), &scaled(kd, GAIN_MARGIN), dt, feed_forward, plant, 1.0);
        let mut joints: Vec<usize> = Vec::new();
        for (_, shares) in modes.iter().filter(|(z, _)| *z >= 1.0) {
            let driven = |i: &usize| kp[*i] > 0.0;
            let largest = (0..n).filter(driven).map(|i| shares[i]).fold(0.0, f64::max);
            joints.extend((0..n).filter(driven).filter(|&i| largest > 0.0 && shares[i] >= PART_OF_MODE * largest));
        }
        joints.sort_unstable();
        joints.dedup();
        (radius, joints)
    };
    let mut omega = vec![START_BANDWIDTH_PER_STEP / dt; n];
    let mut zeta = vec![1.0; n];
    let (mut kp, mut kd) = gains_at(&omega, &zeta);
    let (mut doubled, mut in_modes) = with_margin(&kp, &kd);
    for _ in 0..MAX_LOWERINGS {
        // stable with the margin; or what is unstable is not the controller's doing (a passive joint
        // falling, a mode the gains do not reach): larger gains make it no worse than smaller ones
        if doubled < 1.0 || doubled <= worst_radius(&lins, &scaled(&kp, 1.0 / GAIN_MARGIN), &scaled(&kd, 1.0 / GAIN_MARGIN), dt, feed_forward, plant) + 1e-9 {
            break;
        }
        // modes on joints without a motor, made unstable by the others' gains: lower them all
        let lowered: Vec<usize> = if in_modes.is_empty() { (0..n).filter(|&i| kp[i] > 0.0).collect() } else { in_modes.clone() };
        // first less damping (a light mode between two joints is destabilized by the sampled
        // derivative term, while stiffness is what tracks), if that helps; else less bandwidth
        if lowered.iter().any(|&i| zeta[i] > MIN_DAMPING_RATIO) {
            let mut softer = zeta.clone();
            for &i in &lowered {
                softer[i] = (softer[i] * 0.7).max(MIN_DAMPING_RATIO);
            }
            let (kp_s, kd_s) = gains_at(&omega, &softer);
            let (radius, modes) = with_margin(&kp_s, &kd_s);
            if radius < doubled - 1e-9 {
                (zeta, kp, kd, doubled, in_modes) = (softer, kp_s, kd_s, radius, modes);
                continue;
            }
        }
        for &i in &lowered {
            omega[i] *= 0.7;
        }
        (kp, kd) = gains_at(&omega, &zeta);
        (doubled, in_modes) = with_margin(&kp, &kd);
    }
    let rho = worst_radius(&lins, &kp, &kd, dt, feed_forward, plant);
    Gains { kp, kd, source: "auto-tuned".into(), effective_inertia: Some(inertia), spectral_radius: Some(rho), bandwidth: Some(omega), damping_ratio: Some(zeta) }
}
