//! The renderer's diffuse sampler, judged by lobes on the GPU (lavapipe in CI).

use lobes::check::report::{AlbedoFigures, Chi2Figures, NormalizationFigures};
use lobes::check::{Domain, Reference, Report, Settings, Source, UserSampler, check};
use lobes::check::jacobian::JacobianCheck;
use lobes::engine::gpu::Gpu;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("the sampler tests need a GPU adapter: {e}"))
}

/// The embedded diffuse shader, followed by `extra` test-only files (name, text).
fn sampler(extra: &[(&str, &str)], sample: &str, pdf: &str, eval: Option<&str>) -> UserSampler {
    let mut sources = vec![Source { name: "shaders/diffuse.wgsl".into(), text: renderer_example::diffuse_wgsl().into() }];
    sources.extend(extra.iter().map(|(name, text)| Source { name: (*name).into(), text: (*text).into() }));
    UserSampler::from_sources(sources, sample, pdf, eval, Domain::Sphere).unwrap_or_else(|e| panic!("{e}"))
}

fn print(label: &str, report: &Report) {
    for c in &report.checks {
        eprintln!("{label}: {} {} {}", c.name(), if c.passed { "passed" } else { "FAILED" }, c.summary);
    }
}

#[test]
fn diffuse_lobe_passes() {
    let gpu = gpu();
    let diffuse = sampler(&[], "diffuse_sample", "diffuse_pdf", Some("diffuse_eval"));
    for (albedo, theta) in [(0.8, 30.0), (0.5, 0.0), (1.0, 89.0)] {
        let settings = Settings { params: vec![albedo], incident_theta: theta, incident_phi: 40.0, ..Settings::default() };
        let report = check(&gpu, &diffuse, &settings).unwrap_or_else(|e| panic!("{e}"));
        print(&format!("albedo {albedo}, θi {theta}°"), &report);
        report.assert_passed();
        // every check ran, and the mean weight is the albedo (eval / pdf = albedo exactly)
        for name in ["chi2", "normalization", "pdf_values", "pdf_consistency", "jacobian", "weights", "albedo", "hard_cases"] {
            assert!(report.get(name).is_some_and(|c| c.passed), "check `{name}` missing or failed");
        }
        let mean = report.figures::<AlbedoFigures>().unwrap().mean_weight;
        assert!((mean - albedo).abs() < 1e-5 * albedo, "mean weight {mean} for albedo {albedo}");
        // Samples from above are rejected only where f32 rounding puts them on the rim of the
        // disk (z = 0): u within a few ulps of the square's edge, a few in 2²² samples at most.
        let invalid: u64 = report.invalid.iter().sum();
        eprintln!("albedo {albedo}, θi {theta}°: invalid samples by reason {:?}", report.invalid);
        assert!(invalid <= 40 && report.invalid[..3] == [0, 0, 0], "invalid samples: {:?}", report.invalid);
    }
}

#[test]
fn diffuse_lobe_passes_against_an_f64_reference_pdf() {
    // A renderer with a CPU twin of its BSDF can give it as the reference: the expected histogram
    // then integrates this f64 pdf on the CPU instead of the WGSL one.
    let gpu = gpu();
    let diffuse = sampler(&[], "diffuse_sample", "diffuse_pdf", Some("diffuse_eval"));
    let cosine = Reference::new(|wi, d| if wi.z > 0.0 && d.z > 0.0 { d.z / std::f64::consts::PI } else { 0.0 });
    let settings = Settings { params: vec![0.8], incident_theta: 45.0, reference: Some(cosine), ..Settings::default() };
    let report = check(&gpu, &diffuse, &settings).unwrap_or_else(|e| panic!("{e}"));
    print("f64 reference", &report);
    report.assert_passed();
    // In f64 the cosine lobe integrates to 1 far below f32 rounding (2·10⁻⁶ of the GPU's sum).
    let integral = report.figures::<NormalizationFigures>().unwrap().pdf_integral;
    assert!((integral - 1.0).abs() < 1e-9, "∫pdf = {integral}");
}

#[test]
fn incident_direction_from_below_tests_nothing() {
    let gpu = gpu();
    let diffuse = sampler(&[], "diffuse_sample", "diffuse_pdf", Some("diffuse_eval"));
    let settings = Settings { params: vec![0.8], incident_theta: 120.0, samples: 1 << 16, ..Settings::default() };
    let report = check(&gpu, &diffuse, &settings).unwrap_or_else(|e| panic!("{e}"));
    print("θi 120°", &report);
    // every sample is rejected with pdf 0 (lobes' reason "zero_pdf") and the pdf integrates to
    // 0: the histogram tests nothing, and a test that tested nothing is no pass
    assert_eq!(report.invalid[lobes::reference::Invalid::ZeroPdf.index()], 1 << 16);
    assert_eq!(report.invalid.iter().sum::<u64>(), 1 << 16);
    let integral = report.figures::<Chi2Figures>().unwrap().pdf_integral;
    assert_eq!(integral, 0.0);
    let chi2 = report.get("chi2").expect("a chi2 check");
    assert!(!report.passed && !chi2.passed && chi2.summary.contains("no sample was valid"), "{}", chi2.summary);
}

