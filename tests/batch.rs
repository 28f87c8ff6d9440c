//! `armscope batch`: the tutorial manifest end to end, agreement with single runs, determinism
//! across job counts, a failing experiment, shards and their merge, the comparison recording.

mod common;

use common::{armscope, repo};
use serde_json::Value;
use std::path::Path;

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))).unwrap()
}

/// The summary without its wall-clock time (which differs between any two runs).
fn numbers(summary: &Value) -> Value {
    let mut s = summary.clone();
    s.as_object_mut().unwrap().remove("wall_time");
    s
}

fn experiment<'a>(batch: &'a Value, name: &str) -> &'a Value {
    batch["experiments"].as_array().unwrap().iter().find(|e| e["name"] == name).unwrap_or_else(|| panic!("no experiment {name}"))
}

#[test]
fn tutorial_manifest_runs_end_to_end_and_matches_single_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tutorial");
    let manifest = repo().join("assets/experiments/tutorial.toml");
    assert_eq!(armscope(&["batch", manifest.to_str().unwrap(), "--out", out.to_str().unwrap(), "--jobs", "2"]), 0);
    let batch = read_json(&out.join("summary.json"));
    let names: Vec<&str> = batch["experiments"].as_array().unwrap().iter().map(|e| e["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["default", "static", "no-ff", "no-gravity", "test-joint-1", "test-joint-2", "test-joint-3", "test-joint-4", "test-joint-5", "test-joint-6", "freq0.3", "amp20", "freq1.2"]);
    for name in &names {
        assert_eq!(experiment(&batch, name)["status"], "completed", "{name}");
        for ext in ["rrd", "mcap", "csv", "json", "log"] {
            assert!(out.join(format!("{name}.{ext}")).metadata().unwrap().len() > 0, "{name}.{ext}");
        }
    }
    for table in ["summary.md", "summary.csv", "comparison.rrd"] {
        assert!(out.join(table).exists(), "{table}");
    }
    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    assert_eq!(csv.lines().count(), 14, "header + 13 experiments");
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(md.contains("| no-ff | completed |"));

    // the same experiments through `armscope run` give exactly the same summaries
    for (name, flags) in [("no-ff", vec!["--no-ff", "--duration", "10"]), ("test-joint-3", vec!["--test-joint", "3", "--duration", "5"]), ("default", vec![])] {
        let single = dir.path().join(format!("{name}.json"));
        let mut args = vec!["run", "--quiet", "--summary-json", single.to_str().unwrap()];
        args.extend(flags);
        assert_eq!(armscope(&args), 0);
        assert_eq!(numbers(&read_json(&single)["summary"]), numbers(&experiment(&batch, name)["summary"]), "{name}");
    }
}

const SMALL: &str = r#"
name = "small"
[defaults]
duration = 0.6
[[experiment]]
name = "wave"
[[experiment]]
name = "step-{test-joint}"
grid = { test-joint = [2, "J4"] }
[[experiment]]
name = "broken"
kp = [1, 2, 3]
[[experiment]]
name = "continuous"
time-step = 0
"#;

fn small_manifest(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("small.toml");
    std::fs::write(&path, SMALL).unwrap();
    path
}

#[test]
fn one_failing_experiment_is_reported_and_the_others_are_identical_for_any_job_count() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = small_manifest(dir.path());
    let mut results = Vec::new();
    for jobs in ["1", "2"] {
        let out = dir.path().join(format!("jobs{jobs}"));
        // a failed experiment makes the batch exit 1, after running all the others
        assert_eq!(armscope(&["batch", manifest.to_str().unwrap(), "--out", out.to_str().unwrap(), "--jobs", jobs]), 1);
        let batch = read_json(&out.join("summary.json"));
        let broken = experiment(&batch, "broken");
        assert_eq!(broken["status"], "failed");
        assert!(broken["error"].as_str().unwrap().contains("--kp"), "{broken}");
        for name in ["wave", "step-2", "step-J4", "continuous"] {
            assert_eq!(experiment(&batch, name)["status"], "completed", "{name}");
        }
        results.push(out);
    }
    let (a, b) = (read_json(&results[0].join("summary.json")), read_json(&results[1].join("summary.json")));
    for name in ["wave", "step-2", "step-J4", "continuous"] {
        assert_eq!(numbers(&experiment(&a, name)["summary"]), numbers(&experiment(&b, name)["summary"]), "{name}: --jobs 1 vs 2");
        let csv = |dir: &Path| std::fs::read(dir.join(format!("{name}.csv"))).unwrap();
        assert_eq!(csv(&results[0]), csv(&results[1]), "{name}.csv");
    }
}

