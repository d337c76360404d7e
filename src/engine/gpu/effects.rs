//! Modules for weighted histograms: a case's lobe and sampler, its Fresnel and masking terms,
//! composed into one WGSL module that holds only the code those effects need.
//!
//! Two levels of specialisation:
//! - composition: the module is the case's counting kernel (`compose::lobe_kernel`) and
//!   `shaders/passes/weighted.wgsl`, whose estimator (`shaders/passes/effect.wgsl`) imports
//!   `lobes::effect_fresnel` and `lobes::effect_masking`: `shaders/passes/effect_fresnel.wgsl`
//!   (with `shaders/lib/fresnel.wgsl`) only with a Fresnel term, else `no_fresnel.wgsl`, and
//!   likewise for masking. What this module generates is a few one-line call sites in
//!   `lobes::job` (which sampler's functions, which selector: `samplers_glue`,
//!   `effect_call_sites`);
//! - override constants: what is left to choose inside a file (which Fresnel form, which
//!   masking term, isotropic or not) is a `switch` on a WGSL `override`, fixed when the
//!   pipeline is made, so the driver folds the branch away.
//!
//! The uber-kernel ([`Specialisation::Uber`]) is the opposite, for measuring what generality
//! costs: every lobe, sampler and effect in one module, all switched at run time from the
//! `effect` uniform (`shaders/passes/effect_uniform.wgsl`).

use super::compose::{self, Kernel, call_site};
use super::library;
use super::counting::Counting;
use super::precision::Precision;
use crate::engine::job::{Job, Scatter};
use crate::reference::effects::Effects;
use crate::reference::fresnel::Fresnel;
use crate::reference::masking::Masking;
use crate::reference::sampler::{self, REGISTRY, SamplerSpec};
use crate::reference::{LobeKind, Method};

/// How a weighted module resolves its effects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Specialisation {
    /// Only the case's code, the remaining choices fixed by override constants.
    Specialised,
    /// Every lobe, sampler and effect, switched at run time.
    Uber,
}

