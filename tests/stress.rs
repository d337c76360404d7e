//! The stability suite (`lobes stress`) as tests: every sampler at the inputs where naive
//! formulas break, on the GPU (f32) and the CPU (f64), the rough dielectric's hard cases and
//! broken copies of its WGSL caught, plus the discrete hard cases.

use lobes::engine::gpu::GpuEngine;
use lobes::engine::job::{DiscreteMethod, Job, SampleRange, Scatter};
use lobes::reference::discrete::Distribution;
use lobes::run::compare;
use lobes::stats::expected::Quadrature;

fn engine() -> GpuEngine {
    GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"))
}

#[test]
fn every_sampler_is_stable_at_the_hard_inputs() {
    let mut e = engine();
    let rows = lobes::experiments::stress::run_all(Some(&mut e)).unwrap();
    assert_eq!(rows.len(), 2 * lobes::experiments::stress::cases().len());
    let failed: Vec<_> = rows.iter().filter(|r| !r.passed).map(|r| format!("{} [{}]", r.case, r.kernel)).collect();
    assert!(failed.is_empty(), "unstable: {failed:?}");
    // the suite exercises invalid samples too (u at 0 and 1, grazing and below-horizon light)
    assert!(rows.iter().any(|r| r.valid < r.samples));
    // the rough dielectric's rows: GGX and Beckmann × NDF and visible normals, 30 cases each, on
    // the GPU and the CPU, every GPU row with densities compared
    let glass: Vec<_> = rows.iter().filter(|r| r.case.contains(" glass ")).collect();
    assert_eq!(glass.len(), 2 * 4 * 30);
    assert!(glass.iter().filter(|r| r.kernel == "gpu f32").all(|r| r.worst_pdf_error > 0.0 && r.valid > 0));
}

fn gpu_counts(e: &mut GpuEngine, weights: &[f64], method: DiscreteMethod, n: u64) -> (Distribution, Vec<u64>) {
    let dist = Distribution::new(weights).unwrap();
    let job = Job::Discrete { dist: dist.clone(), method };
    let r = e.histogram(&job, SampleRange::whole(17, n), &mut |_| {}).unwrap();
    assert_eq!(r.counts.total(), n);
    assert_eq!(r.counts.invalid, [0; lobes::reference::Invalid::COUNT]);
    (dist, r.counts.bins)
}

#[test]
fn discrete_hard_cases() {
    let mut e = engine();
    for method in [DiscreteMethod::Cdf, DiscreteMethod::Alias] {
        // one nonzero weight takes every sample
        let (_, c) = gpu_counts(&mut e, &[0.0, 0.0, 3.0, 0.0, 0.0], method, 1_000_000);
        assert_eq!(c, vec![0, 0, 1_000_000, 0, 0], "{method:?}");
        // zeros at both ends and in between are never selected
        let w = [0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 3.0, 0.0];
        let (_, c) = gpu_counts(&mut e, &w, method, 1_000_000);
        for (k, &x) in w.iter().enumerate() {
            assert_eq!(x == 0.0, c[k] == 0, "{method:?} index {k}");
        }
        // weights spanning 1e-30 to 1e30: the huge one takes (almost) all
        let (_, c) = gpu_counts(&mut e, &[1e-30, 1.0, 1e30, 0.0], method, 1_000_000);
        assert_eq!(c[2], 1_000_000, "{method:?}: {c:?}");
    }
}

/// 2^24 + 1 entries: beyond one 24-bit uniform and an f32 CDF. The two-level CDF and the alias
/// table both reproduce the distribution (χ² over the pooled cells).
#[test]
fn tables_beyond_f32_resolution() {
    let mut e = engine();
    let n = (1 << 24) + 1;
    // a ramp, so that neighbouring entries differ and every entry matters
    let mut w: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
    w[n - 1] = 1000.0; // the entry past 2^24 must be reached, often
    w[n - 2] = 0.0; // and a zero next to it never
    for method in [DiscreteMethod::Cdf, DiscreteMethod::Alias] {
        let samples = 1 << 25;
        let (dist, c) = gpu_counts(&mut e, &w, method, samples);
        let job = Job::Discrete { dist, method };
        let exp = compare::expected_counts(&job, samples, &Quadrature::default());
        let counts = lobes::engine::job::Counts { bins: c, invalid: [0; lobes::reference::Invalid::COUNT] };
        let t = compare::chi2_test(&counts, &exp, 0.001);
        assert!(t.passed, "{method:?}: χ² {} / {} p {}", t.statistic, t.dof, t.p_value);
        // the last entry, beyond 2^24, is reached
        let (got, want) = (counts.bins[n - 1] as f64, exp.bins[n - 1]);
        assert!((got - want).abs() < 5.0 * want.sqrt(), "{method:?}: last entry {got}, expected {want}");
        assert_eq!(counts.bins[n - 2], 0);
    }
}

