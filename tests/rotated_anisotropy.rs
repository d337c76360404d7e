//! Rotated anisotropy (issue 17, item 3): a lobe whose tangent frame is turned by φα about the
//! normal. Its f64 densities against independent identities (p_φα(ωi, ωr) = p(R⁻¹ωi, R⁻¹ωr) with R
//! built by glam's quaternion, a half turn is no turn, a quarter turn swaps αx and αy); its
//! histograms against χ² on the CPU engine and on the GPU for every sampler; its weighted pass
//! against f64 quadrature and the CPU engine; and a broken rotation (ωi turned into the lobe's
//! frame, ωr never turned back) rejected by the same χ².

use glam::{DQuat, DVec3};
use lobes::engine::gpu::GpuEngine;
use lobes::engine::gpu::effects::Specialisation;
use lobes::engine::job::{Counts, Job, SampleRange, Scatter};
use lobes::reference::effects::Effects;
use lobes::reference::fresnel::Fresnel;
use lobes::reference::masking::Masking;
use lobes::reference::{Lobe, LobeKind, Method, SAMPLERS, reflect, rng};
use lobes::run::compare::{self, albedo_check};
use lobes::stats::chi2::sidak;
use lobes::stats::expected::Quadrature;
use lobes::stats::histogram::SphereGrid;
use lobes::stats::weighted::WEIGHT_ERROR_LIMIT;
use std::f64::consts::PI;

const GRID: SphereGrid = SphereGrid { rows: 32, cols: 64 };

fn lobe(kind: LobeKind, method: Method, ax: f64, ay: f64, angle_deg: f64) -> Lobe {
    Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: angle_deg }
}

/// A unit direction from two uniforms: θ in [0°, 85°] above the horizon, any φ.
fn direction(u: [f64; 4], k: usize) -> DVec3 {
    reflect::spherical(85f64.to_radians() * u[k], 2.0 * PI * u[k + 1])
}

/// `n` pseudo-random (ωi, ωr) pairs above the horizon.
fn pairs(n: u64) -> impl Iterator<Item = (DVec3, DVec3)> {
    (0..n).map(|i| {
        let u = rng::uniforms(17, i);
        (direction(u, 0), direction(u, 2))
    })
}

fn close(a: f64, b: f64, what: &str) {
    assert!((a - b).abs() <= 1e-12 * a.abs().max(b.abs()) + 1e-300, "{what}: {a} vs {b}");
}

/// Every f64 value a lobe has for (ωi, ωr): p(ωr), f, and with effects f and the weight of the
/// sample its uniforms draw.
fn values(l: &Lobe, wi: DVec3, wr: DVec3, u: [f64; 2]) -> [f64; 4] {
    let effects = Effects { fresnel: Fresnel::Schlick { f0: 0.04 }, masking: Masking::HeightCorrelated };
    let s = l.sample(wi, u);
    [l.pdf_r(wi, wr), l.eval(wi, wr), effects.eval(l, wi, wr), effects.weight(l, wi, &s)]
}

const ALPHAS: [(f64, f64); 3] = [(0.4, 0.1), (0.05, 0.6), (0.3, 0.3)];

/// p_φα(Rωi, Rωr) = p(ωi, ωr), f likewise, and the rotated lobe draws R times the unrotated
/// lobe's sample for the same uniforms; R from glam's quaternion, not the lobe's own rotation.
#[test]
fn a_rotated_lobe_is_the_lobe_seen_from_a_rotated_frame() {
    for (kind, method) in SAMPLERS {
        for (ax, ay) in ALPHAS {
            for angle in [30.0, -115.0, 200.0] {
                let rotated = lobe(kind, method, ax, ay, angle);
                let plain = Lobe { alpha_angle: 0.0, ..rotated };
                let r = DQuat::from_rotation_z(f64::to_radians(angle));
                for (i, (wi, wr)) in pairs(200).enumerate() {
                    let u = [rng::uniforms(5, i as u64)[0], rng::uniforms(5, i as u64)[1]];
                    let (a, b) = (values(&rotated, r * wi, r * wr, u), values(&plain, wi, wr, u));
                    for (k, what) in ["pdf", "eval", "effects eval", "weight"].iter().enumerate() {
                        close(a[k], b[k], &format!("{kind:?} {method:?} α ({ax}, {ay}) {angle}°: {what}"));
                    }
                    let (s, t) = (rotated.sample(r * wi, u), plain.sample(wi, u));
                    assert!((s.omega_r - r * t.omega_r).length() < 1e-12, "{kind:?} {method:?}: {:?} vs {:?}", s.omega_r, r * t.omega_r);
                    assert!((s.h - r * t.h).length() < 1e-12);
                    close(s.pdf_r, t.pdf_r, "sample pdf");
                }
            }
        }
    }
}

