//! A dataset's data files as its episodes are read from them: each file's footer parsed once, and a
//! row group that holds several episodes decoded once for all of them. LeRobot's recorder writes a
//! row group per episode, but a v3 file written in one piece (a conversion, an aggregation) holds
//! hundreds of episodes in one: read episode by episode, each would decode the whole group, and a
//! replay of every episode would grow with their number squared.

use super::columns::{VectorColumn, float_scalars, int_column};
use arrow::array::RecordBatch;
use parquet::arrow::ProjectionMask;
use parquet::arrow::arrow_reader::{ArrowReaderMetadata, ParquetRecordBatchReaderBuilder};
use parquet::file::statistics::Statistics;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// The footers kept (the files most recently read): one per file a replay's threads are reading,
/// with room to spare.
const FOOTERS_KEPT: usize = 16;
/// The decoded row groups kept, bytes: a row group of a million six-entry frames (a 100 MB v3 file,
/// LeRobot's default size, holds one to three) decodes to 72 MB per feature, and a forward replay
/// reads two features on each of its threads.
const DECODED_KEPT: usize = 512 << 20;

/// One row group's frames of one feature, decoded.
pub struct Rows {
    /// Per row, its frame index and timestamp (empty where the file has no such column).
    pub frames: Vec<i64>,
    pub stamps: Vec<f64>,
    /// Per entry of the feature, its value in each row.
    pub values: Vec<Vec<f64>>,
    /// Each episode's rows in file order (None: the file has no episode column, every row is the
    /// episode's).
    episodes: Option<HashMap<i64, Vec<usize>>>,
}

impl Rows {
    /// `episode`'s rows, in file order.
    fn of(&self, episode: i64) -> Vec<usize> {
        match &self.episodes {
            Some(map) => map.get(&episode).cloned().unwrap_or_default(),
            None => (0..self.frames.len().max(self.stamps.len())).collect(),
        }
    }

    fn bytes(&self) -> usize {
        let rows = self.frames.len().max(self.stamps.len());
        rows * (8 * (2 + self.values.len()) + 2 * std::mem::size_of::<usize>())
    }
}

/// One episode's frames of a feature, in file order: frame indices, timestamps (either may be
/// empty), values per entry.
pub type EpisodeRows = (Vec<i64>, Vec<f64>, Vec<Vec<f64>>);

type Decoded = Arc<OnceLock<Result<Arc<Rows>, String>>>;

struct Kept {
    key: (PathBuf, String, usize),
    rows: Decoded,
    bytes: usize,
    used: u64,
}

/// The data files' footers and shared row groups, kept across the episodes read (shared by the
/// threads reading them).
#[derive(Default)]
pub struct DataFiles {
    footers: Mutex<Vec<(PathBuf, ArrowReaderMetadata)>>,
    decoded: Mutex<(Vec<Kept>, u64)>,
}

impl std::fmt::Debug for DataFiles {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("DataFiles { .. }")
    }
}

impl DataFiles {
    /// `episode`'s frames of `feature` (`width` entries) in the data file `path`; `shared`: the file
    /// holds several episodes, told apart by its `episode_index` column. The error is the line to
    /// say of the file.
    pub fn episode(&self, path: &Path, feature: &str, width: usize, episode: i64, shared: bool) -> Result<EpisodeRows, String> {
        let footer = self.footer(path)?;
        let arrow_schema = footer.schema();
        let root_index = |name: &str| arrow_schema.fields().iter().position(|f| f.name() == name);
        let columns = || arrow_schema.fields().iter().map(|f| f.name().as_str()).collect::<Vec<_>>().join(", ");
        let feature_root = root_index(feature).ok_or_else(|| format!("no column '{feature}' (columns: {})", columns()))?;
        let (episode_root, frame_root, timestamp_root) = (root_index("episode_index"), root_index("frame_index"), root_index("timestamp"));
        if episode_root.is_none() && shared {
            return Err(format!("no column 'episode_index' to tell its episodes apart (columns: {})", columns()));
        }
        if frame_root.is_none() && timestamp_root.is_none() {
            return Err(format!("neither 'frame_index' nor 'timestamp' to time the frames (columns: {})", columns()));
        }
        let roots: Vec<usize> = std::iter::once(feature_root).chain([episode_root, frame_root, timestamp_root].into_iter().flatten()).collect();
        let (mut frames, mut stamps, mut values) = (Vec::new(), Vec::new(), vec![Vec::new(); width]);
        for (group, alone) in groups_holding(&footer, episode) {
            // a group of this episode alone is read once: kept, it would only take the memory
            let rows = if alone { Arc::new(decode(path, &footer, &roots, group, feature, width)?) } else { self.shared(path, &footer, &roots, group, feature, width)? };
            for row in rows.of(episode) {
                if !rows.frames.is_empty() {
                    frames.push(rows.frames[row]);
                }
                if !rows.stamps.is_empty() {
                    stamps.push(rows.stamps[row]);
                }
                for (column, all) in values.iter_mut().zip(&rows.values) {
                    column.push(all[row]);
                }
            }
        }
        Ok((frames, stamps, values))
    }

