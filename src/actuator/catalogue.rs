//! Motor catalogues and motor files (TOML).
//!
//! A catalogue (`assets/motors/catalogue.toml`, built in) names real motors and reductions, each a
//! table with a `kind` and a `source` (where its numbers were read; `[NAME.sources]` for a field read
//! elsewhere). A user's catalogue adds to the built-in one and overrides entries of the same name.
//! Motors:
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
//! A servo's entry can carry its firmware, motor and friction as identified (BAM's parameter
//! file's keys, [`super::bus_servo::ServoParams`]), which then drive the joint in the default drive
//! mode (`--drive pd`: the PD controller on the datasheet's line instead):
//!
//! ```toml
//! [XL330-M288.firmware]
//! source = "where the identification was read"
//! family = "xl330"            # the firmware: xl330, xl320, mx64, mx106, sts3215
//! kp = 400                    # its P gain register
//! # supply_voltage = 7.4      # V; the entry's `voltage` when not given
//! model = "m6"                # friction M1–M6 and its keys: kt, R, armature, friction_base, …
//! ```
//!
//! Reductions ([`super::reduction`]): `kind` one of planetary, strain_wave, cycloidal, belt, spur;
//! `ratios = [..]` (a belt: `driver_teeth` and `driven_teeth`); efficiency, backdrive_efficiency,
//! backdriving_torque, rated_torque, repeated_peak_torque, momentary_torque (a number or one per
//! ratio), max_input_speed, input_inertia, backlash (arcmin), mass.
//!
//! A motor file (`--motors FILE.toml`) gives joints a motor and a drive train:
//!
//! ```toml
//! catalogue = "my_motors.toml"   # optional, beside this file; the built-in catalogue otherwise
//! [joints.J1]
//! motor = "17HS4401"
//! # reduction = "NPS015"         # a catalogue reduction, at gear_ratio (one of its ratios), or
//! #                              # stages: reduction = ["GT2-belt", "MG17-G5"], gear_ratio = [2.8, 5]; or:
//! gear_ratio = 15                # the reduction after the motor (and after its own gearbox)
//! efficiency = 0.9               # of that reduction, driving (the joint gets η·N·T)
//! backdrive_efficiency = 0.85    # optional, when the load drives the motor (η when not given; ≤ 0: self-locking)
//! breakaway_torque = 0.1         # optional, N·m at the joint: the reduction's friction at no load
//! viscous = 0.01                 # optional, N·m·s/rad at the joint
//! rated_torque = 9               # N·m at the joint
//! ```
//!
//! A joint whose servo has a firmware model (the catalogue's, or `servo_params = "fit.json"`, a
//! BAM parameter file such as `armscope identify` writes, beside this file) may set its P gain
//! register `kp`, the `supply_voltage`, and a firmware `current_limit` (A: the duty narrowed to
//! keep the current within it, as an XL330's Current Limit(38) in its current-based position mode).
//! A Feetech STS servo's protections are its factory settings unless the joint sets their registers
//! as LeRobot writes them, in the registers' units ([`super::bus_servo::protection`]):
//!
//! ```toml
//! overload_torque = 25              # Overload_Torque, % of full duty: the overload timer starts above it
//! protective_torque = 20            # Protective_Torque, %: the duty left once it trips
//! protection_time = 200             # Protection_Time, 10 ms
//! protection_current = 250          # Protection_Current, 6.5 mA: above it the overcurrent timer runs
//! overcurrent_protection_time = 200 # 10 ms; once it trips the torque is off
//! ```
//!
//! The reduction's losses act as friction at the joint by the direction power flows
//! ([`super::LossyGear`]).

use super::reduction::{KINDS as REDUCTION_KINDS, Reduction};
use super::{DcServo, DriveTrain, LossyGear, Motor, MotorSet, PullOut, Stepper};
use crate::error::Error;
use crate::model::Model;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Value;

pub use crate::builtin::DEFAULT_CATALOGUE;

/// Catalogue entries by name: motors as TOML tables (each made into a motor when a joint uses it),
/// reductions parsed.
#[derive(Debug, Default)]
pub struct Catalogue {
    /// The motors.
    pub entries: BTreeMap<String, toml::Table>,
    pub reductions: BTreeMap<String, Reduction>,
    /// The file (the user's, when it extends the built-in one).
    pub source: PathBuf,
}