/// A half turn maps the αx axis onto −αx, and every lobe is symmetric under h → −h in the
/// tangent plane: the same lobe.
#[test]
fn a_half_turn_is_no_turn() {
    for (kind, method) in SAMPLERS {
        for (ax, ay) in ALPHAS {
            let (half, none) = (lobe(kind, method, ax, ay, 180.0), lobe(kind, method, ax, ay, 0.0));
            for (i, (wi, wr)) in pairs(300).enumerate() {
                let u = [rng::uniforms(6, i as u64)[0], rng::uniforms(6, i as u64)[1]];
                let (a, b) = (values(&half, wi, wr, u), values(&none, wi, wr, u));
                // the samples differ (h is drawn turned), so the weights are compared at the
                // pair's own directions only through p and f
                for k in 0..3 {
                    close(a[k], b[k], &format!("{kind:?} {method:?} α ({ax}, {ay}) 180° value {k}"));
                }
            }
        }
    }
}

/// A quarter turn puts the αx axis on +y: the lobe with αx and αy swapped.
#[test]
fn a_quarter_turn_swaps_the_roughnesses() {
    for (kind, method) in SAMPLERS {
        for (ax, ay) in ALPHAS {
            let quarter = lobe(kind, method, ax, ay, 90.0);
            let swapped = lobe(kind, method, ay, ax, 0.0);
            for (i, (wi, wr)) in pairs(300).enumerate() {
                let u = [rng::uniforms(8, i as u64)[0], rng::uniforms(8, i as u64)[1]];
                let (a, b) = (values(&quarter, wi, wr, u), values(&swapped, wi, wr, u));
                for k in 0..3 {
                    close(a[k], b[k], &format!("{kind:?} {method:?} α ({ax}, {ay}) 90° value {k}"));
                }
            }
        }
    }
}

/// One rotated, anisotropic case per sampler, each at its own angle and incident direction.
fn rotated_cases() -> Vec<Job> {
    use LobeKind::*;
    use Method::*;
    [
        (Ward, Ndf, 0.3, 0.08, 35.0, 45.0, 10.0),
        (Beckmann, Ndf, 0.4, 0.1, -60.0, 30.0, 0.0),
        (Beckmann, Vndf, 0.5, 0.1, 120.0, 60.0, 70.0),
        (Ggx, Ndf, 0.1, 0.4, 75.0, 20.0, 200.0),
        (Ggx, Vndf, 0.1, 0.5, 30.0, 70.0, 0.0),
        (Ggx, Bounded, 0.6, 0.15, -20.0, 55.0, 300.0),
    ]
    .into_iter()
    .map(|(kind, method, ax, ay, angle, theta, phi): (_, _, f64, f64, f64, f64, f64)| Job::Lobe {
        lobe: lobe(kind, method, ax, ay, angle),
        incident: reflect::spherical(theta.to_radians(), phi.to_radians()),
        grid: GRID,
        scatter: Scatter::Reflect,
    })
    .collect()
}

fn unrotated(job: &Job) -> Job {
    let Job::Lobe { lobe, incident, grid, scatter } = *job else { unreachable!("lobe jobs") };
    Job::Lobe { lobe: Lobe { alpha_angle: 0.0, ..lobe }, incident, grid, scatter }
}

/// The histogram a sampler would give if it turned ωi into the lobe's frame but never turned
/// ωr back: the unrotated lobe's samples for R⁻¹ωi, binned as they are.
fn broken_rotation_counts(job: &Job, seed: u64, n: u64) -> Counts {
    let Job::Lobe { lobe, incident, grid, .. } = job else { unreachable!("lobe jobs") };
    let plain = Lobe { alpha_angle: 0.0, ..*lobe };
    let local_wi = lobe.to_local(*incident);
    let mut cells = vec![0u64; grid.bins() + lobes::reference::Invalid::COUNT];
    for i in 0..n {
        let u = rng::uniforms(seed, i);
        let s = plain.sample(local_wi, [u[0], u[1]]);
        cells[match s.invalid {
            None => grid.bin_of(s.omega_r),
            Some(r) => grid.bins() + r.code() as usize - 1,
        }] += 1;
    }
    Counts::from_cells(&cells)
}

