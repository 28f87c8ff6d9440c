//! A command shifted by a constant per joint: a recording's poses in the arm's true angles where
//! the recording's zero is not the URDF's (a calibration offset being identified).

use super::Trajectory;

pub struct Shifted {
    pub inner: Box<dyn Trajectory>,
    /// Added to each joint's position, rad (m).
    pub offsets: Vec<f64>,
}

impl Trajectory for Shifted {
    fn sample(&self, t: f64, cmd: &mut [f64], cmd_dot: &mut [f64]) {
        self.inner.sample(t, cmd, cmd_dot);
        for (c, o) in cmd.iter_mut().zip(&self.offsets) {
            *c += o;
        }
    }

    fn describe(&self) -> String {
        format!("{}, shifted by {:?} rad", self.inner.describe(), self.offsets)
    }

    fn period(&self) -> Option<f64> {
        self.inner.period()
    }

    fn periodic_from(&self) -> f64 {
        self.inner.periodic_from()
    }
}
