//! `lobes check` on shipped example samplers: correct ones pass, broken ones are rejected by the
//! check that should catch them. Each check is shown to reject a deliberately broken sampler:
//!
//! | check | rejects | test |
//! |---|---|---|
//! | `pdf_consistency` | a pdf function that forgot the table of a 2-D warp | `piecewise_constant_2d_warp_on_the_plane` |
//! | `jacobian` | a pdf without the reflection Jacobian 1/(4\|d·h\|); a rough dielectric's refraction density without η² or with the reflection Jacobian; a mixture's pdf with the wrong weight | `missing_reflection_jacobian_is_rejected`, `broken_dielectric_refraction_densities_are_rejected`, `a_wrong_mixture_weight_is_rejected` |
//! | `pdf_values` | a pdf that is negative on a cap | `bad_pdf_values_are_counted_by_reason` |
//! | `normalization` | Mitsuba's rational Beckmann G1 (0.3 % off) | `mitsuba_rational_g1_is_rejected` |
//! | `chi2` | the missing Jacobian; a wrong g in an f64 reference | `missing_reflection_jacobian_is_rejected`, `an_f64_reference_pdf_from_rust` |
//! | `weights`, `albedo` | a sampler that reports twice its pdf | `a_reported_pdf_off_by_a_factor_fails_the_weights_and_the_albedo` |
//! | `hard_cases` | a pdf that is 0/0 at u.x = 1 only | `a_nan_at_u_equal_to_one_is_caught_by_the_hard_cases_alone` |
//!
//! and the correct samplers (GGX and Beckmann visible normals, Henyey–Greenstein, the 2-D warp,
//! a GGX + diffuse mixture chosen with u.z) pass all of them.

use lobes::check::hard::HardRow;
use lobes::check::jacobian::JacobianCheck;
use lobes::check::report::{AlbedoFigures, NormalizationFigures, WeightFigures};
use lobes::check::{Domain, Settings, UserSampler, check};
use lobes::engine::gpu::Gpu;
use std::path::PathBuf;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("lobes check needs a GPU adapter: {e}"))
}

