//! No false verdicts: every correct sampler that lobes ships (`examples/samplers/*.wgsl` but the
//! `broken_*` ones, lobes' own samplers as `lobes check` judges them, `UserSampler::builtin`, and
//! an IBL prefilter's `importanceSampleGGX` as renderers write it,
//! `tests/fixtures/samplers/ibl_prefilter.wgsl`) is judged by `lobes check` at the default
//! settings over the parameters its docs allow — α from 10⁻³ to 2, isotropic and 50:1
//! anisotropic, incidence from 0 to 89.9°, g from −0.99 to 0.99 — with no fail of a check that
//! judges pointwise (`pdf_consistency`, `jacobian`, `pdf_values`, `weights`, `hard_cases`), and
//! statistical fails (`chi2`, `albedo`, `normalization`) no more than chance allows at the
//! significance (a binomial bound over the runs, P(more) < 10⁻³) besides the known systematic
//! ones listed in [`KNOWN`]; and every deliberately broken example (`examples/samplers/broken_*.wgsl`,
//! and broken variants of Henyey–Greenstein and the IBL sampler) still fails by the check that
//! should catch it, at its documented parameters and at a narrow lobe where the f32 allowances
//! are widest.
//!
//! The grid is a fixed selection (each α with one incident angle, every angle met), to keep
//! the test to about two minutes on two CPU cores with lavapipe.

use statrs::distribution::{Binomial, DiscreteCDF};
use lobes::check::{Domain, Report, Settings, UserSampler, check};
use lobes::engine::gpu::Gpu;
use lobes::reference::sampler::REGISTRY;
use std::path::PathBuf;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("lobes check needs a GPU adapter: {e}"))
}

