//! Reading a run rather than making one: the sampled loop's linearization and stability
//! (`armscope analyze`), the speed × amplitude envelope, and the labelled heatmaps they draw.

pub mod analysis;
pub mod envelope;
pub mod heatmap;
pub mod loop_report;
