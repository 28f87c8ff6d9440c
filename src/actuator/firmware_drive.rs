//! Firmware mode: joints driven by their serial-bus servo's own position loop, as a LeRobot or
//! Dynamixel arm runs (no PD of armscope's: the command is the servo's goal position).
//!
//! The command is the goal position, held over the control period; a servo with a command delay
//! acts on the goal sent that long before (a delay line of the goals sent, filled when the drives
//! are made: nothing is allocated while the arm runs). The firmware ticks at every
//! plant step (a servo's loop runs at kilohertz rates, faster than a host sends goals): its duty
//! from the goal and the position, in the servo's units ([`super::bus_servo::firmware`]), and the
//! motor's torque at the joint's speed through its back-EMF, both at the plant step's start. Behind a further reduction of
//! ratio N (a belt after the servo) the servo turns N times the joint: its goal and position are N
//! times the joint's, its torque reaches the joint ×N (the reduction's losses are the plant's
//! friction, as for every drive train). The servo's own friction (its model M1–M6) is the plant's
//! too ([`crate::plant::JointFriction`]).

use super::bus_servo::{BusServo, FirmwareState, ServoFriction, ServoOutput, Trip};
use super::MotorSet;

/// One joint's servo.
#[derive(Clone, Debug)]
struct ServoJoint {
    joint: usize,
    servo: BusServo,
    gear_ratio: f64,
    state: FirmwareState,
    /// The goal at the servo (N × the command).
    goal: f64,
    /// The goals sent, newest at `newest`, as many as the command delay spans plus two.
    sent: Vec<f64>,
    newest: usize,
    /// The command delay in control periods: whole ones, and the fraction beyond.
    delay_periods: usize,
    delay_fraction: f64,
    /// The motor at the last plant step's start.
    out: ServoOutput,
}

impl ServoJoint {
    /// The largest duty its firmware gives now (less once its overload protection has tripped).
    fn duty_limit(&self) -> f64 {
        self.servo.firmware.protection.duty_limit(&self.state.protection, self.servo.firmware.family.max_duty)
    }

    /// Whether its overcurrent protection has switched its torque off.
    fn torque_off(&self) -> bool {
        self.servo.firmware.protection.torque_off(&self.state.protection)
    }
}

/// The joints a motor file drives through their servos' firmware.
#[derive(Clone, Debug)]
pub struct FirmwareDrives {
    joints: Vec<ServoJoint>,
    /// The firmware ticked at the control step's state: the first plant step is that state.
    ticked: bool,
    /// Per coordinate: driven by its servo's firmware here.
    pub driven: Vec<bool>,
}

impl FirmwareDrives {
    /// The joints of `motors` whose servo has a firmware model; None when there are none. `start`
    /// is where each firmware's internal target starts (a Feetech's walks from there), and the goal
    /// every servo has had before the first command; commands come every `control_dt` s.
    pub fn new(motors: &MotorSet, start: &[f64], control_dt: f64) -> Option<Self> {
        let joints: Vec<ServoJoint> = motors
            .joints
            .iter()
            .enumerate()
            .filter_map(|(j, d)| {
                let d = d.as_ref()?;
                let servo = d.servo.clone()?;
                let goal = d.gear_ratio * start[j];
                let periods = servo.command_delay / control_dt;
                let delay_periods = periods.floor() as usize;
                Some(ServoJoint { joint: j, servo, gear_ratio: d.gear_ratio, state: FirmwareState::at(goal), goal, sent: vec![goal; delay_periods + 2], newest: 0, delay_periods, delay_fraction: periods - delay_periods as f64, out: ServoOutput::default() })
            })
            .collect();
        if joints.is_empty() {
            return None;
        }
        let mut driven = vec![false; start.len()];
        for s in &joints {
            driven[s.joint] = true;
        }
        Some(Self { joints, ticked: false, driven })
    }

    /// A control step: the goals `cmd` for the period, and the firmware's tick at the joint's state
    /// (q, q̇) for the period's first plant step of `h` s; each servo's torque at the joint into `u`
    /// (other joints untouched).
    pub fn command(&mut self, cmd: &[f64], q: &[f64], v: &[f64], h: f64, u: &mut [f64]) {
        for s in &mut self.joints {
            s.newest = (s.newest + 1) % s.sent.len();
            s.sent[s.newest] = s.gear_ratio * cmd[s.joint];
            let len = s.sent.len();
            let at = |periods: usize| s.sent[(s.newest + len - periods) % len];
            let (later, earlier) = (at(s.delay_periods), at(s.delay_periods + 1));
            s.goal = later + s.delay_fraction * (earlier - later);
        }
        self.tick(h, q, v, u);
        self.ticked = true;
    }