fn files(names: &[&str]) -> Vec<PathBuf> {
    names.iter().map(|n| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers").join(n)).collect()
}

fn sampler(names: &[&str], sample: &str, pdf: &str, eval: Option<&str>) -> UserSampler {
    UserSampler::from_files(&files(names), sample, pdf, eval, Domain::Sphere).unwrap_or_else(|e| panic!("{e}"))
}

/// The rectangle light of `rect_light.wgsl` sampled by area (`--measure area`, its normal −z),
/// judged against `pdf`.
fn rect_light(sample: &str, pdf: &str) -> UserSampler {
    let composition = lobes::check::Composition::default().normal("vec3<f32>(0.0, 0.0, -1.0)");
    let area = lobes::check::Conventions { measure: lobes::check::conventions::Measure::Area, ..Default::default() };
    UserSampler::from_repository(&files(&["rect_light.wgsl"]), sample, pdf, None, Domain::Sphere, composition).and_then(|s| s.with_conventions(area)).unwrap_or_else(|e| panic!("{e}"))
}

/// The rectangle light's (centre x, y, height, side x, side y): 0.4 sr off the normal,
/// 2.5·10⁻³ sr overhead, 2.2 sr close above (most of the hemisphere's projected area), 0.12 sr
/// towards the horizon (θ 76°), and 10⁻⁴ and 4·10⁻⁶ sr overhead (binned on a cap fitted to them,
/// `lobes::check::support`; on the sphere's grid the quadrature did not converge there: no verdict).
const RECT_LIGHTS: [[f64; 5]; 6] =
    [[0.3, -0.2, 1.0, 0.8, 0.6], [0.1, 0.1, 1.0, 0.05, 0.05], [0.0, 0.0, 0.5, 4.0, 4.0], [2.0, 0.0, 0.5, 1.0, 1.0], [0.0, 0.0, 1.0, 0.01, 0.01], [0.1, 0.1, 1.0, 0.002, 0.002]];

/// The sphere light of `cone_light.wgsl` (its cone's axis θ, φ in radians and sin ρ): 10⁻⁶ sr,
/// ρ 0.002 rad, 0.01 rad at the horizon (θ 89.4°) and 0.05 rad, each binned on a fitted cap.
const CONE_LIGHTS: [[f64; 3]; 4] = [[0.5, 0.3, 5.64e-4], [0.5, 0.3, 0.002], [1.5608, 1.0, 0.01], [0.7, -2.0, 0.05]];

/// The light runs' samples: 2²⁰ (the locating of its edges, not the histogram, costs the time).
const LIGHT_SAMPLES: u64 = 1 << 20;

/// The statistical checks: at significance α each fails a correct sampler with probability
/// about α (`normalization` is a 4σ bound, far less).
const STATISTICAL: [&str; 3] = ["chi2", "albedo", "normalization"];

/// Statistical fails of correct samplers that are systematic, not chance (measured on lavapipe),
/// each with what is known of its cause; the sweep prints every fail and asserts the others stay
/// within chance. None now. (Beckmann VNDF at α (0.05, 0.001), θi 80° was here, χ² 82.7 on 23
/// dof at seed 1: a ridge of the lobe's tail below the horizon slipped between the quadrature's
/// nodes, 9.8 samples of 2²⁴ expected in a bin where the pdf integrates to 74.1, which the retry of
/// disputed bins now finds (`a_ridge_between_the_nodes_is_integrated_again`). Beckmann VNDF at
/// α 0.3, θi 89.9° was here too: its tail's spot below the horizon, found by the retry of bins with
/// samples and no probability.)
const KNOWN: [&str; 0] = [];

/// (αx, αy, θi): α from 10⁻³ to 2, the 50:1 anisotropic pairs, every θi from 0 to 89.9°; the
/// first two are the narrow lobes of issue 23 (α 10⁻³ and 0.0064 at 45°).
const MICROFACET: [(f64, f64, f64); 8] =
    [(1e-3, 1e-3, 45.0), (0.0064, 0.0064, 45.0), (0.05, 0.05, 0.0), (0.3, 0.3, 89.9), (1.0, 1.0, 60.0), (2.0, 2.0, 30.0), (0.05, 1e-3, 80.0), (2.0, 0.04, 10.0)];

/// One verdict of the sweep.
struct Run {
    what: String,
    report: Report,
}

/// The IBL prefilter's sampler (tests/fixtures/samplers/ibl_prefilter.wgsl) as a renderer calls
/// it: a Hammersley-style point (here u.xy), the normal +z, the perceptual roughness p0, a half
/// vector returned, directions below the horizon discarded; `pdf` is the density of d.
fn ibl(pdf: &str) -> UserSampler {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/samplers/ibl_prefilter.wgsl");
    let composition = lobes::check::Composition::default().sample_returns(lobes::check::SampleReturns::HalfVector);
    let s = UserSampler::from_repository(&[path], "importance_sample_ggx(u.xy, vec3<f32>(0.0, 0.0, 1.0), p0)", pdf, None, Domain::Sphere, composition)
        .unwrap_or_else(|e| panic!("{e}"));
    s.with_conventions(lobes::check::Conventions { reflection_only: true, ..Default::default() }).unwrap_or_else(|e| panic!("{e}"))
}

const IBL_PDF: &str = "ibl_pdf(wi, d, p0)";

fn run(gpu: &Gpu, what: String, s: &UserSampler, settings: Settings) -> Run {
    let started = std::time::Instant::now();
    let report = check(gpu, s, &settings).unwrap_or_else(|e| panic!("{what}: {e}"));
    eprintln!("{what}: {} in {:.1} s", if report.passed { "pass".to_string() } else { format!("FAIL {:?}", report.failed()) }, started.elapsed().as_secs_f64());
    for c in report.checks.iter().filter(|c| !c.passed) {
        eprintln!("    {}: {}", c.name(), c.summary);
    }
    if let Some(j) = report.figures::<lobes::check::jacobian::JacobianCheck>() {
        eprintln!(
            "    jacobian systematic: {} of {} resolved off (limit {:.0}), median |pdf · |J| − 1| {:.1e}",
            j.systematic_off,
            j.resolved,
            j.systematic_limit,
            j.median_deviation.unwrap_or(f64::NAN)
        );
    }
    Run { what, report }
}

/// One run of the sweep: what it is, the sampler, its settings.
type Job<'a> = (String, &'a UserSampler, Settings);

