//! What one experiment of a batch produced: the runner makes it, the tables and `batch merge` read it.

use crate::summary::Summary;
use serde::{Deserialize, Serialize};

/// One experiment's result, as the tables and `batch merge` see it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExperimentOutcome {
    pub index: usize,
    pub name: String,
    pub args: Vec<String>,
    /// completed, interrupted, diverged or failed.
    pub status: String,
    pub summary: Option<Summary>,
    pub error: Option<String>,
    /// The whole experiment, recordings included, s.
    pub wall_time: f64,
}
