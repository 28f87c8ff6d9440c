//! URDF → [`Model`]: parsing (urdf-rs, plus roxmltree for `<transmission>`, which urdf-rs drops),
//! validation with one-line errors, fixed-joint merging and welding of a free root.

use super::{Actuator, Coupling, Frame, Geometry, Joint, JointKind, JointMotion, Model, ModelError, ModelErrorKind as K, Visual};
use crate::spatial::{Pose, RigidInertia};
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Gravity of every loaded model; `--no-gravity` replaces it.
pub const STANDARD_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// How strictly a URDF is read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Refuse physically inconsistent inertias (not positive definite, triangle inequality broken),
    /// as Drake does; by default they are a notice and the URDF's numbers are used, as Pinocchio does.
    pub strict_inertia: bool,
}

pub fn load_urdf(path: &Path) -> Result<Model, ModelError> {
    load_urdf_with(path, LoadOptions::default())
}

pub fn load_urdf_with(path: &Path, options: LoadOptions) -> Result<Model, ModelError> {
    let fail = |kind| ModelError { file: path.to_path_buf(), kind };
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("xacro")) {
        return Err(fail(K::Xacro));
    }
    let text = crate::builtin::read_to_string(path).map_err(|e| fail(K::Io(e.to_string())))?;
    load_urdf_str_with(&text, path, options)
}

/// Load URDF text; `source` names it in messages and anchors relative mesh paths.
pub fn load_urdf_str(text: &str, source: &Path) -> Result<Model, ModelError> {
    load_urdf_str_with(text, source, LoadOptions::default())
}

pub fn load_urdf_str_with(text: &str, source: &Path, options: LoadOptions) -> Result<Model, ModelError> {
    let fail = |kind| ModelError { file: source.to_path_buf(), kind };
    build(text, source, options).map_err(fail)
}

