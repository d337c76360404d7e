//! Expected bin probabilities: each bin's integral of p(ωr) in f64, by the adaptive
//! Gauss–Legendre quadrature of [`crate::stats::quadrature`] over (a = 1 − |cos θ|, φ), whose
//! area element is the solid angle's.
//!
//! How we know the quadrature is accurate enough: every part is integrated with a 5 × 5 rule and
//! a 3 × 3 rule; where they agree within a tolerance of 1e-2 of the bin's statistical standard
//! deviation at 10⁸ samples (√(p/10⁸)) the 5 × 5 value is taken. Otherwise the part is also
//! integrated with the 5 × 5 rule on its four quarters, and accepted only when that agrees with
//! the whole-part rule within the same tolerance, else split again. The summed |fine − coarse|
//! differences are returned as an error estimate, and tests check it against quadrature at a
//! finer setting and against the closed-form total mass.

use crate::reference::Lobe;
use crate::reference::dielectric::RoughDielectric;
use crate::stats::domain::Domain;
use crate::stats::gauss_legendre::GaussLegendre;
use crate::stats::histogram::SphereGrid;
pub use crate::stats::quadrature::Peak;
use crate::stats::quadrature::{CpuPdf, Jumps, Part, Settings, Tolerance, peak_parts, refine, row_zones, split};
use glam::DVec3;
use rayon::prelude::*;

/// The smallest roughness α whose expected histogram this quadrature resolves at every θi:
/// scenes refuse a narrower lobe (exit 2). The bins about a lobe's peak are cut down to a
/// quarter of its width ([`Peak`]); at the pole (θi = 0) that is α²/8 in cos θ: 1.25·10⁻⁹ at
/// α = 10⁻⁴, 10⁷ steps of f64's 1.1·10⁻¹⁶ below 1, and less than one step at 10⁻⁸. Measured
/// down to 10⁻⁴ (`tests/reference_sweep.rs`); Mitsuba 3 clamps α at 10⁻⁴ too.
pub const MIN_ALPHA: f64 = 1e-4;

/// Sample count at which the quadrature error must be far below the statistical error.
pub const REFERENCE_SAMPLES: f64 = 1e8;

/// Settings of the adaptive quadrature.
#[derive(Debug, Clone, Copy)]
pub struct Quadrature {
    /// Accept a bin when |fine − coarse| ≤ `sigma_fraction` · √(p / 10⁸) (+ `abs_floor`).
    pub sigma_fraction: f64,
    pub abs_floor: f64,
    pub max_depth: u32,
    /// Upper bound on the initial split of a bin per axis (the split follows the lobe's width).
    pub max_initial_split: u32,
}

impl Quadrature {
    /// A setting 100 times stricter than the default, for judging other rules against.
    pub const STRICT: Quadrature = Quadrature { sigma_fraction: 1e-4, abs_floor: 1e-16, max_depth: 12, max_initial_split: 16 };

    /// This setting for a run of `samples` samples: beyond 10⁸ the tolerance shrinks with the
    /// count's standard deviation, `sigma_fraction` · √(p / N), so that the error stays the same
    /// fraction of a σ however many samples are judged.
    pub fn for_samples(&self, samples: u64) -> Quadrature {
        Quadrature { sigma_fraction: self.sigma_fraction * (REFERENCE_SAMPLES / samples as f64).sqrt().min(1.0), ..*self }
    }
}

impl Default for Quadrature {
    /// 1e-2 σ at 10⁸ samples: an error of ε σ in every one of K bins moves Pearson's statistic by
    /// about K ε² ± 2 ε √K, against its own spread √(2K); for K = 4096 that is 0.4 ± 1.3 against
    /// 90. (The |5 × 5 − 3 × 3| estimate bounds the 5 × 5 rule's error loosely: the true error is
    /// about a fifth of the tolerance, see the test `default_setting_error_against_a_finer_one`.)
    fn default() -> Self {
        Self { sigma_fraction: 1e-2, abs_floor: 1e-14, max_depth: 10, max_initial_split: 16 }
    }
}

