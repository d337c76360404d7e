//! χ² checks of the rough dielectric's f64 sampler (`reference::dielectric`) against its own
//! density over the whole sphere: 200 000 samples drawn with `reference::rng::uniforms`
//! histogrammed on 16 × 32 equal-area cells of (cos θ, φ) plus one cell for the samples on the
//! wrong side of their event, expected counts by adaptive quadrature of the density
//! (`stats::expected::sphere_probabilities`) and N (1 − Σ) for that cell; the library's χ² test
//! (`stats::chi2::test`).
//!
//! GGX and Beckmann × NDF and visible normals, η above and below 1, light from outside and from
//! inside (θi > 90°, η inverted), near-normal and grazing. And two broken densities that must be
//! rejected: the refraction density without eq. 17's η², and with the reflection Jacobian
//! 1/(4|ωo·h|) in place of eq. 17's.
//!
//! Also: the hard cases in f64, the density and the white furnace integrated over the sphere
//! against masses formed in h space, and the f32 WGSL twin (`examples/samplers/rough_dielectric.wgsl`)
//! judged by `lobes check` against the f64 density on the GPU; the height-correlated G2 across
//! the surface against Euler's integral.

use glam::DVec3;
use lobes::experiments::stress::HORIZON_BAND;
use lobes::reference::dielectric::{Event, RoughDielectric, jacobian_transmitted, refract, refraction_half_vector};
use lobes::reference::masking::Masking;
use lobes::reference::reflect::reflect;
use lobes::reference::reflect::spherical;
use lobes::reference::{Lobe, LobeKind, Method, fresnel, rng};
use lobes::stats::chi2;
use lobes::stats::expected::{Quadrature, probabilities, sphere_probabilities};
use lobes::stats::histogram::SphereGrid;
use std::f64::consts::{FRAC_PI_2, PI};

const N: u64 = 200_000;
const GRID: SphereGrid = SphereGrid { rows: 16, cols: 32 };
/// 32 checks of correct samplers at 1e-4 each: a family-wise false-alarm chance under 0.4 %
/// (the seeds are fixed, so a run is reproducible either way).
const PASS_P: f64 = 1e-4;
/// A broken density must be rejected far beyond any doubt.
const BROKEN_P: f64 = 1e-12;

/// Observed cells (bins, then the invalid samples) of `d` seen from `wi`.
fn histogram(d: &RoughDielectric, wi: DVec3, seed: u64) -> Vec<u64> {
    let mut counts = vec![0u64; GRID.bins() + 1];
    for i in 0..N {
        let u = rng::uniforms(seed, i);
        let s = d.sample(wi, [u[0], u[1], u[2]]);
        counts[if s.valid { GRID.bin_of(s.omega_o) } else { GRID.bins() }] += 1;
    }
    counts
}

/// Expected cells of the density `pdf`, the last one holding the mass of no bin.
fn expected(pdf: &(dyn Fn(DVec3) -> f64 + Sync), width: f64) -> Vec<f64> {
    let e = sphere_probabilities(pdf, GRID, width, &Quadrature::default());
    let mut cells: Vec<f64> = e.probabilities.iter().map(|p| p * N as f64).collect();
    cells.push(e.below_horizon * N as f64);
    cells
}

const KINDS: [(LobeKind, Method); 4] =
    [(LobeKind::Ggx, Method::Ndf), (LobeKind::Ggx, Method::Vndf), (LobeKind::Beckmann, Method::Ndf), (LobeKind::Beckmann, Method::Vndf)];

fn dielectric(kind: LobeKind, method: Method, alpha: f64, eta: f64) -> RoughDielectric {
    RoughDielectric::new(Lobe { kind, method, alpha_x: alpha, alpha_y: 0.6 * alpha, alpha_angle: 25.0 }, eta).unwrap()
}