fn one_line(s: impl ToString) -> String {
    s.to_string().split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `<texture/>` without a filename (iCub's and Romeo's exporters write it in every material):
/// urdfdom, and so Pinocchio and Drake, accept it; urdf-rs requires the filename. Textures play no
/// part here: the text without those elements, and a notice, or None when there are none.
fn without_empty_textures(doc: &roxmltree::Document, text: &str, notices: &mut Vec<String>) -> Option<String> {
    let empty: Vec<std::ops::Range<usize>> =
        doc.descendants().filter(|n| n.has_tag_name("texture") && n.attribute("filename").is_none()).map(|n| n.range()).collect();
    if empty.is_empty() {
        return None;
    }
    notices.push(format!("{} <texture> tag(s) without a filename ignored (textures are not drawn)", empty.len()));
    let mut repaired = String::with_capacity(text.len());
    let mut from = 0;
    for range in empty {
        repaired.push_str(&text[from..range.start]);
        from = range.end;
    }
    repaired.push_str(&text[from..]);
    Some(repaired)
}

fn build(text: &str, source: &Path, options: LoadOptions) -> Result<Model, K> {
    let doc = roxmltree::Document::parse(text).map_err(|e| K::Xml(one_line(e)))?;
    if doc.root_element().tag_name().name() != "robot" {
        return Err(K::Urdf(format!("root element is <{}>, expected <robot>", doc.root_element().tag_name().name())));
    }
    let mut notices = Vec::new();
    let mut missing_meshes = Vec::new();
    let repaired = without_empty_textures(&doc, text, &mut notices);
    let robot = urdf_rs::read_from_string(repaired.as_deref().unwrap_or(text)).map_err(|e| K::Urdf(one_line(e)))?;

    // Names.
    let mut link_index: HashMap<&str, usize> = HashMap::new();
    for (i, link) in robot.links.iter().enumerate() {
        if link_index.insert(link.name.as_str(), i).is_some() {
            return Err(K::DuplicateLink(link.name.clone()));
        }
    }
    if robot.links.is_empty() {
        return Err(K::Empty);
    }
    let mut joint_names: HashMap<&str, usize> = HashMap::new();
    for (i, joint) in robot.joints.iter().enumerate() {
        if joint_names.insert(joint.name.as_str(), i).is_some() {
            return Err(K::DuplicateJoint(joint.name.clone()));
        }
    }

    // Numbers, per element.
    for link in &robot.links {
        check_link(link, options, &mut notices)?;
    }
    for joint in &robot.joints {
        check_joint(joint)?;
        if joint.mimic.is_some() && joint.joint_type == urdf_rs::JointType::Fixed {
            notices.push(format!("joint '{}' is fixed; ignoring its <mimic>", joint.name));
        }
    }

    // Tree structure.
    let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut child_joints: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for (j, joint) in robot.joints.iter().enumerate() {
        let lookup = |role: &'static str, name: &str| {
            link_index.get(name).copied().ok_or_else(|| K::UnknownLink {
                joint: joint.name.clone(),
                role,
                link: name.to_string(),
            })
        };
        let parent = lookup("parent", &joint.parent.link)?;
        let child = lookup("child", &joint.child.link)?;
        if let Some(first) = parent_joint[child] {
            return Err(K::TwoParents {
                link: joint.child.link.clone(),
                first: robot.joints[first].name.clone(),
                second: joint.name.clone(),
            });
        }
        parent_joint[child] = Some(j);
        child_joints[parent].push(j);
    }
    let roots: Vec<usize> = (0..robot.links.len()).filter(|&l| parent_joint[l].is_none()).collect();
    let root = match roots.as_slice() {
        [] => return Err(K::Cycle(robot.links[0].name.clone())),
        [root] => *root,
        [a, b, ..] => return Err(K::MultipleRoots(robot.links[*a].name.clone(), robot.links[*b].name.clone())),
    };
    if robot.links[root].name != "world" {
        notices.push(format!(
            "root link '{}' is not attached to 'world'; welding it to the world at the origin",
            robot.links[root].name
        ));
    }

    // Depth-first from the root, in document order: parents before children, subtrees contiguous.
    let mut frames: Vec<Frame> = Vec::with_capacity(robot.links.len());
    let mut frame_of_link: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut depth: Vec<usize> = Vec::with_capacity(robot.links.len());
    let mut bodies: Vec<Joint> = Vec::new();
    // the URDF joint of each body
    let mut body_urdf_joint: Vec<usize> = Vec::new();
    let mut body_inertia: Vec<RigidInertia> = Vec::new();
    let base_dir = source.parent().unwrap_or(Path::new("."));

    let mut stack: Vec<(usize, Option<usize>)> = vec![(root, None)]; // (link, joint that reached it)
    while let Some((link, via)) = stack.pop() {
        let (body, placement, parent_frame, d) = match via {
            None => (None, Pose::identity(), None, 0),
            Some(j) => {
                let uj = &robot.joints[j];
                let pf = frame_of_link[link_index[uj.parent.link.as_str()]].expect("parent visited first");
                let joint_frame = frames[pf].placement.compose(&pose(&uj.origin));
                match joint_kind(uj)? {
                    None => (frames[pf].body, joint_frame, Some(pf), depth[pf] + 1),
                    Some(kind) => {
                        bodies.push(make_joint(uj, kind, frames[pf].body, joint_frame, &mut notices));
                        body_urdf_joint.push(j);
                        body_inertia.push(RigidInertia::zero());
                        (Some(bodies.len() - 1), Pose::identity(), Some(pf), depth[pf] + 1)
                    }
                }
            }
        };
        let ul = &robot.links[link];
        if let Some(b) = body {
            body_inertia[b] = body_inertia[b].combined(&link_inertia(ul).transformed(&placement));
        }
        let visuals = link_visuals(ul, &robot.materials, base_dir, &mut missing_meshes);
        let collisions = link_collisions(ul, base_dir, &mut missing_meshes);
        frame_of_link[link] = Some(frames.len());
        frames.push(Frame {
            name: ul.name.clone(),
            body,
            placement,
            parent_frame,
            parent_joint: via.map(|j| robot.joints[j].name.clone()),
            visuals,
            collisions,
        });
        depth.push(d);
        for &j in child_joints[link].iter().rev() {
            stack.push((link_index[robot.joints[j].child.link.as_str()], Some(j)));
        }
    }
    if let Some(unreached) = frame_of_link.iter().position(|f| f.is_none()) {
        return Err(K::Cycle(robot.links[unreached].name.clone()));
    }
    missing_mesh_notices(&missing_meshes, &mut notices);
    collada_up_axis_notices(&frames, &mut notices);
    if bodies.is_empty() {
        return Err(K::NoMovingJoints);
    }

    for (body, inertia) in bodies.iter_mut().zip(body_inertia) {
        body.inertia = inertia;
    }
    let (joints, couplings) = couple(&bodies, &body_urdf_joint, &robot, &mut notices)?;
    // Massless links are fine (frames, sensors, tools) as long as every coordinate moves
    // something: the mass matrix is then positive definite.
    match coordinate_moving_nothing(&bodies, &couplings, joints.len()) {
        Some(Ok(j)) => return Err(K::MovesNothing { joint: joints[j].name.clone(), link: joints[j].child_link.clone() }),
        // finite numbers whose sums overflow (1e308 in a URDF)
        Some(Err(j)) => return Err(K::NonFinite { element: format!("link '{}'", joints[j].child_link), field: "inertia of the links it carries", value: f64::INFINITY }),
        None => {}
    }

    let actuators = motors(&doc, &robot, &joints, &mut notices)?;

    // Tool: the deepest leaf link (first one in tree order on a tie).
    let is_leaf = |f: usize| !frames.iter().any(|g| g.parent_frame == Some(f));
    let tool_frame = (0..frames.len()).filter(|&f| is_leaf(f)).fold(0, |best, f| if depth[f] > depth[best] { f } else { best });

    let mut model = Model {
        name: robot.name.clone(),
        source: source.to_path_buf(),
        urdf_text: text.to_string(),
        gravity: Vector3::from(STANDARD_GRAVITY),
        joints,
        motions: bodies.iter().map(JointMotion::new).collect(),
        bodies,
        couplings,
        frames,
        actuators: Vec::new(),
        armature: Vec::new(),
        tool_frame,
        notices,
    };
    model.set_actuators(actuators);
    // (whether its plant can be solved — the mass matrix finite and positive definite — is the
    // dynamics' verdict, `dynamics::check_solvable`, asked where the model is simulated)
    Ok(model)
}

