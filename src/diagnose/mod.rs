//! Reading a run rather than making one: the sampled loop's stability report (`armscope analyze`,
//! on `control::sampled_loop`), the speed × amplitude envelope, and the labelled heatmaps and
//! charts they (and the sizing report) draw.

pub mod envelope;
pub mod heatmap;
pub mod loop_report;
