//! Controller gains: the tutorial's for its box model, otherwise tuned from the mass matrix.

use crate::dynamics::{Data, crba};
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
    /// Effective inertia per joint (M_ii at the start pose) when auto-tuned.
    pub effective_inertia: Option<Vec<f64>>,
}

/// Whether this is the tutorial's box model, whose gains are known.
pub fn is_tutorial_model(model: &Model) -> bool {
    model.name == "smallrobot_arm"
        && model.dof() == 6
        && model.joints.iter().enumerate().all(|(i, j)| j.name == format!("J{}", i + 1))
}

/// The tutorial's rule: with I the effective inertia at the start pose,
/// kp = min(effort/0.05, 0.5·(1.5/dt)²·I) and kd = 1.6·√(kp·I).
pub fn auto_tune(model: &Model, q_start: &[f64], dt: f64) -> Gains {
    let mut data = Data::new(model);
    let m = crba(model, &mut data, q_start);
    let inertia: Vec<f64> = (0..model.dof()).map(|i| m[(i, i)]).collect();
    let effort = model.effort_limits();
    let kp: Vec<f64> = inertia
        .iter()
        .zip(&effort)
        .map(|(&i, &e)| (e / 0.05).min(0.5 * (1.5 / dt).powi(2) * i))
        .collect();
    let kd = kp.iter().zip(&inertia).map(|(&kp, &i)| 1.6 * (kp * i).sqrt()).collect();
    Gains { kp, kd, source: "auto-tuned".into(), effective_inertia: Some(inertia) }
}
