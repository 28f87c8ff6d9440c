//! A DC motor or hobby servo: a linear torque–speed line from the stall torque at rest to zero at
//! the no-load speed, T(ω) = T_stall·(1 − |ω|/ω₀), clamped at 0 (Isaac Lab's `DCMotor`, Newton's
//! `ClampingDCMotor`; MuJoCo's `dcmotor` without inductance). Against the motion the back-EMF adds
//! to the drive voltage: the line gives T_stall·(1 + |ω|/ω₀), held to the stall torque (Isaac Lab
//! clips it to the effort limit) — a servo pushed past its no-load speed still brakes.

use super::{Motor, TorqueSpeed};

#[derive(Clone, Debug)]
pub struct DcServo {
    pub name: String,
    /// N·m at the shaft this entry describes (a servo's output shaft: its internal gearbox included).
    pub stall_torque: f64,
    /// rad/s.
    pub no_load_speed: f64,
    pub rotor_inertia: f64,
}

impl Motor for DcServo {
    fn boxed_clone(&self) -> Box<dyn Motor> {
        Box::new(self.clone())
    }
    fn torque_at(&self, speed: f64) -> f64 {
        self.torque_speed().at(speed, self).0
    }

    fn braking_torque_at(&self, speed: f64) -> f64 {
        self.torque_speed().at(speed, self).1
    }

    fn torque_speed(&self) -> TorqueSpeed {
        TorqueSpeed::Line { stall: self.stall_torque, no_load: self.no_load_speed }
    }

    fn rotor_inertia(&self) -> f64 {
        self.rotor_inertia
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn describe(&self) -> String {
        format!("{}: servo, stall {} N·m, no-load {:.3} rad/s", self.name, self.stall_torque, self.no_load_speed)
    }
}