fn pose(p: &urdf_rs::Pose) -> Pose {
    Pose::from_xyz_rpy(p.xyz.0, p.rpy.0)
}

fn joint_kind(joint: &urdf_rs::Joint) -> Result<Option<JointKind>, K> {
    use urdf_rs::JointType as T;
    match joint.joint_type {
        T::Fixed => Ok(None),
        T::Revolute => Ok(Some(JointKind::Revolute)),
        T::Continuous => Ok(Some(JointKind::Continuous)),
        T::Prismatic => Ok(Some(JointKind::Prismatic)),
        T::Floating | T::Planar | T::Spherical => {
            Err(K::UnsupportedJoint { joint: joint.name.clone(), kind: format!("{:?}", joint.joint_type).to_lowercase() })
        }
    }
}

fn make_joint(uj: &urdf_rs::Joint, kind: JointKind, parent: Option<usize>, placement: Pose, notices: &mut Vec<String>) -> Joint {
    let axis = Vector3::from(uj.axis.xyz.0);
    let (lower, upper) = match kind {
        JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
        // SolidWorks' URDF exporter writes lower = upper = 0 as a placeholder for "no limits"
        _ if uj.limit.lower == uj.limit.upper => {
            notices.push(format!("joint '{}' has lower = upper = {} (a placeholder, as exporters write it); treating it as unlimited", uj.name, uj.limit.lower));
            (f64::NEG_INFINITY, f64::INFINITY)
        }
        _ => (uj.limit.lower, uj.limit.upper),
    };
    // no effort limit (0, as exporters write it): an unlimited motor, or passive (see `motors`)
    let effort = if uj.limit.effort > 0.0 { uj.limit.effort } else { f64::INFINITY };
    Joint {
        name: uj.name.clone(),
        kind,
        parent,
        placement,
        axis: axis / axis.norm(),
        inertia: RigidInertia::zero(),
        lower,
        upper,
        effort,
        velocity: uj.limit.velocity,
        damping: uj.dynamics.as_ref().map_or(0.0, |d| d.damping),
        friction: uj.dynamics.as_ref().map_or(0.0, |d| d.friction),
        child_link: uj.child.link.clone(),
    }
}

fn link_inertia(link: &urdf_rs::Link) -> RigidInertia {
    let i = &link.inertial.inertia;
    let tensor = Matrix3::new(i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz);
    let origin = pose(&link.inertial.origin);
    RigidInertia {
        mass: link.inertial.mass.value,
        com: origin.translation,
        inertia_com: origin.rotation * tensor * origin.rotation.transpose(),
    }
}

fn finite(element: &str, field: &'static str, values: &[f64]) -> Result<(), K> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(K::NonFinite { element: element.to_string(), field, value }),
        None => Ok(()),
    }
}

fn check_link(link: &urdf_rs::Link, options: LoadOptions, notices: &mut Vec<String>) -> Result<(), K> {
    let element = format!("link '{}'", link.name);
    let inertial = &link.inertial;
    finite(&element, "inertial origin", &[inertial.origin.xyz.0, inertial.origin.rpy.0].concat())?;
    finite(&element, "mass", &[inertial.mass.value])?;
    let i = &inertial.inertia;
    finite(&element, "inertia", &[i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz])?;
    for v in &link.visual {
        finite(&element, "visual origin", &[v.origin.xyz.0, v.origin.rpy.0].concat())?;
        let sizes: Vec<f64> = match &v.geometry {
            urdf_rs::Geometry::Box { size } => size.0.to_vec(),
            urdf_rs::Geometry::Cylinder { radius, length } | urdf_rs::Geometry::Capsule { radius, length } => vec![*radius, *length],
            urdf_rs::Geometry::Sphere { radius } => vec![*radius],
            urdf_rs::Geometry::Mesh { scale, .. } => scale.map_or(vec![], |s| s.0.to_vec()),
        };
        finite(&element, "visual geometry", &sizes)?;
    }
    if inertial.mass.value < 0.0 {
        return Err(K::NegativeMass { link: link.name.clone(), mass: inertial.mass.value });
    }
    if inertial.mass.value > 0.0 {
        match check_inertia(&link.name, &link_inertia(link).inertia_com) {
            Err(e) if !options.strict_inertia => {
                notices.push(format!("{e}; running with the URDF's numbers, as Pinocchio does (--strict-inertia refuses it)"))
            }
            result => result?,
        }
    }
    Ok(())
}

