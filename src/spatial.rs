//! Spatial (6D) algebra in world coordinates.
//!
//! Every spatial vector is stored angular part first: a motion vector is (ω, v_O), a force
//! vector is (n_O, f), both referred to the world origin O. Working in world coordinates
//! (as Pinocchio does) means the backward passes add children into parents without any
//! 6×6 coordinate transform, which keeps RNEA/CRBA/ABA cheap.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

mod inertia;
pub use inertia::SpatialInertia;

/// A rigid transform stored as a rotation matrix and a translation (cheaper to compose and apply
/// on hot paths than a quaternion).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub rotation: Matrix3<f64>,
    pub translation: Vector3<f64>,
}

impl Default for Pose {
    fn default() -> Self {
        Self::identity()
    }
}

impl Pose {
    pub fn identity() -> Self {
        Self { rotation: Matrix3::identity(), translation: Vector3::zeros() }
    }

    pub fn new(rotation: Matrix3<f64>, translation: Vector3<f64>) -> Self {
        Self { rotation, translation }
    }

    /// URDF `<origin xyz rpy>`: R = Rz(yaw)·Ry(pitch)·Rx(roll), fixed axes.
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Self {
        Self::new(rotation_from_rpy(rpy), Vector3::from(xyz))
    }

    /// self ∘ other: the pose of `other`'s frame expressed in the frame `self` is expressed in.
    #[inline]
    pub fn compose(&self, other: &Pose) -> Pose {
        Pose {
            rotation: self.rotation * other.rotation,
            translation: self.translation + self.rotation * other.translation,
        }
    }

    #[inline]
    pub fn transform_point(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.translation + self.rotation * p
    }

    /// The rotation as a unit quaternion [x, y, z, w].
    pub fn quaternion_xyzw(&self) -> [f64; 4] {
        let q = nalgebra::UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(self.rotation));
        [q.i, q.j, q.k, q.w]
    }

    pub fn inverse(&self) -> Pose {
        let rt = self.rotation.transpose();
        Pose { rotation: rt, translation: -(rt * self.translation) }
    }
}

pub fn rotation_from_rpy([roll, pitch, yaw]: [f64; 3]) -> Matrix3<f64> {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    Matrix3::new(
        cy * cp,
        cy * sp * sr - sy * cr,
        cy * sp * cr + sy * sr,
        sy * cp,
        sy * sp * sr + cy * cr,
        sy * sp * cr - cy * sr,
        -sp,
        cp * sr,
        cp * cr,
    )
}

/// Rotation by `angle` about the unit vector `axis` (Rodrigues).
#[inline]
pub fn rotation_about_axis(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    // R = c·I + s·[a]× + (1 − c)·a·aᵀ
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let (x, y, z) = (axis.x, axis.y, axis.z);
    Matrix3::new(
        c + t * x * x,
        t * x * y - s * z,
        t * x * z + s * y,
        t * x * y + s * z,
        c + t * y * y,
        t * y * z - s * x,
        t * x * z - s * y,
        t * y * z + s * x,
        c + t * z * z,
    )
}

#[inline]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

#[inline]
pub fn angular(m: &Vector6<f64>) -> Vector3<f64> {
    Vector3::new(m[0], m[1], m[2])
}

#[inline]
pub fn linear(m: &Vector6<f64>) -> Vector3<f64> {
    Vector3::new(m[3], m[4], m[5])
}

#[inline]
pub fn spatial(angular: Vector3<f64>, linear: Vector3<f64>) -> Vector6<f64> {
    Vector6::new(angular.x, angular.y, angular.z, linear.x, linear.y, linear.z)
}

/// Motion cross product v ×ₘ m (the derivative of a motion vector fixed in a frame moving with v).
#[inline]
pub fn cross_motion(v: &Vector6<f64>, m: &Vector6<f64>) -> Vector6<f64> {
    let (w, vo) = (angular(v), linear(v));
    let (mw, mv) = (angular(m), linear(m));
    spatial(w.cross(&mw), w.cross(&mv) + vo.cross(&mw))
}

/// Force cross product v ×* f.
#[inline]
pub fn cross_force(v: &Vector6<f64>, f: &Vector6<f64>) -> Vector6<f64> {
    let (w, vo) = (angular(v), linear(v));
    let (n, fl) = (angular(f), linear(f));
    spatial(w.cross(&n) + vo.cross(&fl), w.cross(&fl))
}

