//! Batch manifests: named experiments (any `run` flags) and parameter grids that expand to them.
//!
//! ```toml
//! name = "tutorial"            # the batch's folder under recordings/
//! [defaults]                   # flags for every experiment
//! duration = 10
//! [[experiment]]
//! name = "no-ff"
//! no-ff = true
//! [[experiment]]
//! name = "step-J{test-joint}"  # {flag} takes the grid's value
//! grid = { test-joint = [1, 2, 3] }
//! ```

use crate::error::Error;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ManifestFile {
    name: Option<String>,
    #[serde(default)]
    defaults: Table,
    #[serde(default, rename = "experiment")]
    experiments: Vec<ExperimentSpec>,
}

#[derive(Deserialize)]
struct ExperimentSpec {
    name: String,
    #[serde(default)]
    grid: Table,
    #[serde(flatten)]
    flags: Table,
}

/// One experiment of an expanded manifest.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedExperiment {
    /// Position in the expanded manifest (shards and tables keep this order).
    pub index: usize,
    pub name: String,
    /// `run` flags, e.g. `["--no-ff", "--duration", "10"]`.
    pub args: Vec<String>,
}

#[derive(Clone, Debug)]
pub struct Manifest {
    pub name: String,
    pub path: PathBuf,
    pub experiments: Vec<PlannedExperiment>,
}

/// Flags the batch sets itself for every experiment.
const RESERVED: [&str; 13] = ["name", "rrd", "mcap", "no-rrd", "no-mcap", "csv", "trace", "summary-json", "spawn", "connect", "foxglove", "realtime", "quiet"];

pub fn load_manifest(path: &Path) -> Result<Manifest, Error> {
    let flag = |m: String| Error::flag(format!("manifest {}", path.display()), m);
    let text = crate::builtin::read_to_string(path).map_err(|e| flag(format!("cannot read: {e}")))?;
    let file: ManifestFile = toml::from_str(&text).map_err(|e| flag(e.message().to_string()))?;
    let name = file.name.clone().unwrap_or_else(|| path.file_stem().map_or("batch".into(), |s| s.to_string_lossy().to_string()));
    let base = path.parent().unwrap_or(Path::new("."));
    let mut experiments = Vec::new();
    for spec in &file.experiments {
        for (name, flags) in expand(spec).map_err(|m| flag(format!("experiment '{}': {m}", spec.name)))? {
            let mut merged = file.defaults.clone();
            merged.extend(flags);
            let args = to_args(&merged, base).map_err(|m| flag(format!("experiment '{name}': {m}")))?;
            if experiments.iter().any(|e: &PlannedExperiment| e.name == name) {
                return Err(flag(format!("two experiments are named '{name}'")));
            }
            experiments.push(PlannedExperiment { index: experiments.len(), name, args });
        }
    }
    if experiments.is_empty() {
        return Err(flag("no [[experiment]] entries".into()));
    }
    Ok(Manifest { name, path: path.to_path_buf(), experiments })
}

/// The cartesian product of the grid, each with its name filled in.
fn expand(spec: &ExperimentSpec) -> Result<Vec<(String, Table)>, String> {
    let mut combos: Vec<Vec<(String, Value)>> = vec![Vec::new()];
    for (key, values) in &spec.grid {
        let Value::Array(values) = values else { return Err(format!("grid '{key}' must be a list of values")) };
        if values.is_empty() {
            return Err(format!("grid '{key}' is empty"));
        }
        combos = combos
            .into_iter()
            .flat_map(|c| values.iter().map(move |v| c.iter().cloned().chain([(key.clone(), v.clone())]).collect()))
            .collect();
    }
    Ok(combos
        .into_iter()
        .map(|combo| {
            let mut name = spec.name.clone();
            let templated = name.contains('{');
            let mut flags = spec.flags.clone();
            for (key, value) in combo {
                let text = plain(&value);
                if templated {
                    name = name.replace(&format!("{{{key}}}"), &text);
                } else {
                    name = format!("{name}_{key}{text}");
                }
                flags.insert(key, value);
            }
            (name, flags)
        })
        .collect())
}

fn plain(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Array(a) => a.iter().map(plain).collect::<Vec<_>>().join(","),
        other => other.to_string(),
    }
}

