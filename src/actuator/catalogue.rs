//! Motor catalogues and motor files (TOML).
//!
//! A catalogue (`assets/motors/catalogue.toml`, built in) names real motors:
//!
//! ```toml
//! [17HS4401]
//! kind = "stepper"            # or "servo"
//! holding_torque = 0.40       # N·m
//! rotor_inertia = 5.4e-6      # kg·m²
//! step_angle = 1.8            # degrees
//! inductance = 2.8e-3         # H, with current (A) and supply_voltage (V): the derived pull-out curve
//! current = 1.7
//! supply_voltage = 24
//! # pull_out = [[0, 0.40], [5, 0.30], [10, 0.15]]   # or measured points, rev/s and N·m
//! # gearbox_ratio / gearbox_efficiency / gearbox_rated_torque: a gearmotor's own gearbox, and its
//! # losses where published: gearbox_backdrive_efficiency (η_b, ≤ 1; ≤ 0 self-locking; η when not
//! # given), gearbox_breakaway_torque (N·m at its output), gearbox_viscous (N·m·s/rad at its output)
//! ```
//!
//! A motor file (`--motors FILE.toml`) gives joints a motor and a drive train:
//!
//! ```toml
//! catalogue = "my_motors.toml"   # optional, beside this file; the built-in catalogue otherwise
//! [joints.J1]
//! motor = "17HS4401"
//! gear_ratio = 15                # the reduction after the motor (and after its own gearbox)
//! efficiency = 0.9               # of that reduction, driving (the joint gets η·N·T)
//! backdrive_efficiency = 0.85    # optional, when the load drives the motor (η when not given; ≤ 0: self-locking)
//! breakaway_torque = 0.1         # optional, N·m at the joint: the reduction's friction at no load
//! viscous = 0.01                 # optional, N·m·s/rad at the joint
//! rated_torque = 9               # N·m at the joint
//! ```
//!
//! The reduction's losses act as friction at the joint by the direction power flows
//! ([`super::LossyGear`]).

use super::{DcServo, DriveTrain, LossyGear, Motor, MotorSet, PullOut, Stepper};
use crate::error::Error;
use crate::model::Model;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Value;

pub const DEFAULT_CATALOGUE: &str = "assets/motors/catalogue.toml";

/// Catalogue entries by name, as TOML tables (each made into a motor when a joint uses it).
#[derive(Debug, Default)]
pub struct Catalogue {
    pub entries: BTreeMap<String, toml::Table>,
    pub source: PathBuf,
}

fn fail(file: &Path, message: String) -> Error {
    Error::flag("--motors", format!("{}: {message}", file.display()))
}

impl Catalogue {
    pub fn load(path: &Path) -> Result<Self, Error> {
        let text = crate::builtin::read_to_string(path).map_err(|e| fail(path, format!("cannot read: {e}")))?;
        Self::parse(&text, path)
    }

    pub fn parse(text: &str, path: &Path) -> Result<Self, Error> {
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| fail(path, e.message().to_string()))?;
        let mut entries = BTreeMap::new();
        for (name, value) in table {
            let Value::Table(t) = value else { return Err(fail(path, format!("motor '{name}': expected a table"))) };
            drive_train_from(path, &name, &t)?; // every entry checked at load
            entries.insert(name, t);
        }
        Ok(Self { entries, source: path.to_path_buf() })
    }

    /// The motor named `name` behind its own gearbox (a gearmotor's; ratio 1 for a bare motor), or
    /// None when the catalogue has no such motor.
    pub fn drive_train(&self, name: &str) -> Option<Result<DriveTrain, Error>> {
        self.entries.get(name).map(|t| drive_train_from(&self.source, name, t))
    }

    /// The motor's mass in kg, if the catalogue gives it.
    pub fn mass(&self, name: &str) -> Option<f64> {
        self.entries.get(name)?.get("mass").and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
    }

    /// The catalogue's motor names, for messages.
    pub fn names(&self) -> String {
        self.entries.keys().cloned().collect::<Vec<_>>().join(", ")
    }
}

