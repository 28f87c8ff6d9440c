use super::Trajectory;

/// The tutorial's wave: joint i follows A·sin(ω t + i·π/3), so the joints move out of phase.
#[derive(Clone, Debug)]
pub struct Wave {
    pub amplitude_rad: f64,
    /// ω in rad/s (the tutorial's `--freq`).
    pub omega: f64,
}

impl Trajectory for Wave {
    fn sample(&self, t: f64, cmd: &mut [f64], cmd_dot: &mut [f64]) {
        for (i, (c, cd)) in cmd.iter_mut().zip(cmd_dot.iter_mut()).enumerate() {
            let phase = self.omega * t + i as f64 * std::f64::consts::FRAC_PI_3;
            let (s, co) = phase.sin_cos();
            *c = self.amplitude_rad * s;
            *cd = self.amplitude_rad * self.omega * co;
        }
    }

    fn period(&self) -> Option<f64> {
        super::wave_period(self.omega)
    }

    fn describe(&self) -> String {
        format!("wave: A·sin(ω·t + i·π/3), A = {:.4} rad ({:.1}°), ω = {} rad/s", self.amplitude_rad, self.amplitude_rad.to_degrees(), self.omega)
    }
}
