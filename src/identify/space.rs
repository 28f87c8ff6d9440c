//! The parameters `armscope identify` fits and where it looks for them: BAM's own bounds
//! (Rhoban/bam `bam/model.py`, `bam/dynamixel/actuator.py`, `bam/feetech/actuator.py` at 1b5a1ce:
//! each `Parameter(value, min, max)`), searched on the unit cube: a coordinate u ∈ [0, 1] is
//! lo + u·(hi − lo), or lo·(hi/lo)^u where the range is positive and spans a decade or more
//! (the armature, k_t), so that the search is as fine at the small end as at the large.

use crate::actuator::bus_servo::{Family, FrictionModel, ServoParams};

/// One fitted parameter: its key (BAM's) and range.
#[derive(Clone, Debug, PartialEq)]
pub struct Dimension {
    pub key: &'static str,
    pub lower: f64,
    pub upper: f64,
    pub logarithmic: bool,
}

impl Dimension {
    fn new(key: &'static str, lower: f64, upper: f64) -> Self {
        Self { key, lower, upper, logarithmic: lower > 0.0 && upper / lower >= 10.0 }
    }

    /// The value at u ∈ [0, 1] (clamped).
    pub fn value(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, 1.0);
        if self.logarithmic { self.lower * (self.upper / self.lower).powf(u) } else { self.lower + u * (self.upper - self.lower) }
    }

    /// The u of a value (clamped into the range).
    pub fn coordinate(&self, value: f64) -> f64 {
        let x = value.clamp(self.lower, self.upper);
        if self.logarithmic { (x / self.lower).ln() / (self.upper / self.lower).ln() } else if self.upper > self.lower { (x - self.lower) / (self.upper - self.lower) } else { 0.0 }
    }
}

/// The command delays identification searches, s: a bus servo's transfer, register read and
/// control period add up to milliseconds to tens of them (K-Scale's STS3215 logs fit 20–30 ms);
/// 100 ms is past any of them.
pub const COMMAND_DELAY_RANGE: f64 = 0.1;

/// The search space of one servo family and friction model.
#[derive(Clone, Debug)]
pub struct Space {
    pub family: Family,
    pub model: FrictionModel,
    pub dimensions: Vec<Dimension>,
}

impl Space {
    /// BAM's parameters for `family` with friction `model`, plus the supply's resistance when
    /// `supply_resistance` (armscope's: 0 … 2 Ω), the motor's voltage limit when
    /// `motor_voltage_limit`, and the command delay (0 … [`COMMAND_DELAY_RANGE`] s) when
    /// `command_delay`.
    pub fn new(family: Family, model: FrictionModel, supply_resistance: bool, motor_voltage_limit: bool, command_delay: bool) -> Self {
        let mut d = Vec::new();
        let (max_load, feetech) = (if family.name == "xl320" { 1.0 } else { 0.5 }, family.goal_speed_limiter);
        match family.name {
            "xl330" => d.extend([Dimension::new("kt", 0.1, 3.0), Dimension::new("R", 2.0, 5.0), Dimension::new("armature", 1e-4, 0.05)]),
            "xl320" => d.extend([Dimension::new("kt", 0.25, 1.5), Dimension::new("R", 3.0, 40.0), Dimension::new("armature", 1e-4, 0.01)]),
            "mx64" | "mx106" => d.extend([Dimension::new("kt", 1.0, 3.0), Dimension::new("R", 1.0, 5.0), Dimension::new("armature", 1e-3, 0.05)]),
            _ => d.extend([
                Dimension::new("kt", 0.05, 2.5),
                Dimension::new("error_gain_ratio", 0.1, 10.0),
                Dimension::new("R", 0.1, 10.0),
                Dimension::new("armature", 1e-5, 0.04),
                Dimension::new("max_velocity", 0.1 * family.default_max_velocity, 10.0 * family.default_max_velocity),
            ]),
        }
        d.push(if feetech { Dimension::new("q_offset", -0.2, 0.2) } else { Dimension::new("q_offset", -0.1, 0.1) });
        for key in model.keys() {
            d.push(match key {
                "friction_base" | "friction_stribeck" => Dimension::new(key, 0.0, 0.2),
                "load_friction_base" | "load_friction_motor" | "load_friction_external" => Dimension::new(key, 0.0, max_load),
                "load_friction_stribeck" | "load_friction_motor_stribeck" | "load_friction_external_stribeck" => Dimension::new(key, 0.0, 1.0),
                "load_friction_motor_quad" | "load_friction_external_quad" => Dimension::new(key, 0.0, 0.01),
                "dtheta_stribeck" => Dimension::new(key, 0.1, 3.0),
                "alpha" => Dimension::new(key, 1.0, 10.0),
                _ => Dimension::new(key, 0.0, 1.0), // friction_viscous
            });
        }
        if supply_resistance {
            d.push(Dimension::new(crate::actuator::bus_servo::params::SUPPLY_RESISTANCE_KEY, 0.0, 2.0));
        }
        if motor_voltage_limit {
            d.push(Dimension::new(crate::actuator::bus_servo::params::MOTOR_VOLTAGE_LIMIT_KEY, 0.3 * family.nominal_supply, 2.0 * family.nominal_supply));
        }
        if command_delay {
            d.push(Dimension::new(crate::actuator::bus_servo::params::COMMAND_DELAY_KEY, 0.0, COMMAND_DELAY_RANGE));
        }
        Self { family, model, dimensions: d }
    }

