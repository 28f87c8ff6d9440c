//! What a replay says about one log: the position error against the measurement (BAM's MAE),
//! where the simulation parts from it, and the PWM duty the firmware gave against the measured one.

use super::log::BenchLog;
use super::replay::Rollout;
use serde::Serialize;

/// |simulated − measured| above which the two are said to have parted, rad.
pub const PARTING: f64 = 0.05;

/// One log's result.
#[derive(Clone, Debug, Serialize)]
pub struct LogResult {
    pub log: String,
    pub name: String,
    pub kp: f64,
    pub trajectory: Option<String>,
    pub rows: usize,
    pub dt: f64,
    /// Mean |q_sim − q_measured| over every row, rad.
    pub mae_rad: f64,
    /// The largest gap and when, s.
    pub max_error_rad: f64,
    pub max_error_time: f64,
    /// The first time the gap exceeded [`PARTING`], s (None: never).
    pub parts_at: Option<f64>,
    /// Mean |d_sim − d_measured| over the rows with a measured PWM (None: not logged).
    pub duty_mae: Option<f64>,
    /// The fraction of rows at full duty (within 1 %), measured and simulated.
    pub saturated_measured: Option<f64>,
    pub saturated_simulated: f64,
    /// The measured supply's range, V (None: not logged).
    pub volts_measured: Option<(f64, f64)>,
    /// The largest current the simulated motor drew, A.
    pub peak_current: f64,
}

impl LogResult {
    pub fn of(log: &BenchLog, rollout: &Rollout, max_duty: f64) -> Self {
        let errors: Vec<f64> = rollout.position.iter().zip(&log.entries).map(|(s, e)| s - e.position).collect();
        let (mut max_error, mut max_error_time) = (0.0_f64, 0.0);
        for (e, entry) in errors.iter().zip(&log.entries) {
            if e.abs() > max_error {
                (max_error, max_error_time) = (e.abs(), entry.time);
            }
        }
        let parts_at = errors.iter().zip(&log.entries).find(|(e, _)| e.abs() > PARTING).map(|(_, entry)| entry.time);
        let measured_duty: Vec<(f64, f64)> = log.entries.iter().zip(&rollout.duty).filter_map(|(e, &d)| e.duty.map(|m| (m, d))).collect();
        let full = |d: f64| d.abs() >= 0.99 * max_duty;
        let duty_mae = (!measured_duty.is_empty()).then(|| measured_duty.iter().map(|(m, d)| (m - d).abs()).sum::<f64>() / measured_duty.len() as f64);
        let saturated_measured = (!measured_duty.is_empty()).then(|| measured_duty.iter().filter(|(m, _)| full(*m)).count() as f64 / measured_duty.len() as f64);
        let volts: Vec<f64> = log.entries.iter().filter_map(|e| e.volts).collect();
        let volts_measured = (!volts.is_empty()).then(|| (volts.iter().copied().fold(f64::INFINITY, f64::min), volts.iter().copied().fold(f64::NEG_INFINITY, f64::max)));
        Self {
            log: log.path.display().to_string(),
            name: log.name(),
            kp: log.kp,
            trajectory: log.trajectory.clone(),
            rows: log.entries.len(),
            dt: log.dt,
            mae_rad: rollout.mae(log),
            max_error_rad: max_error,
            max_error_time,
            parts_at,
            duty_mae,
            saturated_measured,
            saturated_simulated: rollout.duty.iter().filter(|&&d| full(d)).count() as f64 / rollout.duty.len().max(1) as f64,
            volts_measured,
            peak_current: rollout.current.iter().fold(0.0_f64, |m, c| m.max(c.abs())),
        }
    }

    /// One line for people.
    pub fn line(&self, width: usize) -> String {
        let parts = match self.parts_at {
            Some(t) => format!("parts at {t:.2} s"),
            None => "never parts".to_string(),
        };
        let duty = match (self.duty_mae, self.saturated_measured) {
            (Some(mae), Some(sat)) => format!("duty off by {:.1} % (full duty: measured {:.0} %, simulated {:.0} % of the time)", 100.0 * mae, 100.0 * sat, 100.0 * self.saturated_simulated),
            _ => format!("PWM not logged (simulated at full duty {:.0} % of the time)", 100.0 * self.saturated_simulated),
        };
        format!("  {:<width$} MAE {:>7.2} mrad   largest {:>6.1} mrad at {:>5.2} s, {parts}; {duty}", self.name, 1e3 * self.mae_rad, 1e3 * self.max_error_rad, self.max_error_time)
    }
}

/// Every log's result and the mean MAE, as `--summary-json` writes it.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub params: String,
    pub step: super::replay::Step,
    pub supply: super::replay::Supply,
    pub logs: Vec<LogResult>,
    pub mean_mae_rad: f64,
}

impl Summary {
    pub fn new(params: String, options: &super::ReplayOptions, logs: Vec<LogResult>) -> Self {
        let mean_mae_rad = logs.iter().map(|l| l.mae_rad).sum::<f64>() / logs.len().max(1) as f64;
        Self { params, step: options.step, supply: options.supply, logs, mean_mae_rad }
    }

    /// The table for people.
    pub fn table(&self) -> String {
        let width = self.logs.iter().map(|l| l.name.chars().count()).max().unwrap_or(4);
        let mut out = String::new();
        for l in &self.logs {
            out += &l.line(width);
            out.push('\n');
        }
        out += &format!("  mean MAE over {} logs: {:.2} mrad\n", self.logs.len(), 1e3 * self.mean_mae_rad);
        out
    }
}
