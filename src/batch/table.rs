use super::outcome::ExperimentOutcome;
use crate::error::Error;
use crate::summary::Summary;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What a batch (or one shard of it) produced: the input of the tables and of `batch merge`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BatchSummary {
    pub batch: String,
    pub manifest: PathBuf,
    /// `[I, N]` for one shard of N, absent for a whole batch.
    pub shard: Option<[usize; 2]>,
    pub experiments: Vec<ExperimentOutcome>,
}

impl BatchSummary {
    pub fn markdown(&self) -> String {
        markdown(self)
    }
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("n/a".into(), |x| format!("{x:.4}"))
}

fn per_joint(s: &Summary, f: impl Fn(usize) -> String) -> String {
    (0..s.joints.len()).map(f).collect::<Vec<_>>().join(" ")
}

/// Whether any experiment of the batch checked collisions (its tables then count them).
fn checks_collisions(summary: &BatchSummary) -> bool {
    summary.experiments.iter().any(|e| e.summary.as_ref().is_some_and(|s| s.collisions.is_some()))
}

/// A run's collisions in a table cell: control steps in contact, and the first contact.
fn collision_cell(s: &Summary) -> String {
    match &s.collisions {
        None => "not checked".into(),
        Some(c) => match &c.first_contact {
            None => "none".into(),
            Some((t, a, b)) => format!("{} steps, first {t:.3} s {a}–{b}", c.steps_in_contact),
        },
    }
}

pub fn markdown(summary: &BatchSummary) -> String {
    let collisions = checks_collisions(summary);
    let mut md = format!("# batch `{}`\n\nMax and RMS tracking error over every step with t ≥ the settle time (2 s), saturation % and chatter % of control steps, full steps lost (stepper mode), per joint J1..Jn{}.\n\n", summary.batch, if collisions { "; collisions: control steps with any pair in contact, and the first contact" } else { "" });
    let (head, rule, extra) = if collisions { (" collisions |", "---|", 1) } else { ("", "", 0) };
    md += &format!("| experiment | status | max err (rad) | RMS err (rad) | saturation % | chatter % | lost steps |{head} tool x / y / z range (m) | wall time incl. recording (s) |\n|---|---|---|---|---|---|---|{rule}---|---|\n");
    for e in &summary.experiments {
        match &e.summary {
            Some(s) => {
                let r = &s.tool_range;
                let cell = if collisions { format!(" {} |", collision_cell(s)) } else { String::new() };
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} | {} | {} |{cell} [{:.3}, {:.3}] / [{:.3}, {:.3}] / [{:.3}, {:.3}] | {:.3} |",
                    e.name,
                    e.status,
                    per_joint(s, |j| fmt_opt(s.max_abs_error[j])),
                    per_joint(s, |j| fmt_opt(s.rms_error[j])),
                    per_joint(s, |j| format!("{:.1}", s.saturation_percent[j])),
                    per_joint(s, |j| format!("{:.1}", s.chatter_percent[j])),
                    per_joint(s, |j| s.lost_steps.get(j).map_or("0".into(), |l| l.to_string())),
                    r.x.min,
                    r.x.max,
                    r.y.min,
                    r.y.max,
                    r.z.min,
                    r.z.max,
                    e.wall_time
                );
            }
            None => {
                let _ = writeln!(md, "| {} | {} | | | | | |{} | |", e.name, e.status, " |".repeat(extra));
            }
        }
    }
    md
}

pub fn csv(summary: &BatchSummary) -> String {
    let n = summary.experiments.iter().filter_map(|e| e.summary.as_ref()).map(|s| s.joints.len()).max().unwrap_or(0);
    let mut header = vec!["experiment".to_string(), "status".into()];
    for prefix in ["max_err", "rms_err", "saturation_pct", "chatter_pct", "lost_steps"] {
        header.extend((1..=n).map(|j| format!("{prefix}_{j}")));
    }
    header.extend(["x_min", "x_max", "y_min", "y_max", "z_min", "z_max", "wall_s"].map(String::from));
    let collisions = checks_collisions(summary);
    if collisions {
        header.extend(["collision_steps", "first_contact_s", "first_contact_pair"].map(String::from));
    }
    header.push("error".into());
    let mut out = header.join(",") + "\n";
    for e in &summary.experiments {
        let mut row = vec![e.name.clone(), e.status.clone()];
        match &e.summary {
            Some(s) => {
                let cell = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:?}"));
                row.extend((0..n).map(|j| cell(s.max_abs_error.get(j).copied().flatten())));
                row.extend((0..n).map(|j| cell(s.rms_error.get(j).copied().flatten())));
                row.extend((0..n).map(|j| cell(s.saturation_percent.get(j).copied())));
                row.extend((0..n).map(|j| cell(s.chatter_percent.get(j).copied())));
                row.extend((0..n).map(|j| s.lost_steps.get(j).map_or("0".into(), |l| l.to_string())));
                let r = &s.tool_range;
                row.extend([r.x.min, r.x.max, r.y.min, r.y.max, r.z.min, r.z.max, e.wall_time].map(|x| format!("{x:?}")));
                if collisions {
                    // empty cells: not checked (steps) or no contact (time, pair)
                    let c = s.collisions.as_ref();
                    row.push(c.map_or(String::new(), |c| c.steps_in_contact.to_string()));
                    let first = c.and_then(|c| c.first_contact.as_ref());
                    row.push(first.map_or(String::new(), |f| format!("{:?}", f.0)));
                    row.push(first.map_or(String::new(), |f| format!("{}–{}", f.1, f.2)));
                }
                row.push(String::new());
            }
            None => {
                row.extend(std::iter::repeat_n(String::new(), 5 * n + 7 + if collisions { 3 } else { 0 }));
                row.push(format!("\"{}\"", e.error.clone().unwrap_or_default().replace('"', "'")));
            }
        }
        out += &(row.join(",") + "\n");
    }
    out
}

