//! A servo's identified parameters in BAM's JSON (Rhoban/bam `bam/params/*/mK.json`), read as
//! published and written back the same way: `kt`, `R`, `armature`, `q_offset`, the friction
//! model's keys ([`FrictionModel::keys`]), `model`, `actuator`, and for a Feetech
//! `error_gain_ratio` and `max_velocity`. What armscope adds (the supply's resistance) is written
//! under keys BAM ignores.

use super::firmware::{Family, family, family_names};
use super::friction::{FrictionModel, ServoFriction};
use serde_json::{Map, Value};
use std::path::Path;

/// What identification finds about one servo (at its output shaft).
#[derive(Clone, Debug, PartialEq)]
pub struct ServoParams {
    pub family: Family,
    /// k_t, N·m/A (= the back-EMF constant, V·s/rad), at the output.
    pub kt: f64,
    /// R, Ω: the motor and its driver.
    pub resistance: f64,
    /// I_a, kg·m²: the rotor's inertia reflected at the output.
    pub armature: f64,
    /// The bench's angle offset (gravity only): a property of the bench, not the servo.
    pub q_offset: f64,
    pub friction: ServoFriction,
    /// The identified correction of the family's error gain (Feetech; 1 elsewhere).
    pub error_gain_ratio: f64,
    /// The goal speed bound, rad/s (Feetech; the family's default when not identified).
    pub max_velocity: f64,
    /// The resistance on the bridge's supply side, Ω (armscope's; 0: an ideal supply, as BAM
    /// assumes).
    pub supply_resistance: f64,
    /// The largest voltage the servo puts across its motor, V (armscope's; infinite: the duty
    /// times the supply, as BAM assumes).
    pub motor_voltage_limit: f64,
    /// How long after a goal is sent the firmware acts on it, s (armscope's; 0 as BAM assumes):
    /// the bus's transfer, the firmware's read of its goal register and its control period.
    pub command_delay: f64,
}

/// The keys armscope writes beyond BAM's.
pub const SUPPLY_RESISTANCE_KEY: &str = "supply_resistance";
pub const MOTOR_VOLTAGE_LIMIT_KEY: &str = "motor_voltage_limit";
pub const COMMAND_DELAY_KEY: &str = "command_delay";
/// The longest command delay a parameter file may give, s: a servo that answers a second late is
/// not a servo's loop.
pub const COMMAND_DELAY_MAX: f64 = 1.0;

