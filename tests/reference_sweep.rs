//! The f64 reference's expected histograms over the documented range of every shipped sampler
//! (α from [`MIN_ALPHA`] to 2, θi 0–89°), judged as `lobes run --cpu` judges (issue 24 items 2
//! and 3): each quadrature converged ([`compare::converged`]), its mass in the bins equal to
//! 1 − P(below the horizon) computed independently over h in stretched-slope coordinates
//! (`reference_quadrature`), and the f64 engine's histogram of the same case never failed by
//! it. A narrow lobe that fits in a bin or two leaves the χ² no cells to compare: such a case is
//! untested ([`Untested`]), never a pass. The same histograms against the density of a lobe 20 %
//! rougher (a broken sampler) fail wherever the lobe spans more than a few cells of the 32 × 64
//! grid (α ≥ 0.1, every θi); at α ≤ 0.01 the lobe and its rougher twin fill the same one to four
//! cells, and the rougher one passed in 32 of the 192 judged cases (measured: every one at α ≤
//! 0.01): a limit of the grid's resolution, not of the reference.

use crate::reference_quadrature;

use glam::DVec3;
use lobes::engine::cpu;
use lobes::engine::job::{Job, SampleRange, Scatter};
use lobes::reference::reflect::{reflect, spherical};
use lobes::reference::{Lobe, Method, SAMPLERS};
use lobes::run::compare;
use lobes::stats::chi2::{Untested, sidak};
use lobes::stats::expected::{MIN_ALPHA, Quadrature};
use lobes::stats::histogram::SphereGrid;
use reference_quadrature::{Cuts, Hemisphere};

const ALPHAS: [f64; 7] = [MIN_ALPHA, 1e-3, 1e-2, 0.1, 0.5, 1.0, 2.0];
const THETA_I_DEG: [f64; 5] = [0.0, 30.0, 60.0, 80.0, 89.0];
const SAMPLES: u64 = 1_000_000;
const GRID: SphereGrid = SphereGrid { rows: 32, cols: 64 };

/// The probability of a valid sample, 1 − P(below the horizon): ∫ pdf_h over the h whose
/// reflection of ωi is above it (for the bounded VNDF, whose `pdf_h` is that of its valid
/// samples, split where its cap ends; k from Eto & Tokuyoshi's listing 1, as in
/// `reference_normalization.rs`).
fn mass_above(l: &Lobe, wi: DVec3) -> f64 {
    let cap = (l.method == Method::Bounded).then(|| {
        let a = l.alpha_x.min(l.alpha_y).clamp(0.0, 1.0);
        let s = 1.0 + (wi.x * wi.x + wi.y * wi.y).sqrt();
        let k = (1.0 - a * a) * s * s / (s * s + a * a * wi.z * wi.z);
        let ws = DVec3::new(l.alpha_x * wi.x, l.alpha_y * wi.y, wi.z).normalize();
        (ws, k * ws.z)
    });
    let cuts = Cuts { wi: Some(wi), cap };
    Hemisphere::new(l.alpha_x, l.alpha_y, 16, 16, 1).integrate(&cuts, |h| if reflect(wi, h).z > 0.0 { l.pdf_h(wi, h) } else { 0.0 })
}

#[derive(Default, Debug)]
struct Tally {
    passed: u32,
    failed: u32,
    untested: u32,
}

impl Tally {
    fn add(&mut self, t: &lobes::stats::chi2::Chi2) {
        match (t.passed, t.untested) {
            (true, _) => self.passed += 1,
            (false, Some(_)) => self.untested += 1,
            (false, None) => self.failed += 1,
        }
    }
}

