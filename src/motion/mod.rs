//! Recorded motion of a real arm, read from where people keep it: LeRobot datasets (parquet), ROS 2
//! bags and armscope recordings (`.mcap`), CSV tables. Each source gives episodes: sample times and
//! named columns of values in the source's own units; [`joint_map`] turns them into the URDF's
//! coordinates. The commands an arm followed come beside its positions: a dataset's `action`, a bag's
//! trajectory controller ([`commands`]).

pub mod bag;
pub mod commands;
pub mod csv;
pub mod joint_map;
pub mod lerobot;
pub mod tick_lattice;

pub use joint_map::JointMap;

use crate::error::Error;
use std::path::{Path, PathBuf};

/// One recorded motion: samples at `time`, and per named column its values there.
#[derive(Clone, Debug, Default)]
pub struct Episode {
    /// How reports name it ("episode 3", the file's name).
    pub label: String,
    /// The dataset's episode index, where it has one.
    pub index: Option<i64>,
    /// Seconds from the episode's first sample, strictly increasing.
    pub time: Vec<f64>,
    /// The positions (or commands), in the source's units.
    pub columns: Vec<Column>,
    /// Measured joint efforts, named by joint (a ROS 2 bag's `effort`), N·m or N.
    pub effort: Vec<Column>,
    /// What the reader assumed or left out, one line each.
    pub notices: Vec<String>,
}

#[derive(Clone, Debug)]
pub struct Column {
    pub name: String,
    pub values: Vec<f64>,
}

impl Episode {
    pub fn column(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.name == name)
    }

    pub fn column_names(&self) -> Vec<&str> {
        self.columns.iter().map(|c| c.name.as_str()).collect()
    }

    /// The episode's samples up to `seconds` from its start.
    pub fn first_seconds(&self, seconds: f64) -> Episode {
        let kept = self.time.partition_point(|&t| t <= seconds);
        let cut = |columns: &[Column]| columns.iter().map(|c| Column { name: c.name.clone(), values: c.values[..kept.min(c.values.len())].to_vec() }).collect();
        Episode { time: self.time[..kept].to_vec(), columns: cut(&self.columns), effort: cut(&self.effort), ..self.clone() }
    }
}

/// What kind of thing a recording is: its units and naming follow from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SourceKind {
    /// A LeRobot dataset: columns named by motor (`shoulder_pan.pos`), in the motors' own units.
    LeRobot,
    /// A ROS 2 bag or an armscope `.mcap`: JointState positions by joint name, SI units.
    Bag,
    /// A CSV table: `t` and one column per joint, SI units.
    Csv,
}

/// A recording opened: which episodes it has, and each read on demand (a dataset of hundreds of
/// episodes is never held whole).
pub enum Source {
    LeRobot(lerobot::Dataset),
    Bag(bag::Bag),
    Csv(PathBuf),
}

impl Source {
    /// Open a LeRobot dataset folder, a `.mcap` file or a `.csv` file, told apart by what it is.
    pub fn open(path: &Path, topic: Option<&str>) -> Result<Self, Error> {
        let fail = |m: String| Error::flag(path.display().to_string(), m);
        if path.is_dir() {
            return Ok(Source::LeRobot(lerobot::Dataset::open(path)?));
        }
        if !path.exists() {
            return Err(fail("no such file or folder".into()));
        }
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("mcap") => Ok(Source::Bag(bag::Bag::open(path, topic)?)),
            Some("csv") => Ok(Source::Csv(path.to_path_buf())),
            _ => Err(fail("not a LeRobot dataset folder, a .mcap bag or a .csv table".into())),
        }
    }

    pub fn kind(&self) -> SourceKind {
        match self {
            Source::LeRobot(_) => SourceKind::LeRobot,
            Source::Bag(_) => SourceKind::Bag,
            Source::Csv(_) => SourceKind::Csv,
        }
    }

    /// The episodes it holds, by index (a bag or a table is one, index 0).
    pub fn episodes(&self) -> Vec<i64> {
        match self {
            Source::LeRobot(d) => d.episode_indices(),
            _ => vec![0],
        }
    }

    /// Read one episode; `feature` picks a LeRobot dataset's column group (`observation.state`,
    /// `action`).
    pub fn read(&self, episode: i64, feature: &str) -> Result<Episode, Error> {
        match self {
            Source::LeRobot(d) => d.read_episode(episode, feature),
            Source::Bag(b) => b.read(),
            Source::Csv(path) => csv::read(path),
        }
    }

    /// An episode's commands and what the follower did, sampled at the same times (for the forward
    /// replay): a LeRobot episode's `action` beside its `feature`; a bag's trajectory-controller
    /// commands (where `commands` says, else on the one command topic there is) at its joint states'
    /// stamps.
    pub fn read_forward(&self, episode: i64, feature: &str, commands: &commands::CommandSource) -> Result<(Episode, Episode), Error> {
        match self {
            Source::LeRobot(d) => Ok((d.read_episode(episode, "action")?, d.read_episode(episode, feature)?)),
            Source::Bag(b) => commands::read_forward(b, commands),
            Source::Csv(path) => Err(Error::flag("--forward", format!("{}: a table holds no commands beside the positions; a LeRobot dataset (action) or a ROS 2 bag with a trajectory controller's commands does", path.display()))),
        }
    }

    /// The rate the samples were taken at, Hz, where the source says it.
    pub fn fps(&self) -> Option<f64> {
        match self {
            Source::LeRobot(d) => Some(d.fps),
            _ => None,
        }
    }

    /// The robot type the dataset says it was recorded with (`so101_follower`), if any.
    pub fn robot_type(&self) -> Option<&str> {
        match self {
            Source::LeRobot(d) => d.robot_type.as_deref(),
            _ => None,
        }
    }
}

