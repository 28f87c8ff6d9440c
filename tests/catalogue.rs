//! The catalogue you can order from (issue 21 item 1): real motors and reductions as separate
//! entries, every number with where it was read and equal to that source's; a user's file on top;
//! one-line errors naming the entry and the field.

mod common;

use armscope::actuator::{Catalogue, load_motor_file};
use std::path::{Path, PathBuf};

fn built_in() -> PathBuf {
    common::repo().join("assets/motors/catalogue.toml")
}

fn raw() -> toml::Table {
    std::fs::read_to_string(built_in()).unwrap().parse().unwrap()
}

#[test]
fn the_built_in_catalogue_holds_thirty_motors_and_fifteen_reductions_of_every_kind_asked() {
    let c = Catalogue::load(&built_in()).unwrap();
    assert!(c.entries.len() >= 30, "{} motors", c.entries.len());
    assert!(c.reductions.len() >= 15, "{} reductions", c.reductions.len());
    let motors = |prefix: &str| c.entries.keys().filter(|n| n.starts_with(prefix)).count();
    assert!(motors("14HS") >= 2 && motors("17H") >= 8 && motors("23HS") >= 1, "NEMA14, 17 and 23 steppers");
    assert!(motors("STS") >= 2 && motors("X") >= 8, "Feetech and Dynamixel bus servos");
    assert!(motors("AK") >= 3 && motors("RMD") >= 3, "geared BLDC actuators (CubeMars AK, MyActuator RMD)");
    let thermal = c.entries.keys().filter(|n| c.drive_train(n).unwrap().unwrap().heat.is_some()).count();
    assert!(thermal >= 2, "small DC/BLDC motors with full thermal data: {thermal}");
    let kind = |k: &str| c.reductions.values().filter(|r| r.kind == k).count();
    assert!(kind("planetary") >= 4 && kind("strain_wave") >= 6 && kind("belt") >= 1);
    for size in ["11", "14", "17", "25"] {
        assert!(c.reductions.keys().any(|n| n.contains(&format!("-{size}-"))), "a strain-wave gear of size {size}");
    }
}

/// Every built-in entry names where its numbers were read (`source`); a number read elsewhere, or a
/// setting rather than a datasheet value, has its own line in `sources`, naming a field it has.
#[test]
fn every_built_in_entry_says_where_its_numbers_were_read() {
    for (name, entry) in raw() {
        let t = entry.as_table().unwrap();
        let source = t.get("source").and_then(|s| s.as_str()).unwrap_or_else(|| panic!("{name}: no source"));
        assert!(source.len() > 20, "{name}: '{source}' is no source");
        if let Some(sources) = t.get("sources") {
            for (field, s) in sources.as_table().unwrap() {
                assert!(t.contains_key(field), "{name}: sources.{field} names no field");
                assert!(s.as_str().is_some_and(|s| s.len() > 10), "{name}: sources.{field}");
            }
        }
    }
}

/// The survey's table row of an entry: the row whose first cell, without spaces, hyphens and
/// punctuation, contains the entry's name so reduced — ends with it where several contain it — (or
/// the row named here, where the two spell it differently).
fn row_of<'a>(rows: &'a [String], name: &str) -> &'a str {
    let squash = |s: &str| s.chars().filter(|c| c.is_ascii_alphanumeric()).collect::<String>().to_lowercase();
    let spelled = match name {
        "NEMA17-RobotShop-1182" => "NEMA17 per RobotShop datasheet-1182",
        "STS3215-C018" | "STS3215-C018-BAM12V" => "Feetech ST-3215-C018",
        "EC-i40-488607" => "maxon EC-i 40 100 W (488607)",
        "EC45flat-50W-24V" => "maxon EC 45 flat 50 W (6516xx)",
        "HD17-20" => "Robrotics HD17",
        "NEMA17-PG100" => "NEMA17 100:1 planetary",
        "NEMA17-PG27" => "NEMA17 27:1",
        "AF042-2stage" => "Apex AF042",
        "AF060-2stage" => "Apex AF060",
        "CricketDrive-MK2" => "Cricket Drive MK II",
        "GT2-belt" => "Synchronous (timing) belt",
        "MG17-G5" => "StepperOnline MG17-G5",
        other => other,
    };
    let key = squash(spelled);
    let first = |r: &String| squash(r.split('|').nth(1).unwrap_or(""));
    let mut found: Vec<&String> = rows.iter().filter(|r| first(r).contains(&key)).collect();
    if found.len() > 1 {
        // "XL430-W250" is in "2XL430-W250 (2 axes)" too: the row that ends with the name
        found.retain(|r| first(r).ends_with(&key));
    }
    assert_eq!(found.len(), 1, "{name}: one survey row, found {found:?}");
    found[0]
}

