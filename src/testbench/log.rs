//! A servo bench log in BAM's JSON (Rhoban/bam's recorders and `bam.process`): a header naming
//! the pendulum (`mass`, `arm_mass` or `arm-mass`, `length`), the firmware's P gain `kp`, the
//! nominal supply `vin`, the servo `motor`, and `entries` of what was sent and read back at each
//! time: `goal_position`, `torque_enable`, `position`, `speed`, `load` (the Present PWM),
//! `input_volts`, `temp`, `timestamp`.
//!
//! A processed log has a `dt` and entries on the grid t_k = k·dt; a raw log (no `dt`) is resampled
//! onto that grid as `bam.process` does: t_k = k·Δt for t_k below the last raw timestamp, each field
//! interpolated linearly between the raw entries around t_k (extrapolated from the first two before
//! the first), `torque_enable` interpolated as 0/1 and thresholded at ½.
//!
//! Read as a second lab's logs are (K-Scale Labs' STS3215 set): an isolated sample at −π (the
//! encoder's read failure: one or two rows within a few counts of −π between rows far from it) is
//! dropped before resampling and counted ([`BenchLog::glitches`]); the header's `vin` is kept as
//! written, and [`BenchLog::measured_supply`] says what the servo's own voltage reading gave.

use std::path::{Path, PathBuf};

/// BAM's default resampling step, s (`bam.process --dt`).
pub const DEFAULT_DT: f64 = 0.005;

/// One row on the log's uniform grid.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Entry {
    pub time: f64,
    pub goal: f64,
    pub enabled: bool,
    pub position: f64,
    pub speed: f64,
    /// The Present PWM as a duty (−1 … 1), where the log holds it.
    pub duty: Option<f64>,
    /// The measured supply, V, where logged.
    pub volts: Option<f64>,
}

/// A bench log on its grid.
#[derive(Clone, Debug)]
pub struct BenchLog {
    pub path: PathBuf,
    /// Tip mass m, kg.
    pub mass: f64,
    /// Arm mass m_a (a uniform rod), kg.
    pub arm_mass: f64,
    /// Pivot to tip l, m.
    pub length: f64,
    /// The firmware's P gain register.
    pub kp: f64,
    /// The nominal supply, V.
    pub vin: f64,
    /// BAM's actuator name of the servo.
    pub actuator: String,
    /// The trajectory's name, if given.
    pub trajectory: Option<String>,
    pub dt: f64,
    /// Whether it was resampled here from a raw log.
    pub resampled: bool,
    /// Isolated samples at −π (encoder read glitches) dropped from the log.
    pub glitches: usize,
    /// The median of the supply the servo measured, V (None: the log has no `input_volts`); worked
    /// out once, when the log is read (a replay asks for it, and a fit replays a log 10⁵ times).
    pub measured_supply: Option<f64>,
    pub entries: Vec<Entry>,
}

/// A position within this of −π is the encoder's read failure value (a few counts of a 4096-count
/// encoder: 2π/4096 = 1.5 mrad a count; K-Scale's glitches read −3.1401, one count above −π).
const GLITCH_TOLERANCE: f64 = 0.01;
/// A glitch is isolated: the rows on either side are this far from it, rad.
const GLITCH_JUMP: f64 = 0.5;
/// A glitch is at most this many rows in a row.
const GLITCH_MAX_ROWS: usize = 2;

/// A raw entry, before resampling.
#[derive(Clone, Copy, Debug)]
struct RawEntry {
    timestamp: f64,
    goal: f64,
    enabled: f64,
    position: f64,
    speed: f64,
    load: Option<f64>,
    volts: Option<f64>,
}

