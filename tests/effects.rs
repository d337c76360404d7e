//! Effects (issue 5): per-effect-set modules that hold only the code they need, weighted
//! histograms whose albedo is judged against f64 quadrature and the weak white furnace, and the
//! per-bin weight check. Each check is shown to reject a deliberately broken weight.

use lobes::engine::gpu::{Counting, GpuEngine};
use lobes::engine::gpu::effects::{self, PipelineSource, Specialisation};
use lobes::engine::job::{Job, SampleRange, Scatter};
use lobes::reference::effects::Effects;
use lobes::reference::fresnel::Fresnel;
use lobes::reference::masking::Masking;
use lobes::reference::{Lobe, LobeKind, Method, reflect};
use lobes::scene::Scene;
use lobes::stats::chi2::sidak;
use lobes::stats::expected::Quadrature;
use lobes::stats::histogram::SphereGrid;
use lobes::run::compare::albedo_check;
use lobes::stats::weighted::{AlbedoCheck, WEIGHT_ERROR_LIMIT};

fn engine() -> GpuEngine {
    GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"))
}

const GRID: SphereGrid = SphereGrid { rows: 32, cols: 64 };
const N: u64 = 1 << 22;

fn job(kind: LobeKind, method: Method, ax: f64, ay: f64, theta_deg: f64) -> Job {
    let lobe = Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 };
    Job::Lobe { lobe, incident: reflect::spherical(theta_deg.to_radians(), 0.3), grid: GRID, scatter: Scatter::Reflect }
}

/// The names of the functions in a module, as naga parses it.
fn functions(source: &str) -> Vec<String> {
    let module = naga::front::wgsl::parse_str(source).expect("a composed module parses");
    module.functions.iter().filter_map(|(_, f)| f.name.clone()).collect()
}

fn scene_modules(toml: &str) -> Vec<PipelineSource> {
    let scene = Scene::parse("test.toml", toml).unwrap();
    scene.cases.iter().map(|c| effects::case_module(&c.job, c.effects.as_ref(), Counting::Workgroup, c.job.bins() as u32)).collect()
}

#[test]
fn modules_hold_only_the_code_their_effects_need() {
    let ward = scene_modules("[[case]]\nname = \"w\"\nlobe = \"ward\"\nalpha = 0.2\nfresnel = \"schlick\"\nf0 = 0.04\n");
    let names = functions(&ward[0].source);
    assert!(names.iter().any(|n| n == "ward_weight") && names.iter().any(|n| n == "fresnel_schlick"), "{names:?}");
    let microfacet: Vec<&String> =
        names.iter().filter(|n| n.starts_with("ggx_") || n.starts_with("beckmann_") || n.starts_with("microfacet_") || *n == "stretch").collect();
    assert!(microfacet.is_empty(), "a Ward-only module holds microfacet code: {microfacet:?}");
    assert!(!names.iter().any(|n| n.starts_with("masking_")), "Ward has no masking: {names:?}");

    let plain = scene_modules("[[case]]\nname = \"g\"\nlobe = \"ggx\"\nmethod = \"vndf\"\nalpha = 0.2\nmasking = \"height-correlated\"\n");
    let names = functions(&plain[0].source);
    let fresnel: Vec<&String> = names.iter().filter(|n| n.starts_with("fresnel_") || n.starts_with("complex_")).collect();
    assert!(fresnel.is_empty(), "a module without Fresnel holds Fresnel code: {fresnel:?}");
    assert!(names.iter().any(|n| n == "masking_height_correlated") && names.iter().any(|n| n == "ggx_sample_vndf"));
    assert!(!names.iter().any(|n| n.starts_with("beckmann_") || n.starts_with("ward_")), "{names:?}");
    // what remains to choose is an override constant, set per pipeline
    assert!(plain[0].constants.contains(&("MASKING", 3.0)), "{:?}", plain[0].constants);

    // the uber-kernel holds everything, and no override constants
    let e = Effects { fresnel: Fresnel::Dielectric { eta: 1.5 }, masking: Masking::G1 };
    let uber = effects::compose_effects(&job(LobeKind::Ggx, Method::Ndf, 0.3, 0.3, 10.0), &e, Counting::Workgroup, Specialisation::Uber);
    let names = functions(&uber.source);
    for f in ["ward_sample", "beckmann_sample_vndf", "ggx_sample_bounded", "fresnel_conductor", "masking_separable"] {
        assert!(names.iter().any(|n| n == f), "uber-kernel lacks {f}");
    }
    assert!(uber.constants.is_empty());
}