/// Runs the jobs on two threads, each with its own adapter (a check spends part of its time in
/// one-threaded work: the driver's shader compiler, the host's quadrature), in their order.
fn run_all(jobs: Vec<Job>) -> Vec<Run> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut done: Vec<(usize, Run)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..2)
            .map(|_| {
                scope.spawn(|| {
                    let gpu = gpu();
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some((what, s, settings)) = jobs.get(i) else { break mine };
                        mine.push((i, run(&gpu, what.clone(), s, settings.clone())));
                    }
                })
            })
            .collect();
        workers.into_iter().flat_map(|w| w.join().unwrap()).collect()
    });
    done.sort_by_key(|d| d.0);
    done.into_iter().map(|d| d.1).collect()
}

#[test]
fn correct_samplers_pass_over_their_documented_range() {
    let mut jobs: Vec<Job> = Vec::new();
    let ggx = sampler(&["ggx_vndf.wgsl"], "ggx_sample", "ggx_pdf", Some("ggx_eval"));
    let beckmann = sampler(&["beckmann_vndf.wgsl"], "beck_sample", "beck_pdf", None);
    let glass = sampler(&["ggx_vndf.wgsl", "rough_dielectric.wgsl"], "rd_sample", "rd_pdf", Some("rd_eval"));
    let mixture = sampler(&["ggx_vndf.wgsl", "ggx_diffuse_mixture.wgsl"], "mix_sample", "mix_pdf", None);
    for (i, &(ax, ay, theta)) in MICROFACET.iter().enumerate() {
        let at = |params: Vec<f64>| Settings { params, incident_theta: theta, incident_phi: 20.0, ..Settings::default() };
        jobs.push((format!("ggx_vndf α ({ax}, {ay}) θi {theta}"), &ggx, at(vec![ax, ay])));
        jobs.push((format!("beckmann_vndf α ({ax}, {ay}) θi {theta}"), &beckmann, at(vec![ax, ay])));
        // glass from outside and (every other α) from inside, η 1.5 and its inverse
        let eta = if i % 2 == 0 { 1.5 } else { 1.0 / 1.5 };
        jobs.push((format!("rough_dielectric α ({ax}, {ay}) η {eta:.3} θi {theta}"), &glass, at(vec![ax, ay, eta])));
        let w = [0.5, 0.25, 0.9][i % 3];
        jobs.push((format!("ggx_diffuse_mixture α ({ax}, {ay}) w {w} θi {theta}"), &mixture, at(vec![ax, ay, w])));
    }
    let hg = sampler(&["henyey_greenstein.wgsl"], "hg_sample", "hg_pdf", Some("hg_eval"));
    for g in [-0.99, -0.95, -0.5, 0.0, 0.3, 0.9, 0.95, 0.99] {
        jobs.push((format!("henyey_greenstein g {g}"), &hg, Settings { params: vec![g], ..Settings::default() }));
    }
    let ibl_sampler = ibl(IBL_PDF);
    for (roughness, theta) in [(0.1, 30.0), (0.3, 60.0), (0.7, 10.0)] {
        let settings = Settings { params: vec![roughness], incident_theta: theta, incident_phi: 20.0, ..Settings::default() };
        jobs.push((format!("ibl_prefilter roughness {roughness} θi {theta}"), &ibl_sampler, settings));
    }
    let plane = Domain::Plane { bounds: [0.0, 0.0, 1.0, 1.0] };
    let env = UserSampler::from_files(&files(&["piecewise_2d.wgsl"]), "env_sample", "env_pdf", None, plane).unwrap();
    for seed in [1, 2] {
        jobs.push((format!("piecewise_2d seed {seed}"), &env, Settings { seed, ..Settings::default() }));
    }
    let light = rect_light("rect_sample", "rect_pdf");
    for params in RECT_LIGHTS {
        jobs.push((format!("rect_light {params:?}"), &light, Settings { params: params.to_vec(), samples: LIGHT_SAMPLES, ..Settings::default() }));
    }
    let cone = sampler(&["cone_light.wgsl"], "cone_sample", "cone_pdf", None);
    for params in CONE_LIGHTS {
        jobs.push((format!("cone_light {params:?}"), &cone, Settings { params: params.to_vec(), samples: LIGHT_SAMPLES, ..Settings::default() }));
    }
    // lobes' own samplers as a user's: every other configuration of the grid each
    let builtins: Vec<UserSampler> = REGISTRY.iter().map(UserSampler::builtin).collect();
    for (j, (spec, s)) in REGISTRY.iter().zip(&builtins).enumerate() {
        for &(ax, ay, theta) in MICROFACET.iter().skip(j % 2).step_by(2) {
            let settings = Settings { params: vec![ax, ay], incident_theta: theta, incident_phi: 20.0, ..Settings::default() };
            jobs.push((format!("builtin {} α ({ax}, {ay}) θi {theta}", spec.name()), s, settings));
        }
    }
    let runs = run_all(jobs);

    let pointwise: Vec<String> = runs
        .iter()
        .flat_map(|r| r.report.failed().into_iter().filter(|c| !STATISTICAL.contains(c)).map(move |c| format!("{}: {c}", r.what)))
        .collect();
    let statistical: Vec<&Run> = runs.iter().filter(|r| r.report.failed().iter().any(|c| STATISTICAL.contains(c))).collect();
    let unexplained: Vec<&&Run> = statistical.iter().filter(|r| !KNOWN.iter().any(|k| r.what.starts_with(k))).collect();
    let n = runs.len() as u64;
    // each run's statistical checks: chi2 and, with an eval, albedo, each at α = 0.01
    let p = 2.0 * Settings::default().significance;
    let chance = (0..n).find(|&k| Binomial::new(p, n).unwrap().sf(k) < 1e-3).unwrap();
    eprintln!(
        "correct samplers: {n} runs, {} failed a pointwise check, {} a statistical one (chance alone: at most {chance}, P(more) < 1e-3 at {p} per run)",
        pointwise.len(),
        statistical.len()
    );
    for r in &statistical {
        let known = if unexplained.iter().any(|u| u.what == r.what) { "" } else { " (known, KNOWN)" };
        eprintln!("  statistical fail: {} {:?}{known}", r.what, r.report.failed());
    }
    assert!(pointwise.is_empty(), "correct samplers failed pointwise checks: {pointwise:#?}");
    let listed: Vec<String> = unexplained.iter().map(|r| format!("{}: {:?}", r.what, r.report.failed())).collect();
    assert!(unexplained.len() as u64 <= chance, "{} statistical fails beyond the known ones, more than chance allows ({chance}): {listed:#?}", unexplained.len());
}