impl BenchLog {
    /// Read a raw or processed log; `dt` resamples a raw log (BAM's 5 ms when None). Errors are
    /// one line naming the file and the field.
    pub fn load(path: &Path, dt: Option<f64>) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
        Self::parse(&text, path, dt)
    }

    pub fn parse(text: &str, path: &Path, dt: Option<f64>) -> Result<Self, String> {
        let file = path.display();
        let value: serde_json::Value = serde_json::from_str(text).map_err(|e| format!("{file}: not JSON: {e}"))?;
        let header = value.as_object().ok_or_else(|| format!("{file}: expected a JSON object with a header and 'entries'"))?;
        let number = |key: &str| -> Result<Option<f64>, String> {
            match header.get(key) {
                None | Some(serde_json::Value::Null) => Ok(None),
                Some(v) => v.as_f64().filter(|x| x.is_finite()).map(Some).ok_or_else(|| format!("{file}: field '{key}' must be a finite number")),
            }
        };
        let positive = |key: &str| -> Result<f64, String> {
            match number(key)? {
                Some(x) if x > 0.0 => Ok(x),
                Some(x) => Err(format!("{file}: field '{key}' must be positive (got {x})")),
                None => Err(format!("{file}: field '{key}' is missing")),
            }
        };
        let mass = match number("mass")? {
            Some(x) if x >= 0.0 => x,
            Some(x) => return Err(format!("{file}: field 'mass' must not be negative (got {x})")),
            None => return Err(format!("{file}: field 'mass' is missing")),
        };
        let arm_mass = match (number("arm_mass")?, number("arm-mass")?) {
            (Some(x), _) | (None, Some(x)) if x >= 0.0 => x,
            (Some(x), _) | (None, Some(x)) => return Err(format!("{file}: field 'arm_mass' must not be negative (got {x})")),
            (None, None) => 0.0,
        };
        let length = positive("length")?;
        let kp = positive("kp")?;
        let vin = positive("vin")?;
        let actuator = match header.get("motor").or_else(|| header.get("actuator")) {
            Some(serde_json::Value::String(s)) => s.clone(),
            Some(_) => return Err(format!("{file}: field 'motor' must be a string")),
            None => return Err(format!("{file}: field 'motor' is missing (the servo's name, e.g. \"xl330\")")),
        };
        if crate::actuator::bus_servo::firmware::family(&actuator).is_none() {
            return Err(format!("{file}: field 'motor' is '{actuator}', not a servo armscope knows ({})", crate::actuator::bus_servo::firmware::family_names()));
        }
        let trajectory = header.get("trajectory").and_then(|v| v.as_str()).map(str::to_string);
        let list = match header.get("entries") {
            Some(serde_json::Value::Array(a)) => a,
            Some(_) => return Err(format!("{file}: field 'entries' must be a list")),
            None => return Err(format!("{file}: field 'entries' is missing")),
        };
        if list.len() < 2 {
            return Err(format!("{file}: field 'entries' has {} entries; a log needs at least 2", list.len()));
        }
        let mut raw = Vec::with_capacity(list.len());
        for (k, e) in list.iter().enumerate() {
            let e = e.as_object().ok_or_else(|| format!("{file}: entries[{k}] must be an object"))?;
            let field = |key: &str| -> Result<Option<f64>, String> {
                match e.get(key) {
                    None | Some(serde_json::Value::Null) => Ok(None),
                    Some(serde_json::Value::Bool(b)) => Ok(Some(if *b { 1.0 } else { 0.0 })),
                    Some(v) => v.as_f64().filter(|x| x.is_finite()).map(Some).ok_or_else(|| format!("{file}: entries[{k}].{key} must be a finite number")),
                }
            };
            let required = |key: &str| field(key)?.ok_or_else(|| format!("{file}: entries[{k}].{key} is missing"));
            raw.push(RawEntry {
                timestamp: required("timestamp")?,
                goal: required("goal_position")?,
                enabled: required("torque_enable")?,
                position: required("position")?,
                speed: field("speed")?.unwrap_or(0.0),
                load: field("load")?,
                volts: field("input_volts")?,
            });
        }
        let glitches = drop_glitches(&mut raw);
        if raw.len() < 2 {
            return Err(format!("{file}: field 'entries' has {} entries once its samples at −π (encoder read glitches) are dropped; a log needs at least 2", raw.len()));
        }
        if let Some(k) = raw.windows(2).position(|w| !(w[1].timestamp > w[0].timestamp)) {
            return Err(format!("{file}: entries[{}].timestamp {} does not increase (after {} at entries[{k}])", k + 1, raw[k + 1].timestamp, raw[k].timestamp));
        }
        // the Present PWM: an XL330 register (0…885, negative duties wrapped into 65535…) in logs
        // recorded before BAM's recorder converted it to a duty; a duty already in newer ones; a
        // placeholder 0 in the Feetech recorder's
        let family = crate::actuator::bus_servo::firmware::family(&actuator).map(|f| f.name).unwrap_or("");
        let register = family == "xl330" && raw.iter().filter_map(|r| r.load).any(|l| l.abs() > 1.5);
        let logged_pwm = family != "sts3215" && raw.iter().any(|r| r.load.is_some_and(|l| l != 0.0));
        // (a processed log interpolated the register across its wrap where the duty changed sign:
        // a value no register holds, left out)
        let to_duty = |load: f64| {
            if !register {
                return Some(load);
            }
            let signed = if load > 32767.0 { load - 65536.0 } else { load };
            (signed.abs() <= 885.0).then_some(signed / 885.0)
        };
        for r in &mut raw {
            r.load = r.load.filter(|_| logged_pwm).and_then(to_duty);
        }
        let logged_dt = number("dt")?;
        let (dt, entries, resampled) = match logged_dt {
            Some(step) => {
                if !(step > 0.0) {
                    return Err(format!("{file}: field 'dt' must be positive (got {step})"));
                }
                let entries = raw.iter().map(|r| entry(r.timestamp, r.goal, r.enabled > 0.5, r.position, r.speed, r.load, r.volts)).collect();
                (step, entries, false)
            }
            None => {
                let step = dt.unwrap_or(DEFAULT_DT);
                (step, resample(&raw, step), true)
            }
        };
        let measured_supply = median_supply(&entries);
        Ok(Self { path: path.to_path_buf(), mass, arm_mass, length, kp, vin, actuator, trajectory, dt, resampled, glitches, measured_supply, entries })
    }

    /// Whether the header's `vin` disagrees with the measured supply by more than
    /// [`SUPPLY_DISAGREEMENT`] (None: nothing measured).
    pub fn supply_disagrees(&self) -> Option<bool> {
        self.measured_supply.map(|v| (v - self.vin).abs() > SUPPLY_DISAGREEMENT * self.vin)
    }

    /// The log's name: its file name without `.json` (and `.processed` / `.raw`).
    pub fn name(&self) -> String {
        let name = self.path.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
        let name = name.strip_suffix(".json").unwrap_or(&name);
        name.strip_suffix(".processed").or_else(|| name.strip_suffix(".raw")).unwrap_or(name).to_string()
    }

    /// Its length, s.
    pub fn duration(&self) -> f64 {
        self.entries.len() as f64 * self.dt
    }
}

