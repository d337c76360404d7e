//! The conventions a sampler declares instead of writing guards (`--incident upper`,
//! `--reflection-only`, `--u-open`, `--measure projected`, `--frame y-up`), and the messages
//! that say where and what. Each convention: a sampler written in it passes with the flag and
//! fails without it (or with the wrong one), and a broken one still fails with it.

use lobes::check::hard::HardRow;
use lobes::check::report::{Chi2Figures, PdfValuesFigures};
use lobes::check::{CheckError, Conventions, Domain, Frame, Incident, Measure, Report, Setting, Settings, Source, UserSampler, check};
use lobes::engine::gpu::Gpu;
use std::path::PathBuf;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("lobes check needs a GPU adapter: {e}"))
}

fn show(r: &Report) {
    for c in &r.checks {
        eprintln!("{}: {} {} {}", r.sampler, c.name(), c.passed, c.summary);
    }
}

fn sampler(name: &str, text: &str, sample: &str, pdf: &str, eval: Option<&str>, conventions: Conventions) -> UserSampler {
    let ggx = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers/ggx_vndf.wgsl");
    let sources = vec![
        Source { name: "ggx_vndf.wgsl".into(), text: std::fs::read_to_string(ggx).unwrap() },
        Source { name: name.into(), text: text.into() },
    ];
    UserSampler::from_sources(sources, sample, pdf, eval, Domain::Sphere).unwrap().with_conventions(conventions).unwrap()
}

fn run(s: &UserSampler, settings: &Settings) -> Report {
    let r = check(&gpu(), s, settings).unwrap_or_else(|e| panic!("{e}"));
    show(&r);
    r
}

fn small() -> Settings {
    Settings { samples: 1 << 20, bins: Some((32, 64)), ..Settings::default() }
}

const UPPER: Conventions = Conventions { incident: Incident::Upper, reflection_only: false, u_open: false, measure: Measure::SolidAngle, frame: Frame::ZUp };

fn with(f: impl FnOnce(&mut Conventions)) -> Conventions {
    let mut c = Conventions::default();
    f(&mut c);
    c
}

/// ggx_vndf.wgsl's sampler without its guard against light from below (as most renderers write
/// it): from below, wi.z < 0 makes its pdf negative. Declared `--incident upper` it passes; on the
/// whole sphere the hard cases from below fail; a missing reflection Jacobian fails either way.
#[test]
fn incident_upper() {
    let text = "fn upper_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {\n\
                let h = ggx_visible_normal(wi, params[0].xy, u.xy);\n let d = 2.0 * dot(wi, h) * h - wi;\n\
                return vec4<f32>(d, upper_pdf(wi, d, params));\n}\n\
                fn upper_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {\n\
                let a = params[0].xy;\n let m = wi + d;\n if (dot(m, m) == 0.0) { return 0.0; }\n\
                let h = normalize(m);\n if (dot(wi, h) <= 0.0) { return 0.0; }\n\
                return ggx_g1(wi, a) * ggx_d(h, a) / (4.0 * wi.z);\n}\n\
                fn upper_broken_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {\n\
                let h = normalize(wi + d);\n return 4.0 * abs(dot(d, h)) * upper_pdf(wi, d, params);\n}\n\
                fn upper_broken_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {\n\
                let s = upper_sample(wi, u, params);\n return vec4<f32>(s.xyz, upper_broken_pdf(wi, s.xyz, params));\n}\n";
    let settings = Settings { params: vec![0.3, 0.3], ..small() };
    let r = run(&sampler("upper.wgsl", text, "upper_sample", "upper_pdf", None, UPPER), &settings);
    r.assert_passed();
    let rows = r.figures::<Vec<HardRow>>().unwrap();
    assert!(rows.iter().all(|row| row.incident_theta < 90.0) && rows.len() == 4, "{rows:?}");

    let r = run(&sampler("upper.wgsl", text, "upper_sample", "upper_pdf", None, Conventions::default()), &settings);
    assert_eq!(r.failed(), ["hard_cases"]);
    let failing: Vec<f64> = r.figures::<Vec<HardRow>>().unwrap().iter().filter(|r| !r.passed).map(|r| r.incident_theta).collect();
    assert!(failing.iter().all(|&t| t > 90.0) && !failing.is_empty(), "{failing:?}");
    // the message shows what the failing sample got
    let summary = &r.get("hard_cases").unwrap().summary;
    assert!(summary.contains(": d = (") && summary.contains(", pdf = "), "{summary}");

    let r = run(&sampler("upper.wgsl", text, "upper_broken_sample", "upper_broken_pdf", None, UPPER), &settings);
    assert!(!r.get("jacobian").unwrap().passed && !r.get("chi2").unwrap().passed);

    // an incident direction from below is refused, before any GPU work, keyed by its setting
    let e = check(&gpu(), &sampler("upper.wgsl", text, "upper_sample", "upper_pdf", None, UPPER), &Settings { incident_theta: 120.0, ..settings }).unwrap_err();
    assert!(matches!(e, CheckError::Setting { setting: Setting::IncidentTheta, .. }), "{e}");
    assert!(e.is_input() && e.to_string().starts_with("incident_theta: 120°") && e.to_string().contains("declared for upper incidence"), "{e}");
}