/// Each broken example fails by its check at its documented parameters, and at a narrow lobe
/// (α 0.0064, θi 45°) where the f32 allowances are widest.
#[test]
fn broken_samplers_still_fail_by_their_check() {
    let gpu = gpu();
    type Case<'a> = (&'a str, UserSampler, Vec<f64>, f64, &'a [&'a str]);
    let cases: Vec<Case> = vec![
        ("broken_no_jacobian", sampler(&["ggx_vndf.wgsl", "broken_no_jacobian.wgsl"], "broken_sample_no_jacobian", "broken_pdf_no_jacobian", None), vec![0.3, 0.3], 30.0, &["jacobian", "chi2"]),
        ("broken_no_jacobian", sampler(&["ggx_vndf.wgsl", "broken_no_jacobian.wgsl"], "broken_sample_no_jacobian", "broken_pdf_no_jacobian", None), vec![0.0064, 0.0064], 45.0, &["jacobian", "chi2"]),
        ("broken_mitsuba_g1", sampler(&["beckmann_vndf.wgsl", "broken_mitsuba_g1.wgsl"], "mitsuba_sample", "mitsuba_pdf", None), vec![0.8, 0.8], 85.0, &["normalization"]),
        ("broken_dielectric no η²", sampler(&["ggx_vndf.wgsl", "rough_dielectric.wgsl", "broken_dielectric.wgsl"], "brd_no_eta2_sample", "brd_no_eta2_pdf", None), vec![0.3, 0.3, 1.5], 30.0, &["jacobian"]),
        ("broken_dielectric no η²", sampler(&["ggx_vndf.wgsl", "rough_dielectric.wgsl", "broken_dielectric.wgsl"], "brd_no_eta2_sample", "brd_no_eta2_pdf", None), vec![0.0064, 0.0064, 1.5], 45.0, &["jacobian"]),
        ("broken_dielectric reflection J", sampler(&["ggx_vndf.wgsl", "rough_dielectric.wgsl", "broken_dielectric.wgsl"], "brd_reflection_j_sample", "brd_reflection_j_pdf", None), vec![0.3, 0.3, 1.5], 30.0, &["jacobian"]),
        ("broken_mixture_weight", sampler(&["ggx_vndf.wgsl", "ggx_diffuse_mixture.wgsl", "broken_mixture_weight.wgsl"], "broken_mix_sample", "broken_mix_pdf", None), vec![0.2, 0.2, 0.25], 40.0, &["jacobian"]),
        ("broken_mixture_weight", sampler(&["ggx_vndf.wgsl", "ggx_diffuse_mixture.wgsl", "broken_mixture_weight.wgsl"], "broken_mix_sample", "broken_mix_pdf", None), vec![0.0064, 0.0064, 0.25], 45.0, &["jacobian"]),
        // where the f32 staircase of the map is steepest: Henyey–Greenstein at g 0.99 judged
        // against the density of g 0.989 (its peak 18 % lower)
        ("henyey_greenstein pdf of g 0.989", sampler(&["henyey_greenstein.wgsl"], "hg_sample", "hg_density(0.989, clamp(dot(-wi, d), -1.0, 1.0))", None), vec![0.99], 30.0, &["jacobian"]),
        // the IBL sampler at roughness 0.1 with the density of h for that of d (no 1/(4 v·h))
        ("ibl_prefilter pdf of h", ibl("ibl_pdf(wi, d, p0) * 4.0 * max(dot(wi, normalize(wi + d)), 0.0)"), vec![0.1], 30.0, &["jacobian"]),
        // a light sampled by area whose pdf function is left per unit area (the classic MIS bug),
        // or converted without |n·d|, towards the horizon (2 away, |n·d| about 0.24)
        ("rect_light pdf per area", rect_light("rect_sample", "rect_pdf_area"), RECT_LIGHTS[3].to_vec(), 30.0, &["pdf_consistency", "normalization"]),
        ("rect_light pdf without |n·d|", rect_light("rect_sample", "rect_pdf_no_cosine"), RECT_LIGHTS[3].to_vec(), 30.0, &["pdf_consistency", "normalization"]),
        // a cone of 10⁻³ rad whose 1 − cos ρ is taken as 1 − √(1 − sin²ρ) (7 % off in f32), and
        // a 5 % warp inside cones of 0.002 rad and of 0.01 rad at the horizon
        ("cone_light naive 1 − cos", sampler(&["cone_light.wgsl"], "cone_sample_naive", "cone_pdf", None), vec![0.5, 0.3, 0.001], 30.0, &["pdf_consistency", "chi2"]),
        ("cone_light warped", sampler(&["cone_light.wgsl"], "cone_sample_warped", "cone_pdf", None), CONE_LIGHTS[1].to_vec(), 30.0, &["chi2"]),
        ("cone_light warped", sampler(&["cone_light.wgsl"], "cone_sample_warped", "cone_pdf", None), CONE_LIGHTS[2].to_vec(), 30.0, &["chi2"]),
    ];
    let mut caught = 0;
    let mut missed = Vec::new();
    for (name, s, params, theta, by) in &cases {
        let r = run(&gpu, format!("{name} params {params:?} θi {theta}"), s, Settings { params: params.clone(), incident_theta: *theta, ..Settings::default() });
        let failed = r.report.failed();
        if by.iter().all(|c| failed.contains(c)) {
            caught += 1;
        } else {
            missed.push(format!("{}: failed {failed:?}, expected {by:?}", r.what));
        }
    }
    eprintln!("broken samplers: {} runs, {caught} caught by their check", cases.len());
    assert!(missed.is_empty(), "{missed:#?}");
}

