//! How a recording's columns become the URDF's joint coordinates (`--joint-map FILE.toml`):
//!
//! ```toml
//! calibration = "so101_follower.json"   # optional: a LeRobot calibration file
//! [joints.shoulder_pan]
//! column = "shoulder_pan.pos"
//! unit = "deg"          # deg | rad | m | range_0_100 | range_m100_100
//! sign = 1              # q = sign·value_in_rad + offset
//! offset = 0.0          # rad (m for a prismatic joint)
//! ```
//!
//! A range maps linearly onto the joint's URDF limits (0…100 or −100…100 from lower to upper; sign
//! −1 from upper to lower): approximate, a real arm's calibrated range is not its URDF's. With a
//! LeRobot calibration file (`range_min`, `range_max`, `drive_mode` per motor) the value is turned
//! back into the motor's tick t, as LeRobot's normalization made it (a `drive_mode` 1 range is
//! negated), and the angle measured from the middle of the calibrated range, where LeRobot's
//! DEGREES mode has its zero: q = sign·(t − (lo + hi)/2)·2π/4095 + offset (LeRobot's degrees are
//! 360/4095 a tick), the same q a DEGREES recording of the arm gives.
//!
//! The SO-101's LeRobot datasets have a built-in map; their body joints' unit (degrees, or LeRobot's
//! RANGE_M100_100, the SO followers' default before 2026-02-13) is not in the dataset:
//! [`decide_body_unit`] tells it from the values where they tell it. A map file with only a
//! `calibration` line gives the built-in map that calibration file, as `--calibration` does.

use super::{Episode, SourceKind};
use crate::error::Error;
use crate::model::{JointKind, Model};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Unit {
    Deg,
    Rad,
    /// Metres (a prismatic joint; the same as `rad`: SI).
    M,
    #[serde(rename = "range_0_100")]
    Range0To100,
    #[serde(rename = "range_m100_100")]
    RangeM100To100,
}

impl Unit {
    pub fn name(self) -> &'static str {
        match self {
            Unit::Deg => "deg",
            Unit::Rad => "rad",
            Unit::M => "m",
            Unit::Range0To100 => "range_0_100",
            Unit::RangeM100To100 => "range_m100_100",
        }
    }

    /// Whether a calibration file turns this unit's values into the motor's angle: all but LeRobot's
    /// 0…100 (its gripper), which LeRobot gives no angle — where the URDF's zero lies in its
    /// calibrated travel nothing says, so it maps onto the joint's limits.
    pub fn takes_calibration(self) -> bool {
        self != Unit::Range0To100
    }
}

/// LeRobot's per-motor calibration record.
#[derive(Clone, Copy, Debug, Deserialize)]
pub struct MotorCalibration {
    #[serde(default)]
    pub drive_mode: i64,
    #[serde(default)]
    pub homing_offset: i64,
    pub range_min: f64,
    pub range_max: f64,
}

/// The encoder's ticks per turn on LeRobot's Feetech and Dynamixel servos, and the tick the
/// calibration pose reads.
const TICKS_PER_TURN: f64 = 4096.0;
/// LeRobot's degrees: 360° over 4095 ticks (`_normalize` divides by `resolution − 1`).
pub const TICKS_PER_360: f64 = TICKS_PER_TURN - 1.0;

#[derive(Clone, Debug)]
pub struct Entry {
    pub joint: usize,
    pub column: String,
    pub unit: Unit,
    pub sign: f64,
    pub offset: f64,
    pub calibration: Option<MotorCalibration>,
}