impl ServoParams {
    /// Parse BAM's JSON; errors name the file and the field. `notices` gets one line per key that
    /// is read and ignored.
    pub fn from_json(text: &str, path: &Path, notices: &mut Vec<String>) -> Result<Self, String> {
        let file = path.display();
        let value: Value = serde_json::from_str(text).map_err(|e| format!("{file}: not JSON: {e}"))?;
        let Value::Object(map) = value else { return Err(format!("{file}: expected a JSON object of parameters")) };
        let string = |key: &str| -> Result<&str, String> {
            match map.get(key) {
                Some(Value::String(s)) => Ok(s),
                Some(_) => Err(format!("{file}: field '{key}' must be a string")),
                None => Err(format!("{file}: field '{key}' is missing")),
            }
        };
        let actuator = string("actuator")?;
        let family = family(actuator).ok_or_else(|| format!("{file}: field 'actuator' is '{actuator}', not a servo armscope knows ({})", family_names()))?;
        if super::firmware::is_alias(actuator) {
            notices.push(format!("{file}: actuator '{actuator}' read as 'sts3215' (the 12 V STS3215: the same firmware; BAM's own code knows no such name)"));
        }
        let model_name = string("model")?;
        let model = FrictionModel::from_name(model_name).ok_or_else(|| format!("{file}: field 'model' is '{model_name}', expected m1 … m6"))?;
        let number = |key: &str| -> Result<Option<f64>, String> {
            match map.get(key) {
                None => Ok(None),
                Some(Value::Number(n)) => n.as_f64().filter(|x| x.is_finite()).map(Some).ok_or_else(|| format!("{file}: field '{key}' must be a finite number")),
                Some(_) => Err(format!("{file}: field '{key}' must be a number")),
            }
        };
        let required = |key: &str| number(key)?.ok_or_else(|| format!("{file}: field '{key}' is missing (a {} file of {} needs it)", model.name(), family.name));
        let positive = |key: &str| {
            let x = required(key)?;
            if x > 0.0 { Ok(x) } else { Err(format!("{file}: field '{key}' must be positive (got {x})")) }
        };
        let mut friction = ServoFriction { model, ..Default::default() };
        for key in model.keys() {
            let x = required(key)?;
            if x < 0.0 {
                return Err(format!("{file}: field '{key}' must not be negative (got {x})"));
            }
            friction.set(key, x);
        }
        if model.stribeck() && friction.stribeck_speed <= 0.0 {
            return Err(format!("{file}: field 'dtheta_stribeck' must be positive"));
        }
        let params = ServoParams {
            family,
            kt: positive("kt")?,
            resistance: positive("R")?,
            armature: {
                let x = required("armature")?;
                if x < 0.0 {
                    return Err(format!("{file}: field 'armature' must not be negative (got {x})"));
                }
                x
            },
            q_offset: number("q_offset")?.unwrap_or(0.0),
            friction,
            error_gain_ratio: match number("error_gain_ratio")? {
                Some(x) if x <= 0.0 => return Err(format!("{file}: field 'error_gain_ratio' must be positive (got {x})")),
                Some(x) => x,
                None => 1.0,
            },
            max_velocity: match number("max_velocity")? {
                Some(x) if x <= 0.0 => return Err(format!("{file}: field 'max_velocity' must be positive (got {x})")),
                Some(x) => x,
                None => family.default_max_velocity,
            },
            supply_resistance: match number(SUPPLY_RESISTANCE_KEY)? {
                Some(x) if x < 0.0 => return Err(format!("{file}: field '{SUPPLY_RESISTANCE_KEY}' must not be negative (got {x})")),
                Some(x) => x,
                None => 0.0,
            },
            motor_voltage_limit: match number(MOTOR_VOLTAGE_LIMIT_KEY)? {
                Some(x) if x <= 0.0 => return Err(format!("{file}: field '{MOTOR_VOLTAGE_LIMIT_KEY}' must be positive (got {x})")),
                Some(x) => x,
                None => f64::INFINITY,
            },
            command_delay: match number(COMMAND_DELAY_KEY)? {
                Some(x) if !(0.0..=COMMAND_DELAY_MAX).contains(&x) => return Err(format!("{file}: field '{COMMAND_DELAY_KEY}' must be between 0 and {COMMAND_DELAY_MAX} s (got {x})")),
                Some(x) => x,
                None => 0.0,
            },
        };
        let known: Vec<&str> = ["kt", "R", "armature", "q_offset", "model", "actuator", "error_gain_ratio", "max_velocity", SUPPLY_RESISTANCE_KEY, MOTOR_VOLTAGE_LIMIT_KEY, COMMAND_DELAY_KEY].into_iter().chain(model.keys()).collect();
        for key in map.keys().filter(|k| !known.contains(&k.as_str())) {
            // another model's keys, or a later BAM's: not part of this model
            notices.push(format!("{file}: field '{key}' is not a parameter of a {} {} model: ignored", family.name, model.name()));
        }
        Ok(params)
    }

