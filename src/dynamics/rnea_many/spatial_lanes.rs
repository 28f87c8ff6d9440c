//! Motions, forces and a body's inertia in lanes, in the body's own frame.

use super::lanes::{Lanes, V3, cross_add, dot, scale, v3};

/// A motion or force vector: angular part, linear part (in a body's frame, about its origin).
#[derive(Clone, Copy, Default)]
pub(super) struct Spatial<const N: usize> {
    pub(super) angular: V3<N>,
    pub(super) linear: V3<N>,
}

impl<const N: usize> Spatial<N> {
    /// base + v ×* f (v = self, a motion; f a force).
    #[inline(always)]
    pub(super) fn cross_force_add(self, f: Self, base: Self) -> Self {
        Self { angular: cross_add(self.linear, f.linear, cross_add(self.angular, f.angular, base.angular)), linear: cross_add(self.angular, f.linear, base.linear) }
    }
}

/// A body's spatial inertia about its own frame's origin, in its frame (as
/// [`SpatialInertia`](crate::spatial::SpatialInertia)): constant, so made once with the workspace.
#[derive(Clone, Copy, Default)]
pub(super) struct Inertia<const N: usize> {
    mass: Lanes<N>,
    first_moment: V3<N>,
    /// xx, yy, zz, xy, xz, yz.
    rotational: [Lanes<N>; 6],
}

impl<const N: usize> Inertia<N> {
    /// The rigid body's inertia about its own frame's origin (SpatialInertia's numbers, in lanes).
    pub(super) fn of_body(body: &crate::spatial::RigidInertia) -> Self {
        let about_origin = crate::spatial::SpatialInertia::of_body(body, &crate::spatial::Pose::identity());
        Self { mass: Lanes::splat(about_origin.mass), first_moment: v3(&about_origin.first_moment), rotational: about_origin.rotational.map(Lanes::splat) }
    }

    #[inline(always)]
    pub(super) fn mul_motion(&self, m: Spatial<N>) -> Spatial<N> {
        let [xx, yy, zz, xy, xz, yz] = self.rotational;
        let w = m.angular;
        let rotational = [dot([xx, xy, xz], w), dot([xy, yy, yz], w), dot([xz, yz, zz], w)];
        // (I_o·ω + c × v, m·v − c × ω)
        Spatial { angular: cross_add(self.first_moment, m.linear, rotational), linear: cross_add(w, self.first_moment, scale(m.linear, self.mass)) }
    }
}