/// The first moving joint whose whole subtree has no inertia about its motion (no rotational
/// inertia about a revolute axis, no mass along a prismatic one) at the zero pose: the mass
/// matrix's diagonal entry, from the composite inertias of the subtrees. `Err(joint)`: that
/// joint's subtree inertia is not finite.
/// The coordinates of the model from its bodies' URDF joints: every joint without a `<mimic>` is one
/// (in body order); a `<mimic>` joint follows its master's coordinate, through chains of mimics. The
/// coordinates' joints carry the damping of the joints that follow them (D_r = GᵀDG).
fn couple(bodies: &[Joint], body_urdf_joint: &[usize], robot: &urdf_rs::Robot, notices: &mut Vec<String>) -> Result<(Vec<Joint>, Vec<Coupling>), K> {
    let mimic = |b: usize| robot.joints[body_urdf_joint[b]].mimic.as_ref();
    let mut coordinate_of_body: Vec<Option<usize>> = vec![None; bodies.len()];
    let mut joints: Vec<Joint> = Vec::new();
    for (b, body) in bodies.iter().enumerate() {
        if mimic(b).is_none() {
            coordinate_of_body[b] = Some(joints.len());
            joints.push(body.clone());
        }
    }
    let mut couplings = Vec::with_capacity(bodies.len());
    for (b, body) in bodies.iter().enumerate() {
        if let Some(c) = coordinate_of_body[b] {
            couplings.push(Coupling::independent(c));
            continue;
        }
        // follow the chain: q_b = m·q_master + o, the master possibly a mimic itself
        let (mut multiplier, mut offset, mut current, mut steps) = (1.0, 0.0, b, 0);
        let coupling = loop {
            let Some(m) = mimic(current) else { break Coupling { coordinate: coordinate_of_body[current].expect("an independent body"), multiplier, offset } };
            let fail = |what: &'static str| K::Mimic { joint: robot.joints[body_urdf_joint[current]].name.clone(), target: m.joint.clone(), what };
            let (k, o) = (m.multiplier.unwrap_or(1.0), m.offset.unwrap_or(0.0));
            if !k.is_finite() || !o.is_finite() {
                return Err(fail("has a multiplier or offset that is not a finite number"));
            }
            offset += multiplier * o;
            multiplier *= k;
            steps += 1;
            current = match bodies.iter().position(|j| j.name == m.joint) {
                Some(_) if steps > bodies.len() => return Err(fail("is part of a cycle of mimic joints")),
                Some(master) => master,
                None if robot.joints.iter().any(|j| j.name == m.joint) => return Err(fail("names a fixed joint; a mimic joint must follow a moving one")),
                None => return Err(fail("names a joint this URDF does not have")),
            };
        };
        let master = &mut joints[coupling.coordinate];
        // D_r = GᵀDG: the mimic's damping, seen through its multiplier, joins its master's
        master.damping += coupling.multiplier * coupling.multiplier * body.damping;
        // and its Coulomb friction, a box |τ| ≤ F seen through G: |multiplier|·F at the master
        master.friction += coupling.multiplier.abs() * body.friction;
        notices.push(format!(
            "joint '{}' mimics '{}' (q = {}·q + {}): it moves with it, its own limits and motor are not used",
            body.name, master.name, coupling.multiplier, coupling.offset
        ));
        couplings.push(coupling);
    }
    Ok((joints, couplings))
}

/// The first coordinate whose bodies' subtrees all have no inertia about their joints' motion
/// (`Ok`), or whose sums are not finite (`Err`).
fn coordinate_moving_nothing(bodies: &[Joint], couplings: &[Coupling], coordinates: usize) -> Option<Result<usize, usize>> {
    let mut composite: Vec<RigidInertia> = bodies.iter().map(|j| j.inertia).collect();
    for i in (0..bodies.len()).rev() {
        if let Some(p) = bodies[i].parent {
            composite[p] = composite[p].combined(&composite[i].transformed(&bodies[i].placement));
        }
    }
    let mut moves = vec![0.0; coordinates];
    for (i, c) in couplings.iter().enumerate() {
        let (ci, a) = (&composite[i], &bodies[i].axis);
        let about_motion = match bodies[i].kind {
            JointKind::Prismatic => ci.mass,
            JointKind::Revolute | JointKind::Continuous => {
                let about_origin = ci.inertia_com + (Matrix3::identity() * ci.com.norm_squared() - ci.com * ci.com.transpose()) * ci.mass;
                a.dot(&(about_origin * a))
            }
        };
        if !about_motion.is_finite() {
            return Some(Err(c.coordinate));
        }
        moves[c.coordinate] += c.multiplier * c.multiplier * about_motion;
    }
    moves.iter().position(|&m| m <= 0.0).map(Ok)
}

