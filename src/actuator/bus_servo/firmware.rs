//! What a serial-bus servo's firmware does in position mode: a P law on the position error in the
//! servo's own units sets the PWM duty, clipped at its limit; a Feetech also walks its internal
//! target towards the goal at a bounded speed. One [`Family`] per servo line, each number with its
//! source.
//!
//! The duty requested is d = e_g·k_p·(q_target − q): the error in encoder counts (counts per turn
//! / 2π per rad) times the P gain register over its divisor gives PWM counts, and the PWM counts of
//! 100 % make it a fraction. e_g folds those together, per unit of the P gain register and rad.

use super::protection::{self, Protection, ProtectionState};

/// The firmware of one servo line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Family {
    /// BAM's actuator name ("xl330", "sts3215", …).
    pub name: &'static str,
    /// e_g: duty (1 = 100 %) per P gain register unit per rad of error.
    pub error_gain: f64,
    /// The largest duty the firmware gives, d_max.
    pub max_duty: f64,
    /// The P gain register's value out of the box.
    pub default_kp: f64,
    /// The supply the vendor rates it at, V.
    pub nominal_supply: f64,
    /// The highest supply the vendor allows, V, where a source gives it (None: not found). Run above
    /// it, a servo does not put the whole supply across its motor (`identify` then fits that cap).
    pub max_supply: Option<f64>,
    /// Whether the firmware walks an internal target towards the goal at a bounded speed (Feetech).
    pub goal_speed_limiter: bool,
    /// That speed out of the box, rad/s.
    pub default_max_velocity: f64,
    /// The firmware's protections out of the box ([`super::protection`]).
    pub protection: Protection,
    /// Where the numbers were read.
    pub source: &'static str,
}

/// Dynamixel XL330 encoder counts per turn, P gain divisor and PWM counts of 100 %.
const XL330_COUNTS_PER_TURN: f64 = 4096.0;
const XL330_KP_DIVISOR: f64 = 256.0;
const XL330_PWM_FULL: f64 = 885.0;

pub const XL330: Family = Family {
    name: "xl330",
    error_gain: (XL330_COUNTS_PER_TURN / std::f64::consts::TAU) / (XL330_KP_DIVISOR * XL330_PWM_FULL),
    max_duty: 1.0,
    default_kp: 400.0,
    nominal_supply: 5.0,
    max_supply: Some(6.0),
    goal_speed_limiter: false,
    default_max_velocity: f64::INFINITY,
    protection: Protection::NONE,
    source: "e_g = (4096/2π)/(256·885): Rhoban/bam bam/dynamixel/actuator.py at 1b5a1ce (the 256 divisor measured by BAM; \
             the Dynamixel manual says 128); 885 = 100 % is the PWM Limit(36) default and Position P Gain(84) defaults to 400 \
             (ROBOTIS e-manual docs/en/dxl/x/xl330-m288.md); 5.0 V: the e-manual's rated voltage, 6.0 V the top of its 3.7–6.0 V \
             supply range (catalogue-sources.md §2)",
};

pub const XL320: Family = Family {
    name: "xl320",
    error_gain: 0.05048199,
    max_duty: 1.0,
    default_kp: 32.0,
    nominal_supply: 7.5,
    max_supply: None,
    goal_speed_limiter: false,
    default_max_velocity: f64::INFINITY,
    protection: Protection::NONE,
    source: "Rhoban/bam bam/dynamixel/actuator.py at 1b5a1ce (e_g and d_max measured by BAM with an oscilloscope; its defaults V_in 7.5, k_p 32)",
};

pub const MX64: Family = Family {
    name: "mx64",
    error_gain: 0.158,
    max_duty: 0.9625,
    default_kp: 32.0,
    nominal_supply: 15.0,
    max_supply: None,
    goal_speed_limiter: false,
    default_max_velocity: f64::INFINITY,
    protection: Protection::NONE,
    source: "Rhoban/bam bam/dynamixel/actuator.py at 1b5a1ce (e_g and d_max measured by BAM with an oscilloscope; its defaults V_in 15, k_p 32)",
};

pub const MX106: Family = Family { name: "mx106", ..MX64 };

pub const STS3215: Family = Family {
    name: "sts3215",
    error_gain: 0.166,
    max_duty: 0.97,
    default_kp: 32.0,
    nominal_supply: 7.4,
    // the family covers the 7.4 V and the 12 V servos: no one limit
    max_supply: None,
    goal_speed_limiter: true,
    default_max_velocity: 3400.0 * std::f64::consts::TAU / 4096.0,
    protection: protection::FEETECH_FACTORY,
    source: "Rhoban/bam bam/feetech/actuator.py at 1b5a1ce (e_g measured by BAM with an oscilloscope, times the identified \
             error_gain_ratio; d_max 0.97; k_p is the P_Coefficient register, default 32; the internal target moves at most \
             max_velocity, default 3400 counts/s of 4096 a turn)",
};

/// Every family armscope knows, by BAM's actuator name.
pub const FAMILIES: [Family; 5] = [XL330, XL320, MX64, MX106, STS3215];

/// Names of the 12 V STS3215 that no BAM version knows, each the STS3215's firmware: BAM's published
/// 12 V file says "sts321512v", K-Scale Labs' parameter files (kscalelabs/sysid) "sts3215v12".
pub const STS3215_ALIASES: [&str; 2] = ["sts321512v", "sts3215v12"];

