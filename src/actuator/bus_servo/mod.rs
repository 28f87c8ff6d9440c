//! A serial-bus servo as it is: the firmware's position loop in the servo's own units sets a PWM
//! duty ([`firmware`]), the duty times the supply voltage drives a DC motor at the output through
//! its resistance against its back-EMF, and the gear train's friction ([`friction`], BAM's models
//! M1–M6) eats part of the torque. Parameters come from BAM's identification files ([`params`]).
//!
//! ```text
//!   d   = clip(e_g·k_p·(q_target − q), ±d_max)       the firmware (a Feetech's target walks)
//!   V_m = d·V_s                                       the mean voltage across the motor
//!   i   = (V_m − k_t·q̇)/R                             back-EMF k_t·q̇
//!   τ_m = k_t·i  (0 with the torque off: no electrical braking)
//! ```
//!
//! Where its datasheet gives a stall torque and a no-load speed, the torque stays within that
//! torque–speed line (the `envelope`): an identification fitted where the loads were light
//! extrapolates k_t·V/R past what the servo gives (BAM's 12 V STS3215 file says 8.3 N·m at full
//! duty and rest, its datasheet 2.94 N·m).
//!
//! The bridge's supply V_s is the nominal voltage less the drop across the resistance R_s on its
//! supply side (a battery's, the cables', and inside the servo what lies before its bridge) for
//! the current it draws, d·i: solving V_s = V₀ − R_s·d·i for V_s gives
//! V_s = (V₀ + R_s·d·k_t·q̇/R)/(1 + R_s·d²/R), a loss that grows with the duty squared. With R_s = 0
//! (BAM's assumption) V_s = V₀. The motor's voltage may also be capped (`motor_voltage_limit`), a
//! loss that starts at a duty.

pub mod firmware;
pub mod friction;
pub mod params;
pub mod protection;

pub use firmware::{Family, Firmware, FirmwareState};
pub use friction::{FrictionModel, ServoFriction};
pub use params::ServoParams;
pub use protection::{Protection, Trip, TripKind};

use super::Motor;

/// One servo: firmware, motor, friction and supply.
#[derive(Clone, Debug, PartialEq)]
pub struct BusServo {
    /// The catalogue name.
    pub name: String,
    pub firmware: Firmware,
    /// k_t at the output, N·m/A.
    pub kt: f64,
    /// R, Ω.
    pub resistance: f64,
    /// Reflected rotor inertia at the output, kg·m².
    pub armature: f64,
    pub friction: ServoFriction,
    /// V₀, the supply's open-circuit voltage, V.
    pub supply: f64,
    /// R_s, Ω: on the bridge's supply side.
    pub supply_resistance: f64,
    /// The largest voltage the servo puts across its motor, V (infinite: none).
    pub motor_voltage_limit: f64,
    /// How long after a goal is sent the firmware acts on it, s.
    pub command_delay: f64,
    /// The datasheet's stall torque (N·m) and no-load speed (rad/s) at the output, where given:
    /// the torque stays within that line (with the motion; its stall torque braking).
    pub envelope: Option<(f64, f64)>,
}

/// What the servo does at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ServoOutput {
    /// The duty the firmware gives, −d_max … d_max.
    pub duty: f64,
    /// The voltage at the servo's supply pins, V.
    pub supply: f64,
    /// The motor's current, A.
    pub current: f64,
    /// The motor's torque at the output, N·m (0 with the torque off).
    pub torque: f64,
    /// Whether the datasheet's line held the torque below what the duty would give.
    pub limited: bool,
}

impl BusServo {
    /// A servo of the identified `params` with P gain register `kp` on a supply of `supply` V.
    pub fn from_params(name: impl Into<String>, params: &ServoParams, kp: f64, supply: f64) -> Self {
        let mut firmware = Firmware::new(params.family, kp);
        firmware.error_gain_ratio = params.error_gain_ratio;
        firmware.max_velocity = params.max_velocity;
        Self { name: name.into(), firmware, kt: params.kt, resistance: params.resistance, armature: params.armature, friction: params.friction, supply, supply_resistance: params.supply_resistance, motor_voltage_limit: params.motor_voltage_limit, command_delay: params.command_delay, envelope: None }
    }

