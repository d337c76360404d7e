//! The rough dielectric's weighted pass on the GPU (`shaders/lib/dielectric_eval.wgsl` through
//! `shaders/passes/weighted.wgsl`): Σ f |cos θo| / p per bin over the whole sphere, judged by
//! the judging every weighted case takes (`run::compare::albedo_check`): the reflected and the
//! transmitted albedo each against an f64 quadrature of `RoughDielectric::eval`, the sphere
//! total (wrong-side samples included) against the white furnace, and per bin the sampler's
//! weight against eval · |cos θo| / pdf. Broken BTDFs are shown to be rejected.
//! GPU test: it needs a wgpu adapter (lavapipe in CI).

use lobes::engine::gpu::GpuEngine;
use lobes::engine::gpu::effects::{Composed, Specialisation};
use lobes::engine::job::{Job, SampleRange, Scatter};
use lobes::reference::effects::Effects;
use lobes::reference::fresnel::Fresnel;
use lobes::reference::masking::Masking;
use lobes::reference::reflect::spherical;
use lobes::reference::{Lobe, LobeKind, Method};
use lobes::run::compare::albedo_check;
use lobes::stats::chi2::sidak;
use lobes::stats::expected::Quadrature;
use lobes::stats::histogram::SphereGrid;
use lobes::stats::weighted::{AlbedoCheck, WEIGHT_ERROR_LIMIT};

const GRID: SphereGrid = SphereGrid { rows: 16, cols: 32 };
const N: u64 = 1 << 21;

fn engine() -> GpuEngine {
    GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"))
}

fn glass(kind: LobeKind, method: Method, alpha: (f64, f64), eta: f64, theta_deg: f64) -> Job {
    let lobe = Lobe { kind, method, alpha_x: alpha.0, alpha_y: alpha.1, alpha_angle: 25.0 };
    Job::Lobe { lobe, incident: spherical(theta_deg.to_radians(), 0.3), grid: GRID, scatter: Scatter::Dielectric { eta } }
}

fn masked(masking: Masking) -> Effects {
    Effects { fresnel: Fresnel::None, masking }
}

fn check(e: &mut GpuEngine, job: &Job, effects: &Effects, module: Option<&Composed>, level: f64) -> AlbedoCheck {
    let composed = module.cloned().unwrap_or_else(|| e.weighted_module(job, effects, Specialisation::Specialised));
    let run = e.weighted_with(job, effects, &composed, SampleRange::whole(11, N)).expect("weighted run");
    albedo_check(job, effects, &run.sums, N, level, &Quadrature::default())
}

