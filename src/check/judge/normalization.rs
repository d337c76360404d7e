//! `normalization`: ∫pdf over the domain is the probability of a valid sample, which the
//! histogram measures as the valid fraction f (standard error √(f(1 − f)/N)). A pdf off by a
//! constant factor shows here at any sample count.

use super::{Measured, Run};
use crate::check::report::{Check, Figures, NormalizationFigures};
use crate::check::{Message, Setting};

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

/// How many standard deviations of the valid count, √N, the pdf's f32 evaluation may move the
/// expected count, N × [`Measured::f32_moved`], before a failing `chi2` decides nothing: one, as
/// a shift of s standard deviations spread over the cells adds up to s² to the χ² statistic of
/// the coarsest grids, where it then weighs as much as a cell's own noise.
pub const F32_MOVED_SIGMA: f64 = 1.0;

/// `Err` with what is wrong where `chi2` failed while the pdf's f32 evaluation alone moves ∫pdf
/// by more than [`F32_MOVED_SIGMA`] standard deviations of the count: the χ² compares counts with
/// the integral of the f32 pdf as it is, and cannot tell its rounding from a defect. A spherical
/// triangle of 10⁻⁷ sr (0.02 × 10⁻⁵ rad), 10⁻⁵ rad wide where f32 places a direction to 6·10⁻⁸,
/// failed `chi2` at 2 of 3 seeds of 2¹⁶ samples with ∫pdf 1.0129, its f32 evaluation moving ∫pdf
/// by about 10⁻² (normalization passing within that; the Jacobian unresolved in f32 at 4083 of
/// 4096 samples).
pub(crate) fn rounding_resolved(run: &Run, m: &Measured, chi2_passed: bool) -> Result<(), Message> {
    let n = run.samples();
    if chi2_passed || n * m.f32_moved <= F32_MOVED_SIGMA * n.sqrt() {
        return Ok(());
    }
    let what = format!(
        "the pdf's f32 evaluation alone moves ∫pdf by {:.1e} (its inputs an ulp off), more than {F32_MOVED_SIGMA} × the count's standard deviation at {n} samples ({:.1e} of ∫pdf): chi2 fails, but cannot tell that rounding from a defect, and the checks that read no integral pass, so no verdict is drawn; evaluate the pdf in a stabler form, or fewer ",
        m.f32_moved,
        F32_MOVED_SIGMA / n.sqrt()
    );
    Err(Message::text(what).setting(Setting::Samples))
}

/// The invalid cell's expected count, for `invalid` of N = `samples` samples where the pdf
/// integrates to `pdf_total` over the domain, known to `resolution`: N × the observed invalid
/// fraction clamped into 1 − ∫pdf ± 2 × resolution, the value within that band closest to what
/// was observed, so that neither a rejection the pdf allows nor the quadrature's own error reads
/// as a sampler's fault (a rejection rate under the band is below what the test can see, even
/// where the pdf integrates to more than 1). Twice the resolution, as `normalization`'s
/// tolerance: the error estimate is the coarse rule's, and across a jump of the pdf the accepted
/// finer value is off by as much (a uniform cone of half-angle 0.3 rad about the normal: ∫pdf
/// 0.999830 with an error estimate of 1.65·10⁻⁴; within 1× the cell expected 12 samples where
/// none can be, a false fail at 2 of 3 seeds).
///
/// ```
/// // a pdf that integrates to 0.9998 known to 10⁻⁴ leaves 2·10⁻⁴ ± 2·10⁻⁴ to rejections:
/// // 0 or 300 rejected of 10⁶ both read as allowed
/// assert_eq!(lobes::check::invalid_expectation(1_000_000, 0, 0.9998, 1e-4), 0.0);
/// assert!((lobes::check::invalid_expectation(1_000_000, 300, 0.9998, 1e-4) - 300.0).abs() < 1e-6);
/// // 2 000 rejected is beyond 4·10⁻⁴: the cell expects 400
/// assert!((lobes::check::invalid_expectation(1_000_000, 2_000, 0.9998, 1e-4) - 400.0).abs() < 1e-6);
/// ```
pub fn invalid_expectation(samples: u64, invalid: u64, pdf_total: f64, resolution: f64) -> f64 {
    let n = samples.max(1) as f64;
    let (missing, band) = (1.0 - pdf_total, 2.0 * resolution);
    n * (invalid as f64 / n).clamp((missing - band).max(0.0), (missing + band).max(band))
}
