use super::{Joint, JointKind};
use crate::spatial::skew;
use nalgebra::{Matrix3, Vector3};

/// A joint's motion in its parent body's frame, multiplied out once when the model is built, so that
/// a body's world pose costs one 3×3 product: with R_pl the placement's rotation and a the
/// unit axis, Rodrigues' formula Rot(a, q) = a·aᵀ + cos q·(1 − a·aᵀ) + sin q·[a]ₓ premultiplied by
/// R_pl gives R_pl·Rot(a, q) = `fixed` + cos q·`cosine` + sin q·`sine`.
#[derive(Clone, Copy, Debug)]
pub struct JointMotion {
    /// R_pl·a·aᵀ for a revolute joint, R_pl for a prismatic one.
    pub(crate) fixed: Matrix3<f64>,
    pub(crate) cosine: Matrix3<f64>,
    pub(crate) sine: Matrix3<f64>,
    /// The axis in the parent body's frame, R_pl·a.
    pub axis: Vector3<f64>,
    /// The joint frame's origin in the parent body's frame.
    pub(crate) origin: Vector3<f64>,
    pub(crate) prismatic: bool,
}

impl JointMotion {
    pub fn new(joint: &Joint) -> Self {
        let r = joint.placement.rotation;
        let a = joint.axis;
        let outer = a * a.transpose();
        let prismatic = joint.kind == JointKind::Prismatic;
        Self {
            fixed: if prismatic { r } else { r * outer },
            cosine: if prismatic { Matrix3::zeros() } else { r * (Matrix3::identity() - outer) },
            sine: if prismatic { Matrix3::zeros() } else { r * skew(&a) },
            axis: r * a,
            origin: joint.placement.translation,
            prismatic,
        }
    }

    /// The body frame in the parent body's frame at joint position `q`.
    #[inline]
    pub fn local_pose(&self, q: f64) -> (Matrix3<f64>, Vector3<f64>) {
        let sin_cos = if self.prismatic { (0.0, 1.0) } else { q.sin_cos() };
        self.local_pose_from(q, sin_cos)
    }

    /// [`local_pose`](Self::local_pose) with q's (sin q, cos q) given (used by a revolute joint only).
    #[inline]
    pub fn local_pose_from(&self, q: f64, (s, c): (f64, f64)) -> (Matrix3<f64>, Vector3<f64>) {
        if self.prismatic {
            (self.fixed, self.origin + self.axis * q)
        } else {
            (self.fixed + self.cosine * c + self.sine * s, self.origin)
        }
    }
}


#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::{Pose, RigidInertia, rotation_about_axis};

    fn joint(kind: JointKind, axis: Vector3<f64>) -> Joint {
        Joint {
            name: "j".into(),
            kind,
            parent: None,
            placement: Pose::from_xyz_rpy([0.1, -0.2, 0.3], [0.4, -0.9, 1.3]),
            axis: axis.normalize(),
            inertia: RigidInertia::zero(),
            lower: -1.0,
            upper: 1.0,
            effort: 1.0,
            velocity: 1.0,
            damping: 0.0,
            friction: 0.0,
            child_link: "l".into(),
        }
    }

    #[test]
    fn local_pose_is_the_placement_composed_with_the_joint_motion() {
        // against the definition: placement ∘ (rotation about a by q), or ∘ (translation a·q)
        for axis in [Vector3::z(), Vector3::new(0.3, -0.5, 0.8)] {
            for q in [-2.5, -0.3, 0.0, 0.7, 3.0] {
                let j = joint(JointKind::Revolute, axis);
                let expected = j.placement.compose(&Pose::new(rotation_about_axis(&j.axis, q), Vector3::zeros()));
                let (rotation, translation) = JointMotion::new(&j).local_pose(q);
                assert!((rotation - expected.rotation).abs().max() < 1e-15 && (translation - expected.translation).abs().max() < 1e-15);
                let j = joint(JointKind::Prismatic, axis);
                let expected = j.placement.compose(&Pose::new(Matrix3::identity(), j.axis * q));
                let (rotation, translation) = JointMotion::new(&j).local_pose(q);
                assert!((rotation - expected.rotation).abs().max() < 1e-15 && (translation - expected.translation).abs().max() < 1e-15);
            }
        }
    }
}
