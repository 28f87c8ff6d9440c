//! What the distance queries keep of a shape beside parry's own, built once with the shape: a
//! mesh's convex hull ([`super::hull`]) and a point of each of its connected parts, and a box's
//! faces as triangles (its distance to a mesh by the mesh–mesh search, [`super::mesh_distance`]).

use super::hull::MeshHull;
use parry3d_f64::math::Vector;
use parry3d_f64::shape::{SharedShape, TriMesh};
use std::sync::Arc;

#[derive(Clone, Default)]
pub struct ShapeAids {
    /// A mesh's convex hull, the exact shortcut for its distances.
    pub hull: Option<Arc<MeshHull>>,
    /// A mesh: a vertex of each connected part. A part that crosses no face of a solid shape is
    /// wholly inside it or wholly outside, so one of its points tells which.
    pub part_points: Vec<Vector>,
    /// A box: its six faces as twelve triangles.
    pub faces: Option<Arc<TriMesh>>,
}

impl ShapeAids {
    pub fn of(shape: &SharedShape) -> Self {
        let faces = shape.as_cuboid().and_then(|c| {
            let (vertices, indices) = c.to_trimesh();
            TriMesh::new(vertices, indices).ok().map(Arc::new)
        });
        let part_points = shape.as_trimesh().map(part_points).unwrap_or_default();
        Self { hull: MeshHull::of(shape), part_points, faces }
    }
}

/// A vertex of each connected part of `mesh` (triangles joined through shared vertices).
fn part_points(mesh: &TriMesh) -> Vec<Vector> {
    let mut parent: Vec<u32> = (0..mesh.vertices().len() as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            parent[v as usize] = parent[parent[v as usize] as usize];
            v = parent[v as usize];
        }
        v
    }
    for t in mesh.indices() {
        for &other in &t[1..] {
            let (a, b) = (root(&mut parent, t[0]), root(&mut parent, other));
            parent[a.max(b) as usize] = a.min(b);
        }
    }
    // vertices used by no triangle are no part of the surface
    let mut used = vec![false; parent.len()];
    for t in mesh.indices() {
        for &v in t {
            used[v as usize] = true;
        }
    }
    (0..parent.len() as u32).filter(|&v| used[v as usize] && root(&mut parent, v) == v).map(|v| mesh.vertices()[v as usize]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mesh_of_two_separate_boxes_has_two_parts_and_a_box_has_its_faces() {
        let cube = parry3d_f64::shape::Cuboid::new(Vector::new(0.1, 0.2, 0.3));
        let (mut vertices, mut indices) = cube.to_trimesh();
        let n = vertices.len() as u32;
        vertices.extend(cube.to_trimesh().0.iter().map(|v| *v + Vector::new(1.0, 0.0, 0.0)));
        indices.extend(cube.to_trimesh().1.iter().map(|t| t.map(|i| i + n)));
        // a vertex no triangle uses
        vertices.push(Vector::new(5.0, 5.0, 5.0));
        let aids = ShapeAids::of(&SharedShape::trimesh(vertices, indices).unwrap());
        assert_eq!(aids.part_points.len(), 2);
        assert!(aids.part_points.iter().any(|p| p.x < 0.5) && aids.part_points.iter().any(|p| p.x > 0.5));
        let faces = ShapeAids::of(&SharedShape::new(cube)).faces.unwrap();
        assert_eq!(faces.indices().len(), 12);
        assert!(faces.vertices().iter().all(|v| (v.x.abs() - 0.1).abs() < 1e-15 && (v.y.abs() - 0.2).abs() < 1e-15 && (v.z.abs() - 0.3).abs() < 1e-15));
    }
}