fn files(names: &[&str]) -> Vec<PathBuf> {
    names.iter().map(|n| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers").join(n)).collect()
}

#[test]
fn henyey_greenstein_passes() {
    let gpu = gpu();
    let s = UserSampler::from_files(&files(&["henyey_greenstein.wgsl"]), "hg_sample", "hg_pdf", Some("hg_eval"), Domain::Sphere).unwrap();
    for g in [0.7, -0.3, 0.0] {
        let r = check(&gpu, &s, &Settings { params: vec![g], ..Settings::default() }).unwrap();
        for c in &r.checks {
            eprintln!("g {g}: {} {} {}", c.name(), c.passed, c.summary);
        }
        r.assert_passed();
    }
}

fn ggx(extra: &[&str], sample: &str, pdf: &str, eval: Option<&str>) -> UserSampler {
    let mut names = vec!["ggx_vndf.wgsl"];
    names.extend_from_slice(extra);
    UserSampler::from_files(&files(&names), sample, pdf, eval, Domain::Sphere).unwrap()
}

fn show(r: &lobes::check::Report) {
    for c in &r.checks {
        eprintln!("{}: {} {} {}", r.sampler, c.name(), c.passed, c.summary);
    }
}

/// A GGX visible-normal sampler written from the papers passes, at a rough, a smooth, an
/// anisotropic and a grazing configuration.
#[test]
fn ggx_vndf_from_scratch_passes() {
    let gpu = gpu();
    let s = ggx(&[], "ggx_sample", "ggx_pdf", Some("ggx_eval"));
    for (a, theta) in [((0.5, 0.5), 30.0), ((0.05, 0.05), 0.0), ((0.3, 0.08), 60.0), ((0.2, 0.2), 85.0)] {
        let r = check(&gpu, &s, &Settings { params: vec![a.0, a.1], incident_theta: theta, ..Settings::default() }).unwrap();
        show(&r);
        r.assert_passed();
        // u.z and u.w unused: every sample a plain 2-D map
        let j = jacobian(&r);
        assert!(j.compared_events == 0 && j.skipped_selection == 0, "{j:?}");
    }
}

/// Without the reflection Jacobian the histogram and the map's Jacobian both disagree with the pdf.
#[test]
fn missing_reflection_jacobian_is_rejected() {
    let gpu = gpu();
    let s = ggx(&["broken_no_jacobian.wgsl"], "broken_sample_no_jacobian", "broken_pdf_no_jacobian", None);
    let r = check(&gpu, &s, &Settings { params: vec![0.3, 0.3], incident_theta: 30.0, ..Settings::default() }).unwrap();
    show(&r);
    assert!(!r.passed);
    assert!(!r.get("chi2").unwrap().passed, "chi2 must reject a pdf without 1/(4|d·h|)");
    assert!(!r.get("jacobian").unwrap().passed, "the Jacobian check must reject it too");
    assert!(r.get("pdf_consistency").unwrap().passed, "the sampler reports the same (wrong) pdf");
}

fn jacobian(r: &lobes::check::Report) -> JacobianCheck {
    r.figures::<JacobianCheck>().unwrap().clone()
}

/// The rough dielectric's samples (GGX visible normals, reflection with probability F chosen
/// with u.z) with the refraction density of two classic bugs: without eq. 17's η², where every
/// refracted sample's p · |J| / share is 1/η² = 0.4444, and with the reflection Jacobian
/// 1/(4|ωo·h|) in place of eq. 17's. The jacobian check compares them event by event and rejects
/// both, as it passes the correct sampler (tests/dielectric.rs).
#[test]
fn broken_dielectric_refraction_densities_are_rejected() {
    let gpu = gpu();
    let settings = Settings { params: vec![0.3, 0.3, 1.5], incident_theta: 30.0, ..Settings::default() };
    for (sample, pdf) in [("brd_no_eta2_sample", "brd_no_eta2_pdf"), ("brd_reflection_j_sample", "brd_reflection_j_pdf")] {
        let s = ggx(&["rough_dielectric.wgsl", "broken_dielectric.wgsl"], sample, pdf, None);
        let r = check(&gpu, &s, &settings).unwrap();
        show(&r);
        let j = jacobian(&r);
        assert!(!r.get("jacobian").unwrap().passed && j.applicable, "{sample}: {j:?}");
        assert!(j.compared_events * 10 > j.probed * 9, "{sample}: F < 1 at every h from 30°: {j:?}");
        if sample == "brd_no_eta2_sample" {
            assert!((j.median_ratio.unwrap() - 1.0 / 2.25).abs() < 1e-3, "{j:?}");
        }
    }
}

/// A 50/50 (and a 25/75) mixture of GGX visible normals and a cosine lobe chosen with u.z, with
/// the mixture's pdf, passes every check: the lobes overlap, so p · |J| / share exceeds 1 where
/// the other lobe adds density, and only a ratio below 1 is off.
#[test]
fn a_mixture_chosen_with_u_z_passes() {
    let gpu = gpu();
    let s = ggx(&["ggx_diffuse_mixture.wgsl"], "mix_sample", "mix_pdf", None);
    for (alpha, w) in [(0.3, 0.5), (0.2, 0.25)] {
        let r = check(&gpu, &s, &Settings { params: vec![alpha, alpha, w], incident_theta: 40.0, ..Settings::default() }).unwrap();
        show(&r);
        r.assert_passed();
        let j = jacobian(&r);
        assert!(j.compared_events == j.compared && j.compared * 10 > j.probed * 9 && j.above_events > 0, "{j:?}");
    }
}

/// The mixture's pdf with the weights fixed at ½ while the sampler picks GGX with probability ¼:
/// a cosine-lobe sample's ratio is (½ p_diffuse + ½ p_ggx) / (¾ p_diffuse) ≥ ⅔, and ⅔ where GGX
/// adds nothing. The jacobian check rejects it; pdf_consistency passes (the sampler reports the
/// same wrong pdf).
#[test]
fn a_wrong_mixture_weight_is_rejected() {
    let gpu = gpu();
    let s = ggx(&["ggx_diffuse_mixture.wgsl", "broken_mixture_weight.wgsl"], "broken_mix_sample", "broken_mix_pdf", None);
    let r = check(&gpu, &s, &Settings { params: vec![0.2, 0.2, 0.25], incident_theta: 40.0, ..Settings::default() }).unwrap();
    show(&r);
    let j = jacobian(&r);
    assert!(!r.get("jacobian").unwrap().passed && r.get("pdf_consistency").unwrap().passed, "{j:?}");
    assert!(j.worst_ratio > 2.0 / 3.0 - 1e-2 && j.worst_ratio < 0.8, "{j:?}");
}

fn temp_wgsl(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lobes-check-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A uniform direction on the sphere from u.xy (z = 1 − 2u.x, φ = 2π u.y), for inline samplers.
const UNIFORM_DIRECTION: &str = "fn uniform_direction(u: vec4<f32>) -> vec3<f32> {\n\
     let z = 1.0 - 2.0 * u.x;\n let r = sqrt(max(0.0, 1.0 - z * z));\n let phi = 6.2831853 * u.y;\n\
     return vec3<f32>(r * cos(phi), r * sin(phi), z);\n}\n";

const GOOD_SAMPLE: &str = "fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {\n    return vec4<f32>(0.0, 0.0, 1.0, 1.0);\n}\n";

/// Events chosen with u.w are judged like those of u.z: the upper hemisphere with probability 0.3
/// (z = ±(1 − u.x), φ = 2π u.y: |J| = 2π on either side), so p = 0.3/(2π) above and 0.7/(2π)
/// below (a handful of probes above 1 by f32 differences near the pole); a pdf of 0.5/(2π) on both
/// sides is ⁵⁄₇ of the density below and is off. A map that moves
/// with u.z continuously (φ = 2π (u.y + u.z)) is skipped, as before events were judged.
#[test]
fn events_chosen_with_u_w_and_maps_moving_with_u_z() {
    let gpu = gpu();
    let hemispheres = |pdf_above: f64, pdf_below: f64| {
        format!(
            "fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
             let r = sqrt(max(0.0, u.x * (2.0 - u.x)));\n let phi = 6.2831853 * u.y;\n\
             let z = select(u.x - 1.0, 1.0 - u.x, u.w < 0.3);\n\
             let d = vec3<f32>(r * cos(phi), r * sin(phi), z);\n return vec4<f32>(d, p(wi, d, params));\n}}\n\
             fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n\
             return select({pdf_below:.8}, {pdf_above:.8}, d.z > 0.0) / 6.2831853;\n}}\n"
        )
    };
    let settings = Settings { samples: 1 << 18, bins: Some((16, 32)), ..Settings::default() };
    let run = |name: &str, text: &str| {
        let s = UserSampler::from_files(&[temp_wgsl(name, text)], "s", "p", None, Domain::Sphere).unwrap();
        let r = check(&gpu, &s, &settings).unwrap();
        show(&r);
        (r.get("jacobian").unwrap().passed, jacobian(&r))
    };
    let (passed, j) = run("by_u_w.wgsl", &hemispheres(0.3, 0.7));
    assert!(passed && j.compared * 10 > j.probed * 9 && j.compared_events == j.compared && j.above_events * 100 < j.compared, "{j:?}");
    assert!((j.median_ratio.unwrap() - 1.0).abs() < 1e-3, "{j:?}");
    let (passed, j) = run("by_u_w_wrong.wgsl", &hemispheres(0.5, 0.5));
    assert!(!passed && (j.worst_ratio - 5.0 / 7.0).abs() < 1e-2, "{j:?}");
    let moving = format!(
        "{UNIFORM_DIRECTION}fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
         return vec4<f32>(uniform_direction(vec4<f32>(u.x, fract(u.y + u.z), 0.0, 0.0)), 0.0795775);\n}}\n\
         fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n return 0.0795775;\n}}\n"
    );
    let (passed, j) = run("moving.wgsl", &moving);
    assert!(passed && !j.applicable && j.compared == 0 && j.skipped_selection * 10 > j.probed * 9, "{j:?}");
}

