//! Judging a job's histogram: the expected count of every cell (bins and invalid reasons), the
//! χ² test over them, the per-sample angular check of GPU directions against f64, and the albedo
//! check of a weighted histogram. (Here, above the engine, because they take its [`Job`]; the
//! statistics they use, in [`crate::stats`], know nothing of jobs.)

use crate::engine::job::{Counts, Job, Scatter};
use crate::reference::dielectric::{RoughDielectric, refract};
use crate::reference::Invalid;
use crate::reference::effects::Effects;
use crate::stats::chi2::Chi2;
use crate::stats::domain::Domain;
use crate::stats::family::{self, Grid};
use crate::stats::expected::{self, Expected, Quadrature};
use crate::stats::quadrature::Peak;
use crate::stats::weighted::{AlbedoCheck, AlbedoTest, WEIGHT_ERROR_LIMIT, WeightedSums, two_sided};
use glam::DVec3;
use serde::Serialize;

/// Expected counts of a run of `samples` samples.
#[derive(Debug, Clone)]
pub struct ExpectedCounts {
    pub bins: Vec<f64>,
    /// Indexed like [`Invalid::ALL`]: only "below horizon" (and a dielectric's
    /// "refracted near side") has a nonzero expectation.
    pub invalid: [f64; Invalid::COUNT],
    /// The quadrature's accuracy (lobes).
    pub quadrature: Option<Expected>,
    /// The grid the bins lie on, for the family of tests ([`family::judge`]): a lobe's sphere
    /// grid, a discrete table's 1 × entries.
    pub grid: Grid,
}

/// The grid of a job's bins: a lobe's rows over cos θ and columns over φ, a discrete
/// distribution's entries in one row.
pub fn grid(job: &Job) -> Grid {
    match job {
        Job::Lobe { grid, .. } => Domain::Sphere.grid(grid.rows, grid.cols),
        // entry i is the cell [i, i + 1] × [0, 1] of one row
        Job::Discrete { dist, .. } => Domain::Plane { bounds: [0.0, 0.0, dist.len() as f64, 1.0] }.grid(1, dist.len() as u32),
    }
}

/// N × (the pdf integrated over each bin), N × pmf for a discrete job; the quadrature's
/// tolerance is `q`'s at N ([`Quadrature::for_samples`]).
pub fn expected_counts(job: &Job, samples: u64, q: &Quadrature) -> ExpectedCounts {
    let n = samples as f64;
    let q = &q.for_samples(samples);
    match job {
        Job::Lobe { lobe, incident, grid, scatter: Scatter::Dielectric { eta } } => {
            let glass = RoughDielectric::new(*lobe, *eta).expect("a dielectric job is checked when made");
            dielectric_expected(&glass, *incident, *grid, n, q)
        }
        Job::Lobe { lobe, incident, grid, .. } => {
            let e = expected::lobe_probabilities(lobe, *incident, *grid, q);
            let mut invalid = [0.0; Invalid::COUNT];
            invalid[Invalid::OutsideDomain.code() as usize - 1] = n * e.below_horizon;
            ExpectedCounts { bins: e.probabilities.iter().map(|p| n * p).collect(), invalid, quadrature: Some(e), grid: Domain::Sphere.grid(grid.rows, grid.cols) }
        }
        Job::Discrete { dist, .. } => {
            ExpectedCounts { bins: dist.pmf().iter().map(|p| n * p).collect(), invalid: [0.0; Invalid::COUNT], quadrature: None, grid: grid(job) }
        }
    }
}

pub use crate::stats::expected::MAX_QUADRATURE_SIGMA;

/// Whether the expected counts of a run of `samples` samples are accurate enough to judge by:
/// `Err` with what is wrong where the quadrature has not converged, so that no verdict is drawn
/// from them (`lobes run` and `lobes merge` report the case as an error, exit 3).
///
/// ```
/// use lobes::{engine::job::{Job, Scatter}, reference::{Lobe, LobeKind, Method, reflect::spherical}};
/// use lobes::{run::compare::{expected_counts, converged}, stats::{expected::Quadrature, histogram::SphereGrid}};
/// let lobe = Lobe { kind: LobeKind::Ward, method: Method::Ndf, alpha_x: 0.05, alpha_y: 0.05, alpha_angle: 0.0 };
/// let job = Job::Lobe { lobe, incident: spherical(0.5, 0.0), grid: SphereGrid { rows: 16, cols: 32 }, scatter: Scatter::Reflect };
/// assert!(converged(&expected_counts(&job, 1_000_000, &Quadrature::default()), 1_000_000).is_ok());
/// // one 5 × 5 rule and its quarters per bin cannot resolve a lobe of α 0.05 in bins of 0.2 rad
/// let coarse = Quadrature { max_depth: 0, max_initial_split: 1, ..Quadrature::default() };
/// // at 10¹² samples, where a count's σ is 10⁻⁶ of it
/// let n = 1_000_000_000_000;
/// assert!(converged(&expected_counts(&job, n, &coarse), n).is_err());
/// ```
pub fn converged(expected: &ExpectedCounts, samples: u64) -> Result<(), String> {
    let Some(q) = &expected.quadrature else { return Ok(()) };
    let sigma = q.max_error_sigma_at(samples);
    if sigma <= MAX_QUADRATURE_SIGMA {
        return Ok(());
    }
    Err(format!(
        "the f64 reference's quadrature did not converge: a bin's error estimate is {sigma:.3}σ of its count at {samples} samples (at most {MAX_QUADRATURE_SIGMA}σ gives a verdict; {} parts accepted at the depth limit), so no verdict is drawn",
        q.unconverged_parts
    ))
}

