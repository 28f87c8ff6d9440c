//! Stepper mode: open-loop steppers, as the real SmallRobotArm runs them (no encoders, no PD loop).
//!
//! The commanded joint angle becomes a commanded motor position in microsteps, N·(cmd − q₀) rounded
//! to a microstep (the rotor is energized where it stands at the start). The rotor, at N·(q − q₀), is
//! pulled toward it with T(ω)·sin(N_r·Δ): Δ the lag of the rotor behind the command (the load angle),
//! N_r = 90°/step angle (50 for 1.8°: an electrical period is 4 full steps), T(ω) the pull-out curve at
//! the rotor's speed. At the joint that is η·N·T·sin(N_r·Δ), capped by the gearbox's rating. When the lag
//! passes 2 full steps the rotor falls into the next stable position, 4 full steps away: those steps are
//! lost, and, open loop, the arm keeps that offset. The torque is evaluated at the plant rate. The
//! rotor's electrical damping adds to it, the total never more than the motor gives at its speed.
//!
//! The torque a plant step applies is worked out at its start, the generator's pulses for that step
//! emitted; the samples record it as it stands at the control step.
//!
//! The driver's step generator, as AccelStepper and the arm's firmware do, follows the command with
//! a bounded acceleration (a stepper cannot start at full speed): its velocity moves toward
//! cmd_dot + K·(cmd − position), K = 50/s, by at most `acceleration`·dt per control period (motor file
//! field `acceleration`, rad/s² at the joint; by default half of what the motor has at rest beyond the
//! weight it carries at the start pose, against the joint's inertia there). Once caught up on a smooth
//! command it follows it exactly.

use super::sin_cos::sin_cos;
use super::{DriveEnvelope, DriveTrain, MotorSet, Stepper};
use std::f64::consts::{FRAC_PI_2, PI};

/// One joint's open-loop stepper.
#[derive(Clone, Debug)]
struct SteppedJoint {
    joint: usize,
    gear_ratio: f64,
    efficiency: f64,
    rated_torque: f64,
    stepper: Stepper,
    /// Its drive train's torque at speed, caps and detent, worked out once.
    envelope: DriveEnvelope,
    /// The rotor's electrical damping at the joint, N²·c, N·m·s/rad.
    damping_at_joint: f64,
    /// Electrical periods per motor radian (N_r).
    teeth: f64,
    /// One microstep, motor radians.
    microstep: f64,
    start: f64,
    /// The step generator: position (joint, from the start) and velocity, and its acceleration bound.
    generator_position: f64,
    generator_velocity: f64,
    max_acceleration: f64,
    /// The commanded motor position, motor radians from the start.
    command: f64,
    /// [sin, cos] of the field's electrical angle N_r·command.
    command_phase: [f64; 2],
    /// [sin, cos] of the electrical angle of each microstep of one electrical period (4 full steps):
    /// the command's phase is looked up, the command being a whole number of microsteps.
    microstep_phases: Vec<[f64; 2]>,
    /// Full steps lost so far, signed (+: the rotor fell behind a positive command).
    lost_steps: i64,
}

impl SteppedJoint {
    /// The holding torque at the joint, η·N·T_H capped by the gearbox's rating.
    fn holding_at_joint(&self) -> f64 {
        (self.efficiency * self.gear_ratio * self.stepper.holding_torque).min(self.rated_torque)
    }

    fn lag(&self, q: f64) -> f64 {
        self.command - self.gear_ratio * (q - self.start)
    }

    fn torque(&self, q: f64, v: f64) -> f64 {
        let (available, _) = self.envelope.motor_torque(v, &self.stepper);
        // the rotor's electrical angle: the field pulls with the sine of the command's less it,
        // sin(N_r·Δ), and the detent has four periods to its one; one sine and cosine give both
        let (sin_rotor, cos_rotor) = sin_cos(self.teeth * (self.gear_ratio * (q - self.start)));
        let [sin_command, cos_command] = self.command_phase;
        let pull = available * (sin_command * cos_rotor - cos_command * sin_rotor);
        // the rotor's oscillation about the field damped (at the joint through the gears, N²): on the
        // slip speed, the field turning at the step generator's speed (the drive holds the current,
        // so there is no drag on the speed itself: that is the pull-out curve's part)
        let damping = self.damping_at_joint * (self.generator_velocity - v);
        // the drive limits the phase current: field and damping together give at most what the
        // motor gives at this speed (capped so that the gearbox's output stays within its rating)
        let most = available.min(self.envelope.driving_cap());
        // the magnets' detent torque does not go through the current limit
        (pull + damping).clamp(-most, most) + self.envelope.detent_torque_at_phase(sin_rotor, cos_rotor)
    }