    /// The servo with identified parameters `params` in place of its own, its P gain, supply,
    /// protections and datasheet envelope kept (they are the arm's settings, not the servo's
    /// physics).
    pub fn set_params(&mut self, params: &ServoParams) {
        self.firmware.error_gain_ratio = params.error_gain_ratio;
        self.firmware.max_velocity = params.max_velocity;
        self.kt = params.kt;
        self.resistance = params.resistance;
        self.armature = params.armature;
        self.friction = params.friction;
        self.supply_resistance = params.supply_resistance;
        self.motor_voltage_limit = params.motor_voltage_limit;
        self.command_delay = params.command_delay;
    }

    /// The identified parameters back (q_offset 0: a bench's, not the servo's).
    pub fn params(&self) -> ServoParams {
        ServoParams {
            family: self.firmware.family,
            kt: self.kt,
            resistance: self.resistance,
            armature: self.armature,
            q_offset: 0.0,
            friction: self.friction,
            error_gain_ratio: self.firmware.error_gain_ratio,
            max_velocity: self.firmware.max_velocity,
            supply_resistance: self.supply_resistance,
            motor_voltage_limit: self.motor_voltage_limit,
            command_delay: self.command_delay,
        }
    }

    /// The supply voltage at duty `duty` and speed `speed` from open-circuit `supply` (see the
    /// module's note).
    #[inline]
    pub fn supply_at(&self, supply: f64, duty: f64, speed: f64) -> f64 {
        if self.supply_resistance == 0.0 {
            return supply;
        }
        let r = self.supply_resistance / self.resistance;
        (supply + r * duty * self.kt * speed) / (1.0 + r * duty * duty)
    }

    /// The motor at duty `duty`, speed `speed`, on an open-circuit supply of `supply` V, with the
    /// torque on or off.
    #[inline]
    pub fn drive(&self, duty: f64, speed: f64, supply: f64, enabled: bool) -> ServoOutput {
        if !enabled {
            // the bridge is off: no voltage across the motor, no current (the firmware still runs)
            return ServoOutput { duty: 0.0, supply, current: 0.0, torque: 0.0, limited: false };
        }
        let supply = self.supply_at(supply, duty, speed);
        let volts = (supply * duty).clamp(-self.motor_voltage_limit, self.motor_voltage_limit);
        // τ = k_t·V/R − k_t²·q̇/R, as BAM writes it
        let mut torque = self.kt * volts / self.resistance - self.kt * self.kt * speed / self.resistance;
        let mut limited = false;
        if let Some((stall, no_load)) = self.envelope {
            let with_motion = torque * speed >= 0.0;
            let limit = if with_motion { (stall * (1.0 - speed.abs() / no_load)).max(0.0) } else { stall };
            limited = torque.abs() > limit;
            torque = torque.clamp(-limit, limit);
        }
        ServoOutput { duty, supply, current: torque / self.kt, torque, limited }
    }

    /// One firmware tick of `dt` s and the motor's answer over it: `goal` at position `q`, speed
    /// `speed`; a tripped protection limits the duty or switches the torque off, and the tick's
    /// duty and current run its timers.
    #[inline]
    pub fn tick(&self, state: &mut FirmwareState, goal: f64, q: f64, speed: f64, dt: f64, supply: f64, enabled: bool) -> ServoOutput {
        let protection = &self.firmware.protection;
        let limit = protection.duty_limit(&state.protection, self.firmware.family.max_duty);
        let duty = self.firmware.tick(state, goal, q, speed, dt, supply, self.kt, self.resistance).clamp(-limit, limit);
        let out = self.drive(duty, speed, supply, enabled && !protection.torque_off(&state.protection));
        protection.update(&mut state.protection, out.duty, out.current, dt);
        out
    }

    /// The duty that gives torque `torque` at the output at speed `speed` on the nominal supply
    /// (the inverse of [`Self::drive`] within its envelope, unclipped): the load a Feetech's
    /// protections see.
    pub fn duty_for(&self, torque: f64, speed: f64) -> f64 {
        let volts = torque * self.resistance / self.kt + self.kt * speed;
        // the supply sags with the duty (its own resistance): a few fixed-point passes settle it
        let mut duty = volts / self.supply;
        for _ in 0..4 {
            duty = volts / self.supply_at(self.supply, duty, speed);
        }
        duty
    }

    /// The torque at rest at full duty on the nominal supply, N·m.
    pub fn stall_torque(&self) -> f64 {
        self.drive(self.firmware.family.max_duty, 0.0, self.supply, true).torque
    }

