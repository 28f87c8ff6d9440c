//! The numbers a run ends with: tracking error, saturation, limit hits, tool range.

use crate::actuator::bus_servo::Trip;
use crate::sample::Sample;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "state", rename_all = "lowercase")]
pub enum RunStatus {
    Completed,
    /// Stopped by the user (SIGINT) at `time`.
    Interrupted { time: f64 },
    /// The state became non-finite or absurd.
    Diverged { joint: String, time: f64, message: String },
    /// Stopped at the first collision (`--stop-on-collision`): its time and the two links ("floor"
    /// for the floor).
    Collided { time: f64, link1: String, link2: String },
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Range {
    pub min: f64,
    pub max: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ToolRange {
    pub x: Range,
    pub y: Range,
    pub z: Range,
}

/// The discrete plant's energy books over a run (see the simulation loop's audit).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnergyBalance {
    /// Mechanical energy that appeared with no torque to supply it, J (negative: lost, as in an
    /// inelastic stop at a joint limit or the plant's numerical damping).
    pub created: f64,
    /// All the work the torques and the damping did on the arm, in absolute value, J.
    pub work: f64,
}

/// A joint's drive against the vendors' duty ratings over a run: the motor's RMS torque at its shaft
/// against its continuous rating, the cubic mean of the torque at the gearbox against its rated
/// average torque (each None where the catalogue gives no rating).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct DriveDuty {
    /// RMS of u/N, the motor's torque at its shaft, N·m.
    pub rms_motor_torque: f64,
    pub continuous_torque: Option<f64>,
    /// Cubic mean of |u|, the torque the motor puts through the gearbox, N·m.
    pub cubic_mean_torque: f64,
    pub rated_average_torque: Option<f64>,
}

