//! Motors and their drive trains as a joint sees them: what torque the joint can get at a speed.
//!
//! A motor kind (servo, stepper, …) is one file behind [`Motor`]; a [`DriveTrain`] puts a motor
//! behind a gearbox (ratio, efficiency, rated output torque); a [`MotorSet`] assigns drive trains to
//! a model's joints, from a motor file (`--motors FILE.toml`, see [`catalogue`]).

pub mod bus_servo;
pub mod carried;
pub mod catalogue;
mod envelope;
mod firmware_drive;
mod lossy_gear;
mod open_loop;
pub mod reduction;
mod servo;
mod sin_cos;
mod stepper;
pub mod thermal;

pub use bus_servo::BusServo;
pub use carried::{Mount, PlacedPart};
pub use catalogue::{Catalogue, load_motor_file};
pub use envelope::{Detent, DriveEnvelope, TorqueSpeed};
pub use firmware_drive::FirmwareDrives;
pub use lossy_gear::{GearLosses, LossyGear};
pub use open_loop::{LostSteps, OpenLoopSteppers, StepperOutput};
pub use reduction::{Reduction, Stage};
pub use servo::DcServo;
pub use stepper::{PullOut, Stepper};

use std::fmt::Debug;

/// A motor at its own shaft.
pub trait Motor: Debug + Send + Sync {
    /// The largest torque (N·m, ≥ 0) it can give at shaft speed `speed` (rad/s, either sign) in the
    /// direction it turns (motoring).
    fn torque_at(&self, speed: f64) -> f64;
    /// The largest torque against the direction it turns (braking); as motoring unless the kind
    /// knows better (a DC motor brakes with at least its stall torque).
    fn braking_torque_at(&self, speed: f64) -> f64 {
        self.torque_at(speed)
    }
    /// Its torque–speed curve as plain numbers, for the control step (the default: only the motor
    /// can say, through the two methods above).
    fn torque_speed(&self) -> TorqueSpeed {
        TorqueSpeed::Motor
    }
    /// Rotor inertia, kg·m².
    fn rotor_inertia(&self) -> f64;
    /// The catalogue name.
    fn name(&self) -> &str;
    /// One line: kind and main numbers.
    fn describe(&self) -> String;
    /// The stepper, if this is one (stepper mode needs its step geometry).
    fn as_stepper(&self) -> Option<&Stepper> {
        None
    }
    /// The serial-bus servo, if this is one (its firmware drives the joint).
    fn as_bus_servo(&self) -> Option<&BusServo> {
        None
    }
    /// A copy of it, boxed (a drive train is copied per candidate in identification).
    fn boxed_clone(&self) -> Box<dyn Motor>;
}

impl Clone for Box<dyn Motor> {
    fn clone(&self) -> Self {
        self.boxed_clone()
    }
}

/// A drive train's part as a body the arm carries: the motor (a solid cylinder where the catalogue
/// gives its frame and length, a point mass otherwise) or a reduction (a point mass: no dimensions
/// are published).
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    pub name: String,
    pub mass: f64,
    /// Diameter and length of a solid cylinder along the joint's axis, m.
    pub cylinder: Option<(f64, f64)>,
}

impl Part {
    /// Its inertia in a frame at its centre whose `axis` (unit) is the cylinder's.
    pub fn inertia(&self, axis: &nalgebra::Vector3<f64>) -> crate::spatial::RigidInertia {
        let inertia_com = match self.cylinder {
            Some((diameter, length)) => {
                let r2 = (0.5 * diameter).powi(2);
                let along = 0.5 * self.mass * r2;
                let across = self.mass * (3.0 * r2 + length * length) / 12.0;
                let a = axis * axis.transpose();
                (nalgebra::Matrix3::identity() - a) * across + a * along
            }
            None => nalgebra::Matrix3::zeros(),
        };
        crate::spatial::RigidInertia { mass: self.mass, com: nalgebra::Vector3::zeros(), inertia_com }
    }
}

