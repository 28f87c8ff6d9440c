//! One state's collisions: per active pair the distance (negative: how deep the shapes overlap),
//! the pairs in contact, and every pair closer than a threshold.

use super::CollisionModel;
use super::aids::ShapeAids;
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

/// One state's result, nearest first: the pairs in contact (distance ≤ 0) and every pair closer
/// than the threshold — or in a run ([`Wanted::RunFlags`]) the pairs in contact, the nearest pair
/// within the threshold, and the pairs nearer than they came before.
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

    /// The pairs in contact, or when none is, the nearest pair within the threshold (if any).
    pub fn in_contact_or_nearest(close: &[PairDistance]) -> &[PairDistance] {
        let touching = close.iter().take_while(|p| p.distance <= 0.0).count();
        &close[..touching.max(close.len().min(1))]
    }
}

/// What a check measures exactly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wanted {
    /// Every pair closer than the threshold, with its distance: a state on its own (`model
    /// --states`, a path's points, sampled states).
    EveryPairWithin,
    /// What a run's flags and summary need, step after step: the pairs in contact, the nearest
    /// pair (the step's smallest distance), and every pair nearer than it has come before in the
    /// run (its closest approach). A pair that is none of these is not measured: the run's
    /// summary, series and contacts are those of measuring every pair, for less work.
    RunFlags,
}

/// What a simulation keeps between checks: where each body was at the last check and how far the
/// points of its shapes can have moved since the first (its path), and per pair of shapes what it
/// measured last (no allocation per step once every pair has been seen).
pub struct CollisionData {
    wanted: Wanted,
    /// How many checks this data has seen.
    check: u64,
    /// The bodies that carry shapes (built at the first check).
    movers: Vec<Mover>,
    /// Per mover: how far the points of its shapes can have travelled since the first check, m (a
    /// bound: per check its body's displacement plus the chord its rotation sweeps at its reach,
    /// rounded up); and last, the world's shapes' and those on links fixed to it, which stay put.
    paths: Vec<f64>,
    /// Per body: its world pose at the last check (the movers').
    body_poses: Vec<Pose>,
    /// Per frame: its world pose worked out at a check (for the shapes measured), and which.
    frames: Vec<(Pose, u64)>,
    /// Per shape, worked out when a check needs it: its bounding sphere's centre and its pose as
    /// parry takes it, and the check they are of.
    placed: Vec<Placed>,
    /// The pairs of shapes, in the order `check_state` visits them, grouped by the pair (of links,
    /// or of a link and a world shape) they belong to: built at the first check.
    checks: Vec<ShapePair>,
    /// The pairs of links and of a link and a world shape, each with its range of `checks`.
    pairs: Vec<CheckedPair>,
    /// In a run, the pair nearest at the last check (within the threshold).
    nearest: Option<usize>,
    /// Per pair of shapes, what is known of it: a distance it was at least at some check plus both
    /// its links' paths then (−∞: nothing). A distance shrinks by no more than the two shapes'
    /// points travel, so it is at least this less both paths now.
    known: Vec<f64>,
    /// Per pair of shapes, where the last measurement found its closest points.
    warm: Vec<WarmStart>,
}

/// A body that carries shapes, and the farthest their points are from its origin (its reach).
#[derive(Clone, Copy, Debug)]
struct Mover {
    body: usize,
    reach: f64,
}

#[derive(Clone, Copy, Debug)]
struct Placed {
    centre: nalgebra::Vector3<f64>,
    parry: Option<PPose>,
    check: u64,
}

/// A pair of shapes: shape `i` (a link's) and shape `j` of another link, or world shape `w`.
#[derive(Clone, Copy, Debug)]
struct ShapePair {
    i: usize,
    other: Other,
}

#[derive(Clone, Copy, Debug)]
enum Other {
    Shape(usize),
    World(usize),
}

/// A pair of a link and what it is checked against, its shapes' pairs `checks[range]`, the two
/// entries of `paths` that are its links', the least of what is known of its shapes' pairs, and (in
/// a run) its smallest distance so far.
#[derive(Clone, Debug)]
struct CheckedPair {
    a: usize,
    b: Against,
    range: std::ops::Range<usize>,
    travellers: [usize; 2],
    known: f64,
    closest: f64,
}

