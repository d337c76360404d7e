//! Judging a histogram: the expected count of every cell (bins and invalid reasons), the χ²
//! test over them, and the per-sample angular check of GPU directions against f64.

use crate::engine::job::{Counts, Job};
use crate::reference::Invalid;
use crate::stats::chi2::{self, Chi2};
use crate::stats::expected::{self, Expected, Quadrature};
use glam::DVec3;
use serde::Serialize;

/// Expected counts of a run of `samples` samples.
#[derive(Debug, Clone)]
pub struct ExpectedCounts {
    pub bins: Vec<f64>,
    /// Indexed like [`Invalid::ALL`]: only "below horizon" has a nonzero expectation.
    pub invalid: [f64; 4],
    /// The quadrature's accuracy (lobes).
    pub quadrature: Option<Expected>,
}

/// N × (the pdf integrated over each bin), N × pmf for a discrete job.
pub fn expected_counts(job: &Job, samples: u64, q: &Quadrature) -> ExpectedCounts {
    let n = samples as f64;
    match job {
        Job::Lobe { lobe, incident, grid } => {
            let e = expected::lobe_probabilities(lobe, *incident, *grid, q);
            let mut invalid = [0.0; 4];
            invalid[Invalid::BelowHorizon.code() as usize - 1] = n * e.below_horizon;
            ExpectedCounts { bins: e.probabilities.iter().map(|p| n * p).collect(), invalid, quadrature: Some(e) }
        }
        Job::Discrete { dist, .. } => {
            ExpectedCounts { bins: dist.pmf().iter().map(|p| n * p).collect(), invalid: [0.0; 4], quadrature: None }
        }
    }
}

/// Pearson's χ² over all cells, bins and invalid reasons alike: a sampler that puts mass below
/// the horizon at the wrong rate fails like one that puts it in the wrong bin.
pub fn chi2_test(counts: &Counts, expected: &ExpectedCounts, significance: f64) -> Chi2 {
    let observed: Vec<u64> = counts.bins.iter().chain(&counts.invalid).copied().collect();
    let exp: Vec<f64> = expected.bins.iter().chain(&expected.invalid).copied().collect();
    chi2::test(&observed, &exp, significance)
}

/// GPU directions against the f64 reference, sample by sample: `lobes run`'s per-sample check
/// and `lobes tradeoff`'s angle per precision.
#[derive(Debug, Clone, Default, PartialEq, Serialize, serde::Deserialize, schemars::JsonSchema)]
pub struct AngleCheck {
    /// Samples compared (valid on both sides).
    pub compared: u64,
    /// Samples valid on one side only.
    pub validity_mismatches: u64,
    pub max_angle_rad: f64,
    pub mean_angle_rad: f64,
}

impl AngleCheck {
    /// Summarises (GPU direction, f64 direction) pairs, each `None` where that side flagged the
    /// sample invalid. The GPU direction is normalised first; the reference's is a unit vector.
    ///
    /// ```
    /// use glam::DVec3;
    /// use lobes::stats::compare::AngleCheck;
    /// let tilted = DVec3::new(1e-3, 0.0, 1.0); // 1e-3 rad (to 3e-7) off the normal
    /// let a = AngleCheck::from_pairs([(Some(tilted), Some(DVec3::Z)), (None, None), (Some(DVec3::Z), None)]);
    /// assert_eq!((a.compared, a.validity_mismatches), (1, 1));
    /// assert!((a.max_angle_rad - 1e-3).abs() < 1e-9 && a.mean_angle_rad == a.max_angle_rad);
    /// ```
    pub fn from_pairs(pairs: impl IntoIterator<Item = (Option<DVec3>, Option<DVec3>)>) -> Self {
        let mut out = AngleCheck::default();
        let mut sum = 0.0;
        for pair in pairs {
            match pair {
                (Some(gpu), Some(reference)) => {
                    let a = angle_between(gpu.normalize(), reference);
                    out.compared += 1;
                    sum += a;
                    out.max_angle_rad = out.max_angle_rad.max(a);
                }
                (None, None) => {}
                _ => out.validity_mismatches += 1,
            }
        }
        out.mean_angle_rad = if out.compared > 0 { sum / out.compared as f64 } else { 0.0 };
        out
    }
}

/// The angle between two unit vectors, atan2(|a × b|, a · b) (accurate at small angles).
pub fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Compares the GPU's directions of samples `first ..` (each `[x, y, z, reason]`) with f64.
pub fn angle_check(job: &Job, seed: u64, first: u64, gpu: &[[f32; 4]]) -> AngleCheck {
    let Job::Lobe { lobe, incident, .. } = job else { return AngleCheck::default() };
    AngleCheck::from_pairs(gpu.iter().enumerate().map(|(k, g)| {
        let u = crate::reference::rng::uniforms(seed, first + k as u64);
        let s = lobe.sample(*incident, [u[0], u[1]]);
        let gpu = (g[3] == 0.0).then(|| DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64));
        (gpu, s.invalid.is_none().then_some(s.omega_r))
    }))
}
