//! What `armscope analyze` reports about a sampled control loop, and its presentation: the spectral
//! radius at a pose (and along the command), the joints that drive an instability, the largest
//! stable control period, and derivative gains that would make it stable — as text or JSON.

use crate::control::sampled_loop::{Linearization, LoopPlant, largest_stable_period, spectral_radius, stabilizing_kd_over, worst_radius};
use crate::experiment::Experiment;
use serde_json::{Value, json};
use std::path::Path;

/// The loop of `experiment` (its model and gains) analysed at `poses` (the first is the reported
/// pose; the others, e.g. along the command, enter the worst radius and the suggested kd).
pub struct LoopReport {
    pub model: String,
    pub pose: Vec<f64>,
    pub poses: usize,
    pub dt: f64,
    pub plant: LoopPlant,
    pub feed_forward: bool,
    pub gains_source: String,
    pub kp: Vec<f64>,
    pub kd: Vec<f64>,
    pub spectral_radius: f64,
    /// Per joint, its share of the dominant mode.
    pub participation: Vec<(String, f64)>,
    pub worst_radius: f64,
    pub largest_stable_dt: Option<f64>,
    pub stable_kd: Vec<f64>,
    pub stable_kd_radius: f64,
    /// The command that runs the loop with the suggested kd.
    pub run_hint: String,
    /// The joints with friction (the URDF's, or a gearbox's losses) and what it is: the
    /// linearization leaves it out.
    pub friction_left_out: Vec<(String, String)>,
}

impl LoopReport {
    /// `motors`: the motor file the experiment has (the loop then runs as `run --motors FILE --drive pd`).
    pub fn new(experiment: &Experiment, urdf: &Path, motors: Option<&Path>, poses: &[Vec<f64>], dt: f64, feed_forward: bool, plant: LoopPlant) -> Self {
        let model = &*experiment.model;
        let (kp, kd) = experiment.controller().effective_gains();
        let lins: Vec<Linearization> = poses.iter().map(|p| Linearization::at(model, p)).collect();
        let (rho, participation) = spectral_radius(&lins[0].closed_loop(&kp, &kd, dt, feed_forward, plant));
        let largest_stable_dt = largest_stable_period(&lins[0], &kp, &kd, dt, feed_forward, plant);
        let worst = worst_radius(&lins, &kp, &kd, dt, feed_forward, plant);
        let (stable_kd, stable_kd_radius) = stabilizing_kd_over(&lins, &kp, &kd, dt, feed_forward, plant);
        let kd_list = stable_kd.iter().map(|k| format!("{k:.4}")).collect::<Vec<_>>().join(",");
        let run_hint = format!(
            "armscope run --urdf {}{}{} --kp {} --kd {kd_list}{}",
            urdf.display(),
            motors.map_or(String::new(), |m| format!(" --motors {} --drive pd", m.display())),
            if plant == LoopPlant::Continuous { " --time-step 0" } else { "" },
            kp.iter().map(|k| format!("{k}")).collect::<Vec<_>>().join(","),
            if dt != 0.001 { format!(" --dt {dt}") } else { String::new() }
        );
        Self {
            model: model.name.clone(),
            pose: poses[0].clone(),
            poses: poses.len(),
            dt,
            plant,
            feed_forward,
            gains_source: experiment.gains.source.clone(),
            participation: model.joints.iter().map(|j| j.name.clone()).zip(participation).collect(),
            kp,
            kd,
            spectral_radius: rho,
            worst_radius: worst,
            largest_stable_dt,
            stable_kd,
            stable_kd_radius,
            run_hint,
            friction_left_out: friction_left_out(experiment),
        }
    }

    pub fn stable(&self) -> bool {
        self.spectral_radius < 1.0
    }

