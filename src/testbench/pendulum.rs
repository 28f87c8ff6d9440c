//! The pendulum bench of BAM's logs: a point mass m at the tip of a uniform rod of mass m_a and
//! length l on the servo's output shaft, q = 0 hanging straight down, q counter-clockwise.

/// Standard gravity, as BAM's bench uses it.
pub const GRAVITY: f64 = 9.80665;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pendulum {
    pub mass: f64,
    pub arm_mass: f64,
    pub length: f64,
    /// g, m/s² (BAM's [`GRAVITY`]).
    pub gravity: f64,
}

impl Pendulum {
    pub fn from_log(log: &super::BenchLog, gravity: f64) -> Self {
        Self { mass: log.mass, arm_mass: log.arm_mass, length: log.length, gravity }
    }

    /// Its inertia about the pivot, m·l² + (m_a/3)·l², kg·m² (the servo's armature not included).
    pub fn inertia(&self) -> f64 {
        self.mass * self.length * self.length + self.arm_mass / 3.0 * self.length * self.length
    }

    /// The gravity torque at angle `q` (the bench's offset included by the caller):
    /// −(m + m_a/2)·g·l·sin q, N·m.
    #[inline]
    pub fn gravity_torque(&self, q: f64) -> f64 {
        // BAM's product order: (m + m_a/2)·(−g)·l·sin q
        (self.mass + self.arm_mass / 2.0) * -self.gravity * self.length * q.sin()
    }
}