/// A catalogue entry as a motor behind its own gearbox; errors name `source`, the motor and the field.
fn drive_train_from(source: &Path, name: &str, t: &toml::Table) -> Result<DriveTrain, Error> {
    let what = format!("motor '{name}'");
    let fields = Fields { file: source, what: &what, table: t };
    let kind = fields.string("kind")?;
    let (gear_ratio, rated) = (fields.optional_positive("gearbox_ratio")?.unwrap_or(1.0), fields.optional_positive("gearbox_rated_torque")?.unwrap_or(f64::INFINITY));
    let gear = fields.gear("gearbox_")?;
    let heat = fields.heat()?;
    let common = [
        "kind",
        "gearbox_ratio",
        "gearbox_efficiency",
        "gearbox_backdrive_efficiency",
        "gearbox_breakaway_torque",
        "gearbox_viscous",
        "gearbox_rated_torque",
        "rotor_inertia",
        "source",
        "torque_constant",
        "terminal_resistance",
        "thermal_resistance_winding_housing",
        "thermal_resistance_housing_ambient",
        "thermal_time_constant_winding",
        "thermal_time_constant_motor",
        "max_winding_temperature",
    ];
    let motor: Box<dyn Motor> = match kind.as_str() {
        "stepper" => {
            fields.known(&[&common[..], &["holding_torque", "step_angle", "inductance", "current", "supply_voltage", "pull_out", "resistance", "mass", "detent_torque"]].concat())?;
            let pull_out = match t.get("pull_out") {
                Some(points) => PullOut::Table(fields.points("pull_out", points)?),
                None => PullOut::Derived { inductance: fields.positive("inductance")?, current: fields.positive("current")?, supply_voltage: fields.positive("supply_voltage")? },
            };
            let holding_torque = fields.positive("holding_torque")?;
            let damping = match (fields.number("resistance")?, fields.number("current")?) {
                (Some(r), Some(i)) if r > 0.0 && i > 0.0 => (holding_torque / i).powi(2) / r,
                _ => 0.0,
            };
            Box::new(Stepper {
                name: name.to_string(),
                holding_torque,
                damping,
                rotor_inertia: fields.non_negative("rotor_inertia")?,
                step_angle_deg: fields.positive("step_angle")?,
                detent_torque: fields.non_negative("detent_torque")?,
                pull_out,
            })
        }
        // a bus servo (its gearbox inside: numbers at the horn) or a bare DC/BLDC motor: both a
        // straight torque–speed line from the stall torque to the no-load speed
        "servo" | "dc" => {
            fields.known(&[&common[..], &["stall_torque", "no_load_speed", "mass", "voltage", "inductance", "continuous_torque"]].concat())?;
            Box::new(DcServo { name: name.to_string(), stall_torque: fields.positive("stall_torque")?, no_load_speed: fields.positive("no_load_speed")?, rotor_inertia: fields.non_negative("rotor_inertia")? })
        }
        other => return Err(fail(source, format!("{what}: field 'kind' is '{other}', expected 'stepper', 'servo' or 'dc'"))),
    };
    let continuous_torque = fields.optional_positive("continuous_torque")?;
    Ok(DriveTrain { motor, gear_ratio, gear, rated_torque: rated, heat, continuous_torque })
}

/// A TOML table's fields, each checked with an error naming the file, the entry and the field.
struct Fields<'a> {
    file: &'a Path,
    what: &'a str,
    table: &'a toml::Table,
}