/// WGSL errors point at the user's file, line and column; a missing function or a wrong
/// signature names the expected signature.
#[test]
fn broken_input_is_reported_at_the_users_file() {
    let syntax = temp_wgsl("syntax.wgsl", "fn s(wi: vec3<f32>) -> f32 {\n    return 1.0\n}\n");
    let e = UserSampler::from_files(std::slice::from_ref(&syntax), "s", "p", None, Domain::Sphere).unwrap_err();
    assert!(e.is_input());
    assert!(e.to_string().starts_with(&format!("{}:3:1: expected `;`", syntax.display())), "{e}");

    let two = temp_wgsl("second.wgsl", "fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {\n    return nope;\n}\n");
    let first = temp_wgsl("first.wgsl", GOOD_SAMPLE);
    let e = UserSampler::from_files(&[first.clone(), two.clone()], "s", "p", None, Domain::Sphere).unwrap_err();
    assert!(e.to_string().starts_with(&format!("{}:2:12:", two.display())), "the second file's own line: {e}");

    let e = UserSampler::from_files(std::slice::from_ref(&first), "s", "missing", None, Domain::Sphere).unwrap_err();
    assert!(e.to_string().contains("function `missing`") && e.to_string().contains("-> f32`"), "{e}");

    let wrong = temp_wgsl("wrong.wgsl", &format!("{GOOD_SAMPLE}fn p(wi: vec3<f32>, d: vec3<f32>) -> f32 {{\n    return 1.0;\n}}\n"));
    let e = UserSampler::from_files(std::slice::from_ref(&wrong), "s", "p", None, Domain::Sphere).unwrap_err();
    assert!(e.to_string().starts_with(&format!("{}:4:1: the pdf function `p` has the wrong signature", wrong.display())), "{e}");
    assert!(e.to_string().contains("expected `fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32`"), "{e}");

    // a `lobes_` name is lobes' own; the names lobes' files declare (the RNG's `pcg4d`, the
    // binning's `Real`, `PI` and `math_atan2`) are the user's to use (lobes' are `lobes_pcg4d`, …
    // in a check's composition)
    let clash = temp_wgsl("clash.wgsl", &format!("{GOOD_SAMPLE}fn lobes_pcg4d(x: f32) -> f32 {{ return x; }}\nfn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{ return 1.0; }}\n"));
    let e = UserSampler::from_files(&[clash], "s", "p", None, Domain::Sphere).unwrap_err();
    assert!(e.to_string().contains("`lobes_pcg4d` is lobes' own"), "{e}");
    let names = "fn pcg4d(x: f32) -> f32 { return x; }\nalias Real = i32;\nconst PI: Real = 3;\nfn math_atan2(x: Real) -> Real { return x; }\n";
    let own = temp_wgsl("own-pcg4d.wgsl", &format!("{GOOD_SAMPLE}{names}fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{ return pcg4d(0.25) * f32(math_atan2(PI)) / 9.424778; }}\n"));
    UserSampler::from_files(&[own], "s", "p", None, Domain::Sphere).unwrap();
}