fn numbers(row: &str) -> Vec<f64> {
    let mut out = Vec::new();
    let chars: Vec<char> = row.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        if chars[i].is_ascii_digit() {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.' || ((chars[i] == 'e') && i + 1 < chars.len() && (chars[i + 1] == '-' || chars[i + 1].is_ascii_digit())) || (chars[i] == '-' && i > 0 && chars[i - 1] == 'e')) {
                i += 1;
            }
            let text: String = chars[start..i].iter().collect();
            if let Ok(x) = text.trim_end_matches('.').parse::<f64>() {
                out.push(x);
            }
        } else {
            i += 1;
        }
    }
    out
}

/// Every number of a built-in entry covered by its `source` is a number of that entry's row in the
/// survey it cites (tests/fixtures/reference/catalogue-sources.md, a copy): equal to 1e-9, or one of
/// the unit conversions the catalogue's comments state — rpm to rad/s (to the printed 3 decimals),
/// percent to a fraction, mm to m, degrees to arcmin, a geared actuator's rotor moved to its output
/// (J·N², to 4 digits), a mixed-number ratio (19 38/187).
#[test]
fn the_built_in_numbers_are_the_surveys() {
    let survey = std::fs::read_to_string(common::repo().join("tests/fixtures/reference/catalogue-sources.md")).unwrap();
    let rows: Vec<String> = survey.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| Part") && !l.starts_with("|---")).map(str::to_string).collect();
    let mut checked = 0;
    for (name, entry) in raw() {
        let t = entry.as_table().unwrap();
        let own_source: Vec<String> = t.get("sources").and_then(|s| s.as_table()).map(|s| s.keys().cloned().collect()).unwrap_or_default();
        let row = row_of(&rows, &name);
        let values = numbers(row);
        let close = |a: f64, b: f64, rel: f64| (a - b).abs() <= rel * a.abs().max(b.abs());
        let is_in = |x: f64| values.iter().any(|&v| close(v, x, 1e-9));
        for (field, value) in t {
            if own_source.contains(field) || ["step_angle", "sources", "source", "kind"].contains(&field.as_str()) {
                continue;
            }
            let list: Vec<f64> = match value {
                toml::Value::Float(x) => vec![*x],
                toml::Value::Integer(i) => vec![*i as f64],
                // (a list of names, like `fits`, holds no number)
                toml::Value::Array(a) => a.iter().filter_map(|v| v.as_float().or(v.as_integer().map(|i| i as f64))).collect(),
                _ => continue,
            };
            for x in list {
                let ok = match field.as_str() {
                    "no_load_speed" | "max_input_speed" => values.iter().any(|&rpm| (rpm * std::f64::consts::TAU / 60.0 - x).abs() < 6e-4),
                    "efficiency" | "backdrive_efficiency" => is_in(x) || is_in(100.0 * x),
                    "length" => is_in(1000.0 * x),
                    "backlash" => is_in(x) || is_in(x / 60.0),
                    "rotor_inertia" => is_in(x) || values.iter().any(|&j| values.iter().any(|&n| n >= 2.0 && close(j * n * n, x, 1e-4))),
                    "ratios" => is_in(x) || values.windows(3).any(|w| close(w[0] + w[1] / w[2], x, 1e-5)),
                    _ => is_in(x),
                };
                assert!(ok, "{name}: {field} = {x} is not in its survey row: {row}");
                checked += 1;
            }
        }
    }
    assert!(checked > 400, "{checked} numbers checked");
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A malformed user catalogue gets one line naming the file, the entry and the field, from the
/// library and from `armscope catalogue --check` (which exits non-zero).
#[test]
fn a_malformed_user_catalogue_gets_one_line_naming_the_entry_and_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("[mine]\nkind = \"stepper\"\nholding_torque = -1\nstep_angle = 1.8\npull_out = [[0, 1]]\n", "mine", "holding_torque"),
        ("[mine]\nkind = \"servo\"\nstall_torque = 1\n", "mine", "no_load_speed"),
        ("[mine]\nkind = \"turbine\"\n", "mine", "kind"),
        ("[gear]\nkind = \"planetary\"\nratios = [5, 3]\nefficiency = 0.9\n", "gear", "ratios"),
        ("[gear]\nkind = \"planetary\"\nratios = [3, 5]\nrated_torque = [1, 2, 3]\n", "gear", "rated_torque"),
        ("[gear]\nkind = \"planetary\"\nratios = [3]\nefficiency = 1.5\n", "gear", "efficiency"),
        ("[gear]\nkind = \"belt\"\ndriver_teeth = [20]\n", "gear", "driven_teeth"),
        ("[gear]\nkind = \"planetary\"\nratios = [3]\ntorque = 2\n", "gear", "torque"),
        ("[gear]\nkind = \"planetary\"\nratios = [3]\nsources.mass = \"x\"\n", "gear", "sources.mass"),
    ];
    for (i, (text, entry, field)) in cases.iter().enumerate() {
        let path = write(dir.path(), &format!("bad{i}.toml"), text);
        let e = Catalogue::load(&path).unwrap_err().to_string();
        assert!(!e.contains('\n') && e.contains(&format!("bad{i}.toml")) && e.contains(&format!("'{entry}'")) && e.contains(field), "case {i}: {e}");
        let code = armscope::cli::main_with_args(["armscope", "catalogue", "--check", path.to_str().unwrap()]);
        assert_ne!(code, 0, "case {i}");
    }
}

