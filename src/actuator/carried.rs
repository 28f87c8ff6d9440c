//! The drive trains as bodies the arm carries: where each joint's motor and reductions sit, and the
//! model with their mass and inertia added to the links they sit on.
//!
//! By default a joint's parts sit on its parent link, at the joint's origin, coaxial with its axis
//! (the motor a solid cylinder of its catalogue mass, flange width and length; a point mass where
//! the catalogue gives no dimensions). A motor file can mount them on another link at an offset (a
//! point mass there: its orientation is not known), or say that the URDF's masses already include
//! them (`in_urdf`). A part on the world (a base joint's motor on a fixed base) moves nothing.

use super::{MotorSet, Part};
use crate::model::Model;
use crate::spatial::{Pose, RigidInertia};
use nalgebra::Vector3;

/// Where a joint's drive-train parts sit.
#[derive(Clone, Debug, PartialEq, Default)]
pub enum Mount {
    /// On the joint's parent link, at its origin, along its axis.
    #[default]
    AtJoint,
    /// On this link (by name), at this point of its frame.
    OnLink { link: String, offset: [f64; 3] },
    /// The URDF's masses already include them.
    InUrdf,
}

/// One carried part placed on the model.
#[derive(Clone, Debug)]
pub struct PlacedPart {
    /// The coordinate whose drive train it belongs to.
    pub joint: usize,
    pub part: Part,
    /// The body it rides on (None: the world).
    pub body: Option<usize>,
    /// The URDF link it is fixed to, and its pose in that link's frame (the part's frame: its
    /// cylinder's axis is `axis` in it).
    pub link: String,
    pub pose_in_link: Pose,
    pub axis: Vector3<f64>,
    /// Its inertia in the body's frame.
    pub inertia_in_body: RigidInertia,
}

/// The index into `model.bodies` of the body coordinate `joint` moves.
fn body_of(model: &Model, joint: usize) -> usize {
    model.bodies.iter().position(|b| b.name == model.joints[joint].name).unwrap_or(joint)
}

/// Every part of `motors` that the arm carries, placed (the ones `in_urdf` left out). Errors name
/// the motor file and the link.
pub fn placed_parts(model: &Model, motors: &MotorSet) -> Result<Vec<PlacedPart>, String> {
    let mut out = Vec::new();
    for (joint, drive) in motors.joints.iter().enumerate() {
        let Some(drive) = drive else { continue };
        let mount = motors.mounts.get(joint).cloned().unwrap_or_default();
        if mount == Mount::InUrdf {
            continue;
        }
        let b = body_of(model, joint);
        let body = &model.bodies[b];
        for part in &drive.parts {
            let placed = match &mount {
                Mount::AtJoint => {
                    let (link, link_in_body) = match model.parent_link(b) {
                        Some(f) => (model.frames[f].name.clone(), model.frames[f].placement),
                        None => (String::new(), Pose::identity()),
                    };
                    // the joint frame in the parent link's frame
                    let pose_in_link = link_in_body.inverse().compose(&body.placement);
                    PlacedPart { joint, part: part.clone(), body: body.parent, link, pose_in_link, axis: body.axis, inertia_in_body: part.inertia(&body.axis).transformed(&body.placement) }
                }
                Mount::OnLink { link, offset } => {
                    let f = model.frame_index(link).ok_or_else(|| format!("joint '{}': mount_link '{link}' is no link of {}", model.joints[joint].name, model.source.display()))?;
                    let frame = &model.frames[f];
                    let pose_in_link = Pose::new(nalgebra::Matrix3::identity(), Vector3::from(*offset));
                    let point = Part { cylinder: None, ..part.clone() };
                    let inertia_in_body = point.inertia(&Vector3::z()).transformed(&frame.placement.compose(&pose_in_link));
                    PlacedPart { joint, part: point, body: frame.body, link: link.clone(), pose_in_link, axis: Vector3::z(), inertia_in_body }
                }
                Mount::InUrdf => unreachable!("skipped above"),
            };
            out.push(placed);
        }
    }
    Ok(out)
}