    /// Where the phase of a command of `microsteps` microsteps is in `microstep_phases`.
    fn phase_index(&self, microsteps: i64) -> usize {
        let period = self.microstep_phases.len();
        if period.is_power_of_two() {
            // two's complement: the mask is the remainder for negative counts too
            microsteps as usize & (period - 1)
        } else {
            microsteps.rem_euclid(period as i64) as usize
        }
    }
}

/// x rounded half away from zero, as `f64::round`, without the library call that becomes on an
/// x86-64 without SSE4.1 (a joint's at every plant step); exact for |x| < 2⁵² (beyond, x is whole).
fn round(x: f64) -> f64 {
    if !(x.abs() < 4_503_599_627_370_496.0) {
        return x.round();
    }
    let whole = x as i64 as f64;
    // x − whole is exact; its sign decides which way a half goes
    let rest = x - whole;
    whole + ((rest >= 0.5) as i64 - (rest <= -0.5) as i64) as f64
}

/// The joints a motor file drives open loop (every stepper, unless `--drive pd`).
#[derive(Clone, Debug)]
pub struct OpenLoopSteppers {
    joints: Vec<SteppedJoint>,
    /// Per coordinate: driven open loop here.
    pub stepped: Vec<bool>,
}

/// What the open-loop steppers give and report at a control step, by coordinate (the joints they do
/// not drive left untouched).
pub struct StepperOutput<'a> {
    /// Each stepper joint's torque as it stands at the control step (what the samples record).
    pub u: &'a mut [f64],
    /// Its limit at its speed in the direction of that torque.
    pub limit: &'a mut [f64],
    /// Past the peak of the torque–angle curve (|load angle| > 90°): the motor gives all it can.
    pub saturated: &'a mut [bool],
    /// The load angle, electrical degrees ([`OpenLoopSteppers::load_angles`]).
    pub load_angle: &'a mut [f64],
    /// Full steps lost so far.
    pub lost_steps: &'a mut [i64],
}

/// A lost-step event: at time `t`, joint `joint` lost `steps` full steps (signed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LostSteps {
    pub joint: usize,
    pub t: f64,
    pub steps: i64,
}

impl OpenLoopSteppers {
    /// The stepper joints of `motors` with their microsteps, their step generators' acceleration
    /// bounds (the default from `inertia`, M_ii at the start pose, and `load`, the torque gravity
    /// asks of each joint there); None when there are none.
    pub fn new(motors: &MotorSet, start: &[f64], inertia: &[f64], load: &[f64]) -> Option<Self> {
        let mut joints = Vec::new();
        for (j, drive) in motors.joints.iter().enumerate() {
            let Some(train) = drive else { continue };
            let DriveTrain { motor, gear_ratio, gear, rated_torque, .. } = train;
            let Some(stepper) = motor.as_stepper() else { continue };
            let micro = motors.microsteps.get(j).copied().flatten().unwrap_or(1) as f64;
            let mut joint = SteppedJoint {
                joint: j,
                gear_ratio: *gear_ratio,
                efficiency: gear.efficiency,
                rated_torque: *rated_torque,
                teeth: 90.0 / stepper.step_angle_deg,
                microstep: stepper.step_angle_deg.to_radians() / micro,
                stepper: stepper.clone(),
                envelope: DriveEnvelope::of(train),
                damping_at_joint: stepper.damping * gear_ratio * gear_ratio,
                start: start[j],
                generator_position: 0.0,
                generator_velocity: 0.0,
                max_acceleration: 0.0,
                command: 0.0,
                command_phase: [0.0, 1.0],
                // a microstep is a quarter period over the microsteps
                microstep_phases: (0..4 * micro as usize)
                    .map(|k| {
                        let (sin, cos) = (k as f64 * FRAC_PI_2 / micro).sin_cos();
                        [sin, cos]
                    })
                    .collect(),
                lost_steps: 0,
            };
            joint.max_acceleration = motors.acceleration.get(j).copied().flatten().unwrap_or_else(|| {
                // half of what the motor has to spare beyond carrying the weight (at least a tenth
                // of its torque): a generator that accelerates with the whole holding torque
                // leaves a loaded joint nothing to hold it with
                let at_rest = joint.holding_at_joint();
                0.5 * (at_rest - load[j].abs()).max(0.2 * at_rest) / inertia[j]
            });
            joints.push(joint);
        }
        if joints.is_empty() {
            return None;
        }
        let mut stepped = vec![false; start.len()];
        for s in &joints {
            stepped[s.joint] = true;
        }
        Some(Self { joints, stepped })
    }

    /// A control step at (q, q̇), before its plant steps ([`Self::plant_step`]): the command to the
    /// drivers, and what the steppers give and report then.
    pub fn control_step(&mut self, cmd: &[f64], cmd_dot: &[f64], dt: f64, q: &[f64], v: &[f64], out: StepperOutput) {
        self.command(cmd, cmd_dot, dt, q, v, out.u);
        self.load_angles(q, out.load_angle);
        self.lost_steps(out.lost_steps);
        self.limits(out.u, v, out.limit);
        for s in &self.joints {
            out.saturated[s.joint] = out.load_angle[s.joint].abs() > 90.0;
        }
    }

