//! lobes' own samplers judged by `lobes check`, as a renderer's would be: each registry entry
//! wrapped in the check's contract (`UserSampler::builtin`) passes every check — the χ² test
//! against the GPU quadrature of its own WGSL pdf, the Jacobian of its map against that pdf,
//! pdf consistency, normalization, hard cases — independently of `lobes run`'s f64 reference. And
//! the same wrapper around a sampler paired with another sampler's pdf is rejected.

use lobes::check::report::NormalizationFigures;
use lobes::check::{Settings, UserSampler, check};
use lobes::engine::gpu::Gpu;
use lobes::reference::reflect::spherical;
use lobes::reference::sampler::REGISTRY;
use lobes::reference::Lobe;
use lobes::stats::expected::{Quadrature, lobe_probabilities};
use lobes::stats::histogram::SphereGrid;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("lobes check needs a GPU adapter: {e}"))
}

fn settings(theta: f64) -> Settings {
    Settings { params: vec![0.3, 0.15], incident_theta: theta, incident_phi: 20.0, samples: 1 << 20, bins: Some((32, 64)), ..Settings::default() }
}

#[test]
fn every_builtin_sampler_passes_lobes_check() {
    let gpu = gpu();
    let significance = 1.0 - 0.99f64.powf(1.0 / REGISTRY.len() as f64 / 2.0);
    for spec in &REGISTRY {
        let sampler = UserSampler::builtin(spec);
        for theta in [10.0, 70.0] {
            let r = check(&gpu, &sampler, &Settings { significance, ..settings(theta) }).unwrap_or_else(|e| panic!("{}: {e}", spec.name()));
            for c in &r.checks {
                eprintln!("{} θi {theta}: {} {} {}", spec.name(), c.name(), if c.passed { "pass" } else { "FAIL" }, c.summary);
            }
            assert!(r.passed, "{} at θi {theta}: failed {:?}", spec.name(), r.failed());
            // ∫pdf over the sphere by the GPU quadrature of the WGSL pdf, against the f64 CPU
            // quadrature of the f64 reference (src/reference): 1 − the mass below the horizon.
            // 2e-5: an f32 pdf summed over ~2000 parts in f32 (measured: at most ~2e-6 apart)
            let lobe = Lobe { kind: spec.kind, method: spec.method, alpha_x: 0.3, alpha_y: 0.15, alpha_angle: 0.0 };
            let wi = spherical(theta.to_radians(), 20f64.to_radians());
            let f64_mass = 1.0 - lobe_probabilities(&lobe, wi, SphereGrid { rows: 32, cols: 64 }, &Quadrature::default()).below_horizon;
            let gpu_mass = r.figures::<NormalizationFigures>().expect("a normalization check").pdf_integral;
            assert!((gpu_mass - f64_mass).abs() < 2e-5, "{} θi {theta}: ∫pdf {gpu_mass} (WGSL, GPU) against {f64_mass} (f64 reference)", spec.name());
        }
    }
}

#[test]
fn a_builtin_sampler_with_another_samplers_pdf_is_rejected() {
    let gpu = gpu();
    let ndf = REGISTRY.iter().find(|s| s.name() == "ggx-ndf").expect("ggx ndf in the registry");
    let vndf = REGISTRY.iter().find(|s| s.name() == "ggx-vndf").expect("ggx vndf in the registry");
    // the NDF sampler's draws, judged against the visible-normal pdf: same lobe, wrong density
    let mut wrong = UserSampler::builtin(ndf);
    wrong.sources[1].text = wrong.sources[1].text.replace(ndf.wgsl.pdf, vndf.wgsl.pdf);
    assert_ne!(wrong, UserSampler::builtin(ndf));
    wrong.validate().unwrap();
    let r = check(&gpu, &wrong, &settings(70.0)).unwrap();
    assert!(!r.passed);
    let failed = r.failed();
    assert!(failed.contains(&"chi2") && failed.contains(&"pdf_consistency") && failed.contains(&"jacobian"), "{failed:?}");
}
