//! The ROS 2 messages armscope writes and reads, field for field as their `.msg` definitions
//! ([`super::definitions`]) order them, encoded and decoded with [`super::cdr`].

use super::cdr::{CdrError, CdrReader, CdrWriter};

/// A message type: its name and its fields in CDR.
pub trait Message: Sized {
    /// "sensor_msgs/msg/JointState".
    const NAME: &'static str;
    fn write(&self, w: &mut CdrWriter);
    fn read(r: &mut CdrReader) -> Result<Self, CdrError>;

    /// The message appended to `out`, its CDR header first.
    fn encode(&self, out: &mut Vec<u8>) {
        let mut w = CdrWriter::new(out);
        self.write(&mut w);
    }

    fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        self.encode(&mut out);
        out
    }

    fn decode(bytes: &[u8]) -> Result<Self, CdrError> {
        Self::read(&mut CdrReader::new(bytes)?)
    }
}

/// A sequence of messages: its count, then each.
pub(super) fn sequence<T: Message>(w: &mut CdrWriter, items: &[T]) {
    w.length(items.len());
    for item in items {
        item.write(w);
    }
}

/// A sequence of messages, each at least `min_size` bytes (the count checked against what is left).
pub(super) fn read_sequence<T: Message>(r: &mut CdrReader, min_size: usize) -> Result<Vec<T>, CdrError> {
    let n = r.length(min_size)?;
    (0..n).map(|_| T::read(r)).collect()
}

/// builtin_interfaces/msg/Time (and Duration: the same fields).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Time {
    pub sec: i32,
    pub nanosec: u32,
}

impl Time {
    /// From nanoseconds since the epoch (or since zero, for a duration).
    pub fn from_nanos(ns: u64) -> Self {
        Self { sec: (ns / 1_000_000_000) as i32, nanosec: (ns % 1_000_000_000) as u32 }
    }

    pub fn nanos(&self) -> i64 {
        self.sec as i64 * 1_000_000_000 + self.nanosec as i64
    }
}

impl Message for Time {
    const NAME: &'static str = "builtin_interfaces/msg/Time";
    fn write(&self, w: &mut CdrWriter) {
        w.i32(self.sec);
        w.u32(self.nanosec);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { sec: r.i32()?, nanosec: r.u32()? })
    }
}

/// std_msgs/msg/Header.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Header {
    pub stamp: Time,
    pub frame_id: String,
}

impl Message for Header {
    const NAME: &'static str = "std_msgs/msg/Header";
    fn write(&self, w: &mut CdrWriter) {
        self.stamp.write(w);
        w.string(&self.frame_id);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { stamp: Time::read(r)?, frame_id: r.string()? })
    }
}

/// std_msgs/msg/String.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StringMessage {
    pub data: String,
}

impl Message for StringMessage {
    const NAME: &'static str = "std_msgs/msg/String";
    fn write(&self, w: &mut CdrWriter) {
        w.string(&self.data);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { data: r.string()? })
    }
}

/// sensor_msgs/msg/JointState.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointState {
    pub header: Header,
    pub name: Vec<String>,
    pub position: Vec<f64>,
    pub velocity: Vec<f64>,
    pub effort: Vec<f64>,
}

impl Message for JointState {
    const NAME: &'static str = "sensor_msgs/msg/JointState";
    fn write(&self, w: &mut CdrWriter) {
        self.header.write(w);
        w.string_sequence(&self.name);
        w.f64_sequence(&self.position);
        w.f64_sequence(&self.velocity);
        w.f64_sequence(&self.effort);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { header: Header::read(r)?, name: r.string_sequence()?, position: r.f64_sequence()?, velocity: r.f64_sequence()?, effort: r.f64_sequence()? })
    }
}

/// geometry_msgs/msg/Vector3 (and Point: the same fields).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vector3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Message for Vector3 {
    const NAME: &'static str = "geometry_msgs/msg/Vector3";
    fn write(&self, w: &mut CdrWriter) {
        w.f64(self.x);
        w.f64(self.y);
        w.f64(self.z);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { x: r.f64()?, y: r.f64()?, z: r.f64()? })
    }
}

/// geometry_msgs/msg/Quaternion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quaternion {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Self { x: 0.0, y: 0.0, z: 0.0, w: 1.0 }
    }
}

