//! The detection table of `lobes tradeoff`: for a defect of size ε, the samples (and seconds)
//! each test needs to catch it at a given power. The defect is the family panel's azimuthal
//! turn with ε as a parameter (`turn.wgsl`; the panel's is ε = 0.005): GGX's visible normals
//! (α 0.3, θi 30°) turned about the normal by ε sin φ, a density off by about ε cos φ that the
//! pointwise 1 % does not see (the Jacobian's systematic test does, from ε ≈ 0.2 %).
//!
//! Power is estimated over seeds: at each doubling of N, `seeds` histograms of the turned
//! sampler (GPU, `lobes check`'s own passes, [`crate::check::histograms`]) are judged by the χ²
//! family ([`crate::stats::family::judge`]) against the expected counts of one whole check at
//! the largest count, and a test catches the defect at N where it rejects in at least
//! `power` of the seeds, at N and at every larger count measured. A test alone rejects where
//! its own p < α; the family where Holm's smallest p < α (the check's verdict). The statistical
//! power of a χ² test grows with N Σ p δ², so the count needed falls as 1/ε².

use crate::check::report::{Chi2Figures, NormalizationFigures};
use crate::check::{CheckError, Domain, Settings, Source, UserSampler, check, histograms};
use crate::engine::gpu::Gpu;
use crate::stats::family;
use crate::stats::median::median;
use serde::{Deserialize, Serialize};

/// The name of the family's row: the whole family under Holm's adjustment.
pub const FAMILY: &str = "family (Holm)";

/// What the detection table measures.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectionSettings {
    /// The turn's sizes ε, radians (0.005 is the panel's fixture).
    pub epsilons: Vec<f64>,
    /// Seeds per count (1, 2, …, seeds).
    pub seeds: u64,
    /// Counts 2^k, k = log2_min, log2_min + 1, … ≤ log2_max.
    pub log2_min: u32,
    pub log2_max: u32,
    /// The share of seeds that must reject (0.9: 90 % power).
    pub power: f64,
    pub significance: f64,
    /// The histogram grid (64 × 128, the default of `lobes check`).
    pub rows: u32,
    pub cols: u32,
}

impl Default for DetectionSettings {
    fn default() -> Self {
        Self { epsilons: vec![0.005, 0.01, 0.02], seeds: 10, log2_min: 16, log2_max: 27, power: 0.9, significance: 0.01, rows: 64, cols: 128 }
    }
}

/// One count of one ε: how many seeds each test rejected.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DetectionPoint {
    pub samples: u64,
    /// Per test, in [`DetectionEpsilon::tests`]' order: the seeds in which it rejected.
    pub rejected: Vec<u64>,
    /// The median wall time of one histogram of this count.
    pub histogram_seconds: f64,
}

/// From which count one test catches the defect of one ε.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Detected {
    /// [`FAMILY`], or a test of the family alone: "64 × 128" (the fine grid, the test before
    /// the family), "8 × 16", "cos θ", "φ".
    pub test: String,
    /// The smallest count at which it rejects in at least `power` of the seeds, there and at
    /// every larger count measured; null when it does not by the largest count.
    pub samples: Option<u64>,
    /// The predicted wall time of one whole `lobes check` at that count on this adapter
    /// (`fixed_seconds` + samples × `seconds_per_sample`).
    pub seconds: Option<f64>,
}

/// The table of one ε.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DetectionEpsilon {
    pub epsilon: f64,
    /// The pointwise checks (pdf_consistency, jacobian, …) and normalization of the whole check
    /// at the largest count: whether each passed (the defect is meant to be invisible to them).
    pub other_checks_passed: Vec<(String, bool)>,
    /// The count of that whole check, whose expected counts judge every histogram.
    pub checked_at: u64,
    /// The tests, [`FAMILY`] first, then the family's tests alone, fine grid first.
    pub tests: Vec<String>,
    pub points: Vec<DetectionPoint>,
    pub detected: Vec<Detected>,
}

/// The whole detection table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Detection {
    pub seeds: u64,
    pub power: f64,
    pub significance: f64,
    pub alpha: f64,
    pub incident_theta_deg: f64,
    pub rows: u32,
    pub cols: u32,
    /// The time model of a whole check on this adapter, from two whole checks of the turned
    /// sampler (2¹⁶ samples and the largest count): t(N) = fixed_seconds + N · seconds_per_sample.
    pub fixed_seconds: f64,
    pub seconds_per_sample: f64,
    pub epsilons: Vec<DetectionEpsilon>,
}

impl Detection {
    /// The count from which `test` catches the defect of size `epsilon`.
    pub fn samples(&self, epsilon: f64, test: &str) -> Option<u64> {
        let e = self.epsilons.iter().find(|e| e.epsilon == epsilon)?;
        e.detected.iter().find(|d| d.test == test)?.samples
    }
}

/// The turned GGX sampler (`turn.wgsl` over examples/samplers/ggx_vndf.wgsl).
pub fn turned() -> Result<UserSampler, CheckError> {
    let sources = vec![
        Source { name: "ggx_vndf.wgsl".into(), text: include_str!("../../../examples/samplers/ggx_vndf.wgsl").into() },
        Source { name: "turn.wgsl".into(), text: include_str!("turn.wgsl").into() },
    ];
    UserSampler::from_sources(sources, "turn_sample", "turn_pdf", None, Domain::Sphere)
}

/// GGX's α and the incidence of the table.
const ALPHA: f64 = 0.3;
const THETA_DEG: f64 = 30.0;

