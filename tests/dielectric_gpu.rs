//! The rough dielectric's GPU sampler (`shaders/lib/dielectric.wgsl`, the registry's
//! `dielectric` call sites) through the kernels every sampler takes: a lobe job with
//! `Scatter::Dielectric`, histogrammed on the GPU over the whole sphere and judged by χ² against
//! the f64 density of `reference::dielectric::RoughDielectric` (adaptive quadrature,
//! `stats::expected::sphere_probabilities`); each GPU sample paired with the f64 sample of the
//! same three uniforms; a density without eq. 17's η² rejected by the same GPU histogram.

use glam::DVec3;
use lobes::engine::gpu::GpuEngine;
use lobes::engine::job::{Counts, Job, SampleRange, Scatter};
use lobes::reference::dielectric::{RoughDielectric, refraction_half_vector};
use lobes::reference::fresnel;
use lobes::reference::reflect::spherical;
use lobes::reference::{Invalid, Lobe, LobeKind, Method};
use lobes::run::compare;
use lobes::stats::chi2;
use lobes::stats::expected::{Quadrature, sphere_probabilities};
use lobes::stats::histogram::SphereGrid;

const N: u64 = 1_000_000;
const GRID: SphereGrid = SphereGrid { rows: 16, cols: 32 };

fn engine() -> GpuEngine {
    GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"))
}

/// (lobe, method, α, η, θi in degrees): from outside, from inside (η inverted), and from inside
/// past the critical angle of η 1.5 (41.8°), where most samples reflect totally.
const CASES: [(LobeKind, Method, f64, f64, f64); 6] = [
    (LobeKind::Ggx, Method::Vndf, 0.3, 1.5, 40.0),
    (LobeKind::Ggx, Method::Ndf, 0.5, 1.5, 140.0),
    (LobeKind::Beckmann, Method::Vndf, 0.4, 1.5, 125.0),
    (LobeKind::Beckmann, Method::Ndf, 0.3, 1.0 / 1.33, 60.0),
    (LobeKind::Ggx, Method::Vndf, 0.6, 2.5, 170.0),
    (LobeKind::Beckmann, Method::Vndf, 0.2, 1.33, 20.0),
];

fn glass(kind: LobeKind, method: Method, alpha: f64, eta: f64) -> RoughDielectric {
    RoughDielectric::new(Lobe { kind, method, alpha_x: alpha, alpha_y: 0.7 * alpha, alpha_angle: 25.0 }, eta).unwrap()
}

fn job(g: &RoughDielectric, theta_deg: f64) -> Job {
    Job::Lobe { lobe: g.lobe, incident: spherical(theta_deg.to_radians(), 0.3), grid: GRID, scatter: Scatter::Dielectric { eta: g.eta } }
}

/// The reasons of a sample on the wrong side of its event.
const WRONG_SIDE: [Invalid; 2] = [Invalid::OutsideDomain, Invalid::RefractedNearSide];

/// The GPU's counts: every sample a bin hit or a sample on the wrong side of its event
/// (a reflection through the surface, a refraction that stayed on the incident side).
fn gpu_counts(e: &mut GpuEngine, job: &Job, seed: u64) -> Counts {
    let c = e.histogram(job, SampleRange::whole(seed, N), &mut |_| {}).expect("GPU histogram").counts;
    assert_eq!(c.total(), N, "every sample is a bin hit or an invalid sample");
    for r in Invalid::ALL.into_iter().filter(|r| !WRONG_SIDE.contains(r)) {
        assert_eq!(c.invalid_count(r), 0, "{}", r.name());
    }
    c
}

/// Observed cells: the bins, then the wrong-side samples.
fn observed(c: &Counts) -> Vec<u64> {
    c.bins.iter().copied().chain([WRONG_SIDE.iter().map(|&r| c.invalid_count(r)).sum()]).collect()
}

/// N × the bins' probabilities under `pdf`, then N × the mass of no bin.
fn expected(pdf: &(dyn Fn(DVec3) -> f64 + Sync), width: f64) -> Vec<f64> {
    let e = sphere_probabilities(pdf, GRID, width, &Quadrature::default());
    e.probabilities.iter().map(|p| p * N as f64).chain([e.below_horizon * N as f64]).collect()
}

/// Light from inside near grazing leaves in a band far narrower than α
/// (tests/dielectric.rs): the quadrature's initial split follows it.
fn width(alpha: f64, wi: DVec3) -> f64 {
    if wi.z.abs() < 0.2 { 0.02 } else { 0.6 * alpha }
}

#[test]
fn the_gpu_sampler_matches_the_f64_density_over_the_sphere_and_sample_by_sample() {
    let mut e = engine();
    let mut failures = Vec::new();
    for (i, &(kind, method, alpha, eta, theta)) in CASES.iter().enumerate() {
        let g = glass(kind, method, alpha, eta);
        let job = job(&g, theta);
        let Job::Lobe { incident, .. } = job else { unreachable!() };
        let seed = 40 + i as u64;
        let c = gpu_counts(&mut e, &job, seed);
        let t = chi2::test(&observed(&c), &expected(&|wo| g.pdf(incident, wo), width(alpha, incident)), 1e-4);
        let dirs = e.directions(&job, SampleRange::whole(seed, 4096)).unwrap();
        let a = compare::angle_check(&job, seed, 0, &dirs);
        println!(
            "{kind:?} {method:?} α {alpha} η {eta:.3} θi {theta}: χ² {:.1}/{} p = {:.3e}; {} paired, max angle {:.2e} rad, {} validity mismatches",
            t.statistic, t.dof, t.p_value, a.compared, a.max_angle_rad, a.validity_mismatches
        );
        if !t.passed {
            failures.push(format!("{kind:?} {method:?} θi {theta}: p = {:.3e}", t.p_value));
        }
        assert!(a.compared > 1000, "{kind:?} {method:?}: only {} samples valid on both sides", a.compared);
        // f32 against f64: the event flips where u.z and F agree to f32's digits
        assert!(a.validity_mismatches <= 4, "{kind:?} {method:?}: {} validity mismatches", a.validity_mismatches);
        assert!(a.max_angle_rad < 1e-4, "{kind:?} {method:?}: a GPU direction {} rad off its f64 twin", a.max_angle_rad);
    }
    assert!(failures.is_empty(), "rejected: {failures:?}");
}

