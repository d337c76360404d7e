//! What `lobes check` found: the [`Report`] that `--json` prints and `--out` writes as
//! `report.json`, and the typed figures of each check. `docs/schema/check-report.schema.json`
//! is its JSON Schema ([`crate::report::schema`]).

use super::Domain;
use super::hard::HardRow;
use super::jacobian::JacobianCheck;
use super::quadrature::Integrals;
use crate::reference::Invalid;
use crate::stats::chi2::Chi2;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The version of the layout of [`Report`] (and of [`super::power::PowerSweep`]): 2 since a
/// report's `domain` may be a fitted cap (`{"kind": "cap", "axis", "height"}`); 3: `invalid` holds
/// the five reasons of [`Invalid::ALL`], shared with `lobes run`, `refracted_near_side` last); 4:
/// `domain` may be a lat-long map's texels (`{"kind": "latlong"}`); 5: or an octahedral
/// equal-area map's (`{"kind": "equal-area"}`).
pub const REPORT_VERSION: u32 = 5;

/// Invalid samples per reason, in the order of [`Invalid::ALL`] (a user's sampler never has a
/// `refracted_near_side`).
pub type InvalidCounts = [u64; Invalid::COUNT];

/// Everything a check of a user's sampler found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Report {
    /// [`REPORT_VERSION`].
    pub format_version: u32,
    /// Whether every check passed.
    pub passed: bool,
    pub checks: Vec<Check>,
    /// "sample/pdf in file.wgsl, …".
    pub sampler: String,
    pub domain: Domain,
    pub samples: u64,
    /// The histogram's grid: rows over cos θ (sphere) or y (plane), columns over φ or x.
    pub rows: u32,
    pub cols: u32,
    pub adapter: String,
    /// GPU time of every pass of the check, from timestamp queries (null where the adapter has
    /// none), and the wall time of the whole check.
    pub gpu_seconds: Option<f64>,
    pub wall_seconds: f64,
    /// Counts per bin (row-major), and per reason of [`Invalid::ALL`].
    pub counts: Vec<u64>,
    pub invalid: InvalidCounts,
    /// Expected counts per bin from the quadrature of the pdf: N ∫pdf, signed (below 0 in a bin
    /// where the pdf is negative, which `pdf_values` fails; the χ² counts those parts as 0).
    pub expected: Vec<f64>,
}

/// One check's verdict and figures; in JSON `{"name", "figures", "passed", "summary"}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Check {
    /// The check's name and its numbers.
    #[serde(flatten)]
    pub figures: Figures,
    pub passed: bool,
    /// One line a person reads.
    pub summary: String,
}

/// The reported pdf against the pdf function at the probe samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ConsistencyFigures {
    /// Valid probe samples compared.
    pub compared: u64,
    /// The largest |reported − pdf(d)| / max(reported, pdf(d)) where pdf(d) is finite.
    pub max_relative_difference: f64,
    /// Samples where pdf(d) is NaN or ∞ while the sampler reports a valid pdf (each fails).
    pub pdf_function_not_finite: u64,
    /// The u of the worst sample: the first whose pdf(d) is not finite, else the one whose
    /// difference is largest against its limit.
    pub worst_u: [f32; 4],
    /// The limit where the pdf is well conditioned ([`super::PDF_CONSISTENCY_LIMIT`]).
    pub limit: f64,
    /// The worst sample's limit: `limit` + [`super::CONDITIONING_ULPS`] × the pdf's f32
    /// conditioning at its d.
    #[serde(default)]
    pub worst_limit: f64,
    /// Samples beyond `limit` but within their widened limit, and beyond it (each fails).
    #[serde(default)]
    pub widened: u64,
    #[serde(default)]
    pub over_limit: u64,
    /// Of the `widened`, samples where pdf(d) is 0 and the support's edge lies within d's own
    /// rounding ([`super::CONDITIONING_ULPS`] ulps): the pdf's conditioning there is infinite.
    #[serde(default)]
    pub at_edge: u64,
}

/// The pdf function's values at the quadrature's nodes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PdfValuesFigures {
    /// Quadrature parts whose integral of the pdf came out NaN, ∞ or negative.
    pub bad_parts: u64,
    pub parts: u64,
    /// With bad parts: the worst value on a fine grid of the domain and where, e.g.
    /// "p(d) = NaN at d = (0.1, 0.2, 0.97) (θ 14.1°, φ 63.4°)" (text: NaN has no JSON number).
    pub worst: Option<String>,
}

/// ∫pdf over the domain against the valid fraction of the samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct NormalizationFigures {
    pub pdf_integral: f64,
    pub valid_fraction: f64,
    /// The quadrature's resolution of ∫pdf: its error estimate plus the f32 rounding of the sum.
    pub resolution: f64,
    pub tolerance: f64,
}