/// A motor behind a gearbox: the joint turns `gear_ratio` times slower than the motor, and the
/// gearbox's losses act as friction at the joint by the direction power flows ([`LossyGear`]).
#[derive(Clone, Debug)]
pub struct DriveTrain {
    pub motor: Box<dyn Motor>,
    pub gear_ratio: f64,
    /// The gearbox's losses: efficiency η driving (the joint gets η·N·T_motor), η_b back-driven,
    /// breakaway and viscous friction at the output.
    pub gear: LossyGear,
    /// The gearbox's rated output torque, N·m (infinite when not limited).
    pub rated_torque: f64,
    /// The motor's thermal data, where its datasheet gives it (None: not thermally checked).
    pub heat: Option<thermal::WindingHeat>,
    /// The motor's continuous (rated) torque at its shaft, N·m, where its datasheet gives it: the
    /// vendors' RMS check (None: not checked; an open-loop stepper draws its set current whatever
    /// the load, so its heat is the driver's setting, not the motion's).
    pub continuous_torque: Option<f64>,
    /// The reductions' inertia seen at the motor's shaft, beyond its rotor, kg·m².
    pub input_inertia: f64,
    /// The highest motor speed the reductions allow at their inputs, rad/s.
    pub max_motor_speed: Option<f64>,
    /// The reductions' rated average torque at the joint (the cubic-mean check), N·m.
    pub rated_average_torque: Option<f64>,
    /// The catalogue reductions after the motor, by name (for reports).
    pub reductions: Vec<String>,
    /// The parts whose mass is published: the motor, then its reductions.
    pub parts: Vec<Part>,
    /// A serial-bus servo's firmware, motor and friction model, where known: in the default drive
    /// mode its firmware's position loop drives the joint ([`FirmwareDrives`]).
    pub servo: Option<BusServo>,
}

impl DriveTrain {
    /// A drive train whose gearbox loses the same fraction both ways (η_b = η) and has no friction
    /// at no load.
    pub fn new(motor: Box<dyn Motor>, gear_ratio: f64, efficiency: f64, rated_torque: f64) -> Self {
        Self::with_gear(motor, gear_ratio, LossyGear::with_efficiency(efficiency), rated_torque)
    }

    /// A motor behind one gearbox of the given losses and peak rating, nothing else known of it.
    pub fn with_gear(motor: Box<dyn Motor>, gear_ratio: f64, gear: LossyGear, rated_torque: f64) -> Self {
        Self { motor, gear_ratio, gear, rated_torque, heat: None, continuous_torque: None, input_inertia: 0.0, max_motor_speed: None, rated_average_torque: None, reductions: Vec::new(), parts: Vec::new(), servo: None }
    }

    /// The gearbox's efficiency when the motor drives, η.
    pub fn efficiency(&self) -> f64 {
        self.gear.efficiency
    }

    /// Torque available at the joint at joint speed `speed`, driving with the motion (the smaller of
    /// the two directions): min(η·N·T_motor(N·speed), rated).
    pub fn torque_limit(&self, speed: f64) -> f64 {
        (self.gear.efficiency * self.gear_ratio * self.motor.torque_at(self.gear_ratio * speed)).min(self.rated_torque)
    }

    /// Whether a torque of this sign at joint speed `speed` brakes the motion (at rest a positive
    /// torque counts as with the motion).
    fn braking(torque: f64, speed: f64) -> bool {
        if speed >= 0.0 { torque < 0.0 } else { torque >= 0.0 }
    }

    /// What the motor gives at the joint before the gearbox's losses, N·T, in the direction of
    /// `torque` at joint speed `speed`: its torque–speed curve with the motion, its braking torque
    /// against it.
    pub fn motor_torque(&self, torque: f64, speed: f64) -> f64 {
        let shaft = self.gear_ratio * speed;
        self.gear_ratio * if Self::braking(torque, speed) { self.motor.braking_torque_at(shaft) } else { self.motor.torque_at(shaft) }
    }

    /// The torque the joint gets in the direction of `torque` at joint speed `speed` (≥ 0), the
    /// motor at its most: driving, η·N·T less the gear's breakaway and viscous friction, capped by
    /// the gearbox's rating; braking (back-driven), N·T_b/η_b plus the friction, which helps (a
    /// self-locking gear holds whatever the rating allows).
    pub fn available(&self, torque: f64, speed: f64) -> f64 {
        self.available_from(torque, speed, self.motor_torque(torque, speed))
    }

    /// [`Self::available`] with the servo's duty held to `duty` (a tripped protection; 0: its
    /// torque off): the motor's torque at that duty, with the motion or braking.
    pub fn available_at_duty(&self, torque: f64, speed: f64, duty: f64) -> f64 {
        let Some(servo) = &self.servo else { return self.available(torque, speed) };
        let shaft = (self.gear_ratio * speed).abs();
        let motor = if duty <= 0.0 {
            0.0
        } else if Self::braking(torque, speed) {
            servo.drive(duty, -shaft, servo.supply, true).torque
        } else {
            servo.drive(duty, shaft, servo.supply, true).torque.max(0.0)
        };
        self.available_from(torque, speed, self.gear_ratio * motor)
    }

