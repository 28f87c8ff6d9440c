//! A motor's heat: the two-node thermal model of maxon's and every motor maker's datasheet
//! (`../shared/reference/sizing.md`; maxon, "Explanation of the pages", lines 17–22).
//!
//! The winding (node w) takes the copper losses P and passes heat to the housing (node s) through
//! R_th1; the housing passes it to the ambient through R_th2. The datasheet's time constants are
//! τ_w = C_w·R_th1 (the winding's) and τ_s = C_s·R_th2 (the motor's), so with θ = T − T_amb:
//!
//!   C_w·θ̇_w = P − (θ_w − θ_s)/R_th1,   C_s·θ̇_s = (θ_w − θ_s)/R_th1 − θ_s/R_th2,
//!
//! P = I²·R(T_w), R(T) = R_25·(1 + 0.0039·(T − 25 °C)) (copper), I = τ_motor/K_t, or a stepper
//! driver's set current. Held constant over a step, P moves θ exactly to θ* + e^{A·h}·(θ − θ*),
//! θ* = (P·(R_th1 + R_th2), P·R_th2) the steady state for that P; e^{A·h} is computed once. At
//! steady state the winding sits at T_amb + (R_th1 + R_th2)·P(T_w), a fixed point reached
//! unless the copper's rising resistance outruns the cooling (thermal runaway:
//! (R_th1 + R_th2)·I²·R_25·0.0039 ≥ 1).

use nalgebra::{Matrix2, Vector2};

/// Copper's resistance rises by this fraction per kelvin (at 25 °C).
pub const COPPER_TEMPERATURE_COEFFICIENT: f64 = 0.0039;
/// The temperature of the datasheet's resistance, °C.
pub const RESISTANCE_REFERENCE_TEMPERATURE: f64 = 25.0;

/// A motor's thermal data, from its datasheet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalData {
    /// Winding to housing, K/W.
    pub winding_to_housing: f64,
    /// Housing to ambient, K/W.
    pub housing_to_ambient: f64,
    /// The winding's thermal time constant τ_w, s.
    pub winding_time_constant: f64,
    /// The motor's (housing's) thermal time constant τ_s, s.
    pub motor_time_constant: f64,
    /// The winding's resistance at 25 °C (terminal resistance), Ω.
    pub resistance_25: f64,
    /// The highest permissible winding temperature, °C.
    pub max_winding_temperature: f64,
}

impl ThermalData {
    /// The winding's resistance at `temperature` °C.
    pub fn resistance(&self, temperature: f64) -> f64 {
        self.resistance_25 * (1.0 + COPPER_TEMPERATURE_COEFFICIENT * (temperature - RESISTANCE_REFERENCE_TEMPERATURE))
    }

    /// The winding's steady temperature carrying `current` A at `ambient` °C (the fixed point of
    /// T = T_amb + (R_th1 + R_th2)·I²·R(T)), or None in thermal runaway.
    pub fn steady_winding_temperature(&self, current: f64, ambient: f64) -> Option<f64> {
        let total = self.winding_to_housing + self.housing_to_ambient;
        let gain = total * current * current * self.resistance_25;
        let denominator = 1.0 - gain * COPPER_TEMPERATURE_COEFFICIENT;
        (denominator > 0.0).then(|| (ambient + gain * (1.0 - COPPER_TEMPERATURE_COEFFICIENT * RESISTANCE_REFERENCE_TEMPERATURE)) / denominator)
    }

    /// The largest current the winding carries forever at `ambient` °C without passing its limit.
    pub fn continuous_current(&self, ambient: f64) -> f64 {
        let rise = self.max_winding_temperature - ambient;
        if rise <= 0.0 {
            return 0.0;
        }
        let total = self.winding_to_housing + self.housing_to_ambient;
        (rise / (total * self.resistance(self.max_winding_temperature))).sqrt()
    }

