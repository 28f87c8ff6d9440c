//! How tall each joint's torque plot is, in both recordings: tall enough for the motion's own
//! torque with the limit beside it, not for the limit alone. A viewer's automatic scale fits
//! everything plotted: the ±limit lines of a 35 N·m servo flatten a 0.25 N·m motion, and a
//! catch-up transient flattens the rest of the run. The motion's own torque is known before the
//! run: the inverse dynamics of following the command exactly (`control::demand`), what any drive
//! that tracks it supplies once settled; the recordings start with that scale (a live viewer needs
//! one) and end with the larger of it and what the run's drives settled to (`after_run`): a loop
//! that chatters against its limits is not what the command needs, but it is what happened.

use crate::control::demand::required_torque;
use crate::control::trajectory::span_with_every_motion;
use crate::experiment::Experiment;

/// A limit up to this many times the motion's peak torque is drawn in the plot; a larger one would
/// squeeze the motion into less than a quarter of the plot's half height, so it is left off scale
/// (its value in the plot's title) and the plot fits the motion.
pub const LIMIT_IN_VIEW: f64 = 4.0;
/// Room above the motion's peak: it is the exact motion's, and tracking it adds the loop's own
/// torque (the tutorial's J1 settles at 1.39× its exact motion's 0.024 N·m; other joints within 1.1×).
const HEADROOM_OVER_MOTION: f64 = 1.5;
/// Room above the limit when it is drawn, so the saturated steps at it are visible.
const HEADROOM_OVER_LIMIT: f64 = 1.1;
/// The demand is sampled at most this many times over a command that does not repeat, at most once
/// per control step: the plot's scale does not need more, and the cost must not grow with the run.
const DEMAND_SAMPLES: f64 = 20_000.0;
/// A repeating command is sampled this many times a period (at most once per control step): its
/// torque is smooth, a few harmonics of the command's own frequency, so its peak sampled this finely
/// is within ~10⁻⁵ of the exact one (tested on the tutorial's wave and its ramp-in), far below what
/// a plot's scale shows.
const DEMAND_SAMPLES_PER_PERIOD: f64 = 4096.0;

/// One joint's torque plot: from −`half_range` to +`half_range` N·m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueAxis {
    pub half_range: f64,
    /// The peak torque of following the command exactly (N·m).
    pub motion_peak: f64,
    /// The controller's limit at rest (N·m; infinite without an effort limit).
    pub limit: f64,
    /// Whether ±limit is within the plot.
    pub limit_in_view: bool,
}

impl TorqueAxis {
    /// The axis for a motion needing `motion_peak` under `limit`.
    pub fn new(motion_peak: f64, limit: f64) -> Self {
        let limited = limit.is_finite() && limit > 0.0;
        let limit_in_view = limited && (motion_peak <= 0.0 || limit <= LIMIT_IN_VIEW * motion_peak);
        let half_range = if limit_in_view {
            // the commanded torque is clipped at the limit: nothing plotted goes beyond it
            HEADROOM_OVER_LIMIT * limit
        } else if motion_peak > 0.0 {
            HEADROOM_OVER_MOTION * motion_peak
        } else {
            1.0 // nothing commanded and no limit: any scale shows zero
        };
        Self { half_range, motion_peak, limit, limit_in_view }
    }

    /// The axis once the run is over: the motion's torque is the larger of the exact motion's and
    /// the peak the run settled to (`settled_peak`, after the settling time; None when the run
    /// ended before it). A loop that chatters or saturates thereby gets its limit into the plot.
    pub fn after_run(&self, settled_peak: Option<f64>) -> Self {
        Self::new(self.motion_peak.max(settled_peak.unwrap_or(0.0)), self.limit)
    }

    /// The plot's title for joint `joint`.
    pub fn title(&self, joint: &str) -> String {
        if self.limit_in_view || !self.limit.is_finite() {
            format!("{joint} torque vs ±limit")
        } else {
            // short: a view's title is cut to its width; the missing limit lines say it is off the plot
            format!("{joint} torque (limit ±{} N·m)", significant(self.limit))
        }
    }
}

/// Three significant digits, without trailing zeros.
fn significant(x: f64) -> String {
    let digits = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s }
}

/// A run's torque axes, worked out the first time they are asked for (by whichever recorder
/// asks first; one that asks meanwhile waits for the same axes).
pub struct LazyAxes<'a> {
    experiment: &'a Experiment,
    axes: std::sync::OnceLock<Vec<TorqueAxis>>,
}

impl<'a> LazyAxes<'a> {
    pub fn of(experiment: &'a Experiment) -> Self {
        Self { experiment, axes: std::sync::OnceLock::new() }
    }

    pub fn get(&self) -> &[TorqueAxis] {
        self.axes.get_or_init(|| torque_axes(self.experiment))
    }
}

