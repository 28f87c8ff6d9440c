//! Friction in a servo's gear train as BAM identifies it: models M1–M6 of Duclusaud, Passault,
//! Padois and Ly, *Extended Friction Models for the Physics Simulation of Servo Actuators* (arXiv
//! 2410.08650; Rhoban/bam `bam/model.py`), with the paper's names and BAM's JSON keys.
//!
//! Each model gives a Coulomb **budget** B ≥ 0: the largest torque friction can give this step,
//! against the motion, or holding the joint still. With τ_m the motor's torque (0 when the torque is
//! off), τ_e the external (gravity) torque on the joint, both positive in the direction of positive
//! q, q̇ the joint speed, and the Stribeck factor s = exp(−|q̇/q̇_s|^α) (1 at rest, → 0 moving):
//!
//! | model | B |
//! |---|---|
//! | M1 Coulomb–viscous | K_c |
//! | M2 Stribeck | K_c + s·K_cs |
//! | M3 load-dependent | K_c + K_l·\|τ_e − τ_m\| |
//! | M4 Stribeck load-dependent | K_c + K_l·\|τ_e − τ_m\| + s·(K_cs + K_ls·\|τ_e − τ_m\|) |
//! | M5 directional | K_c + \|K_e·τ_e − K_m·τ_m\| + s·(K_cs + \|K_es·τ_e − K_ms·τ_m\|) |
//! | M6 directional quadratic | M5 + s·Q |
//!
//! with Q = K_eq·τ_e² when τ_e and τ_m have opposite signs and the motor is the stronger
//! (|τ_e| < |τ_m|), K_mq·τ_m² when they have opposite signs and gravity is the stronger, else 0: the
//! weaker side is squared. Every model also has the viscous coefficient K_v: in BAM's step it is
//! part of the budget (B + K_v·|q̇|, never a separate −K_v·q̇ that could reverse the joint); in
//! armscope's exact step it is an implicit damping beside the Coulomb band B (the two agree as the
//! step goes to zero).

use serde::{Deserialize, Serialize};

/// Which of the paper's models: which terms of [`ServoFriction`] count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum FrictionModel {
    /// Coulomb–viscous.
    #[default]
    M1,
    /// Stribeck.
    M2,
    /// Load-dependent.
    M3,
    /// Stribeck load-dependent.
    M4,
    /// Stribeck load-dependent directional.
    M5,
    /// Stribeck load-dependent directional quadratic.
    M6,
}

impl FrictionModel {
    pub const ALL: [FrictionModel; 6] = [FrictionModel::M1, FrictionModel::M2, FrictionModel::M3, FrictionModel::M4, FrictionModel::M5, FrictionModel::M6];

