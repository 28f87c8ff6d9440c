//! What armscope says about a set of bench logs before replaying them: the samples it dropped and
//! the supply it takes, each in one notice for the whole set; and the one thing that stops a
//! replay, a measured supply asked of a log that has none.

use super::log::BenchLog;
use super::replay::Supply;

/// The notices for `logs` replayed on `supply`: at most one about dropped glitches and one about
/// the headers' `vin`.
pub fn notices(logs: &[BenchLog], supply: Supply) -> Vec<String> {
    let mut out = Vec::new();
    let glitched: Vec<&BenchLog> = logs.iter().filter(|l| l.glitches > 0).collect();
    if let Some(first) = glitched.first() {
        let count: usize = glitched.iter().map(|l| l.glitches).sum();
        out.push(format!(
            "dropped {count} isolated sample{} at −π (encoder read glitches) from {} of {} log{} (the first: {})",
            plural(count),
            glitched.len(),
            logs.len(),
            plural(logs.len()),
            first.path.display()
        ));
    }
    let disagreeing: Vec<(&BenchLog, f64)> = logs.iter().filter(|l| l.supply_disagrees() == Some(true)).filter_map(|l| Some((l, l.measured_supply?))).collect();
    if let Some((first, measured)) = disagreeing.first() {
        let what = format!(
            "{} of {} log{}: the header's vin ({} V in {}) disagrees with the supply the servo measured (median {measured:.1} V)",
            disagreeing.len(),
            logs.len(),
            plural(logs.len()),
            first.vin,
            first.path.display()
        );
        match supply {
            Supply::Auto => out.push(format!("{what}: replayed on the measured supply, row by row (--supply nominal for the header's)")),
            Supply::Nominal => out.push(format!("{what}: replayed on the header's, as --supply nominal asks")),
            Supply::Measured => {}
        }
    }
    out
}

/// The first log `supply` cannot replay: a measured supply asked of a log without `input_volts`,
/// as one line naming the file.
pub fn check_supply(logs: &[BenchLog], supply: Supply) -> Result<(), String> {
    match logs.iter().find(|l| supply == Supply::Measured && l.measured_supply.is_none()) {
        Some(log) => Err(format!("{}: no entry has 'input_volts', the supply the servo measured: --supply measured needs it (--supply nominal replays on the header's vin)", log.path.display())),
        None => Ok(()),
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn log(vin: f64, volts: Option<f64>, glitch: bool, name: &str) -> BenchLog {
        let volts = volts.map(|v| format!(r#", "input_volts": {v}"#)).unwrap_or_default();
        let rows: Vec<String> = (0..5)
            .map(|k| {
                let q = if glitch && k == 2 { -3.1401 } else { 0.5 };
                format!(r#"{{"timestamp": {}, "position": {q}, "goal_position": 0, "torque_enable": true{volts}}}"#, 0.01 * k as f64)
            })
            .collect();
        let text = format!(r#"{{"mass": 1.0, "length": 0.1, "kp": 16, "vin": {vin}, "motor": "sts3215", "entries": [{}]}}"#, rows.join(","));
        BenchLog::parse(&text, Path::new(name), Some(0.01)).unwrap()
    }

    #[test]
    fn one_notice_each_for_the_glitches_and_the_supply() {
        let logs = [log(15.0, Some(12.0), true, "a.json"), log(15.0, Some(12.1), true, "b.json"), log(12.0, Some(12.0), false, "c.json")];
        let n = notices(&logs, Supply::Auto);
        assert_eq!(n.len(), 2, "{n:?}");
        assert_eq!(n[0], "dropped 2 isolated samples at −π (encoder read glitches) from 2 of 3 logs (the first: a.json)");
        assert!(n[1].starts_with("2 of 3 logs: the header's vin (15 V in a.json) disagrees with the supply the servo measured (median 12.0 V): replayed on the measured supply"), "{}", n[1]);
        assert!(notices(&logs, Supply::Nominal)[1].ends_with("replayed on the header's, as --supply nominal asks"));
        assert_eq!(notices(&logs, Supply::Measured).len(), 1);
        // logs that agree with their header say nothing
        assert!(notices(&logs[2..], Supply::Auto).is_empty());
        // auto replays the disagreeing logs on what they measured, the others on their header
        assert!(Supply::Auto.measured_for(&logs[0]) && !Supply::Auto.measured_for(&logs[2]));
    }

    #[test]
    fn a_measured_supply_asked_of_a_log_without_one_names_the_file() {
        let logs = [log(12.0, Some(12.0), false, "ok.json"), log(12.0, None, false, "bare.json")];
        assert!(check_supply(&logs, Supply::Auto).is_ok());
        let e = check_supply(&logs, Supply::Measured).unwrap_err();
        assert!(e.starts_with("bare.json: no entry has 'input_volts'"), "{e}");
        assert!(!e.contains('\n'));
    }
}