/// A sampler of the whole sphere whose pdf formula holds only above the horizon (NaN below, as
/// sqrt(d.z)/sqrt(d.z)), the samples below to be discarded (Bevy's bounded VNDF): with
/// `--reflection-only` its samples below are rejections and ∫pdf = ½ = the valid fraction; without
/// it the NaNs fail; normalised as if over the hemisphere (1/2π) it fails even with the flag.
#[test]
fn reflection_only() {
    let sphere = "fn ro_dir(u: vec4<f32>) -> vec3<f32> {\n let z = 1.0 - 2.0 * u.x;\n let r = sqrt(max(0.0, 1.0 - z * z));\n\
                  let phi = 6.2831853 * u.y;\n return vec3<f32>(r * cos(phi), r * sin(phi), z);\n}\n";
    let text = |density: &str| {
        format!(
            "{sphere}fn ro_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n\
             let s = sqrt(d.z);\n return {density} * s / s;\n}}\n\
             fn ro_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
             let d = ro_dir(u);\n return vec4<f32>(d, ro_pdf(wi, d, params));\n}}\n"
        )
    };
    let good = text("0.07957747");
    let reflection = with(|c| c.reflection_only = true);
    let r = run(&sampler("ro.wgsl", &good, "ro_sample", "ro_pdf", None, reflection), &small());
    r.assert_passed();
    let chi2 = r.figures::<Chi2Figures>().unwrap();
    assert!(chi2.passed() && (chi2.pdf_integral - 0.5).abs() < 1e-4, "{}", chi2.pdf_integral);
    assert!((r.invalid[3] as f64 / r.samples as f64 - 0.5).abs() < 0.01 && r.invalid[..3] == [0, 0, 0], "{:?}", r.invalid);

    let r = run(&sampler("ro.wgsl", &good, "ro_sample", "ro_pdf", None, Conventions::default()), &small());
    assert!(!r.passed && !r.get("pdf_values").unwrap().passed && !r.get("hard_cases").unwrap().passed);
    // pdf_values names where: below the horizon, NaN
    let worst = r.figures::<PdfValuesFigures>().unwrap().worst.clone().unwrap();
    assert!(worst.starts_with("ro_pdf(d) = NaN at d = ("), "{worst}");
    let theta: f64 = worst.split("(θ ").nth(1).unwrap().split('°').next().unwrap().parse().unwrap();
    assert!(theta > 90.0, "{worst}");

    let r = run(&sampler("ro.wgsl", &text("0.15915494"), "ro_sample", "ro_pdf", None, reflection), &small());
    assert!(!r.get("normalization").unwrap().passed && !r.get("chi2").unwrap().passed);
    // the χ² line says that the invalid cell is the cause: ∫pdf = 1 leaves (almost) no room for a
    // rejection, and half the samples are rejected
    let summary = &r.get("chi2").unwrap().summary;
    assert!(summary.contains(" invalid samples where ") && summary.contains(" were expected (zero_pdf 5"), "{summary}");
}

/// A reported pdf with a factor (1 − u.x)/(1 − u.x) that cancels but is 0/0 at u.x = 1, which
/// the renderer's uniforms in [0, 1) never reach: `--u-open` passes it, without the flag the hard
/// cases fail at u.x = 1; the same factor in u.x (0/0 at u.x = 0) fails with it.
#[test]
fn u_open() {
    let text = |t: &str| {
        format!(
            "fn uo_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
             let z = 1.0 - 2.0 * u.x;\n let r = sqrt(max(0.0, 1.0 - z * z));\n let phi = 6.2831853 * u.y;\n\
             let t = {t};\n return vec4<f32>(r * cos(phi), r * sin(phi), z, 0.07957747 * t / t);\n}}\n\
             fn uo_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n return 0.07957747;\n}}\n"
        )
    };
    let open = with(|c| c.u_open = true);
    let r = run(&sampler("uo.wgsl", &text("1.0 - u.x"), "uo_sample", "uo_pdf", None, open), &small());
    r.assert_passed();
    assert!(r.get("hard_cases").unwrap().summary.starts_with("1792 inputs at u ∈ {0, 2⁻²⁴, ½, 1 − 2⁻²⁴}⁴ × 7"), "{}", r.get("hard_cases").unwrap().summary);
    let r = run(&sampler("uo.wgsl", &text("1.0 - u.x"), "uo_sample", "uo_pdf", None, Conventions::default()), &small());
    assert_eq!(r.failed(), ["hard_cases"]);
    assert!(r.figures::<Vec<HardRow>>().unwrap().iter().all(|row| row.first_failure.is_some_and(|u| u[0] == 1.0)));
    assert!(r.get("hard_cases").unwrap().summary.contains("pdf = NaN"), "{}", r.get("hard_cases").unwrap().summary);
    let r = run(&sampler("uo.wgsl", &text("u.x"), "uo_sample", "uo_pdf", None, open), &small());
    assert_eq!(r.failed(), ["hard_cases"]);
}

