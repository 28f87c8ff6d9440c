//! LeRobot datasets of known motions, written as LeRobot writes them (parquet through arrow-rs, the
//! layouts of `../shared/reference/lerobot-format.md`): v3.0 with several episodes per data file
//! (one row group each, an episodes table), v2.1 with one file per episode and `episodes.jsonl`.
//! Positions are quantized as the encoder and LeRobot's normalization quantize them.

use arrow::array::{ArrayRef, FixedSizeListArray, Float32Array, Int64Array, RecordBatch};
use arrow::datatypes::{DataType, Field, Schema};
use parquet::arrow::ArrowWriter;
use std::path::Path;
use std::sync::Arc;

/// One joint's true motion: center + Σ a·sin(ω t + φ), with its exact derivatives.
#[derive(Clone, Debug)]
pub struct Sines {
    pub center: f64,
    pub terms: Vec<(f64, f64, f64)>,
}

impl Sines {
    pub fn q(&self, t: f64) -> f64 {
        self.center + self.terms.iter().map(|(a, w, p)| a * (w * t + p).sin()).sum::<f64>()
    }
    pub fn qd(&self, t: f64) -> f64 {
        self.terms.iter().map(|(a, w, p)| a * w * (w * t + p).cos()).sum()
    }
    pub fn qdd(&self, t: f64) -> f64 {
        self.terms.iter().map(|(a, w, p)| -a * w * w * (w * t + p).sin()).sum()
    }
}

/// How the dataset stores one joint: LeRobot's DEGREES (value = deg(sign·(q − offset)) on the
/// encoder's 4095-per-360° lattice) or RANGE_0_100 over [lower, upper] (1400 ticks of travel).
#[derive(Clone, Copy, Debug)]
pub enum Storage {
    Degrees { sign: f64, offset: f64 },
    Range0To100 { lower: f64, upper: f64 },
    /// LeRobot's RANGE_M100_100 with a calibrated range of ticks: the tick is q's from the range's
    /// middle (LeRobot's DEGREES zero, 4095 ticks a turn), clamped into the range.
    RangeM100To100 { range_min: f64, range_max: f64 },
}

pub const RANGE_TICKS: f64 = 1400.0;

impl Storage {
    pub fn value(&self, q: f64) -> f32 {
        match *self {
            Storage::Degrees { sign, offset } => {
                let degrees = (sign * (q - offset)).to_degrees();
                let tick = (degrees * 4095.0 / 360.0 + 2047.5).round();
                ((tick - 2047.5) * 360.0 / 4095.0) as f32
            }
            Storage::Range0To100 { lower, upper } => {
                let tick = ((q - lower) / (upper - lower) * RANGE_TICKS).round();
                (tick / RANGE_TICKS * 100.0) as f32
            }
            Storage::RangeM100To100 { range_min, range_max } => {
                let tick = (0.5 * (range_min + range_max) + q.to_degrees() * 4095.0 / 360.0).round().clamp(range_min, range_max);
                ((tick - range_min) / (range_max - range_min) * 200.0 - 100.0) as f32
            }
        }
    }
}

/// The SO-101's true motions in episode `e` of the test datasets: every joint swinging through most of
/// its range at up to ~4 rad/s (shoulder_lift with a fast 8.5 rad/s component that takes it over
/// 2.9 N·m with 0.2 kg at the tool), phases shifted per episode.
pub fn so101_motions(e: usize) -> Vec<Sines> {
    let p = e as f64 * 0.7;
    let s = |center: f64, terms: &[(f64, f64, f64)]| Sines { center, terms: terms.iter().map(|&(a, w, ph)| (a, w, ph + p)).collect() };
    vec![
        s(0.1, &[(0.9, 1.1, 0.0), (0.25, 2.7, 1.0)]),
        s(0.3, &[(0.9, 1.6, 0.3), (0.4, 8.5, 0.0)]),
        s(-0.3, &[(0.8, 1.7, 2.0), (0.2, 3.7, 0.0)]),
        s(0.0, &[(0.5, 2.1, 0.5), (0.2, 4.3, 0.0)]),
        s(0.0, &[(1.2, 0.9, 0.0), (0.3, 2.3, 1.0)]),
        s(0.8, &[(0.6, 1.9, 0.0)]),
    ]
}

