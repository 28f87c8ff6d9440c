//! The read-only robot model: built once from a URDF, shared by every simulation of it.

mod error;
pub mod mesh_file;
mod joint_motion;
mod urdf;

pub use error::{ModelError, ModelErrorKind};
pub use joint_motion::JointMotion;
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

/// One moving joint and the rigid body it moves (fixed children merged in). In
/// [`Model::bodies`], joint `i` moves body `i`, and every joint's parent has a smaller index.
#[derive(Clone, Debug)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// The body (index into [`Model::bodies`]) this joint hangs from; `None` is the world.
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
    /// Viscous damping, N·m·s/rad. In [`Model::joints`], a coordinate's: its own plus, for each
    /// joint that mimics it, multiplier² × that joint's (D_r = GᵀDG, which stays diagonal).
    pub damping: f64,
    /// Coulomb friction, N·m or N (URDF `<dynamics friction>`): the joint sticks while the other
    /// torques on it are within ±friction, and slides against −friction·sign(q̇). In
    /// [`Model::joints`] a coordinate's own plus |multiplier| × each of its mimic joints'.
    pub friction: f64,
    /// The URDF link this joint moves.
    pub child_link: String,
}

impl Joint {
    pub fn has_limits(&self) -> bool {
        self.lower.is_finite() || self.upper.is_finite()
    }

    /// Its limits as an interval (lowest, highest), whichever way round the URDF wrote them.
    pub fn range(&self) -> (f64, f64) {
        (self.lower.min(self.upper), self.upper.max(self.lower))
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
    /// Its `<collision>` shapes (the collision checks'; a mesh not found is left out, with a notice).
    pub collisions: Vec<Visual>,
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
    /// The gear ratio N: `<drake:gear_ratio>`, else `<mechanicalReduction>`, else 1.
    pub gear_ratio: f64,
    /// The motor's rotor inertia J_r (kg·m²), `<drake:rotor_inertia>`; 0 when not given.
    pub rotor_inertia: f64,
}

impl Actuator {
    /// The rotor's inertia seen at the joint, J_r·N² (Drake's reflected inertia, MuJoCo's and
    /// Pinocchio's armature).
    pub fn reflected_inertia(&self) -> f64 {
        self.rotor_inertia * self.gear_ratio * self.gear_ratio
    }
}

#[derive(Clone, Debug)]
pub struct Model {
    pub name: String,
    /// The URDF file it came from (or a label for in-memory text).
    pub source: PathBuf,
    /// The URDF text, kept for recordings (`/robot_description`).
    pub urdf_text: String,
    pub gravity: Vector3<f64>,
    /// The independent moving joints: the model's coordinates, which q, q̇, τ and everything per
    /// joint (limits, motors, gains, recordings) are indexed by. A `<mimic>` joint is not one of them.
    pub joints: Vec<Joint>,
    /// Every moving joint with the body it moves: the tree the dynamics walk (parents first).
    /// Without `<mimic>` joints, the same list as `joints`.
    pub bodies: Vec<Joint>,
    /// Per body, the coordinate its joint follows: q_joint = multiplier·q[coordinate] + offset.
    pub couplings: Vec<Coupling>,
    /// Per body, its joint's motion multiplied out from the placement and axis (what forward
    /// kinematics evaluates), computed when the model is built: whoever changes a body's placement,
    /// axis or kind after that rebuilds it with `JointMotion::new`.
    pub motions: Vec<JointMotion>,
    pub frames: Vec<Frame>,
    pub actuators: Vec<Actuator>,
    /// Per coordinate, the reflected inertia of its motor's rotor, J_r·N², added to M's diagonal by
    /// every algorithm (CRBA, ABA), as Drake does. Zero without rotor inertias.
    pub armature: Vec<f64>,
    /// The frame whose origin is the tool tip: the deepest leaf link unless chosen otherwise.
    pub tool_frame: usize,
    /// Things the loader did on the user's behalf (e.g. welding a free root to the world).
    pub notices: Vec<String>,
}

/// How a body's joint follows the model's coordinates, as a URDF `<mimic>` says (Pinocchio's
/// `mimic=True`, Drake's coupler constraint): q_joint = multiplier·q[coordinate] + offset; an
/// independent joint is its own coordinate with multiplier 1 and offset 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupling {
    pub coordinate: usize,
    pub multiplier: f64,
    pub offset: f64,
}

impl Coupling {
    pub fn independent(coordinate: usize) -> Self {
        Self { coordinate, multiplier: 1.0, offset: 0.0 }
    }

    /// The body joint's position (or velocity, with `offset` left out) from the coordinates.
    #[inline]
    pub fn position(&self, q: &[f64]) -> f64 {
        self.multiplier * q[self.coordinate] + self.offset
    }
}

impl Model {
    /// Whether some joint follows another (`<mimic>`): the bodies are then more than the coordinates.
    pub fn has_mimic(&self) -> bool {
        self.bodies.len() != self.joints.len()
    }

    /// The bodies whose joint mimics another, with the coordinate it follows.
    pub fn mimic_bodies(&self) -> impl Iterator<Item = (usize, &Joint, &Coupling)> {
        self.bodies.iter().zip(&self.couplings).enumerate().filter(|(_, (b, c))| self.joints[c.coordinate].name != b.name).map(|(i, (b, c))| (i, b, c))
    }

    /// Number of degrees of freedom (one per independent moving joint).
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    pub fn frame_index(&self, name: &str) -> Option<usize> {
        self.frames.iter().position(|f| f.name == name)
    }

    /// The frame of the link body `body`'s joint hangs from (its URDF parent link).
    pub fn parent_link(&self, body: usize) -> Option<usize> {
        self.frame_index(&self.bodies[body].child_link).and_then(|f| self.frames[f].parent_frame)
    }

    /// Give the model its motors (sorted by joint) and the reflected inertias they bring to M's
    /// diagonal: the one place `armature` is derived from `actuators`.
    pub fn set_actuators(&mut self, mut actuators: Vec<Actuator>) {
        actuators.sort_by_key(|a| a.joint);
        self.armature = vec![0.0; self.dof()];
        for a in &actuators {
            self.armature[a.joint] += a.reflected_inertia();
        }
        self.actuators = actuators;
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

    /// The mass of every link of its URDF, kg (those fixed to the world too).
    pub fn frames_mass(&self) -> f64 {
        urdf_rs::read_from_string(&self.urdf_text).map_or(0.0, |robot| robot.links.iter().map(|l| l.inertial.mass.value).sum())
    }

    /// The model with a point mass of `kg` at the tool frame's origin (a payload; none for 0).
    pub fn with_payload(mut self, kg: f64) -> Model {
        if kg > 0.0 {
            let frame = &self.frames[self.tool_frame];
            if let Some(body) = frame.body {
                let point = RigidInertia { mass: kg, com: frame.placement.translation, inertia_com: nalgebra::Matrix3::zeros() };
                self.bodies[body].inertia = self.bodies[body].inertia.combined(&point);
            }
        }
        self
    }
}