/// The CPU engine (f64 reference samplers) passes χ² for every rotated case; the same test
/// rejects a broken rotation and the unrotated lobe's expected histogram.
#[test]
fn the_cpu_engine_passes_chi2_and_a_broken_rotation_fails() {
    let n = 300_000;
    let cases = rotated_cases();
    let level = sidak(0.01, cases.len());
    for (i, job) in cases.iter().enumerate() {
        let seed = 40 + i as u64;
        let counts = lobes::engine::cpu::histogram(job, SampleRange::whole(seed, n));
        let exp = compare::expected_counts(job, n, &Quadrature::default());
        let t = compare::chi2_test(&counts, &exp, level);
        assert!(t.passed, "{job:?}: p = {}", t.p_value);
        let broken = compare::chi2_test(&broken_rotation_counts(job, seed, n), &exp, level);
        assert!(!broken.passed && broken.p_value < 1e-10, "a broken rotation passed: {job:?}: p = {}", broken.p_value);
        let plain = compare::expected_counts(&unrotated(job), n, &Quadrature::default());
        let t = compare::chi2_test(&counts, &plain, level);
        assert!(!t.passed && t.p_value < 1e-10, "rotated and unrotated are not told apart: {job:?}: p = {}", t.p_value);
    }
}

fn engine() -> GpuEngine {
    GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"))
}

/// Every sampler rotated on the GPU: χ² against the f64 reference's expected histogram, each
/// sample's direction within 1e-4 rad of the f64 reference's for the same uniforms, and the
/// histogram told apart from the unrotated lobe's.
#[test]
fn the_gpu_passes_chi2_for_every_rotated_sampler() {
    let n = 1 << 22;
    let cases = rotated_cases();
    let level = sidak(0.01, cases.len());
    let mut e = engine();
    let mut failures = Vec::new();
    for (i, job) in cases.iter().enumerate() {
        let seed = 60 + i as u64;
        let counts = e.histogram(job, SampleRange::whole(seed, n), &mut |_| {}).expect("GPU histogram").counts;
        assert_eq!(counts.total(), n);
        let exp = compare::expected_counts(job, n, &Quadrature::default());
        let t = compare::chi2_test(&counts, &exp, level);
        let dirs = e.directions(job, SampleRange::whole(seed, 4096)).unwrap();
        let angle = compare::angle_check(job, seed, 0, &dirs);
        println!("{job:?}: χ² {:.1}/{} p = {:.4}, max angle {:.2e}", t.statistic, t.dof, t.p_value, angle.max_angle_rad);
        if !t.passed {
            failures.push(format!("{job:?}: p = {}", t.p_value));
        }
        assert!(angle.max_angle_rad < 1e-4, "{job:?}: GPU direction off by {} rad", angle.max_angle_rad);
        assert!(angle.validity_mismatches <= 2, "{job:?}: {} validity mismatches", angle.validity_mismatches);
        let plain = compare::expected_counts(&unrotated(job), n, &Quadrature::default());
        assert!(compare::chi2_test(&counts, &plain, level).p_value < 1e-10, "{job:?}: the GPU histogram looks unrotated");
    }
    assert!(failures.is_empty(), "rejected: {failures:?}");
}

/// The weighted pass of rotated lobes with anisotropic masking (whose G1 depends on the frame):
/// the albedo agrees with f64 quadrature and the per-bin weight check holds; the GPU's sums
/// agree with the CPU engine's for the same samples, specialised and in the uber-kernel.
#[test]
fn rotated_weighted_cases_match_quadrature_and_the_cpu_engine() {
    let effects = [
        Effects { fresnel: Fresnel::None, masking: Masking::G1 },
        Effects { fresnel: Fresnel::Schlick { f0: 0.04 }, masking: Masking::HeightCorrelated },
        Effects { fresnel: Fresnel::Conductor { eta: 0.2, k: 3.9 }, masking: Masking::Separable },
    ];
    let cases = rotated_cases();
    let level = sidak(0.01, cases.len());
    let mut e = engine();
    let n = 1 << 20;
    for (i, job) in cases.iter().enumerate() {
        let effects = effects[i % effects.len()];
        let sums = e.weighted(job, &effects, SampleRange::whole(9, n), Specialisation::Specialised).unwrap().sums;
        let c = albedo_check(job, &effects, &sums, n, level, &Quadrature::default());
        println!("{job:?} {effects:?}: {c:?}");
        assert!(c.passed, "{job:?} {effects:?}: {c:?}");
        assert!(c.max_weight_error <= WEIGHT_ERROR_LIMIT, "{job:?}: weight error {}", c.max_weight_error);
        let cpu = lobes::engine::cpu::weighted(job, &effects, SampleRange::whole(9, n));
        let (a, b) = (sums.albedo(n), cpu.albedo(n));
        assert!((a - b).abs() < 1e-5 * b, "{job:?}: GPU {a} vs CPU {b}");
        assert!(cpu.max_weight_error() < 1e-9, "f64 weight check: {}", cpu.max_weight_error());
        let uber = e.weighted(job, &effects, SampleRange::whole(9, n), Specialisation::Uber).unwrap().sums;
        assert!((uber.albedo(n) - a).abs() < 1e-6 * a, "{job:?}: uber {} vs specialised {a}", uber.albedo(n));
    }
}
