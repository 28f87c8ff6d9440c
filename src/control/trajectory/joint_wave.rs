use super::Trajectory;
use crate::model::{JointKind, Model};

/// The tutorial's wave fitted to any arm: joint i follows c_i + A_i·sin(ω t + i·π/3) around the
/// start pose, with A_i the tutorial's amplitude (30°) but at most a quarter of the joint's range
/// (a Panda finger has 4 cm), prismatic joints in metres, and c_i the start position moved inside
/// the range far enough for the whole swing to fit.
#[derive(Clone, Debug)]
pub struct JointWave {
    pub centre: Vec<f64>,
    pub amplitude: Vec<f64>,
    /// ω in rad/s (`--freq`).
    pub omega: f64,
}

/// A prismatic joint's amplitude for the tutorial's 30°: 5 cm.
const PRISMATIC_AMPLITUDE_PER_30_DEG: f64 = 0.05;

impl JointWave {
    /// The wave of amplitude `amplitude_deg` (revolute) around `start`, fitted to each joint's range.
    pub fn fitted(model: &Model, start: &[f64], amplitude_deg: f64, omega: f64) -> Self {
        let (mut centre, mut amplitude) = (Vec::new(), Vec::new());
        for (j, &q0) in model.joints.iter().zip(start) {
            let wanted = match j.kind {
                JointKind::Prismatic => PRISMATIC_AMPLITUDE_PER_30_DEG * amplitude_deg / 30.0,
                JointKind::Revolute | JointKind::Continuous => amplitude_deg.to_radians(),
            };
            let range = j.upper - j.lower;
            let a = if range.is_finite() { wanted.min(range / 4.0) } else { wanted };
            let c = if range.is_finite() { q0.clamp(j.lower + a, j.upper - a) } else { q0 };
            amplitude.push(a);
            centre.push(c);
        }
        Self { centre, amplitude, omega }
    }

    /// Whether this is the tutorial's wave: the same amplitude on every joint, around 0.
    pub fn is_uniform_about_zero(&self, amplitude: f64) -> bool {
        self.amplitude.iter().all(|&a| a == amplitude) && self.centre.iter().all(|&c| c == 0.0)
    }
}

impl Trajectory for JointWave {
    fn sample(&self, t: f64, cmd: &mut [f64], cmd_dot: &mut [f64]) {
        for (i, (c, cd)) in cmd.iter_mut().zip(cmd_dot.iter_mut()).enumerate() {
            let phase = self.omega * t + i as f64 * std::f64::consts::FRAC_PI_3;
            let (s, co) = phase.sin_cos();
            *c = self.centre[i] + self.amplitude[i] * s;
            *cd = self.amplitude[i] * self.omega * co;
        }
    }

    fn period(&self) -> Option<f64> {
        super::wave_period(self.omega)
    }

    fn describe(&self) -> String {
        let list = |v: &[f64]| v.iter().map(|x| format!("{x:.4}")).collect::<Vec<_>>().join(", ");
        format!("wave fitted to the joints: c_i + A_i·sin(ω·t + i·π/3), A = [{}], c = [{}], ω = {} rad/s", list(&self.amplitude), list(&self.centre), self.omega)
    }
}
