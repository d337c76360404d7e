//! Monte Carlo check of every CPU sampler against its own density: 200 000 samples drawn with
//! `reference::rng::uniforms`, histogrammed, and compared with the integral of the pdf over each
//! bin by a χ² test (Mitsuba-style pooling of cells expected below 5; any sample in a cell with
//! expected count 0 rejects).
//!
//! - Half vectors: 20 θh × 8 φh cells, the θh edges making the isotropic Beckmann marginal
//!   equal-mass (tan²θk = −α² ln(1 − k/20)), expected counts from ∫∫ pdf_h sin θ dθ dφ.
//! - Reflected directions: 10 × 16 cells in (cos θr, φr) plus one cell for the samples flagged
//!   invalid, expected counts from ∫∫ pdf_r d(cos θ) dφ and N (1 − Σ).
//!
//! Each check is also run on deliberately broken pairs (a pdf missing the Jacobian
//! 1/(4|ωr·h|), Ward's pdf missing 1/cos³θh, the VNDF pdf missing G1, GGX's NDF density paired
//! with Beckmann's sampler) to show that the test can fail.

use crate::reference_quadrature;

use glam::DVec3;
use lobes::reference::beckmann::Beckmann;
use lobes::reference::ggx::Ggx;
use lobes::reference::microfacet::Microfacet;
use lobes::reference::reflect::{reflect, spherical};
use lobes::reference::{Lobe, LobeKind, Method, rng};
use lobes::stats::chi2;
use reference_quadrature::{GaussLegendre, composite};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::{FRAC_PI_2, TAU};

const N: u64 = 200_000;
/// Significance for a correct sampler: 24 checks here, 1e-4 each keeps the family's chance of a
/// false alarm under 0.3 % (the seeds are fixed, so a run is reproducible either way).
const PASS_P: f64 = 1e-4;
/// A broken pair must be rejected far beyond any doubt.
const BROKEN_P: f64 = 1e-12;

/// χ² statistic, degrees of freedom and p-value of observed against expected counts, by the
/// library's test ([`chi2::test`]): cells sorted by expected count, those below 5 pooled, the
/// remainder joining the last pooled cell; an observation in a cell expected to hold nothing
/// makes p = 0.
fn chi_square(observed: &[u64], expected: &[f64]) -> (f64, u64, f64) {
    let t = chi2::test(observed, expected, PASS_P);
    (t.statistic, t.dof, t.p_value)
}

/// The p-value against tabulated χ² quantiles, and pooling by hand.
#[test]
fn chi_square_p_values_match_tables() {
    let sf = |x: f64, k: f64| ChiSquared::new(k).unwrap().sf(x);
    assert!((sf(3.841_458_820_694_124, 1.0) - 0.05).abs() < 1e-9);
    assert!((sf(6.634_896_601_021_214, 1.0) - 0.01).abs() < 1e-9);
    assert!((sf(18.307_038_053_275_146, 10.0) - 0.05).abs() < 1e-9);
    assert!((sf(36.190_869_129_270_05, 19.0) - 0.01).abs() < 1e-9);
    // Perfect agreement: statistic 0, p = 1; the three small cells (2 + 2 + 2) pool into one.
    let (stat, dof, p) = chi_square(&[10, 20, 2, 2, 2], &[10.0, 20.0, 2.0, 2.0, 2.0]);
    assert_eq!((stat, dof, p), (0.0, 2, 1.0));
    // 2 degrees of freedom: sf(x) = e^{−x/2}. Cells 100/100/100 observed 110/90/100: χ² = 2.
    let (stat, dof, p) = chi_square(&[110, 90, 100], &[100.0, 100.0, 100.0]);
    assert_eq!(dof, 2);
    assert!((stat - 2.0).abs() < 1e-12 && (p - (-1.0f64).exp()).abs() < 1e-12);
    // a sample where nothing is expected rejects outright
    assert_eq!(chi_square(&[1, 9], &[0.0, 10.0]).2, 0.0);
}

fn lobe(kind: LobeKind, method: Method, ax: f64, ay: f64) -> Lobe {
    Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 }
}

/// The two configurations every sampler is checked in: isotropic α = 0.3 at θi = 60°, and
/// anisotropic (0.15, 0.4) at θi = 30°, φi = 40°.
const CONFIGS: [(f64, f64, f64, f64); 2] = [(0.3, 0.3, 60.0, 0.0), (0.15, 0.4, 30.0, 40.0)];

const SAMPLERS: [(LobeKind, Method); 6] = lobes::reference::SAMPLERS;

const H_THETA: usize = 20;
const H_PHI: usize = 8;

/// θh bin edges: equal mass for an isotropic Beckmann lobe of roughness √(αx αy).
fn h_edges(ax: f64, ay: f64) -> Vec<f64> {
    let a2 = ax * ay;
    let mut e: Vec<f64> = (0..H_THETA).map(|k| (-a2 * (-(k as f64) / H_THETA as f64).ln_1p()).sqrt().atan()).collect();
    e.push(FRAC_PI_2);
    e
}