    /// Read a parameter file.
    pub fn load(path: &Path, notices: &mut Vec<String>) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
        Self::from_json(&text, path, notices)
    }

    /// BAM's JSON, keys in BAM's order, plus armscope's where they differ from BAM's assumption.
    pub fn to_json(&self) -> Value {
        let mut map = Map::new();
        let mut put = |key: &str, x: f64| {
            map.insert(key.to_string(), serde_json::json!(x));
        };
        put("kt", self.kt);
        if self.family.goal_speed_limiter {
            put("error_gain_ratio", self.error_gain_ratio);
        }
        put("R", self.resistance);
        put("armature", self.armature);
        put("q_offset", self.q_offset);
        if self.family.goal_speed_limiter {
            put("max_velocity", self.max_velocity);
        }
        for key in self.friction.model.keys() {
            put(key, self.friction.get(key).unwrap_or(0.0));
        }
        if self.supply_resistance > 0.0 {
            put(SUPPLY_RESISTANCE_KEY, self.supply_resistance);
        }
        if self.motor_voltage_limit.is_finite() {
            put(MOTOR_VOLTAGE_LIMIT_KEY, self.motor_voltage_limit);
        }
        if self.command_delay > 0.0 {
            put(COMMAND_DELAY_KEY, self.command_delay);
        }
        map.insert("model".into(), Value::String(self.friction.model.name().into()));
        map.insert("actuator".into(), Value::String(self.family.name.into()));
        Value::Object(map)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const M6: &str = r#"{"kt": 0.366, "R": 2.81, "armature": 0.0018, "q_offset": 0.027, "friction_base": 0.0048,
        "friction_stribeck": 0.0047, "load_friction_motor": 0.267, "load_friction_external": 8.5e-06,
        "load_friction_motor_stribeck": 1.07e-05, "load_friction_external_stribeck": 0.0808,
        "load_friction_motor_quad": 0.00997, "load_friction_external_quad": 0.0049, "dtheta_stribeck": 2.89,
        "alpha": 8.68, "friction_viscous": 0.00536, "model": "m6", "actuator": "xl330"}"#;

    #[test]
    fn reads_and_writes_bam_files() {
        let mut notices = Vec::new();
        let p = ServoParams::from_json(M6, Path::new("m6.json"), &mut notices).unwrap();
        assert!(notices.is_empty());
        assert_eq!(p.friction.load_motor, 0.267);
        assert_eq!(p.family.name, "xl330");
        let back = ServoParams::from_json(&p.to_json().to_string(), Path::new("again.json"), &mut notices).unwrap();
        assert_eq!(back, p);
        // armscope's command delay is written where it is not BAM's 0, and read back
        let delayed = ServoParams { command_delay: 0.034, ..p.clone() };
        assert_eq!(ServoParams::from_json(&delayed.to_json().to_string(), Path::new("d.json"), &mut notices).unwrap(), delayed);
        assert!(!p.to_json().as_object().unwrap().contains_key(COMMAND_DELAY_KEY));
    }

    #[test]
    fn k_scale_labs_files_name_the_12_v_sts3215_sts3215v12() {
        // kscalelabs/sysid's parameter files: BAM's keys, the actuator "sts3215v12", and the
        // optimiser's "score" and "trial_number"
        let text = r#"{"kt": 3.5555, "R": 7.1214, "armature": 0.0283, "q_offset": -0.014, "friction_base": 6e-05, "friction_viscous": 0.0762, "score": 0.0309, "trial_number": 4998, "model": "m1", "actuator": "sts3215v12"}"#;
        let mut notices = Vec::new();
        let p = ServoParams::from_json(text, Path::new("m1.json"), &mut notices).unwrap();
        assert_eq!(p.family.name, "sts3215");
        assert_eq!(notices.len(), 3, "{notices:?}");
        assert!(notices[0].contains("actuator 'sts3215v12' read as 'sts3215'"), "{}", notices[0]);
        assert!(notices[1].contains("field 'score' is not a parameter"));
    }

    #[test]
    fn errors_name_the_file_and_field() {
        let mut notices = Vec::new();
        let missing = M6.replace("\"alpha\": 8.68,", "");
        let e = ServoParams::from_json(&missing, Path::new("p.json"), &mut notices).unwrap_err();
        assert!(e.starts_with("p.json: field 'alpha' is missing"), "{e}");
        let unknown = M6.replace("\"xl330\"", "\"xm430\"");
        let e = ServoParams::from_json(&unknown, Path::new("p.json"), &mut notices).unwrap_err();
        assert!(e.contains("field 'actuator' is 'xm430'"), "{e}");
        let late = M6.replace("\"alpha\"", "\"command_delay\": 1.5, \"alpha\"");
        let e = ServoParams::from_json(&late, Path::new("p.json"), &mut notices).unwrap_err();
        assert!(e.contains("field 'command_delay' must be between 0 and 1 s"), "{e}");
        let negative = M6.replace("\"R\": 2.81", "\"R\": -1");
        assert!(ServoParams::from_json(&negative, Path::new("p.json"), &mut notices).unwrap_err().contains("field 'R' must be positive"));
    }
}
