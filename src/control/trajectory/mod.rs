//! Joint commands over time. A new kind of command is one new file implementing [`Trajectory`].

mod hold;
mod joint_wave;
mod ramp_in;
mod schedule;
mod shifted;
mod step;
mod wave;

pub use hold::Hold;
pub use joint_wave::JointWave;
pub use ramp_in::RampIn;
pub use schedule::JointSchedule;
pub use shifted::Shifted;
pub use step::JointStep;
pub use wave::Wave;

/// A joint-space command schedule: position and velocity targets at time t.
pub trait Trajectory: Send + Sync {
    fn sample(&self, t: f64, cmd: &mut [f64], cmd_dot: &mut [f64]);
    /// One line for the console and the recordings' configuration.
    fn describe(&self) -> String;
    /// The time after which the command repeats itself, if it does (a wave's 2π/ω).
    fn period(&self) -> Option<f64> {
        None
    }
    /// The time from which it repeats with [`Trajectory::period`]: 0, or where a ramp-in ends.
    fn periodic_from(&self) -> f64 {
        0.0
    }
}

/// The part of a `duration`-second command that holds all of its motion: up to the end of its
/// first period after it starts repeating (the rest repeats what is in it), or the whole run.
pub fn span_with_every_motion(trajectory: &dyn Trajectory, duration: f64) -> f64 {
    trajectory.period().map_or(duration, |period| (trajectory.periodic_from() + period).min(duration))
}

/// 2π/ω for a wave of angular frequency ω (none for ω = 0: it stands still).
pub(crate) fn wave_period(omega: f64) -> Option<f64> {
    (omega != 0.0 && omega.is_finite()).then(|| std::f64::consts::TAU / omega.abs())
}