/// A header's `vin` more than this fraction away from the measured supply's median disagrees with
/// it. BAM's XL330 logs (vin 7.4 V) read 5.8–9.2 V row by row, medians within 3 % of 7.4; K-Scale's
/// STS3215 logs say 15 V and read 11.7–12.2 V (20 % below).
pub const SUPPLY_DISAGREEMENT: f64 = 0.1;

/// The median of the entries' measured supply, V (None: none measured).
pub fn median_supply(entries: &[Entry]) -> Option<f64> {
    let mut volts: Vec<f64> = entries.iter().filter_map(|e| e.volts).collect();
    if volts.is_empty() {
        return None;
    }
    volts.sort_by(f64::total_cmp);
    Some(volts[volts.len() / 2])
}

/// Drop runs of at most [`GLITCH_MAX_ROWS`] rows at −π whose neighbours (on each side the log has
/// one) are at least [`GLITCH_JUMP`] away; the count dropped.
fn drop_glitches(raw: &mut Vec<RawEntry>) -> usize {
    let at_minus_pi = |r: &RawEntry| (r.position + std::f64::consts::PI).abs() <= GLITCH_TOLERANCE;
    let mut keep = vec![true; raw.len()];
    let mut i = 0;
    while i < raw.len() {
        if !at_minus_pi(&raw[i]) {
            i += 1;
            continue;
        }
        let end = (i..raw.len()).find(|&j| !at_minus_pi(&raw[j])).unwrap_or(raw.len());
        let far = |j: usize| (raw[j].position - raw[i].position).abs() >= GLITCH_JUMP;
        let isolated = end - i <= GLITCH_MAX_ROWS && (i > 0 || end < raw.len()) && (i == 0 || far(i - 1)) && (end == raw.len() || far(end));
        if isolated {
            keep[i..end].iter_mut().for_each(|k| *k = false);
        }
        i = end;
    }
    let before = raw.len();
    let mut flags = keep.into_iter();
    raw.retain(|_| flags.next().unwrap_or(true));
    before - raw.len()
}

fn entry(time: f64, goal: f64, enabled: bool, position: f64, speed: f64, duty: Option<f64>, volts: Option<f64>) -> Entry {
    Entry { time, goal, enabled, position, speed, duty, volts }
}