/// A joint driven by its servo's firmware, over a run: how often its duty was at the limit, and
/// the current its motor drew.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ServoDuty {
    /// Share of control steps at full duty (the position loop asking for more than the PWM gives), %.
    pub full_duty_percent: f64,
    /// When it first reached full duty, s (null if never).
    pub first_full_duty_time: Option<f64>,
    pub peak_abs_duty: f64,
    /// The motor's current, A: its largest and its RMS over the control steps.
    pub peak_current: f64,
    pub rms_current: f64,
    /// The firmware protection that tripped, if one did (a Feetech's overload or overcurrent).
    #[serde(default)]
    pub protection_trip: Option<Trip>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Summary {
    pub status: RunStatus,
    pub joints: Vec<String>,
    /// Simulated time covered, s.
    pub simulated_time: f64,
    /// Control steps taken.
    pub steps: usize,
    pub dt: f64,
    /// Tracking error statistics cover every step with t ≥ this.
    pub error_window_start: f64,
    /// max |cmd − q| per joint over the window, rad (null when the run is shorter than the window).
    pub max_abs_error: Vec<Option<f64>>,
    pub rms_error: Vec<Option<f64>>,
    /// Share of control steps where the controller asked for more than the limit, %.
    pub saturation_percent: Vec<f64>,
    /// The same share over the control steps from `error_window_start` on, % (null when the run is
    /// shorter): saturation only before it is the start's catching up, not the motion's demand.
    #[serde(default)]
    pub saturation_after_settle_percent: Vec<Option<f64>>,
    /// Share of steps whose torque flipped sign from the previous step with one of the two
    /// saturated, %. Close to the saturation share: the saturation is numerical chatter.
    pub chatter_percent: Vec<f64>,
    pub peak_abs_torque: Vec<f64>,
    /// The peak |τ| over the control steps from `error_window_start` on (null when the run is
    /// shorter): the motion's own demand, the start aside.
    #[serde(default)]
    pub peak_abs_torque_after_settle: Vec<Option<f64>>,
    /// Per joint, the RMS of its torque over the run's control steps, N·m (what heats a motor: the
    /// vendors' check against the continuous rating).
    #[serde(default)]
    pub rms_torque: Vec<f64>,
    /// Per joint, the cubic mean of |τ| over the run's control steps, N·m (the gearbox makers'
    /// average torque, Harmonic Drive's T_av).
    #[serde(default)]
    pub cubic_mean_torque: Vec<f64>,
    /// Per joint with a motor, the vendors' duty checks against its catalogue ratings (empty
    /// without motors).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub drive_duty: Vec<Option<DriveDuty>>,
    /// Self-collision and floor contacts, when the run checked them (`--collisions`, `--floor`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub collisions: Option<crate::collision::CollisionSummary>,
    /// Per joint driven by its servo's firmware: its duty and current (empty when none is).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub servos: Vec<Option<ServoDuty>>,
    /// Per joint whose motor has thermal data: its winding over the run (empty when no motor has).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub winding: Vec<Option<crate::actuator::thermal::WindingSummary>>,
    /// Per joint, the largest |friction torque| over the run, N·m (empty without friction).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub peak_friction_torque: Vec<f64>,
    /// Per joint, the share of control steps it was stuck (held still by its friction), % (empty
    /// without friction).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stuck_percent: Vec<f64>,
    /// Per joint, the largest torque the controller can command at rest: the effort limit, or with
    /// `--motors` the motor's torque at the joint before the gearbox's losses (N·T; the joint gets
    /// η of it driving).
    pub effort_limit: Vec<f64>,
    /// The lowest torque limit over the run's control steps: with `--motors`, what the motor gave at
    /// the joint's fastest; the effort limit otherwise.
    #[serde(default)]
    pub lowest_torque_limit: Vec<f64>,
    /// The largest share of the torque available at the joint's speed that the joint used, over the
    /// control steps from `error_window_start` on (the start's catching up aside, as for the tracking
    /// error): |τ| / limit (1 where the controller saturated); for an open-loop stepper, the share of
    /// its pull-out torque its field gives, sin of the load angle (1 from 90° on).
    #[serde(default)]
    pub peak_torque_share: Vec<f64>,
    /// Stepper mode: full steps each joint's rotor slipped over the run, either way (0 where none, or not
    /// a stepper); the recordings carry the net offset the slips left, signed.
    #[serde(default)]
    pub lost_steps: Vec<u64>,
    /// Stepper mode: when each joint first lost steps, s (null if never).
    #[serde(default)]
    pub first_lost_step_time: Vec<Option<f64>>,
    /// Steps at which the joint was stopped at a position limit.
    pub limit_hits: Vec<u64>,
    pub tool_range: ToolRange,
    /// The discrete plant's energy books (null for the continuous plant, which controls its own error).
    #[serde(default)]
    pub energy_balance: Option<EnergyBalance>,
    pub wall_time: f64,
}

/// Accumulates a [`Summary`] sample by sample, without allocating.
pub struct SummaryBuilder {
    joints: Vec<String>,
    dt: f64,
    window_start: f64,
    first_window_step: usize,
    max_err: Vec<f64>,
    sum_sq_err: Vec<f64>,
    window_samples: u64,
    saturated_steps: Vec<u64>,
    saturated_in_window: Vec<u64>,
    chatter_steps: Vec<u64>,
    control_steps: u64,
    peak_torque: Vec<f64>,
    peak_torque_in_window: Vec<f64>,
    peak_friction: Vec<f64>,
    sum_squared_torque: Vec<f64>,
    sum_cubed_torque: Vec<f64>,
    stuck_steps: Vec<u64>,
    effort: Vec<f64>,
    lowest_limit: Vec<f64>,
    peak_share: Vec<f64>,
    stepped: Vec<bool>,
    lost_steps: Vec<u64>,
    first_lost: Vec<Option<f64>>,
    limit_hits: Vec<u64>,
    /// Firmware mode: each driven joint's duty limit (None: not driven), steps at it, when first,
    /// the peak duty and current and the current's sum of squares.
    servo_max_duty: Vec<Option<f64>>,
    full_duty_steps: Vec<u64>,
    first_full_duty: Vec<Option<f64>>,
    peak_duty: Vec<f64>,
    peak_current: Vec<f64>,
    sum_squared_current: Vec<f64>,
    tool_min: [f64; 3],
    tool_max: [f64; 3],
    last_t: f64,
}

