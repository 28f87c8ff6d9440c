//! A gearbox's losses as friction at the joint, by the direction power flows — Modelica's
//! `LossyGear` (Pelchen, Schweiger, Otter, "Modeling and simulating the efficiency of gearboxes and
//! of planetary gearboxes", Modelica 2002; ../shared/reference/friction.md, "Gearbox friction").
//!
//! The motor gives u = N·τ_m at the joint before losses (N the ratio, τ_m its torque). The gear
//! adds a friction torque τ_f at the joint, opposing the joint's motion q̇:
//!
//! ```text
//!   q̇ > 0:  τ_f = −F⁺(u),   q̇ < 0:  τ_f = +F⁻(u),   q̇ = 0:  −F⁺(u) ≤ τ_f ≤ F⁻(u)  (stuck)
//!   F⁺(u) = F_b + loss(u),  F⁻(u) = F_b + loss(−u),  plus the viscous c·q̇
//!   loss(d) = (1 − η)·d          d > 0: the motor drives the load, the joint gets η·N·τ_m
//!           = (1/η_b − 1)·|d|    d < 0: the load back-drives the motor, which holds it with
//!                                        N·τ_m = η_b·τ_load (the friction helps it hold)
//!           = ∞                  d ≤ 0 and η_b ≤ 0: a self-locking drive (a worm) is not
//!                                        back-driven at all, with the motor off too
//! ```
//!
//! So a motor lowering a load with the gear's help needs only η_b of the load's torque, and one
//! raising it gives η of its own — the opposite of a constant η on the motor, which gives a lowered
//! arm less holding torque than a raised one. F_b is the breakaway (Coulomb) torque at the output: a
//! strain-wave gear's starting torque, which Harmonic Drive says must not be relied on to hold a
//! load (it is a friction like any other here: it holds what it can, no more). The loss is taken
//! from the motor's torque (Modelica's τ_a), with the rotor's inertia lumped at the joint (J_r·N² in
//! M): the rotor's own inertial torque is not in the tooth load.

/// One drive train's losses, at the joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LossyGear {
    /// η, when the motor drives the load (0, 1].
    pub efficiency: f64,
    /// η_b, when the load drives the motor, ≤ 1; ≤ 0: self-locking.
    pub backdrive_efficiency: f64,
    /// F_b, N·m at the joint: the friction at no load (breakaway).
    pub breakaway_torque: f64,
    /// c, N·m·s/rad at the joint.
    pub viscous: f64,
}

impl LossyGear {
    /// No losses at all.
    pub const LOSSLESS: LossyGear = LossyGear { efficiency: 1.0, backdrive_efficiency: 1.0, breakaway_torque: 0.0, viscous: 0.0 };

    /// A gear that loses the same fraction both ways (η_b = η), with no friction at no load.
    pub fn with_efficiency(efficiency: f64) -> Self {
        LossyGear { efficiency, backdrive_efficiency: efficiency, ..Self::LOSSLESS }
    }

    pub fn is_lossless(&self) -> bool {
        *self == Self::LOSSLESS
    }

    /// Whether the load cannot drive the motor (η_b ≤ 0).
    pub fn self_locking(&self) -> bool {
        self.backdrive_efficiency <= 0.0
    }

    /// (F⁺, F⁻): the Coulomb friction against positive and against negative joint motion when the
    /// motor gives `motor_torque` (N·τ_m) at the joint; infinite on a side the drive locks.
    pub fn friction_bounds(&self, motor_torque: f64) -> (f64, f64) {
        self.losses().friction_bounds(motor_torque)
    }

    /// Its losses as the coefficients a loop asks at every step.
    pub fn losses(&self) -> GearLosses {
        GearLosses { breakaway: self.breakaway_torque, driving: 1.0 - self.efficiency, back_driven: if self.self_locking() { f64::INFINITY } else { 1.0 / self.backdrive_efficiency - 1.0 } }
    }