/// A motor's thermal model, all or none (the torque constant first: it also serves alone, for the
/// RMS current).
const THERMAL_FIELDS: [&str; 7] = [
    "torque_constant",
    "terminal_resistance",
    "thermal_resistance_winding_housing",
    "thermal_resistance_housing_ambient",
    "thermal_time_constant_winding",
    "thermal_time_constant_motor",
    "max_winding_temperature",
];

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
        let (mut entries, mut reductions) = (BTreeMap::new(), BTreeMap::new());
        for (name, value) in table {
            let Value::Table(t) = value else { return Err(fail(path, format!("entry '{name}': expected a table"))) };
            let kind = Fields { file: path, what: &format!("entry '{name}'"), table: &t }.string("kind")?;
            if REDUCTION_KINDS.contains(&kind.as_str()) {
                reductions.insert(name.clone(), reduction_from(path, &name, &t)?);
            } else {
                drive_train_from(path, &name, &t)?; // every entry checked at load
                entries.insert(name, t);
            }
        }
        for (name, t) in &entries {
            if let Some(of) = t.get("variant_of").and_then(Value::as_str).filter(|of| !entries.contains_key(*of)) {
                return Err(fail(path, format!("motor '{name}': field 'variant_of' names '{of}', which is not in the catalogue")));
            }
        }
        Ok(Self { entries, reductions, source: path.to_path_buf() })
    }

    /// The entry motor `name` is a variant of (the same motor, other identified parameters): sizing
    /// tries a variant only when asked for it by name.
    pub fn variant_of(&self, name: &str) -> Option<&str> {
        self.entries.get(name)?.get("variant_of").and_then(Value::as_str)
    }

    /// The built-in catalogue with a user's file on top (its entries added, or replacing the
    /// built-in ones of the same name).
    pub fn with_user_file(path: &Path) -> Result<Self, Error> {
        let mut out = Self::load(Path::new(DEFAULT_CATALOGUE))?;
        out.extend(Self::load(path)?);
        Ok(out)
    }

    /// Add `other`'s entries, replacing ours of the same name; the source becomes `other`'s.
    pub fn extend(&mut self, other: Catalogue) {
        for name in other.entries.keys().chain(other.reductions.keys()) {
            self.entries.remove(name);
            self.reductions.remove(name);
        }
        self.entries.extend(other.entries);
        self.reductions.extend(other.reductions);
        self.source = other.source;
    }

    pub fn reduction(&self, name: &str) -> Option<&Reduction> {
        self.reductions.get(name)
    }

    /// The catalogue's reduction names, for messages.
    pub fn reduction_names(&self) -> String {
        self.reductions.keys().cloned().collect::<Vec<_>>().join(", ")
    }

    /// A motor's kind ("stepper", "servo", "dc"; "" if unknown).
    pub fn kind(&self, motor: &str) -> &str {
        self.entries.get(motor).and_then(|t| t.get("kind")).and_then(Value::as_str).unwrap_or("")
    }

    /// A stepper's frame ("NEMA17"), if given.
    pub fn frame(&self, motor: &str) -> Option<&str> {
        self.entries.get(motor).and_then(|t| t.get("frame")).and_then(Value::as_str)
    }

    /// Whether reduction `reduction` can follow motor `motor` (see [`Reduction::fits`]).
    pub fn fits(&self, motor: &str, reduction: &str) -> bool {
        self.entries.contains_key(motor) && self.reductions.get(reduction).is_some_and(|r| r.fits(self.kind(motor), self.frame(motor)))
    }

    /// Where the entry's numbers come from (None: the user's own).
    pub fn source_of(&self, name: &str) -> Option<String> {
        match self.entries.get(name) {
            Some(t) => t.get("source").and_then(Value::as_str).map(str::to_string),
            None => self.reductions.get(name)?.source.clone(),
        }
    }

    /// The motor named `name` behind its own gearbox (a gearmotor's; ratio 1 for a bare motor), or
    /// None when the catalogue has no such motor.
    pub fn drive_train(&self, name: &str) -> Option<Result<DriveTrain, Error>> {
        self.entries.get(name).map(|t| drive_train_from(&self.source, name, t))
    }

    /// The identified parameters of the servo named `name` (its `[NAME.firmware]` table), or None
    /// when the catalogue has no such motor or it has no firmware model.
    pub fn servo_params(&self, name: &str) -> Option<Result<super::bus_servo::ServoParams, Error>> {
        let Value::Table(firmware) = self.entries.get(name)?.get("firmware")? else { return None };
        Some(firmware_params(&self.source, name, firmware))
    }

    /// The motors with a firmware model, for messages.
    pub fn servo_names(&self) -> String {
        self.entries.iter().filter(|(_, t)| t.get("firmware").is_some_and(Value::is_table)).map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(", ")
    }

    /// The motor's mass in kg, if the catalogue gives it.
    pub fn mass(&self, name: &str) -> Option<f64> {
        number(self.entries.get(name)?, "mass")
    }

    /// The catalogue's motor names, for messages.
    pub fn names(&self) -> String {
        self.entries.keys().cloned().collect::<Vec<_>>().join(", ")
    }
}