fn check_inertia(link: &str, tensor: &Matrix3<f64>) -> Result<(), K> {
    if tensor.iter().any(|x| !x.is_finite()) {
        return Err(K::NonFinite { element: format!("link '{link}'"), field: "combined inertia", value: f64::INFINITY });
    }
    let mut moments: Vec<f64> = SymmetricEigen::new(*tensor).eigenvalues.iter().copied().collect();
    moments.sort_by(f64::total_cmp);
    let listed = || moments.iter().map(|m| format!("{m:.6e}")).collect::<Vec<_>>().join(", ");
    if !(moments[0] > 0.0) {
        return Err(K::InertiaNotPositive { link: link.to_string(), moments: listed() });
    }
    let tolerance = 1e-6 * (moments[0] + moments[1] + moments[2]);
    if moments[0] + moments[1] < moments[2] - tolerance {
        return Err(K::InertiaTriangle { link: link.to_string(), moments: listed() });
    }
    Ok(())
}

fn check_joint(joint: &urdf_rs::Joint) -> Result<(), K> {
    let element = format!("joint '{}'", joint.name);
    finite(&element, "origin", &[joint.origin.xyz.0, joint.origin.rpy.0].concat())?;
    let moving = joint.joint_type != urdf_rs::JointType::Fixed;
    if moving {
        finite(&element, "axis", &joint.axis.xyz.0)?;
        if Vector3::from(joint.axis.xyz.0).norm() < 1e-9 {
            return Err(K::ZeroAxis(joint.name.clone()));
        }
    }
    let limit = &joint.limit;
    for (field, value) in [("lower limit", limit.lower), ("upper limit", limit.upper), ("effort", limit.effort), ("velocity", limit.velocity)] {
        if value.is_nan() {
            return Err(K::NonFinite { element: element.clone(), field, value });
        }
    }
    if let Some(d) = &joint.dynamics {
        finite(&element, "dynamics", &[d.damping, d.friction])?;
        if d.damping < 0.0 {
            return Err(K::Negative { joint: joint.name.clone(), field: "damping", value: d.damping });
        }
        if d.friction < 0.0 {
            return Err(K::Negative { joint: joint.name.clone(), field: "friction", value: d.friction });
        }
    }
    if moving {
        if limit.effort < 0.0 {
            return Err(K::Negative { joint: joint.name.clone(), field: "effort", value: limit.effort });
        }
        let limited = matches!(joint.joint_type, urdf_rs::JointType::Revolute | urdf_rs::JointType::Prismatic);
        if limited && limit.lower > limit.upper {
            return Err(K::BadLimits { joint: joint.name.clone(), lower: limit.lower, upper: limit.upper });
        }
    }
    Ok(())
}

/// A link's visuals. A mesh that cannot be found (a URDF shared without its mesh folder is common)
/// is a notice, and the link is drawn without it: with its collision shapes if they can be drawn,
/// else as a box with the link's inertia. The simulation does not need the geometry.
fn link_visuals(link: &urdf_rs::Link, materials: &[urdf_rs::Material], base_dir: &Path, missing_meshes: &mut Vec<MissingMesh>) -> Vec<Visual> {
    let mut missing = false;
    let mut visuals: Vec<Visual> = link
        .visual
        .iter()
        .filter_map(|v| match geometry(&v.geometry, base_dir) {
            Ok(geometry) => Some(Visual { origin: pose(&v.origin), geometry, rgba: rgba(v, materials) }),
            Err(looked) => {
                let filename = match &v.geometry {
                    urdf_rs::Geometry::Mesh { filename, .. } => filename.as_str(),
                    _ => "",
                };
                missing_meshes.push(MissingMesh { link: link.name.clone(), filename: filename.to_string(), looked, collision: false });
                missing = true;
                None
            }
        })
        .collect();
    if missing && visuals.is_empty() {
        visuals = link.collision.iter().filter_map(|c| geometry(&c.geometry, base_dir).ok().map(|g| Visual { origin: pose(&c.origin), geometry: g, rgba: None })).collect();
    }
    if missing && visuals.is_empty() {
        visuals.extend(inertia_box(link));
    }
    visuals
}

