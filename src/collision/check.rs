//! One state's collisions: per active pair the distance (negative: how deep the shapes overlap),
//! the pairs in contact, and every pair closer than a threshold.

use super::CollisionModel;
use super::hull::MeshHull;
use crate::model::Model;
use crate::spatial::Pose;
use parry3d_f64::math::{Pose as PPose, Vector};
use parry3d_f64::shape::SharedShape;

/// What a link is checked against: another link (a frame index) or a fixed shape of the world (an
/// index into [`super::Collisions::world`]: the floor, a scene's objects).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Against {
    Link(usize),
    World(usize),
}

/// A link (frame index), what it is checked against, and their distance, m (negative inside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairDistance {
    pub a: usize,
    pub b: Against,
    pub distance: f64,
}

/// One state's result: the pairs in contact (distance ≤ 0) and every pair closer than the
/// threshold (those in contact included), nearest first.
#[derive(Clone, Debug, Default)]
pub struct StateCollisions {
    pub close: Vec<PairDistance>,
}

impl StateCollisions {
    pub fn colliding(&self) -> impl Iterator<Item = &PairDistance> {
        self.close.iter().filter(|p| p.distance <= 0.0)
    }

    /// The smallest distance among the pairs closer than the threshold (None: none that close).
    pub fn min_distance(&self) -> Option<f64> {
        self.close.first().map(|p| p.distance)
    }
}

/// What a simulation keeps between checks: the shapes' world poses, and per pair of shapes what it
/// measured last (no allocation per step once every pair has been seen).
pub struct CollisionData {
    poses: Vec<PPose>,
    centres: Vec<nalgebra::Vector3<f64>>,
    rotations: Vec<[f64; 4]>,
    /// Per pair of shapes, in the order `check_state` visits them.
    measured: Vec<Option<Measured>>,
    /// Per pair of shapes, where the last measurement found its closest points.
    warm: Vec<WarmStart>,
}

/// Where a pair's closest points were found last time, to start the next search there.
#[derive(Clone, Copy, Debug, Default)]
struct WarmStart {
    /// Two meshes: the pair of triangles found closest.
    triangles: Option<(u32, u32)>,
    /// A mesh's hull: the triangles of each mesh its closest points lay on.
    hull: (u32, u32),
}

/// A pair of shapes' distance when last measured, and where both shapes were then.
#[derive(Clone, Copy, Debug)]
struct Measured {
    distance: f64,
    centre_a: nalgebra::Vector3<f64>,
    rotation_a: [f64; 4],
    centre_b: nalgebra::Vector3<f64>,
    rotation_b: [f64; 4],
}

impl CollisionData {
    pub fn new(shapes: &CollisionModel) -> Self {
        let n = shapes.shapes.len();
        Self { poses: vec![PPose::identity(); n], centres: vec![nalgebra::Vector3::zeros(); n], rotations: vec![[0.0, 0.0, 0.0, 1.0]; n], measured: Vec::new(), warm: Vec::new() }
    }

    /// How far any point of shape `i` (bounding radius `radius`) can have moved since it was at
    /// (`centre`, `rotation`): its centre's displacement plus the chord its rotation sweeps at the
    /// radius, ‖R − R₀‖·r = 2 sin(θ/2)·r.
    fn moved(&self, i: usize, radius: f64, centre: &nalgebra::Vector3<f64>, rotation: &[f64; 4]) -> f64 {
        let q = &self.rotations[i];
        let dot = q[0] * rotation[0] + q[1] * rotation[1] + q[2] * rotation[2] + q[3] * rotation[3];
        (self.centres[i] - centre).norm() + 2.0 * radius * (1.0 - dot * dot).max(0.0).sqrt()
    }

    /// The least distance shapes `i` and `j` (world shape: `j` None, fixed) can be at now, from what
    /// pair `k` measured last: a distance moves by no more than the points of the two shapes do.
    fn lower_bound(&self, k: usize, i: usize, radius_i: f64, j: Option<(usize, f64)>) -> f64 {
        match self.measured.get(k).copied().flatten() {
            None => f64::NEG_INFINITY,
            Some(m) => m.distance - self.moved(i, radius_i, &m.centre_a, &m.rotation_a) - j.map_or(0.0, |(j, radius_j)| self.moved(j, radius_j, &m.centre_b, &m.rotation_b)),
        }
    }

    fn warm_start(&mut self, k: usize) -> &mut WarmStart {
        if self.warm.len() <= k {
            self.warm.resize(k + 1, WarmStart::default());
        }
        &mut self.warm[k]
    }