/// Every joint's torque axis for `experiment`'s run. A repeating command is walked up to the end of
/// its first period (after a ramp-in): the rest of the run repeats it (the 30 s wave, 12.6 s long,
/// was a tenth of the 30 s run's instructions, walked 2.4 times over).
pub fn torque_axes(experiment: &Experiment) -> Vec<TorqueAxis> {
    let span = span_with_every_motion(experiment.trajectory.as_ref(), experiment.config.duration);
    let dt = experiment.dt().max(demand_step(experiment.trajectory.as_ref(), span));
    let motion = required_torque(&experiment.model, experiment.trajectory.as_ref(), span, dt);
    let limits = experiment.controller().limits_at_rest();
    let actuated: Vec<bool> = (0..experiment.model.dof()).map(|i| experiment.model.is_actuated(i)).collect();
    motion
        .iter()
        .zip(&limits)
        .zip(&actuated)
        // an unactuated joint's torque is zero: its plot shows only that
        .map(|((&peak, &limit), &actuated)| if actuated { TorqueAxis::new(peak, limit) } else { TorqueAxis::new(0.0, f64::INFINITY) })
        .collect()
}

/// The demand's sampling step over `span` of `trajectory` (before the control period's floor).
fn demand_step(trajectory: &dyn crate::control::trajectory::Trajectory, span: f64) -> f64 {
    trajectory.period().map_or(span / DEMAND_SAMPLES, |period| period / DEMAND_SAMPLES_PER_PERIOD)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_limit_near_the_motion_is_drawn_and_a_far_one_is_left_off_scale() {
        // the SO-100's shoulder: 0.25 N·m of motion under a 35 N·m limit
        let far = TorqueAxis::new(0.25, 35.0);
        assert!(!far.limit_in_view);
        assert!((far.half_range - 0.375).abs() < 1e-12);
        assert_eq!(far.title("shoulder_lift"), "shoulder_lift torque (limit ±35 N·m)");
        // a motion that needs a third of its limit: both in the plot
        let near = TorqueAxis::new(1.0, 3.0);
        assert!(near.limit_in_view);
        assert!((near.half_range - 3.3).abs() < 1e-12);
        assert_eq!(near.title("elbow"), "elbow torque vs ±limit");
        // a motion beyond its limit (it saturates): the torque is clipped at the limit
        assert!((TorqueAxis::new(5.0, 2.0).half_range - 2.2).abs() < 1e-12);
        // no motion: the limit
        assert!(TorqueAxis::new(0.0, 2.0).limit_in_view);
        // a run that settled to more than its motion needs (a chattering loop at its limit)
        assert!(far.after_run(Some(35.0)).limit_in_view);
        assert_eq!(far.after_run(None), far);
        assert_eq!(far.after_run(Some(0.1)), far);
        assert_eq!(significant(0.0123456), "0.0123");
        assert_eq!(significant(87.0), "87");
        assert_eq!(significant(1.26), "1.26");
    }

    /// A repeating command has all of its motion within its first period after it starts repeating:
    /// the peaks over that span and over a 30 s run, sampled every control step, agree to the
    /// sampling's own precision (the 1 ms samples of the run fall at other phases of the wave:
    /// a smooth peak sampled 1 ms off moves by ~(ω·1 ms)²/8, 3·10⁻⁸ relative at ω = 0.5 rad/s).
    #[test]
    fn a_repeating_command_has_all_its_motion_in_its_first_period() {
        use crate::control::demand::required_torque;
        use crate::control::trajectory::{Hold, RampIn, Trajectory, Wave, span_with_every_motion};
        let model = crate::model::load_urdf_str(crate::builtin::builtin(std::path::Path::new(crate::builtin::DEFAULT_URDF)).unwrap(), std::path::Path::new("box.urdf")).unwrap();
        let wave = || Box::new(Wave { amplitude_rad: 30f64.to_radians(), omega: 0.5 });
        let period = std::f64::consts::TAU / 0.5;
        let ramped = RampIn::new(wave(), vec![0.0; 6]);
        assert_eq!(span_with_every_motion(wave().as_ref(), 30.0), period);
        assert_eq!(span_with_every_motion(&ramped, 30.0), 2.0 + period);
        assert_eq!(span_with_every_motion(wave().as_ref(), 5.0), 5.0, "a run shorter than a period");
        assert_eq!(span_with_every_motion(&Hold, 30.0), 30.0, "no period: the whole run");
        for command in [wave() as Box<dyn Trajectory>, Box::new(ramped)] {
            let span = span_with_every_motion(command.as_ref(), 30.0);
            let whole = required_torque(&model, command.as_ref(), 30.0, 0.001);
            let first = required_torque(&model, command.as_ref(), span, 0.001);
            let sampled = required_torque(&model, command.as_ref(), span, 0.001f64.max(demand_step(command.as_ref(), span)));
            for j in 0..6 {
                assert!(first[j] <= whole[j] && first[j] > (1.0 - 1e-6) * whole[j], "J{}: {} over the span, {} over the run", j + 1, first[j], whole[j]);
                // 4096 samples a period (measured: within 8·10⁻⁷ on the wave, 1·10⁻⁵ on its ramp-in)
                assert!(sampled[j] <= whole[j] && sampled[j] > (1.0 - 1e-4) * whole[j], "J{}: {} sampled, {} over the run", j + 1, sampled[j], whole[j]);
            }
        }
    }
}
