//! A reduction of the catalogue: a gearbox product with its list of ratios, or a belt stage with the
//! pulleys available — and the stage it makes at one ratio.
//!
//! A stage carries what the vendors' sizing checks read (Harmonic Drive, Apex, Beckhoff): the
//! repeated peak torque (the peak of the normal cycle; the rated torque where no peak is published),
//! the rated average torque (against the cubic mean of the cycle's torque), the highest input speed,
//! the input inertia (seen by the motor), and its losses as a [`LossyGear`]: the efficiency driving,
//! η_b back-driven, and the back-driving torque at the output as its breakaway friction.

use super::LossyGear;
use serde::Serialize;

/// What kind of reduction (for people; the model is the same for all).
pub const KINDS: [&str; 5] = ["planetary", "strain_wave", "cycloidal", "belt", "spur"];

/// A catalogue reduction.
#[derive(Clone, Debug, Serialize)]
pub struct Reduction {
    pub name: String,
    pub kind: String,
    /// The ratios it comes in, increasing.
    pub ratios: Vec<f64>,
    /// Driving efficiency η; None: not published (the reduction is then not sized).
    pub efficiency: Option<f64>,
    /// Back-driven efficiency η_b (η when not given; ≤ 0: self-locking).
    pub backdrive_efficiency: Option<f64>,
    /// Torque at the output that turns it with the input free, N·m (its friction).
    pub backdriving_torque: f64,
    /// Per ratio: rated (average) output torque, N·m.
    pub rated_torque: Option<Vec<f64>>,
    /// Per ratio: repeated peak output torque, N·m.
    pub repeated_peak_torque: Option<Vec<f64>>,
    /// Per ratio: momentary (emergency-stop) output torque, N·m.
    pub momentary_torque: Option<Vec<f64>>,
    /// Highest input speed, rad/s.
    pub max_input_speed: Option<f64>,
    /// Per ratio: inertia at the input, kg·m².
    pub input_inertia: Option<Vec<f64>>,
    /// Backlash, arcmin.
    pub backlash: Option<f64>,
    /// kg; None: not published (sized as weightless, and said).
    pub mass: Option<f64>,
    /// The motor flanges it takes (a stepper's `frame`); None: any stepper or bare motor.
    pub fits: Option<Vec<String>>,
    pub source: Option<String>,
}

/// One reduction stage at one ratio, as a drive train uses it.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    pub ratio: f64,
    pub gear: LossyGear,
    /// The peak output torque allowed in the normal cycle, N·m (infinite: unrated).
    pub peak_torque: f64,
    /// The rated average output torque (the cubic-mean check), N·m.
    pub rated_average_torque: Option<f64>,
    /// Highest input speed, rad/s.
    pub max_input_speed: Option<f64>,
    /// Inertia at the input, kg·m².
    pub input_inertia: f64,
}

impl Stage {
    /// An ideal stage of the given losses and peak rating (a user's own reduction).
    pub fn plain(ratio: f64, gear: LossyGear, peak_torque: f64) -> Self {
        Self { ratio, gear, peak_torque, rated_average_torque: None, max_input_speed: None, input_inertia: 0.0 }
    }
}

impl Reduction {
    /// The stage at `ratio` (one of [`Self::ratios`]); None when the reduction has no such ratio.
    /// Without a published efficiency the stage is lossless — callers that size refuse such a
    /// reduction first ([`Self::lacks`]).
    pub fn stage(&self, ratio: f64) -> Option<Stage> {
        let index = self.ratios.iter().position(|r| (r - ratio).abs() <= 1e-9 * r)?;
        let pick = |list: &Option<Vec<f64>>| list.as_ref().map(|v| v[index]);
        let efficiency = self.efficiency.unwrap_or(1.0);
        let gear = LossyGear { efficiency, backdrive_efficiency: self.backdrive_efficiency.unwrap_or(efficiency), breakaway_torque: self.backdriving_torque, viscous: 0.0 };
        let rated = pick(&self.rated_torque);
        Some(Stage {
            ratio: self.ratios[index],
            gear,
            peak_torque: pick(&self.repeated_peak_torque).or(rated).unwrap_or(f64::INFINITY),
            rated_average_torque: rated,
            max_input_speed: self.max_input_speed,
            input_inertia: pick(&self.input_inertia).unwrap_or(0.0),
        })
    }

    /// What the entry lacks that sizing reads, for notices and the catalogue listing.
    pub fn lacks(&self) -> Vec<&'static str> {
        let mut out = Vec::new();
        if self.efficiency.is_none() {
            out.push("efficiency (not sized)");
        }
        if self.mass.is_none() {
            out.push("mass (sized as weightless)");
        }
        if self.rated_torque.is_none() && self.repeated_peak_torque.is_none() {
            out.push("torque rating (unrated)");
        }
        if self.max_input_speed.is_none() {
            out.push("input speed limit");
        }
        out
    }

    /// Whether it can follow a motor of `kind` with flange `frame`: a bus servo or geared actuator
    /// (its gearbox inside) takes only a belt; a reduction made for a flange takes only that flange.
    pub fn fits(&self, kind: &str, frame: Option<&str>) -> bool {
        if self.kind == "belt" {
            return true;
        }
        if kind == "servo" {
            return false;
        }
        match &self.fits {
            None => true,
            Some(flanges) => frame.is_some_and(|f| flanges.iter().any(|x| x == f)),
        }
    }

    /// Whether `size` can use it: its losses are published.
    pub fn sizable(&self) -> bool {
        self.efficiency.is_some()
    }
}