    /// d/dt (θ_w, θ_s) = A·θ + (P/C_w, 0).
    fn system(&self) -> Matrix2<f64> {
        let (r1, r2) = (self.winding_to_housing, self.housing_to_ambient);
        let c_w = self.winding_time_constant / r1;
        let c_s = self.motor_time_constant / r2;
        Matrix2::new(-1.0 / (c_w * r1), 1.0 / (c_w * r1), 1.0 / (c_s * r1), -(1.0 / r1 + 1.0 / r2) / c_s)
    }
}

/// A motor's thermal data with what turns its torque into current: I = |τ_motor| / K_t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindingHeat {
    pub thermal: ThermalData,
    /// N·m/A (the current from the torque: I = τ/K_t).
    pub torque_constant: f64,
    /// An open-loop stepper's driver current, A: it flows whatever the load (the two phases' sine
    /// and cosine currents of a microstepping driver square to I² together, so the losses are
    /// I²·R(T) with R per phase); None for a motor whose current follows its torque.
    pub set_current: Option<f64>,
}

/// The ambient temperature of every run, °C (the datasheets' reference).
pub const AMBIENT_TEMPERATURE: f64 = 25.0;

/// What a run did to one motor's winding.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WindingSummary {
    /// The hottest the winding got, °C.
    pub peak_temperature: f64,
    /// Its permissible limit, °C.
    pub max_temperature: f64,
    /// The run's RMS motor current, A.
    pub rms_current: f64,
    /// The winding's steady temperature at that RMS current, °C (None: thermal runaway).
    pub steady_temperature: Option<f64>,
    /// Seconds after the run's end at which the winding would reach its limit if the motion went on
    /// at the run's RMS current (0: reached during the run; None: never).
    pub time_to_limit: Option<f64>,
}

/// Every joint's motor heat over a run: per joint with thermal data, its winding and housing.
#[derive(Clone, Debug)]
pub struct RunHeat {
    motors: Vec<Option<(MotorHeat, f64, Option<f64>)>>,
    /// Winding temperature per joint, °C (NaN for joints without thermal data).
    pub winding_temperature: Vec<f64>,
    peak: Vec<f64>,
    sum_squared_current: Vec<f64>,
    steps: u64,
}

impl RunHeat {
    /// Per joint: its motor's heat data and gear ratio N (the joint torque u is N·τ_motor).
    pub fn new(heat: &[Option<(WindingHeat, f64)>], dt: f64) -> Self {
        let motors: Vec<_> = heat.iter().map(|h| h.map(|(w, ratio)| (MotorHeat::new(w.thermal, AMBIENT_TEMPERATURE, dt), w.torque_constant * ratio, w.set_current))).collect();
        let winding_temperature = winding_temperature_of(&motors);
        let n = heat.len();
        Self { peak: winding_temperature_of(&motors), motors, winding_temperature, sum_squared_current: vec![0.0; n], steps: 0 }
    }

    /// Whether any joint's motor has thermal data.
    pub fn any(&self) -> bool {
        self.motors.iter().any(Option::is_some)
    }

    /// One control step carrying the joint torques `u` (held over it).
    pub fn step(&mut self, u: &[f64]) {
        self.steps += 1;
        for (i, motor) in self.motors.iter_mut().enumerate() {
            let Some((heat, newton_metres_per_amp, set_current)) = motor else { continue };
            let current = set_current.unwrap_or(u[i].abs() / *newton_metres_per_amp);
            self.sum_squared_current[i] += current * current;
            heat.step(current);
            self.winding_temperature[i] = heat.winding_temperature();
            self.peak[i] = self.peak[i].max(self.winding_temperature[i]);
        }
    }

