//! Each link's collision shapes, built once from the model's `<collision>` elements.

use crate::model::{Geometry, Model};
use parry3d_f64::math::Vector;
use parry3d_f64::shape::SharedShape;
use std::path::Path;

/// One collision shape of a link: the link (a frame of the model), the shape's pose in the link's
/// frame, the parry shape, and the radius of a sphere about its origin that bounds it (the broad
/// phase).
#[derive(Clone)]
pub struct LinkShape {
    pub frame: usize,
    pub origin: crate::spatial::Pose,
    pub shape: SharedShape,
    pub bounding_radius: f64,
    /// Where the bounding sphere's centre sits in the shape's frame.
    pub bounding_centre: nalgebra::Vector3<f64>,
    /// What the distance queries keep of it beside parry's shape (a mesh's hull, a box's faces).
    pub aids: super::aids::ShapeAids,
}

/// The collision shapes of a model, and the notices made building them.
#[derive(Clone, Default)]
pub struct CollisionModel {
    pub shapes: Vec<LinkShape>,
    /// Per frame, the indices of its shapes.
    pub of_frame: Vec<Vec<usize>>,
    /// The links left out of the checks, with why (a mesh format not read, a mesh that is empty).
    pub left_out: Vec<String>,
}

pub(crate) fn parry_shape(geometry: &Geometry) -> Result<SharedShape, String> {
    Ok(match geometry {
        Geometry::Box { size } => SharedShape::cuboid(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0),
        // URDF's cylinders and capsules lie along z, parry's along y: turned in `shape_pose`
        Geometry::Cylinder { radius, length } => SharedShape::cylinder(length / 2.0, *radius),
        Geometry::Capsule { radius, length } => SharedShape::capsule_z(length / 2.0, *radius),
        Geometry::Sphere { radius } => SharedShape::ball(*radius),
        Geometry::Mesh { path, scale } => mesh(path, *scale)?,
    })
}

/// An exact triangle mesh from an STL, OBJ or COLLADA file, scaled, its coincident vertices merged.
fn mesh(path: &Path, scale: [f64; 3]) -> Result<SharedShape, String> {
    let (vertices, indices) = crate::model::mesh_file::read_mesh(path)?.welded(scale);
    let vertices: Vec<Vector> = vertices.iter().map(|v| Vector::new(v[0], v[1], v[2])).collect();
    SharedShape::trimesh(vertices, indices).map_err(|e| format!("{}: {e:?}", path.display()))
}

/// URDF's cylinders lie along z; parry's along y: a quarter turn about x brings y onto z.
pub(crate) fn shape_pose(geometry: &Geometry, origin: &crate::spatial::Pose) -> crate::spatial::Pose {
    match geometry {
        Geometry::Cylinder { .. } => origin.compose(&crate::spatial::Pose::new(crate::spatial::rotation_about_axis(&nalgebra::Vector3::x(), std::f64::consts::FRAC_PI_2), nalgebra::Vector3::zeros())),
        _ => *origin,
    }
}

impl CollisionModel {
    /// The shapes of every link of `model` (a shape that cannot be read is left out, said once per link).
    pub fn new(model: &Model) -> Self {
        let mut out = CollisionModel { of_frame: vec![Vec::new(); model.frames.len()], ..Default::default() };
        for (f, frame) in model.frames.iter().enumerate() {
            for c in &frame.collisions {
                if let Err(why) = out.add(f, &c.geometry, &c.origin) {
                    out.left_out.push(format!("link '{}': {why}; left out of the collision checks", frame.name));
                }
            }
        }
        out
    }

    /// One more shape on link (frame) `f`, at `origin` in the link's frame (the payload the tool holds).
    pub fn add(&mut self, f: usize, geometry: &Geometry, origin: &crate::spatial::Pose) -> Result<(), String> {
        let shape = parry_shape(geometry)?;
        let sphere = shape.compute_local_bounding_sphere();
        let centre = nalgebra::Vector3::new(sphere.center.x, sphere.center.y, sphere.center.z);
        self.of_frame[f].push(self.shapes.len());
        let aids = super::aids::ShapeAids::of(&shape);
        self.shapes.push(LinkShape { frame: f, origin: shape_pose(geometry, origin), shape, bounding_radius: sphere.radius, bounding_centre: centre, aids });
        Ok(())
    }

    /// Whether link (frame) `f` has any collision shape.
    pub fn has_shapes(&self, f: usize) -> bool {
        !self.of_frame[f].is_empty()
    }
}
