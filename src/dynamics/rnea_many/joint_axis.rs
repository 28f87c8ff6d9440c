//! How a joint's axis enters the recursions: most URDFs' joints turn about an axis of their own
//! frame, whose products with the axis are one lane each; the rest take the general form.

use super::lanes::{Lanes, M3, V3, add, cross, m3, scale};
use crate::model::JointMotion;
use nalgebra::Vector3;

/// How a joint's axis enters the recursions, chosen per body when the workspace is made: most
/// URDFs' joints turn about an axis of their own frame (x, y or z, either sign), whose products
/// with the axis are a single lane each and whose pose keeps one column fixed; the rest take the
/// general form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum JointAxisKind {
    /// A revolute joint about its frame's axis `index` (the body's `axis` is zero off it).
    Coordinate { index: usize },
    /// A revolute joint about any other axis.
    General,
    Prismatic,
}

impl JointAxisKind {
    /// The kind of the joint moving along `axis` (in its body's frame, times its coupling's
    /// multiplier) as `motion`: a coordinate axis only where the numbers say so exactly (the
    /// axis's other components zero, the pose's fixed part zero off that column and its cosine and
    /// sine parts zero on it), so that the shortened products are the general ones.
    pub(super) fn of(axis: &Vector3<f64>, motion: &JointMotion) -> Self {
        if motion.prismatic {
            return Self::Prismatic;
        }
        let along = |k: usize| {
            (0..3).all(|j| j == k || axis[j] == 0.0)
                && axis[k] != 0.0
                && (0..3).all(|r| motion.cosine[(r, k)] == 0.0 && motion.sine[(r, k)] == 0.0 && (0..3).all(|c| c == k || motion.fixed[(r, c)] == 0.0))
        };
        match (0..3).find(|&k| along(k)) {
            Some(index) => Self::Coordinate { index },
            None => Self::General,
        }
    }
}

/// A joint's pose in its parent's frame as its angle turns it: the body frame's axes there are
/// E = fixed + cos·C + sin·S (a prismatic joint's: fixed), Rodrigues' formula premultiplied by the
/// joint frame's rotation (see [`JointMotion`]).
#[derive(Clone, Copy)]
pub(super) struct JointPose<const N: usize> {
    pub(super) fixed: M3<N>,
    pub(super) cosine: M3<N>,
    pub(super) sine: M3<N>,
}

impl<const N: usize> JointPose<N> {
    pub(super) fn of(motion: &JointMotion) -> Self {
        Self { fixed: m3(&motion.fixed), cosine: m3(&motion.cosine), sine: m3(&motion.sine) }
    }
}

/// A revolute joint's axis in the lanes' arithmetic: its products with a joint rate, and the
/// part of the joint's pose its angle turns.
pub(super) trait JointAxis<const N: usize>: Copy {
    /// The axis times a joint rate, in the form the products below take.
    type Along: Copy;
    fn along(self, rate: Lanes<N>) -> Self::Along;
    /// base + along.
    fn plus(self, base: V3<N>, along: Self::Along) -> V3<N>;
    /// base + w × along.
    fn plus_cross(self, base: V3<N>, w: V3<N>, along: Self::Along) -> V3<N>;
    /// The entries of E = fixed + cos·C + sin·S that the angle changes (the others were set
    /// with the workspace).
    fn turn(pose: &JointPose<N>, sin: Lanes<N>, cos: Lanes<N>, rotation: &mut M3<N>);
}

/// A revolute joint about its frame's axis `K` (0, 1, 2: x, y, z), times `scale`.
#[derive(Clone, Copy)]
pub(super) struct CoordinateAxis<const K: usize, const N: usize> {
    pub(super) scale: Lanes<N>,
}

impl<const K: usize, const N: usize> JointAxis<N> for CoordinateAxis<K, N> {
    type Along = Lanes<N>;

    #[inline(always)]
    fn along(self, rate: Lanes<N>) -> Lanes<N> {
        self.scale * rate
    }

    #[inline(always)]
    fn plus(self, mut base: V3<N>, along: Lanes<N>) -> V3<N> {
        base[K] = base[K] + along;
        base
    }

    /// w × e_K·x = (w_j·x, −w_i·x) on the other two axes (i, j, K in cyclic order), 0 on K.
    #[inline(always)]
    fn plus_cross(self, mut base: V3<N>, w: V3<N>, along: Lanes<N>) -> V3<N> {
        let (i, j) = ((K + 1) % 3, (K + 2) % 3);
        base[i] = w[j].mul_add(along, base[i]);
        base[j] = w[i].neg_mul_add(along, base[j]);
        base
    }

    /// All but column K (the fixed part's alone: see [`JointAxisKind::of`]).
    #[inline(always)]
    fn turn(pose: &JointPose<N>, sin: Lanes<N>, cos: Lanes<N>, rotation: &mut M3<N>) {
        for r in 0..3 {
            for c in [(K + 1) % 3, (K + 2) % 3] {
                rotation[r][c] = pose.sine[r][c].mul_add(sin, pose.cosine[r][c] * cos);
            }
        }
    }
}

/// A revolute joint about any axis (in its body's frame, times its coupling's multiplier).
#[derive(Clone, Copy)]
pub(super) struct GeneralAxis<const N: usize>(pub(super) V3<N>);

impl<const N: usize> JointAxis<N> for GeneralAxis<N> {
    type Along = V3<N>;

    #[inline(always)]
    fn along(self, rate: Lanes<N>) -> V3<N> {
        scale(self.0, rate)
    }

    #[inline(always)]
    fn plus(self, base: V3<N>, along: V3<N>) -> V3<N> {
        add(base, along)
    }

    #[inline(always)]
    fn plus_cross(self, base: V3<N>, w: V3<N>, along: V3<N>) -> V3<N> {
        add(base, cross(w, along))
    }

    #[inline(always)]
    fn turn(pose: &JointPose<N>, sin: Lanes<N>, cos: Lanes<N>, rotation: &mut M3<N>) {
        for r in 0..3 {
            for c in 0..3 {
                rotation[r][c] = pose.sine[r][c].mul_add(sin, pose.cosine[r][c].mul_add(cos, pose.fixed[r][c]));
            }
        }
    }
}
