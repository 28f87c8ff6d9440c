//! What both encodings of the MCAP draw: the arm's links in their parents (from the URDF's own
//! origins), its visuals as one scene, a motor file's table, the tool's path published piece by
//! piece, and Foxglove's geometry types from armscope's.

use crate::model::{Geometry, JointKind, Model};
use crate::recorder::shared::floor_plate::{TABLE_RGBA, TABLE_SIDE, floor_plate};
use crate::recorder::shared::overview::Overview;
use crate::spatial::{Pose, rotation_about_axis};
use foxglove::messages::{Color, CubePrimitive, CylinderPrimitive, FrameTransform, LinePrimitive, ModelPrimitive, Point3, Quaternion, SceneEntity, SceneUpdate, SpherePrimitive, Timestamp, Vector3};
use std::path::PathBuf;

/// Points of the tool path at most in one piece (a piece every half simulated second at 20 Hz).
const PATH_PIECE_POINTS: usize = 10;
/// Points of the path's overview at most.
const PATH_OVERVIEW_POINTS: usize = 512;

/// The tool's path, published incrementally: each message carries the new piece (its own entity,
/// kept, so that playing the file draws the whole path, each point published once) and an overview
/// of everything so far thinned to at most `PATH_OVERVIEW_POINTS` (one entity, replaced), which is
/// what a viewer shows after seeking (it shows a topic's latest message). So the topic's size grows
/// linearly with the duration.
pub(super) struct ToolPath {
    /// The points since the last piece, starting with the last piece's last point (no gap).
    piece: Vec<Point3>,
    pieces: usize,
    overview: Overview<Point3>,
}

impl Default for ToolPath {
    fn default() -> Self {
        Self { piece: Vec::new(), pieces: 0, overview: Overview::new(PATH_OVERVIEW_POINTS) }
    }
}

impl ToolPath {
    pub(super) fn push(&mut self, p: Point3) {
        self.overview.push(p);
        self.piece.push(p);
    }

    /// Whether a piece is due (`PATH_PIECE_POINTS` new points).
    pub(super) fn piece_full(&self) -> bool {
        self.piece.len() > PATH_PIECE_POINTS
    }

    /// The message with the new piece and the overview; starts the next piece.
    pub(super) fn take_update(&mut self, timestamp: Timestamp) -> Option<SceneUpdate> {
        if self.piece.len() < 2 {
            return None;
        }
        let red = color([1.0, 0.25, 0.2, 1.0]);
        let last = *self.piece.last().expect("two points");
        let piece = std::mem::replace(&mut self.piece, vec![last]);
        let mut overview = self.overview.points().to_vec();
        if overview.last() != Some(&last) {
            overview.push(last);
        }
        let entity = |id: String, points: Vec<Point3>, thickness: f64| SceneEntity {
            timestamp: Some(timestamp),
            frame_id: "world".into(),
            id,
            lines: vec![line(points, red, thickness)],
            ..Default::default()
        };
        self.pieces += 1;
        Some(SceneUpdate { deletions: vec![], entities: vec![entity(format!("path-{}", self.pieces), piece, 3.0), entity("path-overview".into(), overview, 2.0)] })
    }
}

/// A moving joint's child link in its parent link: `before` ∘ motion(q) ∘ `after`, where `before`
/// takes the parent link to the joint frame and `after` the joint's body to the child link.
/// Built from the URDF's own origins rather than from world poses, so what the URDF has exactly
/// (zero offsets, an axis along z) stays exact: protobuf then leaves the zeros out, a third of /tf.
pub(super) struct JointTransform {
    pub(super) joint: usize,
    before: Pose,
    after: Pose,
}

/// Every link in its parent link ("world" → the root when the root is not "world"), by (parent,
/// child) name: those a moving joint turns, and the fixed ones with their constant pose.
pub(super) struct LinkTransforms {
    pub(super) moving: Vec<((String, String), JointTransform)>,
    pub(super) fixed: Vec<((String, String), Pose)>,
}