/// Add the carried parts' inertia to the bodies they ride on.
pub fn carry(model: &mut Model, parts: &[PlacedPart]) {
    for p in parts {
        if let Some(body) = p.body {
            model.bodies[body].inertia = model.bodies[body].inertia.combined(&p.inertia_in_body);
            if let Some(j) = model.joint_index(&model.bodies[body].name.clone()) {
                model.joints[j].inertia = model.bodies[body].inertia;
            }
        }
    }
}

/// The arm's moving mass (every body's), kg.
pub fn moving_mass(model: &Model) -> f64 {
    model.bodies.iter().map(|b| b.inertia.mass).sum()
}

/// Give `model` its drive trains: their parts carried (unless in the URDF) and each joint's motor as
/// an actuator whose effort is the torque the drive gives at rest and whose rotor (with the
/// reductions' input inertia) reflects through N² onto M's diagonal. Returns the parts placed.
pub fn install(model: &mut Model, set: &MotorSet) -> Result<Vec<PlacedPart>, String> {
    let parts = placed_parts(model, set)?;
    carry(model, &parts);
    let mut actuators = std::mem::take(&mut model.actuators);
    for (joint, drive) in set.joints.iter().enumerate() {
        let Some(drive) = drive else { continue };
        actuators.retain(|a| a.joint != joint);
        actuators.push(crate::model::Actuator { name: drive.motor.name().to_string(), joint, effort: drive.torque_limit(0.0), gear_ratio: drive.gear_ratio, rotor_inertia: drive.shaft_inertia() });
    }
    model.set_actuators(actuators);
    Ok(parts)
}

/// `urdf` (the model's own text) with each carried part as a link fixed to the link it sits on:
/// its mass and its inertia (about its centre, in the parent link's axes), so any other library
/// loads the masses armscope simulates. (Rotor inertias are not URDF: `model --states` gives the
/// armature beside M.)
pub fn urdf_with_parts(urdf: &str, parts: &[PlacedPart], model: &Model) -> Result<String, String> {
    let end = urdf.rfind("</robot>").ok_or("the URDF has no closing </robot>")?;
    let mut added = String::from("\n  <!-- armscope: the drive trains' parts, carried on the arm -->\n");
    for (i, p) in parts.iter().enumerate() {
        let joint = &model.joints[p.joint].name;
        let name = format!("armscope_{joint}_{}_{i}", p.part.name).chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' || c == '-' { c } else { '_' }).collect::<String>();
        let inertia = p.part.inertia(&p.axis);
        let r = p.pose_in_link.rotation;
        let i_link = r * inertia.inertia_com * r.transpose();
        let t = p.pose_in_link.translation;
        added += &format!(
            "  <link name=\"{name}\">\n    <inertial>\n      <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n      <mass value=\"{:e}\"/>\n      <inertia ixx=\"{:e}\" ixy=\"{:e}\" ixz=\"{:e}\" iyy=\"{:e}\" iyz=\"{:e}\" izz=\"{:e}\"/>\n    </inertial>\n  </link>\n  <joint name=\"{name}_mount\" type=\"fixed\">\n    <parent link=\"{}\"/>\n    <child link=\"{name}\"/>\n    <origin xyz=\"{:e} {:e} {:e}\" rpy=\"0 0 0\"/>\n  </joint>\n",
            p.part.mass,
            i_link[(0, 0)],
            i_link[(0, 1)],
            i_link[(0, 2)],
            i_link[(1, 1)],
            i_link[(1, 2)],
            i_link[(2, 2)],
            p.link,
            t.x,
            t.y,
            t.z
        );
    }
    Ok(format!("{}{added}{}", &urdf[..end], &urdf[end..]))
}