/// Times must go forward: the first sample where they do not, in one line.
pub fn check_increasing(time: &[f64], what: &str) -> Result<(), String> {
    for (i, w) in time.windows(2).enumerate() {
        if w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) {
            return Err(format!("{what}: timestamps do not increase at sample {} ({} s after {} s)", i + 1, w[1], w[0]));
        }
    }
    Ok(())
}

/// A recording ready to use on an arm: its source, the episodes asked for, the joint map, and what
/// was decided on the user's behalf (one notice each).
pub struct MappedRecording {
    pub source: Source,
    pub episodes: Vec<i64>,
    pub map: JointMap,
    pub notices: Vec<String>,
}

/// The unit of a LeRobot dataset's body joints, as `--units` names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BodyUnits {
    /// LeRobot's DEGREES normalisation (the SO followers' default since 2026-02-13).
    Degrees,
    /// LeRobot's RANGE_M100_100 normalisation (the default before).
    Range,
}

/// How the recording's values are to be read, where the user says: the body joints' unit and a
/// LeRobot calibration file (both for the built-in map; a map file gives its own).
#[derive(Clone, Copy, Debug, Default)]
pub struct Reading<'a> {
    pub units: Option<BodyUnits>,
    pub calibration: Option<&'a Path>,
}

/// The episodes the unit of a dataset's body joints is decided on (a bounded read of a dataset of
/// hundreds).
const UNIT_EPISODES: usize = 10;

/// What opening a recording for an arm gave: ready, or no map known from its columns to the arm's
/// joints (then a template of one to fill in).
pub enum Mapped {
    Ready(MappedRecording),
    NeedsMap { template: String },
}

/// Open a recording for `model`: the episodes asked for (default: all), and the joint map — the
/// user's file, else a built-in map chosen by the recording's columns (those of its first episode);
/// a LeRobot dataset's body joints in the unit `reading` gives, else the one its values tell (its
/// `action` and `feature` over its first episodes), else an error asking for it.
pub fn open_mapped(path: &Path, topic: Option<&str>, episodes: Option<&[i64]>, feature: &str, joint_map: Option<&Path>, reading: Reading, model: &crate::model::Model) -> Result<Mapped, Error> {
    let source = Source::open(path, topic)?;
    let episodes = match episodes {
        Some(list) => list.to_vec(),
        None => source.episodes(),
    };
    if episodes.is_empty() {
        return Err(Error::flag(path.display().to_string(), "no episodes"));
    }
    let mut notices = Vec::new();
    // the user's map of its own joints; or the calibration file a map without joints names, for
    // the built-in map (as --calibration gives it)
    let (own, map_calibration) = match joint_map {
        Some(file) => {
            let read = JointMap::read(file, model)?;
            if matches!(read, joint_map::MapFile::Joints(_)) && reading.units.is_some() {
                return Err(Error::flag("--units", format!("{} gives each joint's unit (its 'unit' fields)", file.display())));
            }
            if reading.calibration.is_some() {
                return Err(Error::flag("--calibration", format!("{} names its calibration file itself (its 'calibration' field)", file.display())));
            }
            match read {
                joint_map::MapFile::Joints(map) => (Some(map), None),
                joint_map::MapFile::Calibration(calibration) => (None, Some((file, calibration))),
            }
        }
        None => (None, None),
    };
    let map = match own {
        Some(map) => map,
        None => {
            let calibration_file = reading.calibration.or(map_calibration.as_ref().map(|(_, c)| c.as_path()));
            // where a calibration came from, for an error: the flag, or the map file naming it
            let calibration_source = || map_calibration.as_ref().map_or_else(|| "--calibration".to_string(), |(file, _)| file.display().to_string());
            let first = source.read(episodes[0], feature)?;
            match JointMap::builtin(source.kind(), model, &first) {
                Some(map) if source.kind() == SourceKind::LeRobot => {
                    // the first episodes' values, read once: they tell the unit and a range's width
                    let body: Vec<String> = map.entries.iter().filter(|e| e.unit != joint_map::Unit::Range0To100).map(|e| e.column.clone()).collect();
                    let told = reading.units.is_none() || (reading.units == Some(BodyUnits::Range) && calibration_file.is_none());
                    let values = if told { column_values(&source, &episodes, &[feature, "action"], &body) } else { Vec::new() };
                    let (unit, why) = body_unit(&values, reading.units, path)?;
                    let calibration = match calibration_file {
                        Some(c) => Some((c, joint_map::read_calibration(c)?)),
                        None => None,
                    };
                    let mut map = map.with_body_unit(unit, calibration.as_ref().map(|(p, r)| (*p, r)))?;
                    let how = match (unit, calibration_file) {
                        (joint_map::Unit::RangeM100To100, None) => lattice_ranges(&values, feature, &mut map, model),
                        (_, Some(c)) => format!("; angles from the middle of each motor's calibrated range in {}", c.display()),
                        _ => String::new(),
                    };
                    if let Some(why) = why {
                        notices.push(format!("{}: the body joints {why}{how}", path.display()));
                    } else if !how.is_empty() {
                        notices.push(format!("{}: the body joints in {}{how}", path.display(), unit.name()));
                    }
                    map
                }
                Some(map) => {
                    if reading.units.is_some() || calibration_file.is_some() {
                        return Err(Error::flag(if reading.units.is_some() { "--units".to_string() } else { calibration_source() }, format!("{}: a calibration file or a unit is for a LeRobot dataset's built-in map; this recording's columns are named by joint in SI units", path.display())));
                    }
                    map
                }
                None if map_calibration.is_some() => {
                    return Err(Error::flag(calibration_source(), format!("no [joints.NAME] entries, and armscope knows no built-in map from {}'s columns to {}'s joints: give each joint's column and unit", path.display(), model.source.display())));
                }
                None => return Ok(Mapped::NeedsMap { template: JointMap::template(model, &first.column_names()) }),
            }
        }
    };
    Ok(Mapped::Ready(MappedRecording { source, episodes, map, notices }))
}