#[test]
fn the_sampler_matches_its_density_over_the_sphere() {
    let mut failures = Vec::new();
    let mut seed = 1;
    for (kind, method) in KINDS {
        for (alpha, eta, theta) in [(0.3, 1.5, 30.0), (0.5, 1.0 / 1.5, 75.0), (0.4, 2.5, 120.0), (0.6, 1.0 / 2.5, 170.0), (0.25, 1.33, 89.0), (0.5, 1.5, 95.0), (0.2, 1.0 / 1.33, 10.0), (0.8, 2.0, 150.0)] {
            let d = dielectric(kind, method, alpha, eta);
            let wi = spherical(f64::to_radians(theta), 0.4);
            seed += 1;
            // Light escaping from inside at grazing incidence leaves in a thin band (at θi = 95°,
            // GGX α 0.5, η 1.5: 0.126 < cos θo < 0.131), far narrower than α: the quadrature's
            // initial split must follow that width, or its nodes miss the band.
            let width = if wi.z.abs() < 0.2 { 0.02 } else { 0.6 * alpha };
            let t = chi2::test(&histogram(&d, wi, seed), &expected(&|w| d.pdf(wi, w), width), PASS_P);
            if !t.passed {
                failures.push(format!("{kind:?} {method:?} α {alpha} η {eta} θi {theta}°: χ² {:.1} dof {} p {:.2e}", t.statistic, t.dof, t.p_value));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The refraction density of a broken sampler: Walter's eq. 17 with `jacobian` in place of
/// its Jacobian; the reflected part as it should be.
fn broken_pdf(d: &RoughDielectric, wi: DVec3, wo: DVec3, jacobian: impl Fn(DVec3, DVec3, f64) -> f64) -> f64 {
    if wo.z >= 0.0 {
        return d.pdf(wi, wo);
    }
    let Some(h) = refraction_half_vector(wi, wo, d.eta) else { return 0.0 };
    (1.0 - fresnel::dielectric(wi.dot(h), d.eta)) * d.lobe.pdf_h(wi, h) * jacobian(wo, h, wi.dot(h))
}

#[test]
fn broken_refraction_jacobians_are_rejected() {
    for (kind, method) in [(LobeKind::Ggx, Method::Vndf), (LobeKind::Beckmann, Method::Ndf)] {
        let d = dielectric(kind, method, 0.4, 1.5);
        let wi = spherical(0.6, 0.4);
        let observed = histogram(&d, wi, 99);
        let without_eta2 = |wo: DVec3, h: DVec3, c: f64| jacobian_transmitted(c, -wo.dot(h), d.eta) / (d.eta * d.eta);
        let reflection = |wo: DVec3, h: DVec3, _: f64| 1.0 / (4.0 * wo.dot(h).abs());
        for (what, p) in [
            ("without η²", expected(&|w| broken_pdf(&d, wi, w, without_eta2), 0.24)),
            ("reflection Jacobian", expected(&|w| broken_pdf(&d, wi, w, reflection), 0.24)),
        ] {
            let t = chi2::test(&observed, &p, PASS_P);
            assert!(t.p_value < BROKEN_P, "{kind:?} {method:?} {what}: p {:.2e}", t.p_value);
        }
        // and the correct density passes on the same samples
        assert!(chi2::test(&observed, &expected(&|w| d.pdf(wi, w), 0.24), PASS_P).passed);
    }
}


/// The hard cases of the stress suite, in f64: α from 1e-4 to 2, η from 1/2.5 to 2.5 and within
/// 1e-6 of 1 (where eq. 17's denominator vanishes), incidence at and around the critical angle
/// from inside, grazing from either side, uniforms at 0 and 1. Every sample is a finite unit
/// direction; a valid one has a finite positive density that ωo alone reproduces, and lies on
/// the side of its event (ωi, ωo or ωi·h within the stress suite's horizon band excepted for the last check).
#[test]
fn hard_cases_stay_finite_and_consistent() {
    let us = [0.0, 1e-7, 0.3, 0.5, 0.8, 1.0 - 1e-7, 1.0];
    let mut valid = 0;
    for (kind, method) in KINDS {
        for alpha in [1e-4, 1e-2, 0.5, 2.0] {
            for eta in [1.0 / 2.5, 1.0 / 1.5, 1.0 - 1e-6, 1.0 + 1e-6, 1.5, 2.5] {
                let d = RoughDielectric::new(Lobe { kind, method, alpha_x: alpha, alpha_y: alpha, alpha_angle: 0.0 }, eta).unwrap();
                // the critical angle seen from inside, where light from above reaches it with η > 1
                let critical = if eta > 1.0 { PI - (1.0 / eta).asin() } else { PI - 0.5 };
                for theta in [0.0, 1e-6, 1.0, FRAC_PI_2 - 1e-4, FRAC_PI_2, FRAC_PI_2 + 1e-4, critical - 1e-7, critical, critical + 1e-7, PI - 1e-4] {
                    let wi = spherical(theta, 0.3);
                    for &u0 in &us {
                        for &u1 in &us {
                            for u2 in [0.0, 0.5, 1.0] {
                                let s = d.sample(wi, [u0, u1, u2]);
                                let what = format!("{kind:?} {method:?} α {alpha} η {eta} θi {theta} u {u0} {u1} {u2}: {s:?}");
                                assert!(s.omega_o.is_finite() && (s.omega_o.length() - 1.0).abs() < 1e-9, "{what}");
                                if !s.valid {
                                    continue;
                                }
                                valid += 1;
                                let crossed = s.omega_o.z * wi.z < 0.0 || (wi.z == 0.0 && s.omega_o.z < 0.0);
                                assert_eq!(crossed, s.event == Event::Transmission, "{what}");
                                // near the horizon ωi + ωo of a grazing reflection (ωi + η ωo of a
                                // grazing refraction) cancels, and ωo alone no longer pins h down:
                                // the stress suite's horizon band, as for the reflection lobes
                                // (and the microfacet's own horizon: T and F's slope grow from
                                // ωi·h = 0, which a recomputed h shifts by its rounding)
                                if wi.z.abs() < HORIZON_BAND || s.omega_o.z.abs() < HORIZON_BAND || wi.dot(s.h).abs() < HORIZON_BAND {
                                    continue;
                                }
                                let p = d.pdf(wi, s.omega_o);
                                // densities under 1e-20 (Mitsuba's floor for D cos θ) are 0 to
                                // any sample count: at the TIR boundary T → 0 and the recomputed
                                // c may fall on either side of it
                                assert!(p.is_finite() && (s.pdf_o - p).abs() <= 1e-5 * p + 1e-20, "{what}: pdf of ωo {p}");
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(valid > 10_000, "{valid} valid samples");
}

// ---- the density and the white furnace integrated over the sphere ----

/// The grid of the quadratures below (the histogram's is coarser).
const FINE: SphereGrid = SphereGrid { rows: 64, cols: 128 };
/// Looser than the χ² tests' default (whose tolerance is a thousandth of a standard deviation
/// at 10⁸ samples): enough for masses to 1e-5, in seconds rather than minutes.
const Q: Quadrature = Quadrature { sigma_fraction: 0.01, abs_floor: 1e-13, max_depth: 9, max_initial_split: 4 };

/// The probabilities of the valid reflections and of the valid refractions, formed in h
/// space: ∫ p(h) F [ωr on the near side] dωh and ∫ p(h) (1 − F) [ωt on the far side] dωh.
fn event_masses(d: &RoughDielectric, wi: DVec3, width: f64) -> (f64, f64) {
    let (wi, eta) = d.upper_side(wi);
    let mass = |want: Event| {
        let f = |h: DVec3| {
            let pdf_h = d.lobe.pdf_h(wi, h);
            let f = fresnel::dielectric(wi.dot(h), eta);
            match (want, refract(wi, h, eta)) {
                (Event::Reflection, _) if reflect(wi, h).z > 0.0 => f * pdf_h,
                (Event::Transmission, Some(wt)) if wt.z < 0.0 => fresnel::dielectric_transmittance(wi.dot(h), eta) * pdf_h,
                _ => 0.0,
            }
        };
        probabilities(&f, FINE, width, &Q).probabilities.iter().sum::<f64>()
    };
    (mass(Event::Reflection), mass(Event::Transmission))
}

/// ∫ `f` over the sphere on ωi's side and on the far side.
fn sides(f: &(dyn Fn(DVec3) -> f64 + Sync), wi: DVec3, width: f64) -> (f64, f64) {
    let p = sphere_probabilities(f, FINE, width, &Q).probabilities;
    let edges = FINE.cos_theta_edges();
    let (mut near, mut far) = (0.0, 0.0);
    for (i, p) in p.iter().enumerate() {
        let row = i / FINE.cols as usize;
        if (edges[row] + edges[row + 1]) * wi.z.signum() > 0.0 { near += p } else { far += p }
    }
    (near, far)
}

const CASES: [(f64, f64, f64); 6] = [(0.3, 1.5, 30.0), (0.5, 1.0 / 1.5, 60.0), (0.2, 2.5, 80.0), (0.6, 1.0 / 2.5, 20.0), (0.4, 1.5, 130.0), (0.3, 1.33, 175.0)];

/// ∫ over the sphere of the density of ωo, per event, against the probability of that
/// event's valid samples formed in h space (`event_masses`): no Jacobian appears on the h
/// side, so the refraction and reflection Jacobians are checked by two independent
/// integrals. Includes TIR (η < 1, and η > 1 from inside), grazing and near-normal
/// incidence from both sides.
///
/// And the white furnace with both events (Heitz 2014's weak furnace): with F + T = 1 and
/// G = G1(ωi), f |cos θo| / p(ωo) = 1 for visible-normal sampling (the D's, F's, Jacobians
/// and G1's cancel), so ∫ over the sphere of f |cos θo| dωo plus the mass of the samples on
/// the wrong side of their event is 1: BTDF eq. 21 against density eq. 17.
#[test]
fn the_density_integrates_to_the_mass_of_valid_samples_and_the_furnace_to_one() {
    for (kind, method) in KINDS {
        for (alpha, eta, theta) in CASES {
            let d = RoughDielectric::new(Lobe { kind, method, alpha_x: alpha, alpha_y: alpha * 0.7, alpha_angle: 0.0 }, eta).unwrap();
            let wi = spherical(f64::to_radians(theta), 0.3);
            let (near, far) = sides(&|w| d.pdf(wi, w), wi, alpha * 0.7);
            let (r, t) = event_masses(&d, wi, alpha * 0.7);
            let what = format!("{kind:?} {method:?} α {alpha} η {eta} θi {theta}°");
            assert!((near - r).abs() < 2e-4, "{what}: reflected mass by direction {near}, by h {r}");
            assert!((far - t).abs() < 2e-4, "{what}: transmitted mass by direction {far}, by h {t}");
            assert!(r + t <= 1.0 + 1e-6 && r + t > 0.5, "{what}: {r} + {t}");
            if method == Method::Vndf {
                let (near, far) = sides(&|w| d.eval(wi, w, Masking::G1) * w.z.abs(), wi, alpha * 0.7);
                let wrong_side = 1.0 - r - t;
                assert!((near + far + wrong_side - 1.0).abs() < 3e-4, "{what}: furnace {near} + {far} + {wrong_side}");
            }
        }
    }
}

/// The expected shares of the two wrong-side reasons (`expected::dielectric_wrong_side`, a
/// quadrature about ωi with the sets' edges as breakpoints) against the f64 sampler's own
/// counts: reflections through the surface (`outside_domain`) and refractions back to the
/// incident side (`refracted_near_side`), each a binomial z-test. The cases include TIR from
/// inside and the one a 2-D rule over (cos θh, φh) cells got wrong, θi 125°, η 1.33, where that
/// rule's refracted_near_side share is shown to fail the same test.
#[test]
fn the_wrong_side_shares_match_the_sampler_reason_by_reason() {
    const M: u64 = 1_000_000;
    let cases = [(0.3, 1.33, 125.0), (0.4, 1.5, 130.0), (0.3, 1.5, 30.0), (0.5, 1.0 / 1.5, 60.0), (0.2, 2.5, 80.0), (0.3, 1.33, 175.0)];
    let z = |count: u64, share: f64, m: u64| (count as f64 - m as f64 * share) / (m as f64 * share * (1.0 - share)).sqrt().max(1.0);
    let count = |d: &RoughDielectric, wi: DVec3, m: u64, seed: u64| {
        let (mut below, mut near) = (0u64, 0u64);
        for i in 0..m {
            let u = rng::uniforms(seed, i);
            let s = d.sample(wi, [u[0], u[1], u[2]]);
            let side = s.omega_o.z * wi.z.signum();
            match s.event {
                Event::Reflection if side <= 0.0 => below += 1,
                Event::Transmission if side >= 0.0 => near += 1,
                _ => {}
            }
        }
        (below, near)
    };
    for (kind, method) in KINDS {
        for (k, (alpha, eta, theta)) in cases.into_iter().enumerate() {
            let d = RoughDielectric::new(Lobe { kind, method, alpha_x: alpha, alpha_y: alpha * 0.5, alpha_angle: 25.0 }, eta).unwrap();
            let wi = spherical(f64::to_radians(theta), 0.3);
            let (below_share, near_share) = lobes::stats::expected::dielectric_wrong_side(&d, wi, &Quadrature::default());
            let (below, near) = count(&d, wi, M, 40 + k as u64);
            let what = format!("{kind:?} {method:?} α {alpha} η {eta} θi {theta}°");
            assert!(z(below, below_share, M).abs() < 4.5, "{what}: outside_domain {below} of {M}, expected share {below_share:.6}");
            assert!(z(near, near_share, M).abs() < 4.5, "{what}: refracted_near_side {near} of {M}, expected share {near_share:.6}");
        }
    }
    // The 2-D rule over the bins' cells of h, at θi 125°, η 1.33: 8 % short, far outside the test.
    let d = RoughDielectric::new(Lobe { kind: LobeKind::Beckmann, method: Method::Ndf, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 }, 1.33).unwrap();
    let wi = spherical(f64::to_radians(125.0), 0.0);
    let grid_rule = probabilities(&|h| d.wrong_side_h(wi, h).1, SphereGrid { rows: 32, cols: 64 }, 0.02, &Quadrature::default()).probabilities.iter().sum::<f64>();
    let (_, near) = count(&d, wi, 4 * M, 7);
    let (_, near_share) = lobes::stats::expected::dielectric_wrong_side(&d, wi, &Quadrature::default());
    assert!(z(near, near_share, 4 * M).abs() < 4.5, "refracted_near_side {near} of {}, share {near_share}", 4 * M);
    assert!(z(near, grid_rule, 4 * M) > 6.0, "the grid rule's share {grid_rule} against {near} of {}", 4 * M);
}

// ---- the f32 WGSL twin on the GPU, through `lobes check` ----

use lobes::check::{Domain, Reference, Settings, UserSampler, check};

fn rough_glass(source: Option<String>) -> UserSampler {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers");
    let mut files = vec![dir.join("ggx_vndf.wgsl"), dir.join("rough_dielectric.wgsl")];
    if let Some(text) = source {
        let path = std::env::temp_dir().join(format!("lobes-broken-dielectric-{}.wgsl", std::process::id()));
        std::fs::write(&path, text).unwrap();
        files[1] = path;
    }
    UserSampler::from_files(&files, "rd_sample", "rd_pdf", Some("rd_eval"), Domain::Sphere).unwrap()
}

fn settings(ax: f64, ay: f64, eta: f64, theta: f64) -> Settings {
    let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Vndf, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 };
    let d = RoughDielectric::new(lobe, eta).unwrap();
    Settings { params: vec![ax, ay, eta], incident_theta: theta, reference: Some(Reference::new(move |wi, wo| d.pdf(wi, wo))), ..Settings::default() }
}

/// Every check of `lobes check` passes for the f32 sampler (pdf consistency, the Jacobian,
/// normalisation, χ² against the f64 reference's density, weights, albedo, hard cases), from
/// outside and inside, η above and below 1 (TIR), anisotropic. The Jacobian of the map
/// (u.x, u.y) → d at fixed u.z is the density p(d)/F on the reflected side and p(d)/T across (the
/// event chosen by u.z scales it): the check compares p · |J| with the share of u.z that chose
/// the event (F or T, measured on the GPU), at every probe where both events are possible.
#[test]
fn the_wgsl_twin_passes_lobes_check_against_the_f64_density() {
    let gpu = lobes::engine::gpu::Gpu::new().unwrap_or_else(|e| panic!("lobes check needs a GPU adapter: {e}"));
    let s = rough_glass(None);
    for (ax, ay, eta, theta) in [(0.3, 0.3, 1.5, 30.0), (0.5, 0.25, 1.0 / 1.5, 60.0), (0.4, 0.4, 1.5, 140.0), (0.2, 0.35, 2.5, 175.0)] {
        let r = check(&gpu, &s, &settings(ax, ay, eta, theta)).unwrap();
        for c in &r.checks {
            eprintln!("α ({ax}, {ay}) η {eta} θi {theta}: {} {} {}", c.name(), c.passed, c.summary);
        }
        let failed: Vec<&str> = r.checks.iter().filter(|c| !c.passed).map(|c| c.name()).collect();
        assert!(failed.is_empty() && r.checks.len() == 8, "α ({ax}, {ay}) η {eta} θi {theta}: {failed:?}");
        let j = r.figures::<lobes::check::jacobian::JacobianCheck>().unwrap();
        assert!(j.applicable && j.compared_events * 10 > j.compared && (j.median_ratio.unwrap() - 1.0).abs() < 1e-3, "{j:?}");
    }
}

/// The same sampler with eq. 17's η² dropped from its Jacobian (in its reported pdf and its pdf
/// function alike, so the samples are unchanged) fails χ² against its own pdf, normalisation,
/// the albedo and the Jacobian.
#[test]
fn the_wgsl_twin_without_eta_squared_is_rejected() {
    let gpu = lobes::engine::gpu::Gpu::new().unwrap_or_else(|e| panic!("lobes check needs a GPU adapter: {e}"));
    let text = std::fs::read_to_string(std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers/rough_dielectric.wgsl")).unwrap();
    let broken = text.replace("return eta * eta * ct * s * s / (k * k);", "return ct * s * s / (k * k);");
    assert_ne!(broken, text);
    let r = check(&gpu, &rough_glass(Some(broken)), &Settings { reference: None, ..settings(0.3, 0.3, 1.5, 30.0) }).unwrap();
    for c in &r.checks {
        eprintln!("broken: {} {} {}", c.name(), c.passed, c.summary);
    }
    for name in ["chi2", "normalization", "albedo", "jacobian"] {
        assert!(!r.get(name).unwrap().passed, "{name} passed the broken sampler");
    }
}

/// The f64 reference's transmitted G2 is Euler's integral B(x, y) = ∫₀¹ t^(x−1) (1 − t)^(y−1) dt
/// (x = 1/G1(ωi), y = 1/G1(ωo)), by adaptive Gauss–Legendre at non-integer points, to 1e-11.
#[test]
fn transmitted_g2_is_eulers_integral() {
    let rule = lobes::stats::gauss_legendre::GaussLegendre::new(8);
    for (x, y) in [(1.3, 2.7), (2.25, 1.1), (4.6, 3.4), (1.05, 11.5)] {
        let q = rule.integrate_adaptive(0.0, 1.0, 1e-14, &|t: f64| t.powf(x - 1.0) * (1.0 - t).powf(y - 1.0));
        let g = Masking::HeightCorrelated.g_transmitted(1.0 / x, 1.0 / y);
        assert!((g / q - 1.0).abs() < 1e-11, "B({x}, {y}): {g} vs quadrature {q}");
    }
}