impl Message for Quaternion {
    const NAME: &'static str = "geometry_msgs/msg/Quaternion";
    fn write(&self, w: &mut CdrWriter) {
        w.f64(self.x);
        w.f64(self.y);
        w.f64(self.z);
        w.f64(self.w);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { x: r.f64()?, y: r.f64()?, z: r.f64()?, w: r.f64()? })
    }
}

/// geometry_msgs/msg/Pose (and Transform: a Vector3 and a Quaternion, the same bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose {
    pub position: Vector3,
    pub orientation: Quaternion,
}

impl Message for Pose {
    const NAME: &'static str = "geometry_msgs/msg/Pose";
    fn write(&self, w: &mut CdrWriter) {
        self.position.write(w);
        self.orientation.write(w);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { position: Vector3::read(r)?, orientation: Quaternion::read(r)? })
    }
}

/// geometry_msgs/msg/PoseStamped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PoseStamped {
    pub header: Header,
    pub pose: Pose,
}

impl Message for PoseStamped {
    const NAME: &'static str = "geometry_msgs/msg/PoseStamped";
    fn write(&self, w: &mut CdrWriter) {
        self.header.write(w);
        self.pose.write(w);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { header: Header::read(r)?, pose: Pose::read(r)? })
    }
}

/// geometry_msgs/msg/TransformStamped: the child frame in the header's frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TransformStamped {
    pub header: Header,
    pub child_frame_id: String,
    /// translation and rotation (geometry_msgs/Transform: a Pose's bytes)
    pub transform: Pose,
}

impl Message for TransformStamped {
    const NAME: &'static str = "geometry_msgs/msg/TransformStamped";
    fn write(&self, w: &mut CdrWriter) {
        self.header.write(w);
        w.string(&self.child_frame_id);
        self.transform.write(w);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { header: Header::read(r)?, child_frame_id: r.string()?, transform: Pose::read(r)? })
    }
}

/// tf2_msgs/msg/TFMessage.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TfMessage {
    pub transforms: Vec<TransformStamped>,
}

impl Message for TfMessage {
    const NAME: &'static str = "tf2_msgs/msg/TFMessage";
    fn write(&self, w: &mut CdrWriter) {
        sequence(w, &self.transforms);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { transforms: read_sequence(r, 4)? })
    }
}

/// std_msgs/msg/ColorRGBA.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ColorRgba {
    pub r: f32,
    pub g: f32,
    pub b: f32,
    pub a: f32,
}

impl Message for ColorRgba {
    const NAME: &'static str = "std_msgs/msg/ColorRGBA";
    fn write(&self, w: &mut CdrWriter) {
        w.f32(self.r);
        w.f32(self.g);
        w.f32(self.b);
        w.f32(self.a);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { r: r.f32()?, g: r.f32()?, b: r.f32()?, a: r.f32()? })
    }
}

/// visualization_msgs/msg/Marker: the fields armscope sets; the texture, UV coordinates and
/// embedded mesh it leaves empty (written as empty, skipped when read).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Marker {
    pub header: Header,
    pub ns: String,
    pub id: i32,
    pub kind: i32,
    pub action: i32,
    pub pose: Pose,
    pub scale: Vector3,
    pub color: ColorRgba,
    pub lifetime: Time,
    pub frame_locked: bool,
    pub points: Vec<Vector3>,
    pub colors: Vec<ColorRgba>,
    pub text: String,
    pub mesh_resource: String,
    pub mesh_use_embedded_materials: bool,
}

impl Marker {
    pub const CUBE: i32 = 1;
    pub const SPHERE: i32 = 2;
    pub const CYLINDER: i32 = 3;
    pub const LINE_STRIP: i32 = 4;
    pub const MESH_RESOURCE: i32 = 10;
    pub const ADD: i32 = 0;
    pub const DELETE: i32 = 2;
    pub const DELETEALL: i32 = 3;
}