/// Directions exactly on bin edges, at the poles and at φ = ±π: the GPU's f32 binning lands
/// every one in a valid bin, agrees with the CPU's at the poles and at φ = ±π exactly, and
/// elsewhere within one row or column (an edge is a tie that f32 and f64 may break apart).
#[test]
fn binning_at_edges_poles_and_the_seam() {
    use lobes::reference::{Lobe, LobeKind, Method};
    use lobes::stats::histogram::SphereGrid;
    let mut e = engine();
    let grid = SphereGrid { rows: 64, cols: 128 };
    let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Ndf, alpha_x: 0.5, alpha_y: 0.5, alpha_angle: 0.0 };
    let job = Job::Lobe { lobe, incident: glam::DVec3::Z, grid, scatter: Scatter::Reflect };
    let mut dirs: Vec<[f32; 3]> = Vec::new();
    for z in grid.cos_theta_edges() {
        for phi in grid.phi_edges() {
            let s = (1.0 - z * z).max(0.0).sqrt();
            dirs.push([(s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32]);
        }
    }
    let exact = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [-1.0, -0.0, 0.0], [-0.6, 0.0, 0.8], [-0.6, -0.0, -0.8]];
    dirs.extend(exact);
    let gpu = e.bins_of(&job, &dirs).unwrap();
    let cols = grid.cols as i64;
    for (d, &g) in dirs.iter().zip(&gpu) {
        assert!((g as usize) < grid.bins(), "{d:?} → bin {g}");
        let c = grid.bin_of(glam::DVec3::new(d[0] as f64, d[1] as f64, d[2] as f64)) as i64;
        let (dr, dc) = ((g as i64 / cols - c / cols).abs(), (g as i64 % cols - c % cols).rem_euclid(cols));
        assert!(dr <= 1 && (dc <= 1 || dc == cols - 1), "{d:?}: gpu bin {g}, cpu bin {c}");
    }
    let n = dirs.len();
    let tail: Vec<u32> = gpu[n - exact.len()..].to_vec();
    // +z: top row, φ = 0 → column 64; −z: row 0; φ = ±π (either sign of zero) → column 0
    assert_eq!(tail, vec![63 * 128 + 64, 64, 32 * 128, 32 * 128, 57 * 128, 6 * 128]);
}

/// A mirror lobe narrower than f32 binning's rounding, on an edge of the grid that lies on an
/// axis (issue 24): GGX visible normals at α 1e-4, θi 89°, 10⁶ samples, 64 × 128 bins. Across
/// the plane of incidence the lobe is about 2α cos θi wide (the f32 directions' median |y| is
/// 2e-6 at φi 0), while t = (φ + π)/2π rounds onto a column's edge from half an ulp below it
/// (1.8e-7 rad at φ = π): before the sign test of `bin_of`, φi 0 split the lobe 510 066 to
/// 489 934 between the seam's columns (χ² 301 on 6 dof, a false failure; the f64 engine
/// passed). With it the f32 engine passes with the mirror on the seam (φi 0), on φ = 0 (φi π)
/// and on φ = −π/2 (φi π/2), and a lobe turned off the plane of incidence by 1e-7 rad (1/20 of
/// its median |y|: a sampler whose frame is that far off) fails against the untouched lobe.
#[test]
fn a_grazing_lobe_on_an_axis_edge_is_split_as_sampled() {
    use lobes::reference::reflect::spherical;
    use lobes::reference::{Lobe, LobeKind, Method};
    use lobes::stats::histogram::SphereGrid;
    const N: u64 = 1_000_000;
    let mut e = engine();
    let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Vndf, alpha_x: 1e-4, alpha_y: 1e-4, alpha_angle: 0.0 };
    let theta = 89f64.to_radians();
    let job = |phi: f64| Job::Lobe { lobe, incident: spherical(theta, phi), grid: SphereGrid { rows: 64, cols: 128 }, scatter: Scatter::Reflect };
    let phis = [0.0, std::f64::consts::PI, std::f64::consts::FRAC_PI_2];
    let level = lobes::stats::chi2::sidak(0.01, phis.len());
    for phi in phis {
        let exp = compare::expected_counts(&job(phi), N, &Quadrature::default());
        let counts = e.histogram(&job(phi), SampleRange::whole(7, N), &mut |_| {}).unwrap().counts;
        let t = compare::chi2_test(&counts, &exp, level);
        assert!(t.passed, "φi {phi}: a correct f32 sampler failed: {t:?}");
        assert!(t.dof >= 1, "φi {phi}: the edge must split the lobe into two cells: {t:?}");
        if phi == 0.0 {
            let turned = e.histogram(&job(1e-7), SampleRange::whole(7, N), &mut |_| {}).unwrap().counts;
            let t = compare::chi2_test(&turned, &exp, 0.01);
            assert!(!t.passed && t.untested.is_none(), "a lobe turned by 1e-7 rad passed: {t:?}");
            eprintln!("turned 1e-7 rad: χ² {:.1} on {} dof", t.statistic, t.dof);
        }
    }
}