/// Bin probabilities of a lobe, row-major like [`SphereGrid::bin_of`].
#[derive(Debug, Clone)]
pub struct Expected {
    pub probabilities: Vec<f64>,
    /// 1 − Σ probabilities: the mass of reflections below the horizon (counted as invalid).
    pub below_horizon: f64,
    /// Σ over bins of the accepted |fine − coarse| differences.
    pub error_estimate: f64,
    /// max over bins of |fine − coarse| / √(p/10⁸): the quadrature error in units of the
    /// statistical standard deviation at 10⁸ samples.
    pub max_error_sigma: f64,
    /// Per bin, the accepted |fine − coarse| differences summed (the error estimate of its value).
    pub bin_errors: Vec<f64>,
    /// Parts accepted at the depth limit without the rules agreeing.
    pub unconverged_parts: u64,
}

/// The largest quadrature error of any bin allowed for a verdict, in units of its count's
/// standard deviation at the run's N ([`Expected::max_error_sigma_at`]; `lobes check`'s
/// quadrature alike). The default tolerance is a hundredth of that σ per part (at N ≥ 10⁸, less
/// below), and the bins of every documented configuration stay below 0.05 (docs/statistics.md).
pub const MAX_QUADRATURE_SIGMA: f64 = 0.1;

impl Expected {
    /// The largest quadrature error of a bin in units of its count's standard deviation in a run
    /// of `samples` samples, √(N p), taken as at least one count (where a bin expects less than
    /// one sample, an error below a count changes no χ² cell that matters).
    pub fn max_error_sigma_at(&self, samples: u64) -> f64 {
        let n = samples as f64;
        self.bin_errors.iter().zip(&self.probabilities).map(|(e, p)| n * e / (n * p).max(1.0).sqrt()).fold(0.0, f64::max)
    }
}

/// sin θ from cos θ as √((1 − z)(1 + z)): 1 − z is exact near the poles (Sterbenz), where
/// 1 − z² loses the digits a narrow lobe there is made of.
fn sin_from_cos(z: f64) -> f64 {
    ((1.0 - z) * (1.0 + z)).max(0.0).sqrt()
}

