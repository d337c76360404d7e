//! `normalization`: ∫pdf over the domain is the probability of a valid sample, which the
//! histogram measures as the valid fraction f (standard error √(f(1 − f)/N)). A pdf off by a
//! constant factor shows here at any sample count.

use super::{Measured, Run};
use crate::check::report::{Check, Figures, NormalizationFigures};
use crate::check::invalid_expectation;

pub(crate) fn check(run: &Run, m: &Measured) -> Check {
    let (n, total) = (run.samples(), m.pdf_total());
    let resolution = resolution(m);
    let valid = 1.0 - m.invalid(run.bins()).iter().sum::<u64>() as f64 / n;
    let tolerance = 2.0 * resolution + 4.0 * (valid * (1.0 - valid) / n).sqrt();
    let figures = NormalizationFigures { pdf_integral: total, valid_fraction: valid, resolution, tolerance };
    Check {
        passed: (total - valid).abs() <= tolerance,
        summary: format!("∫{} over the domain = {total:.6} against the valid fraction {valid:.6} of the samples (tolerance {tolerance:.1e})", run.pdf()),
        figures: Figures::Normalization(figures),
    }
}

/// How well ∫pdf is known: no better than the quadrature of it (its error estimate and the f32
/// rounding of the sum), and no better than the f32 pdf moves it: [`Measured::f32_moved`], how far
/// ∫pdf moves on the same parts when the pdf's inputs move by an ulp. Not CONDITIONING_ULPS ×
/// the pdf's mean conditioning: that bounds each node's error at its worst, while the integral
/// sums the errors with their signs (a Phong lobe at n = 1000: 5·10⁻⁴ bounded, 10⁻⁴ moved, and a
/// pdf normalised with (n + 2)/2π, 10⁻³ too large, passed within the bound).
pub(crate) fn resolution(m: &Measured) -> f64 {
    m.integrals.error_estimate + 2e-6 * m.pdf_total() + m.f32_moved
}

/// The invalid cell's expected count: the mass the pdf leaves to invalid samples, 1 − ∫pdf, known
/// to [`resolution`] ([`invalid_expectation`]).
pub(crate) fn expected_invalid(run: &Run, m: &Measured) -> f64 {
    invalid_expectation(run.settings.samples, m.invalid(run.bins()).iter().sum(), m.pdf_total(), resolution(m))
}