pub const SO101_NAMES: [&str; 6] = ["shoulder_pan.pos", "shoulder_lift.pos", "elbow_flex.pos", "wrist_flex.pos", "wrist_roll.pos", "gripper.pos"];

pub struct Spec {
    pub fps: f64,
    pub frames: usize,
    /// Per episode, per joint (the six columns), its true motion.
    pub episodes: Vec<Vec<Sines>>,
    pub storage: Vec<Storage>,
    /// Per episode, frame and joint, what the follower did (rad), where it differs from the command
    /// (`observation.state`; the command, `action`, is `episodes`); None: the follower is the command.
    pub observed: Option<Vec<Vec<Vec<f64>>>>,
}

impl Spec {
    fn values(&self, episode: usize) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.frames * 6);
        for f in 0..self.frames {
            let t = f as f64 / self.fps;
            for (j, motion) in self.episodes[episode].iter().enumerate() {
                out.push(self.storage[j].value(motion.q(t)));
            }
        }
        out
    }

    fn observed_values(&self, episode: usize) -> Option<Vec<f32>> {
        let observed = &self.observed.as_ref()?[episode];
        Some((0..self.frames).flat_map(|f| (0..6).map(move |j| self.storage[j].value(observed[f][j]))).collect())
    }

    fn batch(&self, episode: usize, first_index: i64) -> RecordBatch {
        let n = self.frames;
        let item = Arc::new(Field::new("item", DataType::Float32, true));
        let action = FixedSizeListArray::try_new(item.clone(), 6, Arc::new(Float32Array::from(self.values(episode))), None).unwrap();
        let state = match self.observed_values(episode) {
            Some(values) => FixedSizeListArray::try_new(item.clone(), 6, Arc::new(Float32Array::from(values)), None).unwrap(),
            None => action.clone(),
        };
        let columns: Vec<ArrayRef> = vec![
            Arc::new(action),
            Arc::new(state),
            Arc::new(Float32Array::from((0..n).map(|f| (f as f64 / self.fps) as f32).collect::<Vec<_>>())),
            Arc::new(Int64Array::from((0..n as i64).collect::<Vec<_>>())),
            Arc::new(Int64Array::from(vec![episode as i64; n])),
            Arc::new(Int64Array::from((first_index..first_index + n as i64).collect::<Vec<_>>())),
            Arc::new(Int64Array::from(vec![0i64; n])),
        ];
        RecordBatch::try_new(schema(), columns).unwrap()
    }

    fn info(&self, version: &str, data_path: &str) -> String {
        let names: Vec<String> = SO101_NAMES.iter().map(|n| format!("\"{n}\"")).collect();
        let names = names.join(", ");
        format!(
            r#"{{
    "codebase_version": "{version}",
    "robot_type": "so101_follower",
    "total_episodes": {episodes},
    "total_frames": {total},
    "total_tasks": 1,
    "chunks_size": 1000,
    "fps": {fps},
    "splits": {{"train": "0:{episodes}"}},
    "data_path": "{data_path}",
    "video_path": null,
    "features": {{
        "action": {{"dtype": "float32", "shape": [6], "names": [{names}]}},
        "observation.state": {{"dtype": "float32", "shape": [6], "names": [{names}]}},
        "timestamp": {{"dtype": "float32", "shape": [1], "names": null}},
        "frame_index": {{"dtype": "int64", "shape": [1], "names": null}},
        "episode_index": {{"dtype": "int64", "shape": [1], "names": null}},
        "index": {{"dtype": "int64", "shape": [1], "names": null}},
        "task_index": {{"dtype": "int64", "shape": [1], "names": null}}
    }}
}}
"#,
            episodes = self.episodes.len(),
            total = self.episodes.len() * self.frames,
            fps = self.fps,
        )
    }

    /// v3.0: every episode in `data/chunk-000/file-000.parquet`, one row group each.
    pub fn write_v3(&self, root: &Path) {
        self.write_v3_grouped(root, true);
    }

    /// v3.0 as a conversion or an aggregation writes it: every episode in one row group of
    /// `data/chunk-000/file-000.parquet`.
    pub fn write_v3_one_row_group(&self, root: &Path) {
        self.write_v3_grouped(root, false);
    }

    fn write_v3_grouped(&self, root: &Path, group_per_episode: bool) {
        std::fs::create_dir_all(root.join("meta/episodes/chunk-000")).unwrap();
        std::fs::create_dir_all(root.join("data/chunk-000")).unwrap();
        std::fs::write(root.join("meta/info.json"), self.info("v3.0", "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet")).unwrap();
        let file = std::fs::File::create(root.join("data/chunk-000/file-000.parquet")).unwrap();
        let mut writer = ArrowWriter::try_new(file, schema(), None).unwrap();
        for e in 0..self.episodes.len() {
            writer.write(&self.batch(e, (e * self.frames) as i64)).unwrap();
            if group_per_episode {
                writer.flush().unwrap();
            }
        }
        writer.close().unwrap();
        let count = self.episodes.len() as i64;
        let frames = self.frames as i64;
        let episodes_schema = Arc::new(Schema::new(
            ["episode_index", "length", "data/chunk_index", "data/file_index", "dataset_from_index", "dataset_to_index"].map(|n| Field::new(n, DataType::Int64, false)).to_vec(),
        ));
        let column = |f: &dyn Fn(i64) -> i64| -> ArrayRef { Arc::new(Int64Array::from((0..count).map(f).collect::<Vec<_>>())) };
        let batch = RecordBatch::try_new(episodes_schema.clone(), vec![column(&|e| e), column(&|_| frames), column(&|_| 0), column(&|_| 0), column(&|e| e * frames), column(&|e| (e + 1) * frames)]).unwrap();
        let file = std::fs::File::create(root.join("meta/episodes/chunk-000/file-000.parquet")).unwrap();
        let mut writer = ArrowWriter::try_new(file, episodes_schema, None).unwrap();
        writer.write(&batch).unwrap();
        writer.close().unwrap();
    }

    /// v2.1: `data/chunk-000/episode_00000N.parquet` per episode, `meta/episodes.jsonl`.
    pub fn write_v21(&self, root: &Path) {
        std::fs::create_dir_all(root.join("meta")).unwrap();
        std::fs::create_dir_all(root.join("data/chunk-000")).unwrap();
        std::fs::write(root.join("meta/info.json"), self.info("v2.1", "data/chunk-{episode_chunk:03d}/episode_{episode_index:06d}.parquet")).unwrap();
        let mut jsonl = String::new();
        for e in 0..self.episodes.len() {
            let file = std::fs::File::create(root.join(format!("data/chunk-000/episode_{e:06}.parquet"))).unwrap();
            let mut writer = ArrowWriter::try_new(file, schema(), None).unwrap();
            writer.write(&self.batch(e, (e * self.frames) as i64)).unwrap();
            writer.close().unwrap();
            jsonl += &format!("{{\"episode_index\": {e}, \"tasks\": [\"wave\"], \"length\": {}}}\n", self.frames);
        }
        std::fs::write(root.join("meta/episodes.jsonl"), jsonl).unwrap();
    }
}

pub fn schema() -> Arc<Schema> {
    let list = DataType::FixedSizeList(Arc::new(Field::new("item", DataType::Float32, true)), 6);
    Arc::new(Schema::new(vec![
        Field::new("action", list.clone(), false),
        Field::new("observation.state", list, false),
        Field::new("timestamp", DataType::Float32, false),
        Field::new("frame_index", DataType::Int64, false),
        Field::new("episode_index", DataType::Int64, false),
        Field::new("index", DataType::Int64, false),
        Field::new("task_index", DataType::Int64, false),
    ]))
}
