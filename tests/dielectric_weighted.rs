//! The rough dielectric's weighted pass on the GPU (`shaders/lib/dielectric_eval.wgsl` through
//! `shaders/passes/weighted.wgsl`): Σ f |cos θo| / p per bin over the whole sphere, judged by
//! the judging every weighted case takes (`run::compare::albedo_check`): the reflected and the
//! transmitted albedo each against an f64 quadrature of `RoughDielectric::eval`, the sphere
//! total (wrong-side samples included) against the white furnace, and per bin the sampler's
//! weight against eval · |cos θo| / pdf. Broken BTDFs are shown to be rejected. The
//! height-correlated G2 across the surface, B(1 + Λ(ωi), 1 + Λ(ωo)), is checked in f32 and f64
//! WGSL against the f64 reference over Λ from 0 to 10³ (grazing), and through the weighted pass.
//! GPU test: it needs a wgpu adapter (lavapipe in CI).

use lobes::engine::gpu::effects::{PipelineSource, Specialisation};
use lobes::engine::gpu::params::storage_entry;
use lobes::engine::gpu::precision::Precision;
use lobes::engine::gpu::{Gpu, GpuEngine, library};
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

fn check(e: &mut GpuEngine, job: &Job, effects: &Effects, module: Option<&PipelineSource>, level: f64) -> AlbedoCheck {
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
    judge(&cases);
}

