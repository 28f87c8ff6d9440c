//! Inverse dynamics over many states at once (a trajectory's torques): the recursions of
//! [`rnea`](super::rnea) — out from the root for the bodies' motion and the forces it needs, back in
//! for the joints' torques — written in each body's own frame, where its inertia is constant (the
//! scalar algorithm's world frame rotates every inertia at every state), and run on
//! [`LANES`] states side by side, each number a short array of one value per state. A trajectory's
//! states do not depend on each other, so each operation becomes one 256-bit instruction for four
//! states. The lanes' arithmetic is written lane
//! by lane with fused multiply-adds and compiled for AVX2 and FMA, chosen when called (an x86-64
//! without them takes the scalar algorithm; elsewhere the lanes are the target's own vectors); the
//! joints' sines and cosines are computed here, by polynomial in the lanes, instead of by the
//! library one number at a time.

use super::{Data, rnea};
use crate::model::Model;
use nalgebra::{Matrix3, Vector3};
use std::ops::{Add, Mul, Neg, Sub};

/// States computed side by side: four f64 fill one AVX2 register.
const LANES: usize = 4;

/// One number of the algorithm, for each of the [`LANES`] states.
#[derive(Clone, Copy, Debug, Default)]
#[repr(align(32))]
struct Lanes([f64; LANES]);

