//! `pdf_consistency`: the pdf the sampler reports against the pdf function at the same d, at
//! the valid probes, each within [`PDF_CONSISTENCY_LIMIT`] widened by [`CONDITIONING_ULPS`] ×
//! the pdf's f32 conditioning there.

use super::{Measured, Run};
use crate::check::report::{Check, ConsistencyFigures, Figures};
use crate::check::conventions::Measure;
use crate::check::CONDITIONING_ULPS;

/// Largest relative difference allowed between the reported pdf and the pdf function (f32
/// evaluation of the same formula in two places: agreement to a few ulps is expected, 10⁻³
/// leaves room for a differently-ordered but equivalent expression), where the pdf is well
/// conditioned; see [`CONDITIONING_ULPS`].
pub const PDF_CONSISTENCY_LIMIT: f64 = 1e-3;

pub(crate) fn check(run: &Run, m: &Measured) -> Check {
    let c = figures(m);
    let passed = c.over_limit == 0 && c.pdf_function_not_finite == 0;
    let mut summary = summary(&c, &run.pdf());
    if !passed && run.sampler.conventions.measure == Measure::Area {
        summary += AREA_HINT;
    }
    Check { passed, summary, figures: Figures::PdfConsistency(c) }
}

/// What a light sampled by area most often gets wrong, said where the densities disagree.
const AREA_HINT: &str = "; with the area measure, lobes turns the sample's density per unit area into one per solid angle, pdf_A·|p|²/|n·d| (pbrt-v4 eq. 4.9): the pdf function must be per solid angle too (one left per unit area, or converted without |n·d|, is the classic MIS bug)";

fn figures(m: &Measured) -> ConsistencyFigures {
    let mut c = ConsistencyFigures {
        compared: 0,
        max_relative_difference: 0.0,
        pdf_function_not_finite: 0,
        worst_u: [0.0; 4],
        limit: PDF_CONSISTENCY_LIMIT,
        worst_limit: PDF_CONSISTENCY_LIMIT,
        widened: 0,
        over_limit: 0,
        at_edge: 0,
    };
    let mut worst = 0.0;
    for ((p, u), k) in m.probes.iter().zip(&m.probe_u).zip(&m.kappa).filter(|((p, _), _)| p.valid()) {
        let (rep, fun) = (p.reported_pdf() as f64, p.pdf as f64);
        c.compared += 1;
        if !fun.is_finite() {
            // the worst of all: the first such sample is the one shown
            if c.pdf_function_not_finite == 0 {
                c.worst_u = *u;
            }
            c.pdf_function_not_finite += 1;
            continue;
        }
        let diff = (rep - fun).abs() / rep.max(fun);
        let limit = PDF_CONSISTENCY_LIMIT + CONDITIONING_ULPS * k;
        c.max_relative_difference = c.max_relative_difference.max(diff);
        c.widened += u64::from(diff > PDF_CONSISTENCY_LIMIT && diff <= limit);
        c.at_edge += u64::from(fun == 0.0 && diff <= limit);
        c.over_limit += u64::from(diff > limit);
        if diff / limit > worst {
            worst = diff / limit;
            c.worst_limit = limit;
            if c.pdf_function_not_finite == 0 {
                c.worst_u = *u;
            }
        }
    }
    c
}

/// What the summary says of samples on the support's edge: where `pdf(d)` is 0 and a move of d
/// within its rounding gives a pdf > 0.
fn at_edge(n: u64) -> String {
    match n {
        0 => String::new(),
        n => format!(" ({n} where the pdf function says 0 with its support's edge within the sample's f32 rounding)"),
    }
}

fn summary(c: &ConsistencyFigures, pdf: &str) -> String {
    let not_finite = match c.pdf_function_not_finite {
        0 => String::new(),
        k => format!("; {pdf} NaN or ∞ at {k} of them"),
    };
    let widened = match (c.widened, c.over_limit) {
        (0, 0) => String::new(),
        (w, 0) => format!("; {w} beyond {PDF_CONSISTENCY_LIMIT:.0e} but within the pdf's f32 conditioning there{}", at_edge(c.at_edge)),
        (_, o) => format!("; {o} beyond the limit widened by the pdf's f32 conditioning (worst: {:.2e} allowed there)", c.worst_limit),
    };
    format!(
        "the pdf the sampler reports and {pdf} differ by at most {:.2e} (limit {PDF_CONSISTENCY_LIMIT:.0e} + {CONDITIONING_ULPS} × the pdf's f32 conditioning) over {} samples{widened}{not_finite}",
        c.max_relative_difference, c.compared
    )
}
