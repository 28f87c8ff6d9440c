//! The lanes: one number of the algorithm for each of `N` states side by side, and the 3-vector
//! and 3×3 arithmetic on them, each operation written lane by lane so that it compiles to one
//! vector instruction (fused multiply-adds where a sum follows a product); the sine and cosine of
//! each lane by polynomial.

use nalgebra::{Matrix3, Vector3};
use std::ops::{Add, Mul, Neg, Sub};

/// One number of the algorithm, for each of `N` states side by side (four fill an AVX2 register,
/// eight an AVX-512 one; aligned to a cache line for both: an eight split across two lines loads
/// ~15 % slower, and four lose nothing measurable to the padding).
#[derive(Clone, Copy, Debug)]
#[repr(align(64))]
pub(super) struct Lanes<const N: usize>(pub(super) [f64; N]);

impl<const N: usize> Default for Lanes<N> {
    fn default() -> Self {
        Self([0.0; N])
    }
}

impl<const N: usize> Lanes<N> {
    #[inline(always)]
    pub(super) fn splat(x: f64) -> Self {
        Self([x; N])
    }

    /// c − self·b, rounded once (one FMA instruction on all lanes).
    #[inline(always)]
    pub(super) fn neg_mul_add(self, b: Self, c: Self) -> Self {
        let mut out = [0.0; N];
        for k in 0..N {
            out[k] = (-self.0[k]).mul_add(b.0[k], c.0[k]);
        }
        Self(out)
    }

    /// self·b + c, rounded once (one FMA instruction on all lanes).
    #[inline(always)]
    pub(super) fn mul_add(self, b: Self, c: Self) -> Self {
        let mut out = [0.0; N];
        for k in 0..N {
            out[k] = self.0[k].mul_add(b.0[k], c.0[k]);
        }
        Self(out)
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl<const N: usize> $trait for Lanes<N> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                let mut out = [0.0; N];
                for k in 0..N {
                    out[k] = self.0[k] $op other.0[k];
                }
                Self(out)
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);

impl<const N: usize> Neg for Lanes<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(self.0.map(|x| -x))
    }
}

/// A 3-vector of lanes.
pub(super) type V3<const N: usize> = [Lanes<N>; 3];
/// A 3×3 matrix of lanes, row by row.
pub(super) type M3<const N: usize> = [V3<N>; 3];

#[inline(always)]
pub(super) fn v3<const N: usize>(x: &Vector3<f64>) -> V3<N> {
    [Lanes::splat(x.x), Lanes::splat(x.y), Lanes::splat(x.z)]
}

// (written out: std::array::from_fn's closures are not always inlined, and a call that is not
// runs without AVX2)
#[inline(always)]
pub(super) fn m3<const N: usize>(m: &Matrix3<f64>) -> M3<N> {
    let row = |r: usize| [Lanes::splat(m[(r, 0)]), Lanes::splat(m[(r, 1)]), Lanes::splat(m[(r, 2)])];
    [row(0), row(1), row(2)]
}

