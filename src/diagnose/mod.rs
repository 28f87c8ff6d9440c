//! Reading a run rather than making one: the sampled loop's stability report (`armscope analyze`,
//! on `control::sampled_loop`) and the speed × amplitude envelope (its heatmap drawn on
//! `crate::canvas`, as the sizing report's charts are).

pub mod envelope;
pub mod loop_report;
