//! Shapes and poses in Rerun's types: a link's or object's geometry logged as the archetype that
//! draws it, its colour changed later (contact), a pose as a transform.

use crate::model::Geometry;
use crate::spatial::Pose;
use rerun::{Color, RecordingStream, RecordingStreamResult};

/// The archetype an entity's shape was logged as (its colour component differs).
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    Boxes,
    Cylinders,
    Capsules,
    Ellipsoids,
    Asset,
    Mesh,
}

/// An entity whose colour changes with contact, and its own colour.
#[derive(Clone, Debug)]
pub struct Recolour {
    pub path: String,
    pub kind: Kind,
    pub colour: Color,
}

/// Log `geometry` at `path` (its transform logged by the caller); its colour static when given,
/// else left to temporal colour updates. Returns the archetype used.
pub fn log_geometry(rec: &RecordingStream, path: &str, geometry: &Geometry, colour: Option<Color>) -> Result<Kind, String> {
    // (no colour at all when none is given: an empty static batch would hide the temporal one)
    let r = |x: RecordingStreamResult<()>| x.map_err(|e| e.to_string());
    Ok(match geometry {
        Geometry::Box { size } => {
            let a = rerun::Boxes3D::from_half_sizes([[size[0] as f32 / 2.0, size[1] as f32 / 2.0, size[2] as f32 / 2.0]]).with_fill_mode(rerun::FillMode::Solid);
            r(rec.log_static(path, &match colour {
                Some(c) => a.with_colors([c]),
                None => a,
            }))?;
            Kind::Boxes
        }
        Geometry::Cylinder { radius, length } => {
            let a = rerun::Cylinders3D::from_lengths_and_radii([*length as f32], [*radius as f32]).with_fill_mode(rerun::FillMode::Solid);
            r(rec.log_static(path, &match colour {
                Some(c) => a.with_colors([c]),
                None => a,
            }))?;
            Kind::Cylinders
        }
        Geometry::Capsule { radius, length } => {
            let a = rerun::Capsules3D::from_lengths_and_radii([*length as f32], [*radius as f32]);
            r(rec.log_static(path, &match colour {
                Some(c) => a.with_colors([c]),
                None => a,
            }))?;
            Kind::Capsules
        }
        Geometry::Sphere { radius } => {
            let a = rerun::Ellipsoids3D::from_radii([*radius as f32]).with_fill_mode(rerun::FillMode::Solid);
            r(rec.log_static(path, &match colour {
                Some(c) => a.with_colors([c]),
                None => a,
            }))?;
            Kind::Ellipsoids
        }
        // Rerun reads STL and OBJ itself; COLLADA goes as the triangles read here
        Geometry::Mesh { path: file, .. } if crate::model::mesh_file::is_collada(file) => {
            let mesh = crate::model::mesh_file::read_mesh(file)?;
            r(rec.log_static(path, &match colour {
                Some(c) => mesh3d(&mesh).with_albedo_factor(c.0),
                None => mesh3d(&mesh),
            }))?;
            Kind::Mesh
        }
        Geometry::Mesh { path: file, .. } => {
            let asset = rerun::Asset3D::from_file_path(file).map_err(|e| format!("{}: {e}", file.display()))?;
            r(rec.log_static(path, &match colour {
                Some(c) => asset.with_albedo_factor(c.0),
                None => asset,
            }))?;
            Kind::Asset
        }
    })
}

/// The grey of a mesh part whose file gives it no colour.
const MESH_GREY: [f32; 4] = [0.67, 0.67, 0.7, 1.0];

/// A mesh file's parts as one Rerun mesh, each part in its material's colour; corners with the
/// same position, normal and colour are one vertex (a file's per-corner vertices would make the
/// recording larger than the file).
fn mesh3d(mesh: &crate::model::mesh_file::MeshFile) -> rerun::Mesh3D {
    let with_normals = mesh.parts.iter().all(|p| p.normals.len() == p.vertices.len());
    let (mut positions, mut normals, mut colours, mut triangles) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut index_of: std::collections::HashMap<([u32; 3], [u32; 3], u32), u32> = std::collections::HashMap::new();
    for part in &mesh.parts {
        let [r, g, b, a] = part.colour.unwrap_or(MESH_GREY).map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        let colour = Color::from_unmultiplied_rgba(r, g, b, a);
        let corner: Vec<u32> = (0..part.vertices.len())
            .map(|k| {
                let normal = if with_normals { part.normals[k] } else { [0.0; 3] };
                let key = (part.vertices[k].map(f32::to_bits), normal.map(f32::to_bits), colour.0.0);
                *index_of.entry(key).or_insert_with(|| {
                    positions.push(part.vertices[k]);
                    if with_normals {
                        normals.push(normal);
                    }
                    colours.push(colour);
                    positions.len() as u32 - 1
                })
            })
            .collect();
        triangles.extend(part.triangles.iter().map(|t| t.map(|v| corner[v as usize])));
    }
    let out = rerun::Mesh3D::new(positions).with_triangle_indices(triangles).with_vertex_colors(colours);
    if with_normals { out.with_vertex_normals(normals) } else { out }
}

pub fn log_colour(rec: &RecordingStream, r: &Recolour, colour: Color) -> RecordingStreamResult<()> {
    let path = r.path.as_str();
    match r.kind {
        Kind::Boxes => rec.log(path, &rerun::Boxes3D::update_fields().with_colors([colour])),
        Kind::Cylinders => rec.log(path, &rerun::Cylinders3D::update_fields().with_colors([colour])),
        Kind::Capsules => rec.log(path, &rerun::Capsules3D::update_fields().with_colors([colour])),
        Kind::Ellipsoids => rec.log(path, &rerun::Ellipsoids3D::update_fields().with_colors([colour])),
        Kind::Asset => rec.log(path, &rerun::Asset3D::update_fields().with_albedo_factor(colour.0)),
        Kind::Mesh => rec.log(path, &rerun::Mesh3D::update_fields().with_albedo_factor(colour.0)),
    }
}

/// A pose as Rerun's transform (a translation and a 3×3 rotation).
pub fn transform(pose: &Pose) -> rerun::Transform3D {
    let t = pose.translation;
    rerun::Transform3D::from_translation_mat3x3([t.x as f32, t.y as f32, t.z as f32], mat3(pose))
}

/// [x, y, z, w], as Rerun stores a quaternion.
pub fn quaternion_xyzw(pose: &Pose) -> [f32; 4] {
    pose.quaternion_xyzw().map(|x| x as f32)
}

fn mat3(pose: &Pose) -> rerun::components::TransformMat3x3 {
    let m = pose.rotation.as_slice(); // column-major, as Rerun's Mat3x3
    let mut cols = [0f32; 9];
    for (c, v) in cols.iter_mut().zip(m) {
        *c = *v as f32;
    }
    rerun::components::TransformMat3x3::from(rerun::datatypes::Mat3x3(cols))
}
