//! # lobes
//!
//! GPU importance sampling of reflectance lobes (Ward, Beckmann, GGX) and discrete
//! distributions: WGSL compute kernels draw and histogram millions of samples, and an f64
//! CPU reference judges the histograms with a χ² test.
//!
//! The folders are the layers, from the math up; each imports only layers listed before it
//! (`tests/layout.rs` checks that no two import each other):
//!
//! - `wgsl_tokens`: WGSL's tokens (names, `::` paths, numbers, punctuation; comments skipped),
//!   the one lexer of every rewrite of WGSL text ([`embed`]'s namespace, the GPU library's
//!   imports, [`check`]'s dialects).
//! - [`atomic`]: the one way lobes writes a file (the outputs, and the GPU engine's pipeline
//!   cache); [`console`]: the one way it writes a line on stderr.
//! - [`reference`](mod@reference): the f64 math, one module per lobe, each the twin of a WGSL
//!   file in `shaders/`.
//! - [`stats`]: binning, expected counts by quadrature, the χ² test, weighted sums.
//! - [`engine`]: what to draw ([`engine::job`]) and the engines that draw and histogram it: the
//!   GPU one ([`engine::gpu`], WGSL composed from `shaders/`, run through wgpu) and the f64 CPU
//!   one ([`engine::cpu`]).
//! - [`scene`]: scene files and their cases.
//! - [`run`](mod@run): a case end to end: histogram, expected counts and verdicts of a job
//!   ([`run::compare`]); shards of it and their merge.
//! - [`experiments`]: the stress suite and the accuracy-against-time sweep.
//! - [`check`]: judging a user's own WGSL sampler (`lobes check`).
//! - [`report`]: heat maps, plots, tables and output files.
//! - `cli`: the `lobes` command line (argument parsing, validation, printing), behind the
//!   default feature `cli` (clap, indicatif).
//! - [`embed`]: the WGSL samplers, densities and BRDFs for your own wgpu shaders, and helpers
//!   that upload discrete distributions.
//!
//! Features: `cli` (default) is the command line and everything; `check` is the library
//! without the command line (what a renderer's tests need for [`check`]); without either
//! (`default-features = false`) the crate is [`embed`] alone, with [`reference::discrete`]
//! for its tables, and depends on bytemuck and thiserror only (its texts are generated at build
//! time); features `naga`, `naga-oil`, `wgpu` and `wesl` add [`embed`]'s helpers on those
//! crates (docs/embedding.md lists the crate count of each).

#[cfg(feature = "check")]
pub mod atomic;
#[cfg(feature = "check")]
pub mod console;
#[cfg(feature = "check")]
pub mod folder_names;
#[cfg(feature = "check")]
pub mod suggest;
#[cfg(feature = "check")]
pub mod check;
#[cfg(feature = "cli")]
pub mod cli;
pub mod embed;
#[cfg_attr(not(feature = "check"), allow(dead_code))]
pub(crate) mod wgsl_tokens;
#[cfg(feature = "check")]
pub mod engine;
#[cfg(feature = "check")]
pub mod experiments;
#[cfg(feature = "check")]
pub mod reference;
#[cfg(feature = "check")]
pub mod report;
#[cfg(feature = "check")]
pub mod run;
#[cfg(feature = "check")]
pub mod scene;
#[cfg(feature = "check")]
pub mod stats;

/// What [`embed`] is made of, without the `check` feature: the discrete distributions.
#[cfg(not(feature = "check"))]
pub mod reference {
    pub mod discrete;
}
