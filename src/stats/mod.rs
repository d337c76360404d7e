//! Statistics: binning, expected counts by quadrature, and the χ² test.

pub mod chi2;
pub mod compare;
pub mod expected;
pub mod histogram;
pub mod weighted;