    /// The file's footer, parsed once while it is among the files most recently read.
    fn footer(&self, path: &Path) -> Result<ArrowReaderMetadata, String> {
        {
            let mut footers = self.footers.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(k) = footers.iter().position(|(p, _)| p == path) {
                let entry = footers.remove(k);
                let footer = entry.1.clone();
                footers.push(entry);
                return Ok(footer);
            }
        }
        let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
        let footer = ArrowReaderMetadata::load(&file, Default::default()).map_err(|e| e.to_string())?;
        let mut footers = self.footers.lock().unwrap_or_else(|e| e.into_inner());
        footers.push((path.to_path_buf(), footer.clone()));
        if footers.len() > FOOTERS_KEPT {
            footers.remove(0);
        }
        Ok(footer)
    }

    /// A row group of several episodes, decoded by the first episode that asks for it (the others
    /// wait for that one) and kept while it is among the most recently used within
    /// [`DECODED_KEPT`].
    fn shared(&self, path: &Path, footer: &ArrowReaderMetadata, roots: &[usize], group: usize, feature: &str, width: usize) -> Result<Arc<Rows>, String> {
        let key = (path.to_path_buf(), feature.to_string(), group);
        let slot: Decoded = {
            let mut guard = self.decoded.lock().unwrap_or_else(|e| e.into_inner());
            let (kept, clock) = &mut *guard;
            *clock += 1;
            match kept.iter_mut().find(|k| k.key == key) {
                Some(k) => {
                    k.used = *clock;
                    k.rows.clone()
                }
                None => {
                    let rows = Decoded::default();
                    kept.push(Kept { key: key.clone(), rows: rows.clone(), bytes: 0, used: *clock });
                    // the least recently used go first; the one just asked for stays
                    while kept.iter().map(|k| k.bytes).sum::<usize>() > DECODED_KEPT {
                        let Some(oldest) = kept.iter().enumerate().filter(|(_, k)| k.key != key).min_by_key(|(_, k)| k.used).map(|(i, _)| i) else { break };
                        kept.remove(oldest);
                    }
                    rows
                }
            }
        };
        let rows = slot.get_or_init(|| decode(path, footer, roots, group, feature, width).map(Arc::new)).clone()?;
        let mut guard = self.decoded.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(k) = guard.0.iter_mut().find(|k| k.key == key) {
            k.bytes = rows.bytes();
        }
        Ok(rows)
    }
}

/// The row groups that can hold `episode` by their statistics (all where a group has none), and
/// whether each holds it alone.
fn groups_holding(footer: &ArrowReaderMetadata, episode: i64) -> Vec<(usize, bool)> {
    let metadata = footer.metadata();
    let episode_leaf = footer.parquet_schema().columns().iter().position(|c| c.path().parts() == ["episode_index"]);
    (0..metadata.num_row_groups())
        .filter_map(|group| {
            let Some(leaf) = episode_leaf else { return Some((group, true)) };
            match metadata.row_group(group).column(leaf).statistics() {
                Some(Statistics::Int64(s)) => match (s.min_opt(), s.max_opt()) {
                    (Some(&lo), Some(&hi)) => (lo <= episode && episode <= hi).then_some((group, lo == hi)),
                    _ => Some((group, false)),
                },
                _ => Some((group, false)),
            }
        })
        .collect()
}

/// Decode row group `group` of the file at `path`, its root columns `roots` (`feature` of `width`
/// entries, and the bookkeeping columns it has).
fn decode(path: &Path, footer: &ArrowReaderMetadata, roots: &[usize], group: usize, feature: &str, width: usize) -> Result<Rows, String> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let builder = ParquetRecordBatchReaderBuilder::new_with_metadata(file, footer.clone());
    let mask = ProjectionMask::roots(builder.parquet_schema(), roots.iter().copied());
    let reader = builder.with_projection(mask).with_row_groups(vec![group]).build().map_err(|e| e.to_string())?;
    let mut rows = Rows { frames: Vec::new(), stamps: Vec::new(), values: vec![Vec::new(); width], episodes: None };
    let mut episode_of: Option<Vec<i64>> = None;
    for batch in reader {
        append(&batch.map_err(|e| e.to_string())?, feature, width, &mut rows, &mut episode_of)?;
    }
    rows.episodes = episode_of.map(|episodes| {
        let mut map: HashMap<i64, Vec<usize>> = HashMap::new();
        for (row, e) in episodes.into_iter().enumerate() {
            map.entry(e).or_default().push(row);
        }
        map
    });
    Ok(rows)
}

/// Append one record batch's rows.
fn append(batch: &RecordBatch, feature: &str, width: usize, rows: &mut Rows, episode_of: &mut Option<Vec<i64>>) -> Result<(), String> {
    if let Some(a) = batch.column_by_name("episode_index") {
        episode_of.get_or_insert_with(Vec::new).extend(int_column(a, "episode_index")?);
    }
    if let Some(a) = batch.column_by_name("frame_index") {
        rows.frames.extend(int_column(a, "frame_index")?);
    }
    if let Some(a) = batch.column_by_name("timestamp") {
        rows.stamps.extend(float_scalars(a, "timestamp")?);
    }
    let vectors = batch.column_by_name(feature).ok_or_else(|| format!("no column '{feature}'"))?;
    let vectors = VectorColumn::new(vectors.as_ref(), feature, width)?;
    for (k, column) in rows.values.iter_mut().enumerate() {
        column.extend((0..batch.num_rows()).map(|row| vectors.get(row, k)));
    }
    Ok(())
}
