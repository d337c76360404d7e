//! Statistics: domains and their grids, binning, Gauss–Legendre quadrature and the adaptive
//! quadrature of expected histograms, expected counts, and the χ² test and its family over
//! resolutions.

pub mod chi2;
pub mod domain;
pub mod equal_area;
pub mod expected;
pub mod family;
pub mod gauss_legendre;
pub mod histogram;
pub mod median;
pub mod quadrature;
pub mod weighted;
