//! lobes' built-in light samplers (issue 33 item 4: sphere, disk, spherical triangle,
//! area-uniform triangle, spherical rectangle; `lobes::reference::light::registry::LIGHTS`):
//! - each judged by `lobes check` as a user's light sampler would be (`UserSampler::light`) at
//!   10⁻⁶ sr (at 45°), 10⁻² sr on the horizon or 3 sr overhead (with scenes/lights.toml's
//!   cases in tests/user_scene.rs, every light at two of them): every check passes;
//! - broken variants (a pdf left per unit area at 10⁻² sr, a 5 % warp of u at 10⁻⁶ sr) fail by
//!   the checks that should catch them;
//! - the WGSL's samples and densities equal the f64 twins' for the same u and geometry;
//! - the f64 twins against independent values: ∫pdf dω = 1 by the f64 sphere quadrature
//!   (`check::quadrature::sphere_integral_f64`), and the map u → d preserves measure,
//!   pdf(d) |∂d/∂u0 × ∂d/∂u1| = 1 by central differences.
//!
//! GPU tests: they need a wgpu adapter (lavapipe in CI) and fail without one.

use glam::DVec3;
use lobes::check::light::wrapper;
use lobes::check::quadrature::sphere_integral_f64;
use lobes::check::report::NormalizationFigures;
use lobes::check::{Settings, UserSampler, check};
use lobes::embed::Module;
use lobes::engine::gpu::Gpu;
use lobes::check::light::{LightDraw, LightPasses};
use lobes::reference::light::registry::{LIGHTS, LightParams, LightSpec, by_name};

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"))
}

/// (solid angle in sr, elevation in degrees): tiny at 45°, small on the horizon, large overhead.
const SIZES: [(f64, f64); 3] = [(1e-6, 45.0), (1e-2, 0.0), (3.0, 90.0)];

/// The sizes each light is judged at here, to keep the test near 10 s on two cores (a check
/// costs ~1.7 s on lavapipe, mostly fixed costs): those scenes/lights.toml does not judge
/// (tests/user_scene.rs: a sphere of 10⁻⁶ sr, a rectangle on the horizon, a triangle of 2.4 sr
/// overhead, a disk of 0.28 sr).
fn judged_sizes(name: &str) -> &'static [(f64, f64)] {
    match name {
        "sphere" => &[SIZES[1]],
        "triangle-area" => &[SIZES[0], SIZES[2]],
        _ => &[SIZES[0]],
    }
}

fn settings(p: &LightParams, samples: u64) -> Settings {
    Settings { params: p.to_vec(), samples, seed: 7, ..Settings::default() }
}