/// GGX visible normals and Beckmann NDF from outside, one from inside, one from inside past
/// the critical angle (θi 130°: 50° from the normal, past 41.8° for η 1.5), an anisotropic
/// separable case and one without masking (furnace 1 + Λ(ωi)): both albedos agree with the f64
/// quadrature and the sphere total with the furnace. No GGX NDF: its weights have infinite
/// variance (scenes/effects.toml), which no z-test can judge.
#[test]
fn albedos_match_quadrature_and_the_white_furnace() {
    use LobeKind::*;
    use Method::*;
    let cases = [
        (glass(Ggx, Vndf, (0.3, 0.3), 1.5, 40.0), masked(Masking::G1)),
        (glass(Beckmann, Ndf, (0.4, 0.4), 1.5, 30.0), masked(Masking::G1)),
        (glass(Ggx, Vndf, (0.5, 0.5), 1.5, 140.0), masked(Masking::G1)),
        (glass(Beckmann, Ndf, (0.2, 0.2), 1.5, 130.0), masked(Masking::G1)),
        (glass(Beckmann, Vndf, (0.4, 0.2), 1.33, 120.0), masked(Masking::Separable)),
        (glass(Ggx, Vndf, (0.6, 0.6), 1.0 / 1.5, 70.0), masked(Masking::None)),
    ];
    let mut e = engine();
    let level = sidak(0.01, cases.len());
    let mut failed = Vec::new();
    for (job, effects) in &cases {
        let c = check(&mut e, job, effects, None, level);
        println!("{job:?} {effects:?}: {c:?}");
        let t = c.transmitted.as_ref().expect("a dielectric has a transmitted albedo");
        assert!(c.reference > 0.0 && t.reference > 0.0, "{c:?}");
        assert!(c.max_weight_error <= WEIGHT_ERROR_LIMIT, "{c:?}");
        assert_eq!(c.furnace.is_some(), effects.masking != Masking::Separable, "{c:?}");
        if !c.passed {
            failed.push(format!("{job:?} {effects:?}: {c:?}"));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// The GPU's f32 sums against the CPU engine's f64 sums of the very same samples, per side.
#[test]
fn gpu_and_cpu_weighted_sums_agree() {
    let job = glass(LobeKind::Beckmann, Method::Vndf, (0.35, 0.2), 1.5, 135.0);
    let effects = masked(Masking::Separable);
    let n = 1 << 20;
    let gpu = engine().weighted(&job, &effects, SampleRange::whole(3, n), Specialisation::Specialised).unwrap().sums;
    let cpu = lobes::engine::cpu::weighted(&job, &effects, SampleRange::whole(3, n));
    for lower in [false, true] {
        let (a, b) = (gpu.hemisphere_albedo(n, lower), cpu.hemisphere_albedo(n, lower));
        assert!((a - b).abs() < 1e-4 * b, "lower {lower}: GPU {a} vs CPU {b}");
    }
    assert!(cpu.max_weight_error() < 1e-9, "f64 weight check: {}", cpu.max_weight_error());
    let (a, b) = (gpu.sphere_total(n), cpu.sphere_total(n));
    assert!((a - b).abs() < 1e-4 * b, "sphere: GPU {a} vs CPU {b}");
}

/// A BTDF broken in the GPU module, each as a renderer might break it, is rejected by the same
/// judging: eq. 21 without η² and with the reflection's 1/(4 |ωo·h|) by the weight check, and
/// an event chosen with the wrong Fresnel term (weights and eval/pdf still agree, the furnace
/// still holds) by the reflected and transmitted albedos against f64.
#[test]
fn broken_btdfs_are_rejected() {
    let job = glass(LobeKind::Ggx, Method::Vndf, (0.4, 0.4), 1.5, 35.0);
    let effects = masked(Masking::G1);
    let mut e = engine();
    let level = sidak(0.01, 4);
    let good = e.weighted_module(&job, &effects, Specialisation::Specialised);
    let broken = |from: &str, to: &str| {
        assert!(good.source.contains(from), "{from:?} is not in the module");
        Composed { source: good.source.replacen(from, to, 1), constants: good.constants.clone() }
    };
    let btdf = "return fresnel_dielectric_transmittance(c, p.eta) * d * c * dielectric_jacobian_t(c, -dot(p.o, p.h), p.eta) / cos;";
    // 1. eq. 21 without η²: the BSDF is η² = 2.25 times too small across the surface
    let no_eta2 = broken(btdf, "return fresnel_dielectric_transmittance(c, p.eta) * d * c * dielectric_jacobian_t(c, -dot(p.o, p.h), p.eta) / (p.eta * p.eta * cos);");
    let c = check(&mut e, &job, &effects, Some(&no_eta2), level);
    println!("without η²: {c:?}");
    assert!(!c.passed && c.max_weight_error > 0.5, "{c:?}");
    // 2. the reflection's Jacobian 1/(4 |ωo·h|) for the transmission's
    let reflection_jacobian = broken(btdf, "return fresnel_dielectric_transmittance(c, p.eta) * d / (4.0 * cos);");
    let c = check(&mut e, &job, &effects, Some(&reflection_jacobian), level);
    println!("reflection Jacobian: {c:?}");
    assert!(!c.passed && c.max_weight_error > 0.1, "{c:?}");
    // 3. the sampler chooses its event with F of η 1.65: weight, eval and pdf agree and every
    //    weight is still 1, so only the split into reflected and transmitted albedo can tell
    let wrong_f = broken("    let f = fresnel_dielectric(c, eta);\n", "    let f = fresnel_dielectric(c, eta * 1.1);\n");
    let c = check(&mut e, &job, &effects, Some(&wrong_f), level);
    println!("event by F(1.1 η): {c:?}");
    let t = c.transmitted.as_ref().unwrap();
    assert!(c.max_weight_error <= WEIGHT_ERROR_LIMIT && c.furnace_p_value.unwrap() >= level, "{c:?}");
    assert!(!c.passed && c.p_value < 1e-6 && t.p_value < 1e-6, "{c:?}");
    // and the intact module passes
    let c = check(&mut e, &job, &effects, Some(&good), level);
    assert!(c.passed, "{c:?}");
}
