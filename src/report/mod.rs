//! Reports: per-case JSON and PNG pictures (of `lobes run` and `lobes check`), the run table and
//! its HTML page, the JSON Schema of every output, the one atomic file writer, and
//! `lobes tradeoff`'s outputs.
//!
//! [`heatmap`] lays out a heat map from a [`colour`] scale, [`label`]s and [`text`], and
//! [`png`] encodes it; [`marginals`] charts bins against their expectation; [`compare`] draws a
//! measured histogram against its expectation with both (one code path for `lobes run` and
//! `lobes check`), titled by [`caption`]; [`table`] prints terminal tables; [`output`] writes a
//! case's files (its arrays as NumPy [`npy`]), [`check`] those of `lobes check`; [`html`] writes the run's `index.html`.

pub use crate::atomic;
pub mod caption;
pub mod check;
pub mod colour;
pub mod compare;
pub mod heatmap;
#[cfg(feature = "cli")]
pub mod junit;
pub mod folder;
pub mod html;
pub mod label;
pub mod marginals;
pub mod outcome;
pub mod output;
pub mod schema;
#[cfg(feature = "cli")]
pub mod summary;
pub mod npy;
pub mod png;
pub mod table;
pub mod text;
pub mod tradeoff;
