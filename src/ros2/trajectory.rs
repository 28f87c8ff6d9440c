//! The messages that carry a ROS 2 arm's commands: `trajectory_msgs/msg/JointTrajectory` (what a
//! trajectory controller is sent), `control_msgs/msg/JointTrajectoryControllerState` (what it
//! followed, at its update rate) and `std_msgs/msg/Float64MultiArray` (a forward command
//! controller's positions, in its configured joint order: the message names no joints). The
//! controller state's layout changed between distributions (Foxy: `desired, actual, error`; Humble:
//! `reference, feedback, error, output, desired, actual` and the multi-DOF points; Jazzy: no
//! `desired`/`actual`, a `speed_scaling_factor`), so a bag's
//! messages are read by the layout its schema gives ([`ControllerStateLayout`]); all agree on the
//! header, the joint names and a run of `JointTrajectoryPoint`s, the set point among them.

use super::cdr::{CdrError, CdrReader, CdrWriter};
use super::messages::{Header, Message, Time, read_sequence, sequence};

/// trajectory_msgs/msg/JointTrajectoryPoint.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointTrajectoryPoint {
    pub positions: Vec<f64>,
    pub velocities: Vec<f64>,
    pub accelerations: Vec<f64>,
    pub effort: Vec<f64>,
    /// From the trajectory's start (its header's stamp).
    pub time_from_start: Time,
}

impl Message for JointTrajectoryPoint {
    const NAME: &'static str = "trajectory_msgs/msg/JointTrajectoryPoint";
    fn write(&self, w: &mut CdrWriter) {
        w.f64_sequence(&self.positions);
        w.f64_sequence(&self.velocities);
        w.f64_sequence(&self.accelerations);
        w.f64_sequence(&self.effort);
        self.time_from_start.write(w);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { positions: r.f64_sequence()?, velocities: r.f64_sequence()?, accelerations: r.f64_sequence()?, effort: r.f64_sequence()?, time_from_start: Time::read(r)? })
    }
}

/// trajectory_msgs/msg/JointTrajectory.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointTrajectory {
    pub header: Header,
    pub joint_names: Vec<String>,
    pub points: Vec<JointTrajectoryPoint>,
}

impl Message for JointTrajectory {
    const NAME: &'static str = "trajectory_msgs/msg/JointTrajectory";
    fn write(&self, w: &mut CdrWriter) {
        self.header.write(w);
        w.string_sequence(&self.joint_names);
        sequence(w, &self.points);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        // a point is at least its four sequences' counts and its duration
        Ok(Self { header: Header::read(r)?, joint_names: r.string_sequence()?, points: read_sequence(r, 24)? })
    }
}

/// std_msgs/msg/MultiArrayDimension.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MultiArrayDimension {
    pub label: String,
    pub size: u32,
    pub stride: u32,
}

impl Message for MultiArrayDimension {
    const NAME: &'static str = "std_msgs/msg/MultiArrayDimension";
    fn write(&self, w: &mut CdrWriter) {
        w.string(&self.label);
        w.u32(self.size);
        w.u32(self.stride);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { label: r.string()?, size: r.u32()?, stride: r.u32()? })
    }
}

/// std_msgs/msg/Float64MultiArray.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Float64MultiArray {
    pub dim: Vec<MultiArrayDimension>,
    pub data_offset: u32,
    pub data: Vec<f64>,
}

impl Message for Float64MultiArray {
    const NAME: &'static str = "std_msgs/msg/Float64MultiArray";
    fn write(&self, w: &mut CdrWriter) {
        sequence(w, &self.dim);
        w.u32(self.data_offset);
        w.f64_sequence(&self.data);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        // a dimension is at least its label's length and two counts
        Ok(Self { dim: read_sequence(r, 12)?, data_offset: r.u32()?, data: r.f64_sequence()? })
    }
}

/// control_msgs/msg/JointTrajectoryControllerState as Humble defines it (the layout armscope writes;
/// reading goes by the bag's own schema, [`ControllerStateLayout`]). The multi-DOF fields are
/// written empty.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointTrajectoryControllerState {
    pub header: Header,
    pub joint_names: Vec<String>,
    pub reference: JointTrajectoryPoint,
    pub feedback: JointTrajectoryPoint,
    pub error: JointTrajectoryPoint,
    pub output: JointTrajectoryPoint,
    pub desired: JointTrajectoryPoint,
    pub actual: JointTrajectoryPoint,
}