#[test]
fn the_reference_converges_and_judges_over_the_documented_range() {
    let cases = SAMPLERS.len() * ALPHAS.len() * THETA_I_DEG.len();
    let level = sidak(0.01, cases);
    let (mut correct, mut broken) = (Tally::default(), Tally::default());
    let mut worst_sigma: f64 = 0.0;
    let mut worst_closure: f64 = 0.0;
    let mut wide_rougher_passed = Vec::new();
    for (seed, (kind, method)) in SAMPLERS.into_iter().enumerate() {
        for alpha in ALPHAS {
            for theta in THETA_I_DEG {
                let wi = spherical(theta.to_radians(), 0.7);
                let lobe = Lobe { kind, method, alpha_x: alpha, alpha_y: alpha, alpha_angle: 0.0 };
                let job = Job::Lobe { lobe, incident: wi, grid: GRID, scatter: Scatter::Reflect };
                let tag = format!("{} {} α {alpha} θi {theta}°", kind.name(), method.name());
                let exp = compare::expected_counts(&job, SAMPLES, &Quadrature::default());
                compare::converged(&exp, SAMPLES).unwrap_or_else(|e| panic!("{tag}: {e}"));
                let q = exp.quadrature.as_ref().unwrap();
                worst_sigma = worst_sigma.max(q.max_error_sigma_at(SAMPLES));
                let mass: f64 = q.probabilities.iter().sum();
                let closure = (mass - mass_above(&lobe, wi)).abs();
                assert!(closure <= q.error_estimate + 1e-9, "{tag}: Σ bins {mass} against 1 − P(below) off by {closure:e} (error estimate {:e})", q.error_estimate);
                worst_closure = worst_closure.max(closure);
                let counts = cpu::histogram(&job, SampleRange::whole(seed as u64 + 1, SAMPLES));
                let t = compare::chi2_test(&counts, &exp, level);
                assert!(t.passed || t.untested == Some(Untested::OneCell), "{tag}: a correct sampler failed: {t:?}");
                correct.add(&t);
                if t.untested.is_some() {
                    // a lobe in one cell: the same cells judge no lobe, rougher or not
                    broken.untested += 1;
                    continue;
                }
                let rough = Lobe { alpha_x: 1.2 * alpha, alpha_y: 1.2 * alpha, ..lobe };
                let wrong = compare::expected_counts(&Job::Lobe { lobe: rough, incident: wi, grid: GRID, scatter: Scatter::Reflect }, SAMPLES, &Quadrature::default());
                let t = compare::chi2_test(&counts, &wrong, level);
                eprintln!("{tag}: dof {} correct p {:.3e}; 20 % rougher p {:.3e} {:?}", t.dof, correct_p(&counts, &exp, level), t.p_value, t.untested);
                broken.add(&t);
                if t.passed && alpha >= 0.1 {
                    wide_rougher_passed.push(tag);
                }
            }
        }
    }
    eprintln!("{cases} cases at level {level:.2e}: correct {correct:?}; 20 % rougher {broken:?}; worst quadrature error {worst_sigma:.3}σ at 10⁶; worst closure {worst_closure:.2e}");
    assert_eq!(correct.failed, 0);
    assert!(wide_rougher_passed.is_empty(), "a lobe 20 % rougher passed where the lobe spans many cells: {wide_rougher_passed:?}");
}

fn correct_p(counts: &lobes::engine::job::Counts, exp: &compare::ExpectedCounts, level: f64) -> f64 {
    compare::chi2_test(counts, exp, level).p_value
}

/// Issue 24 item 3: GGX VNDF at α = 1e-8, θi 30°, 10⁶ samples (below [`MIN_ALPHA`], so a scene
/// refuses it, but the library takes it): the quadrature's nodes slipped past the peak and put
/// 83.7 % of the mass below the horizon, and the f64 engine failed against its own reference
/// (χ² = 515 163 on 2 dof). Cut toward the mirror direction, the bins hold the mass, the
/// quadrature has converged, and the f64 engine passes (χ² 0.04 on 1 dof: the lobe's bin and the
/// pooled rest).
#[test]
fn a_lobe_narrower_than_the_nodes_is_resolved() {
    use lobes::reference::LobeKind;
    let wi = spherical(30f64.to_radians(), 0.0);
    let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Vndf, alpha_x: 1e-8, alpha_y: 1e-8, alpha_angle: 0.0 };
    let job = Job::Lobe { lobe, incident: wi, grid: SphereGrid { rows: 64, cols: 128 }, scatter: Scatter::Reflect };
    let exp = compare::expected_counts(&job, SAMPLES, &Quadrature::default());
    let q = exp.quadrature.as_ref().unwrap();
    assert!(q.below_horizon < 1e-9, "below the horizon: {}", q.below_horizon);
    compare::converged(&exp, SAMPLES).unwrap();
    let counts = cpu::histogram(&job, SampleRange::whole(1, SAMPLES));
    let t = compare::chi2_test(&counts, &exp, 0.01);
    assert!(t.passed && t.dof >= 1, "{t:?}");
}

/// A grazing mirror lobe on the φ = ±π seam of the default 64 × 128 grid (Ward, Beckmann, GGX at
/// α 1e-4, θi 89°, φi 0): across the plane of incidence the lobe is cos θi (57 times) narrower
/// than within it, and cut only to its in-plane width the quadrature lost 1.3e-4 of the mass
/// there (134 samples expected below the horizon of 10⁶, none drawn). (On lavapipe the same case
/// failed too, χ² 405 on 1 dof, by the f32 binning's rounding at the seam, until the seam's
/// column was decided by the sign of y: tests/stress.rs, docs/statistics.md.)
#[test]
fn a_grazing_lobe_on_the_seam_keeps_its_mass() {
    let wi = spherical(89f64.to_radians(), 0.0);
    for (kind, method) in SAMPLERS {
        let lobe = Lobe { kind, method, alpha_x: MIN_ALPHA, alpha_y: MIN_ALPHA, alpha_angle: 0.0 };
        let job = Job::Lobe { lobe, incident: wi, grid: SphereGrid { rows: 64, cols: 128 }, scatter: Scatter::Reflect };
        let exp = compare::expected_counts(&job, SAMPLES, &Quadrature::default());
        compare::converged(&exp, SAMPLES).unwrap();
        let q = exp.quadrature.as_ref().unwrap();
        let mass: f64 = q.probabilities.iter().sum();
        let closure = (mass - mass_above(&lobe, wi)).abs();
        assert!(closure <= q.error_estimate + 1e-9, "{kind:?} {method:?}: Σ bins {mass}, off by {closure:e}");
        let t = compare::chi2_test(&cpu::histogram(&job, SampleRange::whole(1, SAMPLES)), &exp, 1e-4);
        assert!(t.passed || t.untested.is_some(), "{kind:?} {method:?}: {t:?}");
    }
}