impl Message for Marker {
    const NAME: &'static str = "visualization_msgs/msg/Marker";
    fn write(&self, w: &mut CdrWriter) {
        self.header.write(w);
        w.string(&self.ns);
        w.i32(self.id);
        w.i32(self.kind);
        w.i32(self.action);
        self.pose.write(w);
        self.scale.write(w);
        self.color.write(w);
        self.lifetime.write(w);
        w.bool(self.frame_locked);
        sequence(w, &self.points);
        sequence(w, &self.colors);
        w.string(""); // texture_resource
        // texture: sensor_msgs/CompressedImage (header, format, data), empty
        Header::default().write(w);
        w.string("");
        w.bytes_sequence(&[]);
        w.length(0); // uv_coordinates
        w.string(&self.text);
        w.string(&self.mesh_resource);
        // mesh_file: visualization_msgs/MeshFile (filename, data), empty
        w.string("");
        w.bytes_sequence(&[]);
        w.bool(self.mesh_use_embedded_materials);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        let header = Header::read(r)?;
        let ns = r.string()?;
        let (id, kind, action) = (r.i32()?, r.i32()?, r.i32()?);
        let (pose, scale, color, lifetime) = (Pose::read(r)?, Vector3::read(r)?, ColorRgba::read(r)?, Time::read(r)?);
        let frame_locked = r.bool()?;
        let points = read_sequence(r, 24)?;
        let colors = read_sequence(r, 16)?;
        let _texture_resource = r.string()?;
        let (_texture_header, _format, _data) = (Header::read(r)?, r.string()?, r.bytes_sequence()?);
        let uv = r.length(8)?;
        for _ in 0..uv {
            r.f32()?;
            r.f32()?;
        }
        let text = r.string()?;
        let mesh_resource = r.string()?;
        let (_filename, _mesh) = (r.string()?, r.bytes_sequence()?);
        let mesh_use_embedded_materials = r.bool()?;
        Ok(Self { header, ns, id, kind, action, pose, scale, color, lifetime, frame_locked, points, colors, text, mesh_resource, mesh_use_embedded_materials })
    }
}

/// visualization_msgs/msg/MarkerArray.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MarkerArray {
    pub markers: Vec<Marker>,
}

impl Message for MarkerArray {
    const NAME: &'static str = "visualization_msgs/msg/MarkerArray";
    fn write(&self, w: &mut CdrWriter) {
        sequence(w, &self.markers);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { markers: read_sequence(r, 4)? })
    }
}

/// armscope_msgs/msg/CollisionState (`assets/ros2/armscope_msgs/msg/CollisionState.msg`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CollisionState {
    pub time: f64,
    pub in_contact: u32,
    pub min_distance: f64,
    pub pairs: Vec<String>,
    pub distances: Vec<f64>,
}

impl Message for CollisionState {
    const NAME: &'static str = "armscope_msgs/msg/CollisionState";
    fn write(&self, w: &mut CdrWriter) {
        w.f64(self.time);
        w.u32(self.in_contact);
        w.f64(self.min_distance);
        w.string_sequence(&self.pairs);
        w.f64_sequence(&self.distances);
    }
    fn read(r: &mut CdrReader) -> Result<Self, CdrError> {
        Ok(Self { time: r.f64()?, in_contact: r.u32()?, min_distance: r.f64()?, pairs: r.string_sequence()?, distances: r.f64_sequence()? })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_round_trip() {
        let js = JointState {
            header: Header { stamp: Time { sec: 3, nanosec: 7 }, frame_id: "".into() },
            name: vec!["J1".into(), "wrist".into()],
            position: vec![0.5, -1.0],
            velocity: vec![1e-300, f64::MAX],
            effort: vec![],
        };
        assert_eq!(JointState::decode(&js.to_bytes()).unwrap(), js);
        let tf = TfMessage { transforms: vec![TransformStamped { header: Header { stamp: Time::from_nanos(1_500_000_000), frame_id: "world".into() }, child_frame_id: "a".into(), transform: Pose { position: Vector3 { x: 1.0, y: 2.0, z: 3.0 }, orientation: Quaternion::default() } }] };
        assert_eq!(TfMessage::decode(&tf.to_bytes()).unwrap(), tf);
        let marker = Marker { ns: "path".into(), id: 4, kind: Marker::LINE_STRIP, points: vec![Vector3::default(); 3], colors: vec![ColorRgba { r: 1.0, ..Default::default() }], text: "x".into(), mesh_resource: "file:///m.stl".into(), ..Default::default() };
        let array = MarkerArray { markers: vec![marker.clone(), marker] };
        assert_eq!(MarkerArray::decode(&array.to_bytes()).unwrap(), array);
        let c = CollisionState { time: 1.0, in_contact: 2, min_distance: -0.01, pairs: vec!["a — b".into()], distances: vec![-0.01] };
        assert_eq!(CollisionState::decode(&c.to_bytes()).unwrap(), c);
        assert!(StringMessage::decode(&StringMessage { data: "<robot/>".into() }.to_bytes()[..6]).is_err());
    }
}