/// `bam.process`: onto t_k = k·dt, t_k < the last raw timestamp.
fn resample(raw: &[RawEntry], dt: f64) -> Vec<Entry> {
    let last = raw[raw.len() - 1].timestamp;
    let count = (last / dt).ceil().max(0.0) as usize;
    let mut out = Vec::with_capacity(count);
    let mut i = 0;
    for k in 0..count {
        let t = k as f64 * dt;
        if t >= last {
            break;
        }
        while i + 2 < raw.len() && t > raw[i + 1].timestamp {
            i += 1;
        }
        let (a, b) = (&raw[i], &raw[i + 1]);
        let w = (t - a.timestamp) / (b.timestamp - a.timestamp);
        let lerp = |x: f64, y: f64| x + (y - x) * w;
        let both = |x: Option<f64>, y: Option<f64>| x.zip(y).map(|(x, y)| lerp(x, y));
        out.push(entry(t, lerp(a.goal, b.goal), lerp(a.enabled, b.enabled) > 0.5, lerp(a.position, b.position), lerp(a.speed, b.speed), both(a.load, b.load), both(a.volts, b.volts)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw_log(entries: &str) -> String {
        format!(r#"{{"mass": 0.49, "length": 0.1, "kp": 100, "vin": 7.4, "motor": "xl330", "entries": [{entries}]}}"#)
    }

    #[test]
    fn resampling_interpolates_and_extrapolates_as_bam_process() {
        let text = raw_log(
            r#"{"timestamp": 0.004, "position": 0.0, "speed": 0, "goal_position": 0.0, "torque_enable": true, "load": 65535, "input_volts": 7.3},
               {"timestamp": 0.009, "position": 0.1, "speed": 0, "goal_position": 0.2, "torque_enable": true, "load": 10, "input_volts": 7.4},
               {"timestamp": 0.016, "position": 0.3, "speed": 0, "goal_position": 0.4, "torque_enable": false, "load": 20, "input_volts": 7.4}"#,
        );
        let log = BenchLog::parse(&text, Path::new("x.raw.json"), None).unwrap();
        assert!(log.resampled);
        // t = 0, 0.005, 0.010, 0.015 (< 0.016)
        assert_eq!(log.entries.len(), 4);
        // t = 0 extrapolates from the first two: 0 + (0.1 − 0)·(0 − 0.004)/0.005
        assert!((log.entries[0].position - (-0.08)).abs() < 1e-12);
        assert!((log.entries[2].position - (0.1 + 0.2 * 1.0 / 7.0)).abs() < 1e-12);
        // the PWM register: 65535 is −1 count
        assert!((log.entries[1].duty.unwrap() - (-1.0 + 0.2 * 11.0) / 885.0).abs() < 1e-12);
        // torque_enable thresholded at ½: at 0.015, 6/7 of the way to 0
        assert!(!log.entries[3].enabled);
        assert_eq!(log.name(), "x");
    }

    #[test]
    fn isolated_samples_at_minus_pi_are_dropped_and_counted() {
        // K-Scale's glitch: one row reads −3.1401 between rows at 1.22 rad; a run of two as well;
        // a real swing through −π (neighbours close to it) is kept
        let row = |t: f64, q: f64| format!(r#"{{"timestamp": {t}, "position": {q}, "speed": 0, "goal_position": 0.0, "torque_enable": true, "input_volts": 12.0}}"#);
        let rows = [row(0.0, 1.22), row(0.01, 1.223), row(0.02, -3.1401), row(0.03, 1.223), row(0.04, -3.1401), row(0.05, -3.1405), row(0.06, 1.2), row(0.07, -3.0), row(0.08, -3.14), row(0.09, -3.1)];
        let text = raw_log(&rows.join(",")).replace("xl330", "sts3215v12");
        let log = BenchLog::parse(&text, Path::new("k.json"), Some(0.01)).unwrap();
        assert_eq!(log.glitches, 3);
        assert_eq!(log.actuator, "sts3215v12");
        // the row at 0.02 is interpolated between its neighbours, not pulled towards −π
        assert!((log.entries[2].position - 1.223).abs() < 1e-12, "{:?}", log.entries[2]);
        assert!(log.entries.iter().all(|e| e.position > -3.2));
        assert!((log.entries[8].position - (-3.14)).abs() < 1e-12);
        // the supply: 12 V measured against the header's 7.4 (the raw_log header) disagrees
        assert_eq!(log.measured_supply, Some(12.0));
        assert_eq!(log.supply_disagrees(), Some(true));
    }

    #[test]
    fn bad_logs_get_one_line_naming_the_file_and_field() {
        let path = Path::new("bad.json");
        let e = BenchLog::parse(&raw_log(""), path, None).unwrap_err();
        assert_eq!(e, "bad.json: field 'entries' has 0 entries; a log needs at least 2");
        let one = r#"{"timestamp": 0.1, "position": 0, "goal_position": 0, "torque_enable": true}"#;
        let e = BenchLog::parse(&raw_log(&format!("{one}, {one}")), path, None).unwrap_err();
        assert!(e.starts_with("bad.json: entries[1].timestamp 0.1 does not increase"), "{e}");
        let e = BenchLog::parse(&raw_log(r#"{"timestamp": 0.1, "goal_position": 0, "torque_enable": true}, {}"#), path, None).unwrap_err();
        assert_eq!(e, "bad.json: entries[0].position is missing");
        let e = BenchLog::parse(&raw_log(&format!("{one}, {one}")).replace("xl330", "ax12"), path, None).unwrap_err();
        assert!(e.starts_with("bad.json: field 'motor' is 'ax12'"), "{e}");
        let e = BenchLog::parse(&raw_log(&format!("{one}, {one}")).replace("\"kp\": 100, ", ""), path, None).unwrap_err();
        assert_eq!(e, "bad.json: field 'kp' is missing");
    }
}
