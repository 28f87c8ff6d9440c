//! armscope: simulate a robot arm with real rigid-body dynamics and record every experiment.
//!
//! Data flows one way: [`config::RunConfig`] → [`model::Model`] → [`sim::simulate`] →
//! [`sample::Sample`]s → [`recorder::Recorder`]s (console, CSV, trace, JSON, …).

pub mod actuator;
pub mod allocator;
pub mod batch;
pub mod builtin;
pub mod canvas;
pub mod collision;
pub mod cli;
pub mod config;
pub mod control;
pub mod diagnose;
pub mod dynamics;
pub mod error;
pub mod experiment;
pub mod flags;
pub mod identify;
pub mod inspect;
pub mod meshgen;
pub mod model;
pub mod motion;
pub mod npy;
pub mod plant;
pub mod recorder;
pub mod replay;
pub mod ros2;
pub mod runner;
pub mod sample;
pub mod sim;
pub mod sizing;
pub mod spatial;
pub mod summary;
pub mod testbench;

pub use error::Error;
