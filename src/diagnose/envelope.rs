//! The speed envelope: sweep the wave's frequency and amplitude and find, per joint, where the
//! torque the motion needs exceeds the motor's limit. The need is the inverse dynamics of the
//! commanded motion (RNEA on cmd, cmd_dot, cmd_ddot, plus damping): what a perfect controller
//! must supply, free of any chatter. Every cell is also simulated with the given (stable) gains,
//! reporting real saturation and chatter alongside.

use crate::config::RunConfig;
use crate::control::demand::need;
use crate::error::Error;
use crate::experiment::Experiment;
use crate::model::Model;
use crate::sim::simulate;
use rayon::prelude::*;
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct Cell {
    pub freq: f64,
    pub amp_deg: f64,
    /// Peak |torque| the commanded motion needs, per joint, N·m.
    pub required: Vec<f64>,
    /// The largest share of the torque available at that instant the motion needs, per joint: above
    /// 1 the motor runs out. With `--motors` the limit falls with speed; otherwise need / effort.
    pub demand: Vec<f64>,
    /// From the simulation with the given gains: saturation and chatter shares, %.
    pub saturation_percent: Vec<f64>,
    pub chatter_percent: Vec<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Envelope {
    pub joints: Vec<String>,
    pub effort: Vec<f64>,
    pub freqs: Vec<f64>,
    pub amps_deg: Vec<f64>,
    pub payload_kg: f64,
    pub kp: Vec<f64>,
    pub kd: Vec<f64>,
    /// Row-major: amplitude index × frequency index.
    pub cells: Vec<Cell>,
}

/// Sweep the grid. `base` supplies the gains, the payload and everything else; `model` is the
/// model as loaded. Each cell runs for the settle time plus one period of the wave (at most 30 s).
pub fn sweep(base: &RunConfig, model: &Model, freqs: &[f64], amps_deg: &[f64], jobs: usize) -> Result<Envelope, Error> {
    let cells_in: Vec<(f64, f64)> = amps_deg.iter().flat_map(|&a| freqs.iter().map(move |&f| (f, a))).collect();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs.max(1)).build().map_err(|e| Error::flag("--jobs", e.to_string()))?;
    let first = Experiment::with_model(base.clone(), model.clone())?;
    let effort = first.controller().effort;
    // the model as the runs see it (with `--motors`, their rotors in M) and the limit at a speed
    let dynamics_model = first.model.clone();
    let motors = first.motors.clone();
    let limit = |j: usize, torque: f64, speed: f64| match motors.as_ref().and_then(|m| m.joints[j].as_ref()) {
        Some(drive) => drive.available(torque, speed),
        None => effort[j],
    };
    let cells: Result<Vec<Cell>, Error> = pool.install(|| {
        cells_in
            .par_iter()
            .map(|&(freq, amp_deg)| {
                let duration = (base.settle_time + 2.0 * std::f64::consts::PI / freq.abs().max(1e-3)).min(30.0);
                let config = RunConfig { freq, amp_deg, wave_as_asked: true, duration, hold: false, test_joint: None, trajectory: None, ..base.clone() };
                let experiment = Experiment::with_model(config, model.clone())?;
                // the command the run follows (the tutorial's wave on its box model, fitted to the
                // joint ranges on any other arm)
                let (required, demand) = need(&dynamics_model, experiment.trajectory.as_ref(), duration, base.dt, &limit);
                let summary = simulate(&experiment, &mut [], None)?;
                Ok(Cell { freq, amp_deg, required, demand, saturation_percent: summary.saturation_percent, chatter_percent: summary.chatter_percent })
            })
            .collect()
    });
    Ok(Envelope {
        joints: model.joints.iter().map(|j| j.name.clone()).collect(),
        effort,
        freqs: freqs.to_vec(),
        amps_deg: amps_deg.to_vec(),
        payload_kg: base.payload,
        kp: first.gains.kp.clone(),
        kd: first.gains.kd.clone(),
        cells: cells?,
    })
}

impl Envelope {
    pub fn cell(&self, a: usize, f: usize) -> &Cell {
        &self.cells[a * self.freqs.len() + f]
    }

    /// Per joint: the fastest frequency at each amplitude whose need stays within the limit.
    pub fn boundary(&self, joint: usize) -> Vec<Option<f64>> {
        (0..self.amps_deg.len())
            .map(|a| (0..self.freqs.len()).filter(|&f| self.cell(a, f).demand[joint] <= 1.0).map(|f| self.freqs[f]).fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x)))))
            .collect()
    }

    /// Markdown table: per joint the torque needed at a reference cell and at the worst cell,
    /// against the limit; margin = limit / need (how much the gear ratio could shrink, or must grow).
    pub fn table(&self, reference: (f64, f64)) -> String {
        let (ri, rf) = (nearest(&self.amps_deg, reference.1), nearest(&self.freqs, reference.0));
        let r = self.cell(ri, rf);
        let mut md = format!(
            "| joint | limit (N·m) | needed at ω = {} rad/s, A = {}° (N·m) | margin there | worst cell need (N·m) | margin at worst |\n|---|---|---|---|---|---|\n",
            r.freq, r.amp_deg
        );
        for (j, name) in self.joints.iter().enumerate() {
            let worst = self.cells.iter().map(|c| c.required[j]).fold(0.0, f64::max);
            let margin = |need: f64| if need > 0.0 { format!("{:.2}×", self.effort[j] / need) } else { "∞".into() };
            md += &format!("| {name} | {} | {:.3} | {} | {worst:.3} | {} |\n", self.effort[j], r.required[j], margin(r.required[j]), margin(worst));
        }
        md
    }
}

fn nearest(values: &[f64], x: f64) -> usize {
    (0..values.len()).min_by(|&a, &b| (values[a] - x).abs().total_cmp(&(values[b] - x).abs())).unwrap_or(0)
}