/// Where a pair's closest points were found last time, to start the next search there.
#[derive(Clone, Copy, Debug, Default)]
struct WarmStart {
    /// Two meshes: the pair of triangles found closest.
    triangles: Option<(u32, u32)>,
    /// A mesh's hull: where the search over the hulls ended.
    hull: super::hull::HullWarmStart,
    /// A mesh and a convex shape: apart when last measured.
    apart: bool,
}

/// Kept off every bound beside the round-off of its sums (relative, `4 ε`): far below any distance
/// that matters (m).
const PATH_ROUNDING: f64 = 1e-12;

impl CollisionData {
    /// For states checked on their own ([`Wanted::EveryPairWithin`]).
    pub fn new(shapes: &CollisionModel) -> Self {
        Self::wanting(shapes, Wanted::EveryPairWithin)
    }

    /// For a run's control steps, one after another ([`Wanted::RunFlags`]).
    pub fn for_run(shapes: &CollisionModel) -> Self {
        Self::wanting(shapes, Wanted::RunFlags)
    }

    fn wanting(shapes: &CollisionModel, wanted: Wanted) -> Self {
        let n = shapes.shapes.len();
        let frames = shapes.of_frame.len();
        Self {
            wanted,
            check: 0,
            movers: Vec::new(),
            paths: Vec::new(),
            body_poses: Vec::new(),
            frames: vec![(Pose::identity(), 0); frames],
            placed: vec![Placed { centre: nalgebra::Vector3::zeros(), parry: None, check: 0 }; n],
            checks: Vec::new(),
            pairs: Vec::new(),
            nearest: None,
            known: Vec::new(),
            warm: Vec::new(),
        }
    }

    /// The bodies that carry shapes and their reach; the pairs of shapes to check, grouped by pair:
    /// the link pairs' shapes, then every moving link's shapes against each world shape.
    fn prepare(&mut self, model: &Model, shapes: &CollisionModel, pairs: &[(usize, usize)], world: &[WorldShape]) {
        for s in &shapes.shapes {
            let frame = &model.frames[s.frame];
            let Some(body) = frame.body else { continue };
            let reach = frame.placement.compose(&s.origin).transform_point(&s.bounding_centre).norm() + s.bounding_radius;
            match self.movers.iter_mut().find(|m| m.body == body) {
                Some(m) => m.reach = m.reach.max(reach),
                None => self.movers.push(Mover { body, reach }),
            }
        }
        // the last entry: what stays put
        self.paths = vec![0.0; self.movers.len() + 1];
        self.body_poses = vec![Pose::identity(); model.bodies.len()];
        let traveller = |f: usize| model.frames[f].body.and_then(|b| self.movers.iter().position(|m| m.body == b)).unwrap_or(self.movers.len());
        let add = |a: usize, b: Against, list: &mut Vec<ShapePair>| {
            let start = list.len();
            for &i in &shapes.of_frame[a] {
                match b {
                    Against::Link(b) => list.extend(shapes.of_frame[b].iter().map(|&j| ShapePair { i, other: Other::Shape(j) })),
                    Against::World(w) => list.push(ShapePair { i, other: Other::World(w) }),
                }
            }
            let travellers = [traveller(a), if let Against::Link(b) = b { traveller(b) } else { self.movers.len() }];
            CheckedPair { a, b, range: start..list.len(), travellers, known: f64::NEG_INFINITY, closest: f64::INFINITY }
        };
        let mut checks = Vec::new();
        let mut listed: Vec<CheckedPair> = pairs.iter().map(|&(a, b)| add(a, Against::Link(b), &mut checks)).collect();
        for w in 0..world.len() {
            for (f, frame) in model.frames.iter().enumerate() {
                if frame.body.is_some() && !shapes.of_frame[f].is_empty() {
                    listed.push(add(f, Against::World(w), &mut checks));
                }
            }
        }
        self.known = vec![f64::NEG_INFINITY; checks.len()];
        self.warm = vec![WarmStart::default(); checks.len()];
        self.checks = checks;
        self.pairs = listed;
    }