/// Cosine-weighted directions (Malley's method) with the pdf and eval per projected solid
/// angle: pdf 1/π, eval (the BRDF f) albedo/π. With `--measure projected` it passes, with the
/// default (per solid angle) it fails; a pdf of 1/(2π) per projected solid angle fails with it.
/// The same sampler written with its normal along +y passes with `--frame y-up` and fails without.
#[test]
fn measure_projected_and_frame_y_up() {
    let text = |density: &str, y_up: bool| {
        let (n, lift) = if y_up { ("y", "vec3<f32>(p.x, z, p.y)") } else { ("z", "vec3<f32>(p.x, p.y, z)") };
        format!(
            "fn pr_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
             if (wi.{n} <= 0.0) {{ return vec4<f32>(0.0); }}\n\
             let r = sqrt(u.x);\n let phi = 6.2831853 * u.y;\n let p = r * vec2<f32>(cos(phi), sin(phi));\n\
             let z = sqrt(max(0.0, 1.0 - dot(p, p)));\n return vec4<f32>({lift}, select(0.0, {density}, z > 0.0));\n}}\n\
             fn pr_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n\
             return select(0.0, {density}, wi.{n} > 0.0 && d.{n} > 0.0);\n}}\n\
             fn pr_eval(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n\
             return params[0].x * select(0.0, 0.31830989, wi.{n} > 0.0 && d.{n} > 0.0);\n}}\n"
        )
    };
    let projected = with(|c| c.measure = Measure::Projected);
    let settings = Settings { params: vec![0.8], incident_phi: 40.0, ..small() };
    let good = text("0.31830989", false);
    let r = run(&sampler("pr.wgsl", &good, "pr_sample", "pr_pdf", Some("pr_eval"), projected), &settings);
    r.assert_passed();
    let r = run(&sampler("pr.wgsl", &good, "pr_sample", "pr_pdf", Some("pr_eval"), Conventions::default()), &settings);
    assert!(!r.get("normalization").unwrap().passed && !r.get("chi2").unwrap().passed && !r.get("jacobian").unwrap().passed);
    let r = run(&sampler("pr.wgsl", &text("0.15915494", false), "pr_sample", "pr_pdf", Some("pr_eval"), projected), &settings);
    assert!(!r.get("normalization").unwrap().passed);

    // y-up: θ from +y (wi.y = cos 30° > 0)
    let y_up = with(|c| {
        c.measure = Measure::Projected;
        c.frame = Frame::YUp;
    });
    let good_y = text("0.31830989", true);
    let r = run(&sampler("pr_y.wgsl", &good_y, "pr_sample", "pr_pdf", Some("pr_eval"), y_up), &settings);
    r.assert_passed();
    // from below in the y-up frame: every sample rejected (wi.y < 0), as its guard says
    let r = run(&sampler("pr_y.wgsl", &good_y, "pr_sample", "pr_pdf", Some("pr_eval"), y_up), &Settings { incident_theta: 120.0, ..settings.clone() });
    assert_eq!(r.invalid[3], r.samples, "{:?}", r.invalid);
    let r = run(&sampler("pr_y.wgsl", &good_y, "pr_sample", "pr_pdf", Some("pr_eval"), projected), &settings);
    assert!(!r.passed && !r.get("chi2").unwrap().passed, "the y-up sampler read with its normal along +z");
    let r = run(&sampler("pr_y.wgsl", &text("0.15915494", true), "pr_sample", "pr_pdf", Some("pr_eval"), y_up), &settings);
    assert!(!r.get("normalization").unwrap().passed);
}

