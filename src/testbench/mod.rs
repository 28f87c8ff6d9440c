//! Servo bench logs replayed against a servo model: BAM's pendulum bench ([`pendulum`]), its
//! logs ([`log`]), the replay ([`replay`]), what it says about each log ([`report`]) and the
//! recordings that overlay measurement and simulation ([`recording`]).

pub mod log;
pub mod pendulum;
pub mod reading;
pub mod recording;
pub mod replay;
pub mod report;
pub mod synthetic;

pub use log::BenchLog;
pub use pendulum::Pendulum;
pub use replay::{ReplayOptions, Rollout, Step, Supply, mae, mae_within, rollout};
pub use report::{LogResult, Summary};