    /// The driver's step generator for the period — its velocity moves toward the command with
    /// bounded acceleration and holds for the period — and each stepper joint's torque at (q, q̇) as
    /// it stands, the pulses so far, into `u`.
    fn command(&mut self, cmd: &[f64], cmd_dot: &[f64], dt: f64, q: &[f64], v: &[f64], u: &mut [f64]) {
        const CATCH_UP: f64 = 50.0;
        for s in &mut self.joints {
            let error = cmd[s.joint] - s.start - s.generator_position;
            let wanted = cmd_dot[s.joint] + CATCH_UP * error;
            let bound = s.max_acceleration * dt;
            s.generator_velocity += (wanted - s.generator_velocity).clamp(-bound, bound);
        }
        self.torques(q, v, u);
    }

    /// A plant step of `h` s from (q, q̇): its pulses, then each stepper joint's torque into `u`.
    pub fn plant_step(&mut self, h: f64, q: &[f64], v: &[f64], u: &mut [f64]) {
        self.advance(h);
        self.torques(q, v, u);
    }

    /// The step pulses over the next `h` seconds of the period (one plant step): the motor's command
    /// is the generator's position at the middle of that step in whole microsteps. A real driver
    /// steps continuously (27 microsteps per millisecond at 4 rev/s and 32 microsteps): a command
    /// moved only at the control rate would kick the rotor by a whole period's steps at once.
    fn advance(&mut self, h: f64) {
        for s in &mut self.joints {
            let middle = s.generator_position + 0.5 * s.generator_velocity * h;
            let microsteps = round(s.gear_ratio * middle / s.microstep);
            s.command = microsteps * s.microstep;
            s.command_phase = s.microstep_phases[s.phase_index(microsteps as i64)];
            s.generator_position += s.generator_velocity * h;
        }
    }

    /// The rest positions that carry the weight: per stepper joint, the sag q − q_start at which its
    /// holding torque balances `tau_g` (η·N·T_H·sin(N_r·N·(−sag)) + τ_g = 0), or None for a joint
    /// whose load is beyond its holding torque.
    pub fn rest_sag(&self, tau_g: &[f64]) -> Vec<(usize, Option<f64>)> {
        self.joints
            .iter()
            .map(|s| {
                let ratio = tau_g[s.joint] / s.holding_at_joint();
                (s.joint, (ratio.abs() < 1.0).then(|| ratio.asin() / (s.teeth * s.gear_ratio)))
            })
            .collect()
    }

    /// The torque each stepper joint gets at (q, q̇), into `u` (other joints untouched).
    fn torques(&self, q: &[f64], v: &[f64], u: &mut [f64]) {
        for s in &self.joints {
            u[s.joint] = s.torque(q[s.joint], v[s.joint]);
        }
    }

    /// Each stepper joint's limit at joint speed `v` in the direction of its torque `u` (what its
    /// motor gives there through its gearbox's caps), into `out`.
    fn limits(&self, u: &[f64], v: &[f64], out: &mut [f64]) {
        for s in &self.joints {
            let (lowest, highest) = s.envelope.torque_range(v[s.joint], &s.stepper);
            out[s.joint] = if u[s.joint] >= 0.0 { highest } else { -lowest };
        }
    }

    /// Each stepper joint's load angle, electrical degrees (±90° is the peak torque, ±180° the slip
    /// point), of the lag left after whole lost periods.
    fn load_angles(&self, q: &[f64], out: &mut [f64]) {
        for s in &self.joints {
            let electrical = s.teeth * s.lag(q[s.joint]);
            out[s.joint] = (electrical - 2.0 * PI * round(electrical / (2.0 * PI))).to_degrees();
        }
    }

    /// After a step: count the electrical periods the rotor has slipped (4 full steps each); report
    /// each new loss.
    pub fn update(&mut self, q: &[f64], t: f64, events: &mut Vec<LostSteps>) {
        for s in &mut self.joints {
            let periods = round(s.teeth * s.lag(q[s.joint]) / (2.0 * PI)) as i64;
            let lost = 4 * periods;
            if lost != s.lost_steps {
                events.push(LostSteps { joint: s.joint, t, steps: lost - s.lost_steps });
                s.lost_steps = lost;
            }
        }
    }

    /// Full steps lost so far, by coordinate (the joints not driven here left untouched).
    fn lost_steps(&self, out: &mut [i64]) {
        for s in &self.joints {
            out[s.joint] = s.lost_steps;
        }
    }