#[test]
fn shards_cover_the_manifest_and_merge_into_the_whole() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = small_manifest(dir.path());
    let whole = dir.path().join("whole");
    armscope(&["batch", manifest.to_str().unwrap(), "--out", whole.to_str().unwrap(), "--no-compare"]);
    let shared = dir.path().join("shards");
    let mut seen = Vec::new();
    for i in 0..3 {
        armscope(&["batch", manifest.to_str().unwrap(), "--out", shared.to_str().unwrap(), "--shard", &format!("{i}/3"), "--no-compare"]);
        let part = read_json(&shared.join(format!("summary.shard-{i}-of-3.json")));
        seen.extend(part["experiments"].as_array().unwrap().iter().map(|e| e["index"].as_u64().unwrap()));
    }
    seen.sort();
    assert_eq!(seen, [0, 1, 2, 3, 4], "every experiment in exactly one shard");
    armscope(&["batch", "merge", shared.to_str().unwrap()]);
    let merged = read_json(&shared.join("summary.json"));
    let reference = read_json(&whole.join("summary.json"));
    let names = |v: &Value| v["experiments"].as_array().unwrap().iter().map(|e| e["name"].as_str().unwrap().to_string()).collect::<Vec<_>>();
    assert_eq!(names(&merged), names(&reference));
    for name in names(&reference) {
        let (m, r) = (experiment(&merged, &name), experiment(&reference, &name));
        assert_eq!(m["status"], r["status"]);
        if r["summary"].is_object() {
            assert_eq!(numbers(&m["summary"]), numbers(&r["summary"]), "{name}");
        }
    }
    assert!(shared.join("comparison.rrd").exists(), "merge builds the comparison recording");
    let merge_error = |dir: &Path| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope")).args(["batch", "merge", dir.to_str().unwrap()]).output().unwrap();
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert_eq!(err.lines().count(), 1, "{err}");
        err
    };
    // the same folder reused with another shard count: the merge names the mixed counts
    armscope(&["batch", manifest.to_str().unwrap(), "--out", shared.to_str().unwrap(), "--shard", "0/2", "--no-compare"]);
    let err = merge_error(&shared);
    assert!(err.contains("shards of 2 counts here (1 of 2, 3 of 3)") && err.contains("another --shard N"), "{err}");
    std::fs::remove_file(shared.join("summary.shard-0-of-2.json")).unwrap();
    // an incomplete set of shards is refused, naming the missing one; shard 0 missing is what an
    // array started at 1 leaves
    std::fs::remove_file(shared.join("summary.shard-1-of-3.json")).unwrap();
    let err = merge_error(&shared);
    assert!(err.contains("shard 1 of 3 missing"), "{err}");
    std::fs::remove_file(shared.join("summary.shard-0-of-3.json")).unwrap();
    let err = merge_error(&shared);
    assert!(err.contains("shard 0, 1 of 3 missing") && err.contains("a Slurm array must start at 0"), "{err}");
    // more shards than experiments: the empty one is written, and said
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["batch", manifest.to_str().unwrap(), "--out", dir.path().join("many").to_str().unwrap(), "--shard", "6/7", "--no-compare"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("shard 6 of 7 holds none of the manifest's 5 experiments"), "{err}");
    assert!(dir.path().join("many/summary.shard-6-of-7.json").exists());
}

#[test]
fn compare_overlays_runs_under_their_own_prefix() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("default.mcap"), dir.path().join("no-ff.mcap"));
    assert_eq!(armscope(&["run", "--quiet", "--duration", "0.5", "--no-rrd", "--mcap", a.to_str().unwrap()]), 0);
    assert_eq!(armscope(&["run", "--quiet", "--duration", "0.5", "--no-ff", "--no-rrd", "--mcap", b.to_str().unwrap()]), 0);
    let out = dir.path().join("cmp.rrd");
    assert_eq!(armscope(&["compare", a.to_str().unwrap(), b.to_str().unwrap(), "--out", out.to_str().unwrap()]), 0);
    let rrd = common::rrd::Rrd::open(&out);
    let entities = rrd.entities();
    for entity in ["/default/joints/J2/error", "/no-ff/joints/J2/error", "/default/joints/J5/torque", "/no-ff/joints/J5/angle"] {
        let e = entities.get(entity).unwrap_or_else(|| panic!("{entity} missing: {:?}", entities.keys()));
        assert_eq!(e.rows, 502, "{entity}: one row per step plus the style");
    }
    assert_eq!(rrd.blueprints, 1);
    // not an armscope recording: a clear error
    let junk = dir.path().join("junk.mcap");
    std::fs::write(&junk, b"not an mcap").unwrap();
    assert_eq!(armscope(&["compare", junk.to_str().unwrap(), "--out", out.to_str().unwrap()]), 2);
}

