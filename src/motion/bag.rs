//! ROS 2 bags and armscope recordings (`.mcap`): the joint states on one topic —
//! `sensor_msgs/msg/JointState` in CDR (rosbag2, `--mcap-encoding ros2`) or `foxglove.JointStates`
//! in protobuf (armscope's default encoding) — as an episode with a column per joint, in SI units,
//! timed by the messages' header stamps (their log times where a stamp is zero).

use super::{Column, Episode, check_increasing};
use crate::error::Error;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const ROS2_JOINT_STATE: &str = "sensor_msgs/msg/JointState";
const FOXGLOVE_JOINT_STATES: &str = "foxglove.JointStates";

#[derive(Debug)]
pub struct Bag {
    pub path: PathBuf,
    /// The topic read.
    pub topic: String,
}

impl Bag {
    /// Open a bag and pick its joint-state topic: `topic`, else `/joint_states`, else the only one.
    pub fn open(path: &Path, topic: Option<&str>) -> Result<Self, Error> {
        let fail = |m: String| Error::flag(path.display().to_string(), m);
        let bytes = std::fs::read(path).map_err(|e| fail(e.to_string()))?;
        let channels = channels(path, &bytes)?;
        let all: Vec<String> = channels.iter().map(|c| c.topic.clone()).collect();
        let topics = topics_of(&channels, &[ROS2_JOINT_STATE, FOXGLOVE_JOINT_STATES]);
        let chosen = match topic {
            Some(t) if topics.iter().any(|x| x == t) => t.to_string(),
            Some(t) => return Err(Error::flag("--topic", format!("{}: no joint states on '{t}' (joint-state topics: {})", path.display(), list(&topics)))),
            None if topics.iter().any(|x| x == "/joint_states") => "/joint_states".to_string(),
            None if topics.len() == 1 => topics[0].clone(),
            None if topics.is_empty() => return Err(fail(format!("no {ROS2_JOINT_STATE} or {FOXGLOVE_JOINT_STATES} topic (topics: {})", list(&all)))),
            None => return Err(Error::flag("--topic", format!("{}: several joint-state topics, choose one: {}", path.display(), topics.join(", ")))),
        };
        Ok(Self { path: path.to_path_buf(), topic: chosen })
    }

    /// The topic's messages as one episode: a column per joint named in the first message.
    pub fn read(&self) -> Result<Episode, Error> {
        Ok(self.read_stamped()?.1)
    }

    /// [`Bag::read`], and each sample's stamp (ns since the epoch, or since the bag's clock's zero).
    pub(super) fn read_stamped(&self) -> Result<(Vec<i64>, Episode), Error> {
        self.read_stamped_from(&self.bytes()?)
    }

    /// The bag's bytes, read whole.
    pub(super) fn bytes(&self) -> Result<Vec<u8>, Error> {
        std::fs::read(&self.path).map_err(|e| Error::flag(self.path.display().to_string(), e.to_string()))
    }

