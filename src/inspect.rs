//! `armscope model`: what armscope made of a URDF — its joints, bodies, actuators and notices —
//! and, for given states, the dynamics quantities by joint name (M, τ_g, C·v, q̈ with and without
//! damping, every link's world pose), so that any other library can be compared with it.

use crate::dynamics::{Data, aba, bias_forces, crba, forward_kinematics, frame_pose, gravity_forces};
use crate::error::Error;
use crate::model::{JointKind, Model};
use serde::Deserialize;
use serde_json::{Value, json};
use std::collections::BTreeMap;

/// One state, by joint name (joints not named are 0).
#[derive(Debug, Default, Deserialize)]
pub struct State {
    #[serde(default)]
    pub q: BTreeMap<String, f64>,
    #[serde(default)]
    pub v: BTreeMap<String, f64>,
    #[serde(default)]
    pub tau: BTreeMap<String, f64>,
}

/// The model as a JSON document: joints (kind, axis, limits, effort, damping, the mass they move),
/// actuators, the tool link, notices.
pub fn describe(model: &Model) -> Value {
    let kind = |k: JointKind| match k {
        JointKind::Revolute => "revolute",
        JointKind::Continuous => "continuous",
        JointKind::Prismatic => "prismatic",
    };
    let finite = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
    json!({
        "name": model.name,
        "source": model.source,
        "dof": model.dof(),
        "joints": model.joints.iter().map(|j| json!({
            "name": j.name, "kind": kind(j.kind), "child_link": j.child_link, "axis": [j.axis.x, j.axis.y, j.axis.z],
            "lower": finite(j.lower), "upper": finite(j.upper), "effort": finite(j.effort), "damping": j.damping, "friction": j.friction, "body_mass": j.inertia.mass,
        })).collect::<Vec<_>>(),
        "actuators": model.actuators.iter().map(|a| json!({ "name": a.name, "joint": model.joints[a.joint].name, "effort": finite(a.effort), "gear_ratio": a.gear_ratio, "rotor_inertia": a.rotor_inertia, "reflected_inertia": a.reflected_inertia() })).collect::<Vec<_>>(),
        "links": model.frames.len(),
        "tool_link": model.frames[model.tool_frame].name,
        "notices": model.notices,
    })
}

/// The dynamics at each state: `M` (rows and columns in `joints` order), `tau_g`, `Cv`,
/// `qdd_no_damping` (= M⁻¹(τ + τ_g − C·v)), `qdd_with_damping` (− D·v inside), and `link_poses`
/// (link name → [x, y, z, qx, qy, qz, qw] in the world).
pub fn dynamics_at(model: &Model, states: &[State]) -> Result<Value, Error> {
    let n = model.dof();
    let index = |map: &BTreeMap<String, f64>, what: &str| -> Result<Vec<f64>, Error> {
        let mut out = vec![0.0; n];
        for (name, &value) in map {
            let j = model.joint_index(name).ok_or_else(|| Error::flag("--states", format!("{what}: no moving joint '{name}'")))?;
            out[j] = value;
        }
        Ok(out)
    };
    let mut data = Data::new(model);
    let mut results = Vec::new();
    for s in states {
        let (q, v, tau) = (index(&s.q, "q")?, index(&s.v, "v")?, index(&s.tau, "tau")?);
        let m = crba(model, &mut data, &q).clone();
        let tau_g = gravity_forces(model, &mut data, &q).to_vec();
        let cv = bias_forces(model, &mut data, &q, &v).to_vec();
        let qdd = aba(model, &mut data, &q, &v, &tau).to_vec();
        let damped: Vec<f64> = tau.iter().zip(&v).zip(&model.joints).map(|((t, v), j)| t - j.damping * v).collect();
        let qdd_damped = aba(model, &mut data, &q, &v, &damped).to_vec();
        forward_kinematics(model, &mut data, &q);
        let poses: BTreeMap<&str, [f64; 7]> = (0..model.frames.len())
            .map(|f| {
                let p = frame_pose(model, &data, f);
                let [x, y, z, w] = p.quaternion_xyzw();
                (model.frames[f].name.as_str(), [p.translation.x, p.translation.y, p.translation.z, x, y, z, w])
            })
            .collect();
        results.push(json!({
            "M": (0..n).map(|i| m.row(i).iter().copied().collect::<Vec<f64>>()).collect::<Vec<_>>(),
            "tau_g": tau_g, "Cv": cv, "qdd_no_damping": qdd, "qdd_with_damping": qdd_damped, "link_poses": poses,
        }));
    }
    // the rotors' reflected inertia is in M's diagonal (no URDF field holds it): given beside it
    Ok(json!({ "joints": model.joints.iter().map(|j| &j.name).collect::<Vec<_>>(), "armature": model.armature, "states": results }))
}

/// The model for people: one line per joint.
pub fn table(model: &Model) -> String {
    let w = model.joints.iter().map(|j| j.name.chars().count()).max().unwrap_or(5).max(5) + 2;
    let mut out = format!("{} ({}): {} moving joints, {} links, tool link '{}'\n", model.name, model.source.display(), model.dof(), model.frames.len(), model.frames[model.tool_frame].name);
    out += &format!("  {:<w$}{:<12}{:>22}{:>12}{:>10}{:>10}{:>12}{:>8}{:>14}\n", "joint", "kind", "range", "effort", "damping", "friction", "body (kg)", "ratio", "rotor J_r·N²");
    let efforts = model.effort_limits();
    for (i, j) in model.joints.iter().enumerate() {
        let range = if j.lower.is_finite() || j.upper.is_finite() { format!("[{:.3}, {:.3}]", j.lower, j.upper) } else { "unlimited".into() };
        let effort = if model.is_actuated(i) { format!("{}", efforts[i]) } else { "passive".into() };
        let kind = format!("{:?}", j.kind).to_lowercase();
        let ratio = model.actuators.iter().find(|a| a.joint == i).map_or(String::from("–"), |a| format!("{}", a.gear_ratio));
        out += &format!("  {:<w$}{:<12}{:>22}{:>12}{:>10}{:>10}{:>12.4}{:>8}{:>14.4e}\n", j.name, kind, range, effort, j.damping, j.friction, j.inertia.mass, ratio, model.armature[i]);
    }
    out
}