/// A manifest can give experiments motor files; the tables count each joint's lost steps.
#[test]
fn batch_tables_count_lost_steps_per_joint() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = dir.path().join("m.toml");
    let motors = common::repo().join("assets/motors");
    std::fs::write(
        &manifest,
        format!(
            "name = \"motors\"\n[[experiment]]\nname = \"tutorial\"\nmotors = \"{}\"\nduration = 2\n[[experiment]]\nname = \"real\"\nmotors = \"{}\"\nduration = 2\n",
            motors.join("tutorial.toml").display(),
            motors.join("smallrobotarm.toml").display()
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    assert_eq!(armscope(&["batch", manifest.to_str().unwrap(), "--out", out.to_str().unwrap(), "--no-compare"]), 0);
    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "lost_steps_2").expect("a lost_steps column per joint");
    let value = |name: &str| -> u64 { csv.lines().find(|l| l.starts_with(name)).unwrap().split(',').nth(col).unwrap().parse().unwrap() };
    assert_eq!(value("tutorial,"), 0, "the tutorial's motors carry the default wave");
    assert!(value("real,") > 0, "the real reductions cannot hold the box model's J2");
    assert!(std::fs::read_to_string(out.join("summary.md")).unwrap().contains("| lost steps |"));
}

/// The batch writes its comparison from the series its runs keep while they go on; `armscope
/// compare` reads the same series back from the runs' `.mcap` files. Both give the same entities,
/// rows and values (f64 through protobuf is exact), the failed experiment in neither.
#[test]
fn the_batch_comparison_from_memory_equals_the_one_from_the_mcap_files() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = small_manifest(dir.path());
    let out = dir.path().join("batch");
    assert_eq!(armscope(&["batch", manifest.to_str().unwrap(), "--out", out.to_str().unwrap(), "--jobs", "2"]), 1, "'broken' fails");
    let finished = ["wave", "step-2", "step-J4", "continuous"];
    let mcaps: Vec<String> = finished.iter().map(|n| out.join(format!("{n}.mcap")).to_str().unwrap().to_string()).collect();
    let from_files = dir.path().join("from_files.rrd");
    let mut args = vec!["compare", "--out", from_files.to_str().unwrap()];
    args.extend(mcaps.iter().map(String::as_str));
    assert_eq!(armscope(&args), 0);
    let (batch, files) = (common::rrd::Rrd::open(&out.join("comparison.rrd")), common::rrd::Rrd::open(&from_files));
    let (batch_entities, file_entities) = (batch.entities(), files.entities());
    assert_eq!(batch_entities.keys().collect::<Vec<_>>(), file_entities.keys().collect::<Vec<_>>());
    assert!(!batch_entities.keys().any(|e| e.starts_with("/broken")));
    let mut compared = 0;
    for (entity, info) in &batch_entities {
        assert_eq!(info.rows, file_entities[entity].rows, "{entity}");
        if entity.ends_with("/error") || entity.ends_with("/torque") || entity.ends_with("/angle") {
            let values = batch.series(entity);
            assert!(values.len() > 500, "{entity}: {} rows", values.len());
            assert_eq!(values, files.series(entity), "{entity}");
            compared += 1;
        }
    }
    assert_eq!(compared, finished.len() * 6 * 3, "every run, joint and series");
    assert_eq!(batch.blueprints, 1);
}

/// Experiments that check collisions (`floor`, `scene` in the manifest) get counted in the tables:
/// the CSV's control steps in contact and first contact equal a single run's summary with the same
/// flags; an experiment that does not check says so (empty cells, "not checked").
#[test]
fn batch_tables_count_collisions() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = dir.path().join("m.toml");
    std::fs::write(&manifest, "name = \"contacts\"\n[[experiment]]\nname = \"unchecked\"\nduration = 2\n[[experiment]]\nname = \"floor\"\nfloor = -0.2\nduration = 2\n").unwrap();
    let out = dir.path().join("out");
    assert_eq!(armscope(&["batch", manifest.to_str().unwrap(), "--out", out.to_str().unwrap(), "--no-compare"]), 0);
    let single = dir.path().join("single.json");
    assert_eq!(armscope(&["run", "--quiet", "--floor", "-0.2", "--duration", "2", "--summary-json", single.to_str().unwrap()]), 0);
    let c = &read_json(&single)["summary"]["collisions"];
    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let cell = |name: &str, column: &str| -> String {
        let i = header.iter().position(|h| *h == column).unwrap_or_else(|| panic!("no column {column}"));
        csv.lines().find(|l| l.starts_with(&format!("{name},"))).unwrap().split(',').nth(i).unwrap().to_string()
    };
    assert_eq!(cell("floor", "collision_steps"), c["steps_in_contact"].to_string());
    assert_eq!(cell("floor", "first_contact_s").parse::<f64>().unwrap(), c["first_contact"][0].as_f64().unwrap());
    assert_eq!(cell("floor", "first_contact_pair"), "tool_link–floor");
    assert_eq!(cell("unchecked", "collision_steps"), "");
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(md.contains("| collisions |") && md.contains("not checked") && md.contains("tool_link–floor"), "{md}");
}