    /// What reaches the joint in the direction of `torque` with the motor giving `motor_torque`
    /// (≥ 0, at the joint before the losses).
    fn available_from(&self, torque: f64, speed: f64, motor_torque: f64) -> f64 {
        let sign = if torque >= 0.0 { 1.0 } else { -1.0 };
        // the direction of motion: the torque's when it drives (at rest too), the other braking
        let direction = if Self::braking(torque, speed) { -sign } else { sign };
        let at_joint = sign * self.gear.output_torque(sign * motor_torque, direction, speed);
        at_joint.max(0.0).min(self.rated_torque)
    }

    /// The torque at the servo's output (N·m, signed) and its speed (rad/s) for a joint torque
    /// `torque` at joint speed `speed`: back through the reductions' losses, plus the servo's own
    /// friction while it slides ([`bus_servo::ServoFriction`]); None without a servo model.
    pub fn servo_torque_for(&self, torque: f64, speed: f64, sliding: bool) -> Option<(f64, f64)> {
        let servo = self.servo.as_ref()?;
        let along = torque + self.gear.viscous * speed;
        let at_output = along.signum() * self.gear.motor_torque_for(torque, speed) / self.gear_ratio;
        let shaft = self.gear_ratio * speed;
        let friction = if sliding { shaft.signum() * servo.friction.budget(at_output, -at_output, shaft) + servo.friction.viscous * shaft } else { 0.0 };
        Some((at_output + friction, shaft))
    }

    /// The range of the motor's torque at the joint before the gearbox's losses, N·T, at joint
    /// speed `speed` — what a controller can command: (lowest ≤ 0, highest ≥ 0). The gearbox's
    /// rating caps what reaches the joint: rated/η driving, rated·η_b braking.
    pub fn torque_range(&self, speed: f64) -> (f64, f64) {
        DriveEnvelope::of(self).torque_range(speed, &*self.motor)
    }

    /// This drive train followed by a further reduction (a belt or gearbox after a gearmotor): the
    /// ratios multiply and the losses compose ([`LossyGear::followed_by`]); the first gearbox's
    /// rating, at its output, is carried through the second, whose own rating caps it.
    pub fn followed_by(self, gear_ratio: f64, next: LossyGear, rated_torque: f64) -> Self {
        self.then(&Stage::plain(gear_ratio, next, rated_torque))
    }

    /// This drive train followed by `stage`: ratios multiply, losses compose, the ratings so far are
    /// carried through the stage (×η·N) and capped by its own; its input turns at the motor's speed
    /// over the ratio so far (its speed limit times that ratio bounds the motor), and its input
    /// inertia reaches the motor's shaft divided by that ratio squared.
    pub fn then(self, stage: &Stage) -> Self {
        let through = stage.ratio * stage.gear.efficiency;
        let rated_average_torque = match (self.rated_average_torque.map(|r| r * through), stage.rated_average_torque) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let max_motor_speed = match (self.max_motor_speed, stage.max_input_speed.map(|w| w * self.gear_ratio)) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        Self {
            rated_torque: (self.rated_torque * through).min(stage.peak_torque),
            gear: self.gear.followed_by(stage.ratio, &stage.gear),
            input_inertia: self.input_inertia + stage.input_inertia / (self.gear_ratio * self.gear_ratio),
            gear_ratio: self.gear_ratio * stage.ratio,
            rated_average_torque,
            max_motor_speed,
            ..self
        }
    }

    /// This drive train followed by the catalogue reduction `reduction` at `ratio`; None when it has
    /// no such ratio.
    pub fn then_reduction(self, reduction: &Reduction, ratio: f64) -> Option<Self> {
        let stage = reduction.stage(ratio)?;
        let mut out = self.then(&stage);
        out.reductions.push(reduction.name.clone());
        if let Some(mass) = reduction.mass {
            out.parts.push(Part { name: reduction.name.clone(), mass, cylinder: None });
        }
        Some(out)
    }

    /// The published mass of its parts, kg.
    pub fn mass(&self) -> f64 {
        self.parts.iter().map(|p| p.mass).sum()
    }

    /// The inertia turning at the motor's speed: its rotor (a servo's identified armature where its
    /// firmware model gives one) and the reductions' inputs, kg·m².
    pub fn shaft_inertia(&self) -> f64 {
        self.servo.as_ref().map_or_else(|| self.motor.rotor_inertia(), |s| s.armature) + self.input_inertia
    }

    /// The rotor's (and the reductions' input) inertia seen at the joint, J·N².
    pub fn reflected_inertia(&self) -> f64 {
        self.shaft_inertia() * self.gear_ratio * self.gear_ratio
    }