    /// BAM's name, "m1" … "m6".
    pub fn name(self) -> &'static str {
        match self {
            FrictionModel::M1 => "m1",
            FrictionModel::M2 => "m2",
            FrictionModel::M3 => "m3",
            FrictionModel::M4 => "m4",
            FrictionModel::M5 => "m5",
            FrictionModel::M6 => "m6",
        }
    }

    /// The model of BAM's name ("m1" … "m6", any case).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name().eq_ignore_ascii_case(name))
    }

    /// The paper's title of the model.
    pub fn title(self) -> &'static str {
        match self {
            FrictionModel::M1 => "Coulomb-viscous (M1)",
            FrictionModel::M2 => "Stribeck (M2)",
            FrictionModel::M3 => "load-dependent (M3)",
            FrictionModel::M4 => "Stribeck load-dependent (M4)",
            FrictionModel::M5 => "Stribeck load-dependent directional (M5)",
            FrictionModel::M6 => "Stribeck load-dependent directional quadratic (M6)",
        }
    }

    pub fn stribeck(self) -> bool {
        !matches!(self, FrictionModel::M1 | FrictionModel::M3)
    }

    pub fn load_dependent(self) -> bool {
        !matches!(self, FrictionModel::M1 | FrictionModel::M2)
    }

    pub fn directional(self) -> bool {
        matches!(self, FrictionModel::M5 | FrictionModel::M6)
    }

    pub fn quadratic(self) -> bool {
        self == FrictionModel::M6
    }

    /// Whether every friction of `other` is one of this model's (its terms are a subset, a
    /// load-dependent model's single factor standing for a directional model's two).
    pub fn contains(self, other: FrictionModel) -> bool {
        (!other.stribeck() || self.stribeck()) && (!other.load_dependent() || self.load_dependent()) && (!other.directional() || self.directional()) && (!other.quadratic() || self.quadratic())
    }

    /// The JSON keys (BAM's) of the model's parameters, in BAM's order.
    pub fn keys(self) -> Vec<&'static str> {
        let mut keys = vec!["friction_base"];
        if self.stribeck() {
            keys.push("friction_stribeck");
        }
        if self.load_dependent() {
            if self.directional() {
                keys.extend(["load_friction_motor", "load_friction_external"]);
            } else {
                keys.push("load_friction_base");
            }
            if self.stribeck() {
                if self.directional() {
                    keys.extend(["load_friction_motor_stribeck", "load_friction_external_stribeck"]);
                } else {
                    keys.push("load_friction_stribeck");
                }
            }
            if self.quadratic() {
                keys.extend(["load_friction_motor_quad", "load_friction_external_quad"]);
            }
        }
        if self.stribeck() {
            keys.extend(["dtheta_stribeck", "alpha"]);
        }
        keys.push("friction_viscous");
        keys
    }
}

/// A servo's friction: the model and its coefficients at the servo's output shaft (N·m, N·m·s/rad,
/// rad/s; the load factors are fractions, the quadratic ones 1/(N·m)). Terms the model does not
/// have are ignored.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ServoFriction {
    pub model: FrictionModel,
    /// K_c `friction_base`.
    pub base: f64,
    /// K_v `friction_viscous`.
    pub viscous: f64,
    /// K_cs `friction_stribeck`.
    pub stribeck: f64,
    /// q̇_s `dtheta_stribeck`.
    pub stribeck_speed: f64,
    /// α `alpha`.
    pub stribeck_exponent: f64,
    /// K_l `load_friction_base` (M3, M4).
    pub load: f64,
    /// K_ls `load_friction_stribeck` (M4).
    pub load_stribeck: f64,
    /// K_m `load_friction_motor` (M5, M6).
    pub load_motor: f64,
    /// K_e `load_friction_external`.
    pub load_external: f64,
    /// K_ms `load_friction_motor_stribeck`.
    pub load_motor_stribeck: f64,
    /// K_es `load_friction_external_stribeck`.
    pub load_external_stribeck: f64,
    /// K_mq `load_friction_motor_quad` (M6).
    pub load_motor_quad: f64,
    /// K_eq `load_friction_external_quad` (M6).
    pub load_external_quad: f64,
}

impl ServoFriction {
    /// The value of the parameter with BAM's JSON key `key` (None: no such key).
    pub fn get(&self, key: &str) -> Option<f64> {
        Some(match key {
            "friction_base" => self.base,
            "friction_viscous" => self.viscous,
            "friction_stribeck" => self.stribeck,
            "dtheta_stribeck" => self.stribeck_speed,
            "alpha" => self.stribeck_exponent,
            "load_friction_base" => self.load,
            "load_friction_stribeck" => self.load_stribeck,
            "load_friction_motor" => self.load_motor,
            "load_friction_external" => self.load_external,
            "load_friction_motor_stribeck" => self.load_motor_stribeck,
            "load_friction_external_stribeck" => self.load_external_stribeck,
            "load_friction_motor_quad" => self.load_motor_quad,
            "load_friction_external_quad" => self.load_external_quad,
            _ => return None,
        })
    }