/// `batch --compress` compresses every experiment's recordings; an experiment's own `compress = true`
/// its own (as `run --compress`). The others keep their chunks as they are.
#[test]
fn batch_compress_applies_to_every_experiment_or_to_one() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = dir.path().join("two.toml");
    std::fs::write(&manifest, "name = \"two\"\n[defaults]\nduration = 0.3\n[[experiment]]\nname = \"plain\"\n[[experiment]]\nname = \"packed\"\ncompress = true\n").unwrap();
    let compression = |out: &Path, name: &str| {
        let bytes = std::fs::read(out.join(format!("{name}.mcap"))).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().expect("summary section");
        let kinds: std::collections::BTreeSet<String> = summary.chunk_indexes.iter().map(|c| c.compression.clone()).collect();
        kinds.into_iter().collect::<Vec<_>>()
    };
    let each = dir.path().join("each");
    assert_eq!(armscope(&["batch", manifest.to_str().unwrap(), "--out", each.to_str().unwrap(), "--no-compare"]), 0);
    assert_eq!(compression(&each, "plain"), [""]);
    assert_eq!(compression(&each, "packed"), ["zstd"]);
    let all = dir.path().join("all");
    assert_eq!(armscope(&["batch", manifest.to_str().unwrap(), "--out", all.to_str().unwrap(), "--no-compare", "--compress"]), 0);
    assert_eq!(compression(&all, "plain"), ["zstd"]);
    assert_eq!(compression(&all, "packed"), ["zstd"]);
}

/// `--mcap-encoding ros2` on the batch gives every experiment a ROS 2 MCAP, the manifest's
/// `mcap_encoding = "ros2"` one experiment; the comparison recording reads both encodings, and
/// `compare` overlays a ROS 2 run with a Foxglove one.
#[test]
fn batch_mcap_encoding_applies_to_every_experiment_or_to_one_and_compares() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = dir.path().join("two.toml");
    std::fs::write(&manifest, "name = \"two\"\n[defaults]\nduration = 0.3\n[[experiment]]\nname = \"fox\"\n[[experiment]]\nname = \"bag\"\nmcap_encoding = \"ros2\"\n").unwrap();
    let encoding = |out: &Path, name: &str| {
        let bytes = std::fs::read(out.join(format!("{name}.mcap"))).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().expect("summary section");
        let joint_states = summary.channels.values().find(|c| c.topic == "/joint_states").unwrap();
        joint_states.message_encoding.clone()
    };
    let each = dir.path().join("each");
    assert_eq!(armscope(&["batch", manifest.to_str().unwrap(), "--out", each.to_str().unwrap()]), 0);
    assert_eq!((encoding(&each, "fox").as_str(), encoding(&each, "bag").as_str()), ("protobuf", "cdr"));
    let rrd = common::rrd::Rrd::open(&each.join("comparison.rrd"));
    let entities = rrd.entities();
    for entity in ["/fox/joints/J2/angle", "/bag/joints/J2/angle"] {
        assert_eq!(entities.get(entity).map(|e| e.rows), Some(302), "{entity} in {:?}", entities.keys());
    }
    let all = dir.path().join("all");
    assert_eq!(armscope(&["batch", manifest.to_str().unwrap(), "--out", all.to_str().unwrap(), "--no-compare", "--mcap-encoding", "ros2"]), 0);
    assert_eq!((encoding(&all, "fox").as_str(), encoding(&all, "bag").as_str()), ("cdr", "cdr"));
    // compare reads a ROS 2 run's angles as a Foxglove run's: the same values
    let out = dir.path().join("cmp.rrd");
    assert_eq!(armscope(&["compare", each.join("fox.mcap").to_str().unwrap(), all.join("fox.mcap").to_str().unwrap(), "--out", out.to_str().unwrap()]), 0);
    let rrd = common::rrd::Rrd::open(&out);
    // two runs named fox.mcap are told apart by their folders, not overlaid into one series
    let series: Vec<_> = rrd.entities().keys().filter(|e| e.ends_with("/joints/J3/angle")).cloned().collect();
    assert_eq!(series, ["/all_fox/joints/J3/angle", "/each_fox/joints/J3/angle"], "{series:?}");
    assert_eq!(rrd.component(&series[0], "Scalars:scalars").iter().map(|r| r.1.clone()).collect::<Vec<_>>(), rrd.component(&series[1], "Scalars:scalars").iter().map(|r| r.1.clone()).collect::<Vec<_>>());
}
