//! With an eval: `weights`, eval/pdf from the sampler against eval/pdf(d) at every sample, and
//! `albedo`, the mean weight against the quadrature of eval.

use super::{CHUNK, Measured, Run, normalization};
use crate::check::report::{self, AlbedoFigures, Check, Figures, WeightFigures};
use crate::check::{CONDITIONING_ULPS, CheckError};

/// The weights pass summed over every sample.
struct Sums {
    /// Σ w and Σ w².
    w: f64,
    w2: f64,
    /// The largest |w − eval/pdf(d)| / (eval/pdf(d)), and the largest against its allowance.
    max_error: f64,
    judged: f64,
    /// Σ |w − eval/pdf(d)| over the samples within their allowance.
    error: f64,
}

fn sums(run: &Run) -> Result<Sums, CheckError> {
    let mut s = Sums { w: 0.0, w2: 0.0, max_error: 0.0, judged: 0.0, error: 0.0 };
    let mut first = 0;
    while first < run.settings.samples {
        let n = CHUNK.min(run.settings.samples - first) as u32;
        for [v, e] in run.passes.weights(&run.params, first, n)? {
            s.w += v[0] as f64;
            s.w2 += v[1] as f64;
            s.max_error = s.max_error.max(v[2] as f64);
            s.error += e[0] as f64;
            s.judged = s.judged.max(e[1] as f64);
        }
        first += n as u64;
    }
    Ok(s)
}

/// `weights` and `albedo`.
pub(crate) fn check(run: &Run, m: &Measured) -> Result<[Check; 2], CheckError> {
    let s = sums(run)?;
    Ok([weights(run, &s), albedo(run, m, &s)])
}

fn weights(run: &Run, s: &Sums) -> Check {
    let limit = crate::stats::weighted::WEIGHT_ERROR_LIMIT as f64;
    let widened = if s.max_error > limit && s.judged <= 1.0 { " (beyond it only within the pdf's f32 conditioning there)" } else { "" };
    Check {
        passed: s.judged <= 1.0,
        summary: format!(
            "eval/pdf from the sampler and eval/{} differ by at most {:.2e} (limit {limit:.0e} + {CONDITIONING_ULPS} × the pdf's f32 conditioning){widened}",
            run.pdf(),
            s.max_error
        ),
        figures: Figures::Weights(WeightFigures { max_weight_error: s.max_error, limit, max_over_allowance: s.judged }),
    }
}

/// The mean weight against ∫eval. ∫eval is known to the quadrature's resolution, taken relative
/// as that of ∫pdf, twice as `normalization` allows; the mean weight is biased by the f32 error of
/// the weights, which the mean of |w − eval/pdf(d)| over the samples within the weights'
/// allowance measures (a larger error is the sampler's, and counts 0), and by its own f32 sums
/// (2·10⁻⁶).
fn albedo(run: &Run, m: &Measured, s: &Sums) -> Check {
    let (n, significance) = (run.samples(), run.settings.significance);
    let mean = s.w / n;
    let se = ((s.w2 / n - mean * mean).max(0.0) / n).sqrt();
    let quad: f64 = m.integrals.eval.iter().sum();
    let quad_err = normalization::resolution(m) / m.pdf_total().max(f64::MIN_POSITIVE) * quad.abs();
    let weight_err = s.error / n + 2e-6 * mean.abs();
    let allowance = 2.0 * quad_err + weight_err;
    let excess = ((mean - quad).abs() - allowance).max(0.0) * (mean - quad).signum();
    let z = if excess == 0.0 { 0.0 } else { excess / se.max(f64::MIN_POSITIVE) };
    let p = libm::erfc(z.abs() / std::f64::consts::SQRT_2);
    let borderline = report::borderline(p, significance, run.settings.seed).map_or(String::new(), |m| format!("; {m}"));
    let figures = AlbedoFigures { mean_weight: mean, std_error: se, quadrature: quad, quadrature_error: quad_err, weight_error: weight_err, allowance, z, p_value: p, significance };
    Check {
        passed: p >= significance,
        summary: format!("mean weight {mean:.6} ± {se:.1e} against ∫eval = {quad:.6} (f32 allowance {allowance:.1e}: quadrature, weights): z = {z:.2}, p = {p:.3e}{borderline}"),
        figures: Figures::Albedo(figures),
    }
}