#[inline(always)]
pub(super) fn add<const N: usize>(a: V3<N>, b: V3<N>) -> V3<N> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
pub(super) fn scale<const N: usize>(a: V3<N>, s: Lanes<N>) -> V3<N> {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
pub(super) fn cross<const N: usize>(a: V3<N>, b: V3<N>) -> V3<N> {
    [a[1].mul_add(b[2], -(a[2] * b[1])), a[2].mul_add(b[0], -(a[0] * b[2])), a[0].mul_add(b[1], -(a[1] * b[0]))]
}

/// base + a × b, each component two fused multiply-adds (the sums of this algorithm are folded
/// into its products so: fewer instructions and fewer numbers waiting in registers).
#[inline(always)]
pub(super) fn cross_add<const N: usize>(a: V3<N>, b: V3<N>, base: V3<N>) -> V3<N> {
    [a[1].mul_add(b[2], a[2].neg_mul_add(b[1], base[0])), a[2].mul_add(b[0], a[0].neg_mul_add(b[2], base[1])), a[0].mul_add(b[1], a[1].neg_mul_add(b[0], base[2]))]
}

/// base + m·v.
#[inline(always)]
pub(super) fn mat_vec_add<const N: usize>(m: &M3<N>, v: V3<N>, base: V3<N>) -> V3<N> {
    let row = |r: usize| m[r][2].mul_add(v[2], m[r][1].mul_add(v[1], m[r][0].mul_add(v[0], base[r])));
    [row(0), row(1), row(2)]
}

#[inline(always)]
pub(super) fn dot<const N: usize>(a: V3<N>, b: V3<N>) -> Lanes<N> {
    a[2].mul_add(b[2], a[1].mul_add(b[1], a[0] * b[0]))
}

#[inline(always)]
pub(super) fn mat_vec<const N: usize>(m: &M3<N>, v: V3<N>) -> V3<N> {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// Beyond this many radians a lane's sine and cosine are the library's (the reduction below keeps its
/// accuracy to about 1e8 rad; a joint is nowhere near either).
const REDUCED_UP_TO: f64 = 1e6;

/// (sin x, cos x) of each lane, to within two units in the last place of the library's: x less the
/// nearest multiple k of π/2 (π/2 in three parts, Cody and Waite's reduction, each product k·part
/// exact), the sine and cosine polynomials of the remainder on [−π/4, π/4] (Cephes' coefficients, the
/// ones of its `sin.c` and `cos.c`), their roles and signs set by k mod 4. The library's sincos is a
/// call per number and was a third of the trajectory's time.
#[inline(always)]
pub(super) fn sin_cos<const N: usize>(x: Lanes<N>) -> (Lanes<N>, Lanes<N>) {
    const HALF_PI: [f64; 3] = [1.570_796_251_296_997_070_31, 7.549_789_415_861_596_353_35e-8, 5.390_302_858_158_119_052_90e-15];
    const SINE: [f64; 6] = [1.589_623_015_765_465_680_60e-10, -2.505_074_776_285_780_728_66e-8, 2.755_731_362_138_572_452_13e-6, -1.984_126_982_958_953_859_96e-4, 8.333_333_333_322_118_588_78e-3, -1.666_666_666_666_663_072_95e-1];
    const COSINE: [f64; 6] = [-1.135_853_652_138_768_173_00e-11, 2.087_570_084_197_473_167_78e-9, -2.755_731_417_929_673_881_12e-7, 2.480_158_728_885_170_453_48e-5, -1.388_888_888_887_305_641_16e-3, 4.166_666_666_666_659_292_18e-2];
    if x.0.iter().any(|v| !(v.abs() <= REDUCED_UP_TO)) {
        let mut sin = Lanes::<N>::default();
        let mut cos = Lanes::<N>::default();
        for k in 0..N {
            (sin.0[k], cos.0[k]) = x.0[k].sin_cos();
        }
        return (sin, cos);
    }
    // written so that every line is one instruction on all lanes (a rounding, a comparison, a
    // blend): no lane is taken out of its register
    let mut k = Lanes::<N>::default();
    for lane in 0..N {
        k.0[lane] = (x.0[lane] * std::f64::consts::FRAC_2_PI).round_ties_even();
    }
    let r = x - k * Lanes::splat(HALF_PI[0]) - k * Lanes::splat(HALF_PI[1]) - k * Lanes::splat(HALF_PI[2]);
    let z = r * r;
    let horner = |c: &[f64; 6]| c[1..].iter().fold(Lanes::splat(c[0]), |p, &ci| p.mul_add(z, Lanes::splat(ci)));
    let sine = (r * z).mul_add(horner(&SINE), r);
    let cosine = (z * z).mul_add(horner(&COSINE), Lanes::splat(-0.5).mul_add(z, Lanes::splat(1.0)));
    // the quadrant k mod 4, exactly, as a float
    let mut quadrant = Lanes::<N>::default();
    for lane in 0..N {
        quadrant.0[lane] = k.0[lane] - 4.0 * (k.0[lane] * 0.25).floor();
    }
    let mut sin = Lanes::<N>::default();
    let mut cos = Lanes::<N>::default();
    for lane in 0..N {
        let (s, c, q) = (sine.0[lane], cosine.0[lane], quadrant.0[lane]);
        let odd = q == 1.0 || q == 3.0;
        let (a, b) = if odd { (c, s) } else { (s, c) };
        sin.0[lane] = if q >= 2.0 { -a } else { a };
        cos.0[lane] = if q == 1.0 || q == 2.0 { -b } else { b };
    }
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lanes' sine and cosine are the library's within two units in the last place (4.5e-16 of
    /// a value at most 1), from −1000 to 1000 rad and at the reduction's edges (multiples of π/4).
    #[test]
    fn lanes_sine_and_cosine_are_the_librarys() {
        let mut worst: f64 = 0.0;
        let mut check = |values: [f64; 4]| {
            let (sin, cos) = sin_cos(Lanes(values));
            for k in 0..4 {
                let (s, c) = values[k].sin_cos();
                worst = worst.max((sin.0[k] - s).abs()).max((cos.0[k] - c).abs());
            }
        };
        for i in -250_000..250_000 {
            let x = i as f64 * 0.004_000_37;
            check([x, x + 1e-3, -x * 0.5, x * 1e-3]);
        }
        for i in -40..40 {
            let x = i as f64 * std::f64::consts::FRAC_PI_4;
            check([x, f64::from_bits(x.to_bits() + 1), f64::from_bits(x.to_bits().saturating_sub(1)), -x]);
        }
        check([1e7, -3e9, f64::MAX, 0.0]);
        assert!(worst <= 4.5e-16, "largest difference from the library's: {worst:e}");
    }
}
