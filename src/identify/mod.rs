//! Identifying a servo from bench logs (`armscope identify`): which parameters and where to look
//! ([`space`]), and the fit ([`fit`]).

pub mod fit;
pub mod space;

pub use fit::{Fit, FitOptions, fit};
pub use space::Space;