#[test]
fn pipelines_are_made_once_per_effect_set() {
    let mut scene = String::from("[defaults]\nsamples = 65536\nbins = [8, 16]\n");
    for i in 0..100 {
        let alpha = 0.1 + 0.005 * i as f64;
        scene += &format!("[[case]]\nname = \"c{i}\"\nlobe = \"ggx\"\nmethod = \"vndf\"\nalpha = {alpha}\nincident_theta = {}\nfresnel = \"schlick\"\nf0 = {}\nmasking = \"separable\"\n", i % 80, 0.01 * (i % 50) as f64);
    }
    // one more shape: the same lobe with another masking term (another override constant)
    scene += "[[case]]\nname = \"other\"\nlobe = \"ggx\"\nmethod = \"vndf\"\nalpha = 0.3\nmasking = \"g1\"\n";
    let scene = Scene::parse("many.toml", &scene).unwrap();
    let mut e = engine();
    for c in &scene.cases {
        let r = e.weighted(&c.job, c.effects.as_ref().unwrap(), SampleRange::whole(c.seed, c.samples), Specialisation::Specialised).unwrap();
        assert_eq!(r.sums.overflow, 0);
    }
    assert_eq!(e.weighted_pipelines_built(), 2, "101 cases of two effect sets");
}

fn check(e: &mut GpuEngine, job: &Job, effects: &Effects, module: Option<&PipelineSource>, level: f64) -> AlbedoCheck {
    let composed = module.cloned().unwrap_or_else(|| e.weighted_module(job, effects, Specialisation::Specialised));
    let run = e.weighted_with(job, effects, &composed, SampleRange::whole(7, N)).expect("weighted run");
    albedo_check(job, effects, &run.sums, N, level, &Quadrature::default())
}

/// Every sampler with every Fresnel form and masking term somewhere: the albedo agrees with
/// the f64 quadrature of f cos θ, the furnace cases with their closed form, and the sampler's
/// weight with eval · cos / pdf to better than 1e-3 in every bin.
#[test]
fn albedo_matches_quadrature_and_the_white_furnace() {
    use LobeKind::*;
    use Method::*;
    let conductor = Fresnel::Conductor { eta: 0.2, k: 3.9 };
    let cases = [
        (job(Ggx, Vndf, 0.5, 0.5, 60.0), Effects { fresnel: Fresnel::None, masking: Masking::G1 }),
        (job(Ggx, Bounded, 0.3, 0.3, 75.0), Effects { fresnel: Fresnel::None, masking: Masking::G1 }),
        (job(Beckmann, Ndf, 0.5, 0.5, 60.0), Effects { fresnel: Fresnel::None, masking: Masking::G1 }),
        (job(Beckmann, Ndf, 0.4, 0.4, 70.0), Effects { fresnel: Fresnel::None, masking: Masking::None }),
        (job(Ggx, Ndf, 0.2, 0.2, 20.0), Effects { fresnel: Fresnel::Schlick { f0: 0.04 }, masking: Masking::HeightCorrelated }),
        (job(Ggx, Vndf, 0.4, 0.1, 45.0), Effects { fresnel: conductor, masking: Masking::Separable }),
        (job(Ggx, Bounded, 0.2, 0.5, 70.0), Effects { fresnel: Fresnel::Dielectric { eta: 1.5 }, masking: Masking::HeightCorrelated }),
        (job(Beckmann, Vndf, 0.3, 0.1, 50.0), Effects { fresnel: Fresnel::Dielectric { eta: 1.33 }, masking: Masking::HeightCorrelated }),
        (job(Ward, Ndf, 0.3, 0.1, 30.0), Effects { fresnel: conductor, masking: Masking::None }),
    ];
    let mut e = engine();
    let level = sidak(0.01, cases.len());
    let mut report = Vec::new();
    for (job, effects) in &cases {
        let c = check(&mut e, job, effects, None, level);
        println!("{effects:?}: {c:?}");
        if !c.passed {
            report.push(format!("{job:?} {effects:?}: {c:?}"));
        }
        assert!(c.max_weight_error <= WEIGHT_ERROR_LIMIT);
        let unbiased = job_method(job) != Method::Bounded && effects.fresnel == Fresnel::None && job_kind(job) != LobeKind::Ward;
        assert_eq!(c.furnace.is_some(), unbiased, "the furnace cases are checked against their closed form");
    }
    assert!(report.is_empty(), "{report:#?}");
}