    /// Set the parameter with BAM's JSON key `key`; false when there is no such key.
    pub fn set(&mut self, key: &str, value: f64) -> bool {
        let slot = match key {
            "friction_base" => &mut self.base,
            "friction_viscous" => &mut self.viscous,
            "friction_stribeck" => &mut self.stribeck,
            "dtheta_stribeck" => &mut self.stribeck_speed,
            "alpha" => &mut self.stribeck_exponent,
            "load_friction_base" => &mut self.load,
            "load_friction_stribeck" => &mut self.load_stribeck,
            "load_friction_motor" => &mut self.load_motor,
            "load_friction_external" => &mut self.load_external,
            "load_friction_motor_stribeck" => &mut self.load_motor_stribeck,
            "load_friction_external_stribeck" => &mut self.load_external_stribeck,
            "load_friction_motor_quad" => &mut self.load_motor_quad,
            "load_friction_external_quad" => &mut self.load_external_quad,
            _ => return false,
        };
        *slot = value;
        true
    }

    /// The same friction as a richer `model` (one that [`FrictionModel::contains`] it) states it (the terms it adds zero, a directional
    /// model's two load factors tied to the single one): the budget is the same at every state.
    /// Where the richer model adds a Stribeck term, its speed and exponent are set to mid-range
    /// values (they do not matter while its coefficient is zero).
    pub fn as_model(&self, model: FrictionModel) -> ServoFriction {
        let mut out = ServoFriction { model, ..*self };
        if model.stribeck() && !self.model.stribeck() {
            (out.stribeck, out.load_stribeck, out.stribeck_speed, out.stribeck_exponent) = (0.0, 0.0, 1.0, 2.0);
        }
        if model.load_dependent() && !self.model.load_dependent() {
            (out.load, out.load_stribeck) = (0.0, 0.0);
        }
        if model.directional() && !self.model.directional() {
            (out.load_motor, out.load_external) = (self.load, self.load);
            let stribeck = if self.model.stribeck() { self.load_stribeck } else { 0.0 };
            (out.load_motor_stribeck, out.load_external_stribeck) = (stribeck, stribeck);
        }
        if model.quadratic() && !self.model.quadratic() {
            (out.load_motor_quad, out.load_external_quad) = (0.0, 0.0);
        }
        out
    }

    /// s = exp(−|q̇/q̇_s|^α): 1 at rest, falling towards 0 as the joint moves.
    #[inline]
    pub fn stribeck_factor(&self, speed: f64) -> f64 {
        if speed == 0.0 {
            // exactly what the formula gives, without its two transcendental calls (a stuck joint)
            return 1.0;
        }
        (-(speed / self.stribeck_speed).abs().powf(self.stribeck_exponent)).exp()
    }

    /// The Coulomb budget B (N·m, without the viscous part) with motor torque `motor`, external
    /// torque `external` and joint speed `speed`.
    #[inline]
    pub fn budget(&self, motor: f64, external: f64, speed: f64) -> f64 {
        let m = self.model;
        let mut budget = self.base;
        if !m.stribeck() {
            if m.load_dependent() {
                budget += self.load * (external - motor).abs();
            }
            return budget;
        }
        let s = self.stribeck_factor(speed);
        budget += s * self.stribeck;
        if m.directional() {
            budget += (external * self.load_external - motor * self.load_motor).abs();
            budget += s * (external * self.load_external_stribeck - motor * self.load_motor_stribeck).abs();
            if m.quadratic() && sign(external) != sign(motor) {
                let (e, t) = (external.abs(), motor.abs());
                // the weaker side is squared
                if e < t {
                    budget += s * self.load_external_quad * e * e;
                } else if e > t {
                    budget += s * self.load_motor_quad * t * t;
                }
            }
        } else if m.load_dependent() {
            let gearbox = (external - motor).abs();
            budget += self.load * gearbox + s * self.load_stribeck * gearbox;
        }
        budget
    }

    /// The largest budget at rest for motor torques up to `motor` in size and external torques up
    /// to `external` in size: how much the servo can hold against itself (for reports).
    pub fn budget_at_rest(&self, motor: f64, external: f64) -> f64 {
        [(motor, -external), (motor, external), (-motor, external), (-motor, -external)].into_iter().map(|(m, e)| self.budget(m, e, 0.0)).fold(0.0, f64::max)
    }
}

