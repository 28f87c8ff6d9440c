use super::Trajectory;

/// A command brought in from the start pose: q(t) = q₀ + s(t)·(w(t) − q₀), with w the command
/// wrapped and s the quintic smoothstep from 0 to 1 over `duration` (s, s′ and s″ zero at 0; s = 1,
/// s′ = s″ = 0 at the end). The arm starts at rest at q₀ and its command starts there too, in
/// position and with zero velocity and acceleration, so the run's first second shows the motion's
/// own demand rather than a PD loop catching up with a command that jumped away (on Panda and UR5
/// that jump saturated the shoulders for half a second; on the SO-100 it spiked the shoulder's
/// torque to 26 N·m where the motion needs 0.25). A blend rather than a shifted wave: the wave keeps
/// its centre and phases, which the default experiment fitted to the joints' ranges and motors.
pub struct RampIn {
    pub inner: Box<dyn Trajectory>,
    pub start: Vec<f64>,
    /// s.
    pub duration: f64,
}

impl RampIn {
    /// The longest ramp: 2 s, or a quarter of the command's period when that is shorter (then the
    /// ramp's own acceleration, (w − q₀)·s″ ≤ 5.8·(w − q₀)/T², stays of the order of the wave's
    /// A·ω² for the same distance).
    pub const LONGEST: f64 = 2.0;

    pub fn new(inner: Box<dyn Trajectory>, start: Vec<f64>) -> Self {
        let duration = inner.period().map_or(Self::LONGEST, |p| (p / 4.0).min(Self::LONGEST));
        Self { inner, start, duration }
    }

    /// s, s′ and s″ at time t.
    fn blend(&self, t: f64) -> (f64, f64, f64) {
        if t >= self.duration {
            return (1.0, 0.0, 0.0);
        }
        let x = (t / self.duration).max(0.0);
        let s = x * x * x * (10.0 - 15.0 * x + 6.0 * x * x);
        let ds = 30.0 * x * x * (1.0 - x) * (1.0 - x) / self.duration;
        let dds = 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x) / (self.duration * self.duration);
        (s, ds, dds)
    }
}

impl Trajectory for RampIn {
    fn sample(&self, t: f64, cmd: &mut [f64], cmd_dot: &mut [f64]) {
        self.inner.sample(t, cmd, cmd_dot);
        let (s, ds, _) = self.blend(t);
        if s == 1.0 {
            return;
        }
        for ((c, cd), q0) in cmd.iter_mut().zip(cmd_dot.iter_mut()).zip(&self.start) {
            let offset = *c - q0;
            *cd = ds * offset + s * *cd;
            *c = q0 + s * offset;
        }
    }

    /// The wrapped command's period: after the ramp it repeats with it.
    fn period(&self) -> Option<f64> {
        self.inner.period()
    }

    fn periodic_from(&self) -> f64 {
        self.duration + self.inner.periodic_from()
    }

    fn describe(&self) -> String {
        format!("{}, brought in from the start pose over {:.3} s (quintic blend)", self.inner.describe(), self.duration)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::trajectory::Wave;

    #[test]
    fn starts_at_the_start_pose_at_rest_and_is_the_wave_after_the_ramp() {
        let start = vec![0.3, -0.2, 0.0, 0.1, 0.0, 0.5];
        let ramp = RampIn::new(Box::new(Wave { amplitude_rad: 0.5, omega: 0.5 }), start.clone());
        assert_eq!(ramp.duration, 2.0);
        let (mut c, mut cd) = (vec![0.0; 6], vec![0.0; 6]);
        ramp.sample(0.0, &mut c, &mut cd);
        assert_eq!(c, start);
        assert!(cd.iter().all(|&v| v == 0.0));
        // velocity is the derivative of position (central difference), through the ramp
        let (mut a, mut b, mut ad) = (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
        for t in [0.1, 0.7, 1.3, 1.99, 2.5] {
            let e = 1e-6;
            ramp.sample(t + e, &mut a, &mut ad);
            ramp.sample(t - e, &mut b, &mut ad);
            ramp.sample(t, &mut c, &mut cd);
            for i in 0..6 {
                assert!(((a[i] - b[i]) / (2.0 * e) - cd[i]).abs() < 1e-7, "t = {t}, joint {i}");
            }
        }
        let wave = Wave { amplitude_rad: 0.5, omega: 0.5 };
        let (mut w, mut wd) = (vec![0.0; 6], vec![0.0; 6]);
        for t in [2.0, 3.0, 10.0] {
            ramp.sample(t, &mut c, &mut cd);
            wave.sample(t, &mut w, &mut wd);
            assert_eq!((&c, &cd), (&w, &wd), "t = {t}");
        }
    }
}