fn job_method(j: &Job) -> Method {
    let Job::Lobe { lobe, .. } = j else { unreachable!() };
    lobe.method
}

fn job_kind(j: &Job) -> LobeKind {
    let Job::Lobe { lobe, .. } = j else { unreachable!() };
    lobe.kind
}

/// χ² cannot see a weight: these modules sample exactly as before (their counts are right),
/// but each breaks the weight or the BRDF, and the verdict must fail.
#[test]
fn broken_weights_are_rejected() {
    let j = job(LobeKind::Ggx, Method::Vndf, 0.4, 0.4, 45.0);
    let schlick = Effects { fresnel: Fresnel::Schlick { f0: 0.04 }, masking: Masking::HeightCorrelated };
    let mut e = engine();
    let level = sidak(0.01, 3);
    let good = e.weighted_module(&j, &schlick, Specialisation::Specialised);
    let broken = |from: &str, to: &str| {
        assert!(good.source.contains(from), "{from:?} is not in the module");
        PipelineSource { source: good.source.replacen(from, to, 1), constants: good.constants.clone() }
    };
    // 1. the weight forgets Fresnel: the weight check and the albedo both catch it
    let no_fresnel = broken("return effect_fresnel(dot(wi, s.h)) * effect_masking", "return effect_masking");
    let c = check(&mut e, &j, &schlick, Some(&no_fresnel), level);
    assert!(!c.passed && c.max_weight_error > 0.5 && c.reflected.p_value < 1e-10, "{c:?}");
    // 2. the BRDF forgets cos θr in its denominator: the weight check catches the disagreement
    let bad_eval = broken("ggx_d(a, h) / (4.0 * wi.z * wr.z)", "ggx_d(a, h) / (4.0 * wi.z)");
    let c = check(&mut e, &j, &schlick, Some(&bad_eval), level);
    assert!(!c.passed && c.max_weight_error > 0.1, "{c:?}");
    // 3. Schlick with (1 - cos)^4: weight and BRDF agree, so only the albedo against the f64
    //    quadrature can tell
    let bad_schlick = broken("return f0 + (1.0 - f0) * (m2 * m2 * m);", "return f0 + (1.0 - f0) * (m2 * m2);");
    let c = check(&mut e, &j, &schlick, Some(&bad_schlick), level);
    assert!(c.max_weight_error <= WEIGHT_ERROR_LIMIT, "{c:?}");
    assert!(!c.passed && c.reflected.p_value < level, "{c:?}");
    // and the intact module passes
    let c = check(&mut e, &j, &schlick, Some(&good), level);
    assert!(c.passed, "{c:?}");
}