/// Every mapped coordinate of a model, and where its values come from.
#[derive(Clone, Debug)]
pub struct JointMap {
    pub entries: Vec<Entry>,
    /// The map file, or what the built-in map is.
    pub source: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MapToml {
    calibration: Option<PathBuf>,
    joints: Option<BTreeMap<String, JointEntry>>,
}

/// What a map file gives: joints of its own, or — a file with no `[joints]` — only the LeRobot
/// calibration file for the built-in map (the SO-101's), as `--calibration` gives it.
pub enum MapFile {
    Joints(JointMap),
    Calibration(PathBuf),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointEntry {
    column: String,
    unit: Unit,
    #[serde(default = "one")]
    sign: f64,
    #[serde(default)]
    offset: f64,
    /// The motor's name in the calibration file (default: the column without `.pos`).
    motor: Option<String>,
}

fn one() -> f64 {
    1.0
}

/// The built-in map of the SO-101 (example-robot-data's `so101.urdf`, the SO-ARM100 repository's
/// `so101_new_calib.urdf`): LeRobot's own kinematics passes the five body joints' degrees to it as
/// they are (sign +1, offset 0: `lerobot/model/kinematics.py`), the gripper's 0…100 spans its
/// travel.
const SO101_URDF: &str = "so101_new_calib";
const SO101_JOINTS: [(&str, Unit); 6] = [("shoulder_pan", Unit::Deg), ("shoulder_lift", Unit::Deg), ("elbow_flex", Unit::Deg), ("wrist_flex", Unit::Deg), ("wrist_roll", Unit::Deg), ("gripper", Unit::Range0To100)];

impl JointMap {
    /// Read a map file and check its joints against the model.
    pub fn load(path: &Path, model: &Model) -> Result<Self, Error> {
        match Self::read(path, model)? {
            MapFile::Joints(map) => Ok(map),
            MapFile::Calibration(_) => Err(Error::flag(path.display().to_string(), "no [joints.NAME] entries: a map of its own needs them")),
        }
    }

    /// Read a map file: its joints checked against the model, or, where it has no `[joints]`, the
    /// calibration file it names (a relative path from the map's folder) for the built-in map.
    pub fn read(path: &Path, model: &Model) -> Result<MapFile, Error> {
        let fail = |m: String| Error::flag(path.display().to_string(), m);
        let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
        let file: MapToml = toml::from_str(&text).map_err(|e| fail(e.message().to_string()))?;
        let calibration_path = file.calibration.map(|c| if c.is_relative() { path.parent().unwrap_or(Path::new(".")).join(c) } else { c });
        let Some(joints) = file.joints else {
            return match calibration_path {
                Some(c) => Ok(MapFile::Calibration(c)),
                None => Err(fail("neither [joints.NAME] entries nor a calibration file: nothing to map with".into())),
            };
        };
        let calibration: Option<BTreeMap<String, MotorCalibration>> = calibration_path.as_deref().map(read_calibration).transpose()?;
        let mut entries = Vec::new();
        for (name, e) in joints {
            let joint = model.joint_index(&name).ok_or_else(|| fail(format!("[joints.{name}]: no moving joint '{name}' in {} (joints: {})", model.source.display(), joint_names(model))))?;
            if !(e.sign == 1.0 || e.sign == -1.0) {
                return Err(fail(format!("[joints.{name}]: sign must be 1 or -1 (got {})", e.sign)));
            }
            if !e.offset.is_finite() {
                return Err(fail(format!("[joints.{name}]: offset must be a number")));
            }
            let ranged = matches!(e.unit, Unit::Range0To100 | Unit::RangeM100To100);
            let limits = model.joints[joint].lower.is_finite() && model.joints[joint].upper.is_finite();
            let motor = e.motor.clone().unwrap_or_else(|| e.column.trim_end_matches(".pos").to_string());
            let calibration = match &calibration {
                Some(c) if e.unit.takes_calibration() => Some(*c.get(&motor).ok_or_else(|| fail(format!("[joints.{name}]: no motor '{motor}' in the calibration file (motors: {})", c.keys().cloned().collect::<Vec<_>>().join(", "))))?),
                _ => None,
            };
            if ranged && calibration.is_none() && !limits {
                let instead = if e.unit.takes_calibration() { "give a calibration file, or unit deg/rad" } else { "unit deg/rad" };
                return Err(fail(format!("[joints.{name}]: unit {} maps onto the joint's limits, and the URDF gives it none ({instead})", e.unit.name())));
            }
            entries.push(Entry { joint, column: e.column, unit: e.unit, sign: e.sign, offset: e.offset, calibration });
        }
        entries.sort_by_key(|e| e.joint);
        Ok(MapFile::Joints(Self { entries, source: path.display().to_string() }))
    }

