//! Reading a run rather than making one: the sampled loop's linearization and stability
//! (`armscope analyze`), the speed × amplitude envelope, and the labelled heatmaps and charts they
//! (and the sizing report) draw.

pub mod analysis;
pub mod envelope;
pub mod heatmap;
pub mod loop_report;