    /// [`Bag::read_stamped`] from the bag's bytes, already read.
    pub(super) fn read_stamped_from(&self, bytes: &[u8]) -> Result<(Vec<i64>, Episode), Error> {
        let fail = |m: String| Error::flag(self.path.display().to_string(), m);
        let mut names: Vec<String> = Vec::new();
        let mut stamps: Vec<i64> = Vec::new();
        let mut positions: Vec<Vec<f64>> = Vec::new();
        let mut efforts: Vec<Vec<f64>> = Vec::new();
        let mut has_effort = true;
        let mut skipped = 0usize;
        for message in mcap::MessageStream::new(bytes).map_err(|e| fail(e.to_string()))? {
            let message = message.map_err(|e| fail(e.to_string()))?;
            if message.channel.topic != self.topic {
                continue;
            }
            let schema = message.channel.schema.as_ref().map(|s| s.name.as_str()).unwrap_or("");
            let (stamp, joint_names, position, effort) = match schema {
                ROS2_JOINT_STATE => {
                    use crate::ros2::Message as _;
                    let js = crate::ros2::messages::JointState::decode(&message.data).map_err(|e| fail(format!("{}: {e}", self.topic)))?;
                    let stamp = js.header.stamp.nanos();
                    (stamp, js.name, js.position, js.effort)
                }
                _ => {
                    use prost::Message as _;
                    let js = foxglove::messages::JointStates::decode(&message.data[..]).map_err(|e| fail(format!("{}: {e}", self.topic)))?;
                    let stamp = js.timestamp.map(|t| t.sec() as i64 * 1_000_000_000 + t.nsec() as i64).unwrap_or(0);
                    let effort: Vec<f64> = js.joints.iter().map(|j| j.effort.unwrap_or(f64::NAN)).collect();
                    let effort = if effort.iter().all(|e| e.is_nan()) { Vec::new() } else { effort };
                    (stamp, js.joints.iter().map(|j| j.name.clone()).collect(), js.joints.iter().map(|j| j.position.unwrap_or(f64::NAN)).collect(), effort)
                }
            };
            if names.is_empty() {
                names = joint_names.clone();
                positions = vec![Vec::new(); names.len()];
                efforts = vec![Vec::new(); names.len()];
            }
            if joint_names != names || position.len() != names.len() {
                // another publisher's joints on the same topic: not this series
                skipped += 1;
                continue;
            }
            let nanos = if stamp != 0 { stamp } else { message.log_time as i64 };
            stamps.push(nanos);
            for (column, value) in positions.iter_mut().zip(&position) {
                column.push(*value);
            }
            if effort.len() == names.len() {
                for (column, value) in efforts.iter_mut().zip(&effort) {
                    column.push(*value);
                }
            } else {
                has_effort = false;
            }
        }
        if stamps.is_empty() {
            return Err(fail(format!("no messages on {}", self.topic)));
        }
        // from the first stamp in whole nanoseconds: epoch seconds in an f64 keep only ~0.2 µs
        let t0 = stamps[0];
        let time: Vec<f64> = stamps.iter().map(|s| (s - t0) as f64 * 1e-9).collect();
        check_increasing(&time, &self.topic).map_err(fail)?;
        let mut notices = Vec::new();
        if skipped > 0 {
            notices.push(format!("{}: {skipped} messages on {} name other joints than its first ({}); left out", self.path.display(), self.topic, names.join(", ")));
        }
        let columns = names.iter().cloned().zip(positions).map(|(name, values)| Column { name, values }).collect();
        let effort = if has_effort { names.iter().cloned().zip(efforts).map(|(name, values)| Column { name, values }).collect() } else { Vec::new() };
        let label = self.path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        Ok((stamps, Episode { label, index: None, time, columns, effort, notices }))
    }
}


/// Every channel of a bag: from its summary, else by walking its messages.
pub(super) fn channels(path: &Path, bytes: &[u8]) -> Result<Vec<std::sync::Arc<mcap::Channel<'static>>>, Error> {
    let fail = |m: String| Error::flag(path.display().to_string(), m);
    let summary = mcap::Summary::read(bytes).map_err(|e| fail(e.to_string()))?;
    Ok(match summary {
        Some(s) => s.channels.values().cloned().collect(),
        None => {
            let mut seen = BTreeMap::new();
            for m in mcap::MessageStream::new(bytes).map_err(|e| fail(e.to_string()))? {
                let m = m.map_err(|e| fail(e.to_string()))?;
                seen.entry(m.channel.id).or_insert(m.channel.clone());
            }
            seen.into_values().collect()
        }
    })
}

/// The topics (sorted, once each) whose schema is one of `schemas`.
pub(super) fn topics_of(channels: &[std::sync::Arc<mcap::Channel<'static>>], schemas: &[&str]) -> Vec<String> {
    let mut topics: Vec<String> = channels.iter().filter(|c| c.schema.as_ref().is_some_and(|s| schemas.contains(&s.name.as_str()))).map(|c| c.topic.clone()).collect();
    topics.sort();
    topics.dedup();
    topics
}

pub(super) fn list(items: &[String]) -> String {
    if items.is_empty() { "none".into() } else { items.join(", ") }
}