/// χ² of a half-vector sampler against `pdf_h` over 20 θh × 8 φh cells: (statistic, dof, p).
fn check_h(sample: impl Fn([f64; 2]) -> DVec3, pdf_h: impl Fn(DVec3) -> f64, ax: f64, ay: f64, seed: u64) -> (f64, u64, f64) {
    let edges = h_edges(ax, ay);
    // Last cell: h below the surface or not finite. A half vector exactly on the horizon (the
    // rng's uniforms lie on a 2⁻²⁴ grid that includes 0, and e.g. Ward maps u1 = 0 to θh = 90°)
    // belongs to the last θ bin, which is closed at 90°.
    let mut observed = vec![0u64; H_THETA * H_PHI + 1];
    for i in 0..N {
        let u = rng::uniforms(seed, i);
        let h = sample([u[0], u[1]]);
        let cell = if h.is_finite() && h.z >= 0.0 {
            let t = edges.partition_point(|&e| e <= h.x.hypot(h.y).atan2(h.z)).clamp(1, H_THETA) - 1;
            let p = ((h.y.atan2(h.x).rem_euclid(TAU) / TAU * H_PHI as f64) as usize).min(H_PHI - 1);
            t * H_PHI + p
        } else {
            H_THETA * H_PHI
        };
        observed[cell] += 1;
    }
    let gl = GaussLegendre::new(8);
    let mut expected = Vec::with_capacity(H_THETA * H_PHI + 1);
    for w in edges.windows(2) {
        for p in 0..H_PHI {
            let (p0, p1) = (TAU * p as f64 / H_PHI as f64, TAU * (p + 1) as f64 / H_PHI as f64);
            let mass = composite(&gl, w[0], w[1], 4, |theta| {
                let (st, ct) = theta.sin_cos();
                st * composite(&gl, p0, p1, 3, |phi| {
                    let (sp, cp) = phi.sin_cos();
                    pdf_h(DVec3::new(st * cp, st * sp, ct))
                })
            });
            expected.push(mass * N as f64);
        }
    }
    expected.push(0.0);
    chi_square(&observed, &expected)
}

const R_COS: usize = 10;
const R_PHI: usize = 16;

/// χ² of a reflected-direction sampler against `pdf_r`: (cos θr, φr) cells plus an invalid cell.
fn check_r(
    sample: impl Fn([f64; 2]) -> (DVec3, bool),
    pdf_r: impl Fn(DVec3) -> f64,
    seed: u64,
) -> (f64, u64, f64) {
    let mut observed = vec![0u64; R_COS * R_PHI + 1];
    for i in 0..N {
        let u = rng::uniforms(seed, i);
        let (wr, valid) = sample([u[0], u[1]]);
        let cell = if valid {
            let c = ((wr.z * R_COS as f64) as usize).min(R_COS - 1);
            let p = ((wr.y.atan2(wr.x).rem_euclid(TAU) / TAU * R_PHI as f64) as usize).min(R_PHI - 1);
            c * R_PHI + p
        } else {
            R_COS * R_PHI
        };
        observed[cell] += 1;
    }
    let gl = GaussLegendre::new(6);
    let mut expected = Vec::with_capacity(R_COS * R_PHI + 1);
    for c in 0..R_COS {
        let (c0, c1) = (c as f64 / R_COS as f64, (c + 1) as f64 / R_COS as f64);
        for p in 0..R_PHI {
            let (p0, p1) = (TAU * p as f64 / R_PHI as f64, TAU * (p + 1) as f64 / R_PHI as f64);
            let mass = composite(&gl, c0, c1, 3, |z| {
                let s = (1.0 - z * z).max(0.0).sqrt();
                composite(&gl, p0, p1, 3, |phi| {
                    let (sp, cp) = phi.sin_cos();
                    pdf_r(DVec3::new(s * cp, s * sp, z))
                })
            });
            expected.push(mass * N as f64);
        }
    }
    let valid: f64 = expected.iter().sum();
    expected.push((N as f64 - valid).max(0.0));
    chi_square(&observed, &expected)
}

/// Every half-vector sampler except bounded VNDF (whose `pdf_h` is only defined for h that
/// reflect above the horizon) matches its `pdf_h`.
#[test]
fn half_vector_histograms_match_pdf_h() {
    for (ci, &(ax, ay, t, p)) in CONFIGS.iter().enumerate() {
        let wi = spherical(t.to_radians(), p.to_radians());
        for (si, &(kind, method)) in SAMPLERS.iter().enumerate().filter(|(_, s)| s.1 != Method::Bounded) {
            let l = lobe(kind, method, ax, ay);
            let (stat, dof, pv) = check_h(|u| l.sample_h(wi, u), |h| l.pdf_h(wi, h), ax, ay, 100 + (ci * 10 + si) as u64);
            eprintln!("h  {} {} α = ({ax}, {ay}) θi = {t}°: χ² = {stat:.1}, dof {dof}, p = {pv:.3}", kind.name(), method.name());
            assert!(pv > PASS_P, "{} {} rejected: χ² = {stat}, dof {dof}, p = {pv}", kind.name(), method.name());
        }
    }
}

