//! What resists each joint's motion besides its damping: the URDF's Coulomb friction and the drive
//! train's gearbox losses ([`LossyGear`]: breakaway, viscous, and the load-dependent loss by the
//! direction power flows), and a serial-bus servo's own friction (BAM's budget M1–M6, from the
//! servo's torque, the joint's gravity torque and its speed at the step's start: `observe`), as one
//! Coulomb band and one viscous coefficient per joint for a plant step with the motor's torque held.
//! (BAM's external torque on a bench is gravity alone; on an arm it is the joint's gravity torque,
//! the other joints' inertial coupling left out.)

use super::stick_slip::JointLaw;
use crate::actuator::{GearLosses, LossyGear};
use crate::actuator::bus_servo::ServoFriction;
use crate::model::Model;

/// Per joint: the URDF's friction F and the gear's losses (None: no drive train, or a lossless one).
#[derive(Clone, Debug)]
pub struct JointFriction {
    coulomb: Vec<f64>,
    gears: Vec<Option<GearLosses>>,
    /// Per joint, its servo's friction and the ratio from the servo to the joint.
    servos: Vec<Option<(ServoFriction, f64)>>,
    /// The servos' inputs at the step's start: each joint's gravity torque and speed.
    external: Vec<f64>,
    speed: Vec<f64>,
    /// Per joint, the gear's and the servo's viscous friction at the joint, and whether it has any
    /// friction at all (worked out once: the plant asks at every step).
    viscous: Vec<f64>,
    has: Vec<bool>,
    /// Whether some joint has a servo's friction.
    servo_friction: bool,
    /// Whether any joint has friction or gear losses (without, the plants keep their plain update).
    pub any: bool,
}

impl JointFriction {
    /// The model's joint friction and the drive trains' gears (by coordinate; empty: none).
    pub fn new(model: &Model, gears: &[Option<LossyGear>]) -> Self {
        let coulomb: Vec<f64> = model.joints.iter().map(|j| j.friction).collect();
        let lossy: Vec<Option<LossyGear>> = (0..model.dof()).map(|i| gears.get(i).copied().flatten().filter(|g| !g.is_lossless())).collect();
        let n = coulomb.len();
        let mut friction = Self { coulomb, gears: lossy.iter().map(|g| g.map(|g| g.losses())).collect(), servos: vec![None; n], external: vec![0.0; n], speed: vec![0.0; n], viscous: lossy.iter().map(|g| g.map_or(0.0, |g| g.viscous)).collect(), has: vec![false; n], servo_friction: false, any: false };
        friction.update_has();
        friction
    }

    /// With the servos' friction (by coordinate, with the ratio from servo to joint).
    pub fn with_servos(mut self, servos: &[Option<(ServoFriction, f64)>]) -> Self {
        for ((slot, servo), viscous) in self.servos.iter_mut().zip(servos).zip(&mut self.viscous) {
            *slot = *servo;
            if let Some((servo, n)) = servo {
                *viscous += n * n * servo.viscous;
            }
        }
        self.update_has();
        self
    }

    fn update_has(&mut self) {
        for (i, has) in self.has.iter_mut().enumerate() {
            *has = self.coulomb[i] > 0.0 || self.gears[i].is_some() || self.servos[i].is_some();
        }
        self.any = self.has.contains(&true);
        self.servo_friction = self.servos.iter().any(Option::is_some);
    }

    /// Whether some joint has a servo's friction.
    pub fn has_servos(&self) -> bool {
        self.servo_friction
    }

    /// The step's start: each joint's gravity torque and speed (what the servos' budgets depend on).
    pub fn observe(&mut self, gravity: &[f64], speed: &[f64]) {
        self.external.copy_from_slice(gravity);
        self.speed.copy_from_slice(speed);
    }

    /// Whether some joint has a lossy gearbox.
    pub fn has_gears(&self) -> bool {
        self.gears.iter().any(Option::is_some)
    }

    /// Whether joint i has any friction (its friction torque and stuck flag mean something).
    pub fn has(&self, i: usize) -> bool {
        self.has[i]
    }

    /// (F⁺, F⁻) of joint i when the motor gives `u` at the joint: the friction against positive and
    /// against negative motion, infinite on a side a self-locking gear locks.
    pub fn bounds(&self, i: usize, u: f64) -> (f64, f64) {
        // a servo's budget at its output, ×N at the joint: its torque u/N, the load τ_e/N, speed N·q̇
        let f = match &self.servos[i] {
            Some((servo, n)) => self.coulomb[i] + n * servo.budget(u / n, self.external[i] / n, n * self.speed[i]),
            None => self.coulomb[i],
        };
        match &self.gears[i] {
            Some(gear) => {
                let (up, down) = gear.friction_bounds(u);
                (f + up, f + down)
            }
            None => (f, f),
        }
    }

    /// Every joint's (F⁺, F⁻) ([`Self::bounds`]) when the motors give `u` at the joints, into `out`.
    pub fn all_bounds(&self, u: &[f64], out: &mut [(f64, f64)]) {
        if self.servo_friction {
            for (i, (out, &u)) in out.iter_mut().zip(u).enumerate() {
                *out = self.bounds(i, u);
            }
            return;
        }
        for ((out, &u), (&f, gear)) in out.iter_mut().zip(u).zip(self.coulomb.iter().zip(&self.gears)) {
            *out = match gear {
                Some(gear) => {
                    let (up, down) = gear.friction_bounds(u);
                    (f + up, f + down)
                }
                None => (f, f),
            };
        }
    }

    /// The gear's and the servo's viscous coefficient at joint i, N·m·s/rad (added to the joint's
    /// damping).
    pub fn viscous(&self, i: usize) -> f64 {
        self.viscous[i]
    }

    /// The law for joint i with the bounds `scale`·(F⁺, F⁻) and the position bounds (lower, upper):
    /// a side with infinite friction becomes a bound at 0 (the joint cannot move that way). Returns
    /// the law and whether its upper / lower bound is such a lock rather than the given one.
    pub fn law(&self, i: usize, u: f64, scale: f64, lower: f64, upper: f64) -> (JointLaw, bool, bool) {
        Self::law_of(self.bounds(i, u), scale, lower, upper)
    }

    /// [`Self::law`] from the joint's bounds (F⁺, F⁻) already worked out.
    pub fn law_of((up, down): (f64, f64), scale: f64, lower: f64, upper: f64) -> (JointLaw, bool, bool) {
        let mut law = JointLaw { lower, upper, below: -scale * down, above: scale * up };
        let (mut locked_up, mut locked_down) = (false, false);
        if up.is_infinite() {
            law.above = 0.0;
            locked_up = law.upper > 0.0;
            law.upper = law.upper.min(0.0);
        }
        if down.is_infinite() {
            law.below = 0.0;
            locked_down = law.lower < 0.0;
            law.lower = law.lower.max(0.0);
        }
        if law.lower > law.upper {
            // a locked joint found past its limit: it stays where it is
            (law.lower, law.upper, locked_up, locked_down) = (0.0, 0.0, true, true);
        }
        (law, locked_up, locked_down)
    }
}
