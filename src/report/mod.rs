//! Reports: per-case JSON and PNG heat maps, the run table, the JSON Schema of every output,
//! and the one atomic file writer.

pub mod atomic;
pub mod heatmap;
pub mod output;
pub mod schema;
pub mod tradeoff;
