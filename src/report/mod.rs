//! Reports: per-case JSON and PNG heat maps, the run table, and the one atomic file writer.

pub mod atomic;
pub mod heatmap;
pub mod output;
pub mod tradeoff;