/// The narrowest feature of a rough dielectric's density and BSDF, for the quadrature's initial
/// split: light leaving from inside near grazing is confined to a band far narrower than α (at
/// θi = 95°, GGX α 0.5, η 1.5: 0.126 < cos θo < 0.131), which the split follows.
fn dielectric_width(glass: &RoughDielectric, wi: DVec3) -> f64 {
    let alpha = glass.lobe.alpha_x.min(glass.lobe.alpha_y).min(1.0);
    if wi.z.abs() < 0.2 { alpha.min(0.02) } else { 0.6 * alpha }
}

/// A rough dielectric's two peaks seen from `wi`, where h = n: the mirror direction, as wide as
/// the lobe's narrowest α, and the refracted one (but under total internal reflection), where a
/// tilt δ of h turns ωt by |1 − 1/η| δ at normal incidence (Snell's law to first order).
fn dielectric_peaks(glass: &RoughDielectric, wi: DVec3) -> Vec<Peak> {
    let reflected = expected::lobe_peak(&glass.lobe, wi);
    let (upper, eta) = glass.upper_side(wi);
    let side = if wi.z < 0.0 { -1.0 } else { 1.0 };
    let transmitted = refract(upper, DVec3::Z, eta).map(|t| Peak { direction: DVec3::new(t.x, t.y, side * t.z), width: reflected.width * (1.0 - 1.0 / eta).abs().min(1.0) });
    std::iter::once(reflected).chain(transmitted).collect()
}

/// A rough dielectric's expected counts: the bins from its density over the whole sphere, the
/// samples on the wrong side of their event by reason from their densities over h
/// ([`RoughDielectric::wrong_side_h`]), two integrals independent of the bins' (together they
/// make the sphere's 1 − Σ, to the quadratures' accuracy).
fn dielectric_expected(glass: &RoughDielectric, wi: DVec3, grid: crate::stats::histogram::SphereGrid, n: f64, q: &Quadrature) -> ExpectedCounts {
    let e = expected::peaked_sphere_probabilities(&|wo| glass.pdf(wi, wo), grid, dielectric_width(glass, wi), &dielectric_peaks(glass, wi), q);
    // The wrong-side sets are slivers of h space bounded by the refraction's and reflection's
    // horizons (indicator edges, not smooth peaks), integrated with those edges as breakpoints.
    // A 2-D rule over the bins' (cos θh, φh) cells missed a band of them near the pole: from
    // inside at θi 125°, η 1.33, refracted_near_side came out at 91 % of its count.
    let (below, near) = expected::dielectric_wrong_side(glass, wi, q);
    let mut invalid = [0.0; Invalid::COUNT];
    invalid[Invalid::OutsideDomain.code() as usize - 1] = n * below;
    invalid[Invalid::RefractedNearSide.code() as usize - 1] = n * near;
    ExpectedCounts { bins: e.probabilities.iter().map(|p| n * p).collect(), invalid, quadrature: Some(e), grid: Domain::Sphere.grid(grid.rows, grid.cols) }
}

/// Pearson's χ² over all cells, bins and invalid reasons alike: a sampler that puts mass below
/// the horizon at the wrong rate fails like one that puts it in the wrong bin; on the fine grid,
/// its aggregations and marginals, Holm-corrected ([`family::judge`], as `lobes check` judges).
/// ([`crate::stats::chi2::judge`]: no valid sample, or a single cell, is never a pass.)
pub fn chi2_test(counts: &Counts, expected: &ExpectedCounts, significance: f64) -> Chi2 {
    family::judge(expected.grid, (&counts.bins, &expected.bins), (&counts.invalid, &expected.invalid), significance)
}