/// Whether `name` is one of [`STS3215_ALIASES`] (a parameter file's reader says it read it as
/// "sts3215").
pub fn is_alias(name: &str) -> bool {
    STS3215_ALIASES.iter().any(|a| a.eq_ignore_ascii_case(name))
}

/// The family of BAM's actuator name, or of one of [`STS3215_ALIASES`].
pub fn family(name: &str) -> Option<Family> {
    let name = if is_alias(name) { "sts3215" } else { name };
    FAMILIES.into_iter().find(|f| f.name.eq_ignore_ascii_case(name))
}

/// The names of the known families, for messages.
pub fn family_names() -> String {
    FAMILIES.iter().map(|f| f.name).collect::<Vec<_>>().join(", ")
}

/// The firmware's state between control ticks: where its internal target is (a Feetech's walks
/// towards the goal; others take the goal as it comes), and its protections' timers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FirmwareState {
    pub target: f64,
    pub protection: ProtectionState,
}

impl FirmwareState {
    /// At rest with the internal target at `target`, no protection timing.
    pub fn at(target: f64) -> Self {
        Self { target, ..Self::default() }
    }
}

/// The firmware's settings on one servo: its family, P gain register, the error gain's identified
/// correction (Feetech; 1 elsewhere), the goal speed bound, and an optional current limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Firmware {
    pub family: Family,
    pub kp: f64,
    pub error_gain_ratio: f64,
    pub max_velocity: f64,
    /// A current limit the firmware enforces by narrowing the duty (A; none in the XL330's and the
    /// STS3215's position mode: the XL330 applies Current Limit(38) only in its current-based modes).
    pub current_limit: Option<f64>,
    /// Its protections (the family's out of the box; a motor file can set them).
    pub protection: Protection,
}

impl Firmware {
    /// The family's firmware with P gain `kp` and the family's defaults elsewhere.
    pub fn new(family: Family, kp: f64) -> Self {
        Self { family, kp, error_gain_ratio: 1.0, max_velocity: family.default_max_velocity, current_limit: None, protection: family.protection }
    }

    /// Duty per rad of error: e_g·r·k_p.
    pub fn duty_per_rad(&self) -> f64 {
        self.family.error_gain * self.error_gain_ratio * self.kp
    }

    /// One firmware tick of length `dt`: move the internal target towards `goal` (a Feetech by at
    /// most max_velocity·dt), then the duty for position `q` (and speed `speed`, for the current
    /// limiter: I = (d·V − k_t·q̇)/R within ±I_max narrows d), clipped at ±d_max.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn tick(&self, state: &mut FirmwareState, goal: f64, q: f64, speed: f64, dt: f64, supply: f64, kt: f64, resistance: f64) -> f64 {
        state.target = if self.family.goal_speed_limiter {
            let step = self.max_velocity * dt;
            goal.clamp(state.target - step, state.target + step)
        } else {
            goal
        };
        let mut duty = (state.target - q) * self.kp * self.family.error_gain * self.error_gain_ratio;
        if let Some(limit) = self.current_limit {
            let centre = kt * speed / supply;
            let span = resistance * limit / supply;
            duty = duty.clamp(centre - span, centre + span);
        }
        duty.clamp(-self.family.max_duty, self.family.max_duty)
    }

    /// The error at which the duty saturates, rad.
    pub fn saturation_error(&self) -> f64 {
        self.family.max_duty / self.duty_per_rad()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xl330_saturates_where_bam_says() {
        // MODEL.md §3.1: |q_g − q| ≥ 1/(e_g k_p): 3.475 rad at k_p = 100, 0.869 at 400
        assert!((Firmware::new(XL330, 100.0).saturation_error() - 3.475).abs() < 1e-3);
        assert!((Firmware::new(XL330, 400.0).saturation_error() - 0.869).abs() < 1e-3);
        assert!((XL330.error_gain - 2.8774e-3).abs() < 1e-7);
    }

    #[test]
    fn feetech_target_walks_at_its_speed_bound() {
        let fw = Firmware::new(STS3215, 32.0);
        let mut state = FirmwareState::default();
        fw.tick(&mut state, 1.0, 0.0, 0.0, 0.01, 7.4, 1.0, 2.0);
        assert!((state.target - 0.052155).abs() < 1e-6);
        let mut xl = FirmwareState::default();
        Firmware::new(XL330, 400.0).tick(&mut xl, 1.0, 0.0, 0.0, 0.01, 7.4, 1.0, 2.0);
        assert_eq!(xl.target, 1.0);
    }

    #[test]
    fn current_limit_narrows_the_duty() {
        let mut fw = Firmware::new(XL330, 800.0);
        fw.current_limit = Some(1.0);
        let mut state = FirmwareState::default();
        // at rest: |d·V/R| ≤ 1 A → d ≤ R/V
        let duty = fw.tick(&mut state, 1.0, 0.0, 0.0, 0.005, 7.4, 0.36, 2.8);
        assert!((duty - 2.8 / 7.4).abs() < 1e-12);
        assert_eq!(family("STS321512V").map(|f| f.name), Some("sts3215"));
        assert_eq!(family("sts3215v12").map(|f| f.name), Some("sts3215"));
        assert!(family("xm430").is_none());
    }
}