#[test]
fn every_light_passes_lobes_check_at_every_size_and_place() {
    let gpu = gpu();
    let significance = 1.0 - 0.99f64.powf(1.0 / 6.0);
    let mut failures = Vec::new();
    for spec in &LIGHTS {
        let sampler = UserSampler::light(spec);
        for &(omega, elevation) in judged_sizes(spec.name) {
            let p = spec.sized(omega, elevation);
            let r = check(&gpu, &sampler, &Settings { significance, ..settings(&p, 1 << 16) }).unwrap_or_else(|e| panic!("{}: {e}", spec.name));
            for c in &r.checks {
                eprintln!("{} {omega} sr at {elevation}°: {} {} {}", spec.name, c.name(), if c.passed { "pass" } else { "FAIL" }, c.summary);
            }
            let n = r.figures::<NormalizationFigures>().expect("a normalization check");
            if !r.passed || (n.pdf_integral - 1.0).abs() > 1e-3 {
                failures.push(format!("{} {omega} sr at {elevation}°: failed {:?}, ∫pdf {}", spec.name, r.failed(), n.pdf_integral));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A corner of a spherical triangle on the horizon lies in the outermost row of the cap fitted to
/// it, where the quadrature must start from parts fine enough to see the corner's wedge
/// (`lobes::check::quadrature::CAP_PARTS_PER_ROW`): with the bin as one part, ∫pdf came out
/// 0.999954 and `normalization` failed this correct light at 2¹⁸ samples, seed 7. Its f32 pdf
/// integrates to 1.00002 (1/Ω rounded), so the bound is 3·10⁻⁵ against the closed form's 1.
#[test]
fn a_corner_in_the_caps_outer_row_keeps_its_mass() {
    let gpu = gpu();
    let spec = by_name("triangle").unwrap();
    let p = spec.sized(1e-2, 0.0);
    let r = check(&gpu, &UserSampler::light(spec), &settings(&p, 1 << 18)).unwrap_or_else(|e| panic!("{e}"));
    let n = r.figures::<NormalizationFigures>().expect("a normalization check");
    assert!(r.passed, "{:?}", r.failed());
    assert!((n.pdf_integral - 1.0).abs() < 3e-5, "∫pdf {} against 1", n.pdf_integral);
}

/// A rectangle light of 10⁻⁴ sr overhead: its f32 pdf integrates to 1.00002, its f32 solid angle
/// being within 2·10⁻⁷ of the f64 one and the rest where f32 places its edges (an ulp of a unit
/// vector, 1.2·10⁻⁷ rad, against sides of 10⁻² rad); `normalization` failed it at 2¹⁸ samples,
/// seed 7 (and at 2²⁰, seeds 1 and 2), until its tolerance held that (`direction_sensitivity`).
/// Its pdf made 10⁻³ too large still fails.
#[test]
fn a_small_lights_edges_in_f32_are_in_the_tolerance_and_a_wrong_pdf_is_not() {
    let gpu = gpu();
    let spec = by_name("rect").unwrap();
    let p = spec.sized(1e-4, 90.0);
    let run = |pdf: &str| {
        let sampler = UserSampler::light_with(spec, &wrapper(spec, spec.sample, pdf));
        check(&gpu, &sampler, &settings(&p, 1 << 18)).unwrap_or_else(|e| panic!("{e}"))
    };
    let r = run(spec.pdf);
    let n = r.figures::<NormalizationFigures>().expect("a normalization check");
    assert!(r.passed, "{:?}: {n:?}", r.failed());
    assert!((n.pdf_integral - 1.0).abs() < 1e-4, "∫pdf {} against 1", n.pdf_integral);
    let r = run(&format!("1.001 * {}", spec.pdf));
    assert!(r.failed().contains(&"normalization"), "{:?}", r.failed());
}

/// A sliver of a triangle lying on the surface's plane (its long edge, 0.6 rad, in the plane
/// cos θ = 0 that the sphere grid's middle row edge lies in; 3·10⁻³ deep below it): f32 puts a
/// few of the samples on that edge at cos θ ≥ 0 (8 of 2¹⁸ at seed 1, where the density is 0 by
/// its own f64 and f32 integrals), and `chi2` failed this correct light ("samples in cells of zero
/// probability") at seeds 1 and 2, until the row edges closer to the pdf's mass than f32
/// resolves joined their bins (`quadrature::join_unresolved_edges`). The same sliver sampled
/// with a 5 % warp of u.x still fails.
#[test]
fn a_sliver_on_the_surfaces_plane_is_judged_across_the_horizon() {
    let gpu = gpu();
    let spec = by_name("triangle").unwrap();
    let (axis, along) = (DVec3::new(0.75f64.sqrt(), 0.5, 0.0), DVec3::new(0.5, -(0.75f64.sqrt()), 0.0));
    let mut p: LightParams = [0.0; 16];
    for (k, v) in [axis + 0.3 * along, axis - 0.3 * along, axis - DVec3::new(0.0, 0.0, 3e-3)].into_iter().enumerate() {
        p[4 * k..4 * k + 3].copy_from_slice(&v.to_array());
    }
    for seed in [1, 2] {
        let r = check(&gpu, &UserSampler::light(spec), &Settings { seed, ..settings(&p, 1 << 18) }).unwrap_or_else(|e| panic!("{e}"));
        let chi2 = r.figures::<lobes::check::report::Chi2Figures>().expect("a chi2 check");
        assert!(r.passed, "seed {seed}: {:?}: {}", r.failed(), r.get("chi2").unwrap().summary);
        assert!(chi2.joined_row_edges >= 1 && chi2.chi2.dof >= 8, "{chi2:?}");
    }
    let warped = spec.sample.replace("u)", "vec2<f32>(u.x * (1.05 - 0.05 * u.x), u.y))");
    let f = failed_with(&gpu, spec, &warped, spec.pdf, &p);
    assert!(f.contains(&"jacobian"), "{f:?}");
}

/// A spherical triangle along the row of the sphere's grid at 45° elevation, azimuth 30°: its
/// long edge 2 `half` rad, its third vertex `width` rad across from the edge's middle.
fn sliver(half: f64, width: f64) -> LightParams {
    let (e, az) = (45f64.to_radians(), 30f64.to_radians());
    let axis = DVec3::new(e.cos() * az.cos(), e.cos() * az.sin(), e.sin());
    let along = axis.cross(DVec3::Z).normalize();
    let across = axis.cross(along);
    let mut p: LightParams = [0.0; 16];
    for (k, v) in [axis + half * along, axis - half * along, axis + width * across].into_iter().enumerate() {
        p[4 * k..4 * k + 3].copy_from_slice(&v.to_array());
    }
    p
}

/// A sliver of a triangle, 0.6 × 3·10⁻⁴ rad, at 45° elevation, lying along a row of the sphere's
/// grid: it passes between every node of most of the quadrature's parts it crosses, and its
/// bins' integrals summed to 0.970 (0.70 before the retries), where the pdf 1/Ω integrates to 1 over
/// the triangle; `normalization` and `chi2` failed it at seeds 1 and 2 until the parts that hold a
/// sample and whose rules give 0 were split (`stats::quadrature::Witnesses`).
#[test]
fn a_sliver_between_the_quadratures_nodes_keeps_its_mass() {
    let gpu = gpu();
    let spec = by_name("triangle").unwrap();
    let p = sliver(0.3, 3e-4);
    let r = check(&gpu, &UserSampler::light(spec), &Settings { seed: 1, ..settings(&p, 1 << 16) }).unwrap_or_else(|e| panic!("{e}"));
    let n = r.figures::<NormalizationFigures>().expect("a normalization check");
    assert!(r.passed, "{:?}: {n:?}", r.failed());
    assert!((n.pdf_integral - 1.0).abs() < 1e-3, "∫pdf {} against 1", n.pdf_integral);
}

/// A tapering sliver of a triangle, 0.2 × 3·10⁻⁴ rad at 45° (its third vertex over the long
/// edge's middle, so both ends taper to a point): the tips, thinner than the finest parts the
/// first 2¹⁶ witnesses lead to, hid mass (a tip's cell expected 1.3 samples where 14 were
/// observed) and the check drew no verdict at seeds 1–2, 2¹⁶ and 2¹⁸ samples; the bins where
/// such a support was found are now integrated again as far as 2²² witnesses lead
/// (`quadrature::Evidence::denser`), and the correct light passes with ∫pdf 1.000045–1.000057
/// (seeds 1–3, 2¹⁶ and 2¹⁸ samples); the same light with a 5 % warp of u.x fails `chi2` at 2¹⁸
/// (Holm p 1.1·10⁻⁴; at this width its Jacobian is unresolved in f32, and at 2¹⁶ the warp passes).
#[test]
fn a_tapering_sliver_gets_a_verdict() {
    let gpu = gpu();
    let spec = by_name("triangle").unwrap();
    let p = sliver(0.1, 3e-4);
    let r = check(&gpu, &UserSampler::light(spec), &Settings { seed: 1, ..settings(&p, 1 << 16) }).unwrap_or_else(|e| panic!("{e}"));
    let n = r.figures::<NormalizationFigures>().expect("a normalization check");
    assert!(r.passed, "{:?}: {n:?}", r.failed());
    assert!((n.pdf_integral - 1.0).abs() < 2e-4, "∫pdf {} against 1", n.pdf_integral);
    let warped = spec.sample.replace("u)", "vec2<f32>(u.x * (1.05 - 0.05 * u.x), u.y))");
    let sampler = UserSampler::light_with(spec, &wrapper(spec, &warped, spec.pdf));
    let r = check(&gpu, &sampler, &Settings { seed: 1, ..settings(&p, 1 << 18) }).unwrap_or_else(|e| panic!("{e}"));
    assert!(r.failed().contains(&"chi2"), "{:?}", r.checks.iter().map(|c| c.summary.clone()).collect::<Vec<_>>());
}

/// The names of the failed checks of `lobes check` on the light `spec` with `sample` and `pdf`.
fn failed_with(gpu: &Gpu, spec: &LightSpec, sample: &str, pdf: &str, p: &LightParams) -> Vec<&'static str> {
    let sampler = UserSampler::light_with(spec, &wrapper(spec, sample, pdf));
    let r = check(gpu, &sampler, &settings(p, 1 << 16)).unwrap();
    r.failed()
}

#[test]
fn broken_lights_fail_by_the_checks_that_should_catch_them() {
    let gpu = gpu();
    // the disk's pdf left per unit area (the classic MIS bug): the density disagrees with the
    // samples' own and does not integrate to 1
    let disk = by_name("disk").unwrap();
    let area = "select(0.0, 1.0 / (3.14159265 * params[0].w * params[0].w), disk_light_pdf(params[0].xyz, normalize(params[1].xyz), params[0].w, d) > 0.0)";
    let f = failed_with(&gpu, disk, disk.sample, area, &disk.sized(1e-2, 45.0));
    assert!(f.contains(&"pdf_consistency") && f.contains(&"normalization"), "{f:?}");
    // a 5 % warp of u.x (u' = u (1.05 − 0.05 u), still onto [0, 1]) with the right pdf: the
    // map's Jacobian sees it, on the cap fitted to a light of 10⁻⁶ sr
    let spec = by_name("triangle").unwrap();
    let warped = spec.sample.replace("u)", "vec2<f32>(u.x * (1.05 - 0.05 * u.x), u.y))");
    assert_ne!(warped, spec.sample);
    let f = failed_with(&gpu, spec, &warped, spec.pdf, &spec.sized(1e-6, 45.0));
    assert!(f.contains(&"jacobian"), "{f:?}");
}

/// The light's WGSL sample and pdf(sample) at each u, on the GPU.
fn wgsl_samples(passes: &LightPasses, spec: &LightSpec, params: &LightParams, us: &[[f64; 2]]) -> Vec<LightDraw> {
    passes.draws(params, us).unwrap_or_else(|e| panic!("{}: {e}", spec.name))
}

/// The geometry as the GPU received it (rounded to f32).
fn in_f32(p: &LightParams) -> LightParams {
    p.map(|x| x as f32 as f64)
}

#[test]
fn wgsl_samples_equal_the_f64_twins() {
    let gpu = gpu();
    for spec in &LIGHTS {
        let us: Vec<[f64; 2]> = (0..24 * 24).map(|k| [(k / 24) as f64 + 0.5, (k % 24) as f64 + 0.5].map(|x| x / 24.0)).collect();
        let (mut worst_d, mut worst_pdf, mut worst_fn) = (0f64, 0f64, 0f64);
        let passes = LightPasses::new(&gpu, spec).unwrap_or_else(|e| panic!("{}: {e}", spec.name));
        for (omega, elevation) in SIZES {
            let p = in_f32(&spec.sized(omega, elevation));
            for (u, s) in us.iter().zip(wgsl_samples(&passes, spec, &p, &us)) {
                let want = (spec.sample_f64)(&p, *u);
                // the direction's error in units of the light's angular radius, sqrt(Ω/π)
                let radius = (1.0 / (std::f64::consts::PI * (spec.pdf_f64)(&p, want.d).max(1e-300))).sqrt().min(1.0);
                worst_d = worst_d.max((s.d - want.d).length() / radius.max(f64::MIN_POSITIVE));
                worst_pdf = worst_pdf.max((s.pdf / want.pdf - 1.0).abs());
                worst_fn = worst_fn.max((s.pdf_at_d / s.pdf - 1.0).abs());
            }
        }
        eprintln!("{}: worst |Δd| / angular radius {worst_d:.2e}, pdf vs f64 {worst_pdf:.2e}, pdf fn vs sample {worst_fn:.2e}", spec.name);
        assert!(worst_d < 1e-3 && worst_pdf < 1e-4 && worst_fn < 1e-4, "{}: Δd {worst_d:.2e}, pdf {worst_pdf:.2e}, pdf fn {worst_fn:.2e}", spec.name);
    }
}

#[test]
fn the_f64_twins_integrate_to_one_and_their_maps_preserve_measure() {
    for spec in &LIGHTS {
        for (omega, elevation) in [(1e-2, 0.0), (3.0, 60.0)] {
            let p = spec.sized(omega, elevation);
            let i = sphere_integral_f64(&|d| (spec.pdf_f64)(&p, d));
            eprintln!("{} {omega} sr: f64 ∫pdf {} (error estimate {:.1e})", spec.name, i.value, i.error_estimate);
            // within the quadrature's own error estimate (a triangle's corners: ~1e-3 at 10⁻² sr)
            assert!((i.value - 1.0).abs() < 2.0 * i.error_estimate + 1e-6, "{} {omega} sr: ∫pdf {} ± {:.1e}", spec.name, i.value, i.error_estimate);
        }
        for (omega, elevation) in SIZES {
            let p = spec.sized(omega, elevation);
            let h = 1e-6;
            let map = |u: [f64; 2]| (spec.sample_f64)(&p, u).d;
            for u in [[0.2, 0.3], [0.5, 0.5], [0.8, 0.1], [0.05, 0.95]] {
                let du0 = (map([u[0] + h, u[1]]) - map([u[0] - h, u[1]])) / (2.0 * h);
                let du1 = (map([u[0], u[1] + h]) - map([u[0], u[1] - h])) / (2.0 * h);
                let jacobian = (spec.sample_f64)(&p, u).pdf * du0.cross(du1).length();
                assert!((jacobian - 1.0).abs() < 1e-4, "{} {omega} sr, u {u:?}: pdf |∂d/∂u| = {jacobian}", spec.name);
            }
        }
    }
}

/// The light registry is the one list: each light's module is a `lobes::embed` module (so
/// `lobes wgsl` and the WESL package offer it) whose API holds its sample and pdf functions.
#[test]
fn every_registered_light_is_an_embedded_module() {
    for l in &LIGHTS {
        let m = Module::from_name(l.module_name()).unwrap_or_else(|| panic!("{}: no embed module {}", l.name, l.module_name()));
        assert_eq!(m.import_path(), l.module);
        for call in [l.sample, l.pdf] {
            let f = call.split('(').next().unwrap();
            assert!(m.api().contains(&f), "{}: {f} is not in {}'s API", l.name, m.name());
        }
        assert!(m.dependencies().contains(&Module::Light), "{}", l.name);
    }
}