/// The direction at (cos θ, φ).
pub fn direction(z: f64, phi: f64) -> DVec3 {
    let s = sin_from_cos(z);
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// ∫∫ f(ω) d(cos θ) dφ over `r` by `rule`'s tensor product. The same as
/// `rule.integrate_2d(r.z, r.phi, |z, φ| f(direction(z, φ)))`, with sin θ and (cos φ, sin φ)
/// computed once per node rather than once per point (n + n roots and sin_cos for n² points).
pub fn integrate_rect(rule: &GaussLegendre, z: (f64, f64), phi: (f64, f64), f: &impl Fn(DVec3) -> f64) -> f64 {
    let trig: Vec<(f64, f64, f64)> = rule.on(phi.0, phi.1).map(|(p, w)| (w, p.cos(), p.sin())).collect();
    rule.on(z.0, z.1)
        .map(|(zk, wz)| {
            let st = sin_from_cos(zk);
            wz * trig.iter().map(|&(wp, c, s)| wp * f(DVec3::new(st * c, st * s, zk))).sum::<f64>()
        })
        .sum()
}

/// The narrow peak of `lobe`'s reflected density seen from `wi`: the mirror direction (h = n,
/// where D peaks for every lobe and sampler here), as wide as the lobe's narrowest α.
pub fn lobe_peak(lobe: &Lobe, wi: DVec3) -> Peak {
    Peak { direction: DVec3::new(-wi.x, -wi.y, wi.z), width: lobe.alpha_x.min(lobe.alpha_y).min(1.0) }
}

/// The probability of each bin of `grid` under `lobe`'s reflected density seen from `wi`.
pub fn lobe_probabilities(lobe: &Lobe, wi: DVec3, grid: SphereGrid, q: &Quadrature) -> Expected {
    let peak = lobe_peak(lobe, wi);
    peaked_probabilities(&|w| lobe.pdf_r(wi, w), grid, peak, q)
}

/// The probability of each upper-hemisphere bin of `grid` under the density `pdf` (per unit
/// solid angle, zero below the horizon) whose narrowest feature is about `width` radians.
pub fn probabilities(pdf: &(dyn Fn(DVec3) -> f64 + Sync), grid: SphereGrid, width: f64, q: &Quadrature) -> Expected {
    bin_probabilities(pdf, grid, width, &[], q, false)
}

/// As [`probabilities`], for a density with a narrow peak at a known direction: the bins about
/// it are cut into parts graded toward it ([`Peak`]).
pub fn peaked_probabilities(pdf: &(dyn Fn(DVec3) -> f64 + Sync), grid: SphereGrid, peak: Peak, q: &Quadrature) -> Expected {
    bin_probabilities(pdf, grid, peak.width, &[peak], q, false)
}

/// As [`probabilities`], over every bin of the sphere: for a density that also lives below the
/// horizon (a rough dielectric's transmission, [`crate::reference::dielectric`]).
/// `below_horizon` is then the mass of no bin, 1 − Σ probabilities.
pub fn sphere_probabilities(pdf: &(dyn Fn(DVec3) -> f64 + Sync), grid: SphereGrid, width: f64, q: &Quadrature) -> Expected {
    bin_probabilities(pdf, grid, width, &[], q, true)
}

/// As [`sphere_probabilities`], for a density with narrow peaks at known directions (a smooth
/// dielectric's reflected and transmitted ones): the bins about each are graded toward it.
pub fn peaked_sphere_probabilities(pdf: &(dyn Fn(DVec3) -> f64 + Sync), grid: SphereGrid, width: f64, peaks: &[Peak], q: &Quadrature) -> Expected {
    bin_probabilities(pdf, grid, width, peaks, q, true)
}

/// The settings of the engine for `q`: its tolerance at 10⁸ samples (`q` comes scaled to the
/// run's N by [`Quadrature::for_samples`]), its depth counted from a bin's initial parts (`q`'s
/// from their first quarters), no edges looked for (lobes' densities have none inside a bin), and
/// no budget of parts.
fn settings(q: &Quadrature) -> Settings<'static> {
    let tolerance = Tolerance { sigma_fraction: q.sigma_fraction, samples: REFERENCE_SAMPLES, floor: q.abs_floor };
    Settings { tolerance, max_depth: q.max_depth + 1, jumps: Jumps::Trust, max_parts: usize::MAX, keep_leaves: false, witnesses: None }
}

/// The initial parts of every bin of `grid` (the upper hemisphere's, or the sphere's where
/// `sphere`): graded toward the first of `peaks` that is in the bin's reach and narrow there
/// ([`peak_parts`]), else split per axis by the bin's angular extent over `width`, at most
/// `q.max_initial_split` times.
fn initial_parts(grid: SphereGrid, width: f64, peaks: &[Peak], q: &Quadrature, sphere: bool) -> Vec<Part> {
    let phis = grid.phi_edges();
    let mut parts = Vec::new();
    for row in 0..grid.rows {
        for zone in row_zones(grid.rows, row).into_iter().filter(|z| sphere || z.h > 0.0) {
            for c in 0..grid.cols as usize {
                let (phi, bin) = ((phis[c], phis[c + 1]), row * grid.cols + c as u32);
                match peaks.iter().find_map(|p| peak_parts(&zone, phi, bin, *p, q.max_initial_split)) {
                    Some(graded) => parts.extend(graded),
                    None => parts.extend(split(zone.a, phi, zone.h, ((zone.extent(phi) / width).ceil() as u32).clamp(1, q.max_initial_split), bin)),
                }
            }
        }
    }
    parts
}