/// Every sampler's reflected directions (and the fraction flagged invalid) match `Lobe::pdf_r`.
#[test]
fn reflected_histograms_match_pdf_r() {
    for (ci, &(ax, ay, t, p)) in CONFIGS.iter().enumerate() {
        let wi = spherical(t.to_radians(), p.to_radians());
        for (si, &(kind, method)) in SAMPLERS.iter().enumerate() {
            let l = lobe(kind, method, ax, ay);
            let sample = |u| {
                let s = l.sample(wi, u);
                (s.omega_r, s.invalid.is_none())
            };
            let (stat, dof, pv) = check_r(sample, |wr| l.pdf_r(wi, wr), 200 + (ci * 10 + si) as u64);
            eprintln!("ωr {} {} α = ({ax}, {ay}) θi = {t}°: χ² = {stat:.1}, dof {dof}, p = {pv:.3}", kind.name(), method.name());
            assert!(pv > PASS_P, "{} {} rejected: χ² = {stat}, dof {dof}, p = {pv}", kind.name(), method.name());
        }
    }
}

/// The same checks reject broken sampler/pdf pairs.
#[test]
fn broken_samplers_are_rejected() {
    let (ax, ay, t) = (0.3, 0.3, 60.0f64);
    let wi = spherical(t.to_radians(), 0.0);
    let ward = lobe(LobeKind::Ward, Method::Ndf, ax, ay);
    let ggx_vndf = lobe(LobeKind::Ggx, Method::Vndf, ax, ay);
    let mut results = Vec::new();

    // Ward's p(h) without the 1/cos³θh of Walter's correction.
    let no_cos3 = |h: DVec3| ward.pdf_h(wi, h) * h.z.powi(3);
    results.push(("Ward pdf_h missing 1/cos³θh", check_h(|u| ward.sample_h(wi, u), no_cos3, ax, ay, 300)));

    // Visible normals without G1 (Donut #23): 6 % too much mass at θi = 60°, α = 0.3.
    let g = Ggx { ax, ay };
    let no_g1 = |h: DVec3| ggx_vndf.pdf_h(wi, h) / g.g1(wi);
    results.push(("GGX VNDF pdf_h missing G1", check_h(|u| ggx_vndf.sample_h(wi, u), no_g1, ax, ay, 301)));

    // GGX's density D cos θh paired with Beckmann's NDF sampler.
    let b = Beckmann { ax, ay };
    let ggx_ndf = lobe(LobeKind::Ggx, Method::Ndf, ax, ay);
    results.push(("Beckmann sampler judged by GGX pdf", check_h(|u| b.sample_ndf(u), |h| ggx_ndf.pdf_h(wi, h), ax, ay, 302)));

    // Reflected densities that forget the Jacobian dωh/dωr = 1/(4|ωr·h|).
    for (name, l, seed) in [("Ward", ward, 303), ("GGX VNDF", ggx_vndf, 304)] {
        let sample = |u| {
            let s = l.sample(wi, u);
            (s.omega_r, s.invalid.is_none())
        };
        let no_jacobian = |wr: DVec3| {
            let h = (wi + wr).normalize();
            if reflect(wi, h).z > 0.0 { l.pdf_h(wi, h) } else { 0.0 }
        };
        results.push((name, check_r(sample, no_jacobian, seed)));
    }
    for (name, (stat, dof, p)) in results {
        eprintln!("broken: {name}: χ² = {stat:.1}, dof {dof}, p = {p:.3e}");
        assert!(p < BROKEN_P, "{name} was not rejected: χ² = {stat}, dof {dof}, p = {p}");
    }
}

/// A subtler break: the Jacobian with |ωr·h| replaced by cos θh (a plausible slip), which
/// changes the reflected density by the factor (ωr·h) / cos θh ≠ 1 off normal incidence.
#[test]
fn reflected_histogram_rejects_a_wrong_jacobian_cosine() {
    let (ax, ay) = (0.3, 0.3);
    let wi = spherical(60f64.to_radians(), 0.0);
    let l = lobe(LobeKind::Beckmann, Method::Ndf, ax, ay);
    let sample = |u| {
        let s = l.sample(wi, u);
        (s.omega_r, s.invalid.is_none())
    };
    let wrong = |wr: DVec3| {
        let h = (wi + wr).normalize();
        l.pdf_h(wi, h) / (4.0 * h.z)
    };
    let (stat, dof, p) = check_r(sample, wrong, 305);
    eprintln!("broken: Jacobian with cos θh: χ² = {stat:.1}, dof {dof}, p = {p:.3e}");
    assert!(p < BROKEN_P, "not rejected: χ² = {stat}, dof {dof}, p = {p}");
}
