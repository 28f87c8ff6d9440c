//! A rigid body's spatial inertia in the ten numbers it has (Pinocchio's `Inertia`), instead of a
//! 6×6 matrix of 36: adding two costs 10 additions, applying one to a motion vector 30 products.
//! The recursions (CRBA's composite inertias, RNEA's forces) work on this form.

use super::{Pose, RigidInertia};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use std::ops::{Add, AddAssign};

/// The spatial inertia of a body referred to the world origin O: its mass m, its first moment
/// h = m·c (c the centre of mass) and its rotational inertia about O, I_O = I_c + m·(|c|²·1 − c·cᵀ),
/// which is symmetric and kept as its six entries. As a matrix (angular part first):
///
/// ```text
///   [ I_O    [h]ₓ ]
///   [ [h]ₓᵀ  m·1  ]
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialInertia {
    pub mass: f64,
    pub first_moment: Vector3<f64>,
    /// I_O's entries xx, yy, zz, xy, xz, yz.
    pub rotational: [f64; 6],
}

impl Default for SpatialInertia {
    fn default() -> Self {
        Self::zero()
    }
}

impl SpatialInertia {
    pub const fn zero() -> Self {
        Self { mass: 0.0, first_moment: Vector3::new(0.0, 0.0, 0.0), rotational: [0.0; 6] }
    }

    /// The inertia of `body` (given in its own frame) seen from the frame `pose` is expressed in:
    /// its centre of mass moved by the pose, its central inertia rotated, R·I_c·Rᵀ, then shifted
    /// to the origin (parallel axes).
    #[inline]
    pub fn of_body(body: &RigidInertia, pose: &Pose) -> Self {
        let m = body.mass;
        let c = pose.transform_point(&body.com);
        let h = c * m;
        let r = &pose.rotation;
        // R·I_c, then only the six distinct entries of (R·I_c)·Rᵀ; a central inertia on its
        // principal axes (most URDFs' links) only scales R's columns — the same numbers, as the
        // full product's other terms are exact zeros
        let i = &body.inertia_com;
        let ri = if body.on_principal_axes() {
            Matrix3::from_columns(&[r.column(0) * i[(0, 0)], r.column(1) * i[(1, 1)], r.column(2) * i[(2, 2)]])
        } else {
            r * i
        };
        let entry = |a: usize, b: usize| ri[(a, 0)] * r[(b, 0)] + ri[(a, 1)] * r[(b, 1)] + ri[(a, 2)] * r[(b, 2)];
        let (hx, hy, hz) = (h.x, h.y, h.z);
        let (cx, cy, cz) = (c.x, c.y, c.z);
        Self {
            mass: m,
            first_moment: h,
            rotational: [
                entry(0, 0) + (hy * cy + hz * cz),
                entry(1, 1) + (hx * cx + hz * cz),
                entry(2, 2) + (hx * cx + hy * cy),
                entry(0, 1) - hx * cy,
                entry(0, 2) - hx * cz,
                entry(1, 2) - hy * cz,
            ],
        }
    }

    /// I_O applied to a 3-vector.
    #[inline]
    fn rotational_times(&self, w: &Vector3<f64>) -> Vector3<f64> {
        let [xx, yy, zz, xy, xz, yz] = self.rotational;
        Vector3::new(xx * w.x + xy * w.y + xz * w.z, xy * w.x + yy * w.y + yz * w.z, xz * w.x + yz * w.y + zz * w.z)
    }

    /// The momentum (force vector) of this inertia moving with the motion vector (ω, v_O):
    /// (I_O·ω + h × v_O, m·v_O − h × ω).
    #[inline]
    pub fn mul_motion(&self, motion: &Vector6<f64>) -> Vector6<f64> {
        let w = Vector3::new(motion[0], motion[1], motion[2]);
        let v = Vector3::new(motion[3], motion[4], motion[5]);
        let h = &self.first_moment;
        let angular = self.rotational_times(&w) + h.cross(&v);
        let linear = v * self.mass - h.cross(&w);
        Vector6::new(angular.x, angular.y, angular.z, linear.x, linear.y, linear.z)
    }

    /// The wrench of a uniform linear acceleration field `g` (gravity) on this body: the inertia
    /// times the motion (0, g), (h × g, m·g).
    #[inline]
    pub fn mul_linear(&self, g: &Vector3<f64>) -> Vector6<f64> {
        let n = self.first_moment.cross(g);
        Vector6::new(n.x, n.y, n.z, self.mass * g.x, self.mass * g.y, self.mass * g.z)
    }

