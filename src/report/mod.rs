//! Reports: per-case JSON and PNG heat maps (of `lobes run` and `lobes check`), the run table,
//! the JSON Schema of every output, the one atomic file writer, and `lobes tradeoff`'s outputs.
//!
//! [`heatmap`] lays out a heat map from a [`colour`] scale, [`label`]s and [`text`], and
//! [`png`] encodes it; [`table`] prints terminal tables; [`output`] writes a case's files
//! (its arrays as NumPy [`npy`]),
//! [`check`] those of `lobes check`.

pub mod atomic;
pub mod check;
pub mod colour;
pub mod heatmap;
pub mod label;
pub mod output;
pub mod schema;
pub mod npy;
pub mod png;
pub mod table;
pub mod text;
pub mod tradeoff;