/// A GGX visible-normal sampler whose pdf takes D in the form α² / (π ((α² − 1) m.z² + 1)²),
/// as many renderers write it (an ulp of m.z becomes ≈ 4/α² ulps of D), and reports that very
/// pdf function at its d: at α 0.0079, θi 45° the two f32 evaluations differ by more than 10⁻³
/// (measured 3.7·10⁻³ on lavapipe), within the pdf's f32 conditioning, and `pdf_consistency`
/// passes; the same sampler reporting 1.02 × its pdf fails it.
#[test]
fn an_ill_conditioned_pdf_is_judged_against_its_f32_conditioning() {
    let mz = |factor: &str| {
        format!(
            "fn mz_d(mz: f32, a: f32) -> f32 {{\n let t = (a * a - 1.0) * mz * mz + 1.0;\n return a * a / (GGX_PI * t * t);\n}}\n\
             fn mz_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n let a = params[0].x;\n let m = wi + d;\n\
             if (wi.z <= 0.0 || dot(m, m) == 0.0) {{ return 0.0; }}\n let h = normalize(m);\n\
             if (dot(wi, h) <= 0.0 || h.z <= 0.0) {{ return 0.0; }}\n return ggx_g1(wi, vec2<f32>(a)) * mz_d(h.z, a) / (4.0 * wi.z);\n}}\n\
             fn mz_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
             if (wi.z <= 0.0) {{ return vec4<f32>(0.0, 0.0, 1.0, 0.0); }}\n let a = params[0].x;\n\
             let h = ggx_visible_normal(wi, vec2<f32>(a), u.xy);\n let d = 2.0 * dot(wi, h) * h - wi;\n\
             return vec4<f32>(d, {factor} * mz_pdf(wi, d, params));\n}}\n"
        )
    };
    let gpu = gpu();
    let settings = Settings { params: vec![0.0079], incident_theta: 45.0, samples: 1 << 20, ..Settings::default() };
    let judged = |factor: &str| {
        let mut sources = vec![lobes::check::Source::read(&files(&["ggx_vndf.wgsl"])[0]).unwrap()];
        sources.push(lobes::check::Source { name: "mz.wgsl".into(), text: mz(factor) });
        let s = UserSampler::from_sources(sources, "mz_sample", "mz_pdf", None, Domain::Sphere).unwrap_or_else(|e| panic!("{e}"));
        run(&gpu, format!("m.z-form GGX × {factor}"), &s, settings.clone()).report
    };
    let r = judged("1.0");
    let c = r.figures::<lobes::check::report::ConsistencyFigures>().unwrap();
    assert!(r.get("pdf_consistency").unwrap().passed && c.max_relative_difference > 1e-3 && c.widened > 0, "{c:?}");
    assert!(r.passed, "{:?}", r.failed());
    let r = judged("1.02");
    assert!(!r.get("pdf_consistency").unwrap().passed, "{}", r.get("pdf_consistency").unwrap().summary);
}

