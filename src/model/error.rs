use std::path::PathBuf;

/// A model that cannot be loaded. Displays as one line naming the file and the link or joint.
#[derive(Debug, thiserror::Error)]
#[error("{}: {kind}", file.display())]
pub struct ModelError {
    pub file: PathBuf,
    pub kind: ModelErrorKind,
}

#[derive(Debug, thiserror::Error)]
pub enum ModelErrorKind {
    #[error("cannot read file: {0}")]
    Io(String),
    #[error("malformed XML: {0}")]
    Xml(String),
    #[error("not a valid URDF: {0}")]
    Urdf(String),
    #[error("duplicate link name '{0}'")]
    DuplicateLink(String),
    #[error("duplicate joint name '{0}'")]
    DuplicateJoint(String),
    #[error("joint '{joint}': unknown {role} link '{link}'")]
    UnknownLink { joint: String, role: &'static str, link: String },
    #[error("link '{link}' has two parent joints ('{first}' and '{second}')")]
    TwoParents { link: String, first: String, second: String },
    #[error("link '{0}' is part of a cycle of joints; a URDF must be a tree")]
    Cycle(String),
    #[error("links '{0}' and '{1}' are both roots; a URDF must be one connected tree")]
    MultipleRoots(String, String),
    #[error("no links")]
    Empty,
    #[error("no moving joints: nothing to simulate")]
    NoMovingJoints,
    #[error("joint '{joint}': {kind} joints are not supported")]
    UnsupportedJoint { joint: String, kind: String },
    #[error("joint '{joint}': <mimic joint='{target}'> {what}")]
    Mimic { joint: String, target: String, what: &'static str },
    #[error("{element}: {field} is {value}, not a finite number")]
    NonFinite { element: String, field: &'static str, value: f64 },
    #[error("joint '{0}': axis is zero")]
    ZeroAxis(String),
    #[error("joint '{joint}': lower limit {lower} is above upper limit {upper}")]
    BadLimits { joint: String, lower: f64, upper: f64 },
    #[error("joint '{joint}': {field} must not be negative (got {value})")]
    Negative { joint: String, field: &'static str, value: f64 },
    #[error("link '{link}': mass {mass} is negative")]
    NegativeMass { link: String, mass: f64 },
    #[error("joint '{joint}' moves nothing: link '{link}' and everything beyond it have no mass or inertia about the joint's motion; give link '{link}' an <inertial>")]
    MovesNothing { joint: String, link: String },
    #[error("joint '{joint}': the mass matrix is singular there (q = 0): the inertia it moves is lost in rounding against numbers many orders of magnitude larger; check the masses, inertias and origins from link '{link}' on")]
    MassMatrixSingular { joint: String, link: String },
    #[error("this is a xacro file; expand it to a URDF first: xacro FILE.urdf.xacro > FILE.urdf (ROS's xacro, also `pip install xacro`)")]
    Xacro,
    #[error("link '{link}': inertia is not positive definite (principal moments {moments})")]
    InertiaNotPositive { link: String, moments: String },
    #[error("link '{link}': inertia breaks the triangle inequality (principal moments {moments}: each must be at most the sum of the other two)")]
    InertiaTriangle { link: String, moments: String },
    #[error("transmission '{transmission}': {what}")]
    Transmission { transmission: String, what: String },
}
