//! A hybrid stepper motor. Its static torque against the load angle is T_H·sin(N_r·Δθ) (N_r = 50 rotor
//! teeth for 1.8°: one electrical period is 4 full steps); the torque it can give while turning
//! falls with speed (the pull-out curve), because the phase current cannot follow.

use super::{Detent, Motor, TorqueSpeed};

/// The pull-out torque against speed.
#[derive(Clone, Debug)]
pub enum PullOut {
    /// Measured points (rev/s, N·m), speeds increasing; linear in between, the last torque beyond.
    Table(Vec<(f64, f64)>),
    /// From the winding and the drive: the current reaches its set point only while a full step lasts
    /// longer than the time the supply needs to drive it through the inductance, t = 2·L·I/V. Below the
    /// corner speed f_c = V/(2·L·I·steps_per_rev) rev/s (a common estimate, ../shared/reference/motors.md)
    /// the motor gives its holding torque; above it the current, and the torque, fall as f_c/f.
    Derived { inductance: f64, current: f64, supply_voltage: f64 },
}

#[derive(Clone, Debug)]
pub struct Stepper {
    pub name: String,
    pub holding_torque: f64,
    pub rotor_inertia: f64,
    /// Full-step angle, degrees (1.8 for a 200-step motor).
    pub step_angle_deg: f64,
    pub pull_out: PullOut,
    /// Viscous damping of the rotor's oscillation about the field, N·m·s/rad at the shaft, acting on
    /// the slip speed: the back-EMF's through the winding resistance, c = K_t²/R with K_t ≈ T_H/I
    /// (0.037 for the 17HS4401). An estimate, upper bound: a chopper drive that holds the current
    /// removes part of it. 0 when the catalogue gives no resistance.
    pub damping: f64,
    /// The detent (residual, unpowered) torque's amplitude, N·m at the shaft (0 when not given).
    pub detent_torque: f64,
}

impl Stepper {
    pub fn steps_per_rev(&self) -> f64 {
        360.0 / self.step_angle_deg
    }

    /// Its detent torque's amplitude and period: the magnets pull the rotor to the nearest detent
    /// position, −T_d·sin(2π·angle/step), one period per full step, the first harmonic of a hybrid
    /// stepper's cogging (its unpowered rest positions are the full steps).
    pub fn detent(&self) -> Detent {
        Detent::new(self.detent_torque, self.step_angle_deg.to_radians())
    }

    /// The corner speed of a derived pull-out curve, rev/s.
    pub fn corner_speed_rev_s(&self) -> Option<f64> {
        match self.pull_out {
            PullOut::Derived { inductance, current, supply_voltage } => Some(supply_voltage / (2.0 * inductance * current * self.steps_per_rev())),
            PullOut::Table(_) => None,
        }
    }
}

impl Motor for Stepper {
    fn boxed_clone(&self) -> Box<dyn Motor> {
        Box::new(self.clone())
    }
    fn torque_at(&self, speed: f64) -> f64 {
        match &self.pull_out {
            // the closed form (it never asks the motor back)
            PullOut::Derived { .. } => self.torque_speed().at(speed, self).0,
            PullOut::Table(points) => {
                let rev_s = speed.abs() / std::f64::consts::TAU;
                let first = points[0];
                if rev_s <= first.0 {
                    return first.1;
                }
                for w in points.windows(2) {
                    let ((s0, t0), (s1, t1)) = (w[0], w[1]);
                    if rev_s <= s1 {
                        return t0 + (t1 - t0) * (rev_s - s0) / (s1 - s0);
                    }
                }
                points[points.len() - 1].1
            }
        }
    }

    fn torque_speed(&self) -> TorqueSpeed {
        match self.corner_speed_rev_s() {
            Some(corner_rev_s) => TorqueSpeed::Corner { torque: self.holding_torque, corner: corner_rev_s * std::f64::consts::TAU },
            None => TorqueSpeed::Motor,
        }
    }

    fn rotor_inertia(&self) -> f64 {
        self.rotor_inertia
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn describe(&self) -> String {
        let curve = match self.corner_speed_rev_s() {
            Some(c) => format!("pull-out T_H up to {c:.1} rev/s, then ∝ 1/speed"),
            None => "pull-out from a table".into(),
        };
        format!("{}: stepper, holding {} N·m, {}° per step, {curve}", self.name, self.holding_torque, self.step_angle_deg)
    }

    fn as_stepper(&self) -> Option<&Stepper> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The detent torque repeats every full step, is zero on the full steps (the rest positions)
    /// and pulls towards the nearest one with at most T_d (a quarter step away).
    #[test]
    fn detent_has_one_period_per_full_step_and_pulls_to_the_nearest_full_step() {
        let stepper = Stepper { name: "s".into(), holding_torque: 0.4, rotor_inertia: 5.4e-6, step_angle_deg: 1.8, pull_out: PullOut::Table(vec![(0.0, 0.4)]), damping: 0.0, detent_torque: 0.022 };
        let (detent, step) = (stepper.detent(), 1.8f64.to_radians());
        for k in [-3.0, 0.0, 1.0, 7.0] {
            assert!(detent.at(k * step).abs() < 1e-15, "zero on full step {k}");
            assert!((detent.at(k * step + 0.25 * step) + 0.022).abs() < 1e-15, "a quarter step past: pulled back with T_d");
            assert!((detent.at(k * step - 0.25 * step) - 0.022).abs() < 1e-15);
        }
        assert!((detent.at(0.1 * step) - detent.at(1.1 * step)).abs() < 1e-15);
    }
}