    /// The map armscope knows for this model and recording, if there is one: a bag's or a table's
    /// columns named by joint (SI units), the SO-101's LeRobot datasets.
    pub fn builtin(kind: SourceKind, model: &Model, episode: &Episode) -> Option<Self> {
        match kind {
            SourceKind::Bag | SourceKind::Csv => {
                let entries: Vec<Entry> = model
                    .joints
                    .iter()
                    .enumerate()
                    .filter(|(_, j)| episode.column(&j.name).is_some())
                    .map(|(joint, j)| Entry { joint, column: j.name.clone(), unit: if j.kind == JointKind::Prismatic { Unit::M } else { Unit::Rad }, sign: 1.0, offset: 0.0, calibration: None })
                    .collect();
                (!entries.is_empty()).then(|| Self { entries, source: "columns named by joint, SI units".into() })
            }
            SourceKind::LeRobot => {
                if model.name != SO101_URDF {
                    return None;
                }
                let mut entries = Vec::new();
                for (name, unit) in SO101_JOINTS {
                    let joint = model.joint_index(name)?;
                    // LeRobot's names since June 2025, or the older layout's (`main_shoulder_pan`)
                    let column = [format!("{name}.pos"), format!("main_{name}")].into_iter().find(|c| episode.column(c).is_some())?;
                    entries.push(Entry { joint, column, unit, sign: 1.0, offset: 0.0, calibration: None });
                }
                Some(Self { entries, source: "built-in SO-101 map (LeRobot's degrees, sign +1, offset 0; gripper 0…100 over its limits)".into() })
            }
        }
    }

    /// The built-in SO-101 map with its body joints in `unit` (degrees or LeRobot's range) and, with
    /// `calibration`, each body motor's calibration record (by the motor's name: the column without
    /// `.pos` or `main_`).
    pub fn with_body_unit(mut self, unit: Unit, calibration: Option<(&Path, &BTreeMap<String, MotorCalibration>)>) -> Result<Self, Error> {
        // the gripper keeps its 0…100 over its URDF limits
        for e in self.entries.iter_mut().filter(|e| e.unit.takes_calibration()) {
            e.unit = unit;
            if let Some((path, records)) = calibration {
                let motor = motor_of(&e.column);
                e.calibration = Some(*records.get(motor).ok_or_else(|| Error::flag(path.display().to_string(), format!("no motor '{motor}' (column {}): a calibration file for other motors? (motors: {})", e.column, records.keys().cloned().collect::<Vec<_>>().join(", "))))?);
            }
        }
        let unit = match unit {
            Unit::RangeM100To100 => "LeRobot's RANGE_M100_100",
            _ => "LeRobot's degrees",
        };
        self.source = match calibration {
            Some((path, _)) => format!("built-in SO-101 map (body joints in {unit}, angles from {}; gripper 0…100 over its limits)", path.display()),
            None => format!("built-in SO-101 map (body joints in {unit}, sign +1, offset 0; gripper 0…100 over its limits)"),
        };
        Ok(self)
    }

    /// A map file to fill in for this model and recording: each joint with the column of the same
    /// position in the recording, if there is one.
    pub fn template(model: &Model, columns: &[&str]) -> String {
        let mut out = String::from("# armscope joint map: q = sign·value_in_rad + offset (rad; m for a prismatic joint)\n");
        out += &format!("# recording's columns: {}\n", columns.join(", "));
        out += "# calibration = \"so101_follower.json\"   # a LeRobot calibration file, optional\n";
        for (k, j) in model.joints.iter().enumerate() {
            let column = columns.get(k).copied().unwrap_or("COLUMN");
            out += &format!("\n[joints.{}]\ncolumn = \"{column}\"\nunit = \"deg\"   # deg | rad | m | range_0_100 | range_m100_100\nsign = 1\noffset = 0.0\n", j.name);
        }
        out
    }

    /// The map's joints whose column `episode` has (a bag's commands name the joints their controller
    /// drives, not every joint).
    pub fn only_columns_of(&self, episode: &Episode) -> JointMap {
        JointMap { entries: self.entries.iter().filter(|e| episode.column(&e.column).is_some()).cloned().collect(), source: self.source.clone() }
    }