    /// Moves every mover's path on by how far its body moved since the last check (`body_poses`,
    /// world frame): the displacement of the body's origin plus the chord its rotation sweeps at its
    /// reach, ‖R − R₀‖₂·r = 2 sin(θ/2)·r where 4 sin²(θ/2) = 3 − tr(R₀ᵀR) (`ROUNDING` keeps the
    /// chord from rounding below its true value when θ is tiny).
    fn travel(&mut self, body_poses: &[Pose]) {
        const ROUNDING: f64 = 1e-14;
        for (m, mover) in self.movers.iter().enumerate() {
            let (pose, last) = (&body_poses[mover.body], &mut self.body_poses[mover.body]);
            if self.check > 1 {
                let shift = (pose.translation - last.translation).norm();
                let chord = ((3.0 - pose.rotation.component_mul(&last.rotation).sum()).max(0.0) + ROUNDING).sqrt();
                // rounded up: a path never falls short of the travel it bounds
                self.paths[m] = (self.paths[m] + (shift + chord * mover.reach)).next_up();
            }
            *last = *pose;
        }
    }

    /// How far pair `p`'s two links can have travelled since the first check.
    fn travelled(&self, p: usize) -> f64 {
        let [a, b] = self.pairs[p].travellers;
        self.paths[a] + self.paths[b]
    }

    /// Link (frame) `f`'s world pose at this check.
    fn frame_pose(&mut self, model: &Model, f: usize) -> Pose {
        if self.frames[f].1 != self.check {
            self.frames[f] = (crate::dynamics::frame_pose_in(model, &self.body_poses, f), self.check);
        }
        self.frames[f].0
    }

    /// Shape `i`'s bounding-sphere centre at this check.
    fn centre(&mut self, model: &Model, shapes: &CollisionModel, i: usize) -> nalgebra::Vector3<f64> {
        self.place(model, shapes, i).centre
    }

    /// Shape `i`'s pose as parry takes it at this check.
    fn parry_pose(&mut self, model: &Model, shapes: &CollisionModel, i: usize) -> PPose {
        let s = &shapes.shapes[i];
        let frame = self.frame_pose(model, s.frame);
        let placed = self.place(model, shapes, i);
        *placed.parry.get_or_insert_with(|| to_parry(&frame.compose(&s.origin)))
    }

    fn place(&mut self, model: &Model, shapes: &CollisionModel, i: usize) -> &mut Placed {
        let s = &shapes.shapes[i];
        if self.placed[i].check != self.check {
            let pose = self.frame_pose(model, s.frame).compose(&s.origin);
            self.placed[i] = Placed { centre: pose.transform_point(&s.bounding_centre), parry: None, check: self.check };
        }
        &mut self.placed[i]
    }
}

/// The least distance a pair can be at now from what is `known` of it (−∞: nothing) and how far its
/// links have `travelled` since.
fn known_bound(known: f64, travelled: f64) -> f64 {
    known - travelled - (PATH_ROUNDING + 4.0 * f64::EPSILON * (known.abs() + travelled))
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
    /// What the distance queries keep of it beside parry's shape (a mesh's hull, a box's faces).
    pub aids: ShapeAids,
}

pub enum WorldBound {
    Sphere { centre: nalgebra::Vector3<f64>, radius: f64 },
    Below(f64),
}

impl WorldShape {
    /// A floor at height `z` (world z, m).
    pub fn floor(z: f64) -> Self {
        Self { name: "floor".into(), shape: SharedShape::halfspace(Vector::new(0.0, 0.0, 1.0)), pose: PPose::from_translation(Vector::new(0.0, 0.0, z)), bound: WorldBound::Below(z), drawn: None, aids: ShapeAids::default() }
    }