#[test]
fn a_pdf_off_by_a_factor_of_two_is_caught() {
    let gpu = gpu();
    let half = sampler(&[("tests/half_pdf.wgsl", include_str!("half_pdf.wgsl"))], "half_sample", "half_pdf", Some("diffuse_eval"));
    let report = check(&gpu, &half, &Settings { params: vec![0.8], ..Settings::default() }).unwrap_or_else(|e| panic!("{e}"));
    print("pdf cos θ/(2π)", &report);
    assert!(!report.passed);
    let chi2 = report.get("chi2").expect("a chi2 check");
    assert!(!chi2.passed, "{}", chi2.summary);
    // The expected histogram holds half the samples: the other half is expected among the
    // invalid samples, and none are there.
    let integral = report.figures::<Chi2Figures>().unwrap().pdf_integral;
    assert!((integral - 0.5).abs() < 1e-4, "∫pdf = {integral}");
    // ... which the normalisation check compares with the valid fraction of the samples, 1.
    let normalization = report.get("normalization").expect("a normalization check");
    assert!(!normalization.passed && report.figures::<NormalizationFigures>().unwrap().valid_fraction > 0.999_99, "{}", normalization.summary);
    // The map's density is cos θ/π, twice the pdf: pdf · |J| = ½ at every smooth sample.
    let jacobian = report.get("jacobian").unwrap();
    let median = report.figures::<JacobianCheck>().unwrap().median_ratio.unwrap();
    assert!(!jacobian.passed && (median - 0.5).abs() < 0.01, "{}", jacobian.summary);
    // The sampler reports the same wrong pdf as the pdf function, so those agree ...
    assert!(report.get("pdf_consistency").unwrap().passed);
    // ... and the weights eval/pdf come out twice the albedo: the mean weight is off too.
    let albedo = report.get("albedo").unwrap();
    let mean = report.figures::<AlbedoFigures>().unwrap().mean_weight;
    assert!(!albedo.passed && (mean - 1.6).abs() < 1e-4, "{}", albedo.summary);
    // The panic message of assert_passed names the failed checks.
    let message = std::panic::catch_unwind(|| report.assert_passed()).unwrap_err();
    let message = message.downcast_ref::<String>().expect("a formatted panic message");
    assert!(message.contains("chi2:") && message.contains("jacobian:"), "{message}");
}

#[test]
fn an_error_of_a_fraction_of_a_percent_is_caught_by_chi2_with_many_samples() {
    let gpu = gpu();
    let skewed = sampler(&[("tests/skewed.wgsl", include_str!("skewed.wgsl"))], "skewed_sample", "diffuse_pdf", Some("diffuse_eval"));
    // The samples' density is off by at most ±0.4 %: below the Jacobian check's pointwise 1 %
    // tolerance, and eval/pdf stays exactly the albedo. The map is off by over 0.1 % at three
    // quarters of the probes (|1 − 2u| > ¼), which the Jacobian's systematic test sees at any
    // sample count; the histogram only with many samples: at the default 2²² it cannot yet (χ²
    // p ≈ 0.4 on 64 × 128 bins), at 2²⁶ on 32 × 64 bins it does.
    let settings = Settings { params: vec![0.8], samples: 1 << 26, bins: Some((32, 64)), ..Settings::default() };
    let report = check(&gpu, &skewed, &settings).unwrap_or_else(|e| panic!("{e}"));
    print("skewed by ±0.4 %", &report);
    assert_eq!(report.failed(), ["jacobian", "chi2"], "only the Jacobian's systematic test and χ² see an error this small");
    let j = report.figures::<lobes::check::jacobian::JacobianCheck>().unwrap();
    assert!(j.systematic && j.share_off <= lobes::check::jacobian::MAX_SHARE_OFF, "{j:?}");
    let p = report.figures::<Chi2Figures>().unwrap().chi2.p_value;
    assert!(p < 1e-4, "χ² p = {p}");
}

#[test]
fn a_reported_pdf_that_differs_from_the_pdf_function_is_caught() {
    let gpu = gpu();
    let squared = sampler(&[("tests/reported_pdf.wgsl", include_str!("reported_pdf.wgsl"))], "squared_sample", "diffuse_pdf", Some("diffuse_eval"));
    let report = check(&gpu, &squared, &Settings { params: vec![0.8], ..Settings::default() }).unwrap_or_else(|e| panic!("{e}"));
    print("reported pdf cos² θ/π", &report);
    // The samples and diffuse_pdf agree: the histogram, the normalisation and the map's Jacobian pass.
    for name in ["chi2", "normalization", "jacobian", "pdf_values", "hard_cases"] {
        assert!(report.get(name).unwrap().passed, "{name}: {}", report.get(name).unwrap().summary);
    }
    // The reported pdf is off by a factor cos θ: consistency and weights fail, and the weights
    // eval / reported pdf = albedo / cos θ average to 2 · albedo (∫ (1/cos θ) cos θ/π dω = 2).
    for name in ["pdf_consistency", "weights", "albedo"] {
        assert!(!report.get(name).unwrap().passed, "{name} passed");
    }
    let mean = report.figures::<AlbedoFigures>().unwrap().mean_weight;
    assert!((mean - 1.6).abs() < 0.05, "mean weight {mean}");
}