/// The χ² test with the pdf's total integral and the quadrature behind the expected counts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Chi2Figures {
    #[serde(flatten)]
    pub chi2: Chi2,
    /// Σ over bins of ∫ pdf: 1 for a pdf that is normalised over the domain.
    pub pdf_integral: f64,
    /// Invalid samples by reason (the order of [`Invalid::ALL`]), and the invalid cell's expectation.
    pub invalid: InvalidCounts,
    pub expected_invalid: f64,
    pub quadrature: Integrals,
    /// Column edges off the axes closer to the lobe than f32 binning places them
    /// ([`crate::check::quadrature::EDGE_RESOLUTION`]): the two bins beside each are one cell of
    /// the χ² (the counts and `expected` of the report stay per bin).
    #[serde(default)]
    pub joined_edges: u64,
    /// Row edges within [`crate::check::quadrature::EDGE_RESOLUTION`] in cos θ of the pdf's mass
    /// (a light's edge in the plane of a row edge, as on the surface's plane): judged likewise.
    #[serde(default)]
    pub joined_row_edges: u64,
}

impl Chi2Figures {
    /// Whether the χ² test passed (the check's verdict; `"passed"` in its JSON figures).
    pub fn passed(&self) -> bool {
        self.chi2.passed
    }
}

/// A count with its thousands apart, as the messages print it: 34 739.
pub fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// When the invalid cell holds most of the χ² statistic (or any count where none was expected):
/// "34 739 invalid samples where 33 were expected (zero_pdf 34 000, outside_domain 739)".
pub fn invalid_dominates(invalid: &InvalidCounts, expected: f64, statistic: f64) -> Option<String> {
    let observed: u64 = invalid.iter().sum();
    let o = observed as f64;
    let share = if expected > 0.0 { (o - expected).powi(2) / expected } else if observed > 0 { f64::INFINITY } else { 0.0 };
    // (a NaN share or statistic says nothing dominates)
    if observed == 0 || share.partial_cmp(&(0.5 * statistic)) != Some(std::cmp::Ordering::Greater) || o <= expected {
        return None;
    }
    let reasons: Vec<String> = Invalid::ALL.iter().zip(invalid).filter(|(_, n)| **n > 0).map(|(r, n)| format!("{} {}", r.name(), grouped(*n))).collect();
    Some(format!("{} invalid samples where {} were expected ({})", grouped(observed), grouped(expected.round() as u64), reasons.join(", ")))
}

/// For a p-value between the significance and 10 × it: the hint that one seed decides little,
/// naming the next seed by the setting's key (a scene's `seed`, the command line's `--seed`).
pub fn borderline(p: f64, significance: f64, seed: u64) -> Option<String> {
    (p >= significance && p < 10.0 * significance).then(|| format!("borderline (p within 10× the significance): run again with another seed, e.g. seed {}", seed + 1))
}

/// eval/pdf from the sampler against eval/pdf(d).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WeightFigures {
    pub max_weight_error: f64,
    pub limit: f64,
    /// The largest weight error over its allowance: `limit` + [`super::CONDITIONING_ULPS`] ×
    /// the pdf's f32 conditioning at the sample's d (the check passes at ≤ 1).
    #[serde(default)]
    pub max_over_allowance: f64,
}

/// The mean weight against the quadrature of eval.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct AlbedoFigures {
    pub mean_weight: f64,
    pub std_error: f64,
    pub quadrature: f64,
    /// The resolution of the quadrature of eval (relative as that of ∫pdf).
    pub quadrature_error: f64,
    /// The mean of |w − eval/pdf(d)| (0 for a sample beyond the weights' allowance: that error
    /// is the sampler's) plus the f32 rounding of the mean: the f32 error of the weights.
    #[serde(default)]
    pub weight_error: f64,
    /// |mean − ∫eval| not counted against the sampler: 2 × quadrature_error + weight_error; z
    /// is the rest over the standard error (0 within the allowance).
    #[serde(default)]
    pub allowance: f64,
    pub z: f64,
    pub p_value: f64,
    pub significance: f64,
}

/// A type of figures, to read one check's figures typed: `report.figures::<Chi2Figures>()`.
pub trait FiguresOf: Sized {
    fn of(figures: &Figures) -> Option<&Self>;
}