/// The example GGX visible-normal sampler (`sample`: its function or an expression over it,
/// judged against `ggx_pdf`) at θi 89°, isotropic α, φi `phi` in degrees: its run and χ² figures.
fn grazing_ggx(gpu: &Gpu, sample: &str, alpha: f64, phi: f64, note: &str) -> (Run, lobes::check::report::Chi2Figures) {
    let settings = Settings { params: vec![alpha, alpha], incident_theta: 89.0, incident_phi: phi, ..Settings::default() };
    let r = run(gpu, format!("ggx_vndf α {alpha:e} θi 89 φi {phi} {note}"), &sampler(&["ggx_vndf.wgsl"], sample, "ggx_pdf", None), settings);
    let c = r.report.figures::<lobes::check::report::Chi2Figures>().unwrap().clone();
    (r, c)
}

/// A grazing mirror lobe on the φ = ±π seam (GGX visible normals, α 10⁻⁴, θi 89°, φi 0): across
/// the plane of incidence it is about 2α cos θi = 3.5·10⁻⁶ rad wide, and f32's t = (φ + π)/2π
/// rounds onto the seam from half an ulp below it (φ = π − 10⁻⁷ gave t = 1: column 0), while the
/// quadrature's parts, with φ in f32, overlapped there by twice f32(π) − π = 1.7·10⁻⁷ rad. Before
/// `lobes check` shared the engine's axis-exact binning (`lobes_axis_column`) and measured its
/// parts' φ from the nearest axis, this correct sampler failed `chi2` (χ² 3751 on 13 dof,
/// ∫pdf = 1.0246, measured on lavapipe); now it passes, with ∫pdf within 10⁻³ of 1, and the same
/// sampler with its incident direction turned 10⁻⁷ rad about the normal (the mirror 1/35 of the
/// lobe's width off the seam) fails `chi2`.
#[test]
fn a_grazing_lobe_on_the_seam_is_judged_as_sampled() {
    let gpu = gpu();
    let (r, c) = grazing_ggx(&gpu, "ggx_sample", 1e-4, 0.0, "(the seam)");
    assert!(r.report.passed, "{:?}: χ² {:?}", r.report.failed(), c.chi2);
    assert!((c.pdf_integral - 1.0).abs() < 1e-3, "∫pdf = {}", c.pdf_integral);
    assert!(c.chi2.dof >= 1, "the seam must split the lobe into two cells: {:?}", c.chi2);
    // wi turned by ε about the normal, (x − ε y, y + ε x, z); the pdf judged at the untouched wi
    let (r, _) = grazing_ggx(&gpu, "ggx_sample(vec3<f32>(wi.x - 1e-7 * wi.y, wi.y + 1e-7 * wi.x, wi.z), u, params).xyz", 1e-4, 0.0, "sampled 1e-7 rad turned");
    assert!(r.report.failed().contains(&"chi2"), "a lobe turned 1e-7 rad passed: {:?}", r.report.failed());
}

