//! Inverse dynamics over many states at once (a trajectory's torques): the recursions of
//! [`rnea`](super::rnea) — out from the root for the bodies' motion and the forces it needs, back in
//! for the joints' torques — written in each body's own frame, where its inertia is constant (the
//! scalar algorithm's world frame rotates every inertia at every state), and run on several states
//! side by side, each number a short array of one value per state ("lanes"). A trajectory's states
//! do not depend on each other, so each operation becomes one instruction for all of them: eight
//! states in an AVX-512 register where the processor has it, else four in an AVX2 one. The lanes'
//! arithmetic is written lane by lane with fused multiply-adds and compiled for those instruction
//! sets, chosen when the workspace is made and checked when called (an x86-64 without AVX2 and FMA
//! takes the scalar algorithm; elsewhere four lanes are the target's own vectors); the joints' sines
//! and cosines by polynomial in the lanes, instead of by the library one number at a time.
//!
//! `lanes` holds the numbers and their arithmetic, `spatial_lanes` motions, forces and inertias in
//! lanes, `joint_axis` how a joint's axis enters the recursions; this file the workspace and the
//! recursions.

mod joint_axis;
mod lanes;
mod spatial_lanes;

use super::{Data, rnea};
use crate::model::Model;
use joint_axis::{CoordinateAxis, GeneralAxis, JointAxis, JointAxisKind, JointPose};
use lanes::{Lanes, M3, V3, add, cross, cross_add, dot, mat_vec, mat_vec_add, scale, sin_cos, v3};
use spatial_lanes::{Inertia, Spatial};
use std::sync::Arc;

/// One body's constants, each number as lanes (so the arithmetic reads them straight from
/// memory), made once with the workspace.
#[derive(Clone, Copy)]
struct BodyLanes<const N: usize> {
    parent: Option<usize>,
    /// The coordinate moving the joint: its position is multiplier·q + offset.
    coordinate: usize,
    multiplier: Lanes<N>,
    offset: Lanes<N>,
    kind: JointAxisKind,
    /// The joint's axis in the body's frame (the same as in the joint's: the joint moves along
    /// it), times its coupling's multiplier.
    axis: V3<N>,
    pose: JointPose<N>,
    /// The joint frame's origin in the parent's frame, and a prismatic joint's direction there:
    /// the body frame's origin is origin + slide·position.
    origin: V3<N>,
    slide: V3<N>,
    inertia: Inertia<N>,
}

impl<const N: usize> BodyLanes<N> {
    fn new(model: &Model, i: usize) -> Self {
        let (body, coupling, motion) = (&model.bodies[i], &model.couplings[i], &model.motions[i]);
        let axis = body.axis * coupling.multiplier;
        Self {
            parent: body.parent,
            coordinate: coupling.coordinate,
            multiplier: Lanes::splat(coupling.multiplier),
            offset: Lanes::splat(coupling.offset),
            kind: JointAxisKind::of(&axis, motion),
            axis: v3(&axis),
            pose: JointPose::of(motion),
            origin: v3(&motion.origin),
            slide: v3(&motion.axis),
            inertia: Inertia::of_body(&body.inertia),
        }
    }
}

/// The model's numbers in `N` lanes, made once and shared by every workspace cloned from the one
/// that made them (a trajectory split over the cores clones one per task).
struct LanesModel<const N: usize> {
    bodies: Vec<BodyLanes<N>>,
    /// Per coordinate, its motor's rotor inertia seen at the joint, J_r·N².
    armature: Vec<Lanes<N>>,
    /// The world's acceleration upward (the negated gravity), in the world's frame.
    lift: Spatial<N>,
}

/// The lanes' part of [`RneaManyData`], for `N` states side by side: the model's numbers (shared);
/// per body, its lanes' pose in its parent's frame and its velocity, acceleration and force in its
/// own frame.
#[derive(Clone)]
struct LanesData<const N: usize> {
    model: Arc<LanesModel<N>>,
    /// The body frame's axes in its parent's frame (columns), E.
    rotation: Vec<M3<N>>,
    /// The body frame's origin in its parent's frame, r.
    translation: Vec<V3<N>>,
    /// The states' positions, velocities and accelerations, a coordinate at a time.
    inputs: [Vec<Lanes<N>>; 3],
    velocity: Vec<Spatial<N>>,
    acceleration: Vec<Spatial<N>>,
    force: Vec<Spatial<N>>,
    tau: Vec<Lanes<N>>,
}