    /// The torque the joint gets while it moves in `direction` (> 0 or < 0) at `speed` with the
    /// motor at `motor_torque` (u + τ_f, the viscous part included): what the motor's torque becomes
    /// through the gear; ±∞ where a self-locking gear takes whatever the load asks.
    pub fn output_torque(&self, motor_torque: f64, direction: f64, speed: f64) -> f64 {
        let (up, down) = self.friction_bounds(motor_torque);
        let coulomb = if direction > 0.0 { -up } else { down };
        motor_torque + coulomb - self.viscous * speed
    }

    /// The motor's torque at the joint, |u| (before the losses), that gives the joint `joint_torque`
    /// at `speed` (at rest: as if moving with the torque): driving the motion, (|τ + c·q̇| + F_b)/η;
    /// held back by it, η_b·(|τ + c·q̇| − F_b) (the friction helps; 0 when it holds alone or the gear
    /// locks). The inverse of [`Self::output_torque`], for sizing.
    pub fn motor_torque_for(&self, joint_torque: f64, speed: f64) -> f64 {
        let along = joint_torque + self.viscous * speed;
        let direction = if speed != 0.0 { speed.signum() } else { along.signum() };
        if along * direction >= 0.0 {
            (along.abs() + self.breakaway_torque) / self.efficiency
        } else if self.self_locking() {
            0.0
        } else {
            self.backdrive_efficiency * (along.abs() - self.breakaway_torque).max(0.0)
        }
    }

    /// This gear followed by another of ratio `ratio` (the joint turns `ratio` times slower than
    /// this gear's output): the efficiencies multiply (a self-locking stage locks the train), the
    /// first stage's breakaway and viscous losses are seen through the second (×η₂·N₂, ×N₂²).
    pub fn followed_by(&self, ratio: f64, next: &LossyGear) -> LossyGear {
        let backdrive = if self.self_locking() || next.self_locking() {
            self.backdrive_efficiency.min(next.backdrive_efficiency).min(0.0)
        } else {
            self.backdrive_efficiency * next.backdrive_efficiency
        };
        LossyGear {
            efficiency: self.efficiency * next.efficiency,
            backdrive_efficiency: backdrive,
            breakaway_torque: self.breakaway_torque * ratio * next.efficiency + next.breakaway_torque,
            viscous: self.viscous * ratio * ratio + next.viscous,
        }
    }
}

/// A gear's losses at the joint as coefficients, worked out once: the breakaway F_b, the share lost
/// driving (1 − η) and back-driven (1/η_b − 1; infinite for a self-locking gear).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GearLosses {
    breakaway: f64,
    driving: f64,
    back_driven: f64,
}

impl GearLosses {
    /// The load-dependent loss when the motor's torque at the joint along the motion is `along`
    /// (> 0: it drives the motion; < 0: the motion back-drives it).
    fn loss(&self, along: f64) -> f64 {
        if along > 0.0 {
            self.driving * along
        } else if self.back_driven.is_infinite() {
            f64::INFINITY
        } else {
            self.back_driven * -along
        }
    }