    /// A scene object: `geometry` at `pose` in the world.
    pub fn fixed(name: &str, geometry: &crate::model::Geometry, pose: &Pose) -> Result<Self, String> {
        let shape = super::geometry::parry_shape(geometry)?;
        let placed = super::geometry::shape_pose(geometry, pose);
        let sphere = shape.compute_local_bounding_sphere();
        let centre = placed.transform_point(&nalgebra::Vector3::new(sphere.center.x, sphere.center.y, sphere.center.z));
        let aids = ShapeAids::of(&shape);
        Ok(Self { name: name.to_string(), shape, pose: to_parry(&placed), bound: WorldBound::Sphere { centre, radius: sphere.radius }, drawn: Some((geometry.clone(), *pose)), aids })
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
/// the check against coal caught — its composite-shape walk for a mesh and another convex shape),
/// and where two convex shapes overlap its contact depth (negative). A mesh is a surface (as coal
/// reads it): overlapping, it has no depth to measure, and the pair's distance is 0 (parry's depth
/// search over two meshes' triangles cost ~4 ms a state on the Panda, for a number with no meaning
/// there).
///
/// A mesh with its hull: first through the hull where that is exact ([`super::hull`]). Two meshes,
/// or a mesh and a box (its faces): by the mesh–mesh search ([`super::mesh_distance`]), their
/// distance when below `limit`, else `limit` (a lower bound). `warm`: where the searches found the
/// closest points last time, updated.
#[allow(clippy::too_many_arguments)]
fn signed_distance(p1: &PPose, s1: &SharedShape, a1: &ShapeAids, p2: &PPose, s2: &SharedShape, a2: &ShapeAids, limit: f64, warm: &mut WarmStart) -> f64 {
    use super::hull::HullDistance;
    let (h1, h2) = (a1.hull.as_deref(), a2.hull.as_deref());
    let hulls = if h1.is_some() || h2.is_some() { super::hull::certified_distance(p1, s1, h1, p2, s2, h2, limit, &mut warm.hull) } else { None };
    if let Some(HullDistance::Exact(d)) = hulls {
        return d;
    }
    let apart = hulls == Some(HullDistance::Apart);
    if let (Some(m1), Some(m2)) = (s1.as_trimesh(), s2.as_trimesh()) {
        return super::mesh_distance::mesh_mesh_distance(p1, m1, p2, m2, limit, &mut warm.triangles);
    }
    if let (Some(mesh), Some(faces), Some(cuboid)) = (s1.as_trimesh(), a2.faces.as_deref(), s2.as_cuboid()) {
        return mesh_box_distance((p1, mesh, &a1.part_points), (p2, faces, cuboid), apart, limit, warm);
    }
    if let (Some(mesh), Some(faces), Some(cuboid)) = (s2.as_trimesh(), a1.faces.as_deref(), s1.as_cuboid()) {
        return mesh_box_distance((p2, mesh, &a2.part_points), (p1, faces, cuboid), apart, limit, warm);
    }
    let d = match (s1.as_support_map(), s2.as_support_map()) {
        (Some(a), Some(b)) => parry3d_f64::query::details::distance_support_map_support_map(&p1.inv_mul(p2), a, b),
        // a mesh and a convex shape: the least distance of a triangle to the (solid) shape, 0
        // where one crosses it or lies inside it. In contact the distance search visits every
        // triangle near the shape, a yes/no intersection test stops at the first: it goes first
        // where the pair was in contact last time and the hulls touch
        _ if s1.as_trimesh().is_some() || s2.as_trimesh().is_some() => {
            let distance = || parry3d_f64::query::distance(p1, s1.as_ref(), p2, s2.as_ref()).map_or(f64::INFINITY, |d| d.distance.max(0.0));
            let d = if warm.apart || apart {
                distance()
            } else if parry3d_f64::query::intersection_test(p1, s1.as_ref(), p2, s2.as_ref()).is_ok_and(|i| i.intersecting) {
                0.0
            } else {
                distance()
            };
            warm.apart = d > 0.0;
            return d;
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

/// A mesh (a surface: its pose, triangles and a point of each connected part) and a solid box (its
/// pose, faces as triangles and the box itself): the mesh–mesh search against the box's faces (0
/// where a triangle crosses one), and 0 where a part of the mesh lies wholly inside the box —
/// unless the mesh's hull is apart from the box (`hulls_apart`). Else as [`signed_distance`].
fn mesh_box_distance(
    (mesh_pose, mesh, part_points): (&PPose, &parry3d_f64::shape::TriMesh, &[Vector]),
    (box_pose, faces, cuboid): (&PPose, &parry3d_f64::shape::TriMesh, &parry3d_f64::shape::Cuboid),
    hulls_apart: bool,
    limit: f64,
    warm: &mut WarmStart,
) -> f64 {
    let d = super::mesh_distance::mesh_mesh_distance(mesh_pose, mesh, box_pose, faces, limit, &mut warm.triangles);
    let inside = |p: &Vector| {
        let local = box_pose.inverse_transform_point(mesh_pose.transform_point(*p));
        local.x.abs() <= cuboid.half_extents.x && local.y.abs() <= cuboid.half_extents.y && local.z.abs() <= cuboid.half_extents.z
    };
    if d > 0.0 && !hulls_apart && part_points.iter().any(inside) {
        return 0.0;
    }
    d
}

/// The collisions of the state whose body poses are `body_poses` (world frame), over `pairs`, and
/// with each of the `world`'s shapes for every link not fixed to the world; pairs farther than
/// `threshold` are not measured past the broad phase. Two broad phases, both exact (a pair skipped
/// is one that cannot be closer than `threshold`, nor than its links' nearest pair of shapes found):
/// what is known of the pair from an earlier check — a distance it was at least at, less how far its
/// shapes' points can have travelled since (from one control step to the next the arm moves little,
/// so a pair of shapes 6 cm apart is looked at again only when it could have come within 5 cm) — and
/// when that is not enough, the gap between the shapes' bounding spheres.
///
/// In a run ([`Wanted::RunFlags`]) a pair is measured only when it could be in contact, nearer
/// than its closest approach so far, or nearer than the nearest pair found at this step; the pair
/// nearest at the last check is measured first, so that the others are mostly left at their bounds.
#[allow(clippy::too_many_arguments)]
pub fn check_state(model: &Model, shapes: &CollisionModel, pairs: &[(usize, usize)], world: &[WorldShape], data: &mut CollisionData, body_poses: &[Pose], threshold: f64, out: &mut StateCollisions) {
    out.close.clear();
    if data.check == 0 {
        data.prepare(model, shapes, pairs, world);
    }
    data.check += 1;
    data.travel(body_poses);
    let run = data.wanted == Wanted::RunFlags;
    // in a run, the pair nearest at the last check first: it most likely is this check's nearest,
    // and its distance rules the others out
    let first = if run { data.nearest.take() } else { None };
    let mut step_nearest = f64::INFINITY;
    for p in first.into_iter().chain((0..data.pairs.len()).filter(|&p| Some(p) != first)) {
        // how near the pair must be to be wanted: within the threshold, and in a run nearer than
        // its closest approach so far or than this step's nearest pair — or in contact
        let level = if run { threshold.min(data.pairs[p].closest.max(step_nearest)) } else { threshold };
        // only a contact is wanted: measured up to the threshold, so that a distance returned as a
        // bound at the limit is never taken for a contact
        let (wanted, limit) = if level > 0.0 { (level, level) } else { (0.0, threshold) };
        let travelled = data.travelled(p);
        if known_bound(data.pairs[p].known, travelled) > wanted {
            continue;
        }
        let mut best = f64::INFINITY;
        for k in data.pairs[p].range.clone() {
            // the least distance the pair of shapes can be at from what is known of it
            let bound = known_bound(data.known[k], travelled);
            if bound > wanted.min(best) {
                continue;
            }
            // what is known does not rule the pair out: its bounding spheres may
            let c = data.checks[k];
            let si = &shapes.shapes[c.i];
            let centre = data.centre(model, shapes, c.i);
            let gap = match c.other {
                Other::Shape(j) => (centre - data.centre(model, shapes, j)).norm() - si.bounding_radius - shapes.shapes[j].bounding_radius,
                Other::World(w) => world[w].gap(&centre, si.bounding_radius),
            };
            if gap > bound {
                data.known[k] = gap + travelled;
                if gap > wanted.min(best) {
                    continue;
                }
            }
            let mut warm = data.warm[k];
            let pose_i = data.parry_pose(model, shapes, c.i);
            let d = match c.other {
                Other::Shape(j) => {
                    let sj = &shapes.shapes[j];
                    let pose_j = data.parry_pose(model, shapes, j);
                    signed_distance(&pose_i, &si.shape, &si.aids, &pose_j, &sj.shape, &sj.aids, limit.min(best), &mut warm)
                }
                Other::World(w) => {
                    let fixed = &world[w];
                    signed_distance(&fixed.pose, &fixed.shape, &fixed.aids, &pose_i, &si.shape, &si.aids, limit.min(best), &mut warm)
                }
            };
            data.warm[k] = warm;
            data.known[k] = d + travelled;
            best = best.min(d);
        }
        let range = data.pairs[p].range.clone();
        data.pairs[p].known = data.known[range].iter().copied().fold(f64::INFINITY, f64::min);
        if best < threshold && (best < level || best <= 0.0) {
            let pair = &mut data.pairs[p];
            out.close.push(PairDistance { a: pair.a, b: pair.b, distance: best });
            pair.closest = pair.closest.min(best);
            if best < step_nearest {
                (step_nearest, data.nearest) = (best, Some(p));
            }
        }
    }
    out.close.sort_by(|x, y| x.distance.total_cmp(&y.distance));
}
