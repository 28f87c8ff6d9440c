//! The read-only robot model: built once from a URDF, shared by every simulation of it.

mod error;
mod urdf;

pub use error::{ModelError, ModelErrorKind};
pub use urdf::{LoadOptions, load_urdf, load_urdf_str, load_urdf_str_with, load_urdf_with};

use crate::spatial::{Pose, RigidInertia};
use nalgebra::Vector3;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    Revolute,
    /// A revolute joint without position limits.
    Continuous,
    Prismatic,
}

/// One moving joint and the rigid body it moves (fixed children merged in).
/// Joint `i` moves body `i`, and every joint's parent has a smaller index.
#[derive(Clone, Debug)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// The body this joint hangs from; `None` is the world.
    pub parent: Option<usize>,
    /// The joint frame in the parent body's frame (at q = 0).
    pub placement: Pose,
    /// Unit axis in the joint frame.
    pub axis: Vector3<f64>,
    /// Inertia of the moved body (its URDF link and every link welded to it) in the body frame,
    /// which is the joint frame.
    pub inertia: RigidInertia,
    pub lower: f64,
    pub upper: f64,
    /// URDF `<limit effort>`, N·m or N; infinite when the URDF gives none.
    pub effort: f64,
    /// URDF `<limit velocity>` (informational: like Drake, not enforced).
    pub velocity: f64,
    /// Viscous damping, N·m·s/rad.
    pub damping: f64,
    /// The URDF link this joint moves.
    pub child_link: String,
}

impl Joint {
    pub fn has_limits(&self) -> bool {
        self.lower.is_finite() || self.upper.is_finite()
    }
}

/// Every URDF link, as a frame rigidly attached to a body.
#[derive(Clone, Debug)]
pub struct Frame {
    pub name: String,
    /// The body it moves with; `None` is the world.
    pub body: Option<usize>,
    /// The link frame in the body frame.
    pub placement: Pose,
    /// Index of the parent frame (the parent link), `None` for the root.
    pub parent_frame: Option<usize>,
    /// Name of the URDF joint that attaches this link to its parent.
    pub parent_joint: Option<String>,
    pub visuals: Vec<Visual>,
}

#[derive(Clone, Debug)]
pub struct Visual {
    /// The visual's origin in its link frame.
    pub origin: Pose,
    pub geometry: Geometry,
    pub rgba: Option<[f32; 4]>,
}

#[derive(Clone, Debug)]
pub enum Geometry {
    Box { size: [f64; 3] },
    /// Along the frame's z axis, as in URDF.
    Cylinder { radius: f64, length: f64 },
    Capsule { radius: f64, length: f64 },
    Sphere { radius: f64 },
    Mesh { path: PathBuf, scale: [f64; 3] },
}

/// A motor driving one joint.
#[derive(Clone, Debug)]
pub struct Actuator {
    pub name: String,
    pub joint: usize,
    /// Torque (force) limit at the joint.
    pub effort: f64,
    /// `<mechanicalReduction>`; 1 when the URDF gives none.
    pub gear_ratio: f64,
}

#[derive(Clone, Debug)]
pub struct Model {
    pub name: String,
    /// The URDF file it came from (or a label for in-memory text).
    pub source: PathBuf,
    /// The URDF text, kept for recordings (`/robot_description`).
    pub urdf_text: String,
    pub gravity: Vector3<f64>,
    pub joints: Vec<Joint>,
    pub frames: Vec<Frame>,
    pub actuators: Vec<Actuator>,
    /// The frame whose origin is the tool tip: the deepest leaf link unless chosen otherwise.
    pub tool_frame: usize,
    /// Things the loader did on the user's behalf (e.g. welding a free root to the world).
    pub notices: Vec<String>,
}

impl Model {
    /// Number of degrees of freedom (one per moving joint).
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    pub fn frame_index(&self, name: &str) -> Option<usize> {
        self.frames.iter().position(|f| f.name == name)
    }

    /// Torque limit per joint: the actuator's effort, 0 for a joint without an actuator.
    pub fn effort_limits(&self) -> Vec<f64> {
        let mut effort = vec![0.0; self.dof()];
        for a in &self.actuators {
            effort[a.joint] = a.effort;
        }
        effort
    }

    pub fn is_actuated(&self, joint: usize) -> bool {
        self.actuators.iter().any(|a| a.joint == joint)
    }

    pub fn damping(&self) -> Vec<f64> {
        self.joints.iter().map(|j| j.damping).collect()
    }

    pub fn with_gravity(mut self, gravity: Vector3<f64>) -> Self {
        self.gravity = gravity;
        self
    }

    /// Choose the tool frame by link name.
    pub fn set_tool_frame(&mut self, link: &str) -> Result<(), String> {
        match self.frame_index(link) {
            Some(i) => {
                self.tool_frame = i;
                Ok(())
            }
            None => Err(format!("no link named '{link}' in {}", self.source.display())),
        }
    }

    /// The chain of joints from the root to `body`, as a boolean mask (for Jacobians).
    pub fn supports(&self, body: Option<usize>, joint: usize) -> bool {
        let mut b = body;
        while let Some(i) = b {
            if i == joint {
                return true;
            }
            b = self.joints[i].parent;
        }
        false
    }
}
