//! Flags as clap parses them, shared by the command line (`cli`) and batch manifests (`batch`), whose
//! experiments are written as `run` flags.

mod run;
mod shared;

pub use run::RunArgs;
pub use shared::{GainArgs, MotorArgs, RecordedMotionArgs, RecordingFiles, WaveArgs};