impl Message for JointTrajectoryControllerState {
    const NAME: &'static str = "control_msgs/msg/JointTrajectoryControllerState";
    fn write(&self, w: &mut CdrWriter) {
        self.header.write(w);
        w.string_sequence(&self.joint_names);
        for p in [&self.reference, &self.feedback, &self.error, &self.output, &self.desired, &self.actual] {
            p.write(w);
        }
        w.string_sequence::<&str>(&[]);
        // six empty MultiDOFJointTrajectoryPoints: transforms, velocities, accelerations, duration
        for _ in 0..6 {
            for _ in 0..3 {
                w.length(0);
            }
            Time::default().write(w);
        }
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        let header = Header::read(r)?;
        let joint_names = r.string_sequence()?;
        let mut points = (0..6).map(|_| JointTrajectoryPoint::read(r)).collect::<Result<Vec<_>, _>>()?.into_iter();
        let mut next = || points.next().unwrap_or_default();
        Ok(Self { header, joint_names, reference: next(), feedback: next(), error: next(), output: next(), desired: next(), actual: next() })
    }
}

/// Where a controller state's set point is, as the bag's schema lays the message out: after the
/// header and the joint names, the `JointTrajectoryPoint` fields in order (the rest is not read).
#[derive(Clone, Debug, PartialEq)]
pub struct ControllerStateLayout {
    /// The names of the points that follow the joint names, in order.
    pub points: Vec<String>,
}

/// A controller state's set point: when, for which joints, and which field it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct SetPoint {
    pub header: Header,
    pub joint_names: Vec<String>,
    pub positions: Vec<f64>,
    /// `reference` or `desired`.
    pub field: &'static str,
}

/// The fields that hold the set point, the preferred first (Humble fills both; Foxy has `desired`).
const SET_POINT_FIELDS: [&str; 2] = ["reference", "desired"];

impl ControllerStateLayout {
    /// The layout a ros2msg definition (an MCAP schema's text) gives; why not, in words.
    pub fn from_definition(text: &str) -> Result<Self, String> {
        let fields = top_level_fields(text);
        let is_header = |f: &(String, String)| f.1 == "header" && (f.0 == "std_msgs/Header" || f.0 == "Header");
        if fields.len() < 3 || !is_header(&fields[0]) || fields[1] != ("string[]".to_string(), "joint_names".to_string()) {
            return Err("its schema does not begin `std_msgs/Header header`, `string[] joint_names`".into());
        }
        let points: Vec<String> = fields[2..].iter().take_while(|(ty, _)| ty == "trajectory_msgs/JointTrajectoryPoint" || ty == "JointTrajectoryPoint").map(|(_, name)| name.clone()).collect();
        if !points.iter().any(|p| SET_POINT_FIELDS.contains(&p.as_str())) {
            return Err(format!("its schema has no `reference` or `desired` JointTrajectoryPoint after the joint names (it has: {})", points.join(", ")));
        }
        Ok(Self { points })
    }

    /// The set point of one message: `reference` where it holds a position per joint, else `desired`.
    pub fn set_point(&self, bytes: &[u8]) -> Result<SetPoint, CdrError> {
        let mut r = CdrReader::new(bytes)?;
        let header = Header::read(&mut r)?;
        let joint_names = r.string_sequence()?;
        let mut found: Vec<(&str, Vec<f64>)> = Vec::new();
        for name in &self.points {
            let point = JointTrajectoryPoint::read(&mut r)?;
            if let Some(field) = SET_POINT_FIELDS.iter().find(|f| **f == name) {
                found.push((field, point.positions));
            }
            if found.len() == SET_POINT_FIELDS.len() {
                break;
            }
        }
        let (field, positions) = SET_POINT_FIELDS
            .iter()
            .find_map(|f| found.iter().find(|(name, p)| name == f && p.len() == joint_names.len() && !p.is_empty()).map(|(_, p)| (*f, p.clone())))
            .unwrap_or(("reference", Vec::new()));
        Ok(SetPoint { header, joint_names, positions, field })
    }
}

