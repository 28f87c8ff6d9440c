//! LeRobot datasets, format v2.1 (one parquet file per episode, `meta/episodes.jsonl`) and v3.0
//! (many episodes per `data/chunk-XXX/file-XXX.parquet`, an episodes table in
//! `meta/episodes/…parquet`): `meta/info.json` says which, its `data_path` template where the
//! frames are, its `features` what the vector columns' entries are called.

mod columns;
mod row_groups;

use super::{Column, Episode, check_increasing};
use crate::error::Error;
use columns::int_column;
use parquet::arrow::ProjectionMask;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use row_groups::DataFiles;
use serde_json::Value;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// v2.x: `data_path` formatted with `episode_chunk`, `episode_index`.
    FilePerEpisode,
    /// v3.x: `data_path` formatted with `chunk_index`, `file_index` from the episodes table.
    SharedFiles,
}

/// One row of the episodes table (v3) or of `episodes.jsonl` (v2).
#[derive(Clone, Debug)]
struct EpisodeEntry {
    index: i64,
    length: Option<i64>,
    chunk: i64,
    file: i64,
}

#[derive(Debug)]
pub struct Dataset {
    pub root: PathBuf,
    pub version: String,
    pub layout: Layout,
    pub fps: f64,
    pub robot_type: Option<String>,
    data_path: String,
    features: serde_json::Map<String, Value>,
    episodes: Vec<EpisodeEntry>,
    /// The data files' footers and the row groups of several episodes, read once for all of them.
    files: DataFiles,
}

impl Dataset {
    pub fn open(root: &Path) -> Result<Self, Error> {
        let info_path = root.join("meta/info.json");
        let fail = |path: &Path, m: String| Error::flag(path.display().to_string(), m);
        let text = std::fs::read_to_string(&info_path).map_err(|e| fail(&info_path, format!("{e} (a LeRobot dataset folder has meta/info.json)")))?;
        let info: Value = serde_json::from_str(&text).map_err(|e| fail(&info_path, e.to_string()))?;
        let field = |name: &str| info.get(name).ok_or_else(|| fail(&info_path, format!("no field '{name}'")));
        let version = field("codebase_version")?.as_str().ok_or_else(|| fail(&info_path, "'codebase_version' is not a string".into()))?.to_string();
        let layout = match version.trim_start_matches('v').split('.').next() {
            Some("2") => Layout::FilePerEpisode,
            Some("3") => Layout::SharedFiles,
            _ => return Err(fail(&info_path, format!("codebase_version '{version}': armscope reads v2.x and v3.x datasets"))),
        };
        let fps = field("fps")?.as_f64().filter(|f| *f > 0.0).ok_or_else(|| fail(&info_path, "'fps' is not a positive number".into()))?;
        let data_path = field("data_path")?.as_str().ok_or_else(|| fail(&info_path, "'data_path' is not a string".into()))?.to_string();
        let features = field("features")?.as_object().cloned().ok_or_else(|| fail(&info_path, "'features' is not a map".into()))?;
        let chunks_size = info.get("chunks_size").and_then(Value::as_i64).unwrap_or(1000).max(1);
        let robot_type = info.get("robot_type").and_then(Value::as_str).map(String::from);
        let episodes = match layout {
            Layout::FilePerEpisode => read_episodes_jsonl(root, chunks_size)?,
            Layout::SharedFiles => read_episodes_table(root)?,
        };
        Ok(Self { root: root.to_path_buf(), version, layout, fps, robot_type, data_path, features, episodes, files: DataFiles::default() })
    }

    pub fn episode_indices(&self) -> Vec<i64> {
        self.episodes.iter().map(|e| e.index).collect()
    }

    /// The names of a feature's entries (`names` as a list, a one-entry map of a list, or absent:
    /// then `FEATURE[k]`).
    pub fn feature_names(&self, feature: &str) -> Option<Vec<String>> {
        let spec = self.features.get(feature)?;
        let width = spec.get("shape").and_then(Value::as_array).and_then(|s| s.first()).and_then(Value::as_u64).unwrap_or(1) as usize;
        let listed = |v: &Value| v.as_array().map(|a| a.iter().map(|n| n.as_str().map(String::from).unwrap_or_else(|| n.to_string())).collect::<Vec<_>>());
        let names = match spec.get("names") {
            Some(Value::Array(_)) => listed(&spec["names"]),
            Some(Value::Object(map)) => map.values().find_map(listed),
            _ => None,
        };
        Some(names.unwrap_or_else(|| (0..width).map(|k| format!("{feature}[{k}]")).collect()))
    }