/// Judges every case with the intact module at a family-wise level of 0.01: both albedos
/// against the f64 quadrature, the weight check, and the furnace where G = G1(ωi) or 1.
fn judge(cases: &[(Job, Effects)]) {
    let mut e = engine();
    let level = sidak(0.01, cases.len());
    let mut failed = Vec::new();
    for (job, effects) in cases {
        let c = check(&mut e, job, effects, None, level);
        println!("{job:?} {effects:?}: {c:?}");
        let t = c.transmitted.as_ref().expect("a dielectric has a transmitted albedo");
        assert!(c.reflected.reference > 0.0 && t.reference > 0.0, "{c:?}");
        assert!(c.max_weight_error <= WEIGHT_ERROR_LIMIT, "{c:?}");
        assert_eq!(c.furnace.is_some(), matches!(effects.masking, Masking::G1 | Masking::None), "{c:?}");
        if !c.passed {
            failed.push(format!("{job:?} {effects:?}: {c:?}"));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// The GPU's f32 sums against the CPU engine's f64 sums of the very same samples, per side and
/// over the sphere (wrong-side samples included), separable and height-correlated.
#[test]
fn gpu_and_cpu_weighted_sums_agree() {
    let job = glass(LobeKind::Beckmann, Method::Vndf, (0.35, 0.2), 1.5, 135.0);
    let n = 1 << 20;
    let mut e = engine();
    for effects in [masked(Masking::Separable), masked(Masking::HeightCorrelated)] {
        let gpu = e.weighted(&job, &effects, SampleRange::whole(3, n), Specialisation::Specialised).unwrap().sums;
        let cpu = lobes::engine::cpu::weighted(&job, &effects, SampleRange::whole(3, n));
        for lower in [false, true] {
            let (a, b) = (gpu.hemisphere_albedo(n, lower), cpu.hemisphere_albedo(n, lower));
            assert!((a - b).abs() < 1e-4 * b, "{effects:?} lower {lower}: GPU {a} vs CPU {b}");
        }
        assert!(cpu.max_weight_error() < 1e-9, "{effects:?} f64 weight check: {}", cpu.max_weight_error());
        let (a, b) = (gpu.sphere_total(n), cpu.sphere_total(n));
        assert!((a - b).abs() < 1e-4 * b, "{effects:?} sphere: GPU {a} vs CPU {b}");
    }
}

/// `good` with its first `from` replaced by `to` (which must be there): a module broken on purpose.
fn replaced(good: &PipelineSource, from: &str, to: &str) -> PipelineSource {
    assert!(good.source.contains(from), "{from:?} is not in the module");
    PipelineSource { source: good.source.replacen(from, to, 1), constants: good.constants.clone() }
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
    let broken = |from: &str, to: &str| replaced(&good, from, to);
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
    assert!(!c.passed && c.reflected.p_value < 1e-6 && t.p_value < 1e-6, "{c:?}");
    // and the intact module passes
    let c = check(&mut e, &job, &effects, Some(&good), level);
    assert!(c.passed, "{c:?}");
}

/// Height-correlated masking across the surface (Heitz 2014's B(1 + Λ(ωi), 1 + Λ(ωo))): GGX
/// visible normals and Beckmann NDF from outside, Beckmann visible normals from inside
/// (anisotropic, turned): both albedos against the f64 quadrature of `RoughDielectric::eval`,
/// which takes the Beta form across the surface. No furnace: with G ≠ G1(ωi) the sphere total
/// has no closed form.
#[test]
fn height_correlated_albedos_match_quadrature() {
    use LobeKind::*;
    use Method::*;
    let hc = masked(Masking::HeightCorrelated);
    judge(&[(glass(Ggx, Vndf, (0.3, 0.3), 1.5, 50.0), hc), (glass(Beckmann, Ndf, (0.4, 0.4), 1.5, 30.0), hc), (glass(Beckmann, Vndf, (0.4, 0.2), 1.33, 125.0), hc)]);
}

/// The reflection's 1 / (1 + Λi + Λo) used across the surface too (what pbrt-v4 does), put in
/// the GPU module at GGX α 0.8, θi 70° (Λ(ωi) 0.71): the weights and eval/pdf still agree (both
/// take the same G) and the reflected albedo is unchanged, but the transmitted albedo comes out
/// 30 % above the f64 Beta form (0.7240 ± 1.7e-4 against 0.5567; at α 0.3, θi 50° the two
/// forms differ by only 6e-4). The intact module passes there.
#[test]
fn the_reflections_form_across_the_surface_is_rejected() {
    let job = glass(LobeKind::Ggx, Method::Vndf, (0.8, 0.8), 1.5, 70.0);
    let effects = masked(Masking::HeightCorrelated);
    let mut e = engine();
    let good = e.weighted_module(&job, &effects, Specialisation::Specialised);
    let broken = replaced(&good, "g = masking_height_correlated_transmitted(gi, gr);", "g = masking_height_correlated(gi, gr);");
    let level = sidak(0.01, 2);
    let c = check(&mut e, &job, &effects, Some(&broken), level);
    println!("reflection's G2 across the surface: {c:?}");
    let t = c.transmitted.as_ref().unwrap();
    assert!(c.max_weight_error <= WEIGHT_ERROR_LIMIT && c.reflected.p_value >= level, "{c:?}");
    assert!(!c.passed && t.p_value < 1e-6 && t.albedo > t.reference, "{c:?}");
    let c = check(&mut e, &job, &effects, Some(&good), level);
    assert!(c.passed, "{c:?}");
}

/// Λ from 0 to 10³ (θ within ~0.02° of grazing for α 0.3): the G1 values 1 / (1 + Λ) of the
/// grid's pairs.
const LAMBDAS: [f64; 14] = [0.0, 1e-6, 1e-3, 0.02, 0.1, 0.3, 1.0, 2.5, 6.0, 7.5, 30.0, 150.0, 600.0, 1000.0];

/// `masking_height_correlated_transmitted` of every pair of `g1s` (LAMBDAS's G1) in a kernel of
/// `precision` (f32 or f64: `Real` is its scalar), read back as f64.
fn transmitted_g2_on_gpu(gpu: &Gpu, precision: Precision, g1s: &[f64]) -> Vec<f64> {
    let n = g1s.len();
    let kernel = format!(
        "@group(0) @binding(0) var<storage, read> g1s: array<Real>;\n\
         @group(0) @binding(1) var<storage, read_write> g2s: array<Real>;\n\
         @compute @workgroup_size(64)\n\
         fn g2_grid(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
             if (id.x < {n}u * {n}u) {{\n        \
                 g2s[id.x] = masking_height_correlated_transmitted(g1s[id.x / {n}u], g1s[id.x % {n}u]);\n    \
             }}\n\
         }}\n"
    );
    let source = library::wgsl(&["lobes::masking"], precision).unwrap() + &kernel;
    let f64s = precision == Precision::F64;
    let bytes: Vec<u8> = if f64s { bytemuck::cast_slice(g1s).to_vec() } else { bytemuck::cast_slice(&g1s.iter().map(|&g| g as f32).collect::<Vec<_>>()).to_vec() };
    let size = (n * n * if f64s { 8 } else { 4 }) as u64;
    let (group, layout) = gpu.layout("g2", &[storage_entry(0, true), storage_entry(1, false)]);
    let module = gpu.module("the transmitted G2 grid", &source).unwrap_or_else(|e| panic!("{e}"));
    let pipeline = gpu.pipeline(&module, Some(&layout), "g2_grid", &[]).unwrap_or_else(|e| panic!("{e}"));
    let input = gpu.buffer("G1", bytes.len() as u64, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST);
    gpu.queue.write_buffer(&input, 0, &bytes);
    let output = gpu.buffer("G2", size, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
    let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &group,
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() }, wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() }],
    });
    gpu.dispatch(&[lobes::engine::gpu::dispatch::Pass { label: "g2", bind: &bind, offset: None, steps: vec![lobes::engine::gpu::dispatch::Step { pipeline: &pipeline, groups: 4 }], group1: None }]).unwrap();
    let out = gpu.read(&output, size).unwrap();
    if f64s { bytemuck::cast_slice::<u8, f64>(&out).to_vec() } else { bytemuck::cast_slice::<u8, f32>(&out).iter().map(|&g| g as f64).collect() }
}