    /// A plant step of `h` s from (q, q̇): the firmware's tick (the control step's, for the first)
    /// and each servo's torque at the joint into `u`.
    pub fn plant_step(&mut self, h: f64, q: &[f64], v: &[f64], u: &mut [f64]) {
        if std::mem::take(&mut self.ticked) {
            return;
        }
        self.tick(h, q, v, u);
    }

    fn tick(&mut self, h: f64, q: &[f64], v: &[f64], u: &mut [f64]) {
        for s in &mut self.joints {
            let n = s.gear_ratio;
            s.out = s.servo.tick(&mut s.state, s.goal, n * q[s.joint], n * v[s.joint], h, s.servo.supply, true);
            u[s.joint] = n * s.out.torque;
        }
    }

    /// Per coordinate, the duty, the motor's current (A) and the supply at the servo (V), as the
    /// last [`Self::torques`] left them; other joints untouched.
    pub fn outputs(&self, duty: &mut [f64], current: &mut [f64], supply: &mut [f64]) {
        for s in &self.joints {
            duty[s.joint] = s.out.duty;
            current[s.joint] = s.out.current;
            supply[s.joint] = s.out.supply;
        }
    }

    /// Whether joint `j`'s servo is at its duty limit, at its firmware's current limit, or its
    /// torque at the datasheet's line.
    pub fn saturated(&self, j: usize) -> bool {
        self.joints.iter().find(|s| s.joint == j).is_some_and(|s| {
            let at_current_limit = s.servo.firmware.current_limit.is_some_and(|limit| s.out.current.abs() >= limit * (1.0 - 1e-9));
            s.out.duty.abs() >= s.duty_limit() || s.out.limited || at_current_limit || s.torque_off()
        })
    }

    /// Per coordinate, the protection that tripped on its servo, if one did.
    pub fn trips(&self, dof: usize) -> Vec<Option<Trip>> {
        let mut out = vec![None; dof];
        for s in &self.joints {
            out[s.joint] = s.state.protection.trip;
        }
        out
    }

    /// The torque joint `j`'s servo gives at full duty at joint speed `speed` in the direction of
    /// `torque` (its limit at this step, at the joint).
    pub fn limit(&self, j: usize, torque: f64, speed: f64) -> f64 {
        self.joints.iter().find(|s| s.joint == j).map_or(0.0, |s| {
            let d = s.duty_limit() * if torque >= 0.0 { 1.0 } else { -1.0 };
            s.gear_ratio * s.servo.drive(d, s.gear_ratio * speed, s.servo.supply, !s.torque_off()).torque.abs()
        })
    }

    /// Each driven joint's servo friction and gear ratio (the servo's friction acts at its
    /// output: ×N at the joint), for the plant.
    pub fn frictions(&self, dof: usize) -> Vec<Option<(ServoFriction, f64)>> {
        let mut out = vec![None; dof];
        for s in &self.joints {
            out[s.joint] = Some((s.servo.friction, s.gear_ratio));
        }
        out
    }

    /// The sag at which each servo holds `load` (the torque gravity asks of its joint, N·m) with
    /// its loop's error, friction aside (None: more than its duty gives): the closed form
    /// k_t·V·e_g·k_p·N²·e/R = load at rest.
    pub fn rest_sag(&self, load: &[f64]) -> Vec<(usize, Option<f64>)> {
        self.joints.iter().map(|s| (s.joint, s.servo.static_error(-load[s.joint] / s.gear_ratio).map(|e| -e / s.gear_ratio))).collect()
    }

    /// Per driven joint, the stiffness of its position loop (N·m/rad at the joint, at rest, the
    /// duty below its limit) and its back-EMF's damping (N·m·s/rad at the joint): what the plant
    /// step must resolve.
    pub fn stiffness_and_damping(&self) -> Vec<(usize, f64, f64)> {
        self.joints
            .iter()
            .map(|s| {
                let n2 = s.gear_ratio * s.gear_ratio;
                let per_volt = s.servo.kt / s.servo.resistance;
                (s.joint, n2 * per_volt * s.servo.supply * s.servo.firmware.duty_per_rad(), n2 * per_volt * s.servo.kt)
            })
            .collect()
    }

    /// The servos, by joint.
    pub fn servos(&self) -> impl Iterator<Item = (usize, &BusServo, f64)> {
        self.joints.iter().map(|s| (s.joint, &s.servo, s.gear_ratio))
    }
}
