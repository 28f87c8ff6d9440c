use super::Data;
use crate::model::{Joint, JointKind, Model};
use crate::spatial::{Pose, rotation_about_axis, spatial};
use nalgebra::{Matrix3, Vector3};

/// Body `joint`'s world pose from its parent's, and its joint axis in world coordinates.
#[inline]
fn body_pose(joint: &Joint, parent: &Pose, q: f64) -> (Pose, Vector3<f64>) {
    let joint_frame = parent.compose(&joint.placement);
    let axis_world: Vector3<f64> = joint_frame.rotation * joint.axis;
    let pose = match joint.kind {
        JointKind::Revolute | JointKind::Continuous => {
            // rotating about the axis commutes with the axis itself, so R·Rot(a,q) = Rot(R a, q)·R
            Pose::new(rotation_about_axis(&axis_world, q) * joint_frame.rotation, joint_frame.translation)
        }
        JointKind::Prismatic => Pose::new(joint_frame.rotation, joint_frame.translation + axis_world * q),
    };
    (pose, axis_world)
}

/// Body poses, joint motion subspaces (scaled by each body's coupling multiplier: a mimic joint
/// moves multiplier × its coordinate's velocity) and body inertias in world coordinates at `q`.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) {
    debug_assert_eq!(q.len(), model.dof());
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate() {
        let parent = joint.parent.map_or(Pose::identity(), |p| data.body_pose[p]);
        let (pose, axis_world) = body_pose(joint, &parent, coupling.position(q));
        let subspace = match joint.kind {
            JointKind::Revolute | JointKind::Continuous => spatial(axis_world, pose.translation.cross(&axis_world)),
            JointKind::Prismatic => spatial(Vector3::zeros(), axis_world),
        };
        data.motion_subspace[i] = subspace * coupling.multiplier;
        let inertia = &joint.inertia;
        let world = crate::spatial::RigidInertia {
            mass: inertia.mass,
            com: pose.transform_point(&inertia.com),
            inertia_com: rotate_inertia(&pose.rotation, &inertia.inertia_com),
        };
        data.body_inertia[i] = world.spatial_matrix();
        data.body_pose[i] = pose;
    }
}

/// Only the body poses at `q` (no motion subspaces or inertias): where a command puts the arm.
/// `poses` has one entry per body (`model.bodies`).
pub fn body_poses(model: &Model, q: &[f64], poses: &mut [Pose]) {
    debug_assert_eq!(q.len(), model.dof());
    for (i, (joint, coupling)) in model.bodies.iter().zip(&model.couplings).enumerate() {
        let parent = joint.parent.map_or(Pose::identity(), |p| poses[p]);
        poses[i] = body_pose(joint, &parent, coupling.position(q)).0;
    }
}

#[inline]
fn rotate_inertia(r: &Matrix3<f64>, inertia: &Matrix3<f64>) -> Matrix3<f64> {
    r * inertia * r.transpose()
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
