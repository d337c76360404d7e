//! # lobes
//!
//! GPU importance sampling of reflectance lobes (Ward, Beckmann, GGX) and discrete
//! distributions: WGSL compute kernels draw and histogram millions of samples, and an f64
//! CPU reference judges the histograms with a χ² test.
//!
//! - [`reference`](mod@reference): the f64 math, one module per lobe, each the twin of a WGSL file in
//!   `shaders/`.
//! - [`gpu`]: the GPU engine: WGSL composed from `shaders/`, run through wgpu.
//! - [`cpu`]: the same samples drawn in f64 on all cores.
//! - [`stats`]: binning, expected counts by quadrature, the χ² test.
//! - [`cli`]: the `lobes` command line (argument parsing, validation, subcommands).
//! - [`embed`]: the WGSL samplers, densities and BRDFs for your own wgpu shaders, and helpers
//!   that upload discrete distributions.

pub mod cli;
pub mod cpu;
pub mod embed;
pub mod gpu;
pub mod job;
pub mod reference;
pub mod report;
pub mod run;
pub mod scene;
pub mod stats;
pub mod stress;
pub mod tradeoff;