/// A seeded random search beyond the listed cases: roughness log-uniform in [1e-6, 10] with
/// anisotropy up to 1000:1, incidence from 0° to 90°, every sampler; the same assertions as
/// the suite.
#[test]
fn random_search_beyond_the_listed_cases() {
    use lobes::reference::{Lobe, reflect, rng};
    use lobes::experiments::stress::{SAMPLERS as samplers, StressCase, run_case};
    let mut e = engine();
    let mut failed = Vec::new();
    for i in 0..120u64 {
        let r = rng::uniforms(2024, i);
        let (kind, method) = samplers[i as usize % samplers.len()];
        let ax = 10f64.powf(-6.0 + 7.0 * r[0]);
        // anisotropy up to 1000:1 either way (beyond it, at grazing incidence, the f32 cap rim
        // near the antipode of ωs loses the direction: seen at 25000:1, not handled yet)
        let ay = if i % 3 == 0 { ax } else { (ax * 10f64.powf(3.0 * (2.0 * r[1] - 1.0))).clamp(1e-6, 10.0) };
        let wi = reflect::spherical((90.0 * r[2]).to_radians(), 360f64.to_radians() * r[3]);
        let case = StressCase { name: format!("random {i}: {kind:?} {method:?} α ({ax:.3e}, {ay:.3e}) ωi {wi:?}"), lobe: Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 }, incident: wi, scatter: Scatter::Reflect };
        for row in run_case(&case, Some(&mut e)).unwrap() {
            if !row.passed {
                failed.push(format!("{} [{}]: {:?}", row.case, row.kernel, row));
            }
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// The suite catches a broken rough dielectric on the GPU: a copy of
/// `shaders/lib/dielectric.wgsl` put in place of the built-in one fails the dielectric rows
/// that its error shows in, by the check that should see it, while the built-in one passes
/// them all (`every_sampler_is_stable_at_the_hard_inputs`).
/// - Eq. 17 as Walter writes it, η² cos θt / (c − η cos θt)²: the difference cancels as η → 1,
///   and at η = 1 ± 1e-6 the f32 density is off by ~25 %, 250 times what the density check
///   allows (at 1 ± 1e-3 it keeps enough digits to pass).
/// - A refraction without the test for total internal reflection: past the critical angle F = 1,
///   so only u.z = 1 refracts, along a direction that is no unit vector and does not agree
///   with f64's reflection.
#[test]
fn broken_dielectrics_are_caught() {
    use lobes::engine::gpu::library::{self, File};
    use lobes::experiments::stress::{dielectric_cases, run_case};
    let text = library::source("lobes::dielectric").unwrap();
    let edit = |from: &str, to: &str| {
        assert!(text.contains(from), "shaders/lib/dielectric.wgsl no longer has `{from}`");
        text.replace(from, to)
    };
    let naive = edit("return eta * eta * ct * s * s / (k * k);", "let d = c - eta * ct;\n    return eta * eta * ct / (d * d);");
    let no_tir = edit("if (c <= 0.0 || ct < 0.0 || u < f) {", "if (c <= 0.0 || u < f) {");
    let cases = dielectric_cases();
    let mut e = engine();
    for (what, broken, must_fail) in [("eq. 17 as written", naive, "1e-6 a"), ("no TIR test", no_tir, "past-critical")] {
        e.replaced = vec![File::generated(format!("shaders/lib/dielectric.wgsl, {what}"), broken)];
        let mut failed = Vec::new();
        for case in &cases {
            let rows = run_case(case, Some(&mut e)).unwrap();
            let gpu = rows.iter().find(|r| r.kernel == "gpu f32").unwrap();
            if !gpu.passed {
                failed.push((case.name.clone(), gpu.clone()));
            }
        }
        let names: Vec<&str> = failed.iter().map(|(n, _)| n.as_str()).collect();
        for case in cases.iter().filter(|c| c.name.contains(must_fail)) {
            assert!(names.contains(&case.name.as_str()), "{what}: `{}` passed; failed: {names:?}", case.name);
        }
        eprintln!("{what}: {} of {} dielectric rows fail: {names:?}", failed.len(), cases.len());
        // and by the check that should see it
        for (name, row) in failed.iter().filter(|(n, _)| n.contains(must_fail)) {
            match what {
                "eq. 17 as written" => assert!(row.worst_pdf_error > 1.0, "{what}: {name}: {row:?}"),
                _ => assert!(row.worst_unit_error > lobes::experiments::stress::UNIT_BOUND_F32 && row.validity_mismatches > 0, "{what}: {name}: {row:?}"),
            }
        }
    }
}

/// The light samplers' hard cases (`lobes stress`'s light table): every light at 10⁻⁶ sr, on the
/// horizon and near its largest size, sliver and collinear triangles, rectangles and a disk
/// seen edge-on, a shading point inside and on a sphere: no NaN, no negative pdf, unit
/// directions, and the pdf function at each interior sample equal to the pdf reported with it,
/// on the GPU (f32) and in the f64 twins. And the checks bite: a copy of the sphere's cone whose
/// 1 − cos θmax is taken as 1 − sqrt(1 − sin²) (no stable form) is inconsistent at 10⁻⁶ sr.
#[test]
fn every_light_is_stable_at_its_hard_cases() {
    use lobes::check::light::LightPasses;
    use lobes::experiments::light_stress::{light_cases, run_all_lights, run_light_case};
    let e = engine();
    let rows = run_all_lights(Some(&e.gpu)).unwrap();
    assert_eq!(rows.len(), 2 * light_cases().len(), "a CPU and a GPU row per case");
    let failed: Vec<_> = rows.iter().filter(|r| !r.passed).collect();
    assert!(failed.is_empty(), "{failed:#?}");
    assert!(rows.iter().all(|r| r.bad_values == 0), "no NaN, no negative pdf, also in the degenerate cases");
    // the tiny cases are judged, not skipped: every sample valid, every interior one consistent
    let tiny = rows.iter().find(|r| r.case == "rect-1e-6sr" && r.kernel == "gpu f32").unwrap();
    assert_eq!((tiny.valid, tiny.inconsistent), (tiny.samples, 0), "{tiny:?}");
    // a broken cone: 1 − cos θmax as 1 − sqrt(1 − sin²θmax), which f32 rounds to 0 or 2⁻²⁴'s
    // multiples at 10⁻⁶ sr, in the pdf function only
    let mut case = light_cases().into_iter().find(|c| c.name == "sphere-1e-6sr").unwrap();
    let naive = "select(0.0, 1.0 / (2.0 * 3.14159265 * (1.0 - sqrt(1.0 - params[0].w * params[0].w / dot(params[0].xyz, params[0].xyz)))), sphere_light_pdf(params[0].xyz, params[0].w, d) > 0.0)";
    let broken = Box::leak(Box::new(lobes::reference::light::registry::LightSpec { pdf: naive, ..*case.light }));
    case.light = broken;
    let rows = run_light_case(&case, Some(&LightPasses::new(&e.gpu, case.light).unwrap())).unwrap();
    let gpu = rows.iter().find(|r| r.kernel == "gpu f32").unwrap();
    assert!(!gpu.passed && gpu.inconsistent + gpu.bad_values > gpu.interior / 2, "{gpu:?}");
}
