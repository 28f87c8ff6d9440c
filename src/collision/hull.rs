//! A triangle mesh's convex hull as an exact shortcut for its distance to a convex shape or to
//! another mesh. Every triangle of the mesh lies within the hull, so the distance to the hull is a
//! lower bound of the distance to the mesh; where the hull's closest point also lies on one of the
//! mesh's triangles, the mesh has a point that far away and the two distances are equal. Collision
//! meshes are mostly convex (the Panda's are their hulls but for quads split along the other
//! diagonal, dents of 0.02–0.23 mm), so one GJK on the hulls (~150 points) replaces a walk over the
//! mesh's tree with a GJK per triangle; where the closest point falls in a dent, or the hulls
//! overlap, the caller measures the mesh itself. The answer is the mesh's within
//! [`ON_SURFACE`] (the gap allowed between the hull's closest point and the triangle it lies on).

use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::PointQuery;
use parry3d_f64::query::gjk::{self, CsoPoint, GJKResult, VoronoiSimplex};
use parry3d_f64::shape::{SharedShape, SupportMap, TriMesh, Triangle};

/// How close the hull's closest point must be to a triangle of the mesh for the hull's distance to
/// stand for the mesh's (m): the error allowed, far below the 1e-5 m the check against coal asks.
pub const ON_SURFACE: f64 = 1e-9;

/// A mesh's convex hull and the mesh's triangles that lie on it.
pub struct MeshHull {
    /// The hull's vertices (all of them vertices of the mesh), in the mesh's frame.
    points: Vec<Vector>,
    /// Each hull vertex's neighbours along the hull's edges: the support point is found by climbing
    /// from the last one (on a convex polytope a vertex no neighbour beats is the farthest).
    neighbours: Vec<Vec<u32>>,
    /// The mesh's triangles in a supporting plane of the hull (every vertex of the mesh on one side
    /// of its plane): the only ones the hull's closest point can lie on.
    surface: Vec<Triangle>,
}

/// What one pair of shapes found last time, to start the next search there: the surface
/// triangles its closest points lay on, the hull vertices its support points were, and GJK's last
/// simplex — its points as the pair of points on the two shapes, each in its own shape's frame, so
/// that they are points of the two shapes wherever the shapes are now.
#[derive(Clone, Copy, Debug, Default)]
pub struct HullWarmStart {
    pub surface: (u32, u32),
    pub climb: (u32, u32),
    simplex: [(Vector, Vector); 4],
    simplex_points: usize,
}

/// A hull whose support points are climbed to from where its pair's last search ended: from one
/// control step to the next the support point moves by a vertex or none.
struct Climbing<'a> {
    hull: &'a MeshHull,
    at: std::cell::Cell<u32>,
}

impl SupportMap for Climbing<'_> {
    fn local_support_point(&self, dir: Vector) -> Vector {
        let at = self.hull.climb(self.at.get(), dir);
        self.at.set(at);
        self.hull.points[at as usize]
    }
}

impl MeshHull {
    /// A shape's hull when it is a mesh that has one.
    pub fn of(shape: &SharedShape) -> Option<std::sync::Arc<Self>> {
        shape.as_trimesh().and_then(Self::new).map(std::sync::Arc::new)
    }

    /// The hull of `mesh`; None when it has none (a flat mesh).
    pub fn new(mesh: &TriMesh) -> Option<Self> {
        let vertices = mesh.vertices();
        let (points, faces) = parry3d_f64::transformation::try_convex_hull(vertices).ok()?;
        if points.len() < 4 {
            return None;
        }
        let mut neighbours = vec![Vec::new(); points.len()];
        for face in &faces {
            for (a, b) in [(face[0], face[1]), (face[1], face[2]), (face[2], face[0])] {
                for (from, to) in [(a, b), (b, a)] {
                    if !neighbours[from as usize].contains(&to) {
                        neighbours[from as usize].push(to);
                    }
                }
            }
        }
        let extent = mesh.local_aabb().extents().length();
        // a candidate only: whether the hull's closest point is on a triangle is measured exactly
        let planar = 1e-7 * extent.max(1e-3);
        let surface = (0..mesh.indices().len() as u32)
            .map(|i| mesh.triangle(i))
            .filter(|t| {
                let Some(normal) = t.normal() else { return false };
                let (mut above, mut below) = (0.0_f64, 0.0_f64);
                for v in vertices {
                    let h = normal.dot(*v - t.a);
                    above = above.max(h);
                    below = below.min(h);
                }
                above <= planar || below >= -planar
            })
            .collect();
        Some(Self { points, neighbours, surface })
    }