/// NumPy's sign: −1, 0 or +1 (BAM's models and bench step use it; `f64::signum` gives ±1 at 0).
#[inline]
pub(crate) fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m6() -> ServoFriction {
        // BAM's published XL330 m6 file (params/xl330/m6.json at Rhoban/bam 1b5a1ce)
        ServoFriction {
            model: FrictionModel::M6,
            base: 0.004771183165566,
            viscous: 0.005359668274599504,
            stribeck: 0.004676345799486616,
            stribeck_speed: 2.890372094130307,
            stribeck_exponent: 8.683259907618984,
            load_motor: 0.2667860954283698,
            load_external: 8.515871897059342e-06,
            load_motor_stribeck: 1.0722918395099123e-05,
            load_external_stribeck: 0.08077928978935671,
            load_motor_quad: 0.009972471242139415,
            load_external_quad: 0.004902565732332559,
            ..Default::default()
        }
    }

    #[test]
    fn the_quadratic_term_squares_the_weaker_side() {
        let f = m6();
        let without = ServoFriction { model: FrictionModel::M5, ..f };
        // motor stronger, opposite signs: K_eq·τ_e²
        assert!((f.budget(0.9, -0.3, 0.0) - without.budget(0.9, -0.3, 0.0) - f.load_external_quad * 0.09).abs() < 1e-15);
        // gravity stronger: K_mq·τ_m²
        assert!((f.budget(0.3, -0.9, 0.0) - without.budget(0.3, -0.9, 0.0) - f.load_motor_quad * 0.09).abs() < 1e-15);
        // same signs, or a zero: nothing
        assert_eq!(f.budget(0.3, 0.9, 0.0), without.budget(0.3, 0.9, 0.0));
        assert_eq!(f.budget(0.0, 0.0, 0.0), without.budget(0.0, 0.0, 0.0));
    }

    #[test]
    fn stribeck_terms_fade_with_speed() {
        let f = m6();
        assert_eq!(f.stribeck_factor(0.0), 1.0);
        assert!(f.stribeck_factor(10.0) < 1e-4);
        let moving = f.budget(0.5, -0.2, 10.0);
        let expected = f.base + (-0.2 * f.load_external - 0.5 * f.load_motor).abs();
        assert!((moving - expected).abs() < 1e-5);
    }

    #[test]
    fn a_simpler_model_embeds_with_the_same_budget() {
        let f = m6();
        let m4 = ServoFriction { model: FrictionModel::M4, base: 0.01, stribeck: 0.02, stribeck_speed: 0.4, stribeck_exponent: 1.5, load: 0.3, load_stribeck: 0.1, viscous: 0.01, ..Default::default() };
        let m1 = ServoFriction { model: FrictionModel::M1, base: 0.02, viscous: 0.003, ..Default::default() };
        for (simple, rich) in [(m4, FrictionModel::M5), (m4, FrictionModel::M6), (m1, FrictionModel::M3), (m1, FrictionModel::M2), (m1, FrictionModel::M6), (f, FrictionModel::M6)] {
            let embedded = simple.as_model(rich);
            for (motor, external, speed) in [(0.5, -0.2, 0.0), (-0.3, -0.4, 0.2), (0.1, 0.6, -1.0), (0.0, 0.0, 3.0)] {
                let (a, b) = (simple.budget(motor, external, speed), embedded.budget(motor, external, speed));
                assert!((a - b).abs() < 1e-15, "{:?} → {rich:?}: {a} vs {b}", simple.model);
            }
        }
    }

    #[test]
    fn keys_round_trip_and_match_bam() {
        assert_eq!(FrictionModel::M1.keys(), ["friction_base", "friction_viscous"]);
        assert_eq!(FrictionModel::M3.keys(), ["friction_base", "load_friction_base", "friction_viscous"]);
        assert_eq!(FrictionModel::M6.keys().len(), 11);
        let mut f = ServoFriction::default();
        for (i, key) in FrictionModel::M6.keys().into_iter().chain(["load_friction_base", "load_friction_stribeck"]).enumerate() {
            assert!(f.set(key, i as f64 + 0.5));
            assert_eq!(f.get(key), Some(i as f64 + 0.5));
        }
        assert!(!f.set("kt", 1.0));
    }
}
