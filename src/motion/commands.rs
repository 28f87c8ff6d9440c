//! A ROS 2 arm's commands in a bag, for the forward replay: what its trajectory controller followed
//! (`control_msgs/msg/JointTrajectoryControllerState`: the set point at each update, `reference`,
//! else `desired`) or what it was sent (`trajectory_msgs/msg/JointTrajectory`: each message's points
//! from its stamp on, a newer message replacing what an older one planned from the newer's start,
//! the last point held after it) or what a forward command controller was sent
//! (`std_msgs/msg/Float64MultiArray`: a position per joint in the controller's joint order, which the
//! message does not carry and the user gives; at its log time, held until the next). Set points are
//! joined by straight lines (a forward controller's held) and sampled at the joint states' stamps, so
//! that the commands and the follower come as one episode each at the same times.

use super::bag::{Bag, channels, list, topics_of};
use super::{Column, Episode, check_increasing};
use crate::error::Error;
use crate::ros2::messages::Message as _;
use crate::ros2::trajectory::{ControllerStateLayout, Float64MultiArray, JointTrajectory};

const CONTROLLER_STATE: &str = "control_msgs/msg/JointTrajectoryControllerState";
const TRAJECTORY: &str = "trajectory_msgs/msg/JointTrajectory";
const POSITION_ARRAY: &str = "std_msgs/msg/Float64MultiArray";

/// Where a bag's commands are: the topic (None: the one there is) and, for a forward command
/// controller's arrays, the joints in the controller's order.
#[derive(Clone, Debug, Default)]
pub struct CommandSource {
    pub topic: Option<String>,
    pub joints: Option<Vec<String>>,
}

/// A controller's set points: when (ns, as the joint states are stamped) and, per joint, where.
#[derive(Clone, Debug)]
pub struct Commands {
    pub topic: String,
    /// Which message and field they were read from, as a notice says it.
    pub what: String,
    pub joints: Vec<String>,
    pub stamps: Vec<i64>,
    /// Per joint, a position at each stamp.
    pub positions: Vec<Vec<f64>>,
    /// Whether the last set point holds after it (a trajectory's end) or the commands stop there (a
    /// controller's last update).
    pub held_after_end: bool,
    /// Whether each set point holds until the next (a forward controller's command) rather than
    /// leading to it on a line (a trajectory's interpolation, a controller's samples of one).
    pub stepwise: bool,
    pub notices: Vec<String>,
}