    /// The vertex farthest along `dir`, climbing the hull's edges from vertex `from`.
    fn climb(&self, from: u32, dir: Vector) -> u32 {
        let mut at = (from as usize).min(self.points.len() - 1);
        let mut best = self.points[at].dot(dir);
        loop {
            let mut next = at;
            for &n in &self.neighbours[at] {
                let d = self.points[n as usize].dot(dir);
                if d > best {
                    (best, next) = (d, n as usize);
                }
            }
            if next == at {
                return at as u32;
            }
            at = next;
        }
    }

    /// How many of the mesh's triangles lie on the hull.
    pub fn surface_triangles(&self) -> usize {
        self.surface.len()
    }

    /// Whether `p` (mesh frame) lies on a triangle of the mesh, within [`ON_SURFACE`]; `hint` is
    /// the triangle found last time, tried first.
    fn on_surface(&self, p: Vector, hint: &mut u32) -> bool {
        let near = |t: &Triangle| t.distance_to_local_point(p, true) <= ON_SURFACE;
        if self.surface.get(*hint as usize).is_some_and(near) {
            return true;
        }
        match self.surface.iter().position(near) {
            Some(i) => {
                *hint = i as u32;
                true
            }
            None => false,
        }
    }
}

/// A shape's convex stand-in for GJK: a convex shape itself, or a mesh's hull climbed from `from`.
enum Support<'a> {
    Convex(&'a dyn SupportMap),
    Hull(Climbing<'a>),
}

impl<'a> Support<'a> {
    fn of(shape: &'a SharedShape, hull: Option<&'a MeshHull>, from: u32) -> Option<Self> {
        match hull {
            Some(hull) => Some(Support::Hull(Climbing { hull, at: from.into() })),
            None => shape.as_support_map().map(Support::Convex),
        }
    }

    fn map(&self) -> &dyn SupportMap {
        match self {
            Support::Convex(s) => *s,
            Support::Hull(h) => h,
        }
    }

    /// Where a hull's climb ended (a convex shape: `unchanged`).
    fn climbed(&self, unchanged: u32) -> u32 {
        match self {
            Support::Convex(_) => unchanged,
            Support::Hull(h) => h.at.get(),
        }
    }
}

/// GJK's closest points of two convex shapes from `simplex` (both in the first shape's frame), and a
/// lower bound of their distance that shows how exact they are: every point x of the shapes'
/// difference has x·u ≥ s·u, with u the direction between the closest points and s the support
/// point opposite it, so the distance is within [s·u, |p1 − p2|]. None: the shapes overlap.
fn closest_points(pos12: &Pose, g1: &dyn SupportMap, g2: &dyn SupportMap, simplex: &mut VoronoiSimplex) -> Option<(Vector, Vector, f64)> {
    let GJKResult::ClosestPoints(p1, p2, _) = gjk::closest_points(pos12, g1, g2, f64::MAX, true, simplex) else {
        return None;
    };
    let u = (p1 - p2).normalize_or_zero();
    let lower = CsoPoint::from_shapes(pos12, g1, g2, -u).point.dot(u);
    Some((p1, p2, lower))
}

/// What the hulls of two shapes (at least one a mesh) show of the shapes' distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HullDistance {
    /// The shapes' distance: the hulls apart and their closest points on the meshes themselves; or a
    /// lower bound of the hulls' distance when that is above the limit (as the mesh–mesh search
    /// returns).
    Exact(f64),
    /// The hulls are apart (so are the shapes within them), but the distance is the meshes' to
    /// measure: the hull's closest point lies in a dent of the mesh.
    Apart,
    /// The hulls touch or overlap: the meshes are to be measured, contact included.
    Touching,
}