/// The file stem of the tables: `summary`, or `summary.shard-I-of-N` for shard I of N.
pub fn table_stem(shard: Option<[usize; 2]>) -> String {
    match shard {
        Some([i, n]) => format!("summary.shard-{i}-of-{n}"),
        None => "summary".into(),
    }
}

/// Writes DIR/STEM.md, .csv and .json; returns the paths.
pub fn write_tables(dir: &Path, summary: &BatchSummary) -> Result<Vec<PathBuf>, Error> {
    let stem = table_stem(summary.shard);
    let files = [
        (dir.join(format!("{stem}.md")), markdown(summary)),
        (dir.join(format!("{stem}.csv")), csv(summary)),
        (dir.join(format!("{stem}.json")), serde_json::to_string_pretty(summary).unwrap_or_default() + "\n"),
    ];
    for (path, text) in &files {
        std::fs::write(path, text).map_err(|e| Error::output(path, e))?;
    }
    Ok(files.into_iter().map(|(p, _)| p).collect())
}

/// Joins the shard summaries found in `dirs` into one, in manifest order; every experiment must
/// appear exactly once.
pub fn merge_summaries(dirs: &[PathBuf]) -> Result<BatchSummary, Error> {
    // each summary with the file it came from (the messages name them)
    let mut parts: Vec<(PathBuf, BatchSummary)> = Vec::new();
    for dir in dirs {
        let entries = std::fs::read_dir(dir).map_err(|e| Error::flag("batch merge", format!("{}: {e}", dir.display())))?;
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().to_string();
            if name.starts_with("summary.shard-") && name.ends_with(".json") {
                let text = std::fs::read_to_string(entry.path()).map_err(|e| Error::output(&entry.path(), e))?;
                let part: BatchSummary = serde_json::from_str(&text).map_err(|e| Error::flag("batch merge", format!("{}: {e}", entry.path().display())))?;
                parts.push((entry.path(), part));
            }
        }
    }
    parts.sort_by(|a, b| a.0.cmp(&b.0));
    let first = parts.first().ok_or_else(|| Error::flag("batch merge", "no summary.shard-*.json in the given folders"))?.1.clone();
    if let Some((path, other)) = parts.iter().find(|(_, p)| p.batch != first.batch) {
        return Err(Error::flag("batch merge", format!("{} is of batch '{}', the others of '{}': merge one batch's shards at a time", path.display(), other.batch, first.batch)));
    }
    // a folder reused with another shard count holds two sets that overlap
    let mut counts: Vec<usize> = parts.iter().map(|(_, p)| p.shard.map_or(1, |[_, n]| n)).collect();
    counts.sort();
    counts.dedup();
    if counts.len() > 1 {
        let sets: Vec<String> = counts.iter().map(|n| format!("{} of {n}", parts.iter().filter(|(_, p)| p.shard.map_or(1, |[_, m]| m) == *n).count())).collect();
        return Err(Error::flag("batch merge", format!("batch '{}' has shards of {} counts here ({}): a folder reused with another --shard N? remove the summary.shard-*-of-N.* files of the run that is not wanted", first.batch, counts.len(), sets.join(", "))));
    }
    let total = counts[0];
    let mut shards: Vec<usize> = parts.iter().filter_map(|(_, p)| p.shard.map(|[i, _]| i)).collect();
    shards.sort();
    shards.dedup();
    if shards.len() != total {
        let missing: Vec<String> = (0..total).filter(|i| !shards.contains(i)).map(|i| i.to_string()).collect();
        let hint = if missing.first().is_some_and(|m| m == "0") { " (shards count from 0: a Slurm array must start at 0, --array=0-N−1)" } else { " (still running, or failed before writing its summary?)" };
        return Err(Error::flag("batch merge", format!("batch '{}': shard {} of {total} missing{hint}", first.batch, missing.join(", "))));
    }
    let mut experiments: Vec<ExperimentOutcome> = parts.into_iter().flat_map(|(_, p)| p.experiments).collect();
    experiments.sort_by_key(|e| e.index);
    if let Some(dup) = experiments.windows(2).find(|w| w[0].index == w[1].index) {
        return Err(Error::flag("batch merge", format!("experiment '{}' appears in two shards", dup[0].name)));
    }
    Ok(BatchSummary { batch: first.batch, manifest: first.manifest, shard: None, experiments })
}