/// A sampler whose pdf is NaN, infinite or negative in places is counted by reason and judged,
/// never a crash: uniform directions whose reported pdf is NaN for z > 0.9 and negative for
/// z < −0.9, with a pdf function that is negative on the same cap (the report's expected counts
/// negative there, as its pictures draw them).
#[test]
fn bad_pdf_values_are_counted_by_reason() {
    let src = temp_wgsl(
        "nan.wgsl",
        &format!(
            "{UNIFORM_DIRECTION}fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
         let d = uniform_direction(u);\n\
         var pdf = 0.0795775;\n if (d.z > 0.9) {{ pdf = sqrt(-d.z); }}\n if (d.z < -0.9) {{ pdf = -1.0; }}\n\
         return vec4<f32>(d, pdf);\n}}\n\
         fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n\
         if (d.z < -0.9) {{ return -1.0; }}\n return 0.0795775;\n}}\n"
        ),
    );
    let s = UserSampler::from_files(&[src], "s", "p", None, Domain::Sphere).unwrap();
    let r = check(&gpu(), &s, &Settings { samples: 1 << 20, ..Settings::default() }).unwrap();
    show(&r);
    let n = (1u64 << 20) as f64;
    // 5% of the sphere above z = 0.9 and 5% below −0.9: counted as non-finite and zero pdf
    assert!((r.invalid[2] as f64 / n - 0.05).abs() < 0.002, "non_finite_pdf {:?}", r.invalid);
    assert!((r.invalid[3] as f64 / n - 0.05).abs() < 0.002, "zero_pdf {:?}", r.invalid);
    assert_eq!(r.counts.iter().sum::<u64>() + r.invalid.iter().sum::<u64>(), 1 << 20, "every sample is a bin hit or an invalid sample");
    assert!(!r.get("pdf_values").unwrap().passed);
    assert!(!r.get("hard_cases").unwrap().passed);
    assert!(!r.passed);
    // the report's expected counts are the pdf's signed integral (what the pictures draw
    // magenta): rows 0–2 of 64 lie inside the cap, each bin N × (−1) × its solid angle 4π/8192
    let want = -n * 4.0 * std::f64::consts::PI / (64.0 * 128.0);
    for (i, e) in r.expected[..3 * 128].iter().enumerate() {
        assert!((e - want).abs() <= 1e-4 * want.abs(), "bin {i}: expected count {e}, the pdf integrates to {want}");
    }
    // over the sphere they sum to the signed integral, 0.95 × 1 − (0.05 × 4π) × 1 = 0.95 − 0.2π
    // (to 10⁻²: a part across the cap's rim is bad, so left unsplit, its rule across a jump)
    let signed = r.expected.iter().sum::<f64>() / n;
    assert!((signed - (0.95 - 0.2 * std::f64::consts::PI)).abs() < 1e-2, "Σ expected / N = {signed}");
    let c = r.figures::<lobes::check::report::Chi2Figures>().unwrap();
    assert_eq!(c.quadrature.dropped.len(), 64 * 128);
}