impl SummaryBuilder {
    pub fn new(joints: Vec<String>, effort: Vec<f64>, dt: f64, window_start: f64) -> Self {
        let n = joints.len();
        Self {
            joints,
            dt,
            window_start,
            first_window_step: (window_start / dt - 1e-9).ceil().max(0.0) as usize,
            max_err: vec![0.0; n],
            sum_sq_err: vec![0.0; n],
            window_samples: 0,
            saturated_steps: vec![0; n],
            saturated_in_window: vec![0; n],
            chatter_steps: vec![0; n],
            control_steps: 0,
            peak_torque: vec![0.0; n],
            peak_torque_in_window: vec![0.0; n],
            peak_friction: Vec::new(),
            sum_squared_torque: vec![0.0; n],
            sum_cubed_torque: vec![0.0; n],
            stuck_steps: Vec::new(),
            lowest_limit: effort.clone(),
            peak_share: vec![0.0; n],
            stepped: vec![false; n],
            lost_steps: vec![0; n],
            first_lost: vec![None; n],
            effort,
            limit_hits: vec![0; n],
            servo_max_duty: Vec::new(),
            full_duty_steps: vec![0; n],
            first_full_duty: vec![None; n],
            peak_duty: vec![0.0; n],
            peak_current: vec![0.0; n],
            sum_squared_current: vec![0.0; n],
            tool_min: [f64::INFINITY; 3],
            tool_max: [f64::NEG_INFINITY; 3],
            last_t: 0.0,
        }
    }

    /// The joints driven by open-loop steppers (their torque share is their load angle's).
    pub fn with_stepped_joints(mut self, stepped: Vec<bool>) -> Self {
        self.stepped = stepped;
        self
    }

    /// Some joint has friction: its peak friction torque and stuck steps are counted.
    pub fn with_friction(mut self, has_friction: bool) -> Self {
        let n = if has_friction { self.joints.len() } else { 0 };
        self.peak_friction = vec![0.0; n];
        self.stuck_steps = vec![0; n];
        self
    }

    /// The joints driven by their servos' firmware, each with its duty limit (None elsewhere).
    pub fn with_servos(mut self, max_duty: Vec<Option<f64>>) -> Self {
        if max_duty.iter().any(Option::is_some) {
            self.servo_max_duty = max_duty;
        }
        self
    }

    /// A stepper lost steps (stepper mode).
    pub fn lost_steps(&mut self, e: crate::actuator::LostSteps) {
        self.lost_steps[e.joint] += e.steps.unsigned_abs();
        self.first_lost[e.joint].get_or_insert(e.t);
    }