/// A link's collision geometry (`<collision>`); a mesh that cannot be found is a notice, and the
/// shape is left out of the collision checks.
fn link_collisions(link: &urdf_rs::Link, base_dir: &Path, missing_meshes: &mut Vec<MissingMesh>) -> Vec<Visual> {
    link.collision
        .iter()
        .filter_map(|c| match geometry(&c.geometry, base_dir) {
            Ok(geometry) => Some(Visual { origin: pose(&c.origin), geometry, rgba: None }),
            Err(looked) => {
                let filename = match &c.geometry {
                    urdf_rs::Geometry::Mesh { filename, .. } => filename.as_str(),
                    _ => "",
                };
                missing_meshes.push(MissingMesh { link: link.name.clone(), filename: filename.to_string(), looked, collision: true });
                None
            }
        })
        .collect()
}

/// A mesh file a link names that is not on disk.
struct MissingMesh {
    link: String,
    filename: String,
    looked: String,
    collision: bool,
}

/// What was done without the meshes that are not on disk, in one notice: a URDF shared without its mesh
/// folder misses every mesh, and one line per mesh (forty on an SO-101) would bury every other notice.
fn missing_mesh_notices(missing: &[MissingMesh], notices: &mut Vec<String>) {
    match missing {
        [] => {}
        [one] if one.collision => notices.push(format!("link '{}': collision mesh '{}' not found (looked for {}); left out of the collision checks", one.link, one.filename, one.looked)),
        [one] => notices.push(format!("link '{}': mesh '{}' not found (looked for {}); drawing the link without it", one.link, one.filename, one.looked)),
        [first, ..] => {
            let mut files: Vec<&str> = missing.iter().map(|m| m.filename.as_str()).collect();
            files.sort_unstable();
            files.dedup();
            let mut links: Vec<&str> = Vec::new();
            for m in missing {
                if !links.contains(&m.link.as_str()) {
                    links.push(&m.link);
                }
            }
            notices.push(format!(
                "{} mesh files not found ('{}'), named by links '{}' (the first, '{}' of link '{}', looked for {}): those links are drawn without them and the shapes left out of the collision checks",
                files.len(),
                files.join("', '"),
                links.join("', '"),
                first.filename,
                first.link,
                first.looked
            ));
        }
    }
}

/// One notice per COLLADA file that declares an up axis other than z: it is turned (the spec's
/// reading, Foxglove's and Gazebo's), which RViz, MoveIt and Pinocchio do not do — the one place
/// those tools draw the same file differently.
fn collada_up_axis_notices(frames: &[Frame], notices: &mut Vec<String>) {
    let mut seen = std::collections::HashSet::new();
    for frame in frames {
        for shape in frame.visuals.iter().chain(&frame.collisions) {
            let Geometry::Mesh { path, .. } = &shape.geometry else { continue };
            if !super::mesh_file::is_collada(path) || !seen.insert(path.clone()) {
                continue;
            }
            if let Some(up) = super::mesh_file::declared_up_axis(path).filter(|up| up != "Z_UP") {
                notices.push(format!(
                    "link '{}': mesh {} is {up} (COLLADA's <up_axis>): turned so that its up axis is z, as Foxglove and Gazebo draw it (RViz, MoveIt and Pinocchio leave it unturned)",
                    frame.name,
                    path.display()
                ));
            }
        }
    }
}

fn geometry(g: &urdf_rs::Geometry, base_dir: &Path) -> Result<Geometry, String> {
    Ok(match g {
        urdf_rs::Geometry::Box { size } => Geometry::Box { size: size.0 },
        urdf_rs::Geometry::Cylinder { radius, length } => Geometry::Cylinder { radius: *radius, length: *length },
        urdf_rs::Geometry::Capsule { radius, length } => Geometry::Capsule { radius: *radius, length: *length },
        urdf_rs::Geometry::Sphere { radius } => Geometry::Sphere { radius: *radius },
        urdf_rs::Geometry::Mesh { filename, scale } => Geometry::Mesh { path: resolve_mesh(filename, base_dir)?, scale: scale.map_or([1.0; 3], |s| s.0) },
    })
}

fn rgba(v: &urdf_rs::Visual, materials: &[urdf_rs::Material]) -> Option<[f32; 4]> {
    v.material.as_ref().and_then(|m| {
        m.color
            .as_ref()
            .or_else(|| materials.iter().find(|g| g.name == m.name).and_then(|g| g.color.as_ref()))
            .map(|c| c.rgba.0.map(|x| x as f32))
    })
}