impl<const N: usize> LanesData<N> {
    fn new(model: &Model) -> Self {
        let bodies: Vec<BodyLanes<N>> = (0..model.bodies.len()).map(|i| BodyLanes::new(model, i)).collect();
        // what the angles never change: a coordinate joint's fixed column, a prismatic joint's
        // rotation and a revolute joint's origin
        let rotation = bodies.iter().map(|body| match body.kind {
            JointAxisKind::Coordinate { index } => std::array::from_fn(|r| std::array::from_fn(|c| if c == index { body.pose.fixed[r][c] } else { Lanes::default() })),
            JointAxisKind::General => M3::default(),
            JointAxisKind::Prismatic => body.pose.fixed,
        });
        Self {
            rotation: rotation.collect(),
            translation: bodies.iter().map(|body| body.origin).collect(),
            inputs: std::array::from_fn(|_| vec![Lanes::default(); model.dof()]),
            velocity: vec![Spatial::default(); model.bodies.len()],
            acceleration: vec![Spatial::default(); model.bodies.len()],
            force: vec![Spatial::default(); model.bodies.len()],
            tau: vec![Lanes::default(); model.dof()],
            model: Arc::new(LanesModel { bodies, armature: model.armature.iter().map(|&j| Lanes::splat(j)).collect(), lift: Spatial { angular: V3::default(), linear: v3(&-model.gravity) } }),
        }
    }
}

/// How many states run side by side, chosen for the processor when the workspace is made.
#[derive(Clone)]
enum Width {
    /// Four: one AVX2 register (or the target's own vectors, off x86-64).
    Four(LanesData<4>),
    /// Eight: one AVX-512 register. With 32 registers instead of 16 the model's numbers stay in
    /// registers instead of spilling to the stack: ~1.6× the states a second of four lanes on a
    /// Xeon (Cascade Lake).
    Eight(LanesData<8>),
}

/// The workspace of [`rnea_many`], sized once for a model: the lanes' (see `LanesData`), and the
/// scalar algorithm's for the states left over when the count is not a multiple of the lanes (made
/// when first needed). A clone shares the model's numbers: cloning one made for a model is the
/// cheap way to another (3 µs for the UR5 here, where making one takes 6–12).
#[derive(Clone)]
pub struct RneaManyData {
    width: Width,
    scalar: Option<Box<Data>>,
}

impl RneaManyData {
    pub fn new(model: &Model) -> Self {
        Self::with_width(model, has_avx512())
    }

    /// Four lanes on any processor (the benchmarks compare it with the eight of AVX-512).
    pub fn with_four_lanes(model: &Model) -> Self {
        Self::with_width(model, false)
    }

    /// Eight lanes or four, as asked (the tests run both on any processor).
    fn with_width(model: &Model, eight: bool) -> Self {
        let width = if eight { Width::Eight(LanesData::new(model)) } else { Width::Four(LanesData::new(model)) };
        Self { width, scalar: None }
    }
}