    fn remember(&mut self, k: usize, distance: f64, i: usize, j: Option<usize>) {
        if self.measured.len() <= k {
            self.measured.resize(k + 1, None);
        }
        let (centre_b, rotation_b) = j.map_or((nalgebra::Vector3::zeros(), [0.0, 0.0, 0.0, 1.0]), |j| (self.centres[j], self.rotations[j]));
        self.measured[k] = Some(Measured { distance, centre_a: self.centres[i], rotation_a: self.rotations[i], centre_b, rotation_b });
    }
}

/// A fixed shape of the world: the floor (a half-space) or a scene's object.
pub struct WorldShape {
    pub name: String,
    pub shape: SharedShape,
    pub pose: PPose,
    /// The broad phase: a bounding sphere, or for the floor the height of its plane.
    pub bound: WorldBound,
    /// What the recordings draw: a scene object's geometry and its pose in the world (None: the floor).
    pub drawn: Option<(crate::model::Geometry, Pose)>,
    /// A mesh's convex hull ([`super::hull`]).
    pub hull: Option<std::sync::Arc<super::hull::MeshHull>>,
}

pub enum WorldBound {
    Sphere { centre: nalgebra::Vector3<f64>, radius: f64 },
    Below(f64),
}

impl WorldShape {
    /// A floor at height `z` (world z, m).
    pub fn floor(z: f64) -> Self {
        Self { name: "floor".into(), shape: SharedShape::halfspace(Vector::new(0.0, 0.0, 1.0)), pose: PPose::from_translation(Vector::new(0.0, 0.0, z)), bound: WorldBound::Below(z), drawn: None, hull: None }
    }

    /// A scene object: `geometry` at `pose` in the world.
    pub fn fixed(name: &str, geometry: &crate::model::Geometry, pose: &Pose) -> Result<Self, String> {
        let shape = super::geometry::parry_shape(geometry)?;
        let placed = super::geometry::shape_pose(geometry, pose);
        let sphere = shape.compute_local_bounding_sphere();
        let centre = placed.transform_point(&nalgebra::Vector3::new(sphere.center.x, sphere.center.y, sphere.center.z));
        let hull = MeshHull::of(&shape);
        Ok(Self { name: name.to_string(), shape, pose: to_parry(&placed), bound: WorldBound::Sphere { centre, radius: sphere.radius }, drawn: Some((geometry.clone(), *pose)), hull })
    }

    /// How far a sphere at `centre` of `radius` is from this shape's bound at least.
    fn gap(&self, centre: &nalgebra::Vector3<f64>, radius: f64) -> f64 {
        match &self.bound {
            WorldBound::Sphere { centre: c, radius: r } => (centre - c).norm() - radius - r,
            WorldBound::Below(z) => centre.z - radius - z,
        }
    }
}

fn to_parry(p: &Pose) -> PPose {
    let [x, y, z, w] = p.quaternion_xyzw();
    PPose::from_parts(Vector::new(p.translation.x, p.translation.y, p.translation.z), parry3d_f64::math::Rot3::from_xyzw(x, y, z, w).normalize())
}

/// The signed distance of two placed shapes: parry's exact distance (GJK for two convex shapes —
/// parry's own box–box shortcut projects twice and can miss the closest points by millimetres, which
/// the check against coal caught — its composite-shape walk for meshes), and where two convex shapes
/// overlap its contact depth (negative). A mesh is a surface (as coal reads it): overlapping, it has
/// no depth to measure, and the pair's distance is 0 (parry's depth search over two meshes' triangles
/// cost ~4 ms a state on the Panda, for a number with no meaning there).
///
/// A mesh with its hull (`h1`, `h2`): first through the hull where that is exact
/// ([`super::hull`]). Two meshes: their distance by [`super::mesh_distance`] when below `limit`, else
/// `limit` (a lower bound). `warm`: where both searches found the closest points last time, updated.
#[allow(clippy::too_many_arguments)]
fn signed_distance(p1: &PPose, s1: &SharedShape, h1: Option<&MeshHull>, p2: &PPose, s2: &SharedShape, h2: Option<&MeshHull>, limit: f64, warm: &mut WarmStart) -> f64 {
    if (h1.is_some() || h2.is_some())
        && let Some(d) = super::hull::certified_distance(p1, s1, h1, p2, s2, h2, limit, &mut warm.hull)
    {
        return d;
    }
    if let (Some(m1), Some(m2)) = (s1.as_trimesh(), s2.as_trimesh()) {
        return super::mesh_distance::mesh_mesh_distance(p1, m1, p2, m2, limit, &mut warm.triangles);
    }
    let d = match (s1.as_support_map(), s2.as_support_map()) {
        (Some(a), Some(b)) => parry3d_f64::query::details::distance_support_map_support_map(&p1.inv_mul(p2), a, b),
        // a mesh: a yes/no intersection test first (it stops at the first crossing pair of triangles)
        _ if s1.as_trimesh().is_some() || s2.as_trimesh().is_some() => {
            if parry3d_f64::query::intersection_test(p1, s1.as_ref(), p2, s2.as_ref()).is_ok_and(|i| i.intersecting) {
                return 0.0;
            }
            return parry3d_f64::query::distance(p1, s1.as_ref(), p2, s2.as_ref()).map_or(f64::INFINITY, |d| d.distance.max(0.0));
        }
        // the floor (a half-space) with a convex shape
        _ => parry3d_f64::query::distance(p1, s1.as_ref(), p2, s2.as_ref()).map_or(f64::INFINITY, |d| d.distance),
    };
    if d > 0.0 {
        return d;
    }
    match parry3d_f64::query::contact(p1, s1.as_ref(), p2, s2.as_ref(), 0.0) {
        Ok(Some(c)) => c.dist.min(0.0),
        _ => 0.0,
    }
}