/// The smallest index from which `share ≥ power` holds at every later point.
fn from_index(shares: &[f64], power: f64) -> Option<usize> {
    let from = shares.iter().rposition(|&s| s < power).map_or(0, |i| i + 1);
    (from < shares.len()).then_some(from)
}

/// Measures the table on `gpu` (see the module's text).
pub fn detection(gpu: &Gpu, set: &DetectionSettings, log: &mut dyn FnMut(&str)) -> Result<Detection, CheckError> {
    let sampler = turned()?;
    let settings = |epsilon: f64, samples: u64| Settings {
        params: vec![ALPHA, ALPHA, epsilon],
        incident_theta: THETA_DEG,
        samples,
        bins: Some((set.rows, set.cols)),
        significance: set.significance,
        // the histograms below are counted on the sphere's grid (`histograms`)
        fit: crate::check::support::Fit::Never,
        ..Settings::default()
    };
    let counts: Vec<u64> = (set.log2_min..=set.log2_max).map(|k| 1u64 << k).collect();
    let (first, last) = (counts[0], *counts.last().expect("a count"));
    let grid = Domain::Sphere.grid(set.rows, set.cols);
    let family_tests: Vec<String> = family::tests(grid).into_iter().map(|t| t.name).collect();
    let tests: Vec<String> = std::iter::once(FAMILY.to_string()).chain(family_tests.iter().cloned()).collect();
    let bins = (set.rows * set.cols) as usize;
    let mut out = Detection {
        seeds: set.seeds,
        power: set.power,
        significance: set.significance,
        alpha: ALPHA,
        incident_theta_deg: THETA_DEG,
        rows: set.rows,
        cols: set.cols,
        ..Detection::default()
    };
    let mut times = (0.0, 0.0);
    for &epsilon in &set.epsilons {
        // the expected counts: one whole check at the largest count (its quadrature resolved for
        // that count, and so for every smaller one); its other checks' verdicts
        log(&format!("detection: ε {epsilon}: the whole check at {last} samples"));
        let whole = check(gpu, &sampler, &settings(epsilon, last))?;
        let small = check(gpu, &sampler, &settings(epsilon, first))?;
        times = (small.wall_seconds, whole.wall_seconds);
        let p: Vec<f64> = whole.expected.iter().map(|e| e / last as f64).collect();
        let norm = whole.figures::<NormalizationFigures>().expect("every check has normalization");
        let (pdf_total, resolution) = (whole.figures::<Chi2Figures>().expect("every check has chi2").pdf_integral, norm.resolution);
        let other_checks_passed = whole.checks.iter().filter(|c| c.name() != "chi2").map(|c| (c.name().to_string(), c.passed)).collect();
        let mut points: Vec<DetectionPoint> = Vec::new();
        for &n in &counts {
            let runs: Vec<(u64, u64)> = (1..=set.seeds).map(|seed| (n, seed)).collect();
            let hists = histograms(gpu, &sampler, &settings(epsilon, n), &runs)?;
            let mut rejected = vec![0u64; tests.len()];
            for (h, _) in &hists {
                let expected: Vec<f64> = p.iter().map(|q| q * n as f64).collect();
                // the invalid cell as the check expects it
                let invalid: u64 = h[bins..].iter().sum();
                let expected_invalid = crate::check::invalid_expectation(n, invalid, pdf_total, resolution);
                let verdict = family::judge(grid, (&h[..bins], &expected), (&[invalid], &[expected_invalid]), set.significance);
                rejected[0] += u64::from(!verdict.passed);
                for (k, t) in verdict.family.iter().enumerate() {
                    rejected[k + 1] += u64::from(t.dof > 0 && t.p_value < set.significance);
                }
            }
            let seconds: Vec<f64> = hists.iter().map(|(_, s)| *s).collect();
            let point = DetectionPoint { samples: n, rejected, histogram_seconds: median(seconds) };
            log(&format!("detection: ε {epsilon}, {n} samples: rejected in {:?} of {} seeds ({})", point.rejected, set.seeds, tests.join(", ")));
            points.push(point);
            // on until the family and the fine grid alone reject in every seed
            if points.last().is_some_and(|q| q.rejected[0] == set.seeds && q.rejected[1] == set.seeds) {
                break;
            }
        }
        out.epsilons.push(DetectionEpsilon { epsilon, other_checks_passed, checked_at: last, tests: tests.clone(), points, detected: Vec::new() });
    }
    // the time model of a whole check: the line through the two whole checks
    out.seconds_per_sample = ((times.1 - times.0) / (last - first) as f64).max(0.0);
    out.fixed_seconds = (times.0 - out.seconds_per_sample * first as f64).max(0.0);
    for e in &mut out.epsilons {
        e.detected = e
            .tests
            .iter()
            .enumerate()
            .map(|(k, test)| {
                let shares: Vec<f64> = e.points.iter().map(|q| q.rejected[k] as f64 / set.seeds as f64).collect();
                // a search stopped early: the counts not measured reject as the last one did
                let samples = from_index(&shares, set.power).map(|i| e.points[i].samples);
                Detected { test: test.clone(), samples, seconds: samples.map(|n| out.fixed_seconds + n as f64 * out.seconds_per_sample) }
            })
            .collect();
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_which_share_on() {
        assert_eq!(from_index(&[0.0, 0.95, 0.8, 0.9, 1.0], 0.9), Some(3));
        assert_eq!(from_index(&[1.0, 1.0], 0.9), Some(0));
        assert_eq!(from_index(&[1.0, 0.5], 0.9), None);
    }
}