impl Fields<'_> {
    fn err(&self, field: &str, message: &str) -> Error {
        fail(self.file, format!("{}: field '{field}' {message}", self.what))
    }

    fn number(&self, field: &str) -> Result<Option<f64>, Error> {
        match self.table.get(field) {
            None => Ok(None),
            Some(Value::Float(x)) if x.is_finite() => Ok(Some(*x)),
            Some(Value::Integer(i)) => Ok(Some(*i as f64)),
            Some(_) => Err(self.err(field, "must be a finite number")),
        }
    }

    fn positive(&self, field: &str) -> Result<f64, Error> {
        self.optional_positive(field)?.ok_or_else(|| self.err(field, "is missing"))
    }

    fn optional_positive(&self, field: &str) -> Result<Option<f64>, Error> {
        match self.number(field)? {
            Some(x) if x <= 0.0 => Err(self.err(field, &format!("must be positive (got {x})"))),
            other => Ok(other),
        }
    }

    fn optional_fraction(&self, field: &str) -> Result<Option<f64>, Error> {
        match self.number(field)? {
            Some(x) if !(x > 0.0 && x <= 1.0) => Err(self.err(field, &format!("must be in (0, 1] (got {x})"))),
            other => Ok(other),
        }
    }

    /// A gear's losses from the fields `{prefix}efficiency`, `{prefix}backdrive_efficiency`,
    /// `{prefix}breakaway_torque` and `{prefix}viscous` (a lossless gear where none is given).
    fn gear(&self, prefix: &str) -> Result<LossyGear, Error> {
        let efficiency = self.optional_fraction(&format!("{prefix}efficiency"))?.unwrap_or(1.0);
        let field = format!("{prefix}backdrive_efficiency");
        let backdrive_efficiency = match self.number(&field)? {
            Some(x) if x > 1.0 => return Err(self.err(&field, &format!("must be at most 1 (got {x}; 0 or less: a self-locking drive)"))),
            Some(x) => x,
            None => efficiency,
        };
        Ok(LossyGear { efficiency, backdrive_efficiency, breakaway_torque: self.non_negative(&format!("{prefix}breakaway_torque"))?, viscous: self.non_negative(&format!("{prefix}viscous"))? })
    }

    /// The motor's thermal data: all of torque_constant, terminal_resistance (Ω at 25 °C),
    /// thermal_resistance_winding_housing, thermal_resistance_housing_ambient (K/W),
    /// thermal_time_constant_winding, thermal_time_constant_motor (s) and max_winding_temperature
    /// (°C), or none of them (the motor is then not thermally checked).
    fn heat(&self) -> Result<Option<super::thermal::WindingHeat>, Error> {
        const FIELDS: [&str; 7] = [
            "torque_constant",
            "terminal_resistance",
            "thermal_resistance_winding_housing",
            "thermal_resistance_housing_ambient",
            "thermal_time_constant_winding",
            "thermal_time_constant_motor",
            "max_winding_temperature",
        ];
        let given: Vec<&str> = FIELDS.iter().copied().filter(|f| self.table.contains_key(*f)).collect();
        if given.is_empty() {
            return Ok(None);
        }
        if let Some(missing) = FIELDS.iter().find(|f| !given.contains(f)) {
            return Err(self.err(missing, &format!("is missing: a thermal model needs all of {}", FIELDS.join(", "))));
        }
        let thermal = super::thermal::ThermalData {
            resistance_25: self.positive("terminal_resistance")?,
            winding_to_housing: self.positive("thermal_resistance_winding_housing")?,
            housing_to_ambient: self.positive("thermal_resistance_housing_ambient")?,
            winding_time_constant: self.positive("thermal_time_constant_winding")?,
            motor_time_constant: self.positive("thermal_time_constant_motor")?,
            max_winding_temperature: self.positive("max_winding_temperature")?,
        };
        Ok(Some(super::thermal::WindingHeat { thermal, torque_constant: self.positive("torque_constant")? }))
    }

    fn non_negative(&self, field: &str) -> Result<f64, Error> {
        match self.number(field)? {
            None => Ok(0.0),
            Some(x) if x < 0.0 => Err(self.err(field, &format!("must not be negative (got {x})"))),
            Some(x) => Ok(x),
        }
    }

    fn string(&self, field: &str) -> Result<String, Error> {
        match self.table.get(field) {
            Some(Value::String(s)) => Ok(s.clone()),
            Some(_) => Err(self.err(field, "must be a string")),
            None => Err(self.err(field, "is missing")),
        }
    }

    fn points(&self, field: &str, value: &Value) -> Result<Vec<(f64, f64)>, Error> {
        let bad = || self.err(field, "must be a list of [speed rev/s, torque N·m] pairs with speeds increasing from 0 and torques ≥ 0");
        let list = value.as_array().ok_or_else(bad)?;
        let mut points = Vec::new();
        for p in list {
            let pair = p.as_array().filter(|a| a.len() == 2).ok_or_else(bad)?;
            let num = |v: &Value| v.as_float().or(v.as_integer().map(|i| i as f64)).filter(|x| x.is_finite() && *x >= 0.0).ok_or_else(bad);
            points.push((num(&pair[0])?, num(&pair[1])?));
        }
        if points.is_empty() || points.windows(2).any(|w| w[1].0 <= w[0].0) {
            return Err(bad());
        }
        Ok(points)
    }

    fn known(&self, fields: &[&str]) -> Result<(), Error> {
        match self.table.keys().find(|k| !fields.contains(&k.as_str())) {
            Some(k) => Err(fail(self.file, format!("{}: unknown field '{k}' (known: {})", self.what, fields.join(", ")))),
            None => Ok(()),
        }
    }
}