    /// The features a replay can read: the numeric ones with names (not the bookkeeping columns).
    pub fn vector_features(&self) -> Vec<String> {
        let bookkeeping = ["timestamp", "frame_index", "episode_index", "index", "task_index"];
        self.features.iter().filter(|(name, spec)| !bookkeeping.contains(&name.as_str()) && matches!(spec.get("dtype").and_then(Value::as_str), Some("float32" | "float64"))).map(|(n, _)| n.clone()).collect()
    }

    fn data_file(&self, entry: &EpisodeEntry) -> PathBuf {
        let keys: [(&str, i64); 4] = [("episode_chunk", entry.chunk), ("episode_index", entry.index), ("chunk_index", entry.chunk), ("file_index", entry.file)];
        self.root.join(format_template(&self.data_path, &keys))
    }

    /// Read one episode's frames of `feature`, in frame order, timed by `frame_index / fps`.
    pub fn read_episode(&self, episode: i64, feature: &str) -> Result<Episode, Error> {
        // the entries are sorted by episode (read_episodes_*)
        let entry = self.episodes.binary_search_by_key(&episode, |e| e.index).ok().map(|k| &self.episodes[k]).ok_or_else(|| {
            let indices = self.episode_indices();
            let range = match (indices.iter().min(), indices.iter().max()) {
                (Some(a), Some(b)) => format!("{} episodes, {a} to {b}", indices.len()),
                _ => "no episodes".into(),
            };
            Error::flag("--episode", format!("{episode}: no such episode in {} ({range})", self.root.display()))
        })?;
        let names = self.feature_names(feature).ok_or_else(|| Error::flag("--feature", format!("no feature '{feature}' in {} (features: {})", self.root.join("meta/info.json").display(), self.vector_features().join(", "))))?;
        let path = self.data_file(entry);
        let fail = |m: String| Error::flag(path.display().to_string(), m);
        let (mut frames, mut stamps, mut values) = self.files.episode(&path, feature, names.len(), episode, self.layout == Layout::SharedFiles).map_err(fail)?;
        if frames.is_empty() && stamps.is_empty() || values.first().is_none_or(Vec::is_empty) {
            return Err(fail(format!("no frames of episode {episode}")));
        }
        let label = format!("episode {episode}");
        let time: Vec<f64> = if !frames.is_empty() {
            // in frame order; frame_index / fps, exact where float32 timestamps are not
            let mut order: Vec<usize> = (0..frames.len()).collect();
            order.sort_by_key(|&i| frames[i]);
            if order.iter().enumerate().any(|(k, &i)| k != i) {
                for column in &mut values {
                    *column = order.iter().map(|&i| column[i]).collect();
                }
                if !stamps.is_empty() {
                    stamps = order.iter().map(|&i| stamps[i]).collect();
                }
                frames = order.iter().map(|&i| frames[i]).collect();
            }
            if let Some(w) = frames.windows(2).find(|w| w[1] == w[0]) {
                return Err(fail(format!("{label}: frame_index {} appears twice", w[0])));
            }
            frames.iter().map(|&f| (f - frames[0]) as f64 / self.fps).collect()
        } else {
            stamps.iter().map(|s| s - stamps[0]).collect()
        };
        if !stamps.is_empty() {
            check_increasing(&stamps, &label).map_err(|m| fail(format!("{m} (column 'timestamp')")))?;
        }
        if let Some(length) = entry.length.filter(|&l| l != time.len() as i64) {
            return Err(fail(format!("{label}: {} frames, the episodes table says {length}", time.len())));
        }
        let columns = names.into_iter().zip(values).map(|(name, values)| Column { name, values }).collect();
        Ok(Episode { label, index: Some(episode), time, columns, effort: Vec::new(), notices: Vec::new() })
    }
}

