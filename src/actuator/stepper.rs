//! A hybrid stepper motor. Its static torque against the load angle is T_H·sin(N_r·Δθ) (N_r = 50 rotor
//! teeth for 1.8°: one electrical period is 4 full steps); the torque it can give while turning
//! falls with speed (the pull-out curve), because the phase current cannot follow.

use super::Motor;
use std::f64::consts::PI;

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
}

impl Stepper {
    pub fn steps_per_rev(&self) -> f64 {
        360.0 / self.step_angle_deg
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
    fn torque_at(&self, speed: f64) -> f64 {
        let rev_s = speed.abs() / (2.0 * PI);
        match &self.pull_out {
            PullOut::Derived { .. } => {
                let corner = self.corner_speed_rev_s().unwrap_or(f64::INFINITY);
                if rev_s <= corner { self.holding_torque } else { self.holding_torque * corner / rev_s }
            }
            PullOut::Table(points) => {
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