/// A piecewise-constant 2-D distribution on the plane passes, and its zero-weight cells get no
/// samples; the same map with the density of a uniform square (a pdf that forgot the table) fails.
#[test]
fn piecewise_constant_2d_warp_on_the_plane() {
    let gpu = gpu();
    let plane = Domain::Plane { bounds: [0.0, 0.0, 1.0, 1.0] };
    let s = UserSampler::from_files(&files(&["piecewise_2d.wgsl"]), "env_sample", "env_pdf", None, plane).unwrap();
    let r = check(&gpu, &s, &Settings::default()).unwrap();
    show(&r);
    r.assert_passed();
    // The table's second row (y in [0.25, 0.5)) has weight 0: rows 16..32 of the 64 × 64 grid.
    let empty: u64 = r.counts[16 * 64..32 * 64].iter().sum();
    assert_eq!(empty, 0);
    // Independent value: the first row (y < 0.25) holds its weights 1+2+3+4+4+3+2+1 = 20 of Σw = 60.
    let first: u64 = r.counts[..16 * 64].iter().sum();
    let expect = 20.0 / 60.0;
    let n = r.samples as f64;
    assert!((first as f64 / n - expect).abs() < 4.0 * (expect * (1.0 - expect) / n).sqrt(), "{first}");

    let uniform = temp_wgsl("uniform_pdf.wgsl", "fn uniform_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {\n    return 1.0;\n}\n");
    let mut paths = files(&["piecewise_2d.wgsl"]);
    paths.push(uniform);
    let broken = UserSampler::from_files(&paths, "env_sample", "uniform_pdf", None, plane).unwrap();
    let r = check(&gpu, &broken, &Settings::default()).unwrap();
    assert!(!r.get("chi2").unwrap().passed && !r.get("pdf_consistency").unwrap().passed && !r.get("jacobian").unwrap().passed);
}

/// Beckmann visible normals from the papers pass at normal, oblique and grazing incidence.
#[test]
fn beckmann_vndf_passes() {
    let gpu = gpu();
    let s = UserSampler::from_files(&files(&["beckmann_vndf.wgsl"]), "beck_sample", "beck_pdf", None, Domain::Sphere).unwrap();
    for (a, theta) in [(0.8, 85.0), (0.3, 0.0), (0.2, 60.0)] {
        let r = check(&gpu, &s, &Settings { params: vec![a, a], incident_theta: theta, ..Settings::default() }).unwrap();
        show(&r);
        r.assert_passed();
    }
}

/// Mitsuba 3.9.1's rational Beckmann G1 (< 0.35% error) in the visible-normal pdf: the samples
/// are exact, so the histogram alone sees the error only from many samples (here 2^26, as
/// Mitsuba's own test does from 4·10⁷), while the pdf's normalisation, ∫pdf = 1.003 instead of 1,
/// gives it away at any sample count.
#[test]
fn mitsuba_rational_g1_is_rejected() {
    let gpu = gpu();
    let s = UserSampler::from_files(&files(&["beckmann_vndf.wgsl", "broken_mitsuba_g1.wgsl"]), "mitsuba_sample", "mitsuba_pdf", None, Domain::Sphere)
        .unwrap();
    let settings = Settings { params: vec![0.8, 0.8], incident_theta: 85.0, samples: 1 << 20, ..Settings::default() };
    let r = check(&gpu, &s, &settings).unwrap();
    show(&r);
    let norm = r.get("normalization").unwrap();
    assert!(!norm.passed);
    // Independent value: G1 exact at a = cot(85°)/0.8 against Walter's rational form, by the
    // f64 reference of lobes (erfc-based Λ).
    let a = (5f64).to_radians().tan() / 0.8;
    let lambda = 0.5 * (libm::erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * std::f64::consts::PI.sqrt());
    let exact = 1.0 / (1.0 + lambda);
    let approx = (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a);
    let integral = r.figures::<NormalizationFigures>().unwrap().pdf_integral;
    assert!((integral - approx / exact).abs() < 2e-4, "∫pdf {integral} against G1 ratio {}", approx / exact);
    let r = check(&gpu, &s, &Settings { samples: 1 << 26, ..settings }).unwrap();
    show(&r);
    assert!(!r.get("chi2").unwrap().passed, "at 2^26 samples the histogram sees it too");
}