/// The collisions of the state whose link poses `frame_pose` gives (world frame), over `pairs`, and
/// with each of the `world`'s shapes for every link not fixed to the world; pairs farther than
/// `threshold` are not measured past the broad phase. Two broad phases, both exact (a pair skipped
/// is one that cannot be closer than `threshold`, nor than its links' nearest pair of shapes found):
/// bounding spheres, and the pair's distance when last measured less how far its shapes can have
/// moved since (from one control step to the next the arm moves little, so a pair of shapes 6 cm
/// apart is measured again only when it could have come within 5 cm).
#[allow(clippy::too_many_arguments)]
pub fn check_state(model: &Model, shapes: &CollisionModel, pairs: &[(usize, usize)], world: &[WorldShape], data: &mut CollisionData, frame_pose: impl Fn(usize) -> Pose, threshold: f64, out: &mut StateCollisions) {
    out.close.clear();
    // a link's shapes follow each other: its pose is worked out once for them
    let mut link: Option<(usize, Pose)> = None;
    for (i, s) in shapes.shapes.iter().enumerate() {
        let frame = match link {
            Some((f, pose)) if f == s.frame => pose,
            _ => {
                let pose = frame_pose(s.frame);
                link = Some((s.frame, pose));
                pose
            }
        };
        let pose = frame.compose(&s.origin);
        data.centres[i] = pose.transform_point(&s.bounding_centre);
        data.rotations[i] = pose.quaternion_xyzw();
        let [x, y, z, w] = data.rotations[i];
        data.poses[i] = PPose::from_parts(Vector::new(pose.translation.x, pose.translation.y, pose.translation.z), parry3d_f64::math::Rot3::from_xyzw(x, y, z, w).normalize());
    }
    let mut k = 0;
    for &(a, b) in pairs {
        let mut best = f64::INFINITY;
        for &i in &shapes.of_frame[a] {
            for &j in &shapes.of_frame[b] {
                let (si, sj) = (&shapes.shapes[i], &shapes.shapes[j]);
                let limit = threshold.min(best);
                let gap = (data.centres[i] - data.centres[j]).norm() - si.bounding_radius - sj.bounding_radius;
                k += 1;
                if gap > limit || data.lower_bound(k - 1, i, si.bounding_radius, Some((j, sj.bounding_radius))) > limit {
                    continue;
                }
                let mut warm = *data.warm_start(k - 1);
                let d = signed_distance(&data.poses[i], &si.shape, si.hull.as_deref(), &data.poses[j], &sj.shape, sj.hull.as_deref(), limit, &mut warm);
                data.warm[k - 1] = warm;
                data.remember(k - 1, d, i, Some(j));
                best = best.min(d);
            }
        }
        if best < threshold {
            out.close.push(PairDistance { a, b: Against::Link(b), distance: best });
        }
    }
    for (w, fixed) in world.iter().enumerate() {
        for (f, frame) in model.frames.iter().enumerate() {
            if frame.body.is_none() || shapes.of_frame[f].is_empty() {
                continue;
            }
            let mut best = f64::INFINITY;
            for &i in &shapes.of_frame[f] {
                let s = &shapes.shapes[i];
                let limit = threshold.min(best);
                k += 1;
                if fixed.gap(&data.centres[i], s.bounding_radius) > limit || data.lower_bound(k - 1, i, s.bounding_radius, None) > limit {
                    continue;
                }
                let mut warm = *data.warm_start(k - 1);
                let d = signed_distance(&fixed.pose, &fixed.shape, fixed.hull.as_deref(), &data.poses[i], &s.shape, s.hull.as_deref(), limit, &mut warm);
                data.warm[k - 1] = warm;
                data.remember(k - 1, d, i, None);
                best = best.min(d);
            }
            if best < threshold {
                out.close.push(PairDistance { a: f, b: Against::World(w), distance: best });
            }
        }
    }
    out.close.sort_by(|x, y| x.distance.total_cmp(&y.distance));
}
