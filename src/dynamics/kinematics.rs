use super::Data;
use crate::model::{JointKind, Model};
use crate::spatial::{Pose, rotation_about_axis, spatial};
use nalgebra::{Matrix3, Vector3};

/// Body poses, joint motion subspaces and body inertias in world coordinates at `q`.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) {
    debug_assert_eq!(q.len(), model.dof());
    for (i, joint) in model.joints.iter().enumerate() {
        let parent = match joint.parent {
            Some(p) => data.body_pose[p],
            None => Pose::identity(),
        };
        let joint_frame = parent.compose(&joint.placement);
        let axis_world: Vector3<f64> = joint_frame.rotation * joint.axis;
        let pose = match joint.kind {
            JointKind::Revolute | JointKind::Continuous => {
                // rotating about the axis commutes with the axis itself, so R·Rot(a,q) = Rot(R a, q)·R
                Pose::new(rotation_about_axis(&axis_world, q[i]) * joint_frame.rotation, joint_frame.translation)
            }
            JointKind::Prismatic => Pose::new(joint_frame.rotation, joint_frame.translation + axis_world * q[i]),
        };
        data.motion_subspace[i] = match joint.kind {
            JointKind::Revolute | JointKind::Continuous => spatial(axis_world, pose.translation.cross(&axis_world)),
            JointKind::Prismatic => spatial(Vector3::zeros(), axis_world),
        };
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

#[inline]
fn rotate_inertia(r: &Matrix3<f64>, inertia: &Matrix3<f64>) -> Matrix3<f64> {
    r * inertia * r.transpose()
}

/// World pose of a frame (URDF link), from the body poses of the last `forward_kinematics`.
pub fn frame_pose(model: &Model, data: &Data, frame: usize) -> Pose {
    let f = &model.frames[frame];
    match f.body {
        Some(b) => data.body_pose[b].compose(&f.placement),
        None => f.placement,
    }
}