    /// The 6×6 matrix (for the articulated inertias of ABA, which are no longer rigid).
    pub fn to_matrix(&self) -> Matrix6<f64> {
        let [xx, yy, zz, xy, xz, yz] = self.rotational;
        let hx = super::skew(&self.first_moment);
        let mut matrix = Matrix6::zeros();
        matrix.fixed_view_mut::<3, 3>(0, 0).copy_from(&Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz));
        matrix.fixed_view_mut::<3, 3>(0, 3).copy_from(&hx);
        matrix.fixed_view_mut::<3, 3>(3, 0).copy_from(&hx.transpose());
        matrix.fixed_view_mut::<3, 3>(3, 3).copy_from(&(Matrix3::identity() * self.mass));
        matrix
    }
}

impl AddAssign for SpatialInertia {
    #[inline]
    fn add_assign(&mut self, other: Self) {
        self.mass += other.mass;
        self.first_moment += other.first_moment;
        for (a, b) in self.rotational.iter_mut().zip(other.rotational) {
            *a += b;
        }
    }
}

impl Add for SpatialInertia {
    type Output = Self;
    #[inline]
    fn add(mut self, other: Self) -> Self {
        self += other;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::{rotation_from_rpy, spatial};

    fn body() -> RigidInertia {
        RigidInertia {
            mass: 1.7,
            com: Vector3::new(0.12, -0.05, 0.31),
            inertia_com: Matrix3::new(0.021, 0.002, -0.001, 0.002, 0.017, 0.003, -0.001, 0.003, 0.009),
        }
    }

    fn pose() -> Pose {
        Pose::from_xyz_rpy([0.4, -0.2, 0.7], [0.3, -1.1, 2.0])
    }

    #[test]
    fn equals_the_six_by_six_matrix_of_the_transformed_body() {
        // the same inertia two ways: the 6×6 matrix of the moved body, and the ten numbers
        let expected = body().transformed(&pose()).spatial_matrix();
        let compact = SpatialInertia::of_body(&body(), &pose());
        assert!((compact.to_matrix() - expected).abs().max() < 1e-15);
    }

    /// A central inertia on its principal axes takes the shortcut, and gives the numbers of the
    /// full product R·I_c·Rᵀ (equal as floats: at most a zero's sign differs).
    #[test]
    fn a_principal_axes_inertia_gives_the_full_products_numbers() {
        let diagonal = RigidInertia { mass: 0.4, com: Vector3::new(0.09, 0.0, 0.0), inertia_com: Matrix3::from_diagonal(&Vector3::new(1.66e-4, 1.41e-3, 1.42e-3)) };
        for (k, rpy) in [[0.3, -1.1, 2.0], [0.0, 0.0, 0.0], [0.0, std::f64::consts::FRAC_PI_2, 0.0], [-2.9, 0.4, 1.3]].iter().enumerate() {
            let pose = Pose::from_xyz_rpy([0.1 * k as f64, -0.2, 0.7], *rpy);
            let fast = SpatialInertia::of_body(&diagonal, &pose);
            // the general path, by the same formula with a full matrix product
            let r = &pose.rotation;
            let ri = r * diagonal.inertia_com;
            let entry = |a: usize, b: usize| ri[(a, 0)] * r[(b, 0)] + ri[(a, 1)] * r[(b, 1)] + ri[(a, 2)] * r[(b, 2)];
            let c = pose.transform_point(&diagonal.com);
            let h = c * diagonal.mass;
            let full = [entry(0, 0) + (h.y * c.y + h.z * c.z), entry(1, 1) + (h.x * c.x + h.z * c.z), entry(2, 2) + (h.x * c.x + h.y * c.y), entry(0, 1) - h.x * c.y, entry(0, 2) - h.x * c.z, entry(1, 2) - h.y * c.z];
            assert_eq!(fast.rotational, full, "rpy {rpy:?}");
        }
    }

    #[test]
    fn products_equal_the_matrix_products() {
        let compact = SpatialInertia::of_body(&body(), &pose());
        let matrix = compact.to_matrix();
        let motion = Vector6::new(0.3, -1.2, 0.8, 2.0, 0.1, -0.7);
        assert!((compact.mul_motion(&motion) - matrix * motion).abs().max() < 1e-15);
        let g = Vector3::new(0.0, 0.0, -9.81);
        assert!((compact.mul_linear(&g) - matrix * spatial(Vector3::zeros(), g)).abs().max() < 1e-14);
    }

    #[test]
    fn sums_are_the_sums_of_the_matrices() {
        let a = SpatialInertia::of_body(&body(), &pose());
        let b = SpatialInertia::of_body(&body(), &Pose::new(rotation_from_rpy([1.0, 0.2, -0.4]), Vector3::new(-0.3, 0.1, 0.0)));
        assert!(((a + b).to_matrix() - (a.to_matrix() + b.to_matrix())).abs().max() < 1e-15);
    }
}