/// The box of uniform density with the link's mass and principal moments, on its principal axes
/// at its centre of mass; `None` for a link without mass.
fn inertia_box(link: &urdf_rs::Link) -> Option<Visual> {
    let inertia = link_inertia(link);
    if !(inertia.mass > 0.0) {
        return None;
    }
    let eigen = SymmetricEigen::new(inertia.inertia_com);
    let (i, m) = (eigen.eigenvalues, inertia.mass);
    // a box a×b×c: I_x = m(b² + c²)/12, …, so a² = 6(I_y + I_z − I_x)/m
    let side = |k: usize| (6.0 * (i[(k + 1) % 3] + i[(k + 2) % 3] - i[k]) / m).max(0.0).sqrt().max(0.005);
    let mut rotation = eigen.eigenvectors;
    if rotation.determinant() < 0.0 {
        rotation.column_mut(2).neg_mut();
    }
    Some(Visual { origin: Pose::new(rotation, inertia.com), geometry: Geometry::Box { size: [side(0), side(1), side(2)] }, rgba: Some([0.6, 0.6, 0.65, 0.5]) })
}

/// Resolve a mesh reference: `package://PKG/rest` (searched as ROS does, in ROS_PACKAGE_PATH's
/// folders and AMENT_PREFIX_PATH's `share/`, then for a folder PKG, or a folder named PKG, at or
/// above the URDF's folder), `file://` and plain paths (relative to the URDF's folder).
fn resolve_mesh(filename: &str, base_dir: &Path) -> Result<PathBuf, String> {
    let mut candidates: Vec<PathBuf> = Vec::new();
    if let Some(rest) = filename.strip_prefix("package://") {
        let (package, relative) = rest.split_once('/').unwrap_or((rest, ""));
        let paths = |var: &str| std::env::var_os(var).map(|v| std::env::split_paths(&v).collect::<Vec<_>>()).unwrap_or_default();
        for dir in paths("ROS_PACKAGE_PATH") {
            if dir.file_name().is_some_and(|n| n == package) {
                candidates.push(dir.join(relative));
            }
            candidates.push(dir.join(package).join(relative));
        }
        for prefix in paths("AMENT_PREFIX_PATH") {
            candidates.push(prefix.join("share").join(package).join(relative));
        }
        for dir in base_dir.ancestors() {
            if dir.file_name().is_some_and(|n| n == package) {
                candidates.push(dir.join(relative));
            }
            candidates.push(dir.join(package).join(relative));
        }
        candidates.push(base_dir.join(relative));
    } else {
        let plain = filename.strip_prefix("file://").unwrap_or(filename);
        candidates.push(base_dir.join(plain));
    }
    match candidates.iter().find(|c| c.is_file()) {
        Some(found) => Ok(found.clone()),
        None => Err(candidates.iter().take(3).map(|c| c.display().to_string()).collect::<Vec<_>>().join(", ")),
    }
}

/// One actuator per `<transmission>`; empty when the URDF declares none. A transmission on a joint
/// that does not move (fixed) or that the URDF does not have is a notice and is ignored.
/// The motors: one per `<transmission>`; a moving joint without one is driven directly with its
/// URDF effort limit (as ros_control clamps to it), except, in a URDF whose transmissions leave it
/// out, a joint with no effort limit either: that one is passive. Drake makes motors from
/// transmissions only, which would leave e.g. Baxter's arms (transmissions on its grippers only)
/// hanging; each assumption is a notice.
fn motors(doc: &roxmltree::Document, robot: &urdf_rs::Robot, joints: &[Joint], notices: &mut Vec<String>) -> Result<Vec<Actuator>, K> {
    let mut actuators = actuators_from_transmissions(doc, robot, joints, notices)?;
    let has_transmissions = !actuators.is_empty();
    let urdf_effort = |j: &Joint| robot.joints.iter().find(|u| u.name == j.name).map_or(0.0, |u| u.limit.effort);
    let (mut direct, mut passive) = (Vec::new(), Vec::new());
    for (i, joint) in joints.iter().enumerate() {
        if actuators.iter().any(|a| a.joint == i) {
            continue;
        }
        if has_transmissions && urdf_effort(joint) <= 0.0 {
            passive.push(joint.name.as_str());
            continue;
        }
        if has_transmissions {
            direct.push(joint.name.as_str());
        }
        actuators.push(Actuator { name: joint.name.clone(), joint: i, effort: joint.effort, gear_ratio: 1.0, rotor_inertia: 0.0 });
    }
    let list = |names: &[&str]| names.iter().map(|n| format!("'{n}'")).collect::<Vec<_>>().join(", ");
    if !direct.is_empty() {
        notices.push(format!("joints {} have no <transmission>: each is driven directly by a motor with its URDF effort limit", list(&direct)));
    }
    if !passive.is_empty() {
        notices.push(format!("joints {} have neither a <transmission> nor an effort limit: passive", list(&passive)));
    }
    actuators.sort_by_key(|a| a.joint);
    for a in &actuators {
        if a.effort.is_infinite() {
            notices.push(format!("joint '{}' has no effort limit; its motor is treated as unlimited", joints[a.joint].name));
        }
    }
    Ok(actuators)
}