impl LinkTransforms {
    pub(super) fn of(model: &Model) -> Self {
        let pairs = model.frames.iter().enumerate().filter(|(_, f)| f.parent_frame.is_some() || f.name != "world");
        // a link moves relative to its parent when its joint is a moving joint (the child's body's joint)
        let (moving, fixed): (Vec<_>, Vec<_>) = pairs.partition(|(_, f)| f.parent_frame.is_some_and(|p| model.frames[p].body != f.body));
        let name_of = |f: Option<usize>| f.map_or("world".to_string(), |i| model.frames[i].name.clone());
        // a parent link's placement on its body (the world's: identity)
        let placement_of = |f: Option<usize>| f.map_or(Pose::identity(), |p| model.frames[p].placement);
        let names = |parent: Option<usize>, child: usize| (name_of(parent), name_of(Some(child)));
        Self {
            moving: moving
                .iter()
                .map(|(c, f)| {
                    let joint = f.body.expect("a moving link has a body");
                    (names(f.parent_frame, *c), JointTransform { joint, before: placement_of(f.parent_frame).inverse().compose(&model.bodies[joint].placement), after: f.placement })
                })
                .collect(),
            // links on the same body (or on the world) keep their relative pose: P_parent⁻¹ ∘ P_child
            fixed: fixed.iter().map(|(c, f)| (names(f.parent_frame, *c), placement_of(f.parent_frame).inverse().compose(&f.placement))).collect(),
        }
    }
}

impl JointTransform {
    pub(super) fn pose(&self, model_joint: &crate::model::Joint, q: f64) -> Pose {
        let motion = match model_joint.kind {
            JointKind::Revolute | JointKind::Continuous => Pose::new(rotation_about_axis(&model_joint.axis, q), nalgebra::Vector3::zeros()),
            JointKind::Prismatic => Pose::new(nalgebra::Matrix3::identity(), model_joint.axis * q),
        };
        self.before.compose(&motion).compose(&self.after)
    }
}

pub(super) fn set_transform(m: &mut FrameTransform, pose: &Pose, ts: Option<Timestamp>) {
    m.timestamp = ts;
    m.translation = Some(vec3(&pose.translation));
    m.rotation = Some(quaternion(pose));
}

pub(super) fn color(c: [f32; 4]) -> Color {
    Color { r: c[0] as f64, g: c[1] as f64, b: c[2] as f64, a: c[3] as f64 }
}

/// A line strip `thickness` pixels wide at any zoom.
pub(super) fn line(points: Vec<Point3>, color: Color, thickness: f64) -> LinePrimitive {
    LinePrimitive { r#type: 0, thickness, scale_invariant: true, points, color: Some(color), ..Default::default() }
}

pub(super) fn vec3(v: &nalgebra::Vector3<f64>) -> Vector3 {
    Vector3 { x: v.x, y: v.y, z: v.z }
}

pub(super) fn quaternion(pose: &Pose) -> Quaternion {
    let [x, y, z, w] = pose.quaternion_xyzw();
    Quaternion { x, y, z, w }
}

pub(super) fn fox_pose(pose: &Pose) -> foxglove::messages::Pose {
    foxglove::messages::Pose { position: Some(vec3(&pose.translation)), orientation: Some(quaternion(pose)) }
}

/// `geometry` at `origin` as primitives in `entity`, grown by `grow` (m, each side: a highlight over
/// the link's own surfaces); a mesh as its bounding box.
pub(super) fn add_primitives(entity: &mut SceneEntity, geometry: &Geometry, origin: &Pose, colour: Color, grow: f64) {
    let v = |x: f64, y: f64, z: f64| Some(Vector3 { x: x + 2.0 * grow, y: y + 2.0 * grow, z: z + 2.0 * grow });
    match geometry {
        Geometry::Box { size } => entity.cubes.push(CubePrimitive { pose: Some(fox_pose(origin)), size: v(size[0], size[1], size[2]), color: Some(colour) }),
        Geometry::Cylinder { radius, length } | Geometry::Capsule { radius, length } => {
            entity.cylinders.push(CylinderPrimitive { pose: Some(fox_pose(origin)), size: v(2.0 * radius, 2.0 * radius, *length), bottom_scale: 1.0, top_scale: 1.0, color: Some(colour) });
            if matches!(geometry, Geometry::Capsule { .. }) {
                for end in [-0.5, 0.5] {
                    let cap = origin.compose(&Pose::new(nalgebra::Matrix3::identity(), nalgebra::Vector3::new(0.0, 0.0, end * length)));
                    entity.spheres.push(SpherePrimitive { pose: Some(fox_pose(&cap)), size: v(2.0 * radius, 2.0 * radius, 2.0 * radius), color: Some(colour) });
                }
            }
        }
        Geometry::Sphere { radius } => entity.spheres.push(SpherePrimitive { pose: Some(fox_pose(origin)), size: v(2.0 * radius, 2.0 * radius, 2.0 * radius), color: Some(colour) }),
        Geometry::Mesh { .. } => {
            if let Ok(shape) = crate::collision::geometry::parry_shape(geometry) {
                let aabb = shape.compute_local_aabb();
                let (c, h) = (aabb.center(), aabb.half_extents());
                let centre = origin.compose(&Pose::new(nalgebra::Matrix3::identity(), nalgebra::Vector3::new(c.x, c.y, c.z)));
                entity.cubes.push(CubePrimitive { pose: Some(fox_pose(&centre)), size: v(2.0 * h.x, 2.0 * h.y, 2.0 * h.z), color: Some(colour) });
            }
        }
    }
}

/// The table a motor file's `[floor]` puts under the tool, in the world frame.
pub(super) fn table_entity(height: f64) -> SceneEntity {
    let (plate, pose) = floor_plate(height, TABLE_SIDE);
    let mut entity = SceneEntity { frame_id: "world".into(), id: "floor".into(), frame_locked: true, ..Default::default() };
    add_primitives(&mut entity, &plate, &pose, color(TABLE_RGBA.map(|c| c as f32 / 255.0)), 0.0);
    entity
}

fn media_type(path: &std::path::Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
        Some("stl") => "model/stl",
        Some("obj") => "model/obj",
        Some("dae") => "model/vnd.collada+xml",
        Some("glb") => "model/gltf-binary",
        _ => "model/gltf+json",
    }
}