fn bin_probabilities(pdf: &(dyn Fn(DVec3) -> f64 + Sync), grid: SphereGrid, width: f64, peaks: &[Peak], q: &Quadrature, sphere: bool) -> Expected {
    let cpu = CpuPdf::new(pdf, Domain::Sphere, Jumps::Trust);
    let parts = initial_parts(grid, width, peaks, q, sphere);
    let r = match refine::<std::convert::Infallible>(&cpu, parts, grid.bins(), &settings(q)) {
        Ok(r) => r,
        Err(never) => match never {},
    };
    let total: f64 = r.pdf.iter().sum();
    let sigma = |p: f64| (p.max(1e-300) / REFERENCE_SAMPLES).sqrt();
    Expected {
        below_horizon: (1.0 - total).max(0.0),
        error_estimate: r.linear.iter().sum(),
        max_error_sigma: r.linear.iter().zip(&r.pdf).map(|(e, p)| e / sigma(*p)).fold(0.0, f64::max),
        unconverged_parts: r.unconverged.iter().sum(),
        bin_errors: r.linear,
        probabilities: r.pdf,
    }
}

/// The shares of a rough dielectric's samples that leave on the wrong side of their event:
/// (reflected through the surface, refracted back to the incident side), the integrals over h
/// of [`RoughDielectric::wrong_side_h`].
///
/// The integral is taken in polar coordinates about ωi (moved to the upper side):
/// h = c ωi + √(1 − c²) (cos ψ e₁ + sin ψ e₂), dωh = dc dψ, e₁ towards the normal. There h.z
/// = c ωi.z + √(1 − c²) sin θi cos ψ, so at fixed c each edge of the two sets, a value of h.z
/// ([`RoughDielectric::wrong_side_h_z_breaks`]), is one ψ in [0, π] and its mirror 2π − ψ;
/// total internal reflection is the edge c = √(1 − η²) in c. Between edges the densities are
/// smooth, and each piece is integrated by adaptive Gauss–Legendre; the pieces are also graded
/// towards h = n (c = ωi.z, ψ = 0), where a narrow lobe's p(h) peaks. Tolerance: `q`'s σ
/// fraction of the count's deviation at a share of 10⁻², at 10⁸ samples.
pub fn dielectric_wrong_side(glass: &RoughDielectric, wi: DVec3, q: &Quadrature) -> (f64, f64) {
    use std::f64::consts::PI;
    let (w, eta) = glass.upper_side(wi);
    let sin_i = (1.0 - w.z * w.z).max(0.0).sqrt();
    let e1 = if sin_i > 1e-12 { (DVec3::Z - w.z * w) / sin_i } else { DVec3::X };
    let e2 = w.cross(e1);
    let rule = GaussLegendre::new(7);
    let tol = q.sigma_fraction * (1e-2 / REFERENCE_SAMPLES).sqrt();
    // The inner integral's error is noise to the outer rule: kept well below its tolerance.
    let tol_psi = tol / (20.0 * PI);
    // Nodes graded towards 0 and towards `at`: 4⁻ᵏ of the way, k = 1..12.
    let graded = |lo: f64, hi: f64, at: f64, ends: &mut Vec<f64>| {
        for k in 1..=12 {
            let d = 0.25f64.powi(k);
            ends.extend([at - d * (at - lo), at + d * (hi - at)]);
        }
    };
    let pieces = |mut ends: Vec<f64>, lo: f64, hi: f64| {
        ends.extend([lo, hi]);
        ends.retain(|x| (lo..=hi).contains(x));
        ends.sort_by(f64::total_cmp);
        ends.dedup();
        ends
    };
    let over_psi = |c: f64| -> [f64; 2] {
        let s = (1.0 - c * c).max(0.0).sqrt();
        let h_at = |psi: f64| c * w + s * (psi.cos() * e1 + psi.sin() * e2);
        let mut ends: Vec<f64> = RoughDielectric::wrong_side_h_z_breaks(w, eta, c)
            .into_iter()
            .map(|t| (t - c * w.z) / (s * sin_i))
            .filter(|x| x.abs() < 1.0)
            .map(f64::acos)
            .collect();
        graded(0.0, PI, 0.0, &mut ends);
        let ends = pieces(ends, 0.0, PI);
        // both sets at once; ψ and its mirror 2π − ψ share every edge
        let g = |psi: f64| {
            let (r1, t1) = glass.wrong_side_h(wi, h_at(psi));
            let (r2, t2) = glass.wrong_side_h(wi, h_at(2.0 * PI - psi));
            [r1 + r2, t1 + t2]
        };
        ends.windows(2).fold([0.0; 2], |acc, p| {
            let v = rule.integrate_adaptive_n(p[0], p[1], tol_psi * (p[1] - p[0]), &g);
            [acc[0] + v[0], acc[1] + v[1]]
        })
    };
    let mut ends = vec![0.0];
    if eta < 1.0 {
        ends.push((1.0 - eta * eta).sqrt()); // the critical angle's c
    }
    graded(-1.0, 1.0, w.z, &mut ends);
    let ends = pieces(ends, -1.0, 1.0);
    let parts: Vec<[f64; 2]> = ends.par_windows(2).map(|p| rule.integrate_adaptive_n(p[0], p[1], 0.5 * tol * (p[1] - p[0]), &over_psi)).collect();
    parts.iter().fold((0.0, 0.0), |a, b| (a.0 + b[0], a.1 + b[1]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The trig-hoisted product rule is the plain tensor-product rule of `direction(z, φ)`.
    #[test]
    fn integrate_rect_is_the_tensor_product_rule() {
        let f = |w: DVec3| (3.0 * w.x + w.y * w.y).exp() * (1.0 + w.z);
        let (z, phi) = ((0.1, 0.4), (-2.0, -1.3));
        for n in [3, 5, 8] {
            let rule = GaussLegendre::new(n);
            let plain = rule.integrate_2d(z, phi, |z, p| f(direction(z, p)));
            assert!((integrate_rect(&rule, z, phi, &f) - plain).abs() < 1e-15 * plain.abs(), "n = {n}");
        }
    }

    /// The default setting against a 100 times stricter one, for the four microfacet samplers at
    /// α 0.3, θi 40°, on Mitsuba's 128 × 64 grid: every bin within 1e-2 σ at 10⁸ samples, and the
    /// error estimate an upper bound of the summed true error.
    #[test]
    fn default_setting_error_against_a_finer_one() {
        use crate::reference::{LobeKind, Method, reflect};
        let grid = SphereGrid { rows: 128, cols: 64 };
        let wi = reflect::spherical(40f64.to_radians(), 0.0);
        for (kind, method) in [(LobeKind::Ggx, Method::Ndf), (LobeKind::Ggx, Method::Vndf), (LobeKind::Beckmann, Method::Ndf), (LobeKind::Beckmann, Method::Vndf)] {
            let lobe = Lobe { kind, method, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 };
            let fine = lobe_probabilities(&lobe, wi, grid, &Quadrature::STRICT);
            let e = lobe_probabilities(&lobe, wi, grid, &Quadrature::default());
            let pairs = e.probabilities.iter().zip(&fine.probabilities);
            let max_sigma = pairs.clone().filter(|(_, f)| **f > 0.0).map(|(a, f)| (a - f).abs() / (f / REFERENCE_SAMPLES).sqrt()).fold(0.0, f64::max);
            let l1: f64 = pairs.map(|(a, f)| (a - f).abs()).sum();
            assert!(max_sigma < 1e-2, "{kind:?} {method:?}: {max_sigma} σ");
            assert!(l1 <= e.error_estimate, "{kind:?} {method:?}: true L1 {l1:e} above the estimate {:e}", e.error_estimate);
        }
    }
}