    /// The speed at which full duty gives no torque, rad/s (the datasheet's where it is lower).
    pub fn no_load_speed(&self) -> f64 {
        let d = self.firmware.family.max_duty;
        let model = self.supply_at(self.supply, d, 0.0) * d / self.kt;
        self.envelope.map_or(model, |(_, no_load)| model.min(no_load))
    }

    /// Where a held joint settles against a steady torque `load` (N·m, the external torque the
    /// motor must cancel) on an ideal supply, friction aside: k_t·V·e_g·k_p·e/R = load gives the
    /// error e (rad) the position loop needs; None when it needs more than the duty limit.
    pub fn static_error(&self, load: f64) -> Option<f64> {
        let per_rad = self.kt * self.supply * self.firmware.duty_per_rad() / self.resistance;
        let error = load / per_rad;
        (error.abs() <= self.firmware.saturation_error()).then_some(error)
    }
}

impl Motor for BusServo {
    fn boxed_clone(&self) -> Box<dyn Motor> {
        Box::new(self.clone())
    }
    fn torque_at(&self, speed: f64) -> f64 {
        self.drive(self.firmware.family.max_duty, speed.abs(), self.supply, true).torque.max(0.0)
    }

    /// Against the motion full duty adds to the back-EMF.
    fn braking_torque_at(&self, speed: f64) -> f64 {
        self.drive(self.firmware.family.max_duty, -speed.abs(), self.supply, true).torque
    }

    fn rotor_inertia(&self) -> f64 {
        self.armature
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn describe(&self) -> String {
        format!(
            "{}: {} bus servo, P gain {} on {} V, stall {:.3} N·m, no-load {:.2} rad/s, friction {}",
            self.name,
            self.firmware.family.name,
            self.firmware.kp,
            self.supply,
            self.stall_torque(),
            self.no_load_speed(),
            self.friction.model.title()
        )
    }

    fn as_bus_servo(&self) -> Option<&BusServo> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn xl330() -> BusServo {
        let params = ServoParams {
            family: firmware::XL330,
            kt: 0.366,
            resistance: 2.81,
            armature: 0.0018,
            q_offset: 0.0,
            friction: ServoFriction { model: FrictionModel::M1, base: 0.005, viscous: 0.005, ..Default::default() },
            error_gain_ratio: 1.0,
            max_velocity: f64::INFINITY,
            supply_resistance: 0.0,
            motor_voltage_limit: f64::INFINITY,
            command_delay: 0.0,
        };
        BusServo::from_params("XL330", &params, 400.0, 7.4)
    }

    #[test]
    fn the_motor_law_is_the_dc_motor_with_back_emf() {
        let s = xl330();
        let out = s.drive(0.5, 1.0, 7.4, true);
        assert!((out.torque - (0.366 * 3.7 / 2.81 - 0.366 * 0.366 / 2.81)).abs() < 1e-15);
        assert!((out.current - (3.7 - 0.366) / 2.81).abs() < 1e-14);
        assert_eq!(s.drive(0.5, 1.0, 7.4, false).torque, 0.0);
        assert!((s.stall_torque() - 0.366 * 7.4 / 2.81).abs() < 1e-15);
        assert!((s.torque_at(s.no_load_speed())).abs() < 1e-12);
    }

    #[test]
    fn supply_resistance_acts_as_series_resistance_at_full_duty() {
        let mut s = xl330();
        s.supply_resistance = 0.5;
        // at d = 1 the supply's resistance is in series with the motor's
        let out = s.drive(1.0, 0.3, 7.4, true);
        let expected = 0.366 * (7.4 - 0.366 * 0.3) / (2.81 + 0.5);
        assert!((out.torque - expected).abs() < 1e-12, "{} vs {expected}", out.torque);
        // the supply gives d·i at the voltage it has left
        assert!((out.supply - (7.4 - 0.5 * out.current)).abs() < 1e-12);
    }

    #[test]
    fn static_error_is_the_position_loops_closed_form() {
        let s = xl330();
        let load = 0.2;
        let e = s.static_error(load).unwrap();
        let mut state = FirmwareState::default();
        let out = s.tick(&mut state, e, 0.0, 0.0, 0.005, 7.4, true);
        assert!((out.torque - load).abs() < 1e-12);
        assert!(s.static_error(10.0).is_none());
    }
}