/// A motor file for `model`: the drive train of each joint it names (the others keep the URDF's
/// constant effort limit).
pub fn load_motor_file(path: &Path, model: &Model) -> Result<MotorSet, Error> {
    let text = crate::builtin::read_to_string(path).map_err(|e| fail(path, format!("cannot read: {e}")))?;
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| fail(path, e.message().to_string()))?;
    if let Some(k) = table.keys().find(|k| !["catalogue", "joints", "motors", "description"].contains(&k.as_str())) {
        return Err(fail(path, format!("unknown key '{k}' (known: catalogue, joints, motors, description)")));
    }
    let mut catalogue = match table.get("catalogue") {
        Some(Value::String(file)) => Catalogue::load(&path.parent().unwrap_or(Path::new(".")).join(file))?,
        Some(_) => return Err(fail(path, "field 'catalogue' must be a file name".into())),
        None => Catalogue::load(Path::new(DEFAULT_CATALOGUE))?,
    };
    // motors defined in the file itself
    if let Some(motors) = table.get("motors") {
        let text = toml::to_string(motors).unwrap_or_default();
        let own = Catalogue::parse(&text, path)?;
        catalogue.entries.extend(own.entries);
    }
    let joints = match table.get("joints") {
        Some(Value::Table(t)) => t,
        _ => return Err(fail(path, "no [joints.NAME] tables".into())),
    };
    let mut set = MotorSet { joints: (0..model.dof()).map(|_| None).collect(), microsteps: vec![None; model.dof()], acceleration: vec![None; model.dof()], source: path.to_path_buf() };
    for (name, value) in joints {
        let what = format!("joint '{name}'");
        let Some(index) = model.joint_index(name) else {
            return Err(fail(path, format!("{what}: {} has no moving joint of that name (joints: {})", model.source.display(), model.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(", "))));
        };
        let Value::Table(t) = value else { return Err(fail(path, format!("{what}: expected a table"))) };
        let fields = Fields { file: path, what: &what, table: t };
        fields.known(&["motor", "gear_ratio", "efficiency", "backdrive_efficiency", "breakaway_torque", "viscous", "rated_torque", "microsteps", "acceleration"])?;
        set.acceleration[index] = fields.optional_positive("acceleration")?;
        let motor_name = fields.string("motor")?;
        let own = catalogue.drive_train(&motor_name).ok_or_else(|| fail(path, format!("{what}: no motor '{motor_name}' (known: {})", catalogue.names())))??;
        let ratio = fields.optional_positive("gear_ratio")?.unwrap_or(1.0);
        let gear = fields.gear("")?;
        let rated = fields.optional_positive("rated_torque")?.unwrap_or(f64::INFINITY);
        if let Some(m) = fields.optional_positive("microsteps")? {
            if m.fract() != 0.0 || m > 1024.0 {
                return Err(fields.err("microsteps", "must be a whole number up to 1024"));
            }
            set.microsteps[index] = Some(m as u32);
        }
        set.joints[index] = Some(own.followed_by(ratio, gear, rated));
    }
    Ok(set)
}
