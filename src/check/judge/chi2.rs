//! `chi2`: the GPU histogram of the samples against N × ∫pdf per bin, over the multi-resolution
//! family of grids and marginals ([`crate::stats::family`]), with the invalid samples as one more
//! cell that expects 1 − ∫pdf ([`super::normalization::expected_invalid`]).

use super::{Measured, Run, normalization};
use crate::check::quadrature;
use crate::check::report::{self, Check, Chi2Figures, Figures};
use crate::check::CheckError;
use crate::stats::chi2::Chi2;
use crate::stats::family;

pub(crate) fn check(run: &Run, m: &Measured) -> Result<Check, CheckError> {
    let (counts, expected, joined) = judged_cells(run, m)?;
    let grid = run.grid();
    let invalid = m.invalid(run.bins());
    let expected_invalid = normalization::expected_invalid(run, m);
    let chi2 = family::judge(grid, (&counts, &expected), (&[invalid.iter().sum()], &[expected_invalid]), run.settings.significance);
    let summary = summary(run, m, &chi2, expected_invalid, joined);
    let passed = chi2.passed;
    let figures = Chi2Figures { chi2, pdf_integral: m.pdf_total(), invalid, expected_invalid, quadrature: m.integrals.clone(), joined_edges: joined.columns as u64, joined_row_edges: joined.rows as u64 };
    Ok(Check { passed, summary, figures: Figures::Chi2(figures) })
}

/// The expected counts per bin, N × ∫pdf (the parts where the pdf is bad count 0).
pub(crate) fn expected(run: &Run, m: &Measured) -> Vec<f64> {
    m.integrals.probabilities.iter().map(|p| run.samples() * p).collect()
}

/// The cells the χ² judges: the bins, but where a column edge off the axes or a row edge lies
/// closer to the pdf's mass than f32 places samples and bins, the two bins beside it as one cell.
fn judged_cells(run: &Run, m: &Measured) -> Result<(Vec<u64>, Vec<f64>, quadrature::Joined), CheckError> {
    let (counts, expected) = (m.counts(run.bins()), expected(run, m));
    if !run.sampler.domain.rounds_phi_edges() {
        return Ok((counts.to_vec(), expected, quadrature::Joined::default()));
    }
    let (rows, cols, samples) = (run.rows, run.cols, run.settings.samples);
    let strips = run.with_integrand(|f| quadrature::edge_strips(f, rows, cols, m.width, samples, &m.integrals.probabilities))?;
    Ok(quadrature::join_unresolved_edges(counts, &expected, &strips, rows, cols, samples))
}

fn summary(run: &Run, m: &Measured, chi2: &Chi2, expected_invalid: f64, joined: quadrature::Joined) -> String {
    let (significance, seed) = (run.settings.significance, run.settings.seed);
    let family_p = chi2.family_p_value.unwrap_or(chi2.p_value);
    let invalid = m.invalid(run.bins());
    let joined = match (joined.columns, joined.rows) {
        (0, 0) => String::new(),
        (c, r) => format!(
            "; {c} column edges off the axes and {r} row edges lie closer to the pdf's mass than f32 places samples and bins (±{:.0e}): the bins beside each judged as one",
            quadrature::EDGE_RESOLUTION
        ),
    };
    format!(
        "{}{}χ² = {:.1} on {} dof, p = {:.3e}; over {} grids and marginals (Holm) p = {:.3e} (significance {significance}){}{}; ∫pdf = {:.6}; {} samples in cells of zero probability; quadrature error ≤ {:.2}σ{joined}",
        chi2.untested.map_or(String::new(), |u| format!("{}; ", u.describe())),
        family::caught(chi2).map_or(String::new(), |c| format!("{c}; ")),
        chi2.statistic,
        chi2.dof,
        chi2.p_value,
        chi2.family.len(),
        family_p,
        report::invalid_dominates(&invalid, expected_invalid, chi2.statistic).map_or(String::new(), |m| format!("; {m}")),
        report::borderline(family_p, significance, seed).map_or(String::new(), |m| format!("; {m}")),
        m.pdf_total(),
        chi2.in_impossible_cells,
        m.integrals.max_error_sigma,
    )
}