    pub fn record(&mut self, s: &Sample) {
        let n = self.joints.len();
        if s.k >= self.first_window_step {
            self.window_samples += 1;
            for i in 0..n {
                let e = s.tracking_error(i).abs();
                self.max_err[i] = self.max_err[i].max(e);
                self.sum_sq_err[i] += e * e;
            }
        }
        if !s.is_final {
            self.control_steps += 1;
            let in_window = s.k >= self.first_window_step;
            for i in 0..n {
                self.saturated_steps[i] += s.saturated[i] as u64;
                self.saturated_in_window[i] += (in_window && s.saturated[i]) as u64;
                self.chatter_steps[i] += s.chatter[i] as u64;
                self.peak_torque[i] = self.peak_torque[i].max(s.u[i].abs());
                self.sum_squared_torque[i] += s.u[i] * s.u[i];
                self.sum_cubed_torque[i] += s.u[i].abs().powi(3);
                if in_window {
                    self.peak_torque_in_window[i] = self.peak_torque_in_window[i].max(s.u[i].abs());
                }
                self.lowest_limit[i] = self.lowest_limit[i].min(s.torque_limit[i]);
                let share = if s.k < self.first_window_step {
                    0.0
                } else if self.stepped[i] {
                    s.load_angle[i].abs().min(90.0).to_radians().sin()
                } else if s.torque_limit[i] > 0.0 {
                    s.u[i].abs() / s.torque_limit[i]
                } else {
                    0.0
                };
                self.peak_share[i] = self.peak_share[i].max(share);
            }
        }
        for i in 0..n {
            self.limit_hits[i] += s.at_limit[i] as u64;
        }
        if !self.servo_max_duty.is_empty() && !s.is_final {
            for i in 0..n {
                let Some(limit) = self.servo_max_duty[i] else { continue };
                let full = s.duty[i].abs() >= limit;
                self.full_duty_steps[i] += full as u64;
                if full {
                    self.first_full_duty[i].get_or_insert(s.t);
                }
                self.peak_duty[i] = self.peak_duty[i].max(s.duty[i].abs());
                self.peak_current[i] = self.peak_current[i].max(s.current[i].abs());
                self.sum_squared_current[i] += s.current[i] * s.current[i];
            }
        }
        if !self.stuck_steps.is_empty() && !s.is_final {
            for i in 0..n {
                self.peak_friction[i] = self.peak_friction[i].max(s.friction[i].abs());
                self.stuck_steps[i] += s.stuck[i] as u64;
            }
        }
        for a in 0..3 {
            self.tool_min[a] = self.tool_min[a].min(s.tool_position[a]);
            self.tool_max[a] = self.tool_max[a].max(s.tool_position[a]);
        }
        self.last_t = s.t;
    }

    pub fn finish(&self, status: RunStatus, wall_time: f64) -> Summary {
        let in_window = self.window_samples > 0;
        let range = |a: usize| Range { min: self.tool_min[a], max: self.tool_max[a] };
        // the control steps k = 0, 1, … from the window's first on
        let window_control_steps = self.control_steps.saturating_sub(self.first_window_step as u64);
        let share_of_control_steps = |counts: &[u64]| -> Vec<f64> {
            counts.iter().map(|&c| if self.control_steps == 0 { 0.0 } else { 100.0 * c as f64 / self.control_steps as f64 }).collect()
        };
        Summary {
            status,
            joints: self.joints.clone(),
            simulated_time: self.last_t,
            steps: self.control_steps as usize,
            dt: self.dt,
            error_window_start: self.window_start,
            max_abs_error: self.max_err.iter().map(|&e| in_window.then_some(e)).collect(),
            rms_error: self
                .sum_sq_err
                .iter()
                .map(|&s| in_window.then(|| (s / self.window_samples as f64).sqrt()))
                .collect(),
            saturation_percent: share_of_control_steps(&self.saturated_steps),
            saturation_after_settle_percent: self
                .saturated_in_window
                .iter()
                .map(|&c| (window_control_steps > 0).then(|| 100.0 * c as f64 / window_control_steps as f64))
                .collect(),
            chatter_percent: share_of_control_steps(&self.chatter_steps),
            peak_abs_torque: self.peak_torque.clone(),
            peak_abs_torque_after_settle: self.peak_torque_in_window.iter().map(|&p| (window_control_steps > 0).then_some(p)).collect(),
            rms_torque: self.sum_squared_torque.iter().map(|&s| if self.control_steps == 0 { 0.0 } else { (s / self.control_steps as f64).sqrt() }).collect(),
            cubic_mean_torque: self.sum_cubed_torque.iter().map(|&s| if self.control_steps == 0 { 0.0 } else { (s / self.control_steps as f64).cbrt() }).collect(),
            drive_duty: Vec::new(),
            servos: self
                .servo_max_duty
                .iter()
                .enumerate()
                .map(|(i, limit)| {
                    limit.map(|_| ServoDuty {
                        full_duty_percent: share_of_control_steps(&self.full_duty_steps)[i],
                        first_full_duty_time: self.first_full_duty[i],
                        peak_abs_duty: self.peak_duty[i],
                        peak_current: self.peak_current[i],
                        rms_current: if self.control_steps == 0 { 0.0 } else { (self.sum_squared_current[i] / self.control_steps as f64).sqrt() },
                        protection_trip: None,
                    })
                })
                .collect(),
            collisions: None,
            winding: Vec::new(),
            peak_friction_torque: self.peak_friction.clone(),
            stuck_percent: share_of_control_steps(&self.stuck_steps),
            effort_limit: self.effort.clone(),
            lowest_torque_limit: self.lowest_limit.clone(),
            peak_torque_share: self.peak_share.clone(),
            lost_steps: self.lost_steps.clone(),
            first_lost_step_time: self.first_lost.clone(),
            limit_hits: self.limit_hits.clone(),
            tool_range: ToolRange { x: range(0), y: range(1), z: range(2) },
            energy_balance: None,
            wall_time,
        }
    }
}