fn read_episodes_jsonl(root: &Path, chunks_size: i64) -> Result<Vec<EpisodeEntry>, Error> {
    let path = root.join("meta/episodes.jsonl");
    let fail = |m: String| Error::flag(path.display().to_string(), m);
    let text = std::fs::read_to_string(&path).map_err(|e| fail(e.to_string()))?;
    let mut entries = Vec::new();
    for (line_number, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let row: Value = serde_json::from_str(line).map_err(|e| fail(format!("line {}: {e}", line_number + 1)))?;
        let index = row.get("episode_index").and_then(Value::as_i64).ok_or_else(|| fail(format!("line {}: no integer 'episode_index'", line_number + 1)))?;
        let length = row.get("length").and_then(Value::as_i64);
        entries.push(EpisodeEntry { index, length, chunk: index / chunks_size, file: 0 });
    }
    entries.sort_by_key(|e| e.index);
    Ok(entries)
}

fn read_episodes_table(root: &Path) -> Result<Vec<EpisodeEntry>, Error> {
    let folder = root.join("meta/episodes");
    let mut files = Vec::new();
    let list = |dir: &Path| -> Vec<PathBuf> {
        let mut found: Vec<PathBuf> = std::fs::read_dir(dir).map(|d| d.flatten().map(|e| e.path()).collect()).unwrap_or_default();
        found.sort();
        found
    };
    for chunk in list(&folder).into_iter().filter(|p| p.is_dir()) {
        files.extend(list(&chunk).into_iter().filter(|p| p.extension().is_some_and(|e| e == "parquet")));
    }
    if files.is_empty() {
        return Err(Error::flag(folder.display().to_string(), "no episodes table (meta/episodes/chunk-XXX/file-XXX.parquet)"));
    }
    let mut entries = Vec::new();
    for path in files {
        let fail = |m: String| Error::flag(path.display().to_string(), m);
        let file = std::fs::File::open(&path).map_err(|e| fail(e.to_string()))?;
        let builder = ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| fail(e.to_string()))?;
        let schema = builder.schema().clone();
        let wanted = ["episode_index", "length", "data/chunk_index", "data/file_index"];
        let mut roots = Vec::new();
        for name in wanted {
            match schema.fields().iter().position(|f| f.name() == name) {
                Some(i) => roots.push(i),
                None if name == "length" => {}
                None => return Err(fail(format!("no column '{name}' in the episodes table"))),
            }
        }
        let mask = ProjectionMask::roots(builder.parquet_schema(), roots);
        for batch in builder.with_projection(mask).build().map_err(|e| fail(e.to_string()))? {
            let batch = batch.map_err(|e| fail(e.to_string()))?;
            let column = |name: &str| batch.column_by_name(name).map(|a| int_column(a.as_ref(), name)).transpose().map_err(&fail);
            let index = column("episode_index")?.unwrap_or_default();
            let length = column("length")?;
            let chunk = column("data/chunk_index")?.unwrap_or_default();
            let file = column("data/file_index")?.unwrap_or_default();
            for r in 0..batch.num_rows() {
                entries.push(EpisodeEntry { index: index[r], length: length.as_ref().map(|l| l[r]), chunk: chunk[r], file: file[r] });
            }
        }
    }
    entries.sort_by_key(|e| e.index);
    Ok(entries)
}

/// Python's `str.format` for the templates LeRobot writes: `{key}` and `{key:0Nd}`.
pub fn format_template(template: &str, keys: &[(&str, i64)]) -> String {
    let mut out = String::new();
    let mut rest = template;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let Some(close) = rest[open..].find('}') else { break };
        let field = &rest[open + 1..open + close];
        let (key, spec) = field.split_once(':').unwrap_or((field, ""));
        match keys.iter().find(|(k, _)| *k == key) {
            Some((_, value)) => {
                let width: usize = spec.trim_start_matches('0').trim_end_matches('d').parse().unwrap_or(0);
                out.push_str(&format!("{value:0width$}"));
            }
            None => out.push_str(&rest[open..=open + close]),
        }
        rest = &rest[open + close + 1..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn templates_format_as_python_does() {
        let keys = [("episode_chunk", 0), ("episode_index", 42), ("chunk_index", 1), ("file_index", 7)];
        assert_eq!(super::format_template("data/chunk-{episode_chunk:03d}/episode_{episode_index:06d}.parquet", &keys), "data/chunk-000/episode_000042.parquet");
        assert_eq!(super::format_template("data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet", &keys), "data/chunk-001/file-007.parquet");
    }
}
