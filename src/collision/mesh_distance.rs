//! The distance of two triangle meshes, both as surfaces (0 where they cross), by a simultaneous
//! descent of their two bounding-volume trees: a pair of nodes is opened only while its boxes are
//! closer than the best pair of triangles found so far, and the search starts from the pair that was
//! closest at the previous state (a control step moves the arm little). parry's own mesh–mesh query
//! searches the second mesh afresh for every triangle of the first; this one costs a fraction of it
//! on the Panda's and the SmallRobotArm's meshes, with the same answer (triangle–triangle GJK; the
//! coal check in `.ci/` and the fixtures hold).

use parry3d_f64::math::{Matrix, Pose, Vector};
use parry3d_f64::partitioning::BvhNode;
use parry3d_f64::shape::TriMesh;
use std::cell::Cell;

/// The distance between `mesh1` at `pose1` and `mesh2` at `pose2` when it is below `limit`; else
/// `limit` (a lower bound). `warm`: the pair of triangles closest last time, updated.
pub fn mesh_mesh_distance(pose1: &Pose, mesh1: &TriMesh, pose2: &Pose, mesh2: &TriMesh, limit: f64, warm: &mut Option<(u32, u32)>) -> f64 {
    let pose12 = pose1.inv_mul(pose2);
    let rotation = Matrix::from_quat(pose12.rotation);
    let abs_rotation = Matrix::from_cols(rotation.x_axis.abs(), rotation.y_axis.abs(), rotation.z_axis.abs());
    let triangles = |a: u32, b: u32| {
        let (t1, t2) = (mesh1.triangle(a), mesh2.triangle(b));
        triangle_distance([t1.a, t1.b, t1.c], [pose12.transform_point(t2.a), pose12.transform_point(t2.b), pose12.transform_point(t2.c)])
    };
    let best = Cell::new(limit);
    let mut found = None;
    if let Some((a, b)) = *warm {
        let d = triangles(a, b);
        if d < best.get() {
            best.set(d);
            found = Some((a, b));
        }
    }
    if best.get() > 0.0 {
        // node2's box in mesh1's frame: its centre moved, its half extents through |R|
        let apart = |n1: &BvhNode, n2: &BvhNode| {
            let (c2, h2) = ((n2.mins() + n2.maxs()) * 0.5, (n2.maxs() - n2.mins()) * 0.5);
            let (c1, h1) = ((n1.mins() + n1.maxs()) * 0.5, (n1.maxs() - n1.mins()) * 0.5);
            let c2 = pose12.transform_point(c2);
            let h2 = abs_rotation * h2;
            let gap = ((c1 - c2).abs() - h1 - h2).max(Vector::ZERO);
            gap.length() < best.get()
        };
        for (a, b) in mesh1.bvh().leaf_pairs(mesh2.bvh(), apart) {
            let d = triangles(a, b);
            if d < best.get() {
                best.set(d);
                found = Some((a, b));
                if d <= 0.0 {
                    break;
                }
            }
        }
    }
    if found.is_some() {
        *warm = found;
    }
    best.get().max(0.0)
}

/// The distance of two triangles (0 where they cross): the least of the nine edge–edge distances and
/// of each vertex's distance to the other triangle where it projects inside it — the closest points
/// of two apart triangles are on one of those pairs (as in PQP's and coal's TriDist).
pub fn triangle_distance(p: [Vector; 3], q: [Vector; 3]) -> f64 {
    if crosses(&p, &q) || crosses(&q, &p) {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for i in 0..3 {
        for j in 0..3 {
            best = best.min(segment_distance(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3]));
        }
    }
    for (vertices, triangle) in [(&p, &q), (&q, &p)] {
        for v in vertices.iter() {
            if let Some(d) = inside_distance(*v, triangle) {
                best = best.min(d);
            }
        }
    }
    best
}

/// The distance of `v` to the plane of `t` when `v` projects inside `t`.
fn inside_distance(v: Vector, t: &[Vector; 3]) -> Option<f64> {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let area2 = n.length_squared();
    if area2 <= f64::MIN_POSITIVE {
        return None;
    }
    let h = (v - t[0]).dot(n);
    let projected = v - n * (h / area2);
    let inside = (0..3).all(|i| (t[(i + 1) % 3] - t[i]).cross(projected - t[i]).dot(n) >= 0.0);
    inside.then(|| h.abs() / area2.sqrt())
}

/// Whether an edge of `p` passes through triangle `q` (touching included).
fn crosses(p: &[Vector; 3], q: &[Vector; 3]) -> bool {
    let n = (q[1] - q[0]).cross(q[2] - q[0]);
    if n.length_squared() <= f64::MIN_POSITIVE {
        return false;
    }
    (0..3).any(|i| {
        let (a, b) = (p[i], p[(i + 1) % 3]);
        let (da, db) = ((a - q[0]).dot(n), (b - q[0]).dot(n));
        if da * db > 0.0 || da == db {
            // both on one side, or in the plane (coplanar overlap is found by the edge and vertex distances)
            return false;
        }
        let x = a + (b - a) * (da / (da - db));
        (0..3).all(|k| (q[(k + 1) % 3] - q[k]).cross(x - q[k]).dot(n) >= 0.0)
    })
}

/// The distance of segments [p1, q1] and [p2, q2] (Ericson, Real-Time Collision Detection, 5.1.9).
fn segment_distance(p1: Vector, q1: Vector, p2: Vector, q2: Vector) -> f64 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    let eps = 1e-300;
    let (s, t);
    if a <= eps && e <= eps {
        return r.length();
    }
    if a <= eps {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= eps {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 0.0 { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    ((p1 + d1 * s) - (p2 + d2 * t)).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against parry's GJK on random pairs of triangles, apart, touching and crossing.
    #[test]
    fn triangle_distance_is_gjks() {
        let mut seed = 0x1234_5678_9abc_def1_u64;
        let mut uniform = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut point = |spread: f64| Vector::new(spread * (uniform() - 0.5), spread * (uniform() - 0.5), spread * (uniform() - 0.5));
        let (mut crossing, mut apart) = (0, 0);
        for k in 0..20_000 {
            let spread = [0.5, 1.0, 2.0][k % 3];
            let p = [point(1.0), point(1.0), point(1.0)];
            let offset = point(spread);
            let q = [point(1.0) + offset, point(1.0) + offset, point(1.0) + offset];
            let ours = triangle_distance(p, q);
            let gjk = parry3d_f64::query::details::distance_support_map_support_map(&Pose::IDENTITY, &parry3d_f64::shape::Triangle::new(p[0], p[1], p[2]), &parry3d_f64::shape::Triangle::new(q[0], q[1], q[2]));
            assert!((ours - gjk).abs() < 1e-9, "{p:?} {q:?}: {ours} vs GJK {gjk}");
            if gjk == 0.0 { crossing += 1 } else { apart += 1 }
        }
        assert!(crossing > 1000 && apart > 1000, "{crossing} crossing, {apart} apart");
    }
}
