//! What a drive train lets a controller command at a joint speed, with what does not change from
//! step to step worked out once: the motor's torque–speed curve as plain numbers where its kind has
//! one in closed form ([`TorqueSpeed`]), the gearbox's caps, a stepper's detent. The control loop
//! asks this of every joint at every step; a motor kind without a closed form is asked through its
//! [`Motor`] as before.

use super::{DriveTrain, Motor};
use std::f64::consts::TAU;

/// A motor's torque–speed curve, with the motion and against it, at its shaft.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TorqueSpeed {
    /// `torque` up to the corner speed (rad/s at the shaft), then falling as corner/speed, either
    /// way: a stepper's derived pull-out curve ([`super::Stepper`]).
    Corner { torque: f64, corner: f64 },
    /// T_stall·(1 − |ω|/ω₀), not below 0, with the motion; T_stall against it: a DC servo's line
    /// ([`super::DcServo`]).
    Line { stall: f64, no_load: f64 },
    /// Only the motor can say (a measured table, a servo's firmware on its supply).
    Motor,
}

impl TorqueSpeed {
    /// (with the motion, against it) at shaft speed `speed`, rad/s; `motor` answers for [`Self::Motor`].
    pub fn at(&self, speed: f64, motor: &dyn Motor) -> (f64, f64) {
        match *self {
            TorqueSpeed::Corner { torque, corner } => {
                let t = if speed.abs() <= corner { torque } else { torque * corner / speed.abs() };
                (t, t)
            }
            TorqueSpeed::Line { stall, no_load } => ((stall * (1.0 - speed.abs() / no_load)).max(0.0), stall),
            TorqueSpeed::Motor => (motor.torque_at(speed), motor.braking_torque_at(speed)),
        }
    }
}

/// A stepper's detent (unpowered cogging) torque: −T_d·sin(2π·angle/step), one period per full
/// step, the first harmonic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detent {
    /// T_d, N·m at the shaft.
    amplitude: f64,
    /// 2π over one full step, per rad.
    per_rad: f64,
}

impl Detent {
    /// The detent of amplitude T_d (N·m at the shaft) and full step `full_step` (rad).
    pub fn new(amplitude: f64, full_step: f64) -> Self {
        Detent { amplitude, per_rad: TAU / full_step }
    }

    /// Its amplitude T_d, N·m at the shaft.
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// The torque at rotor angle `angle` (rad) from a detent position.
    pub fn at(&self, angle: f64) -> f64 {
        -self.amplitude * (self.per_rad * angle).sin()
    }

    /// The same at the rotor's electrical angle e (N_r·angle), given as sin e and cos e: a full step
    /// is a quarter of an electrical period, so the detent is −T_d·sin 4e.
    pub fn at_electrical(&self, sin_e: f64, cos_e: f64) -> f64 {
        let (sin_2e, cos_2e) = (2.0 * sin_e * cos_e, (cos_e - sin_e) * (cos_e + sin_e));
        -self.amplitude * 2.0 * sin_2e * cos_2e
    }
}

/// One drive train as the control step sees it.
#[derive(Clone, Copy, Debug)]
pub struct DriveEnvelope {
    gear_ratio: f64,
    curve: TorqueSpeed,
    /// The most of the motor's torque at the joint (before the gearbox's losses) that keeps the
    /// gearbox within its rating: driving rated/η, braking rated·η_b (a self-locking gear: rated).
    driving_cap: f64,
    braking_cap: f64,
    /// A stepper's detent, where it has one.
    detent: Option<Detent>,
}

impl DriveEnvelope {
    pub fn of(drive: &DriveTrain) -> Self {
        let gear = &drive.gear;
        DriveEnvelope {
            gear_ratio: drive.gear_ratio,
            curve: drive.motor.torque_speed(),
            driving_cap: drive.rated_torque / gear.efficiency,
            braking_cap: if gear.self_locking() { drive.rated_torque } else { drive.rated_torque * gear.backdrive_efficiency },
            detent: drive.motor.as_stepper().map(|s| s.detent()).filter(|d| d.amplitude() != 0.0),
        }
    }

    /// The range of the motor's torque at the joint before the gearbox's losses, N·T, at joint
    /// speed `speed` (lowest ≤ 0, highest ≥ 0): its curve with the motion and against it, each
    /// capped by the gearbox's rating. `motor` is the drive train's (asked only when its curve has
    /// no closed form).
    pub fn torque_range(&self, speed: f64, motor: &dyn Motor) -> (f64, f64) {
        let (with, against) = self.motor_torque(speed, motor);
        let driving = with.min(self.driving_cap);
        let braking = against.min(self.braking_cap);
        // at rest a positive torque counts as with the motion
        if speed >= 0.0 { (-braking, driving) } else { (-driving, braking) }
    }

    /// The motor's torque at the joint, N·T, with the motion and against it at joint speed `speed`
    /// (before the gearbox's losses and caps).
    pub fn motor_torque(&self, speed: f64, motor: &dyn Motor) -> (f64, f64) {
        let (with, against) = self.curve.at(self.gear_ratio * speed, motor);
        (self.gear_ratio * with, self.gear_ratio * against)
    }

    /// The most of the motor's torque at the joint that keeps the gearbox within its rating when
    /// the motor drives: rated/η.
    pub fn driving_cap(&self) -> f64 {
        self.driving_cap
    }

    /// A stepper's detent torque at the joint, N·T_d(N·offset), with the joint `offset` (rad) from
    /// where the rotor sat in a detent position; 0 for other motors.
    pub fn detent_torque(&self, offset: f64) -> f64 {
        self.detent.map_or(0.0, |d| self.gear_ratio * d.at(self.gear_ratio * offset))
    }

    /// The same with the rotor's electrical angle given as its sine and cosine ([`Detent::at_electrical`]).
    pub fn detent_torque_at_phase(&self, sin_electrical: f64, cos_electrical: f64) -> f64 {
        self.detent.map_or(0.0, |d| self.gear_ratio * d.at_electrical(sin_electrical, cos_electrical))
    }
}