/// The largest error of `g2s` (row-major over pairs of `g1s`) against the f64 reference
/// (statrs's ln Γ) at the same G1 values, relative and per unit of |ln G2| (at least 1): an ulp
/// of an argument 1/G1 moves ln B by up to |ln B| ulps, so that is what a precision can hold.
/// Over the pairs whose G2 is above 1e-30 (the WGSL's documented floor, and f32's exponential
/// flushes below its normal range); the others must come out below 1e-30.
fn worst_error(g1s: &[f64], g2s: &[f64]) -> f64 {
    let n = g1s.len();
    let mut worst = 0.0f64;
    for (k, &got) in g2s.iter().enumerate() {
        let want = Masking::HeightCorrelated.g_transmitted(g1s[k / n], g1s[k % n]);
        if want > 1e-30 {
            worst = worst.max((got - want).abs() / want / want.ln().abs().max(1.0));
        } else {
            assert!((0.0..=1e-30).contains(&got), "G1 {} {}: {got} for {want}", g1s[k / n], g1s[k % n]);
        }
    }
    worst
}

/// The WGSL form (Stirling without cancellation, shaders/lib/masking.wgsl) against the f64
/// reference over every pair of Λ from 0 to 10³, per unit of |ln G2| ([`worst_error`]): in f32
/// within 5e-6 (measured on lavapipe: 1.8e-6, near G2 = 1; 3.8e-6 relative at ln G2 = −28.7),
/// in f64 (where the adapter has it) within 1e-10 (measured 1.2e-13, 1.2e-12 relative: the
/// reference's own ln Γ differences, which put B(1, 1001) 8e-13 off). The textbook f32 form,
/// lgamma(x) + lgamma(y) − lgamma(x + y) (libm's lgammaf, ~1 ulp each), fails the f32 limit at
/// grazing Λ (6.4e-5; 5.8e-4 relative at G2 = 1.1e-4).
#[test]
fn transmitted_g2_in_wgsl_matches_f64_to_grazing() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
    let g1 = |l: f64| 1.0 / (1.0 + l);
    // f32: the reference at the very G1 values the kernel reads
    let g1s: Vec<f64> = LAMBDAS.iter().map(|&l| g1(l) as f32 as f64).collect();
    let f32_error = worst_error(&g1s, &transmitted_g2_on_gpu(&gpu, Precision::F32Accurate, &g1s));
    let textbook: Vec<f64> = (0..g1s.len() * g1s.len())
        .map(|k| {
            let (x, y) = ((1.0 / g1s[k / g1s.len()]) as f32, (1.0 / g1s[k % g1s.len()]) as f32);
            (libm::lgammaf(x) + libm::lgammaf(y) - libm::lgammaf(x + y)).exp() as f64
        })
        .collect();
    let textbook_error = worst_error(&g1s, &textbook);
    println!("f32 WGSL: worst error per unit of |ln G2| {f32_error:.2e}; f32 lgamma differences: {textbook_error:.2e}");
    assert!(f32_error < 5e-6, "f32: {f32_error:e}");
    assert!(textbook_error > 5e-6, "the textbook f32 form should lose digits at grazing Λ: {textbook_error:e}");
    if gpu.has_f64() {
        let g1s: Vec<f64> = LAMBDAS.iter().map(|&l| g1(l)).collect();
        let f64_error = worst_error(&g1s, &transmitted_g2_on_gpu(&gpu, Precision::F64, &g1s));
        println!("f64 WGSL: worst error per unit of |ln G2| {f64_error:.2e}");
        assert!(f64_error < 1e-10, "f64: {f64_error:e}");
    }
}