impl Lanes {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self([x; LANES])
    }

    /// self·b + c, rounded once (one FMA instruction on all lanes).
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        let mut out = [0.0; LANES];
        for k in 0..LANES {
            out[k] = self.0[k].mul_add(b.0[k], c.0[k]);
        }
        Self(out)
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Lanes {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                let mut out = [0.0; LANES];
                for k in 0..LANES {
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

impl Neg for Lanes {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(self.0.map(|x| -x))
    }
}

/// A 3-vector of lanes.
type V3 = [Lanes; 3];
/// A 3×3 matrix of lanes, row by row.
type M3 = [V3; 3];

#[inline(always)]
fn v3(x: &Vector3<f64>) -> V3 {
    [Lanes::splat(x.x), Lanes::splat(x.y), Lanes::splat(x.z)]
}

// (written out: std::array::from_fn's closures are not always inlined, and a call that is not
// runs without AVX2)
#[inline(always)]
fn m3(m: &Matrix3<f64>) -> M3 {
    let row = |r: usize| [Lanes::splat(m[(r, 0)]), Lanes::splat(m[(r, 1)]), Lanes::splat(m[(r, 2)])];
    [row(0), row(1), row(2)]
}

#[inline(always)]
fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn scale(a: V3, s: Lanes) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
fn cross(a: V3, b: V3) -> V3 {
    [a[1].mul_add(b[2], -(a[2] * b[1])), a[2].mul_add(b[0], -(a[0] * b[2])), a[0].mul_add(b[1], -(a[1] * b[0]))]
}

#[inline(always)]
fn dot(a: V3, b: V3) -> Lanes {
    a[2].mul_add(b[2], a[1].mul_add(b[1], a[0] * b[0]))
}

#[inline(always)]
fn mat_vec(m: &M3, v: V3) -> V3 {
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
fn sin_cos(x: Lanes) -> (Lanes, Lanes) {
    const HALF_PI: [f64; 3] = [1.570_796_251_296_997_070_31, 7.549_789_415_861_596_353_35e-8, 5.390_302_858_158_119_052_90e-15];
    const SINE: [f64; 6] = [1.589_623_015_765_465_680_60e-10, -2.505_074_776_285_780_728_66e-8, 2.755_731_362_138_572_452_13e-6, -1.984_126_982_958_953_859_96e-4, 8.333_333_333_322_118_588_78e-3, -1.666_666_666_666_663_072_95e-1];
    const COSINE: [f64; 6] = [-1.135_853_652_138_768_173_00e-11, 2.087_570_084_197_473_167_78e-9, -2.755_731_417_929_673_881_12e-7, 2.480_158_728_885_170_453_48e-5, -1.388_888_888_887_305_641_16e-3, 4.166_666_666_666_659_292_18e-2];
    if x.0.iter().any(|v| !(v.abs() <= REDUCED_UP_TO)) {
        let mut sin = Lanes::default();
        let mut cos = Lanes::default();
        for k in 0..LANES {
            (sin.0[k], cos.0[k]) = x.0[k].sin_cos();
        }
        return (sin, cos);
    }
    // written so that every line is one instruction on all lanes (a rounding, a comparison, a
    // blend): no lane is taken out of its register
    let mut k = Lanes::default();
    for lane in 0..LANES {
        k.0[lane] = (x.0[lane] * std::f64::consts::FRAC_2_PI).round_ties_even();
    }
    let r = x - k * Lanes::splat(HALF_PI[0]) - k * Lanes::splat(HALF_PI[1]) - k * Lanes::splat(HALF_PI[2]);
    let z = r * r;
    let horner = |c: &[f64; 6]| c[1..].iter().fold(Lanes::splat(c[0]), |p, &ci| p.mul_add(z, Lanes::splat(ci)));
    let sine = (r * z).mul_add(horner(&SINE), r);
    let cosine = (z * z).mul_add(horner(&COSINE), Lanes::splat(-0.5).mul_add(z, Lanes::splat(1.0)));
    // the quadrant k mod 4, exactly, as a float
    let mut quadrant = Lanes::default();
    for lane in 0..LANES {
        quadrant.0[lane] = k.0[lane] - 4.0 * (k.0[lane] * 0.25).floor();
    }
    let mut sin = Lanes::default();
    let mut cos = Lanes::default();
    for lane in 0..LANES {
        let (s, c, q) = (sine.0[lane], cosine.0[lane], quadrant.0[lane]);
        let odd = q == 1.0 || q == 3.0;
        let (a, b) = if odd { (c, s) } else { (s, c) };
        sin.0[lane] = if q >= 2.0 { -a } else { a };
        cos.0[lane] = if q == 1.0 || q == 2.0 { -b } else { b };
    }
    (sin, cos)
}

/// A motion or force vector: angular part, linear part (in a body's frame, about its origin).
#[derive(Clone, Copy, Default)]
struct Spatial {
    angular: V3,
    linear: V3,
}

impl Spatial {
    #[inline(always)]
    fn plus(self, other: Self) -> Self {
        Self { angular: add(self.angular, other.angular), linear: add(self.linear, other.linear) }
    }

    /// v ×* f.
    #[inline(always)]
    fn cross_force(self, f: Self) -> Self {
        Self { angular: add(cross(self.angular, f.angular), cross(self.linear, f.linear)), linear: cross(self.angular, f.linear) }
    }
}

/// A body's spatial inertia about its own frame's origin, in its frame (as
/// [`SpatialInertia`](crate::spatial::SpatialInertia)): constant, so made once with the workspace.
#[derive(Clone, Copy, Default)]
struct Inertia {
    mass: Lanes,
    first_moment: V3,
    /// xx, yy, zz, xy, xz, yz.
    rotational: [Lanes; 6],
}

impl Inertia {
    /// The rigid body's inertia about its own frame's origin (SpatialInertia's numbers, in lanes).
    fn of_body(body: &crate::spatial::RigidInertia) -> Self {
        let about_origin = crate::spatial::SpatialInertia::of_body(body, &crate::spatial::Pose::identity());
        Self { mass: Lanes::splat(about_origin.mass), first_moment: v3(&about_origin.first_moment), rotational: about_origin.rotational.map(Lanes::splat) }
    }

    #[inline(always)]
    fn mul_motion(&self, m: Spatial) -> Spatial {
        let [xx, yy, zz, xy, xz, yz] = self.rotational;
        let w = m.angular;
        let rotational = [dot([xx, xy, xz], w), dot([xy, yy, yz], w), dot([xz, yz, zz], w)];
        Spatial { angular: add(rotational, cross(self.first_moment, m.linear)), linear: sub(scale(m.linear, self.mass), cross(self.first_moment, w)) }
    }
}

/// The workspace of [`rnea_many`]: per body, its lanes' pose in its parent's frame and its
/// velocity, acceleration and force in its own frame; the bodies' inertias. Sized once for a model.
#[derive(Clone)]
pub struct RneaManyData {
    /// The body frame's axes in its parent's frame (columns), E.
    rotation: Vec<M3>,
    /// The body frame's origin in its parent's frame, r.
    translation: Vec<V3>,
    inertia: Vec<Inertia>,
    /// The joint's axis in the body's frame (the same as in the joint's: the joint moves along
    /// it), times its coupling's multiplier.
    axis: Vec<Vector3<f64>>,
    /// The states' positions, velocities and accelerations, a coordinate at a time.
    inputs: [Vec<Lanes>; 3],
    velocity: Vec<Spatial>,
    acceleration: Vec<Spatial>,
    force: Vec<Spatial>,
    tau: Vec<Lanes>,
    /// The states left over when the count is not a multiple of [`LANES`], one at a time.
    scalar: Data,
}

impl RneaManyData {
    pub fn new(model: &Model) -> Self {
        let bodies = model.bodies.len();
        Self {
            rotation: vec![M3::default(); bodies],
            translation: vec![V3::default(); bodies],
            inertia: model.bodies.iter().map(|body| Inertia::of_body(&body.inertia)).collect(),
            axis: model.bodies.iter().zip(&model.couplings).map(|(body, coupling)| body.axis * coupling.multiplier).collect(),
            inputs: std::array::from_fn(|_| vec![Lanes::default(); model.dof()]),
            velocity: vec![Spatial::default(); bodies],
            acceleration: vec![Spatial::default(); bodies],
            force: vec![Spatial::default(); bodies],
            tau: vec![Lanes::default(); model.dof()],
            scalar: Data::new(model),
        }
    }
}

/// Inverse dynamics of every state of a trajectory: row k of `q`, `v`, `a` (each states × dof,
/// row-major) gives row k of `tau`, τ = M(q)·q̈ + C(q, q̇)·q̇ − τ_g(q) as [`rnea`] gives it, within a
/// few roundings (it works in each body's frame where [`rnea`] works in the world's, and fused
/// multiply-adds round once where the scalar algorithm rounds twice).
pub fn rnea_many(model: &Model, data: &mut RneaManyData, q: &[f64], v: &[f64], a: &[f64], tau: &mut [f64]) {
    let n = model.dof();
    assert!(q.len() == tau.len() && v.len() == tau.len() && a.len() == tau.len() && (n == 0 || tau.len() % n == 0), "rnea_many: rows of {n} values each");
    assert!(data.inertia.len() == model.bodies.len(), "rnea_many: a workspace made for another model");
    if n == 0 {
        return;
    }
    let states = tau.len() / n;
    let whole = states / LANES * LANES;
    // an x86-64 without AVX2 and FMA (none made since 2015) takes the scalar algorithm: FMA is a
    // library call there
    #[cfg(target_arch = "x86_64")]
    let whole = if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the processor has AVX2 and FMA (checked just above)
        unsafe { lanes_avx2(model, data, q, v, a, tau, whole) };
        whole
    } else {
        0
    };
    #[cfg(not(target_arch = "x86_64"))]
    lanes_portable(model, data, q, v, a, tau, whole);
    for k in whole..states {
        let row = k * n..(k + 1) * n;
        tau[row.clone()].copy_from_slice(rnea(model, &mut data.scalar, &q[row.clone()], &v[row.clone()], &a[row]));
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn lanes_avx2(model: &Model, data: &mut RneaManyData, q: &[f64], v: &[f64], a: &[f64], tau: &mut [f64], whole: usize) {
    lanes_portable(model, data, q, v, a, tau, whole);
}

/// The first `whole` states (a multiple of [`LANES`]), [`LANES`] at a time.
#[inline(always)]
fn lanes_portable(model: &Model, data: &mut RneaManyData, q: &[f64], v: &[f64], a: &[f64], tau: &mut [f64], whole: usize) {
    let n = model.dof();
    let group = LANES * n;
    for (first, out) in (0..whole).step_by(LANES).zip(tau[..whole * n].chunks_exact_mut(group)) {
        let rows = first * n..first * n + group;
        for (lanes, x) in data.inputs.iter_mut().zip([&q[rows.clone()], &v[rows.clone()], &a[rows]]) {
            for (k, row) in x.chunks_exact(n).enumerate() {
                for (coordinate, value) in lanes.iter_mut().zip(row) {
                    coordinate.0[k] = *value;
                }
            }
        }
        forward_pass(model, data);
        backward_pass(model, data);
        for (k, row) in out.chunks_exact_mut(n).enumerate() {
            for (value, coordinate) in row.iter_mut().zip(&data.tau) {
                *value = coordinate.0[k];
            }
        }
    }
}

/// Eᵀ·x: a vector of the parent's frame in the body's.
#[inline(always)]
fn to_body(e: &M3, x: V3) -> V3 {
    let column = |c: usize| e[2][c].mul_add(x[2], e[1][c].mul_add(x[1], e[0][c] * x[0]));
    [column(0), column(1), column(2)]
}

/// A motion of the parent's frame (about its origin) in the body's frame (about the body's origin
/// r): ω' = Eᵀ·ω, v' = Eᵀ·(v + ω × r).
#[inline(always)]
fn motion_to_body(e: &M3, r: V3, m: Spatial) -> Spatial {
    Spatial { angular: to_body(e, m.angular), linear: to_body(e, add(m.linear, cross(m.angular, r))) }
}

/// A force of the body's frame in its parent's: F = E·f, N = E·n + r × F.
#[inline(always)]
fn force_to_parent(e: &M3, r: V3, f: Spatial) -> Spatial {
    let linear = mat_vec(e, f.linear);
    Spatial { angular: add(mat_vec(e, f.angular), cross(r, linear)), linear }
}

/// The recursion from the root out: each body's pose in its parent, and its velocity,
/// acceleration (gravity as the world's upward acceleration) and the force its motion needs, all
/// in its own frame.
#[inline(always)]
fn forward_pass(model: &Model, data: &mut RneaManyData) {
    let [q, v, a] = &data.inputs;
    let gravity = Spatial { angular: V3::default(), linear: v3(&-model.gravity) };
    for i in 0..model.bodies.len() {
        let (joint, coupling, motion) = (&model.bodies[i], &model.couplings[i], &model.motions[i]);
        let position = Lanes::splat(coupling.multiplier).mul_add(q[coupling.coordinate], Lanes::splat(coupling.offset));
        let (rotation, translation) = if motion.prismatic {
            (m3(&motion.fixed), add(v3(&motion.origin), scale(v3(&motion.axis), position)))
        } else {
            let (sin, cos) = sin_cos(position);
            let (fixed, cosine, sine) = (m3(&motion.fixed), m3(&motion.cosine), m3(&motion.sine));
            let entry = |r: usize, c: usize| sine[r][c].mul_add(sin, cosine[r][c].mul_add(cos, fixed[r][c]));
            ([[entry(0, 0), entry(0, 1), entry(0, 2)], [entry(1, 0), entry(1, 1), entry(1, 2)], [entry(2, 0), entry(2, 1), entry(2, 2)]], v3(&motion.origin))
        };
        let (v_parent, a_parent) = match joint.parent {
            Some(p) => (motion_to_body(&rotation, translation, data.velocity[p]), motion_to_body(&rotation, translation, data.acceleration[p])),
            None => (Spatial::default(), motion_to_body(&rotation, translation, gravity)),
        };
        let axis = v3(&data.axis[i]);
        let (vc, ac) = (v[coupling.coordinate], a[coupling.coordinate]);
        let joint_velocity = scale(axis, vc);
        let (velocity, acceleration) = if motion.prismatic {
            let velocity = Spatial { angular: v_parent.angular, linear: add(v_parent.linear, joint_velocity) };
            // v ×ₘ (0, s·q̇) = (0, ω × s·q̇)
            let linear = add(add(a_parent.linear, scale(axis, ac)), cross(velocity.angular, joint_velocity));
            (velocity, Spatial { angular: a_parent.angular, linear })
        } else {
            let velocity = Spatial { angular: add(v_parent.angular, joint_velocity), linear: v_parent.linear };
            // v ×ₘ (s·q̇, 0) = (ω × s·q̇, v × s·q̇)
            let angular = add(add(a_parent.angular, scale(axis, ac)), cross(velocity.angular, joint_velocity));
            let linear = add(a_parent.linear, cross(velocity.linear, joint_velocity));
            (velocity, Spatial { angular, linear })
        };
        let inertia = &data.inertia[i];
        data.force[i] = inertia.mul_motion(acceleration).plus(velocity.cross_force(inertia.mul_motion(velocity)));
        data.velocity[i] = velocity;
        data.acceleration[i] = acceleration;
        data.rotation[i] = rotation;
        data.translation[i] = translation;
    }
}

/// The recursion from the leaves in: each joint's torque, the body's force carried to its parent;
/// then the motors' rotors (J_r·N²·q̈), into `data.tau`.
#[inline(always)]
fn backward_pass(model: &Model, data: &mut RneaManyData) {
    data.tau.fill(Lanes::default());
    for i in (0..model.bodies.len()).rev() {
        let (joint, coupling, motion) = (&model.bodies[i], &model.couplings[i], &model.motions[i]);
        let c = coupling.coordinate;
        let axis = v3(&data.axis[i]);
        let force = data.force[i];
        let along = if motion.prismatic { force.linear } else { force.angular };
        data.tau[c] = data.tau[c] + dot(axis, along);
        if let Some(p) = joint.parent {
            data.force[p] = data.force[p].plus(force_to_parent(&data.rotation[i], data.translation[i], force));
        }
    }
    for (c, armature) in model.armature.iter().enumerate() {
        data.tau[c] = data.tau[c] + Lanes::splat(*armature) * data.inputs[2][c];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot(name: &str) -> Model {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/robots").join(name);
        crate::model::load_urdf(&path).expect("the fixture loads")
    }

    /// The lanes' sine and cosine are the library's within two units in the last place (4.5e-16 of
    /// a value at most 1), from −1000 to 1000 rad and at the reduction's edges (multiples of π/4).
    #[test]
    fn lanes_sine_and_cosine_are_the_librarys() {
        let mut worst: f64 = 0.0;
        let mut check = |values: [f64; LANES]| {
            let (sin, cos) = sin_cos(Lanes(values));
            for k in 0..LANES {
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

    /// Every state's torques are the scalar RNEA's: the same dynamics in the bodies' frames instead
    /// of the world's, so within a few roundings (1e-12 of the largest torque), on a 6-joint chain, a branched tree
    /// with prismatic joints (Tiago) and one with mimic joints (Baxter), over a count of states that
    /// leaves a remainder for the scalar path.
    #[test]
    fn many_states_give_the_scalar_rneas_torques() {
        for name in ["so101.urdf", "tiago.urdf", "baxter.urdf"] {
            let model = robot(name);
            let n = model.dof();
            let states = 4 * LANES + 3;
            let wave = |k: usize, c: usize, f: f64| ((k * n + c) as f64 * f).sin();
            let q: Vec<f64> = (0..states * n).map(|i| wave(i / n, i % n, 0.37)).collect();
            let v: Vec<f64> = (0..states * n).map(|i| 2.0 * wave(i / n, i % n, 0.71)).collect();
            let a: Vec<f64> = (0..states * n).map(|i| 5.0 * wave(i / n, i % n, 1.13)).collect();
            let mut tau = vec![f64::NAN; states * n];
            rnea_many(&model, &mut RneaManyData::new(&model), &q, &v, &a, &mut tau);
            let mut data = Data::new(&model);
            for k in 0..states {
                let row = k * n..(k + 1) * n;
                let expected = rnea(&model, &mut data, &q[row.clone()], &v[row.clone()], &a[row.clone()]).to_vec();
                let scale = expected.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                for (c, (got, want)) in tau[row].iter().zip(&expected).enumerate() {
                    assert!((got - want).abs() <= 1e-12 * scale, "{name}: state {k}, coordinate {c}: {got} against rnea's {want}");
                }
            }
        }
    }
}