/// Through the library, an f64 Rust closure can stand in for the WGSL pdf as the reference the
/// histogram is judged against: Henyey–Greenstein's closed form passes, a wrong g fails.
#[test]
fn an_f64_reference_pdf_from_rust() {
    use lobes::check::Reference;
    let gpu = gpu();
    let s = UserSampler::from_files(&files(&["henyey_greenstein.wgsl"]), "hg_sample", "hg_pdf", None, Domain::Sphere).unwrap();
    let hg = |g: f64| {
        Reference::new(move |wi: glam::DVec3, d: glam::DVec3| {
            let c = (-wi).dot(d).clamp(-1.0, 1.0);
            (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * c).powf(1.5))
        })
    };
    let settings = |g: f64| Settings { params: vec![0.5], reference: Some(hg(g)), ..Settings::default() };
    let r = check(&gpu, &s, &settings(0.5)).unwrap();
    show(&r);
    r.assert_passed();
    let r = check(&gpu, &s, &settings(0.45)).unwrap();
    assert!(!r.get("chi2").unwrap().passed);
}

/// A uniform sampler of the upper hemisphere, correct everywhere but at u.x = 1 exactly: its
/// pdf is written (1/2π) · r/sin θ, a factor that cancels analytically but is 0/0 at the pole.
/// lobes' RNG never draws u = 1, so the histogram, the probes and every statistic pass: only the
/// hard cases see the NaN.
#[test]
fn a_nan_at_u_equal_to_one_is_caught_by_the_hard_cases_alone() {
    let src = temp_wgsl(
        "pole.wgsl",
        "fn pole_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {\n\
         let z = u.x;\n let r = sqrt(max(0.0, 1.0 - z * z));\n let phi = 6.2831853 * u.y;\n\
         let pdf = 0.15915494 * r / sqrt(1.0 - z * z);\n\
         return vec4<f32>(r * cos(phi), r * sin(phi), z, pdf);\n}\n\
         fn pole_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {\n\
         return select(0.0, 0.15915494, d.z >= 0.0);\n}\n\
         fn pole_eval(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {\n\
         return 0.5 * pole_pdf(wi, d, params);\n}\n",
    );
    let s = UserSampler::from_files(&[src], "pole_sample", "pole_pdf", Some("pole_eval"), Domain::Sphere).unwrap();
    let r = check(&gpu(), &s, &Settings { samples: 1 << 18, bins: Some((32, 64)), ..Settings::default() }).unwrap();
    show(&r);
    assert_eq!(r.failed(), ["hard_cases"]);
    let rows = r.figures::<Vec<HardRow>>().unwrap();
    for row in rows {
        assert!(row.bad_pdf > 0 && row.first_failure.is_some_and(|u| u[0] == 1.0), "{row:?}");
    }
}

/// A sampler that reports twice its pdf (the pdf function is right): the weights eval/pdf a
/// renderer forms come out half of eval/pdf(d), and their mean half the albedo. The histogram,
/// the normalisation and the Jacobian judge the pdf function and pass.
#[test]
fn a_reported_pdf_off_by_a_factor_fails_the_weights_and_the_albedo() {
    let src = temp_wgsl(
        "double.wgsl",
        &format!(
            "{UNIFORM_DIRECTION}fn twice_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
         return vec4<f32>(uniform_direction(u), 2.0 * 0.07957747);\n}}\n\
         fn uniform_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n\
         return 0.07957747;\n}}\n\
         fn uniform_eval(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n\
         return 0.3 * 0.07957747 * (1.0 + d.z);\n}}\n"
        ),
    );
    let s = UserSampler::from_files(&[src], "twice_sample", "uniform_pdf", Some("uniform_eval"), Domain::Sphere).unwrap();
    let r = check(&gpu(), &s, &Settings { samples: 1 << 18, bins: Some((32, 64)), ..Settings::default() }).unwrap();
    show(&r);
    assert_eq!(r.failed(), ["pdf_consistency", "weights", "albedo"]);
    let weights = r.figures::<WeightFigures>().unwrap();
    assert!((weights.max_weight_error - 0.5).abs() < 1e-3, "{weights:?}");
    // independent value: ∫eval = 0.3/(4π) ∫(1 + cos θ) dω = 0.3; the weights average half of it
    let albedo = r.figures::<AlbedoFigures>().unwrap();
    assert!((albedo.quadrature - 0.3).abs() < 1e-4 && (albedo.mean_weight - 0.15).abs() < 5.0 * albedo.std_error, "{albedo:?}");
}