impl Summary {
    /// In words, per joint that saturates noticeably: real torque demand or numerical chatter.
    pub fn saturation_verdicts(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (j, name) in self.joints.iter().enumerate() {
            let (sat, chat) = (self.saturation_percent[j], self.chatter_percent[j]);
            if let (Some(&lost), Some(Some(first))) = (self.lost_steps.get(j), self.first_lost_step_time.get(j)) {
                if lost > 0 {
                    out.push(format!(
                        "{name}: its stepper lost {lost} full steps, the first at t = {first:.3} s — the command asked for more torque or speed than the pull-out curve gives there; open loop, the joint keeps that offset"
                    ));
                    continue;
                }
            }
            if let Some(Some(servo)) = self.servos.get(j) {
                // a servo's position loop: at full duty it gives what the supply allows, and its
                // current is what heats it and trips the supply
                if let Some(trip) = &servo.protection_trip {
                    out.push(format!("{name}: {} — a real one reports an {} error", trip.describe(), trip.kind.name()));
                }
                if servo.full_duty_percent > 0.0 {
                    out.push(format!(
                        "{name}: its servo at full duty {:.1}% of the run (first at t = {:.3} s), drawing up to {:.2} A (RMS {:.2} A) — the position loop asks for more than the PWM gives there",
                        servo.full_duty_percent,
                        servo.first_full_duty_time.unwrap_or(0.0),
                        servo.peak_current,
                        servo.rms_current
                    ));
                } else if sat >= 2.0 {
                    out.push(format!("{name}: its servo at its current limit or its torque at the datasheet's line {sat:.0}% of steps (duty at most {:.0} %), drawing up to {:.2} A (RMS {:.2} A)", 100.0 * servo.peak_abs_duty, servo.peak_current, servo.rms_current));
                }
                continue;
            }
            if sat < 2.0 {
                continue;
            }
            if chat >= 0.5 * sat {
                out.push(format!(
                    "{name}: saturated {sat:.0}% of steps, and the torque flips sign on {chat:.0}% — mostly numerical chatter (the sampled loop is unstable), not torque demand; `armscope analyze` (with the run's --motors) finds stable gains"
                ));
            } else if self.saturation_after_settle_percent.get(j).copied().flatten().is_some_and(|after| after < 0.5) {
                // the command starts away from the start pose (the wave's phases): the controller
                // catches up at full torque, which says nothing of what the motion needs
                out.push(format!(
                    "{name}: saturated {sat:.0}% of steps, nearly all before t = {} s, catching up with the command at the start — not the motion's own demand",
                    self.error_window_start
                ));
            } else {
                out.push(format!("{name}: saturated {sat:.0}% of steps with little chatter ({chat:.0}%) — real torque demand beyond the motor's limit"));
            }
        }
        out
    }
}