/// A ridge narrower than the quadrature's nodes: Beckmann visible normals at α (0.05, 0.001),
/// θi 80°, φi 20°, whose tail below the horizon is a ridge about 10⁻³ rad across. The 5 × 5 and
/// 3 × 3 rules agreed on 9.8 samples of 2²⁴ in the bin at row 28, column 7 (cos θ in [−1/8,
/// −3/32)), where the pdf integrates to 74.1 and 68–77 were observed at seeds 1–4. The check's
/// expected counts there, after the retry of disputed bins, are held to an independent integral:
/// the visible-normal density of h (lobes' f64 reference) summed over a 4000 × 4000 grid of
/// slopes within 6α, each h's mass put in the bin of its reflection.
#[test]
fn a_ridge_between_the_nodes_is_integrated_again() {
    use lobes::reference::{Lobe, LobeKind, Method};
    let (ax, ay, theta, phi) = (0.05, 0.001, 80.0, 20.0);
    let gpu = gpu();
    let settings = Settings { params: vec![ax, ay], incident_theta: theta, incident_phi: phi, ..Settings::default() };
    let r = run(&gpu, format!("beckmann_vndf α ({ax}, {ay}) θi {theta}"), &sampler(&["beckmann_vndf.wgsl"], "beck_sample", "beck_pdf", None), settings.clone());
    assert!(r.report.passed, "{:?}", r.report.failed());
    // the h-space integral, at the f32 incident direction the check uses
    let lobe = Lobe { kind: LobeKind::Beckmann, method: Method::Vndf, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 };
    let w = lobes::reference::reflect::spherical(theta.to_radians(), phi.to_radians());
    let wi = glam::DVec3::new(w.x as f32 as f64, w.y as f32 as f64, w.z as f32 as f64);
    let (rows, cols, k) = (r.report.rows as usize, r.report.cols as usize, 4000usize);
    let (sx, sy) = (12.0 * ax / k as f64, 12.0 * ay / k as f64);
    let mut mass = vec![0.0f64; rows * cols];
    for i in 0..k {
        for j in 0..k {
            let h = glam::DVec3::new(6.0 * ax - (i as f64 + 0.5) * sx, 6.0 * ay - (j as f64 + 0.5) * sy, 1.0).normalize();
            let d = 2.0 * wi.dot(h) * h - wi;
            let row = (((d.z + 1.0) * 0.5 * rows as f64) as usize).min(rows - 1);
            let col = (((d.y.atan2(d.x) / std::f64::consts::TAU + 0.5) * cols as f64) as usize).min(cols - 1);
            // p(h) dω over a cell of slopes: dω = h.z³ dslope²
            mass[row * cols + col] += lobe.pdf_h(wi, h) * h.z.powi(3) * sx * sy;
        }
    }
    let n = r.report.samples as f64;
    for (row, col) in [(28usize, 7usize), (29, 7), (30, 7), (31, 7)] {
        let (e, want) = (r.report.expected[row * cols + col], n * mass[row * cols + col]);
        eprintln!("row {row}, column {col}: expected {e:.2}, the slopes' sum {want:.2}");
        assert!((e - want).abs() <= 0.25 * want.sqrt().max(1.0), "row {row}, column {col}: the check expects {e}, the pdf integrates to {want}");
    }
}