/// Why a failed χ² test failed, one phrase each: what left it untested ([`crate::stats::chi2::Untested`]), the
/// tests of the family that caught it against the fine grid's figures ([`family::caught`]), the samples in bins the reference gives no probability, and the
/// invalid samples of a reason it expects none of, by name (they are no bin's).
///
/// ```
/// use lobes::{engine::job::Counts, run::compare::{ExpectedCounts, chi2_failure, chi2_test}};
/// let counts = Counts { bins: vec![500, 480], invalid: [0, 0, 20, 0, 0] };
/// let grid = lobes::stats::domain::Domain::Sphere.grid(1, 2);
/// let expected = ExpectedCounts { bins: vec![500.0, 500.0], invalid: [0.0; 5], quadrature: None, grid };
/// let why = chi2_failure(&counts, &expected, &chi2_test(&counts, &expected, 0.01));
/// assert_eq!(why[1], "20 samples rejected as non_finite_pdf, where the reference expects none");
/// ```
pub fn chi2_failure(counts: &Counts, expected: &ExpectedCounts, c: &Chi2) -> Vec<String> {
    let mut why: Vec<String> = c.untested.map(|u| u.describe().to_string()).into_iter().collect();
    if let Some(caught) = family::caught(c) {
        why.push(format!("{caught} (the case's level {:.3e}; χ² = {:.1} with {} dof at the fine grid)", c.significance, c.statistic, c.dof));
    } else if c.untested.is_none() || c.p_value < c.significance {
        why.push(format!("χ² = {:.1} with {} dof, p = {:.3e} below the case's level {:.3e}", c.statistic, c.dof, c.p_value, c.significance));
    }
    let in_empty_bins: u64 = counts.bins.iter().zip(&expected.bins).filter(|(_, e)| **e <= 0.0).map(|(o, _)| o).sum();
    if in_empty_bins > 0 {
        why.push(format!("{in_empty_bins} samples in bins of zero probability"));
    }
    for ((reason, &o), &e) in Invalid::ALL.iter().zip(&counts.invalid).zip(&expected.invalid) {
        if o > 0 && e <= 0.0 {
            why.push(format!("{o} samples rejected as {}, where the reference expects none", reason.name()));
        }
    }
    why
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
    /// use lobes::run::compare::AngleCheck;
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
/// A dielectric's GPU sample pairs with [`RoughDielectric::sample`] of the same three uniforms.
pub fn angle_check(job: &Job, seed: u64, first: u64, gpu: &[[f32; 4]]) -> AngleCheck {
    let Job::Lobe { lobe, incident, scatter, .. } = job else { return AngleCheck::default() };
    let glass = match *scatter {
        Scatter::Reflect => None,
        Scatter::Dielectric { eta } => Some(RoughDielectric::new(*lobe, eta).expect("a dielectric job is checked when made")),
    };
    AngleCheck::from_pairs(gpu.iter().enumerate().map(|(k, g)| {
        let u = crate::reference::rng::uniforms(seed, first + k as u64);
        let reference = match glass {
            None => {
                let s = lobe.sample(*incident, [u[0], u[1]]);
                s.invalid.is_none().then_some(s.omega_r)
            }
            Some(glass) => {
                let s = glass.sample(*incident, [u[0], u[1], u[2]]);
                s.valid.then_some(s.omega_o)
            }
        };
        let gpu = (g[3] == 0.0).then(|| DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64));
        (gpu, reference)
    }))
}