    /// The joint speed above which the joint gets less than `fraction` of its torque at rest
    /// (bisection on the monotone torque–speed curve; infinite if it never falls that far).
    pub fn speed_at_fraction(&self, fraction: f64) -> f64 {
        let target = fraction * self.torque_limit(0.0);
        let (mut lo, mut hi) = (0.0_f64, 1e-3_f64);
        while self.torque_limit(hi) > target {
            hi *= 2.0;
            if hi > 1e9 {
                return f64::INFINITY;
            }
        }
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.torque_limit(mid) > target { lo = mid } else { hi = mid }
        }
        hi
    }
}

/// The drive trains of a model's joints (by coordinate; `None`: the URDF's constant effort limit).
#[derive(Clone, Debug, Default)]
pub struct MotorSet {
    pub joints: Vec<Option<DriveTrain>>,
    /// Per coordinate, the driver's microsteps per full step (steppers).
    pub microsteps: Vec<Option<u32>>,
    /// Per coordinate, the step generator's acceleration bound, rad/s² at the joint (steppers).
    pub acceleration: Vec<Option<f64>>,
    /// Per coordinate, where its drive train's parts sit (on the parent link at the joint by default).
    pub mounts: Vec<Mount>,
    /// The motor file it came from.
    pub source: std::path::PathBuf,
    /// A floor under a point of the arm (the file's `[floor]`: the table a real arm's gripper
    /// rests on, as `identify --from` finds it).
    pub floor: Option<crate::plant::FloorContact>,
}

impl MotorSet {
    /// No motors yet on `dof` coordinates.
    pub fn empty(dof: usize, source: impl Into<std::path::PathBuf>) -> Self {
        Self { joints: (0..dof).map(|_| None).collect(), microsteps: vec![None; dof], acceleration: vec![None; dof], mounts: vec![Mount::AtJoint; dof], source: source.into(), floor: None }
    }

    /// For people: one line per joint with a motor — the motor, the drive train, the torque at rest,
    /// the rotor's inertia at the joint and the joint speed at which the torque runs out.
    pub fn table(&self, joint_names: &[String]) -> String {
        let w = joint_names.iter().map(|n| n.chars().count()).max().unwrap_or(5).max(5) + 2;
        let mut out = format!("    {:<w$}{:<20}{:>7}{:>6}{:>7}{:>10}{:>15}{:>16}{:>26}\n", "joint", "motor", "ratio", "η", "η_b", "rated", "at rest (N·m)", "J_r·N² (kg·m²)", "half of it above (rad/s)");
        for (name, drive) in joint_names.iter().zip(&self.joints) {
            let Some(d) = drive else { continue };
            let rated = if d.rated_torque.is_finite() { format!("{:.2}", d.rated_torque) } else { "–".into() };
            let top = d.speed_at_fraction(0.5);
            let top = if top.is_finite() { format!("{top:.2}") } else { "–".into() };
            let backdrive = if d.gear.self_locking() { "locks".to_string() } else { format!("{}", d.gear.backdrive_efficiency) };
            out += &format!("    {:<w$}{:<20}{:>7}{:>6}{:>7}{:>10}{:>15.3}{:>16.3e}{:>26}\n", name, d.motor.name(), d.gear_ratio, d.gear.efficiency, backdrive, rated, d.torque_limit(0.0), d.reflected_inertia(), top);
            if d.gear.breakaway_torque > 0.0 || d.gear.viscous > 0.0 {
                out += &format!("    {:<w$}  gear friction at the joint: breakaway {} N·m, viscous {} N·m·s/rad\n", "", d.gear.breakaway_torque, d.gear.viscous);
            }
        }
        out
    }

    /// The speed of joint `joint`'s motor shaft, N·q̇ in rev/s, at joint speed `joint_speed`; None
    /// for a joint the motor file leaves out.
    pub fn motor_speed(&self, joint: usize, joint_speed: f64) -> Option<f64> {
        self.joints[joint].as_ref().map(|d| d.gear_ratio * joint_speed / std::f64::consts::TAU)
    }

    /// Per coordinate, the gearbox losses of the joint's drive train (None without one).
    pub fn gears(&self) -> Vec<Option<LossyGear>> {
        self.joints.iter().map(|d| d.as_ref().map(|d| d.gear)).collect()
    }

    /// Per coordinate, its motor's thermal data and the gear ratio between them (None without one).
    pub fn heat(&self) -> Vec<Option<(thermal::WindingHeat, f64)>> {
        self.joints.iter().map(|d| d.as_ref().and_then(|d| d.heat.map(|h| (h, d.gear_ratio)))).collect()
    }

    /// Whether any joint has a stepper.
    pub fn has_steppers(&self) -> bool {
        self.joints.iter().flatten().any(|d| d.motor.as_stepper().is_some())
    }

}