/// [`Figures`] with a variant per check, its name (in JSON and [`Figures::name`]) and the
/// [`FiguresOf`] impl of its type, from one list.
macro_rules! figures {
    ($($variant:ident($ty:ty) = $name:literal),* $(,)?) => {
        /// Each check's figures, named by the check (`"name"` in JSON, its figures under
        /// `"figures"`).
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
        #[serde(tag = "name", content = "figures")]
        pub enum Figures {
            $(#[serde(rename = $name)] $variant($ty),)*
        }

        impl Figures {
            /// The check's name, as in JSON.
            pub fn name(&self) -> &'static str {
                match self {
                    $(Figures::$variant(_) => $name,)*
                }
            }
        }

        $(impl FiguresOf for $ty {
            fn of(figures: &Figures) -> Option<&Self> {
                match figures {
                    Figures::$variant(f) => Some(f),
                    _ => None,
                }
            }
        })*
    };
}

figures!(
    PdfConsistency(ConsistencyFigures) = "pdf_consistency",
    Jacobian(JacobianCheck) = "jacobian",
    PdfValues(PdfValuesFigures) = "pdf_values",
    Normalization(NormalizationFigures) = "normalization",
    Chi2(Chi2Figures) = "chi2",
    Weights(WeightFigures) = "weights",
    Albedo(AlbedoFigures) = "albedo",
    HardCases(Vec<HardRow>) = "hard_cases",
);

impl Check {
    /// The check's name: `pdf_consistency`, `jacobian`, `pdf_values`, `normalization`, `chi2`,
    /// `weights`, `albedo` or `hard_cases`.
    pub fn name(&self) -> &'static str {
        self.figures.name()
    }
}

impl Report {
    /// The histogram's grid over the sampler's domain.
    pub fn grid(&self) -> crate::stats::domain::Grid {
        self.domain.grid(self.rows, self.cols)
    }

    /// The check called `name`.
    pub fn get(&self, name: &str) -> Option<&Check> {
        self.checks.iter().find(|c| c.name() == name)
    }

    /// The figures of the check of type `T`, e.g. `report.figures::<Chi2Figures>()`; `None`
    /// for a check that did not run (`weights` and `albedo` without an eval).
    pub fn figures<T: FiguresOf>(&self) -> Option<&T> {
        self.checks.iter().find_map(|c| T::of(&c.figures))
    }

    /// The names of the checks that failed.
    pub fn failed(&self) -> Vec<&'static str> {
        self.checks.iter().filter(|c| !c.passed).map(Check::name).collect()
    }

    /// Panics, naming every failed check and its summary, unless every check passed.
    pub fn assert_passed(&self) {
        self.assert_passed_with(None)
    }

    /// As [`Report::assert_passed`], naming where the outputs were written.
    pub fn assert_passed_with(&self, outputs: Option<&Path>) {
        if self.passed {
            return;
        }
        let failed: Vec<String> = self.checks.iter().filter(|c| !c.passed).map(|c| format!("  {}: {}", c.name(), c.summary)).collect();
        let out = outputs.map(|p| format!("\noutputs: {}", p.display())).unwrap_or_default();
        panic!("lobes check: {} failed {} of {} checks:\n{}{out}", self.sampler, failed.len(), self.checks.len(), failed.join("\n"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_grouped_by_thousands() {
        assert_eq!(grouped(0), "0");
        assert_eq!(grouped(999), "999");
        assert_eq!(grouped(34_739), "34 739");
        assert_eq!(grouped(1_234_567), "1 234 567");
    }

    /// The invalid cell is named when it holds most of χ², not when the bins do.
    #[test]
    fn a_dominating_invalid_cell_is_named() {
        let m = invalid_dominates(&[0, 739, 0, 34_000, 0], 33.0, 3.7e7).unwrap();
        assert_eq!(m, "34 739 invalid samples where 33 were expected (outside_domain 739, zero_pdf 34 000)");
        // (34 739 − 33)² / 33 ≈ 3.65e7: less than half of a statistic of 1e8
        assert!(invalid_dominates(&[0, 739, 0, 34_000, 0], 33.0, 1e8).is_none());
        assert!(invalid_dominates(&[0, 0, 0, 10, 0], 0.0, 5.0).is_some());
        assert!(invalid_dominates(&[0, 0, 0, 0, 0], 3.0, 5.0).is_none());
        // fewer than expected: the pdf allows more rejections than happen; not "invalid samples"
        assert!(invalid_dominates(&[0, 0, 0, 10, 0], 1000.0, 1000.0).is_none());
    }

    #[test]
    fn borderline_p_values_suggest_another_seed() {
        assert!(borderline(0.05, 0.01, 1).unwrap().ends_with("another seed, e.g. seed 2"));
        assert!(borderline(0.005, 0.01, 1).is_none() && borderline(0.1, 0.01, 1).is_none());
    }
}