    /// The fastest any stepper's field turns, electrical rad/s, at joint speeds `speeds`: N_r·N·|q̇|.
    pub fn electrical_speed(&self, speeds: &[f64]) -> f64 {
        self.joints.iter().map(|s| s.teeth * s.gear_ratio * speeds[s.joint].abs()).fold(0.0, f64::max)
    }

    /// The electrical damping of each stepper joint at the joint, N²·c (N·m·s/rad).
    pub fn damping(&self) -> Vec<(usize, f64)> {
        self.joints.iter().map(|s| (s.joint, s.damping_at_joint)).collect()
    }

    /// Each stepper joint's step-generator acceleration bound, rad/s² at the joint.
    pub fn generator_accelerations(&self) -> Vec<(usize, f64)> {
        self.joints.iter().map(|s| (s.joint, s.max_acceleration)).collect()
    }

    /// The stiffness of each stepper joint about its stable position at rest, η·N²·T_H·N_r (N·m/rad).
    pub fn stiffness(&self) -> Vec<(usize, f64)> {
        self.joints.iter().map(|s| (s.joint, s.efficiency * s.gear_ratio * s.gear_ratio * s.stepper.holding_torque * s.teeth)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounding without the library call is `f64::round`: halves away from zero, whole numbers
    /// kept, both signs, large values.
    #[test]
    fn round_is_f64_round() {
        let mut seed = 0x9E37_79B9_7F4A_7C15_u64;
        let mut values = vec![0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, 0.49999999999999994, -0.49999999999999994, 4503599627370495.5, -4503599627370495.5, 9.007199254740993e15, 1e300, -1e300, 123456.5, -123456.5];
        for _ in 0..10_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let x = (seed as f64 / u64::MAX as f64 - 0.5) * 10f64.powi((seed % 17) as i32);
            values.push(x);
            values.push(x.trunc() + 0.5);
        }
        for x in values {
            assert_eq!(round(x), x.round(), "{x}");
        }
    }

    /// The field's pull and the detent, worked out from the sine and cosine of the rotor's electrical
    /// angle and the command's tabled phase, are η·N·T·sin(N_r·Δ) and the detent's sine as written,
    /// over commands both ways across many electrical periods, lags past slipping and speeds past the
    /// corner, with the file's 32 microsteps, 10 (a period not a power of two) and full steps: within
    /// 10⁻¹¹ of the holding torque (the sine of N_r·Δ taken directly loses the last bits of
    /// N_r·command, thousands of radians, about 10⁻¹³).
    #[test]
    fn the_pull_and_the_detent_from_the_phases_are_their_sines() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let model = crate::model::load_urdf(&root.join("assets/smallrobot_arm.urdf")).unwrap();
        let mut motors = crate::actuator::catalogue::load_motor_file(&root.join("assets/motors/tutorial.toml"), &model).unwrap();
        let dof = model.dof();
        let start: Vec<f64> = (0..dof).map(|j| 0.1 * j as f64 - 0.2).collect();
        for microsteps in [None, Some(10), Some(1)] {
            if microsteps.is_some() {
                motors.microsteps.fill(microsteps);
            }
            the_pull_and_the_detent_are_their_sines_with(OpenLoopSteppers::new(&motors, &start, &vec![0.05; dof], &vec![0.0; dof]).unwrap());
        }
    }

    fn the_pull_and_the_detent_are_their_sines_with(mut steppers: OpenLoopSteppers) {
        let mut compared = 0;
        for step in 0..3000 {
            for s in &mut steppers.joints {
                s.generator_velocity = 4.0 * (step as f64 * 0.004).sin();
            }
            steppers.advance(1e-3);
            for s in &steppers.joints {
                for (lag, v) in [(0.0, 0.0), (1e-4, 0.3), (-0.002, -2.0), (0.03, 9.0), (-0.4, 25.0)] {
                    let q = s.start + (s.command - lag) / s.gear_ratio;
                    let (available, _) = s.envelope.motor_torque(v, &s.stepper);
                    let most = available.min(s.envelope.driving_cap());
                    let pull = available * (s.teeth * s.lag(q)).sin();
                    let as_written = (pull + s.damping_at_joint * (s.generator_velocity - v)).clamp(-most, most) + s.envelope.detent_torque(q - s.start);
                    let difference = (s.torque(q, v) - as_written).abs();
                    assert!(difference <= 1e-11 * s.holding_at_joint(), "joint {} command {} lag {lag}: {difference:e}", s.joint, s.command);
                    compared += 1;
                }
            }
        }
        assert!(compared > 10_000);
        // the commands went both ways through many electrical periods
        let periods = steppers.joints.iter().map(|s| (s.command / (4.0 * s.stepper.step_angle_deg.to_radians())).abs()).fold(0.0, f64::max);
        assert!(periods > 10.0, "{periods}");
    }
}
