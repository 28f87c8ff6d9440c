//! What `armscope catalogue` shows: every motor and reduction with its main numbers, where they were
//! read, and what each entry lacks and what that means for sizing.

use crate::actuator::Catalogue;
use crate::actuator::catalogue::number;
use serde::Serialize;
use toml::Value;

#[derive(Debug, Serialize)]
pub struct MotorRow {
    pub name: String,
    pub kind: String,
    /// Torque at rest at its output, N·m (stepper: holding; servo, dc: stall or peak).
    pub torque_at_rest: f64,
    /// Where its torque runs out or bends: no-load speed (servo, dc) or the pull-out corner (stepper), rad/s.
    pub speed: Option<f64>,
    pub continuous_torque: Option<f64>,
    pub rotor_inertia: Option<f64>,
    pub mass: Option<f64>,
    pub thermal_model: bool,
    /// Where its numbers were read; None: the user's own.
    pub source: Option<String>,
    /// What it lacks, and what follows.
    pub lacks: Vec<&'static str>,
}

#[derive(Debug, Serialize)]
pub struct ReductionRow {
    pub name: String,
    pub kind: String,
    pub ratios: Vec<f64>,
    pub efficiency: Option<f64>,
    /// Per ratio: the peak in the normal cycle (the repeated peak, or the rated torque where none), N·m.
    pub peak_torque: Option<Vec<f64>>,
    pub rated_torque: Option<Vec<f64>>,
    pub max_input_speed: Option<f64>,
    pub mass: Option<f64>,
    pub source: Option<String>,
    pub lacks: Vec<&'static str>,
}

#[derive(Debug, Serialize)]
pub struct Listing {
    pub file: String,
    pub motors: Vec<MotorRow>,
    pub reductions: Vec<ReductionRow>,
}

impl Catalogue {
    /// Every entry as a row (the catalogue was checked at load, so each motor builds).
    pub fn listing(&self) -> Listing {
        let mut motors = Vec::new();
        for (name, t) in &self.entries {
            let Some(Ok(drive)) = self.drive_train(name) else { continue };
            let kind = t.get("kind").and_then(Value::as_str).unwrap_or("").to_string();
            let speed = match drive.motor.as_stepper() {
                Some(s) => s.corner_speed_rev_s().map(|rev_s| rev_s * std::f64::consts::TAU),
                None => number(t, "no_load_speed"),
            };
            let mut lacks = Vec::new();
            if number(t, "mass").is_none() {
                lacks.push("mass (not sized by default)");
            }
            if number(t, "rotor_inertia").is_none() {
                lacks.push("rotor inertia (not reflected at the joint)");
            }
            if drive.continuous_torque.is_none() && kind != "stepper" {
                lacks.push("continuous rating (not RMS-checked)");
            }
            if drive.heat.is_none() {
                lacks.push("thermal model (not thermally checked)");
            }
            motors.push(MotorRow {
                name: name.clone(),
                kind,
                torque_at_rest: drive.torque_limit(0.0),
                speed,
                continuous_torque: drive.continuous_torque,
                rotor_inertia: number(t, "rotor_inertia"),
                mass: number(t, "mass"),
                thermal_model: drive.heat.is_some(),
                source: t.get("source").and_then(Value::as_str).map(str::to_string),
                lacks,
            });
        }
        let reductions = self
            .reductions
            .values()
            .map(|r| ReductionRow {
                name: r.name.clone(),
                kind: r.kind.clone(),
                ratios: r.ratios.clone(),
                efficiency: r.efficiency,
                peak_torque: r.repeated_peak_torque.clone().or(r.rated_torque.clone()),
                rated_torque: r.rated_torque.clone(),
                max_input_speed: r.max_input_speed,
                mass: r.mass,
                source: r.source.clone(),
                lacks: r.lacks(),
            })
            .collect();
        Listing { file: self.source.display().to_string(), motors, reductions }
    }
}

fn or_dash(x: Option<f64>, f: impl Fn(f64) -> String) -> String {
    x.map_or("–".into(), f)
}

fn list(v: &Option<Vec<f64>>) -> String {
    match v {
        None => "–".into(),
        Some(v) if v.windows(2).all(|w| w[0] == w[1]) => format!("{}", v[0]),
        Some(v) => v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("/"),
    }
}

impl Listing {
    /// For people: a table of motors, one of reductions, each row's source and what it lacks.
    pub fn table(&self) -> String {
        let mut out = format!("{} motors, {} reductions ({})\n\nMotors\n", self.motors.len(), self.reductions.len(), self.file);
        let w = self.motors.iter().map(|m| m.name.chars().count()).max().unwrap_or(4).max(5) + 2;
        out += &format!("  {:<w$}{:<9}{:>10}{:>11}{:>11}{:>12}{:>8}{:>9}\n", "name", "kind", "rest N·m", "speed r/s", "cont. N·m", "rotor kg·m²", "kg", "thermal");
        for m in &self.motors {
            out += &format!(
                "  {:<w$}{:<9}{:>10.3}{:>11}{:>11}{:>12}{:>8}{:>9}\n",
                m.name,
                m.kind,
                m.torque_at_rest,
                or_dash(m.speed, |x| format!("{x:.1}")),
                or_dash(m.continuous_torque, |x| format!("{x:.3}")),
                or_dash(m.rotor_inertia, |x| format!("{x:.2e}")),
                or_dash(m.mass, |x| format!("{x:.3}")),
                if m.thermal_model { "yes" } else { "–" }
            );
        }
        let w = self.reductions.iter().map(|r| r.name.chars().count()).max().unwrap_or(4).max(5) + 2;
        out += &format!("\nReductions\n  {:<w$}{:<12}{:<20}{:>6}{:>24}{:>22}{:>9}{:>7}\n", "name", "kind", "ratios", "η", "peak N·m", "rated N·m", "max rpm", "kg");
        for r in &self.reductions {
            let ratios = r.ratios.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(", ");
            out += &format!(
                "  {:<w$}{:<12}{:<20}{:>6}{:>24}{:>22}{:>9}{:>7}\n",
                r.name,
                r.kind,
                ratios,
                or_dash(r.efficiency, |x| format!("{x}")),
                list(&r.peak_torque),
                list(&r.rated_torque),
                or_dash(r.max_input_speed, |x| format!("{:.0}", x * 60.0 / std::f64::consts::TAU)),
                or_dash(r.mass, |x| format!("{x:.3}"))
            );
        }
        out += "\nSources and gaps\n";
        for (name, source, lacks) in self.motors.iter().map(|m| (&m.name, &m.source, &m.lacks)).chain(self.reductions.iter().map(|r| (&r.name, &r.source, &r.lacks))) {
            out += &format!("  {name}: {}", source.as_deref().unwrap_or("the user's own (no source given)"));
            if !lacks.is_empty() {
                out += &format!("; lacks {}", lacks.join(", "));
            }
            out += "\n";
        }
        out
    }
}