/// The two refraction densities that go wrong most often: without eq. 17's η², and with the
/// reflection Jacobian 1/(4|ωt·h|) in place of eq. 17's (what a sampler with either bug would be
/// judged against, or would draw): the GPU histogram of the correct sampler rejects both.
#[test]
fn broken_refraction_densities_are_rejected_by_the_gpu_histogram() {
    let mut e = engine();
    let g = glass(LobeKind::Ggx, Method::Vndf, 0.3, 1.5);
    let job = job(&g, 40.0);
    let Job::Lobe { incident, .. } = job else { unreachable!() };
    let c = gpu_counts(&mut e, &job, 7);
    let without_eta2 = |wo: DVec3| if wo.z < 0.0 { g.pdf(incident, wo) / (g.eta * g.eta) } else { g.pdf(incident, wo) };
    let reflection_jacobian = |wo: DVec3| {
        if wo.z >= 0.0 {
            return g.pdf(incident, wo);
        }
        let Some(h) = refraction_half_vector(incident, wo, g.eta) else { return 0.0 };
        fresnel::dielectric_transmittance(incident.dot(h), g.eta) * g.lobe.pdf_h(incident, h) / (4.0 * wo.dot(h).abs())
    };
    let brokens: [(&str, &(dyn Fn(DVec3) -> f64 + Sync)); 2] = [("without η²", &without_eta2), ("reflection Jacobian", &reflection_jacobian)];
    for (what, broken) in brokens {
        let mut exp = expected(broken, 0.18);
        // keep the total: only the shape is wrong
        let total: f64 = exp.iter().sum();
        exp.iter_mut().for_each(|x| *x *= N as f64 / total);
        let t = chi2::test(&observed(&c), &exp, 1e-12);
        println!("{what}: χ² {:.1}/{} p = {:.3e}", t.statistic, t.dof, t.p_value);
        assert!(!t.passed && t.p_value < 1e-12, "{what}: p = {}", t.p_value);
    }
}

/// The CPU engine draws the same samples in f64 (`Job::cell_f64`): the histograms differ only
/// where an f32 direction and its f64 twin fall on opposite sides of a bin edge or an event.
#[test]
fn gpu_and_cpu_engines_agree_sample_by_sample() {
    let mut e = engine();
    let g = glass(LobeKind::Beckmann, Method::Vndf, 0.4, 1.5);
    let job = job(&g, 130.0);
    let n = 200_000;
    let gc = e.histogram(&job, SampleRange::whole(9, n), &mut |_| {}).unwrap().counts;
    let cc = lobes::engine::cpu::histogram(&job, SampleRange::whole(9, n));
    let moved: u64 = gc.bins.iter().zip(&cc.bins).map(|(a, b)| a.abs_diff(*b)).sum();
    println!("GPU invalid {:?}, CPU {:?}", gc.invalid, cc.invalid);
    assert!(moved < n / 2000, "{moved} of {n} samples binned differently");
    // the GPU reads the event from h (shaders/passes/lobe_kernel.wgsl), the CPU knows it
    for r in WRONG_SIDE {
        assert!(cc.invalid_count(r) > 100, "the case has samples of {}", r.name());
        assert!(gc.invalid_count(r).abs_diff(cc.invalid_count(r)) <= n / 20000, "{}: GPU {gc:?} CPU {cc:?}", r.name());
    }
}


/// `lobes run`'s expectation of a dielectric case (`run::compare::expected_counts`): the bins
/// from the density over the sphere, each wrong-side reason from its density over h; the two
/// reasons' shares add up to the sphere's 1 − Σ (two independent quadratures), and the GPU's
/// counts, reasons included, pass `lobes run`'s χ².
#[test]
fn lobes_run_judges_a_dielectric_case_with_its_reasons() {
    let mut e = engine();
    let g = glass(LobeKind::Beckmann, Method::Vndf, 0.4, 1.5);
    let job = job(&g, 130.0);
    let c = gpu_counts(&mut e, &job, 11);
    let exp = compare::expected_counts(&job, N, &Quadrature::default());
    let q = exp.quadrature.as_ref().unwrap();
    let wrong: f64 = WRONG_SIDE.iter().map(|&r| exp.invalid[r.code() as usize - 1]).sum();
    println!("wrong side: by h {:.1} {:?}, by 1 − Σ {:.1}; observed {:?}", wrong, exp.invalid, q.below_horizon * N as f64, c.invalid);
    assert!((wrong / N as f64 - q.below_horizon).abs() < 1e-4, "{wrong} against {}", q.below_horizon * N as f64);
    for r in WRONG_SIDE {
        assert!(exp.invalid[r.code() as usize - 1] > 1000.0, "the case has samples of {}", r.name());
    }
    let t = compare::chi2_test(&c, &exp, 1e-4);
    println!("χ² {:.1}/{} p = {:.3e}", t.statistic, t.dof, t.p_value);
    assert!(t.passed, "p = {}", t.p_value);
}