/// The inertia of one rigid body in its own frame: mass, centre of mass and the rotational
/// inertia about the centre of mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidInertia {
    pub mass: f64,
    pub com: Vector3<f64>,
    pub inertia_com: Matrix3<f64>,
}

impl RigidInertia {
    pub fn zero() -> Self {
        Self { mass: 0.0, com: Vector3::zeros(), inertia_com: Matrix3::zeros() }
    }

    /// Whether its central inertia is diagonal (the body's frame on its principal axes, as most
    /// URDFs' links are): rotating it then only scales the rotation's columns.
    #[inline]
    pub fn on_principal_axes(&self) -> bool {
        let i = &self.inertia_com;
        i[(0, 1)] == 0.0 && i[(0, 2)] == 0.0 && i[(1, 2)] == 0.0 && i[(1, 0)] == 0.0 && i[(2, 0)] == 0.0 && i[(2, 1)] == 0.0
    }

    /// The same body seen from another frame: `pose` is this body's frame in the other frame.
    pub fn transformed(&self, pose: &Pose) -> RigidInertia {
        RigidInertia {
            mass: self.mass,
            com: pose.transform_point(&self.com),
            inertia_com: pose.rotation * self.inertia_com * pose.rotation.transpose(),
        }
    }

    /// The combined inertia of two bodies expressed in the same frame (parallel-axis theorem).
    pub fn combined(&self, other: &RigidInertia) -> RigidInertia {
        let mass = self.mass + other.mass;
        if mass <= 0.0 {
            return RigidInertia { mass, com: Vector3::zeros(), inertia_com: self.inertia_com + other.inertia_com };
        }
        let com = (self.com * self.mass + other.com * other.mass) / mass;
        let shift = |body: &RigidInertia| {
            let d = body.com - com;
            body.inertia_com + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * body.mass
        };
        RigidInertia { mass, com, inertia_com: shift(self) + shift(other) }
    }

    /// The 6×6 spatial inertia referred to the origin of the frame this inertia is expressed in.
    #[inline]
    pub fn spatial_matrix(&self) -> Matrix6<f64> {
        let h = self.com * self.mass;
        let hx = skew(&h);
        let cx = skew(&self.com);
        let inertia_origin = self.inertia_com - cx * hx;
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&inertia_origin);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&hx);
        m.fixed_view_mut::<3, 3>(3, 0).copy_from(&hx.transpose());
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&(Matrix3::identity() * self.mass));
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_matches_composition_of_fixed_axis_rotations() {
        let rpy = [0.3, -0.7, 1.1];
        let expected = rotation_about_axis(&Vector3::z(), rpy[2])
            * rotation_about_axis(&Vector3::y(), rpy[1])
            * rotation_about_axis(&Vector3::x(), rpy[0]);
        assert!((rotation_from_rpy(rpy) - expected).norm() < 1e-14);
    }

    #[test]
    fn spatial_inertia_momentum_matches_point_mass_formula() {
        // a point mass at c moving with (ω, v_O): p = m (v_O + ω × c), L_O = c × p
        let body = RigidInertia { mass: 2.0, com: Vector3::new(0.1, -0.2, 0.3), inertia_com: Matrix3::zeros() };
        let w = Vector3::new(0.4, 0.5, -0.6);
        let vo = Vector3::new(1.0, 2.0, 3.0);
        let h = body.spatial_matrix() * spatial(w, vo);
        let p = (vo + w.cross(&body.com)) * body.mass;
        assert!((linear(&h) - p).norm() < 1e-14);
        assert!((angular(&h) - body.com.cross(&p)).norm() < 1e-14);
    }

    #[test]
    fn combining_inertias_preserves_spatial_matrix_sum() {
        let a = RigidInertia { mass: 1.5, com: Vector3::new(0.1, 0.0, 0.2), inertia_com: Matrix3::from_diagonal(&Vector3::new(0.01, 0.02, 0.015)) };
        let b = RigidInertia { mass: 0.5, com: Vector3::new(-0.3, 0.4, 0.0), inertia_com: Matrix3::from_diagonal(&Vector3::new(0.003, 0.001, 0.0035)) };
        let sum = a.spatial_matrix() + b.spatial_matrix();
        assert!((a.combined(&b).spatial_matrix() - sum).norm() < 1e-14);
    }
}