/// `key = value` → `--key value` (`_` in a key is `-`: `mcap_encoding` is `--mcap-encoding`);
/// `true` → `--key`; `false` → nothing; lists → comma lists.
fn to_args(flags: &Table, base: &Path) -> Result<Vec<String>, String> {
    let mut args = Vec::new();
    for (key, value) in flags {
        let key = &key.replace('_', "-");
        if RESERVED.contains(&key.as_str()) {
            return Err(format!("'{key}' is set by the batch itself"));
        }
        match value {
            Value::Boolean(true) => args.push(format!("--{key}")),
            Value::Boolean(false) => {}
            Value::Table(_) => return Err(format!("'{key}' is a table; flags take values or lists")),
            Value::String(s) if key == "urdf" => {
                // a model path is relative to the manifest when it exists there
                let relative = base.join(s);
                args.push(format!("--{key}"));
                args.push(if Path::new(s).is_relative() && relative.exists() { relative.display().to_string() } else { s.clone() });
            }
            other => {
                args.push(format!("--{key}"));
                args.push(plain(other));
            }
        }
    }
    Ok(args)
}

/// `I/N`: this is shard I (from 0) of N.
pub fn parse_shard(text: &str) -> Result<(usize, usize), Error> {
    let bad = || Error::flag("--shard", format!("expected I/N with 0 ≤ I < N, got '{text}'"));
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if n == 0 {
        return Err(bad());
    }
    if i >= n {
        // a Slurm array written --array=1-N hands the last task I = N
        return Err(Error::flag("--shard", format!("shard {i} of {n}: shards count from 0 (0…{}); a Slurm array must start at 0 (--array=0-{})", n - 1, n - 1)));
    }
    Ok((i, n))
}

/// The experiments of shard `i` of `n`: every n-th, starting at i (deterministic, balanced).
pub fn shard(experiments: &[PlannedExperiment], i: usize, n: usize) -> Vec<PlannedExperiment> {
    experiments.iter().filter(|e| e.index % n == i).cloned().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest(text: &str) -> Result<Manifest, Error> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.toml");
        std::fs::write(&path, text).unwrap();
        load_manifest(&path)
    }

    #[test]
    fn grids_expand_to_their_cartesian_product_with_names() {
        let m = manifest(
            r#"
            [defaults]
            duration = 5
            [[experiment]]
            name = "w{freq}-a{amp-deg}"
            grid = { freq = [0.3, 1.2], amp-deg = [10, 20, 30] }
            no-ff = true
            [[experiment]]
            name = "step"
            grid = { test-joint = [2, "J3"] }
            "#,
        )
        .unwrap();
        let names: Vec<&str> = m.experiments.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(names, ["w0.3-a10", "w0.3-a20", "w0.3-a30", "w1.2-a10", "w1.2-a20", "w1.2-a30", "step_test-joint2", "step_test-jointJ3"]);
        let first = &m.experiments[0].args;
        for flag in ["--duration", "5", "--no-ff", "--freq", "0.3", "--amp-deg", "10"] {
            assert!(first.contains(&flag.to_string()), "{flag} in {first:?}");
        }
        assert_eq!(m.experiments.iter().map(|e| e.index).collect::<Vec<_>>(), (0..8).collect::<Vec<_>>());
    }

    #[test]
    fn shards_cover_every_experiment_exactly_once() {
        let m = manifest("[[experiment]]\nname = \"x{freq}\"\ngrid = { freq = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11] }\n").unwrap();
        for n in 1..=5 {
            let mut seen: Vec<usize> = (0..n).flat_map(|i| shard(&m.experiments, i, n)).map(|e| e.index).collect();
            seen.sort();
            assert_eq!(seen, (0..11).collect::<Vec<_>>(), "{n} shards");
        }
        assert!(parse_shard("2/2").is_err() && parse_shard("x").is_err() && parse_shard("1/0").is_err());
        let from_one = parse_shard("4/4").unwrap_err().to_string();
        assert!(from_one.contains("shards count from 0 (0…3)") && from_one.contains("--array=0-3"), "{from_one}");
        assert_eq!(parse_shard("3/4").unwrap(), (3, 4));
    }

    #[test]
    fn bad_manifests_name_the_problem() {
        let e = manifest("[[experiment]]\nname = \"a\"\n[[experiment]]\nname = \"a\"\n").unwrap_err().to_string();
        assert!(e.contains("two experiments are named 'a'"), "{e}");
        let e = manifest("[[experiment]]\nname = \"a\"\nrrd = \"x.rrd\"\n").unwrap_err().to_string();
        assert!(e.contains("experiment 'a'") && e.contains("'rrd' is set by the batch"), "{e}");
        let e = manifest("[[experiment]\n").unwrap_err().to_string();
        assert!(e.contains("m.toml"), "{e}");
    }
}