/// `lobes check --power` exits 1 when some count fails and says from which count, and after
/// how much GPU time, the error is caught: Mitsuba's rational G1 fails the normalisation and the
/// Jacobian's systematic test (its map off by about 0.3 % everywhere) at every count (the χ² test
/// alone would need about 2²⁶ samples). Bad input exits 2.
#[test]
fn power_sweep_exits_1_and_says_from_which_count_an_error_is_caught() {
    let samplers = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers");
    let (beckmann, broken) = (samplers.join("beckmann_vndf.wgsl"), samplers.join("broken_mitsuba_g1.wgsl"));
    let lobes = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_lobes"))
            .arg("check")
            .args([&beckmann, &broken])
            .args(["--sample", "mitsuba_sample", "--pdf", "mitsuba_pdf", "--params", "0.8,0.8", "--incident-theta", "85", "--bins", "32,64", "--power"])
            .args(extra)
            .output()
            .unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (code, stdout, stderr) = lobes(&["--samples", "262144"]);
    assert_eq!(code, Some(1), "{stdout}{stderr}");
    let verdict = stdout.lines().last().unwrap();
    assert!(verdict.starts_with("caught from 65536 samples (jacobian, normalization failing), after "), "{stdout}");
    assert!(verdict.contains(" s of GPU time") || verdict.contains("no GPU timestamps"), "{verdict}");
    assert!(stdout.lines().any(|l| l.starts_with("262144 ")), "a row per count: {stdout}");
    assert!(stderr.contains("caught from 65536 samples"), "{stderr}");

    let (code, stdout, _) = lobes(&["--samples", "262144", "--json"]);
    assert_eq!(code, Some(1));
    let sweep: lobes::check::power::PowerSweep = serde_json::from_str(&stdout).unwrap();
    assert!(!sweep.passed && sweep.points.iter().all(|p| !p.normalization_passed));
    assert_eq!(sweep.caught.map(|c| (c.samples, c.failed)), Some((65536, vec!["jacobian".to_string(), "normalization".to_string()])));

    let (code, _, stderr) = lobes(&["--samples", "0"]);
    assert_eq!(code, Some(2), "{stderr}");
}

/// Bad flags of `lobes check` exit 2 with a message naming the flag, before any GPU work.
#[test]
fn bad_flags_exit_2_naming_the_flag() {
    let hg = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers/henyey_greenstein.wgsl");
    let seventeen = vec!["0.1"; 17].join(",");
    for (extra, flag) in [
        (vec!["--bins", "0,4"], "--bins"),
        (vec!["--bins", "5000,5000"], "--bins"),
        (vec!["--bins", "4.5,8"], "--bins"),
        (vec!["--params", seventeen.as_str()], "--params"),
        (vec!["--samples", "0"], "--samples"),
        (vec!["--significance", "1.5"], "--significance"),
        (vec!["--domain", "plane"], "--bounds"),
        (vec!["--bounds", "0,0,1,1"], "--bounds"),
    ] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_lobes"))
            .arg("check")
            .arg(&hg)
            .args(["--sample", "hg_sample", "--pdf", "hg_pdf"])
            .args(&extra)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {stderr}");
        assert!(stderr.contains(flag), "{extra:?} should name {flag}: {stderr}");
    }
}

/// Issue 24 item 1: the GGX sampler with its guard inverted (`wi.z > 0.0` for `wi.z <= 0.0`)
/// rejects every sample and its pdf is 0 everywhere, which agree: χ² = 0 on 0 dof and
/// ∫pdf = 0 against a valid fraction of 0 read as a pass. A test that tested nothing fails,
/// saying no sample was valid.
#[test]
fn a_sampler_that_rejects_every_sample_fails() {
    let gpu = gpu();
    let text = std::fs::read_to_string(files(&["ggx_vndf.wgsl"])[0].clone()).unwrap().replace("wi.z <= 0.0", "wi.z > 0.0");
    let path = temp_wgsl("inverted_guard.wgsl", &text);
    let s = UserSampler::from_files(&[path], "ggx_sample", "ggx_pdf", None, Domain::Sphere).unwrap();
    let r = check(&gpu, &s, &Settings { params: vec![0.3, 0.3], samples: 262_144, ..Settings::default() }).unwrap();
    show(&r);
    assert!(!r.passed);
    let chi2 = r.get("chi2").unwrap();
    assert!(!chi2.passed && chi2.summary.starts_with("no sample was valid"), "{}", chi2.summary);
    let f = r.figures::<lobes::check::report::Chi2Figures>().unwrap();
    assert_eq!(f.chi2.untested, Some(lobes::stats::chi2::Untested::NoValidSample));
    assert_eq!(r.invalid.iter().sum::<u64>(), 262_144);
}