    pub fn to_json(&self, urdf: &Path) -> Value {
        let fixes = self.stable_kd_radius < 1.0;
        json!({
            "model": self.model, "urdf": urdf, "pose": self.pose, "dt": self.dt, "plant": self.plant, "feed_forward": self.feed_forward,
            "kp": self.kp, "kd": self.kd, "gains": self.gains_source,
            "spectral_radius": self.spectral_radius, "stable": self.stable(),
            "poses": self.poses, "worst_spectral_radius_over_poses": self.worst_radius,
            "participation": self.participation.iter().cloned().collect::<std::collections::BTreeMap<_, _>>(),
            "largest_stable_dt": self.largest_stable_dt,
            "stable_kd": if fixes { Some(&self.stable_kd) } else { None },
            "stable_kd_spectral_radius": self.stable_kd_radius,
            "run_with_stable_kd": fixes.then_some(&self.run_hint),
            "friction_left_out": self.friction_left_out.iter().cloned().collect::<std::collections::BTreeMap<_, _>>(),
        })
    }

    /// For people: what the loop does and what to change.
    pub fn text(&self) -> String {
        let (rho, h) = (self.spectral_radius, self.dt);
        let plant = match self.plant {
            LoopPlant::Discrete => "discrete",
            LoopPlant::Continuous => "continuous",
        };
        let mut out = format!("sampled closed loop of {} at pose {:?}, dt = {} ms, {plant} plant, gains {}:\n", self.model, self.pose, h * 1e3, self.gains_source);
        out += &format!("  kp = {:?}\n  kd = {:?}\n", self.kp, self.kd);
        if self.stable() {
            out += &format!("  spectral radius {rho:.3}: STABLE (a small disturbance decays by {rho:.3}× per control step)\n");
        } else {
            out += &format!("  spectral radius {rho:.3}: UNSTABLE (a small disturbance grows {rho:.2}× per control step, until the torque limits clip it into chatter)\n");
            let mut drivers = self.participation.clone();
            drivers.sort_by(|a, b| b.1.total_cmp(&a.1));
            out += &format!("  driven by: {}\n", drivers.iter().filter(|d| d.1 > 0.02).map(|(n, p)| format!("{n} {:.0}%", 100.0 * p)).collect::<Vec<_>>().join(", "));
        }
        if self.poses > 1 {
            out += &format!("  worst spectral radius over {} poses along the wave: {:.3}\n", self.poses, self.worst_radius);
        }
        out += &match self.largest_stable_dt {
            Some(d) if d >= h => "  these gains are stable at this dt\n".to_string(),
            Some(d) => format!("  largest stable dt for these gains: {:.4} ms (run with --dt {:.6})\n", d * 1e3, d),
            None => "  these gains are unstable even at 1 µs\n".to_string(),
        };
        let kd_list = self.stable_kd.iter().map(|k| format!("{k:.4}")).collect::<Vec<_>>().join(",");
        if self.stable_kd_radius < 1.0 {
            out += &format!("  stable derivative gains at dt = {} ms (kp unchanged): kd = [{kd_list}], spectral radius {:.3}\n", h * 1e3, self.stable_kd_radius);
            out += &format!("  run with them: {}\n", self.run_hint);
        } else {
            out += &format!("  no kd scaling makes this loop stable at dt = {} ms (best spectral radius {:.3}): lower kp or dt\n", h * 1e3, self.stable_kd_radius);
        }
        if !self.friction_left_out.is_empty() {
            out += &format!(
                "  left out: friction on {} — Coulomb friction is not linear: the run can stick where this loop moves, and a small oscillation it predicts can be held still\n",
                self.friction_left_out.iter().map(|(j, what)| format!("{j} ({what})")).collect::<Vec<_>>().join(", ")
            );
        }
        out
    }
}

/// Per joint with friction: its name and what the friction is (the URDF's F, the gearbox's losses).
fn friction_left_out(experiment: &Experiment) -> Vec<(String, String)> {
    let gears = experiment.gears();
    experiment
        .model
        .joints
        .iter()
        .zip(&gears)
        .filter_map(|(joint, gear)| {
            let mut parts = Vec::new();
            if joint.friction > 0.0 {
                parts.push(format!("{} N·m", joint.friction));
            }
            if let Some(g) = gear.filter(|g| !g.is_lossless()) {
                let backdrive = if g.self_locking() { "self-locking".to_string() } else { format!("η_b {}", g.backdrive_efficiency) };
                parts.push(format!("gear η {}, {backdrive}, breakaway {} N·m", g.efficiency, g.breakaway_torque));
            }
            (!parts.is_empty()).then(|| (joint.name.clone(), parts.join("; ")))
        })
        .collect()
}