/// The `(type, name)` of each field of a definition's own type (its first section), constants and
/// comments left out.
fn top_level_fields(text: &str) -> Vec<(String, String)> {
    let mut fields = Vec::new();
    for line in text.lines() {
        if line.starts_with("====") {
            break;
        }
        let line = line.split('#').next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        let (Some(ty), Some(name)) = (words.next(), words.next()) else { continue };
        // a constant: `int32 ARROW=0` or `int32 ARROW = 0`
        if name.contains('=') || words.next().is_some_and(|w| w.starts_with('=')) {
            continue;
        }
        fields.push((ty.to_string(), name.to_string()));
    }
    fields
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(positions: &[f64]) -> JointTrajectoryPoint {
        JointTrajectoryPoint { positions: positions.to_vec(), time_from_start: Time { sec: 0, nanosec: 5_000_000 }, ..Default::default() }
    }

    #[test]
    fn a_trajectory_and_a_controller_state_come_back_as_written() {
        let trajectory = JointTrajectory { header: Header { stamp: Time { sec: 3, nanosec: 7 }, frame_id: String::new() }, joint_names: vec!["a".into(), "b".into()], points: vec![point(&[1.0, 2.0]), point(&[3.0, 4.0])] };
        assert_eq!(JointTrajectory::decode(&trajectory.to_bytes()).unwrap(), trajectory);
        let state = JointTrajectoryControllerState { joint_names: vec!["a".into()], reference: point(&[0.5]), actual: point(&[0.25]), ..Default::default() };
        assert_eq!(JointTrajectoryControllerState::decode(&state.to_bytes()).unwrap(), state);
        let array = Float64MultiArray { dim: vec![MultiArrayDimension { label: "joints".into(), size: 2, stride: 2 }], data_offset: 0, data: vec![0.5, -0.25] };
        assert_eq!(Float64MultiArray::decode(&array.to_bytes()).unwrap(), array);
    }

    #[test]
    fn the_set_point_is_read_by_the_schemas_layout_in_every_distribution() {
        let humble = super::super::definitions::full_definition(JointTrajectoryControllerState::NAME).unwrap();
        let layout = ControllerStateLayout::from_definition(&humble).unwrap();
        assert_eq!(layout.points, ["reference", "feedback", "error", "output", "desired", "actual"]);
        // Humble's controllers before the `reference` field was filled left it empty: `desired` then
        let state = JointTrajectoryControllerState { joint_names: vec!["a".into(), "b".into()], desired: point(&[0.1, 0.2]), feedback: point(&[9.0, 9.0]), ..Default::default() };
        let set = layout.set_point(&state.to_bytes()).unwrap();
        assert_eq!((set.field, set.positions), ("desired", vec![0.1, 0.2]));
        let state = JointTrajectoryControllerState { reference: point(&[0.3, 0.4]), ..state };
        assert_eq!(layout.set_point(&state.to_bytes()).unwrap().positions, vec![0.3, 0.4]);
        // Foxy's layout: desired, actual, error, read from its own schema
        let foxy = "std_msgs/Header header\nstring[] joint_names\ntrajectory_msgs/JointTrajectoryPoint desired\ntrajectory_msgs/JointTrajectoryPoint actual\ntrajectory_msgs/JointTrajectoryPoint error  # Redundant, but useful\n";
        let layout = ControllerStateLayout::from_definition(foxy).unwrap();
        let mut bytes = Vec::new();
        let mut w = CdrWriter::new(&mut bytes);
        Header::default().write(&mut w);
        w.string_sequence(&["a"]);
        for p in [point(&[0.7]), point(&[0.6]), point(&[0.1])] {
            p.write(&mut w);
        }
        let set = layout.set_point(&bytes).unwrap();
        assert_eq!((set.field, set.positions), ("desired", vec![0.7]));
        // a schema that is not a controller state says why
        assert!(ControllerStateLayout::from_definition("float64[] data\n").unwrap_err().contains("joint_names"));
        let odd = "std_msgs/Header header\nstring[] joint_names\nfloat64[] positions\n";
        assert!(ControllerStateLayout::from_definition(odd).unwrap_err().contains("`reference` or `desired`"));
    }
}