/// A user's file adds to the built-in catalogue and overrides an entry of the same name; an entry
/// without a source is accepted as the user's own.
#[test]
fn a_user_catalogue_adds_to_and_overrides_the_built_in_one() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "mine.toml", "[17HS4401]\nkind = \"servo\"\nstall_torque = 9\nno_load_speed = 3\nmass = 1\n\n[my-belt]\nkind = \"belt\"\ndriver_teeth = [16, 20]\ndriven_teeth = [20, 40]\nefficiency = 0.96\n");
    let c = Catalogue::with_user_file(&path).unwrap();
    let built_in = Catalogue::load(&built_in()).unwrap();
    assert_eq!(c.entries.len(), built_in.entries.len());
    assert_eq!(c.drive_train("17HS4401").unwrap().unwrap().torque_limit(0.0), 9.0, "the user's entry replaced the built-in one");
    assert_eq!(c.reductions.len(), built_in.reductions.len() + 1);
    // every driven/driver above 1, once: 20/16, 40/20, 40/16
    assert_eq!(c.reduction("my-belt").unwrap().ratios, vec![1.25, 2.0, 2.5]);
    assert_eq!(c.source_of("my-belt"), None, "the user's own");
    assert!(c.source_of("NPS015").is_some());
    assert_eq!(armscope::cli::main_with_args(["armscope", "catalogue", "--check", path.to_str().unwrap(), "--json"]), 0);
}

/// A motor file names a catalogue reduction at one of its ratios: the drive train takes its
/// efficiency, back-driving friction, repeated peak (the peak cap), rated average torque, input speed
/// and input inertia; a ratio it does not come in is refused naming the joint and the field.
#[test]
fn a_motor_file_names_a_catalogue_reduction_at_one_of_its_ratios() {
    let dir = tempfile::tempdir().unwrap();
    let model = armscope::model::load_urdf(&common::box_urdf()).unwrap();
    let path = write(dir.path(), "m.toml", "[joints.J2]\nmotor = \"17HS19-2004S1\"\nreduction = \"NPS015\"\ngear_ratio = 5\n\n[joints.J3]\nmotor = \"17HS4401\"\nreduction = \"DYD-14-051\"\n");
    let set = load_motor_file(&path, &model).unwrap();
    let j2 = set.joints[1].as_ref().unwrap();
    assert_eq!((j2.gear_ratio, j2.gear.efficiency, j2.rated_torque, j2.rated_average_torque), (5.0, 0.97, 40.0, Some(21.0)));
    assert!((j2.max_motor_speed.unwrap() - 837.758).abs() < 1e-9 && j2.reductions == ["NPS015"]);
    let j3 = set.joints[2].as_ref().unwrap();
    assert_eq!((j3.gear_ratio, j3.gear.breakaway_torque, j3.rated_torque), (51.0, 3.0, 14.8), "a one-ratio reduction needs no gear_ratio");
    assert!((j3.reflected_inertia() - (5.4e-6 + 1.19e-5) * 51.0 * 51.0).abs() < 1e-15, "rotor and the gear's input inertia through N²");
    // two stages from the motor out: a belt, then a planetary: ratios multiply, efficiencies too, the
    // planetary's input turns at the motor's speed over the belt's ratio
    let staged = write(dir.path(), "staged.toml", "[joints.J2]\nmotor = \"17HS19-2004S1\"\nreduction = [\"GT2-belt\", \"NPS015\"]\ngear_ratio = [2.8, 5]\n");
    let d = load_motor_file(&staged, &model).unwrap().joints[1].take().unwrap();
    assert!((d.gear_ratio - 14.0).abs() < 1e-12 && (d.gear.efficiency - 0.95 * 0.97).abs() < 1e-15 && d.reductions == ["GT2-belt", "NPS015"]);
    assert!((d.max_motor_speed.unwrap() - 837.758 * 2.8).abs() < 1e-9 && d.rated_torque == 40.0);
    for (text, field) in [("reduction = [\"GT2-belt\", \"NPS015\"]\ngear_ratio = 5\n", "gear_ratio"), ("reduction = \"NPS015\"\ngear_ratio = 6\n", "gear_ratio"), ("reduction = \"NPS015\"\n", "gear_ratio"), ("reduction = \"nope\"\n", "reduction"), ("reduction = \"NPS015\"\ngear_ratio = 5\nefficiency = 0.5\n", "efficiency")] {
        let bad = write(dir.path(), "bad.toml", &format!("[joints.J2]\nmotor = \"17HS4401\"\n{text}"));
        let e = load_motor_file(&bad, &model).unwrap_err().to_string();
        assert!(!e.contains('\n') && e.contains("bad.toml") && e.contains("joint 'J2'") && e.contains(field), "{text}: {e}");
    }
}
