use super::{Data, frame_pose};
use crate::model::Model;
use crate::spatial::{angular, linear};
use nalgebra::{DMatrix, Vector3};

/// Geometric Jacobian of a frame's origin in world axes (6 × dof): rows 0–2 angular velocity,
/// rows 3–5 the velocity of the frame origin. Uses the last `forward_kinematics`.
pub fn frame_jacobian(model: &Model, data: &Data, frame: usize, out: &mut DMatrix<f64>) {
    let origin = frame_pose(model, data, frame).translation;
    out.fill(0.0);
    let mut body = model.frames[frame].body;
    while let Some(j) = body {
        let s = &data.motion_subspace[j];
        let w = angular(s);
        // S is referred to the world origin; shift its linear part to the frame origin.
        let v = linear(s) + w.cross(&origin);
        // a mimic joint's motion adds to its coordinate's column
        let c = model.couplings[j].coordinate;
        for r in 0..3 {
            out[(r, c)] += w[r];
            out[(r + 3, c)] += v[r];
        }
        body = model.bodies[j].parent;
    }
}

/// Row 5 of [`frame_jacobian`] (the world-vertical velocity of the point `origin`, the frame's
/// origin, per coordinate) into `out`, with the same arithmetic: bit for bit that row, without the
/// other five (a floor contact needs only the vertical).
pub fn frame_vertical_jacobian(model: &Model, data: &Data, frame: usize, origin: &Vector3<f64>, out: &mut [f64]) {
    out.fill(0.0);
    let mut body = model.frames[frame].body;
    while let Some(j) = body {
        let s = &data.motion_subspace[j];
        let w = angular(s);
        // the z of linear(S) + w × origin
        out[model.couplings[j].coordinate] += linear(s)[2] + (w[0] * origin[1] - w[1] * origin[0]);
        body = model.bodies[j].parent;
    }
}