    pub fn len(&self) -> usize {
        self.dimensions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.dimensions.is_empty()
    }

    /// The parameters at point `u` of the unit cube.
    pub fn params(&self, u: &[f64]) -> ServoParams {
        let mut p = ServoParams {
            family: self.family,
            kt: 1.0,
            resistance: 1.0,
            armature: 0.0,
            q_offset: 0.0,
            friction: crate::actuator::bus_servo::ServoFriction { model: self.model, ..Default::default() },
            error_gain_ratio: 1.0,
            max_velocity: self.family.default_max_velocity,
            supply_resistance: 0.0,
            motor_voltage_limit: f64::INFINITY,
            command_delay: 0.0,
        };
        for (d, &u) in self.dimensions.iter().zip(u) {
            set(&mut p, d.key, d.value(u));
        }
        p
    }

    /// The space of `keys` only (those it has), in its order.
    pub fn only(mut self, keys: &[&str]) -> Self {
        self.dimensions.retain(|d| keys.contains(&d.key));
        self
    }

    /// `base` with the parameters of this space set to those at point `u`.
    pub fn params_from(&self, base: &ServoParams, u: &[f64]) -> ServoParams {
        let mut p = base.clone();
        for (d, &u) in self.dimensions.iter().zip(u) {
            set(&mut p, d.key, d.value(u));
        }
        p
    }

    /// The point of the unit cube of `params` (values outside a range clamped into it).
    pub fn point(&self, params: &ServoParams) -> Vec<f64> {
        self.dimensions.iter().map(|d| d.coordinate(get(params, d.key))).collect()
    }
}

fn set(p: &mut ServoParams, key: &str, x: f64) {
    match key {
        "kt" => p.kt = x,
        "R" => p.resistance = x,
        "armature" => p.armature = x,
        "q_offset" => p.q_offset = x,
        "error_gain_ratio" => p.error_gain_ratio = x,
        "max_velocity" => p.max_velocity = x,
        "supply_resistance" => p.supply_resistance = x,
        "motor_voltage_limit" => p.motor_voltage_limit = x,
        "command_delay" => p.command_delay = x,
        _ => {
            p.friction.set(key, x);
        }
    }
}

/// The parameter `key` (BAM's name) of `p`.
pub(crate) fn get(p: &ServoParams, key: &str) -> f64 {
    match key {
        "kt" => p.kt,
        "R" => p.resistance,
        "armature" => p.armature,
        "q_offset" => p.q_offset,
        "error_gain_ratio" => p.error_gain_ratio,
        "max_velocity" => p.max_velocity,
        "supply_resistance" => p.supply_resistance,
        "motor_voltage_limit" => p.motor_voltage_limit,
        "command_delay" => p.command_delay,
        _ => p.friction.get(key).unwrap_or(0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::actuator::bus_servo::firmware::{STS3215, XL330};

    #[test]
    fn points_and_params_round_trip() {
        for (family, model) in [(XL330, FrictionModel::M6), (STS3215, FrictionModel::M1), (XL330, FrictionModel::M4)] {
            let space = Space::new(family, model, true, true, true);
            let u: Vec<f64> = (0..space.len()).map(|i| (i as f64 * 0.37).fract()).collect();
            let back = space.point(&space.params(&u));
            for (a, b) in u.iter().zip(&back) {
                assert!((a - b).abs() < 1e-12, "{a} vs {b}");
            }
        }
        let space = Space::new(XL330, FrictionModel::M6, false, false, false);
        assert_eq!(space.len(), 3 + 1 + 11);
        let armature = space.dimensions.iter().find(|d| d.key == "armature").unwrap();
        assert!(armature.logarithmic);
        assert!((armature.value(0.5) - (1e-4f64 * 0.05).sqrt()).abs() < 1e-15);
    }
}
