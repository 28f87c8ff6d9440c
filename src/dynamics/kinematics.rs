use super::Data;
use crate::model::{JointKind, JointMotion, Model};
use crate::spatial::{Pose, SpatialInertia, spatial};
use nalgebra::Vector3;

/// Body i's world pose from its parent's (None: the world), and its joint axis in world coordinates.
#[inline]
fn body_pose(motion: &JointMotion, parent: Option<&Pose>, q: f64) -> (Pose, Vector3<f64>) {
    let (rotation, translation) = motion.local_pose(q);
    match parent {
        Some(parent) => (Pose::new(parent.rotation * rotation, parent.translation + parent.rotation * translation), parent.rotation * motion.axis),
        None => (Pose::new(rotation, translation), motion.axis),
    }
}

/// Body poses, joint motion subspaces (scaled by each body's coupling multiplier: a mimic joint
/// moves multiplier × its coordinate's velocity) and body inertias in world coordinates at `q`.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) {
    debug_assert_eq!(q.len(), model.dof());
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate() {
        let (pose, axis_world) = body_pose(&model.motions[i], joint.parent.map(|p| &data.body_pose[p]), coupling.position(q));
        let subspace = match joint.kind {
            JointKind::Revolute | JointKind::Continuous => spatial(axis_world, pose.translation.cross(&axis_world)),
            JointKind::Prismatic => spatial(Vector3::zeros(), axis_world),
        };
        data.motion_subspace[i] = subspace * coupling.multiplier;
        data.body_inertia[i] = SpatialInertia::of_body(&joint.inertia, &pose);
        data.body_pose[i] = pose;
    }
}

/// Only the body poses at `q` (no motion subspaces or inertias): where a command puts the arm.
/// `poses` has one entry per body (`model.bodies`).
pub fn body_poses(model: &Model, q: &[f64], poses: &mut [Pose]) {
    debug_assert_eq!(q.len(), model.dof());
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate() {
        poses[i] = body_pose(&model.motions[i], joint.parent.map(|p| &poses[p]), coupling.position(q)).0;
    }
}

/// World pose of a frame (URDF link), from the body poses of the last `forward_kinematics`.
pub fn frame_pose(model: &Model, data: &Data, frame: usize) -> Pose {
    frame_pose_in(model, &data.body_pose, frame)
}

/// World pose of a frame (URDF link) given the world poses of the bodies.
pub fn frame_pose_in(model: &Model, body_poses: &[Pose], frame: usize) -> Pose {
    let f = &model.frames[frame];
    match f.body {
        Some(b) => body_poses[b].compose(&f.placement),
        None => f.placement,
    }
}