    /// Per joint with thermal data, what the run did to its winding.
    pub fn summary(&self) -> Vec<Option<WindingSummary>> {
        self.motors
            .iter()
            .enumerate()
            .map(|(i, motor)| {
                let (heat, _, _) = motor.as_ref()?;
                let rms_current = (self.sum_squared_current[i] / self.steps.max(1) as f64).sqrt();
                Some(WindingSummary {
                    peak_temperature: self.peak[i],
                    max_temperature: heat.data.max_winding_temperature,
                    rms_current,
                    steady_temperature: heat.data.steady_winding_temperature(rms_current, heat.ambient),
                    time_to_limit: if self.peak[i] >= heat.data.max_winding_temperature { Some(0.0) } else { heat.time_to_limit(rms_current) },
                })
            })
            .collect()
    }
}

fn winding_temperature_of(motors: &[Option<(MotorHeat, f64, Option<f64>)>]) -> Vec<f64> {
    motors.iter().map(|m| m.as_ref().map_or(f64::NAN, |(m, _, _)| m.winding_temperature())).collect()
}

/// One motor's winding and housing temperatures over a run.
#[derive(Clone, Debug)]
pub struct MotorHeat {
    pub data: ThermalData,
    pub ambient: f64,
    /// e^{A·h} for the step h.
    step: Matrix2<f64>,
    /// (θ_w, θ_s): above ambient, K.
    rise: Vector2<f64>,
}

impl MotorHeat {
    /// A motor at `ambient` °C throughout, stepped every `dt` seconds.
    pub fn new(data: ThermalData, ambient: f64, dt: f64) -> Self {
        Self { data, ambient, step: (data.system() * dt).exp(), rise: Vector2::zeros() }
    }

    pub fn winding_temperature(&self) -> f64 {
        self.ambient + self.rise.x
    }

    pub fn housing_temperature(&self) -> f64 {
        self.ambient + self.rise.y
    }

    /// The copper losses carrying `current` A now, W.
    pub fn losses(&self, current: f64) -> f64 {
        current * current * self.data.resistance(self.winding_temperature())
    }

    /// Advance one step carrying `current` A (held over the step).
    pub fn step(&mut self, current: f64) {
        let power = self.losses(current);
        let steady = Vector2::new(power * (self.data.winding_to_housing + self.data.housing_to_ambient), power * self.data.housing_to_ambient);
        self.rise = steady + self.step * (self.rise - steady);
    }

