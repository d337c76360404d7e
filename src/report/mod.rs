//! Reports: per-case JSON and PNG heat maps, and the run table.

pub mod heatmap;
pub mod output;
pub mod table;
pub mod tradeoff;
