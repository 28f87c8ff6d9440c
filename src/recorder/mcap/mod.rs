//! The MCAP output, for Foxglove (its well-known schemas, [`McapRecorder`]) or ROS 2 (CDR,
//! [`Ros2McapRecorder`]): the file and live clients both encodings write to, the scene they draw,
//! the collision topics, and the Foxglove layout written beside the file.

mod collisions;
mod foxglove_recorder;
mod layout;
pub mod live;
mod out;
mod protobuf_schema;
mod robot_description;
mod ros2_recorder;
mod scene;
mod step_messages;
pub mod telemetry;

pub use foxglove_recorder::McapRecorder;
pub use robot_description::{RobotDescription, decode as decode_robot_description};
pub use ros2_recorder::{Ros2McapRecorder, decode_controller_telemetry};
pub use scene::SCENE_BYTES_PER_SECOND;
pub use telemetry::ControllerTelemetry;

use std::path::PathBuf;

pub const TOPIC_TF: &str = "/tf";
pub const TOPIC_SCENE: &str = "/robot/geometry";
pub const TOPIC_JOINT_STATES: &str = "/joint_states";
pub const TOPIC_CONTROLLER: &str = "/controller";
pub const TOPIC_TOOL_POSE: &str = "/tool/pose";
pub const TOPIC_TOOL_PATH: &str = "/tool/path";
pub const TOPIC_COMMANDED_PATH: &str = "/tool/commanded_path";
pub const TOPIC_ROBOT_DESCRIPTION: &str = "/robot_description";

/// How the MCAP's messages are encoded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum McapEncoding {
    /// Foxglove's well-known protobuf schemas (Foxglove's 3D, plot and URDF panels as they are).
    #[default]
    Foxglove,
    /// ROS 2's: CDR with ros2msg schemas, the ros2 profile, rosbag2's QoS (`ros2 bag play`, RViz,
    /// PlotJuggler, rosbags, Rerun's MCAP importer).
    Ros2,
}

/// Where the MCAP recorder's messages go: a file, live Foxglove clients, or both.
#[derive(Clone, Debug, Default)]
pub struct McapOptions {
    pub file: Option<PathBuf>,
    /// `HOST:PORT` to serve the Foxglove WebSocket protocol at.
    pub live: Option<String>,
    /// zstd the file's chunks (`--compress`): ~35 % smaller, more CPU.
    pub compress: bool,
}
