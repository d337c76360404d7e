//! # lobes
//!
//! GPU importance sampling of reflectance lobes (Ward, Beckmann, GGX) and discrete
//! distributions: WGSL compute kernels draw and histogram millions of samples, and an f64
//! CPU reference judges the histograms with a χ² test.
//!
//! - [`reference`]: the f64 math, one module per lobe, each the twin of a WGSL file in
//!   `shaders/`.
//! - [`cli`]: the `lobes` command line (argument parsing, validation, subcommands).

pub mod cli;
pub mod reference;
pub mod report;