/// A composed module and the override constants its pipelines are made with.
#[derive(Debug, Clone, PartialEq)]
pub struct PipelineSource {
    pub source: String,
    pub constants: Vec<(&'static str, f64)>,
}

impl PipelineSource {
    /// A key naming the pipeline: the source with its constants.
    pub fn key(&self) -> String {
        format!("{}\n// pipeline constants: {:?}", self.source, self.constants)
    }
}

pub use crate::reference::SAMPLERS;

/// The uber-kernel's id of a sampler (its index in the registry).
pub fn sampler_id(kind: LobeKind, method: Method) -> u32 {
    sampler::find(kind, method).id()
}

/// The call sites of the samplers' weight, BRDF, density and (with masking) G1 that
/// `shaders/passes/effect.wgsl` calls (one sampler in a specialised module, all in the uber-kernel;
/// `sampler_sample` comes with the counting kernels, [`compose::lobe_kernel`]); for a rough
/// `dielectric`, its weight, BSDF and density (`shaders/lib/dielectric_eval.wgsl`) and the same G1.
fn samplers_glue(samplers: &[&SamplerSpec], rotated: bool, masking: bool, dielectric: bool) -> String {
    let of = |w: &sampler::Wgsl| w.dielectric_eval.unwrap_or_else(|| panic!("{} has no dielectric", w.sample));
    let pick = |reflect: fn(&sampler::Wgsl) -> &'static str, glass: fn(sampler::DielectricEval) -> &'static str| {
        move |w: &sampler::Wgsl| String::from(if dielectric { glass(of(w)) } else { reflect(w) })
    };
    let mut src = call_site("sampler_weight", "a: vec2<f32>, wi: vec3<f32>, s: LobeSample", "f32", samplers, rotated, pick(|w| w.weight, |d| d.weight));
    src += &call_site("sampler_eval", "a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>, h: vec3<f32>", "f32", samplers, rotated, pick(|w| w.eval, |d| d.eval));
    src += &call_site("sampler_pdf", "a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>", "f32", samplers, rotated, pick(|w| w.pdf, |d| d.pdf));
    if masking {
        src += &call_site("sampler_g1", "a: vec2<f32>, w: vec3<f32>", "f32", samplers, rotated, |w| w.g1.unwrap_or("1.0").into());
    }
    src
}

/// How a weighted module picks what is left to choose: the override constants of a
/// specialised module, or the `effect` uniform's modes in the uber-kernel.
struct Selectors {
    anisotropic: &'static str,
    fresnel: &'static str,
    masking: &'static str,
}

const OVERRIDES: Selectors = Selectors { anisotropic: "ANISOTROPIC", fresnel: "FRESNEL", masking: "MASKING" };
const UNIFORM: Selectors = Selectors { anisotropic: "effect.modes.w != 0u", fresnel: "effect.modes.y", masking: "effect.modes.z" };

/// The generated call sites of `shaders/passes/effect.wgsl` and its effect files: whether α is
/// anisotropic, the mode of each effect the case has, and with masking whether a pair lies
/// across a `dielectric`'s surface (`masking_across`).
fn effect_call_sites(sel: &Selectors, fresnel: bool, masking: bool, dielectric: bool) -> String {
    let mut src = format!("fn effect_anisotropic() -> bool {{\n    return {};\n}}\n", sel.anisotropic);
    if fresnel {
        src += &format!("fn fresnel_mode() -> u32 {{\n    return {};\n}}\n", sel.fresnel);
    }
    if masking {
        src += &format!("fn masking_mode() -> u32 {{\n    return {};\n}}\n", sel.masking);
        let across = if dielectric { "wi.z * wr.z < 0.0" } else { "false" };
        src += &format!("fn masking_across(wi: vec3<f32>, wr: vec3<f32>) -> bool {{\n    return {across};\n}}\n");
    }
    src
}

/// `kernel` with the weighted pass over `samplers`, its effects chosen by `sel`: the samplers'
/// density and weight modules (a rough `dielectric`'s too), the effect files (or those without
/// the effect), the call sites.
fn weighted(mut kernel: Kernel, samplers: &[&SamplerSpec], sel: &Selectors, rotated: bool, fresnel: bool, masking: bool, dielectric: bool) -> String {
    kernel.roots.push("lobes::weighted");
    for spec in samplers {
        kernel.job.uses(compose::sampler_module(spec, true));
    }
    if dielectric {
        kernel.job.uses("lobes::dielectric_eval");
    }
    if !fresnel {
        kernel.chosen.push(library::NO_FRESNEL);
    }
    if !masking {
        kernel.chosen.push(library::NO_MASKING);
    }
    kernel.job.push(&samplers_glue(samplers, rotated, masking, dielectric));
    kernel.job.push(&effect_call_sites(sel, fresnel, masking, dielectric));
    kernel.source()
}

/// The weighted module of a lobe `job` with `effects`: the counting module of the job (so
/// that one module serves both passes of the case) and `shaders/passes/weighted.wgsl` with the
/// effect files it needs.
pub fn compose_effects(job: &Job, effects: &Effects, counting: Counting, how: Specialisation) -> PipelineSource {
    let Job::Lobe { lobe, scatter, .. } = job else { panic!("effects apply to lobe jobs only") };
    let dielectric = matches!(scatter, Scatter::Dielectric { .. });
    match how {
        Specialisation::Specialised => {
            let spec = sampler::find(lobe.kind, lobe.method);
            let fresnel = effects.fresnel != Fresnel::None;
            let masking = effects.masking != Masking::None && spec.wgsl.g1.is_some();
            let mut kernel = compose::lobe_kernel(job, counting, job.bins() as u32, Precision::F32Accurate, &[spec]);
            let mut constants = vec![("ANISOTROPIC", f64::from(u8::from(lobe.alpha_x != lobe.alpha_y)))];
            kernel.job.push("override ANISOTROPIC: bool = true;\n");
            if fresnel {
                kernel.job.push("override FRESNEL: u32 = 1u;\n");
                constants.push(("FRESNEL", effects.fresnel.mode() as f64));
            }
            if masking {
                kernel.job.push("override MASKING: u32 = 1u;\n");
                constants.push(("MASKING", effects.masking.mode() as f64));
            }
            PipelineSource { source: weighted(kernel, &[spec], &OVERRIDES, lobe.is_rotated(), fresnel, masking, dielectric), constants }
        }
        Specialisation::Uber => {
            assert!(!dielectric, "the uber-kernel draws reflections only (Ward and bounded VNDF have no dielectric)");
            PipelineSource { source: compose_uber(job, counting), constants: Vec::new() }
        }
    }
}

/// The module a case runs: its weighted module (which holds its counting kernels too) with
/// effects, else its counting module (`tile_bins` bins per pass where the histogram is tiled),
/// counting as `counting` says.
pub fn case_module(job: &Job, effects: Option<&Effects>, counting: Counting, tile_bins: u32) -> PipelineSource {
    match (effects, job) {
        (Some(e), Job::Lobe { .. }) => compose_effects(job, e, counting, Specialisation::Specialised),
        _ => PipelineSource { source: compose::compose_counting(job, counting, tile_bins, Precision::F32Accurate), constants: Vec::new() },
    }
}

/// The uber-kernel on `job`'s grid: every lobe and sampler, Fresnel and masking, switched at
/// run time by `effect.modes` = (sampler id, Fresnel mode, masking mode, anisotropic).
fn compose_uber(job: &Job, counting: Counting) -> String {
    let Job::Lobe { lobe, .. } = job else { panic!("the uber-kernel draws lobes") };
    let all: Vec<&SamplerSpec> = REGISTRY.iter().collect();
    let kernel = compose::lobe_kernel(job, counting, job.bins() as u32, Precision::F32Accurate, &all);
    weighted(kernel, &all, &UNIFORM, lobe.is_rotated(), true, true, false)
}

/// The `effect` uniform of a case (`Effect` in `shaders/passes/weighted.wgsl`).
pub fn effect_uniform(kind: LobeKind, method: Method, anisotropic: bool, effects: &Effects) -> ([u32; 4], [f32; 4]) {
    let masking = if sampler::find(kind, method).wgsl.g1.is_none() { 0 } else { effects.masking.mode() };
    ([sampler_id(kind, method), effects.fresnel.mode(), masking, u32::from(anisotropic)], effects.fresnel.params())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::Lobe;
    use crate::stats::histogram::SphereGrid;
    use glam::DVec3;

    fn job(kind: LobeKind, method: Method, anisotropic: bool) -> Job {
        let lobe = Lobe { kind, method, alpha_x: 0.3, alpha_y: if anisotropic { 0.1 } else { 0.3 }, alpha_angle: 0.0 };
        Job::Lobe { lobe, incident: DVec3::new(0.6, 0.0, 0.8), grid: SphereGrid { rows: 8, cols: 16 }, scatter: crate::engine::job::Scatter::Reflect }
    }

    #[test]
    fn every_effect_set_and_the_uber_kernel_validate() {
        let fresnels = [Fresnel::None, Fresnel::Schlick { f0: 0.04 }, Fresnel::Conductor { eta: 0.2, k: 3.9 }, Fresnel::Dielectric { eta: 1.5 }];
        for (kind, method) in SAMPLERS {
            for fresnel in fresnels {
                for masking in Masking::ALL {
                    let effects = Effects { fresnel, masking };
                    let c = compose_effects(&job(kind, method, true), &effects, Counting::Workgroup, Specialisation::Specialised);
                    compose::validate("effects", &c.source).unwrap_or_else(|e| panic!("{kind:?} {method:?} {effects:?}: {e}"));
                }
            }
        }
        // a rough dielectric's weighted pass: its own density, BSDF and weight, plain and rotated
        for spec in REGISTRY.iter().filter(|s| s.wgsl.dielectric.is_some()) {
            for masking in Masking::ALL {
                for alpha_angle in [0.0, 30.0] {
                    let Job::Lobe { lobe, incident, grid, .. } = job(spec.kind, spec.method, true) else { unreachable!() };
                    let glass = Job::Lobe { lobe: Lobe { alpha_angle, ..lobe }, incident, grid, scatter: crate::engine::job::Scatter::Dielectric { eta: 1.5 } };
                    let c = compose_effects(&glass, &Effects { fresnel: Fresnel::None, masking }, Counting::Workgroup, Specialisation::Specialised);
                    compose::validate("dielectric effects", &c.source).unwrap_or_else(|e| panic!("{} {masking:?}: {e}", spec.name()));
                    let d = spec.wgsl.dielectric_eval.unwrap();
                    for expr in [d.pdf, d.eval, d.weight] {
                        assert!(c.source.contains(&format!("return {expr};")), "{}: {expr}", spec.name());
                    }
                }
            }
        }
        let c = compose_effects(&job(LobeKind::Ggx, Method::Vndf, false), &Effects::NONE, Counting::Workgroup, Specialisation::Uber);
        compose::validate("uber", &c.source).unwrap();
        assert!(c.constants.is_empty());
        // a rotated lobe's weight, BRDF, density and G1 take world directions into its frame
        let effects = Effects { fresnel: Fresnel::Schlick { f0: 0.04 }, masking: Masking::HeightCorrelated };
        for (kind, method) in SAMPLERS {
            let Job::Lobe { lobe, incident, grid, scatter } = job(kind, method, true) else { unreachable!() };
            let rotated = Job::Lobe { lobe: Lobe { alpha_angle: 57.0, ..lobe }, incident, grid, scatter };
            for how in [Specialisation::Specialised, Specialisation::Uber] {
                let c = compose_effects(&rotated, &effects, Counting::Workgroup, how);
                compose::validate("rotated effects", &c.source).unwrap_or_else(|e| panic!("{kind:?} {method:?} {how:?}: {e}"));
                assert!(c.source.contains("    let s = sample_to_local(lobe_frame(), s_world);\n"));
            }
        }
    }

    /// The dielectric's density, BSDF and weight are written over `Real`: they compose in f64 too.
    #[test]
    fn the_dielectric_eval_composes_in_f64() {
        let src = library::wgsl(&["lobes::dielectric_eval"], Precision::F64).unwrap();
        compose::validate("dielectric_eval f64", &src).unwrap();
        assert!(src.contains("alias Real = f64;") && src.contains("fn dielectric_ggx_vndf_pdf(a: vec2<Real>"));
    }
}