/// Judges `sums` of `n` samples of a lobe case with `effects` at per-case `significance`:
/// the albedo against the f64 quadrature of f |cos θr| (a rough dielectric's reflected and
/// transmitted albedos each), the sphere total against the furnace value where there is one,
/// the per-bin weight check, and no overflow.
///
/// ```
/// use lobes::{engine::job::{Job, SampleRange, Scatter}, run::compare::albedo_check, stats::{histogram::SphereGrid, expected::Quadrature}};
/// use lobes::reference::{Lobe, LobeKind, Method, effects::Effects, masking::Masking, fresnel::Fresnel, reflect::spherical};
/// let lobe = Lobe { kind: LobeKind::Beckmann, method: Method::Ndf, alpha_x: 0.5, alpha_y: 0.5, alpha_angle: 0.0 };
/// let job = Job::Lobe { lobe, incident: spherical(1.0, 0.0), grid: SphereGrid { rows: 8, cols: 16 }, scatter: Scatter::Reflect };
/// let effects = Effects { fresnel: Fresnel::None, masking: Masking::G1 };
/// let sums = lobes::engine::cpu::weighted(&job, &effects, SampleRange::whole(1, 200_000));
/// let check = albedo_check(&job, &effects, &sums, 200_000, 0.01, &Quadrature::default());
/// assert!(check.passed, "{check:?}");
/// assert_eq!(check.furnace, Some(1.0)); // F = 1, G = G1(ωi): the weak white furnace
/// ```
pub fn albedo_check(
    job: &Job,
    effects: &Effects,
    sums: &WeightedSums,
    n: u64,
    significance: f64,
    q: &Quadrature,
) -> AlbedoCheck {
    let Job::Lobe { lobe, incident, grid, scatter } = job else { panic!("albedo of a lobe job") };
    let wi = *incident;
    // per bin, the quadrature of f |cos θo|; a dielectric's over the whole sphere, its furnace
    // seen from the upper side (where the closed forms of Λ hold)
    let (reference_bins, furnace_wi) = match *scatter {
        Scatter::Reflect => {
            let f_cos = |w: DVec3| effects.eval(lobe, wi, w) * w.z;
            (expected::peaked_probabilities(&f_cos, *grid, expected::lobe_peak(lobe, wi), q).probabilities, wi)
        }
        Scatter::Dielectric { eta } => {
            let glass = RoughDielectric::new(*lobe, eta).expect("a dielectric job is checked when made");
            let f_cos = |w: DVec3| glass.eval(wi, w, effects.masking) * w.z.abs();
            (expected::peaked_sphere_probabilities(&f_cos, *grid, dielectric_width(&glass, wi), &dielectric_peaks(&glass, wi), q).probabilities, glass.upper_side(wi).0)
        }
    };
    // the incident side's bins (a reflection's: the lower half holds nothing), and across the
    // surface a dielectric's transmitted ones
    let half = reference_bins.len() / 2;
    let side = |lower: bool| {
        let bins = if lower { &reference_bins[..half] } else { &reference_bins[half..] };
        AlbedoTest::new(sums.hemisphere_albedo(n, lower), sums.hemisphere_std_error(n, lower), bins.iter().sum())
    };
    let below = wi.z < 0.0;
    let reflected = side(below);
    let transmitted = matches!(scatter, Scatter::Dielectric { .. }).then(|| side(!below));
    let sphere_total = sums.sphere_total(n);
    let sphere_std_error = sums.std_error(n, false);
    let furnace = effects.furnace(lobe, furnace_wi);
    let furnace_p_value = furnace.map(|f| two_sided(sphere_total - f, sphere_std_error, f).1);
    let max_weight_error = sums.max_weight_error();
    let passed = reflected.p_value >= significance
        && transmitted.as_ref().is_none_or(|t| t.p_value >= significance)
        && furnace_p_value.is_none_or(|p| p >= significance)
        && max_weight_error <= WEIGHT_ERROR_LIMIT
        && sums.overflow == 0;
    AlbedoCheck {
        reflected,
        transmitted,
        sphere_total,
        sphere_std_error,
        furnace,
        furnace_p_value,
        max_weight_error,
        weight_error_limit: WEIGHT_ERROR_LIMIT,
        overflow: sums.overflow,
        significance,
        passed,
        reference_bins,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::reflect::spherical;
    use crate::reference::{Lobe, LobeKind, Method};
    use crate::stats::histogram::SphereGrid;

    /// Nearly smooth glass (α 10⁻³, η 1.5) is two narrow peaks, the mirror direction's and the
    /// refracted one's, holding F and 1 − F of the mass: near normal incidence F is
    /// ((η − 1)/(η + 1))² = 0.04 (Fresnel's equations; it moves by 10⁻⁵ at θi 0.1 rad) on either
    /// side of the surface. Both peaks are graded toward, by every sampler: the transmitted one
    /// was not, and its 96 % fell between the rules' nodes with no error reported.
    #[test]
    fn nearly_smooth_glass_keeps_both_peaks_mass() {
        let grid = SphereGrid { rows: 16, cols: 32 };
        let edges = grid.cos_theta_edges();
        for (kind, method) in [(LobeKind::Beckmann, Method::Ndf), (LobeKind::Ggx, Method::Ndf), (LobeKind::Beckmann, Method::Vndf)] {
            let glass = RoughDielectric::new(Lobe { kind, method, alpha_x: 1e-3, alpha_y: 1e-3, alpha_angle: 0.0 }, 1.5).unwrap();
            for wi in [DVec3::Z, spherical(0.1, 0.7), -spherical(0.1, 0.2)] {
                let e = dielectric_expected(&glass, wi, grid, 1.0, &Quadrature::default());
                let near: f64 = e.bins.iter().enumerate().filter(|(i, _)| (edges[i / 32] + edges[i / 32 + 1]) * wi.z > 0.0).map(|(_, p)| p).sum();
                let far = e.bins.iter().sum::<f64>() - near;
                let what = format!("{kind:?} {method:?} from {wi}");
                assert!((near - 0.04).abs() < 1e-4, "{what}: reflected mass {near}");
                assert!((far - 0.96).abs() < 1e-4, "{what}: transmitted mass {far}");
            }
        }
    }
}