/// A grazing lobe on a column edge off the axes (GGX visible normals, α 10⁻³, θi 89°, φi
/// 2.8125°: the mirror on the edge next to the seam, across which the lobe is about 2α cos θi =
/// 3.5·10⁻⁵ rad wide). f32 binning places that edge within about 2·10⁻⁷ rad, a share of the lobe
/// that split its samples unevenly: χ² 3597 on 150 dof, a false failure (measured on lavapipe
/// before the check judged the bins beside such an edge as one cell). Now it passes with edges
/// joined, and the same sampler with a lobe 10 % rougher than its pdf still fails.
#[test]
fn a_grazing_lobe_on_an_off_axis_edge_is_judged_as_one_cell() {
    let gpu = gpu();
    let (r, c) = grazing_ggx(&gpu, "ggx_sample", 1e-3, 2.8125, "(an off-axis edge)");
    assert!(r.report.passed, "{:?}: χ² {:?}", r.report.failed(), c.chi2);
    assert!(c.joined_edges >= 1 && c.chi2.dof >= 10, "joined {} edges, {} dof", c.joined_edges, c.chi2.dof);
    let rougher = "ggx_sample(wi, u, array<vec4<f32>, 4>(params[0] * 1.1, params[1], params[2], params[3])).xyz";
    let (r, _) = grazing_ggx(&gpu, rougher, 1e-3, 2.8125, "sampled 10 % rougher");
    assert!(r.report.failed().contains(&"chi2"), "a lobe 10 % rougher passed: {:?}", r.report.failed());
}