    /// The recording's columns in the model's coordinates: per coordinate its series, `None` where
    /// the map leaves the joint out.
    pub fn apply(&self, model: &Model, episode: &Episode) -> Result<Vec<Option<Vec<f64>>>, Error> {
        let mut out: Vec<Option<Vec<f64>>> = vec![None; model.dof()];
        for e in &self.entries {
            let column = episode.column(&e.column).ok_or_else(|| {
                Error::flag(self.source.clone(), format!("joint '{}': no column '{}' in {} (columns: {})", model.joints[e.joint].name, e.column, episode.label, episode.column_names().join(", ")))
            })?;
            let joint = &model.joints[e.joint];
            out[e.joint] = Some(column.values.iter().map(|&v| e.to_coordinate(v, joint.lower, joint.upper)).collect());
        }
        Ok(out)
    }
}

impl Entry {
    /// One recorded value in the joint's coordinate.
    pub fn to_coordinate(&self, value: f64, lower: f64, upper: f64) -> f64 {
        if let Some(c) = &self.calibration {
            let (lo, hi) = (c.range_min, c.range_max);
            let reversed = c.drive_mode == 1;
            // back to the motor's tick, as LeRobot normalized it (`_normalize`: a range negated
            // where drive_mode is 1; degrees are not)
            let tick = match self.unit {
                Unit::Deg => value * TICKS_PER_360 / 360.0 + 0.5 * (lo + hi),
                Unit::Rad | Unit::M => value * TICKS_PER_360 / TAU + 0.5 * (lo + hi),
                Unit::RangeM100To100 => ((if reversed { -value } else { value }) + 100.0) / 200.0 * (hi - lo) + lo,
                Unit::Range0To100 => (if reversed { 100.0 - value } else { value }) / 100.0 * (hi - lo) + lo,
            };
            return self.sign * (tick - 0.5 * (lo + hi)) * TAU / TICKS_PER_360 + self.offset;
        }
        match self.unit {
            Unit::Deg => self.sign * value.to_radians() + self.offset,
            Unit::Rad | Unit::M => self.sign * value + self.offset,
            Unit::Range0To100 | Unit::RangeM100To100 => {
                let fraction = if self.unit == Unit::Range0To100 { value / 100.0 } else { (value + 100.0) / 200.0 };
                let fraction = if self.sign < 0.0 { 1.0 - fraction } else { fraction };
                lower + fraction * (upper - lower) + self.offset
            }
        }
    }
}

/// The motor a LeRobot column names (`shoulder_pan.pos`, the older `main_shoulder_pan`).
fn motor_of(column: &str) -> &str {
    let name = column.strip_suffix(".pos").unwrap_or(column);
    name.strip_prefix("main_").unwrap_or(name)
}

/// A LeRobot calibration file: per motor its `range_min`, `range_max`, `drive_mode`.
pub fn read_calibration(path: &Path) -> Result<BTreeMap<String, MotorCalibration>, Error> {
    let fail = |m: String| Error::flag(path.display().to_string(), m);
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let records: BTreeMap<String, MotorCalibration> = serde_json::from_str(&text).map_err(|e| fail(format!("not a LeRobot calibration file: {e}")))?;
    if let Some((motor, c)) = records.iter().find(|(_, c)| !(c.range_max > c.range_min)) {
        return Err(fail(format!("motor '{motor}': range_max {} is not above range_min {}", c.range_max, c.range_min)));
    }
    Ok(records)
}

/// Body values beyond this are no LeRobot range (it clamps one to ±100).
const RANGE_LIMIT: f64 = 100.0;

/// The body joints' unit as the values tell it, and why (one line): a value beyond ±100 is degrees
/// (LeRobot clamps RANGE_M100_100 to ±100); values all within ±100 with some exactly at ±100 are a
/// range (a joint driven to its calibrated end reads its clamp exactly; degrees land on 360/4095 a
/// tick and reach 100.0 only by chance). Neither: Err, why the values cannot tell.
pub fn decide_body_unit(columns: &[(&str, &[f64])]) -> Result<(Unit, String), String> {
    let mut widest: Option<(&str, f64)> = None;
    let mut at_clamp = 0usize;
    for (name, values) in columns {
        for &v in values.iter().filter(|v| v.is_finite()) {
            if widest.is_none_or(|(_, w)| v.abs() > w.abs()) {
                widest = Some((name, v));
            }
            at_clamp += usize::from(v.abs() == RANGE_LIMIT);
        }
    }
    match widest {
        Some((name, v)) if v.abs() > RANGE_LIMIT => Ok((Unit::Deg, format!("read as degrees: {name} reaches {v:.1}, beyond the ±100 LeRobot clamps its range normalisation to"))),
        Some(_) if at_clamp > 0 => Ok((Unit::RangeM100To100, format!("read as LeRobot's RANGE_M100_100: every value within ±100, {at_clamp} exactly at ±100 (where LeRobot clamps a range)"))),
        Some((name, v)) => Err(format!("every value is within ±100 (the widest {name} at {v:.1}) and none at ±100: degrees or LeRobot's RANGE_M100_100 (the SO followers' default before 2026-02-13) alike")),
        None => Err("no values".into()),
    }
}

fn joint_names(model: &Model) -> String {
    model.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_values_tell_degrees_or_a_range_where_they_can() {
        let (unit, why) = decide_body_unit(&[("shoulder_pan.pos", &[10.0, -40.0]), ("elbow_flex.pos", &[95.0, 134.2])]).unwrap();
        assert_eq!(unit, Unit::Deg);
        assert!(why.contains("elbow_flex.pos reaches 134.2"), "{why}");
        let (unit, why) = decide_body_unit(&[("shoulder_pan.pos", &[10.0, -40.0]), ("elbow_flex.pos", &[99.6, 100.0, 100.0])]).unwrap();
        assert_eq!(unit, Unit::RangeM100To100);
        assert!(why.contains("2 exactly at ±100"), "{why}");
        let why = decide_body_unit(&[("shoulder_pan.pos", &[10.0, -40.0]), ("elbow_flex.pos", &[99.6])]).unwrap_err();
        assert!(why.contains("the widest elbow_flex.pos at 99.6") && why.contains("none at ±100"), "{why}");
    }

    #[test]
    fn a_map_says_what_a_joint_without_limits_needs_for_its_unit() {
        // a range maps onto limits; a calibration file gives a -100…100 column an angle of its own,
        // never a 0…100 one (LeRobot gives a gripper no angle)
        let urdf = r#"<robot name="wheel"><link name="base"/><link name="disc"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
            <joint name="spin" type="continuous"><parent link="base"/><child link="disc"/><axis xyz="0 0 1"/></joint></robot>"#;
        let model = crate::model::load_urdf_str(urdf, Path::new("wheel.urdf")).unwrap();
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("cal.json"), r#"{"spin": {"id": 1, "drive_mode": 0, "homing_offset": 0, "range_min": 0, "range_max": 4095}}"#).unwrap();
        let map = |unit: &str, calibrated: bool| {
            let path = dir.path().join("map.toml");
            let calibration = if calibrated { "calibration = \"cal.json\"\n" } else { "" };
            std::fs::write(&path, format!("{calibration}[joints.spin]\ncolumn = \"spin.pos\"\nunit = \"{unit}\"\n")).unwrap();
            JointMap::load(&path, &model).map(|_| ()).map_err(|e| e.to_string())
        };
        assert_eq!(map("range_m100_100", true), Ok(()));
        let error = map("range_m100_100", false).unwrap_err();
        assert!(error.contains("[joints.spin]: unit range_m100_100 maps onto the joint's limits, and the URDF gives it none (give a calibration file, or unit deg/rad)"), "{error}");
        let error = map("range_0_100", true).unwrap_err();
        assert!(error.contains("[joints.spin]: unit range_0_100 maps onto the joint's limits, and the URDF gives it none (unit deg/rad)"), "{error}");
    }

    #[test]
    fn a_calibrated_range_value_is_the_motors_angle_from_its_ranges_middle() {
        // lerobot-format.md §5.3: deg = value/100 · (hi − lo)/2 · 360/4095, zero at (lo + hi)/2, the
        // same angle a DEGREES recording of the tick gives; a drive_mode 1 range is negated
        let c = MotorCalibration { drive_mode: 0, homing_offset: 0, range_min: 1000.0, range_max: 3000.0 };
        let entry = |unit: Unit, c: MotorCalibration| Entry { joint: 0, column: "elbow_flex.pos".into(), unit, sign: 1.0, offset: 0.0, calibration: Some(c) };
        let tick = 2600.0;
        let range_value = (tick - 1000.0) / 2000.0 * 200.0 - 100.0;
        let degrees_value = (tick - 2000.0) * 360.0 / 4095.0;
        let q = entry(Unit::RangeM100To100, c).to_coordinate(range_value, -1.0, 1.0);
        assert!((q - degrees_value.to_radians()).abs() < 1e-12, "{q}");
        assert!((entry(Unit::Deg, c).to_coordinate(degrees_value, -1.0, 1.0) - q).abs() < 1e-12);
        assert!((entry(Unit::RangeM100To100, MotorCalibration { drive_mode: 1, ..c }).to_coordinate(-range_value, -1.0, 1.0) - q).abs() < 1e-12);
        // ±100 are the calibrated ends: ±(hi − lo)/2 ticks
        assert!((entry(Unit::RangeM100To100, c).to_coordinate(100.0, -1.0, 1.0) - 1000.0 * TAU / 4095.0).abs() < 1e-12);
    }
}