/// The commands topic of `bag`: `asked`, else its one controller-state topic, else its one trajectory
/// topic, else its one array topic; with its message type.
fn choose_topic(bag: &Bag, channels: &[std::sync::Arc<mcap::Channel<'static>>], asked: Option<&str>) -> Result<(String, &'static str), Error> {
    let states = topics_of(channels, &[CONTROLLER_STATE]);
    let trajectories = topics_of(channels, &[TRAJECTORY]);
    let arrays = topics_of(channels, &[POSITION_ARRAY]);
    let kind = |t: &str| [(&states, CONTROLLER_STATE), (&trajectories, TRAJECTORY), (&arrays, POSITION_ARRAY)].into_iter().find(|(topics, _)| topics.iter().any(|s| s == t)).map(|(_, k)| k);
    let candidates: Vec<String> = states.iter().chain(&trajectories).chain(&arrays).cloned().collect();
    let path = bag.path.display();
    match asked {
        Some(t) => kind(t).map(|k| (t.to_string(), k)).ok_or_else(|| Error::flag("--command-topic", format!("{path}: no {CONTROLLER_STATE}, {TRAJECTORY} or {POSITION_ARRAY} on '{t}' (command topics: {})", list(&candidates)))),
        None => match (states.as_slice(), trajectories.as_slice(), arrays.as_slice()) {
            ([one], _, _) => Ok((one.clone(), CONTROLLER_STATE)),
            ([], [one], _) => Ok((one.clone(), TRAJECTORY)),
            ([], [], [one]) => Ok((one.clone(), POSITION_ARRAY)),
            ([], [], []) => Err(Error::flag(
                "--forward",
                format!(
                    "{path}: no commands to follow: a forward replay of a bag needs a trajectory controller's {CONTROLLER_STATE}, the {TRAJECTORY} it was sent or a forward command controller's {POSITION_ARRAY} (topics: {})",
                    list(&channels.iter().map(|c| c.topic.clone()).collect::<Vec<_>>())
                ),
            )),
            _ => Err(Error::flag("--command-topic", format!("{path}: several command topics, choose one: {}", candidates.join(", ")))),
        },
    }
}

/// Read the commands `from` asks for (or on the one command topic there is) in `bag`.
pub fn read(bag: &Bag, from: &CommandSource) -> Result<Commands, Error> {
    read_from(bag, &bag.bytes()?, from)
}

/// [`read`] from the bag's bytes, already read.
fn read_from(bag: &Bag, bytes: &[u8], from: &CommandSource) -> Result<Commands, Error> {
    let fail = |m: String| Error::flag(bag.path.display().to_string(), m);
    let channels = channels(&bag.path, bytes)?;
    let asked = from.topic.as_deref();
    let (topic, kind) = choose_topic(bag, &channels, asked)?;
    // an array names no joints: the controller's order is the user's to give
    let array_joints = match (kind, &from.joints) {
        (POSITION_ARRAY, Some(joints)) => joints.clone(),
        (POSITION_ARRAY, None) => {
            return Err(Error::flag("--command-joints", format!("{}: {topic} holds {POSITION_ARRAY}s, which name no joints: give its controller's joints in order", bag.path.display())));
        }
        _ => Vec::new(),
    };
    // a controller state is read by the layout its schema gives
    let layout = match kind {
        CONTROLLER_STATE => {
            let channel = channels.iter().find(|c| c.topic == topic).ok_or_else(|| fail(format!("{topic}: no such channel")))?;
            let schema = channel.schema.as_ref().ok_or_else(|| fail(format!("{topic}: no schema")))?;
            if schema.encoding != "ros2msg" {
                return Err(fail(format!("{topic}: its schema is {}, armscope reads ros2msg", schema.encoding)));
            }
            Some(ControllerStateLayout::from_definition(&String::from_utf8_lossy(&schema.data)).map_err(|e| fail(format!("{topic}: {e}")))?)
        }
        _ => None,
    };
    let mut joints: Vec<String> = Vec::new();
    // (stamp, positions in `joints` order)
    let mut set_points: Vec<(i64, Vec<f64>)> = Vec::new();
    let (mut other_joints, mut empty) = (0usize, 0usize);
    let mut field = "";
    for message in mcap::MessageStream::new(bytes).map_err(|e| fail(e.to_string()))? {
        let message = message.map_err(|e| fail(e.to_string()))?;
        if message.channel.topic != topic {
            continue;
        }
        let decode_error = |e: crate::ros2::CdrError| fail(format!("{topic}: {e}"));
        let (stamp, names, points): (i64, Vec<String>, Vec<(i64, Vec<f64>)>) = if let Some(layout) = &layout {
            let set = layout.set_point(&message.data).map_err(decode_error)?;
            if set.positions.is_empty() {
                empty += 1;
                continue;
            }
            field = set.field;
            (set.header.stamp.nanos(), set.joint_names, vec![(0, set.positions)])
        } else if kind == POSITION_ARRAY {
            let array = Float64MultiArray::decode(&message.data).map_err(decode_error)?;
            let values = array.data.get(array.data_offset as usize..).unwrap_or(&[]).to_vec();
            if values.len() != array_joints.len() {
                return Err(Error::flag("--command-joints", format!("{}: {topic} sends {} positions, --command-joints names {} joints", bag.path.display(), values.len(), array_joints.len())));
            }
            // no stamp: when it was logged
            (0, array_joints.clone(), vec![(0, values)])
        } else {
            let trajectory = JointTrajectory::decode(&message.data).map_err(decode_error)?;
            let points = trajectory.points.into_iter().filter(|p| p.positions.len() == trajectory.joint_names.len()).map(|p| (p.time_from_start.nanos(), p.positions)).collect::<Vec<_>>();
            if points.is_empty() {
                empty += 1;
                continue;
            }
            (trajectory.header.stamp.nanos(), trajectory.joint_names, points)
        };
        // a zero stamp: "now", when it was logged
        let start = if stamp != 0 { stamp } else { message.log_time as i64 };
        if joints.is_empty() {
            joints = names.clone();
        }
        let Some(order) = joints.iter().map(|j| names.iter().position(|n| n == j)).collect::<Option<Vec<usize>>>().filter(|_| names.len() == joints.len()) else {
            other_joints += 1;
            continue;
        };
        if kind == TRAJECTORY {
            // a newer trajectory replaces what an older one planned from the newer's start on
            while set_points.last().is_some_and(|(t, _)| *t >= start) {
                set_points.pop();
            }
        }
        for (offset, positions) in points {
            let at = start + offset;
            if kind == TRAJECTORY && set_points.last().is_some_and(|(t, _)| *t >= at) {
                continue;
            }
            set_points.push((at, order.iter().map(|&i| positions[i]).collect()));
        }
    }
    if set_points.is_empty() {
        return Err(fail(format!("{topic}: no set point with a position per joint")));
    }
    let stamps: Vec<i64> = set_points.iter().map(|(t, _)| *t).collect();
    let t0 = stamps[0];
    check_increasing(&stamps.iter().map(|s| (s - t0) as f64 * 1e-9).collect::<Vec<_>>(), &topic).map_err(fail)?;
    let positions = (0..joints.len()).map(|j| set_points.iter().map(|(_, p)| p[j]).collect()).collect();
    let what = match kind {
        CONTROLLER_STATE => format!("{CONTROLLER_STATE}'s {field}"),
        TRAJECTORY => format!("{TRAJECTORY}'s points"),
        _ => format!("{POSITION_ARRAY}s for {}", joints.join(", ")),
    };
    let mut notices = Vec::new();
    if asked.is_none() {
        // the kinds passed over for this one (a controller's state before what it was sent)
        let others: Vec<String> = topics_of(&channels, &[CONTROLLER_STATE, TRAJECTORY, POSITION_ARRAY]).into_iter().filter(|t| *t != topic).collect();
        if !others.is_empty() {
            notices.push(format!("{}: the commands followed are the {what} on {topic}, not those on {} (--command-topic to choose)", bag.path.display(), others.join(", ")));
        }
    }
    if other_joints > 0 {
        notices.push(format!("{}: {other_joints} messages on {topic} name other joints than its first ({}); left out", bag.path.display(), joints.join(", ")));
    }
    if empty > 0 {
        notices.push(format!("{}: {empty} messages on {topic} hold no position per joint; left out", bag.path.display()));
    }
    // a trajectory's last point and a forward controller's last command hold; a controller's state
    // stops where it was recorded
    Ok(Commands { topic, what, joints, stamps, positions, held_after_end: kind != CONTROLLER_STATE, stepwise: kind == POSITION_ARRAY, notices })
}

/// The commands and the joint states of `bag` as two episodes sampled at the joint states' stamps
/// while there are commands: commanded positions on straight lines between set points, or each
/// held until the next (a forward controller's). A joint the commands do not name is said in a
/// notice; the forward replay sends it where the real joint was.
pub fn read_forward(bag: &Bag, from: &CommandSource) -> Result<(Episode, Episode), Error> {
    let bytes = bag.bytes()?;
    let commands = read_from(bag, &bytes, from)?;
    let (stamps, observed) = bag.read_stamped_from(&bytes)?;
    let fail = |m: String| Error::flag(bag.path.display().to_string(), m);
    let (first, last) = (commands.stamps[0], *commands.stamps.last().unwrap_or(&commands.stamps[0]));
    let kept: Vec<usize> = (0..stamps.len()).filter(|&k| stamps[k] >= first && (commands.held_after_end || stamps[k] <= last)).collect();
    if kept.len() < 2 {
        let span = |a: i64, b: i64| format!("{:.3} s to {:.3} s", a as f64 * 1e-9, b as f64 * 1e-9);
        return Err(fail(format!(
            "the commands on {} ({}) and the joint states on {} ({}) do not overlap",
            commands.topic,
            span(first, last),
            bag.topic,
            span(stamps[0], *stamps.last().unwrap_or(&stamps[0]))
        )));
    }
    let t0 = stamps[kept[0]];
    let time: Vec<f64> = kept.iter().map(|&k| (stamps[k] - t0) as f64 * 1e-9).collect();
    let pick = |values: &[f64]| kept.iter().map(|&k| values[k]).collect::<Vec<f64>>();
    let follower = Episode {
        time: time.clone(),
        columns: observed.columns.iter().map(|c| Column { name: c.name.clone(), values: pick(&c.values) }).collect(),
        effort: observed.effort.iter().map(|c| Column { name: c.name.clone(), values: pick(&c.values) }).collect(),
        ..observed.clone()
    };
    // the set points on straight lines, at each kept joint-state stamp (both in time order)
    let mut segment = 0;
    let weights: Vec<(usize, f64)> = kept
        .iter()
        .map(|&k| {
            let s = stamps[k];
            while segment + 1 < commands.stamps.len() && commands.stamps[segment + 1] <= s {
                segment += 1;
            }
            match commands.stamps.get(segment + 1) {
                Some(&next) if !commands.stepwise => (segment, (s - commands.stamps[segment]) as f64 / (next - commands.stamps[segment]) as f64),
                _ => (segment, 0.0),
            }
        })
        .collect();
    let columns: Vec<Column> = commands
        .joints
        .iter()
        .zip(&commands.positions)
        .map(|(name, p)| Column { name: name.clone(), values: weights.iter().map(|&(i, w)| if w > 0.0 { p[i] + w * (p[i + 1] - p[i]) } else { p[i] }).collect() })
        .collect();
    let mut notices = commands.notices.clone();
    let joined = if commands.stepwise { "each held until the next" } else { "on straight lines between set points" };
    notices.push(format!("{}: commands from {} on {}, {joined}, at {}'s {} stamps", bag.path.display(), commands.what, commands.topic, bag.topic, kept.len()));
    for c in &follower.columns {
        if !commands.joints.contains(&c.name) {
            notices.push(format!("{}: no command for {} on {}; its motor is sent where the real joint was (not compared)", bag.path.display(), c.name, commands.topic));
        }
    }
    let dropped = stamps.len() - kept.len();
    if dropped > 0 {
        notices.push(format!("{}: {dropped} of {}'s samples lie outside the commands; left out", bag.path.display(), bag.topic));
    }
    let commanded = Episode { label: follower.label.clone(), index: None, time, columns, effort: Vec::new(), notices };
    Ok((commanded, follower))
}