/// A pdf no quadrature resolves (white noise at the scale of an ulp,
/// tests/fixtures/samplers/noisy_pdf.wgsl) gives no verdict: `check` returns
/// `CheckError::NoVerdict` naming the bin error in σ (the command's exit 3, as a failure to do
/// the work, never 0 or 1); the same sampler with a smooth pdf (its uniform density) still gets a
/// verdict. (At 2¹⁶ samples the noisy pdf's quadrature converges to the tolerance of that N, and
/// it passes: an error far below the counts' σ is no reason to withhold a verdict.)
#[test]
fn an_unconverged_quadrature_gives_no_verdict() {
    let gpu = gpu();
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/samplers/noisy_pdf.wgsl");
    let settings = Settings { samples: 1 << 18, bins: Some((4, 8)), ..Settings::default() };
    let noisy = UserSampler::from_files(std::slice::from_ref(&path), "noisy_sample", "noisy_pdf", None, Domain::Sphere).unwrap();
    match check(&gpu, &noisy, &settings) {
        Err(lobes::check::CheckError::NoVerdict(m)) => {
            let shown = m.render(&|s| format!("<{}>", s.key()));
            assert!(shown.contains("did not converge") && shown.contains("no verdict") && shown.ends_with("fewer <samples> or more <bins>"), "{shown}")
        }
        Err(e) => panic!("another error: {e}"),
        Ok(r) => panic!("a verdict ({}) from an unconverged quadrature", if r.passed { "pass" } else { "fail" }),
    }
    // the uniform density, which the sampler draws: a verdict, a pass
    let smooth = UserSampler::from_files(&[path], "noisy_sample", "0.25 / 3.14159265", None, Domain::Sphere).unwrap();
    let r = check(&gpu, &smooth, &Settings { samples: 1 << 16, ..settings }).unwrap_or_else(|e| panic!("{e}"));
    assert!(r.get("chi2").unwrap().passed, "{}", r.get("chi2").unwrap().summary);
}

/// A pdf with a jump: a uniform cone of half-angle 0.3 rad about the normal, whose rim lies
/// inside a row of bins. The quadrature's parts across the rim stop at the depth limit, and
/// ∫pdf comes out 0.999830 with an error estimate of 1.65·10⁻⁴: the invalid cell, expecting the
/// missing mass within 1× that estimate, expected 12 samples where none can be, and `chi2`
/// false-failed at seeds 2 and 3 (measured on lavapipe). Within twice the estimate (as
/// `normalization`'s tolerance) it passes at seeds 1–3, tilted 30° too; the same sampler rejecting
/// 0.1 % of its samples (u.x < 10⁻³ returned as (0, 0, 0) with pdf 0) fails `chi2`.
#[test]
fn a_uniform_cone_is_judged_across_its_rim() {
    let gpu = gpu();
    let cone = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/samplers/uniform_cone.wgsl");
    let s = UserSampler::from_files(std::slice::from_ref(&cone), "cone_sample", "cone_pdf", None, Domain::Sphere).unwrap();
    for (tilt, seed) in [(0.0, 1), (0.0, 2), (0.0, 3), (std::f64::consts::FRAC_PI_6, 1)] {
        let r = check(&gpu, &s, &Settings { params: vec![0.3, tilt], seed, ..Settings::default() }).unwrap();
        show(&r);
        assert!(r.passed, "tilt {tilt}, seed {seed}: {:?}", r.failed());
    }
    let rejecting = UserSampler::from_files(
        &[cone],
        "select(cone_sample(wi, u, params), vec4<f32>(0.0), u.x < 1e-3)",
        "cone_pdf",
        None,
        Domain::Sphere,
    )
    .unwrap();
    let r = check(&gpu, &rejecting, &Settings { params: vec![0.3, 0.0], seed: 2, ..Settings::default() }).unwrap();
    show(&r);
    assert!(r.failed().contains(&"chi2"), "a cone rejecting 0.1 % of its samples passed: {:?}", r.failed());
}