/// Without a calibration file, each body joint's calibrated range as the tick lattice of its
/// `feature` values tells it (the follower's calibration turns its goals into ticks too;
/// [`tick_lattice`]); a joint whose values do not tell it maps onto its URDF limits. What was done,
/// as the tail of the unit's notice.
fn lattice_ranges(values: &[Series], feature: &str, map: &mut JointMap, model: &crate::model::Model) -> String {
    let (mut read, mut unread) = (Vec::new(), Vec::new());
    for entry in map.entries.iter_mut().filter(|e| e.unit == joint_map::Unit::RangeM100To100) {
        let name = &model.joints[entry.joint].name;
        let all: Vec<f64> = values.iter().filter(|s| s.group == feature && s.column == entry.column).flat_map(|s| s.values.iter().copied()).collect();
        match tick_lattice::range_width(&all) {
            Some(width) => {
                entry.calibration = Some(joint_map::MotorCalibration { drive_mode: 0, homing_offset: 0, range_min: 0.0, range_max: f64::from(width) });
                read.push(format!("{name} {width} ({:.3} rad)", f64::from(width) * std::f64::consts::TAU / joint_map::TICKS_PER_360));
            }
            None => unread.push(name.clone()),
        }
    }
    let mut how = String::from("; without its calibration file (--calibration)");
    if !read.is_empty() {
        how += &format!(" each joint's calibrated range read from the tick lattice of its {feature} values (ticks: {}), angles from the range's middle (where LeRobot's degrees have their zero; the URDF's zero assumed there)", read.join(", "));
    }
    if !unread.is_empty() {
        how += &format!("{} −100…100 mapped onto the URDF limits of {} (too few distinct values to tell the range): approximate", if read.is_empty() { "" } else { ";" }, unread.join(", "));
    }
    how
}

/// One column's values in one feature of one episode.
struct Series {
    group: String,
    column: String,
    values: Vec<f64>,
}

/// The values of `columns` in `groups` (a dataset's features) over the first episodes, per feature,
/// column and episode (a bounded read of a dataset of hundreds).
fn column_values(source: &Source, episodes: &[i64], groups: &[&str], columns: &[String]) -> Vec<Series> {
    let mut series = Vec::new();
    for &index in episodes.iter().take(UNIT_EPISODES) {
        for group in groups {
            let Ok(episode) = source.read(index, group) else { continue };
            for column in columns {
                if let Some(c) = episode.column(column) {
                    series.push(Series { group: group.to_string(), column: column.clone(), values: c.values.clone() });
                }
            }
        }
    }
    series
}

/// The unit of a dataset's body joints: `units` where given (no reason to say), else what the
/// `values` of its first episodes tell (and why), else one line asking for it.
fn body_unit(values: &[Series], units: Option<BodyUnits>, path: &Path) -> Result<(joint_map::Unit, Option<String>), Error> {
    match units {
        Some(BodyUnits::Degrees) => return Ok((joint_map::Unit::Deg, None)),
        Some(BodyUnits::Range) => return Ok((joint_map::Unit::RangeM100To100, None)),
        None => {}
    }
    let columns: Vec<(&str, &[f64])> = values.iter().map(|s| (s.column.as_str(), s.values.as_slice())).collect();
    match joint_map::decide_body_unit(&columns) {
        Ok((unit, why)) => Ok((unit, Some(why))),
        Err(why) => Err(Error::flag(path.display().to_string(), format!("the body joints' unit cannot be told from the data: {why}; say which with --units degrees or --units range (or a joint map's unit)"))),
    }
}