    /// When the winding would reach its limit if `current` A (RMS) went on from now, s; None if
    /// it never does (its steady temperature is below the limit). Exact for the resistance at
    /// the limit (the losses' largest value on the way), so never late.
    pub fn time_to_limit(&self, current: f64) -> Option<f64> {
        let limit = self.data.max_winding_temperature - self.ambient;
        if self.rise.x >= limit {
            return Some(0.0);
        }
        let power = current * current * self.data.resistance(self.data.max_winding_temperature);
        let steady = Vector2::new(power * (self.data.winding_to_housing + self.data.housing_to_ambient), power * self.data.housing_to_ambient);
        if steady.x <= limit {
            return None;
        }
        let system = self.data.system();
        let winding_at = |t: f64| (steady + (system * t).exp() * (self.rise - steady)).x;
        // θ_w rises monotonically toward θ*_w > limit from below: bracket, then bisect to 1 ms
        let mut high = self.data.winding_time_constant.min(self.data.motor_time_constant).max(1e-3);
        while winding_at(high) < limit {
            high *= 2.0;
        }
        let mut low = 0.0;
        while high - low > 1e-3 {
            let mid = 0.5 * (low + high);
            if winding_at(mid) < limit { low = mid } else { high = mid }
        }
        Some(high)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// maxon EC 45 flat 30 W, 24 V (catalogue-sources.md §4, source 1).
    fn ec45_flat_30w() -> ThermalData {
        ThermalData { winding_to_housing: 3.96, housing_to_ambient: 5.7, winding_time_constant: 11.5, motor_time_constant: 251.0, resistance_25: 4.83, max_winding_temperature: 125.0 }
    }

    #[test]
    fn a_constant_current_settles_where_the_losses_at_that_temperature_balance_the_cooling() {
        let data = ec45_flat_30w();
        // the nominal torque 0.0553 N·m through K_t 0.051 N·m/A
        let current = 0.0553 / 0.051;
        let mut heat = MotorHeat::new(data, 25.0, 1e-3);
        for _ in 0..(20.0 * data.motor_time_constant / 1e-3) as usize {
            heat.step(current);
        }
        let closed_form = data.steady_winding_temperature(current, 25.0).unwrap();
        // and the fixed point itself: T = T_amb + (R_th1 + R_th2)·I²·R(T)
        let balance = 25.0 + (data.winding_to_housing + data.housing_to_ambient) * current * current * data.resistance(closed_form);
        assert!((closed_form - balance).abs() < 1e-9, "{closed_form} vs {balance}");
        assert!((heat.winding_temperature() - closed_form).abs() < 0.5, "{} vs {closed_form}", heat.winding_temperature());
        // the housing sits R_th2·P above ambient
        let housing = 25.0 + data.housing_to_ambient * current * current * data.resistance(closed_form);
        assert!((heat.housing_temperature() - housing).abs() < 0.5);
    }

    #[test]
    fn the_transient_is_the_two_exponential_closed_form() {
        // the step's matrix exponential against the eigen-solution worked out here, for a held P
        // (the copper's resistance apart: 100 s at 10 W)
        let data = ec45_flat_30w();
        let (r1, r2, c_w, c_s) = (data.winding_to_housing, data.housing_to_ambient, data.winding_time_constant / data.winding_to_housing, data.motor_time_constant / data.housing_to_ambient);
        let power = 10.0;
        // eigenvalues of A by hand
        let (a, b, c, d) = (-1.0 / (c_w * r1), 1.0 / (c_w * r1), 1.0 / (c_s * r1), -(1.0 / r1 + 1.0 / r2) / c_s);
        let (trace, det) = (a + d, a * d - b * c);
        let root = (trace * trace / 4.0 - det).sqrt();
        let (l1, l2) = (trace / 2.0 + root, trace / 2.0 - root);
        // θ_w(t) = θ*_w + k1·e^{l1 t} + k2·e^{l2 t} from θ = 0 with θ̇_w(0) = P/C_w
        let steady = power * (r1 + r2);
        let (k1, k2) = {
            // k1 + k2 = −θ*_w, l1·k1 + l2·k2 = P/C_w
            let k1 = (power / c_w + l2 * steady) / (l1 - l2);
            (k1, -steady - k1)
        };
        let exact = |t: f64| steady + k1 * (l1 * t).exp() + k2 * (l2 * t).exp();
        let step = MotorHeat::new(data, 25.0, 1e-3).step;
        let mut rise = Vector2::zeros();
        let held = Vector2::new(steady, power * r2);
        for k in 1..=100_000 {
            rise = held + step * (rise - held);
            if k % 10_000 == 0 {
                let t = k as f64 * 1e-3;
                assert!((rise.x - exact(t)).abs() < 1e-9 * steady, "t = {t}: {} vs {}", rise.x, exact(t));
            }
        }
    }

    #[test]
    fn time_to_limit_is_when_the_winding_gets_there() {
        let data = ec45_flat_30w();
        let heat = MotorHeat::new(data, 25.0, 1e-3);
        // the continuous current never gets there; twice it does, and the simulated winding agrees
        assert_eq!(heat.time_to_limit(0.99 * data.continuous_current(25.0)), None);
        let current = 2.0 * data.continuous_current(25.0);
        let predicted = heat.time_to_limit(current).unwrap();
        let mut simulated = heat.clone();
        let mut t = 0.0;
        while simulated.winding_temperature() < data.max_winding_temperature {
            simulated.step(current);
            t += 1e-3;
        }
        // predicted with the limit's resistance (the largest on the way): never later
        assert!(predicted <= t + 1e-3 && predicted > 0.8 * t, "predicted {predicted} s, simulated {t} s");
    }
}