/// A rejection reported as d = (0, 0, 0) with pdf 0 (half the samples, chosen by u.z) is a
/// `zero_pdf` rejection, as the contract says, not a point outside the domain.
#[test]
fn a_rejection_at_the_origin_is_zero_pdf() {
    let text = "fn z_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {\n\
                if (u.z < 0.5) { return vec4<f32>(0.0); }\n\
                let z = 1.0 - 2.0 * u.x;\n let r = sqrt(max(0.0, 1.0 - z * z));\n let phi = 6.2831853 * u.y;\n\
                return vec4<f32>(r * cos(phi), r * sin(phi), z, 0.5 * 0.07957747);\n}\n\
                fn z_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {\n return 0.5 * 0.07957747;\n}\n";
    let r = run(&sampler("origin.wgsl", text, "z_sample", "z_pdf", None, Conventions::default()), &small());
    r.assert_passed();
    assert!(r.invalid[1] == 0 && (r.invalid[3] as f64 / r.samples as f64 - 0.5).abs() < 0.01, "{:?}", r.invalid);
}

/// Directions of length 0.87: the Jacobian's message names the length as the cause.
#[test]
fn a_non_unit_direction_is_named_by_the_jacobian() {
    let text = "fn nu_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {\n\
                let z = 1.0 - 2.0 * u.x;\n let r = sqrt(max(0.0, 1.0 - z * z));\n let phi = 6.2831853 * u.y;\n\
                return vec4<f32>(0.87 * vec3<f32>(r * cos(phi), r * sin(phi), z), 0.07957747);\n}\n\
                fn nu_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {\n return 0.07957747;\n}\n";
    let r = run(&sampler("short.wgsl", text, "nu_sample", "nu_pdf", None, Conventions::default()), &small());
    let j = r.get("jacobian").unwrap();
    assert!(!j.passed && j.summary.contains("|d| = 0.87 at the worst sample, not a unit vector"), "{}", j.summary);
    let chi2 = r.get("chi2").unwrap();
    assert!(chi2.summary.contains("1 048 576 invalid samples where ") && chi2.summary.contains(" were expected (outside_domain 1 048 576)"), "{}", chi2.summary);
}

/// The flags of `lobes check`: a bad value exits 2 naming the flag and its values; a direction
/// convention on the plane exits 2; `--incident upper` with θ ≥ 90 exits 2 before any GPU work.
#[test]
fn convention_flags() {
    let hg = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers/henyey_greenstein.wgsl");
    for (extra, said) in [
        (vec!["--incident", "lower"], "upper"),
        (vec!["--measure", "volume"], "projected"),
        (vec!["--frame", "x-up"], "y-up"),
        (vec!["--incident", "upper", "--incident-theta", "135"], "--incident-theta"),
        (vec!["--reflection-only", "--incident-theta", "90"], "declared reflection-only"),
        (vec!["--domain", "plane", "--bounds", "0,0,1,1", "--frame", "y-up"], "--frame: only for directions"),
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
        assert!(stderr.contains(said), "{extra:?} should say {said}: {stderr}");
    }
}

/// The same conventions as keys of a scene's sampler; a bad value is an error at its line, and
/// a swept incident θ from below is refused for an `incident = "upper"` sampler.
#[test]
fn convention_scene_keys() {
    let dir = std::env::temp_dir().join(format!("lobes-conventions-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ggx = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers/ggx_vndf.wgsl");
    let scene = |keys: &str, theta: &str| {
        format!(
            "[[case]]\nname = \"g\"\nsampler = {{ wgsl = [{ggx:?}], sample = \"ggx_sample\", pdf = \"ggx_pdf\"{keys} }}\nparams = [0.3, 0.3]\nincident_theta = {theta}\n"
        )
    };
    let parse = |text: &str| lobes::scene::Scene::parse(dir.join("s.toml").to_str().unwrap(), text);
    let s = parse(&scene(", reflection_only = true, u_open = true, measure = \"projected\", frame = \"y-up\"", "[0, 45]")).unwrap();
    let c = s.user_cases[0].sampler.conventions;
    assert!(c.reflection_only && c.u_open && c.measure == Measure::Projected && c.frame == Frame::YUp && c.incident() == Incident::Upper);
    let e = parse(&scene(", incident = \"upper\"", "[0, 120]")).unwrap_err().to_string();
    assert!(e.contains("incident_theta") && e.contains("120"), "{e}");
    let e = parse(&scene(", measure = \"volume\"", "30")).unwrap_err().to_string();
    assert!(e.contains("sampler.measure") && e.contains("projected"), "{e}");
    let e = parse(&scene(", u_open = 1", "30")).unwrap_err().to_string();
    assert!(e.contains("sampler.u_open must be true or false"), "{e}");
}