/// The distance of two shapes of which at least one is a mesh with its hull, when the hulls show
/// it exactly ([`HullDistance`]; None: a shape has no support map). `warm`: where the pair's last
/// search ended, updated — GJK starts from its last simplex (its points are points of the two
/// shapes wherever they are, so their differences are points of the shapes' difference, as GJK's
/// simplex must be; after a small motion the closest features are those of last time and GJK stops
/// after one support point), and each hull's support points are climbed to from the last.
#[allow(clippy::too_many_arguments)]
pub fn certified_distance(pose1: &Pose, shape1: &SharedShape, hull1: Option<&MeshHull>, pose2: &Pose, shape2: &SharedShape, hull2: Option<&MeshHull>, limit: f64, warm: &mut HullWarmStart) -> Option<HullDistance> {
    let (s1, s2) = (Support::of(shape1, hull1, warm.climb.0)?, Support::of(shape2, hull2, warm.climb.1)?);
    let (g1, g2) = (s1.map(), s2.map());
    let pos12 = pose1.inv_mul(pose2);
    let mut simplex = VoronoiSimplex::new();
    let kept = &warm.simplex[..warm.simplex_points];
    let mut found = None;
    if let Some((&(a, b), rest)) = kept.split_first() {
        simplex.reset(CsoPoint::new(a, pos12.transform_point(b)));
        for &(a, b) in rest {
            simplex.add_point(CsoPoint::new(a, pos12.transform_point(b)));
        }
        // a simplex of points far from the closest ones can leave GJK stuck short of them (it
        // drops a new point too close to the simplex's plane): then it starts afresh
        found = closest_points(&pos12, g1, g2, &mut simplex).filter(|&(p1, p2, lower)| (p1 - p2).length() - lower <= ON_SURFACE);
    }
    if found.is_none() {
        let dir = -pos12.translation;
        let dir = if dir.length_squared() > 1e-24 { dir.normalize() } else { Vector::X };
        simplex.reset(CsoPoint::from_shapes(&pos12, g1, g2, dir));
        found = closest_points(&pos12, g1, g2, &mut simplex);
    }
    warm.climb = (s1.climbed(warm.climb.0), s2.climbed(warm.climb.1));
    let Some((p1, p2, lower)) = found else {
        warm.simplex_points = 0;
        return Some(HullDistance::Touching);
    };
    warm.simplex_points = simplex.dimension() + 1;
    for i in 0..warm.simplex_points {
        let p = simplex.point(i);
        warm.simplex[i] = (p.orig1, pos12.inverse_transform_point(p.orig2));
    }
    if lower > limit {
        return Some(HullDistance::Exact(lower));
    }
    let distance = (p1 - p2).length();
    // touching hulls, or closest points GJK did not pin down: the meshes are measured
    if distance <= ON_SURFACE {
        return Some(HullDistance::Touching);
    }
    if distance - lower > ON_SURFACE {
        return Some(if lower > 0.0 { HullDistance::Apart } else { HullDistance::Touching });
    }
    // p1 in shape 1's frame, p2 too (GJK's answer is in the first shape's frame)
    let on_surface1 = hull1.is_none_or(|h| h.on_surface(p1, &mut warm.surface.0));
    let on_surface2 = on_surface1 && hull2.is_none_or(|h| h.on_surface(pos12.inverse_transform_point(p2), &mut warm.surface.1));
    Some(if on_surface2 { HullDistance::Exact(distance) } else { HullDistance::Apart })
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::math::Rot3;

    /// A ball of radius 5 cm as a UV mesh whose vertices are moved radially by up to ±0.5 mm: its
    /// quads are not planar and each is split along a fixed diagonal, so about half of them dent
    /// inwards as the Panda's meshes do.
    fn dented_ball(seed: &mut u64) -> TriMesh {
        let (rings, segments) = (8u32, 12u32);
        let mut vertices = vec![Vector::new(0.0, 0.0, 0.05), Vector::new(0.0, 0.0, -0.05)];
        for r in 1..rings {
            let theta = std::f64::consts::PI * r as f64 / rings as f64;
            for s in 0..segments {
                let phi = std::f64::consts::TAU * s as f64 / segments as f64;
                let radius = 0.05 + 0.0005 * (2.0 * unit(seed) - 1.0);
                vertices.push(Vector::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()) * radius);
            }
        }
        let at = |r: u32, s: u32| 2 + (r - 1) * segments + s % segments;
        let mut indices = Vec::new();
        for s in 0..segments {
            indices.push([0, at(1, s), at(1, s + 1)]);
            indices.push([1, at(rings - 1, s + 1), at(rings - 1, s)]);
            for r in 1..rings - 1 {
                indices.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
                indices.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
            }
        }
        TriMesh::new(vertices, indices).unwrap()
    }

    fn unit(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed % 1_000_001) as f64 / 1_000_000.0
    }

    fn random_pose(seed: &mut u64, reach: f64) -> Pose {
        let mut u = || 2.0 * unit(seed) - 1.0;
        let axis = Vector::new(u(), u(), u());
        let angle = 3.0 * u();
        let rotation = if axis.length() > 1e-3 { Rot3::from_axis_angle(axis.normalize(), angle) } else { Rot3::IDENTITY };
        Pose::from_parts(Vector::new(u(), u(), u()) * reach, rotation)
    }

    #[test]
    fn the_hulls_distance_where_certified_is_the_meshs() {
        // against parry's own mesh–box distance and the mesh–mesh search, on dented meshes: equal
        // within ON_SURFACE where certified; both outcomes occur
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let (mut certified, mut refused) = (0, 0);
        for case in 0..400 {
            let mesh = dented_ball(&mut seed);
            let hull = MeshHull::new(&mesh).expect("a ball has a hull");
            assert!(hull.surface_triangles() > 0 && hull.surface_triangles() < mesh.indices().len(), "some triangles dent in, some do not");
            let ball = SharedShape::new(mesh.clone());
            let pose1 = random_pose(&mut seed, 0.05);
            let (other, other_hull) = if case % 2 == 0 {
                (SharedShape::cuboid(0.01 + 0.02 * unit(&mut seed), 0.01 + 0.02 * unit(&mut seed), 0.005 + 0.01 * unit(&mut seed)), None)
            } else {
                let m = dented_ball(&mut seed);
                let h = MeshHull::new(&m).map(std::sync::Arc::new);
                (SharedShape::new(m), h)
            };
            let pose2 = random_pose(&mut seed, 0.12);
            let mut warm = HullWarmStart::default();
            let Some(HullDistance::Exact(d)) = certified_distance(&pose1, &ball, Some(&hull), &pose2, &other, other_hull.as_deref(), f64::INFINITY, &mut warm) else {
                refused += 1;
                continue;
            };
            certified += 1;
            let exact = match other.as_trimesh() {
                Some(m2) => crate::collision::mesh_distance::mesh_mesh_distance(&pose1, &mesh, &pose2, m2, f64::INFINITY, &mut None),
                None => parry3d_f64::query::distance(&pose1, ball.as_ref(), &pose2, other.as_ref()).unwrap().distance,
            };
            assert!((d - exact).abs() <= 1e-9, "case {case}: hull {d} vs mesh {exact}");
        }
        assert!(certified > 100 && refused > 10, "certified {certified}, measured on the mesh {refused}");
    }
}
