//! The Rerun output: the `.rrd` file and the live viewer. [`RerunRecorder`] sends the run; the
//! files beside it are what it is made of: the blueprint it opens to, the shapes it draws, the
//! collision checks, the columns it sends and the file it writes.

mod blueprint;
mod collisions;
mod column_pool;
mod columns;
pub(crate) mod file;
mod geometry;
mod markdown;
mod recorder;

pub use blueprint::{blueprint, joint_color, send_blueprint};
pub(crate) use columns::{scalar_column, send_in_order};
pub use markdown::{config_markdown, summary_markdown};
pub use recorder::{DEFAULT_CONNECT_URL, LiveViewer, RerunOptions, RerunRecorder};

/// The timeline every series and pose is logged on: the simulation's time, s.
pub const TIMELINE: &str = "sim_time";
