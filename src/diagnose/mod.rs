//! Reading a run rather than making one: the sampled loop's linearization and stability
//! (`armscope analyze`), the speed × amplitude envelope, motor sizing (`armscope size`), and the
//! labelled heatmaps and charts they draw.

pub mod analysis;
pub mod envelope;
pub mod heatmap;
pub mod loop_report;
pub mod size;
mod size_report;