/// The GPU's f32 sums against the CPU engine's f64 sums of the very same samples.
#[test]
fn gpu_and_cpu_weighted_sums_agree() {
    let j = job(LobeKind::Beckmann, Method::Vndf, 0.35, 0.2, 40.0);
    let effects = Effects { fresnel: Fresnel::Conductor { eta: 1.1, k: 2.2 }, masking: Masking::HeightCorrelated };
    let mut e = engine();
    let n = 1 << 20;
    let gpu = e.weighted(&j, &effects, SampleRange::whole(3, n), Specialisation::Specialised).unwrap().sums;
    let cpu = lobes::engine::cpu::weighted(&j, &effects, SampleRange::whole(3, n));
    let (a, b) = (gpu.albedo(n), cpu.albedo(n));
    assert!((a - b).abs() < 1e-5 * b, "GPU {a} vs CPU {b}");
    assert!(cpu.max_weight_error() < 1e-9, "f64 weight check: {}", cpu.max_weight_error());
    // the uber-kernel draws and weighs the same samples
    let uber = e.weighted(&j, &effects, SampleRange::whole(3, n), Specialisation::Uber).unwrap().sums;
    assert!((uber.albedo(n) - a).abs() < 1e-6 * a, "uber {} vs specialised {a}", uber.albedo(n));
}

/// `lobes shader` through the binary: the module of one case, with its pipeline constants; an
/// unknown case is bad input (exit 2) naming the cases there are.
#[test]
fn shader_command_prints_the_composed_module() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/effects.toml");
    let run = |args: &[&str]| std::process::Command::new(env!("CARGO_BIN_EXE_lobes")).args(args).output().expect("run lobes");
    let out = run(&["shader", scene, "--case", "ward-schlick"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("// ==== lobes module for case(s) ward-schlick; pipeline constants: ANISOTROPIC = 1, FRESNEL = 1"), "{}", &text[..200.min(text.len())]);
    let source = text.split_once('\n').unwrap().1;
    let names = functions(source);
    assert!(names.iter().any(|n| n == "effect_weight") && !names.iter().any(|n| n.starts_with("ggx_")));
    let all = run(&["shader", scene]);
    assert_eq!(String::from_utf8_lossy(&all.stdout).matches("// ==== lobes module").count(), 10, "ten cases, ten effect sets");
    let json = run(&["shader", scene, "--json"]);
    let doc: serde_json::Value = serde_json::from_slice(&json.stdout).expect("one JSON object");
    let modules = doc["modules"].as_array().unwrap();
    assert_eq!(modules.len(), 10);
    assert_eq!(modules[5]["cases"][0], "ward-schlick");
    assert_eq!(modules[5]["constants"]["FRESNEL"], 1.0);
    assert!(modules[5]["source"].as_str().unwrap().contains("fn ward_weight"));
    let bad = run(&["shader", scene, "--case", "nope"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("its cases are: ggx-vndf-furnace"));
}

/// The hard cases of issue 4 with effects: near-specular α, grazing incidence, α > 1. The
/// weights stay within the f32 limit of eval·cos/pdf, none overflows, and the albedo still
/// agrees with the f64 quadrature.
#[test]
fn weights_stay_accurate_at_hard_cases() {
    use LobeKind::*;
    use Method::*;
    let conductor = Fresnel::Conductor { eta: 0.2, k: 3.9 };
    let hc = Masking::HeightCorrelated;
    let cases = [
        (job(Ggx, Vndf, 0.01, 0.01, 45.0), Effects { fresnel: conductor, masking: hc }),
        (job(Beckmann, Ndf, 0.02, 0.02, 30.0), Effects { fresnel: Fresnel::None, masking: Masking::Separable }),
        (job(Ward, Ndf, 0.02, 0.02, 30.0), Effects { fresnel: Fresnel::Schlick { f0: 0.5 }, masking: Masking::None }),
        (job(Ggx, Bounded, 0.3, 0.3, 88.0), Effects { fresnel: Fresnel::None, masking: hc }),
        (job(Beckmann, Vndf, 0.5, 0.5, 87.0), Effects { fresnel: Fresnel::None, masking: Masking::G1 }),
        (job(Ggx, Ndf, 2.0, 2.0, 60.0), Effects { fresnel: Fresnel::Dielectric { eta: 1.5 }, masking: hc }),
    ];
    let mut e = engine();
    let level = sidak(0.01, cases.len());
    for (job, effects) in &cases {
        let c = check(&mut e, job, effects, None, level);
        println!("{job:?} {effects:?}: {c:?}");
        assert!(c.passed, "{job:?} {effects:?}: {c:?}");
    }
}
