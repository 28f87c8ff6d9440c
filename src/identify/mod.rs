//! Identifying a servo from bench logs (`armscope identify`): which parameters and where to look
//! ([`space`]), and the fit ([`fit`]) with CMA-ES ([`cmaes`]); an arm from its own episodes ([`arm`]),
//! with the supply on which the catalogue's servos would hold as its fitted ones do ([`equivalent_supply`]).

pub mod arm;
pub mod cmaes;
pub mod equivalent_supply;
pub mod fit;
pub mod floor;
pub mod space;

pub use fit::{Fit, FitOptions, Progress, fit};
pub use space::Space;