    /// [`LossyGear::friction_bounds`].
    pub fn friction_bounds(&self, motor_torque: f64) -> (f64, f64) {
        if self.back_driven.is_infinite() {
            return (self.breakaway + self.loss(motor_torque), self.breakaway + self.loss(-motor_torque));
        }
        // the same sums without a branch on the torque's sign, which swings step to step when a
        // joint chatters: one of the two parts is 0
        let (driving, back_driven) = (motor_torque.max(0.0), (-motor_torque).max(0.0));
        (self.breakaway + (self.driving * driving + self.back_driven * back_driven), self.breakaway + (self.driving * back_driven + self.back_driven * driving))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holding_band_is_eta_b_to_one_over_eta_of_the_load() {
        // gravity −G on the joint, the motor's u holds it still iff −F⁺ ≤ G − u ≤ F⁻ (u + τ_g + τ_f = 0)
        let gear = LossyGear { efficiency: 0.8, backdrive_efficiency: 0.5, breakaway_torque: 0.0, viscous: 0.0 };
        let g = 2.0;
        let holds = |u: f64| {
            let (up, down) = gear.friction_bounds(u);
            // (1e-12: the rounding of 1 − η and 1/η_b − 1)
            g - u <= down + 1e-12 && u - g <= up + 1e-12
        };
        assert!(holds(0.5 * g) && !holds(0.5 * g - 1e-9), "lowest holding torque η_b·G");
        assert!(holds(g / 0.8) && !holds(g / 0.8 + 1e-9), "highest holding torque G/η");
    }

    #[test]
    fn self_locking_locks_with_the_motor_off_and_against_the_motor() {
        let worm = LossyGear { efficiency: 0.4, backdrive_efficiency: -0.2, breakaway_torque: 0.1, viscous: 0.0 };
        assert_eq!(worm.friction_bounds(0.0), (f64::INFINITY, f64::INFINITY));
        let (up, down) = worm.friction_bounds(1.0);
        assert!((up - (0.1 + 0.6)).abs() < 1e-15 && down.is_infinite(), "drives forward with loss, locked backward");
        let efficient = LossyGear { backdrive_efficiency: 0.9, ..worm };
        assert_eq!(efficient.friction_bounds(0.0), (0.1, 0.1), "an efficient gear only has its breakaway with the motor off");
    }

    #[test]
    fn output_torque_by_power_flow() {
        let gear = LossyGear { efficiency: 0.9, backdrive_efficiency: 0.7, breakaway_torque: 0.0, viscous: 0.0 };
        assert!((gear.output_torque(1.0, 1.0, 1.0) - 0.9).abs() < 1e-15, "driving: η·u");
        assert!((gear.output_torque(1.0, -1.0, -1.0) - 1.0 / 0.7).abs() < 1e-12, "back-driven: u/η_b");
        assert!((gear.output_torque(-1.0, -1.0, -1.0) + 0.9).abs() < 1e-15);
    }

    #[test]
    fn two_stages_compose() {
        let a = LossyGear { efficiency: 0.9, backdrive_efficiency: 0.8, breakaway_torque: 0.01, viscous: 1e-4 };
        let b = LossyGear { efficiency: 0.95, backdrive_efficiency: 0.9, breakaway_torque: 0.02, viscous: 0.0 };
        let both = a.followed_by(4.0, &b);
        assert!((both.efficiency - 0.855).abs() < 1e-15 && (both.backdrive_efficiency - 0.72).abs() < 1e-15);
        assert!((both.breakaway_torque - (0.01 * 4.0 * 0.95 + 0.02)).abs() < 1e-15 && (both.viscous - 16e-4).abs() < 1e-18);
        let worm = LossyGear { backdrive_efficiency: -0.1, ..b };
        assert!(a.followed_by(4.0, &worm).self_locking() && worm.followed_by(2.0, &a).self_locking());
        assert_eq!(LossyGear::LOSSLESS.followed_by(3.0, &LossyGear::LOSSLESS), LossyGear::LOSSLESS);
    }

    #[test]
    fn motor_torque_for_inverts_output_torque() {
        let gear = LossyGear { efficiency: 0.8, backdrive_efficiency: 0.5, breakaway_torque: 0.1, viscous: 0.02 };
        for speed in [-1.5, 1.5] {
            for torque in [-2.0, -0.7, 0.7, 2.0] {
                let along = torque + gear.viscous * speed;
                let u = along.signum() * gear.motor_torque_for(torque, speed);
                let back = gear.output_torque(u, speed.signum(), speed);
                assert!((back - torque).abs() < 1e-12, "speed {speed}, torque {torque}: u = {u} gives {back}");
            }
        }
        // a load the friction holds alone, and a self-locking gear: the motor gives nothing
        assert_eq!(gear.motor_torque_for(-0.05, 1.0), 0.0);
        assert_eq!(LossyGear { backdrive_efficiency: -0.2, ..gear }.motor_torque_for(-2.0, 1.0), 0.0);
    }
}