/// How often the geometry is republished: once a simulated second, but at most
/// [`SCENE_BYTES_PER_SECOND`] on average — a robot drawn from meshes (a Panda's are 7 MB) is
/// republished every few minutes instead of every second, which would have been most of its file.
pub(super) fn scene_interval_s(scene_bytes: usize) -> i64 {
    (scene_bytes as f64 / SCENE_BYTES_PER_SECOND).ceil().max(1.0) as i64
}

/// The geometry's share of the MCAP, bytes per simulated second (the whole file is ~450 kB/s).
pub const SCENE_BYTES_PER_SECOND: f64 = 20_000.0;

/// One scene entity per link with visuals, locked to the link's frame.
pub(super) fn scene_from_model(model: &Model) -> Result<SceneUpdate, (PathBuf, std::io::Error)> {
    let mut entities = Vec::new();
    for frame in &model.frames {
        if frame.visuals.is_empty() {
            continue;
        }
        let mut entity = SceneEntity { frame_id: frame.name.clone(), id: frame.name.clone(), frame_locked: true, ..Default::default() };
        for v in &frame.visuals {
            let c = color(v.rgba.unwrap_or([0.67, 0.67, 0.7, 1.0]));
            match &v.geometry {
                // the mesh file itself, for the viewer to draw (a collision highlight draws its box)
                Geometry::Mesh { path, scale } => {
                    let data = std::fs::read(path).map_err(|e| (path.clone(), e))?;
                    entity.models.push(ModelPrimitive {
                        pose: Some(fox_pose(&v.origin)),
                        scale: Some(Vector3 { x: scale[0], y: scale[1], z: scale[2] }),
                        color: Some(c),
                        override_color: v.rgba.is_some(),
                        url: String::new(),
                        media_type: media_type(path).into(),
                        data: data.into(),
                    });
                }
                primitive => add_primitives(&mut entity, primitive, &v.origin, c, 0.0),
            }
        }
        entities.push(entity);
    }
    Ok(SceneUpdate { deletions: vec![], entities })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Primitive shapes (a few kB) once a simulated second; a 7 MB mesh scene (a Panda) every 350 s,
    /// so the geometry stays at most 20 kB per simulated second of the file.
    #[test]
    fn geometry_is_republished_at_a_bounded_byte_rate() {
        assert_eq!(scene_interval_s(0), 1);
        assert_eq!(scene_interval_s(3_000), 1);
        assert_eq!(scene_interval_s(7_000_000), 350);
        for bytes in [25_000, 1_000_000, 7_000_000] {
            assert!(bytes as f64 / scene_interval_s(bytes) as f64 <= SCENE_BYTES_PER_SECOND);
        }
    }
}