fn actuators_from_transmissions(doc: &roxmltree::Document, robot: &urdf_rs::Robot, joints: &[Joint], notices: &mut Vec<String>) -> Result<Vec<Actuator>, K> {
    let mut actuators: Vec<Actuator> = Vec::new();
    let mut directly_driven: Vec<usize> = Vec::new();
    for t in doc.root_element().children().filter(|n| n.has_tag_name("transmission")) {
        let name = t.attribute("name").unwrap_or("(unnamed)").to_string();
        let fail = |what: String| K::Transmission { transmission: name.clone(), what };
        let joint_nodes: Vec<_> = t.children().filter(|n| n.has_tag_name("joint")).collect();
        let actuator_nodes: Vec<_> = t.children().filter(|n| n.has_tag_name("actuator")).collect();
        if joint_nodes.is_empty() {
            // e.g. PR2's pr2_mechanism_model transmissions (<flexJoint>, <gap_joint>, …)
            let kind = t.children().find(|n| n.has_tag_name("type")).and_then(|n| n.text()).or(t.attribute("type")).unwrap_or("unknown");
            notices.push(format!("transmission '{name}' (type '{}') has no <joint> element; ignoring it", kind.trim()));
            continue;
        }
        if joint_nodes.len() != 1 || actuator_nodes.len() > 1 {
            // e.g. a differential wrist: its joints are driven directly, with their URDF effort limits
            notices.push(format!(
                "transmission '{name}' has {} joints and {} actuators; only simple transmissions (one joint, one actuator) are modelled: its joints get a motor each with their URDF effort",
                joint_nodes.len(),
                actuator_nodes.len()
            ));
            directly_driven.extend(joint_nodes.iter().filter_map(|n| n.attribute("name")).filter_map(|n| joints.iter().position(|j| j.name == n)));
            continue;
        }
        let joint_name = joint_nodes[0].attribute("name").ok_or_else(|| fail("<joint> has no name".into()))?;
        let Some(joint) = joints.iter().position(|j| j.name == joint_name) else {
            let what = match robot.joints.iter().find(|j| j.name == joint_name) {
                Some(j) if j.mimic.is_some() && j.joint_type != urdf_rs::JointType::Fixed => "a mimic joint (it follows the joint it mimics)",
                Some(_) => "a fixed joint",
                None => "a joint this URDF does not have",
            };
            notices.push(format!("transmission '{name}' drives joint '{joint_name}', {what}; ignoring the transmission"));
            continue;
        };
        if actuators.iter().any(|a| a.joint == joint) {
            return Err(fail(format!("joint '{joint_name}' already has an actuator")));
        }
        let actuator_name = actuator_nodes.first().and_then(|a| a.attribute("name")).unwrap_or(&name).to_string();
        let reduction_node = actuator_nodes
            .first()
            .and_then(|a| a.children().find(|n| n.has_tag_name("mechanicalReduction")))
            .or_else(|| t.children().find(|n| n.has_tag_name("mechanicalReduction")));
        let reduction = match reduction_node.and_then(|n| n.text()) {
            None => None,
            Some(text) => match text.trim().parse::<f64>() {
                Ok(r) if r.is_finite() && r != 0.0 => Some(r),
                _ => return Err(fail(format!("mechanicalReduction '{}' is not a finite non-zero number", text.trim()))),
            },
        };
        // Drake's own tags (xmlns:drake="http://drake.mit.edu"), matched by local name
        let drake_value = |tag: &str, positive: bool| -> Result<Option<f64>, K> {
            let Some(node) = actuator_nodes.first().and_then(|a| a.children().find(|n| n.is_element() && n.tag_name().name() == tag)) else { return Ok(None) };
            let text = node.attribute("value").ok_or_else(|| fail(format!("<drake:{tag}> has no value attribute")))?;
            match text.trim().parse::<f64>() {
                Ok(x) if x.is_finite() && (if positive { x > 0.0 } else { x >= 0.0 }) => Ok(Some(x)),
                _ => Err(fail(format!("<drake:{tag} value='{}'> must be a finite {} number", text.trim(), if positive { "positive" } else { "non-negative" }))),
            }
        };
        let gear_ratio = drake_value("gear_ratio", true)?.or(reduction).unwrap_or(1.0);
        let rotor_inertia = drake_value("rotor_inertia", false)?.unwrap_or(0.0);
        actuators.push(Actuator { name: actuator_name, joint, effort: joints[joint].effort, gear_ratio, rotor_inertia });
    }
    for joint in directly_driven {
        if !actuators.iter().any(|a| a.joint == joint) {
            actuators.push(Actuator { name: joints[joint].name.clone(), joint, effort: joints[joint].effort, gear_ratio: 1.0, rotor_inertia: 0.0 });
        }
    }
    Ok(actuators)
}