/// Whether the processor runs AVX-512 (with its FMA and the 256-bit forms the compiler mixes in).
fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("avx512vl") && std::arch::is_x86_feature_detected!("avx512dq") && std::arch::is_x86_feature_detected!("fma");
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// Inverse dynamics of every state of a trajectory: row k of `q`, `v`, `a` (each states × dof,
/// row-major) gives row k of `tau`, τ = M(q)·q̈ + C(q, q̇)·q̇ − τ_g(q) as [`rnea`] gives it, within a
/// few roundings (it works in each body's frame where [`rnea`] works in the world's, and fused
/// multiply-adds round once where the scalar algorithm rounds twice).
pub fn rnea_many(model: &Model, data: &mut RneaManyData, q: &[f64], v: &[f64], a: &[f64], tau: &mut [f64]) {
    let n = model.dof();
    assert!(q.len() == tau.len() && v.len() == tau.len() && a.len() == tau.len() && (n == 0 || tau.len() % n == 0), "rnea_many: rows of {n} values each");
    let (bodies, dof) = match &data.width {
        Width::Four(lanes) => (lanes.model.bodies.len(), lanes.tau.len()),
        Width::Eight(lanes) => (lanes.model.bodies.len(), lanes.tau.len()),
    };
    assert!(bodies == model.bodies.len() && dof == n, "rnea_many: a workspace made for another model");
    if n == 0 {
        return;
    }
    let states = tau.len() / n;
    let whole = match &mut data.width {
        Width::Eight(lanes) => {
            let whole = states / 8 * 8;
            #[cfg(target_arch = "x86_64")]
            if has_avx512() {
                // SAFETY: the processor has AVX-512 F, VL, DQ and FMA (checked just above)
                unsafe { lanes_avx512(lanes, q, v, a, tau, whole) };
            } else {
                lanes_portable(lanes, q, v, a, tau, whole);
            }
            #[cfg(not(target_arch = "x86_64"))]
            lanes_portable(lanes, q, v, a, tau, whole);
            whole
        }
        Width::Four(lanes) => {
            let whole = states / 4 * 4;
            // an x86-64 without AVX2 and FMA (none made since 2015) takes the scalar algorithm:
            // FMA is a library call there
            #[cfg(target_arch = "x86_64")]
            let whole = if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
                // SAFETY: the processor has AVX2 and FMA (checked just above)
                unsafe { lanes_avx2(lanes, q, v, a, tau, whole) };
                whole
            } else {
                0
            };
            #[cfg(not(target_arch = "x86_64"))]
            lanes_portable(lanes, q, v, a, tau, whole);
            whole
        }
    };
    if whole < states {
        let scalar = data.scalar.get_or_insert_with(|| Box::new(Data::new(model)));
        for k in whole..states {
            let row = k * n..(k + 1) * n;
            tau[row.clone()].copy_from_slice(rnea(model, scalar, &q[row.clone()], &v[row.clone()], &a[row]));
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn lanes_avx2(data: &mut LanesData<4>, q: &[f64], v: &[f64], a: &[f64], tau: &mut [f64], whole: usize) {
    lanes_portable(data, q, v, a, tau, whole);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
fn lanes_avx512(data: &mut LanesData<8>, q: &[f64], v: &[f64], a: &[f64], tau: &mut [f64], whole: usize) {
    lanes_portable(data, q, v, a, tau, whole);
}

/// The first `whole` states (a multiple of `N`), `N` at a time: the bodies' poses in a loop of
/// their own (independent of each other, and fewer numbers in the registers than one loop doing
/// all), then their motion out from the root with the forces it needs, and the torques back in.
#[inline(always)]
fn lanes_portable<const N: usize>(data: &mut LanesData<N>, q: &[f64], v: &[f64], a: &[f64], tau: &mut [f64], whole: usize) {
    let LanesData { model, rotation, translation, inputs, velocity, acceleration, force, tau: torque } = data;
    let LanesModel { bodies, armature, lift } = &**model;
    let n = torque.len();
    let group = N * n;
    for (first, out) in (0..whole).step_by(N).zip(tau[..whole * n].chunks_exact_mut(group)) {
        let rows = first * n..first * n + group;
        // the group's rows into lanes, a coordinate at a time: one register from its N rows
        for (lanes, x) in inputs.iter_mut().zip([&q[rows.clone()], &v[rows.clone()], &a[rows]]) {
            for (c, coordinate) in lanes.iter_mut().enumerate() {
                *coordinate = Lanes(std::array::from_fn(|k| x[k * n + c]));
            }
        }
        let [positions, rates, accelerations] = &*inputs;
        poses(bodies, positions, rotation, translation);
        motions(bodies, rates, accelerations, rotation, translation, lift, velocity, acceleration, force);
        torques(bodies, rotation, translation, accelerations, armature, force, torque);
        for (c, coordinate) in torque.iter().enumerate() {
            for (k, value) in coordinate.0.iter().enumerate() {
                out[k * n + c] = *value;
            }
        }
    }
}

/// Eᵀ·x: a vector of the parent's frame in the body's.
#[inline(always)]
fn to_body<const N: usize>(e: &M3<N>, x: V3<N>) -> V3<N> {
    let column = |c: usize| e[2][c].mul_add(x[2], e[1][c].mul_add(x[1], e[0][c] * x[0]));
    [column(0), column(1), column(2)]
}

/// A motion of the parent's frame (about its origin) in the body's frame (about the body's origin
/// r): ω' = Eᵀ·ω, v' = Eᵀ·(v + ω × r).
#[inline(always)]
fn motion_to_body<const N: usize>(e: &M3<N>, r: V3<N>, m: Spatial<N>) -> Spatial<N> {
    Spatial { angular: to_body(e, m.angular), linear: to_body(e, cross_add(m.angular, r, m.linear)) }
}

/// A force of the body's frame added to one of its parent's: F = E·f, N = E·n + r × F.
#[inline(always)]
fn add_force_to_parent<const N: usize>(e: &M3<N>, r: V3<N>, f: Spatial<N>, parent: Spatial<N>) -> Spatial<N> {
    let linear = mat_vec(e, f.linear);
    Spatial { angular: cross_add(r, linear, mat_vec_add(e, f.angular, parent.angular)), linear: add(parent.linear, linear) }
}

/// Each body's pose in its parent's frame at `positions`: the entries of its rotation the joint
/// turns, a prismatic joint's translation.
#[inline(always)]
fn poses<const N: usize>(bodies: &[BodyLanes<N>], positions: &[Lanes<N>], rotation: &mut [M3<N>], translation: &mut [V3<N>]) {
    for ((body, e), r) in bodies.iter().zip(rotation.iter_mut()).zip(translation.iter_mut()) {
        let position = body.multiplier.mul_add(positions[body.coordinate], body.offset);
        if body.kind == JointAxisKind::Prismatic {
            *r = add(body.origin, scale(body.slide, position));
            continue;
        }
        let (sin, cos) = sin_cos(position);
        match body.kind {
            JointAxisKind::Coordinate { index: 0 } => CoordinateAxis::<0, N>::turn(&body.pose, sin, cos, e),
            JointAxisKind::Coordinate { index: 1 } => CoordinateAxis::<1, N>::turn(&body.pose, sin, cos, e),
            JointAxisKind::Coordinate { .. } => CoordinateAxis::<2, N>::turn(&body.pose, sin, cos, e),
            _ => GeneralAxis::turn(&body.pose, sin, cos, e),
        }
    }
}

/// The recursion from the root out: each body's velocity and acceleration in its own frame, the
/// world's acceleration `lift` (upward, against gravity) standing in for gravity, and the force
/// its motion needs, f = I·a + v ×* I·v (in the same loop: a loop of the forces alone, each body's
/// independent of the others', is vectorized by the compiler across bodies, lane by lane).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn motions<const N: usize>(bodies: &[BodyLanes<N>], rates: &[Lanes<N>], accelerations: &[Lanes<N>], rotation: &[M3<N>], translation: &[V3<N>], lift: &Spatial<N>, velocity: &mut [Spatial<N>], acceleration: &mut [Spatial<N>], force: &mut [Spatial<N>]) {
    for (i, body) in bodies.iter().enumerate() {
        let (e, r) = (&rotation[i], translation[i]);
        let (v_parent, a_parent) = match body.parent {
            Some(p) => (motion_to_body(e, r, velocity[p]), motion_to_body(e, r, acceleration[p])),
            None => (Spatial::default(), motion_to_body(e, r, *lift)),
        };
        let (rate, joint_acceleration) = (rates[body.coordinate], accelerations[body.coordinate]);
        (velocity[i], acceleration[i]) = match body.kind {
            JointAxisKind::Coordinate { index: 0 } => revolute_motion(CoordinateAxis::<0, N> { scale: body.axis[0] }, v_parent, a_parent, rate, joint_acceleration),
            JointAxisKind::Coordinate { index: 1 } => revolute_motion(CoordinateAxis::<1, N> { scale: body.axis[1] }, v_parent, a_parent, rate, joint_acceleration),
            JointAxisKind::Coordinate { .. } => revolute_motion(CoordinateAxis::<2, N> { scale: body.axis[2] }, v_parent, a_parent, rate, joint_acceleration),
            JointAxisKind::General => revolute_motion(GeneralAxis(body.axis), v_parent, a_parent, rate, joint_acceleration),
            JointAxisKind::Prismatic => {
                let joint_velocity = scale(body.axis, rate);
                let velocity = Spatial { angular: v_parent.angular, linear: add(v_parent.linear, joint_velocity) };
                // v ×ₘ (0, s·q̇) = (0, ω × s·q̇)
                let linear = add(add(a_parent.linear, scale(body.axis, joint_acceleration)), cross(velocity.angular, joint_velocity));
                (velocity, Spatial { angular: a_parent.angular, linear })
            }
        };
        let (v, a) = (velocity[i], acceleration[i]);
        force[i] = v.cross_force_add(body.inertia.mul_motion(v), body.inertia.mul_motion(a));
    }
}

/// A revolute joint's body's velocity and acceleration from its parent's (in the body's frame).
#[inline(always)]
fn revolute_motion<const N: usize, A: JointAxis<N>>(axis: A, v_parent: Spatial<N>, a_parent: Spatial<N>, rate: Lanes<N>, joint_acceleration: Lanes<N>) -> (Spatial<N>, Spatial<N>) {
    let joint_velocity = axis.along(rate);
    let velocity = Spatial { angular: axis.plus(v_parent.angular, joint_velocity), linear: v_parent.linear };
    // v ×ₘ (s·q̇, 0) = (ω × s·q̇, v × s·q̇)
    let angular = axis.plus_cross(axis.plus(a_parent.angular, axis.along(joint_acceleration)), velocity.angular, joint_velocity);
    let linear = axis.plus_cross(a_parent.linear, velocity.linear, joint_velocity);
    (velocity, Spatial { angular, linear })
}

/// The recursion from the leaves in: each joint's torque, the body's force carried to its parent;
/// then the motors' rotors (J_r·N²·q̈).
#[inline(always)]
fn torques<const N: usize>(bodies: &[BodyLanes<N>], rotation: &[M3<N>], translation: &[V3<N>], accelerations: &[Lanes<N>], armature: &[Lanes<N>], force: &mut [Spatial<N>], torque: &mut [Lanes<N>]) {
    for ((t, j), q̈) in torque.iter_mut().zip(armature).zip(accelerations) {
        *t = *j * *q̈;
    }
    for (i, body) in bodies.iter().enumerate().rev() {
        let f = force[i];
        let along = match body.kind {
            JointAxisKind::Coordinate { index } => body.axis[index] * f.angular[index],
            JointAxisKind::General => dot(body.axis, f.angular),
            JointAxisKind::Prismatic => dot(body.axis, f.linear),
        };
        torque[body.coordinate] = torque[body.coordinate] + along;
        if let Some(p) = body.parent {
            force[p] = add_force_to_parent(&rotation[i], translation[i], f, force[p]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot(name: &str) -> Model {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/robots").join(name);
        crate::model::load_urdf(&path).expect("the fixture loads")
    }

    /// A chain with a joint of every kind the lanes tell apart: about x, −y and z of its frame
    /// (turned by its origin's rpy), about a skew axis, prismatic, and a mimic joint about −z at
    /// −1.5 times its leader; a link frame's inertia off its axes.
    fn every_joint_kind() -> Model {
        let link = |name: &str| format!(r#"<link name="{name}"><inertial><origin xyz="0.02 -0.01 0.05" rpy="0.3 0.1 -0.2"/><mass value="0.7"/><inertia ixx="0.003" iyy="0.002" izz="0.001" ixy="0.0001" ixz="-0.0002" iyz="0.00005"/></inertial></link>"#);
        let joint = |name: &str, kind: &str, parent: &str, child: &str, rpy: &str, axis: &str, extra: &str| {
            format!(r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><origin xyz="0.01 0.02 0.1" rpy="{rpy}"/><axis xyz="{axis}"/><limit lower="-3" upper="3" effort="10" velocity="3"/>{extra}</joint>"#)
        };
        let links: String = ["base", "a", "b", "c", "d", "e", "f"].iter().map(|n| link(n)).collect();
        let joints = [
            joint("about_x", "revolute", "base", "a", "0.2 0.1 0", "1 0 0", ""),
            joint("about_minus_y", "revolute", "a", "b", "0 1.5708 0", "0 -1 0", ""),
            joint("about_z", "revolute", "b", "c", "-0.4 0 0.7", "0 0 1", ""),
            joint("about_skew", "revolute", "c", "d", "0 0 0", "0.6 0 0.8", ""),
            joint("slide", "prismatic", "d", "e", "0.1 0.2 0.3", "0 0 1", ""),
            joint("mimic", "revolute", "c", "f", "0.5 0 0", "0 0 -1", r#"<mimic joint="about_z" multiplier="-1.5" offset="0.2"/>"#),
        ]
        .concat();
        let urdf = format!(r#"<robot name="kinds">{links}{joints}</robot>"#);
        crate::model::load_urdf_str(&urdf, std::path::Path::new("kinds.urdf")).expect("the chain loads")
    }

    /// The kinds are told from the numbers: each coordinate axis (with its sign, or a mimic's
    /// multiplier) as such, a skew axis and a prismatic joint as the general forms.
    #[test]
    fn joint_axis_kinds_are_read_from_the_model() {
        let model = every_joint_kind();
        let kinds: Vec<JointAxisKind> = LanesData::<4>::new(&model).model.bodies.iter().map(|b| b.kind).collect();
        use JointAxisKind::*;
        assert_eq!(kinds, [Coordinate { index: 0 }, Coordinate { index: 1 }, Coordinate { index: 2 }, General, Prismatic, Coordinate { index: 2 }]);
        let so101 = robot("so101.urdf");
        assert!(LanesData::<4>::new(&so101).model.bodies.iter().all(|b| matches!(b.kind, Coordinate { .. })), "the SO-101's joints all turn about an axis of their frames");
    }

    /// Every state's torques are the scalar RNEA's: the same dynamics in the bodies' frames instead
    /// of the world's, so within a few roundings (1e-12 of the largest torque), on a 6-joint chain, a
    /// branched tree with prismatic joints (Tiago), one with mimic joints (Baxter) and a chain with
    /// a joint of every kind, in four lanes and in eight (in AVX-512 where the processor has it,
    /// else in the portable form), over a count of states that leaves a remainder for the scalar
    /// path.
    #[test]
    fn many_states_give_the_scalar_rneas_torques() {
        for (name, eight) in ["so101.urdf", "tiago.urdf", "baxter.urdf", "every joint kind"].into_iter().flat_map(|name| [(name, false), (name, true)]) {
            let model = if name == "every joint kind" { every_joint_kind() } else { robot(name) };
            let n = model.dof();
            let states = 4 * 8 + 5;
            let wave = |k: usize, c: usize, f: f64| ((k * n + c) as f64 * f).sin();
            let q: Vec<f64> = (0..states * n).map(|i| wave(i / n, i % n, 0.37)).collect();
            let v: Vec<f64> = (0..states * n).map(|i| 2.0 * wave(i / n, i % n, 0.71)).collect();
            let a: Vec<f64> = (0..states * n).map(|i| 5.0 * wave(i / n, i % n, 1.13)).collect();
            let mut tau = vec![f64::NAN; states * n];
            rnea_many(&model, &mut RneaManyData::with_width(&model, eight), &q, &v, &a, &mut tau);
            let mut data = Data::new(&model);
            for k in 0..states {
                let row = k * n..(k + 1) * n;
                let expected = rnea(&model, &mut data, &q[row.clone()], &v[row.clone()], &a[row.clone()]).to_vec();
                let scale = expected.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                for (c, (got, want)) in tau[row].iter().zip(&expected).enumerate() {
                    assert!((got - want).abs() <= 1e-12 * scale, "{name}, {} lanes: state {k}, coordinate {c}: {got} against rnea's {want}", if eight { 8 } else { 4 });
                }
            }
        }
    }
}
