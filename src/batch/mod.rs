//! `armscope batch`: many experiments from a manifest, in parallel, with summary tables and a
//! comparison recording; shards for clusters and merging of their summaries.

mod compare;
mod manifest;
mod outcome;
mod runner;
mod table;

pub use compare::{ComparedRun, build_comparison};
pub use manifest::{Manifest, PlannedExperiment, load_manifest, parse_shard, shard};
pub use outcome::ExperimentOutcome;
pub use runner::{BatchOptions, run_args, run_batch, write_comparison};
pub use table::{BatchSummary, merge_summaries, table_stem, write_tables};
