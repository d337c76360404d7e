//! # lobes
//!
//! GPU importance sampling of reflectance lobes (Ward, Beckmann, GGX) and discrete
//! distributions: WGSL compute kernels draw and histogram millions of samples, and an f64
//! CPU reference judges the histograms with a χ² test.
//!
//! The folders are the layers, from the math up; each imports only layers listed before it
//! (`tests/layout.rs` checks that no two import each other):
//!
//! - [`atomic`]: the one way lobes writes a file (the outputs, and the GPU engine's pipeline
//!   cache).
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

pub mod atomic;
pub mod check;
#[cfg(feature = "cli")]
pub mod cli;
pub mod embed;
pub mod engine;
pub mod experiments;
pub mod reference;
pub mod report;
pub mod run;
pub mod scene;
pub mod stats;