/// An entry's number `field` (a float or an integer), unchecked: None where it has none.
pub(crate) fn number(t: &toml::Table, field: &str) -> Option<f64> {
    t.get(field).and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
}

/// A catalogue entry as a motor behind its own gearbox; errors name `source`, the motor and the field.
fn drive_train_from(source: &Path, name: &str, t: &toml::Table) -> Result<DriveTrain, Error> {
    let what = format!("motor '{name}'");
    let fields = Fields { file: source, what: &what, table: t };
    let kind = fields.string("kind")?;
    let (gear_ratio, rated) = (fields.optional_positive("gearbox_ratio")?.unwrap_or(1.0), fields.optional_positive("gearbox_rated_torque")?.unwrap_or(f64::INFINITY));
    let gear = fields.gear("gearbox_")?;
    let heat = fields.heat()?;
    let mut servo = None;
    let common = [&["kind", "gearbox_ratio", "gearbox_efficiency", "gearbox_backdrive_efficiency", "gearbox_breakaway_torque", "gearbox_viscous", "gearbox_rated_torque", "rotor_inertia", "source", "sources", "length"][..], &THERMAL_FIELDS[..]].concat();
    fields.sources()?;
    let motor: Box<dyn Motor> = match kind.as_str() {
        "stepper" => {
            fields.known(&[&common[..], &["holding_torque", "step_angle", "inductance", "current", "supply_voltage", "pull_out", "resistance", "mass", "detent_torque", "frame"]].concat())?;
            if t.get("frame").is_some_and(|f| !f.is_str()) {
                return Err(fields.err("frame", "must be a flange name, e.g. \"NEMA17\""));
            }
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
        // straight torque–speed line from the stall torque to the no-load speed; a servo's firmware
        // model where identified
        "servo" | "dc" => {
            fields.known(&[&common[..], &["stall_torque", "no_load_speed", "mass", "voltage", "inductance", "continuous_torque", "firmware", "variant_of"]].concat())?;
            if t.get("variant_of").is_some_and(|v| !v.is_str()) {
                return Err(fields.err("variant_of", "must be the name of the catalogue entry this one is a variant of"));
            }
            let line = match (t.contains_key("stall_torque") || !t.contains_key("firmware"), kind.as_str()) {
                (true, _) | (_, "dc") => Some(DcServo { name: name.to_string(), stall_torque: fields.positive("stall_torque")?, no_load_speed: fields.positive("no_load_speed")?, rotor_inertia: fields.non_negative("rotor_inertia")? }),
                _ => None,
            };
            servo = match t.get("firmware") {
                None => None,
                Some(Value::Table(firmware)) if kind == "servo" => Some(firmware_from(source, name, firmware, fields.number("voltage")?, line.as_ref())?),
                Some(_) => return Err(fields.err("firmware", "must be a table of the servo's identified parameters ([NAME.firmware])")),
            };
            match (line, &servo) {
                (Some(line), _) => Box::new(line),
                (None, Some(servo)) => Box::new(servo.clone()),
                (None, None) => return Err(fields.err("stall_torque", "is missing")),
            }
        }
        other => return Err(fail(source, format!("{what}: field 'kind' is '{other}', expected a motor ('stepper', 'servo', 'dc') or a reduction ({})", REDUCTION_KINDS.join(", ")))),
    };
    let continuous_torque = fields.optional_positive("continuous_torque")?;
    let mut drive = DriveTrain::with_gear(motor, gear_ratio, gear, rated);
    drive.servo = servo;
    drive.heat = heat;
    drive.continuous_torque = continuous_torque;
    if let Some(mass) = fields.optional_positive("mass")? {
        // a NEMA frame's number is its flange width in tenths of an inch
        let diameter = t.get("frame").and_then(Value::as_str).and_then(|f| f.strip_prefix("NEMA")).and_then(|n| n.parse::<f64>().ok()).map(|n| n * 0.1 * 0.0254);
        let cylinder = diameter.zip(fields.optional_positive("length")?);
        drive.parts.push(super::Part { name: name.to_string(), mass, cylinder });
    }
    Ok(drive)
}

/// A motor file joint's servo settings: `servo_params` (a BAM parameter file, beside the motor
/// file) replaces the catalogue's firmware model, `kp` and `supply_voltage` set its P gain register
/// and supply.
fn servo_settings(fields: &Fields, path: &Path, motor: &str, drive: &mut DriveTrain) -> Result<(), Error> {
    if let Some(value) = fields.table.get("servo_params") {
        let Value::String(file) = value else { return Err(fields.err("servo_params", "must be the name of a BAM parameter file (JSON)")) };
        let params_path = path.parent().unwrap_or(Path::new(".")).join(file);
        let mut notices = Vec::new();
        let params = super::bus_servo::ServoParams::load(&params_path, &mut notices).map_err(|m| fail(path, format!("{}: field 'servo_params': {m}", fields.what)))?;
        for n in notices {
            eprintln!("armscope: notice: {n}");
        }
        // the catalogue's datasheet line stays the envelope, and its supply the supply
        let (envelope, supply, kp) = match &drive.servo {
            Some(s) => (s.envelope, s.supply, s.firmware.kp),
            None => (None, params.family.nominal_supply, params.family.default_kp),
        };
        let mut servo = super::BusServo::from_params(motor, &params, kp, supply);
        servo.envelope = envelope;
        drive.servo = Some(servo);
    }
    for key in ["kp", "supply_voltage", "current_limit"] {
        let Some(x) = fields.optional_positive(key)? else { continue };
        let Some(servo) = drive.servo.as_mut() else {
            return Err(fields.err(key, &format!("sets a servo's firmware, but motor '{motor}' has no firmware model (give servo_params = \"P.json\", a BAM parameter file)")));
        };
        match key {
            "kp" => servo.firmware.kp = x,
            "supply_voltage" => servo.supply = x,
            _ => servo.firmware.current_limit = Some(x),
        }
    }
    protection_registers(fields, motor, drive)
}

/// A Feetech's protection registers, by their names and in their units
/// ([`super::bus_servo::protection`]): the largest value each register takes.
const PROTECTION_REGISTERS: [(&str, f64); 5] = [("overload_torque", 100.0), ("protective_torque", 100.0), ("protection_time", 254.0), ("protection_current", 511.0), ("overcurrent_protection_time", 254.0)];

/// A motor file joint's Feetech protection registers, set as LeRobot writes them (`Overload_Torque`,
/// `Protection_Current`, …): overload and protective torque in %, times in 10 ms, the current in
/// 6.5 mA.
fn protection_registers(fields: &Fields, motor: &str, drive: &mut DriveTrain) -> Result<(), Error> {
    use super::bus_servo::protection::{CURRENT_UNIT, PERCENT, TIME_UNIT};
    for (key, largest) in PROTECTION_REGISTERS {
        let Some(x) = fields.number(key)? else { continue };
        if !(0.0..=largest).contains(&x) || x.fract() != 0.0 {
            return Err(fields.err(key, &format!("must be a whole register value from 0 to {largest} (got {x})")));
        }
        let protection = drive.servo.as_mut().map(|s| &mut s.firmware.protection);
        let Some(p) = protection.filter(|p| !p.is_none()) else {
            return Err(fields.err(key, &format!("sets a Feetech protection register, but motor '{motor}' has no firmware model with protections (a Feetech STS servo's)")));
        };
        match (key, p.overload.as_mut(), p.overcurrent.as_mut()) {
            ("overload_torque", Some(o), _) => o.threshold = x * PERCENT,
            ("protective_torque", Some(o), _) => o.protective = x * PERCENT,
            ("protection_time", Some(o), _) => o.time = x * TIME_UNIT,
            ("protection_current", _, Some(o)) => o.current = x * CURRENT_UNIT,
            ("overcurrent_protection_time", _, Some(o)) => o.time = x * TIME_UNIT,
            _ => return Err(fields.err(key, &format!("sets a protection motor '{motor}' does not have"))),
        }
    }
    Ok(())
}

/// A servo entry's `firmware` table as a servo model; `voltage` is the entry's rated supply, `line`
/// its datasheet torque–speed line (the model's envelope) where given.
fn firmware_from(source: &Path, name: &str, table: &toml::Table, voltage: Option<f64>, line: Option<&DcServo>) -> Result<super::BusServo, Error> {
    let what = format!("motor '{name}'");
    let fields = Fields { file: source, what: &what, table };
    let params = firmware_params(source, name, table)?;
    let kp = fields.optional_positive("kp")?.unwrap_or(params.family.default_kp);
    let supply = match (fields.optional_positive("supply_voltage")?, voltage) {
        (Some(v), _) | (None, Some(v)) => v,
        (None, None) => params.family.nominal_supply,
    };
    let mut servo = super::BusServo::from_params(name, &params, kp, supply);
    servo.envelope = line.map(|l| (l.stall_torque, l.no_load_speed));
    Ok(servo)
}

/// A servo entry's `firmware` table as the identified parameters (BAM's keys).
fn firmware_params(source: &Path, name: &str, table: &toml::Table) -> Result<super::bus_servo::ServoParams, Error> {
    let what = format!("motor '{name}'");
    let fields = Fields { file: source, what: &what, table };
    let family = fields.string("family").map_err(|_| fields.err("firmware.family", "is missing: the servo's firmware (xl330, xl320, mx64, mx106, sts3215)"))?;
    let mut json = serde_json::Map::new();
    for (key, value) in table {
        match key.as_str() {
            "family" | "kp" | "supply_voltage" | "source" | "sources" => {}
            _ => {
                let v = match value {
                    Value::Float(x) => serde_json::json!(x),
                    Value::Integer(i) => serde_json::json!(*i as f64),
                    Value::String(s) => serde_json::json!(s),
                    _ => return Err(fields.err(&format!("firmware.{key}"), "must be a number (or the friction model's name)")),
                };
                json.insert(key.clone(), v);
            }
        }
    }
    json.insert("actuator".into(), serde_json::json!(family));
    let mut notices = Vec::new();
    let params = super::bus_servo::ServoParams::from_json(&serde_json::Value::Object(json).to_string(), Path::new(&format!("{}: {what}: firmware", source.display())), &mut notices).map_err(|m| Error::flag("--motors", m))?;
    if let Some(n) = notices.first() {
        return Err(Error::flag("--motors", n.replace(": ignored", ": unknown here")));
    }
    if !table.get("source").and_then(Value::as_str).is_some_and(|s| !s.trim().is_empty()) {
        return Err(fields.err("firmware.source", "is missing: where the identified parameters were read"));
    }
    Ok(params)
}

/// A catalogue reduction; errors name `source`, the entry and the field.
fn reduction_from(source: &Path, name: &str, t: &toml::Table) -> Result<Reduction, Error> {
    let what = format!("reduction '{name}'");
    let fields = Fields { file: source, what: &what, table: t };
    fields.known(&[
        "kind", "source", "sources", "ratios", "driver_teeth", "driven_teeth", "efficiency", "backdrive_efficiency", "backdriving_torque", "rated_torque", "repeated_peak_torque", "momentary_torque", "max_input_speed", "input_inertia", "backlash", "mass", "fits",
    ])?;
    fields.sources()?;
    let ratios = match (t.get("ratios"), t.get("driver_teeth"), t.get("driven_teeth")) {
        (Some(_), None, None) => {
            let ratios = fields.list("ratios")?;
            if ratios.iter().any(|&r| r < 1.0) {
                return Err(fields.err("ratios", "must all be at least 1 (a reduction)"));
            }
            ratios
        }
        (None, Some(_), Some(_)) => {
            let (driver, driven) = (fields.list("driver_teeth")?, fields.list("driven_teeth")?);
            // every pulley pair that reduces, each ratio once
            let mut ratios: Vec<f64> = driver.iter().flat_map(|a| driven.iter().map(move |b| b / a)).filter(|&r| r > 1.0).collect();
            ratios.sort_by(f64::total_cmp);
            ratios.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * *b);
            if ratios.is_empty() {
                return Err(fields.err("driven_teeth", "gives no ratio above 1 with driver_teeth"));
            }
            ratios
        }
        _ => return Err(fail(source, format!("{what}: give either 'ratios' or both 'driver_teeth' and 'driven_teeth'"))),
    };
    let mut sorted = ratios.clone();
    sorted.sort_by(f64::total_cmp);
    if sorted != ratios {
        return Err(fields.err("ratios", "must increase"));
    }
    let per_ratio = |field: &str| -> Result<Option<Vec<f64>>, Error> {
        match t.get(field) {
            None => Ok(None),
            Some(Value::Array(_)) => {
                let list = fields.list(field)?;
                if list.len() != ratios.len() {
                    return Err(fields.err(field, &format!("has {} values for {} ratios (one number, or one per ratio)", list.len(), ratios.len())));
                }
                Ok(Some(list))
            }
            Some(_) => Ok(Some(vec![fields.positive(field)?; ratios.len()])),
        }
    };
    let backdrive_efficiency = match fields.number("backdrive_efficiency")? {
        Some(x) if x > 1.0 => return Err(fields.err("backdrive_efficiency", &format!("must be at most 1 (got {x}; 0 or less: a self-locking drive)"))),
        other => other,
    };
    Ok(Reduction {
        name: name.to_string(),
        kind: fields.string("kind")?,
        efficiency: fields.optional_fraction("efficiency")?,
        backdrive_efficiency,
        backdriving_torque: fields.non_negative("backdriving_torque")?,
        rated_torque: per_ratio("rated_torque")?,
        repeated_peak_torque: per_ratio("repeated_peak_torque")?,
        momentary_torque: per_ratio("momentary_torque")?,
        max_input_speed: fields.optional_positive("max_input_speed")?,
        input_inertia: per_ratio("input_inertia")?,
        backlash: fields.optional_positive("backlash")?,
        mass: fields.optional_positive("mass")?,
        fits: match t.get("fits") {
            None => None,
            Some(Value::Array(a)) if !a.is_empty() && a.iter().all(Value::is_str) => Some(a.iter().filter_map(Value::as_str).map(str::to_string).collect()),
            Some(_) => return Err(fields.err("fits", "must be a list of motor flanges, e.g. [\"NEMA17\"]")),
        },
        source: t.get("source").and_then(Value::as_str).map(str::to_string),
        ratios,
    })
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

    /// The motor's thermal data: all of torque_constant (a stepper: its driver's `current`
    /// instead), terminal_resistance (Ω at 25 °C, per phase for a stepper),
    /// thermal_resistance_winding_housing, thermal_resistance_housing_ambient (K/W),
    /// thermal_time_constant_winding, thermal_time_constant_motor (s) and max_winding_temperature
    /// (°C), or none of them (the motor is then not thermally checked).
    fn heat(&self) -> Result<Option<super::thermal::WindingHeat>, Error> {
        let given: Vec<&str> = THERMAL_FIELDS.iter().copied().filter(|f| self.table.contains_key(*f)).collect();
        // the torque constant alone is no thermal model (it also serves the RMS current)
        if given.iter().all(|f| *f == "torque_constant") {
            return Ok(None);
        }
        // an open-loop stepper's current is its driver's setting (`current`), not its torque's
        let stepper = self.table.get("kind").and_then(Value::as_str) == Some("stepper");
        let needed: Vec<&str> = if stepper { THERMAL_FIELDS[1..].iter().copied().chain(["current"]).collect() } else { THERMAL_FIELDS.to_vec() };
        if let Some(missing) = needed.iter().find(|f| !self.table.contains_key(**f)) {
            return Err(self.err(missing, &format!("is missing: a thermal model needs all of {}", needed.join(", "))));
        }
        let thermal = super::thermal::ThermalData {
            resistance_25: self.positive("terminal_resistance")?,
            winding_to_housing: self.positive("thermal_resistance_winding_housing")?,
            housing_to_ambient: self.positive("thermal_resistance_housing_ambient")?,
            winding_time_constant: self.positive("thermal_time_constant_winding")?,
            motor_time_constant: self.positive("thermal_time_constant_motor")?,
            max_winding_temperature: self.positive("max_winding_temperature")?,
        };
        if stepper {
            // K_t only for the RMS torque's current where given; the losses follow the set current
            let torque_constant = self.optional_positive("torque_constant")?.unwrap_or(f64::INFINITY);
            return Ok(Some(super::thermal::WindingHeat { thermal, torque_constant, set_current: Some(self.positive("current")?) }));
        }
        Ok(Some(super::thermal::WindingHeat { thermal, torque_constant: self.positive("torque_constant")?, set_current: None }))
    }

    /// Where a joint's parts sit: `in_urdf = true` (or the file's), else `mount_link` with
    /// `mount_xyz` (m, in that link's frame; its origin when not given), else at the joint.
    fn mount(&self, file_in_urdf: bool) -> Result<super::Mount, Error> {
        let in_urdf = match self.table.get("in_urdf") {
            None => file_in_urdf,
            Some(Value::Boolean(b)) => *b,
            Some(_) => return Err(self.err("in_urdf", "must be true or false")),
        };
        let link = match self.table.get("mount_link") {
            None => None,
            Some(Value::String(s)) => Some(s.clone()),
            Some(_) => return Err(self.err("mount_link", "must be a link name")),
        };
        let offset = match self.table.get("mount_xyz") {
            None => [0.0; 3],
            Some(Value::Array(a)) if a.len() == 3 => {
                let mut xyz = [0.0; 3];
                for (x, v) in xyz.iter_mut().zip(a) {
                    *x = v.as_float().or(v.as_integer().map(|i| i as f64)).filter(|x| x.is_finite()).ok_or_else(|| self.err("mount_xyz", "must be [x, y, z] in metres"))?;
                }
                xyz
            }
            Some(_) => return Err(self.err("mount_xyz", "must be [x, y, z] in metres")),
        };
        if in_urdf && (link.is_some() || self.table.contains_key("mount_xyz")) {
            return Err(self.err("in_urdf", "and a mount: a drive train already in the URDF's masses is mounted nowhere else"));
        }
        Ok(match (in_urdf, link) {
            (true, _) => super::Mount::InUrdf,
            (false, Some(link)) => super::Mount::OnLink { link, offset },
            (false, None) if self.table.contains_key("mount_xyz") => return Err(self.err("mount_xyz", "needs mount_link: the link the offset is in")),
            (false, None) => super::Mount::AtJoint,
        })
    }

    /// A non-empty list of positive numbers.
    fn list(&self, field: &str) -> Result<Vec<f64>, Error> {
        let bad = || self.err(field, "must be a non-empty list of positive numbers");
        let list = self.table.get(field).and_then(Value::as_array).filter(|a| !a.is_empty()).ok_or_else(bad)?;
        list.iter().map(|v| v.as_float().or(v.as_integer().map(|i| i as f64)).filter(|x| x.is_finite() && *x > 0.0).ok_or_else(bad)).collect()
    }

    /// `source` a string and `sources` a table of strings naming fields of the entry.
    fn sources(&self) -> Result<(), Error> {
        if let Some(v) = self.table.get("source") {
            if !v.as_str().is_some_and(|s| !s.trim().is_empty()) {
                return Err(self.err("source", "must be a non-empty string: where the numbers were read"));
            }
        }
        match self.table.get("sources") {
            None => Ok(()),
            Some(Value::Table(t)) => {
                for (field, v) in t {
                    if !self.table.contains_key(field) || field == "sources" || field == "source" {
                        return Err(self.err(&format!("sources.{field}"), "names no field of this entry"));
                    }
                    if !v.as_str().is_some_and(|s| !s.trim().is_empty()) {
                        return Err(self.err(&format!("sources.{field}"), "must be a non-empty string"));
                    }
                }
                Ok(())
            }
            Some(_) => Err(self.err("sources", "must be a table: field = \"where it was read\"")),
        }
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

/// A motor file's `[floor]`: `height` (world z, m) under the origin of `link` (the model's tool
/// frame if left out).
fn floor_contact(t: &toml::Table, path: &Path, model: &Model) -> Result<crate::plant::FloorContact, Error> {
    let fields = Fields { file: path, what: "[floor]", table: t };
    fields.known(&["height", "link"])?;
    let height = match t.get("height") {
        Some(Value::Float(z)) if z.is_finite() => *z,
        Some(Value::Integer(z)) => *z as f64,
        _ => return Err(fields.err("height", "must be a height in m (world z)")),
    };
    let frame = match t.get("link") {
        None => model.tool_frame,
        Some(Value::String(link)) => model.frame_index(link).ok_or_else(|| fields.err("link", &format!("'{link}' is no link of {}", model.source.display())))?,
        Some(_) => return Err(fields.err("link", "must be a link's name")),
    };
    Ok(crate::plant::FloorContact { frame, height })
}

/// The catalogue the motor file (`table`, read from `path`) draws on: the built-in one or its own
/// `catalogue` file on top of it, and the motors the file defines itself.
fn catalogue_of(path: &Path, table: &toml::Table) -> Result<Catalogue, Error> {
    let mut catalogue = match table.get("catalogue") {
        Some(Value::String(file)) => Catalogue::with_user_file(&path.parent().unwrap_or(Path::new(".")).join(file))?,
        Some(_) => return Err(fail(path, "field 'catalogue' must be a file name".into())),
        None => Catalogue::load(Path::new(DEFAULT_CATALOGUE))?,
    };
    // motors defined in the file itself
    if let Some(motors) = table.get("motors") {
        let text = toml::to_string(motors).unwrap_or_default();
        let own = Catalogue::parse(&text, path)?;
        catalogue.extend(own);
    }
    Ok(catalogue)
}

/// The catalogue the motor file at `path` draws on (see [`load_motor_file`]).
pub fn motor_file_catalogue(path: &Path) -> Result<Catalogue, Error> {
    let text = crate::builtin::read_to_string(path).map_err(|e| fail(path, format!("cannot read: {e}")))?;
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| fail(path, e.message().to_string()))?;
    catalogue_of(path, &table)
}

/// A motor file for `model`: the drive train of each joint it names (the others keep the URDF's
/// constant effort limit).
pub fn load_motor_file(path: &Path, model: &Model) -> Result<MotorSet, Error> {
    let text = crate::builtin::read_to_string(path).map_err(|e| fail(path, format!("cannot read: {e}")))?;
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| fail(path, e.message().to_string()))?;
    if let Some(k) = table.keys().find(|k| !["catalogue", "joints", "motors", "description", "in_urdf", "floor"].contains(&k.as_str())) {
        return Err(fail(path, format!("unknown key '{k}' (known: catalogue, joints, motors, description, in_urdf, floor)")));
    }
    let all_in_urdf = match table.get("in_urdf") {
        None => false,
        Some(Value::Boolean(b)) => *b,
        Some(_) => return Err(fail(path, "field 'in_urdf' must be true or false".into())),
    };
    let catalogue = catalogue_of(path, &table)?;
    let joints = match table.get("joints") {
        Some(Value::Table(t)) => t,
        _ => return Err(fail(path, "no [joints.NAME] tables".into())),
    };
    let mut set = MotorSet::empty(model.dof(), path);
    set.floor = match table.get("floor") {
        Some(Value::Table(t)) => Some(floor_contact(t, path, model)?),
        Some(_) => return Err(fail(path, "[floor] must be a table: height = z in m, link = the link resting on it".into())),
        None => None,
    };
    for (name, value) in joints {
        let what = format!("joint '{name}'");
        let Some(index) = model.joint_index(name) else {
            return Err(fail(path, format!("{what}: {} has no moving joint of that name (joints: {})", model.source.display(), model.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(", "))));
        };
        let Value::Table(t) = value else { return Err(fail(path, format!("{what}: expected a table"))) };
        let fields = Fields { file: path, what: &what, table: t };
        fields.known(&["motor", "reduction", "gear_ratio", "efficiency", "backdrive_efficiency", "breakaway_torque", "viscous", "rated_torque", "microsteps", "acceleration", "in_urdf", "mount_link", "mount_xyz", "servo_params", "kp", "supply_voltage", "current_limit", "overload_torque", "protective_torque", "protection_time", "protection_current", "overcurrent_protection_time"])?;
        set.acceleration[index] = fields.optional_positive("acceleration")?;
        set.mounts[index] = fields.mount(all_in_urdf)?;
        if let Some(m) = fields.optional_positive("microsteps")? {
            if m.fract() != 0.0 || m > 1024.0 {
                return Err(fields.err("microsteps", "must be a whole number up to 1024"));
            }
            set.microsteps[index] = Some(m as u32);
        }
        let motor_name = fields.string("motor")?;
        let mut own = catalogue.drive_train(&motor_name).ok_or_else(|| fail(path, format!("{what}: no motor '{motor_name}' (known: {})", catalogue.names())))??;
        servo_settings(&fields, path, &motor_name, &mut own)?;
        if let Some(value) = t.get("reduction") {
            // catalogue reductions, one or a list of stages from the motor out: their own losses and
            // ratings, each at one of its ratios
            let names: Vec<String> = match value {
                Value::String(name) => vec![name.clone()],
                Value::Array(list) if !list.is_empty() && list.iter().all(Value::is_str) => list.iter().filter_map(Value::as_str).map(str::to_string).collect(),
                _ => return Err(fields.err("reduction", "must be the name of a catalogue reduction, or a list of them (stages from the motor out)")),
            };
            if let Some(k) = ["efficiency", "backdrive_efficiency", "breakaway_torque", "viscous", "rated_torque"].iter().find(|k| t.contains_key(**k)) {
                return Err(fields.err(k, &format!("comes from the catalogue's reduction '{}': leave it out, or give the reduction's numbers without 'reduction'", names.join("', '"))));
            }
            let ratios: Vec<Option<f64>> = match t.get("gear_ratio") {
                None => vec![None; names.len()],
                Some(Value::Array(list)) if list.len() == names.len() => list.iter().map(|v| v.as_float().or(v.as_integer().map(|i| i as f64)).filter(|x| *x > 0.0).map(Some).ok_or_else(|| fields.err("gear_ratio", "must be positive numbers"))).collect::<Result<_, _>>()?,
                Some(_) if names.len() == 1 => vec![Some(fields.positive("gear_ratio")?)],
                Some(_) => return Err(fields.err("gear_ratio", &format!("must list one ratio per reduction ({})", names.len()))),
            };
            let mut drive = own;
            for (reduction, ratio) in names.iter().zip(ratios) {
                let r = catalogue.reduction(reduction).ok_or_else(|| fields.err("reduction", &format!("names no catalogue reduction '{reduction}' (known: {})", catalogue.reduction_names())))?;
                let list = r.ratios.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(", ");
                let ratio = match ratio {
                    Some(x) => x,
                    None if r.ratios.len() == 1 => r.ratios[0],
                    None => return Err(fields.err("gear_ratio", &format!("is missing: '{reduction}' comes in {list}"))),
                };
                if r.efficiency.is_none() {
                    eprintln!("armscope: notice: {}: {what}: reduction '{reduction}' publishes no efficiency: simulated lossless", path.display());
                }
                drive = drive.then_reduction(r, ratio).ok_or_else(|| fields.err("gear_ratio", &format!("{ratio} is not a ratio of '{reduction}' ({list})")))?;
            }
            set.joints[index] = Some(drive);
            continue;
        }
        let ratio = fields.optional_positive("gear_ratio")?.unwrap_or(1.0);
        let gear = fields.gear("")?;
        let rated = fields.optional_positive("rated_torque")?.unwrap_or(f64::INFINITY);
        set.joints[index] = Some(own.followed_by(ratio, gear, rated));
    }
    Ok(set)
}
