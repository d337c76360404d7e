//! Modules for weighted histograms: a case's lobe and sampler, its Fresnel and masking terms,
//! composed into one WGSL module that holds only the code those effects need.
//!
//! Two levels of specialisation:
//! - composition: a module includes the shader files of its lobe only, `shaders/lib/fresnel.wgsl`
//!   (with `shaders/passes/effect_fresnel.wgsl`) only with a Fresnel term, `shaders/lib/masking.wgsl`
//!   (with `shaders/passes/effect_masking.wgsl`) only with masking; all glue is in those files and
//!   `shaders/passes/effect.wgsl`, and what this module generates is a few one-line call sites (which
//!   sampler's functions, which selector: `effect_call_sites`);
//! - override constants: what is left to choose inside a file (which Fresnel form, which
//!   masking term, isotropic or not) is a `switch` on a WGSL `override`, fixed when the
//!   pipeline is made, so the driver folds the branch away.
//!
//! The uber-kernel ([`Specialisation::Uber`]) is the opposite, for measuring what generality
//! costs: every lobe, sampler and effect in one module, all switched at run time from the
//! `effect` uniform.

use super::compose::{self, call_site, sources};
use super::precision::Precision;
use crate::engine::job::Job;
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
pub struct Composed {
    pub source: String,
    pub constants: Vec<(&'static str, f64)>,
}

impl Composed {
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
/// `sampler_sample` comes with the counting kernels, [`compose::sampler_call_site`]).
fn samplers_glue(samplers: &[&SamplerSpec], masking: bool) -> String {
    let mut src = call_site("sampler_weight", "a: vec2<f32>, wi: vec3<f32>, s: LobeSample", "f32", samplers, |w| w.weight.into());
    src += &call_site("sampler_eval", "a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>, h: vec3<f32>", "f32", samplers, |w| w.eval.into());
    src += &call_site("sampler_pdf", "a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>", "f32", samplers, |w| w.pdf.into());
    if masking {
        src += &call_site("sampler_g1", "a: vec2<f32>, w: vec3<f32>", "f32", samplers, |w| w.g1.unwrap_or("1.0").into());
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

/// The generated call sites of `shaders/passes/effect.wgsl` and its effect files: which sampler,
/// whether α is anisotropic, and for each effect either its mode (and the effect's file follows)
/// or the constant 1.
fn effect_call_sites(sel: &Selectors, fresnel: bool, masking: bool) -> String {
    let mut src = format!("fn effect_anisotropic() -> bool {{\n    return {};\n}}\n", sel.anisotropic);
    src += &if fresnel {
        format!("fn fresnel_mode() -> u32 {{\n    return {};\n}}\n", sel.fresnel)
    } else {
        "fn effect_fresnel(c: f32) -> f32 {\n    return 1.0;\n}\n".into()
    };
    src += &if masking {
        format!("fn masking_mode() -> u32 {{\n    return {};\n}}\n", sel.masking)
    } else {
        "fn effect_masking(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {\n    return 1.0;\n}\n".into()
    };
    src
}

/// The effect glue of a module with (or without) Fresnel and masking, then the estimator and
/// the weighted pass.
fn effect_files(fresnel: bool, masking: bool) -> Vec<&'static str> {
    let mut files = Vec::new();
    if fresnel {
        files.push(sources::EFFECT_FRESNEL);
    }
    if masking {
        files.push(sources::EFFECT_MASKING);
    }
    files.extend([sources::EFFECT, sources::WEIGHTED]);
    files
}

/// The library modules of Fresnel and masking that [`effect_files`] call.
fn effect_modules(fresnel: bool, masking: bool) -> Vec<&'static str> {
    [(fresnel, "lobes::fresnel"), (masking, "lobes::masking")].into_iter().filter_map(|(on, m)| on.then_some(m)).collect()
}

/// The weighted module of a lobe `job` with `effects`: the counting module of the job (so
/// that one module serves both passes of the case), the effect files it needs, the glue and
/// `shaders/passes/weighted.wgsl`.
pub fn compose_effects(job: &Job, effects: &Effects, workgroup_words: u32, how: Specialisation) -> Composed {
    let Job::Lobe { lobe, .. } = job else { panic!("effects apply to lobe jobs only") };
    match how {
        Specialisation::Specialised => {
            let spec = sampler::find(lobe.kind, lobe.method);
            let fresnel = effects.fresnel != Fresnel::None;
            let masking = effects.masking != Masking::None && lobe.kind != LobeKind::Ward;
            let mut modules = vec![compose::sampler_module(spec, true)];
            modules.extend(effect_modules(fresnel, masking));
            let mut source = compose::compose_with(job, workgroup_words, job.bins() as u32, Precision::F32Accurate, &modules);
            source.push('\n');
            let mut constants = vec![("ANISOTROPIC", f64::from(u8::from(lobe.alpha_x != lobe.alpha_y)))];
            source.push_str("override ANISOTROPIC: bool = true;\n");
            if fresnel {
                source.push_str("override FRESNEL: u32 = 1u;\n");
                constants.push(("FRESNEL", effects.fresnel.mode() as f64));
            }
            if masking {
                source.push_str("override MASKING: u32 = 1u;\n");
                constants.push(("MASKING", effects.masking.mode() as f64));
            }
            source.push_str(&samplers_glue(&[spec], masking));
            source.push_str(&effect_call_sites(&OVERRIDES, fresnel, masking));
            compose::push_all(&mut source, &effect_files(fresnel, masking));
            Composed { source, constants }
        }
        Specialisation::Uber => Composed { source: compose_uber(job, workgroup_words), constants: Vec::new() },
    }
}

/// The module a case runs: its weighted module (which holds its counting kernels too) with
/// effects, else its counting module (`tile_bins` bins per pass where the histogram is tiled).
pub fn case_module(job: &Job, effects: Option<&Effects>, workgroup_words: u32, tile_bins: u32) -> Composed {
    match (effects, job) {
        (Some(e), Job::Lobe { .. }) => compose_effects(job, e, workgroup_words, Specialisation::Specialised),
        _ => Composed { source: compose::compose_tile(job, workgroup_words, tile_bins), constants: Vec::new() },
    }
}

/// The uber-kernel on `job`'s grid: every lobe and sampler, Fresnel and masking, switched at
/// run time by `effect.modes` = (sampler id, Fresnel mode, masking mode, anisotropic).
fn compose_uber(job: &Job, workgroup_words: u32) -> String {
    let mut modules: Vec<&str> = Vec::new();
    for spec in &REGISTRY {
        let m = compose::sampler_module(spec, true);
        if !modules.contains(&m) {
            modules.push(m);
        }
    }
    modules.extend(effect_modules(true, true));
    let mut source = compose::header(job, workgroup_words, job.bins() as u32, Precision::F32Accurate, &modules);
    source.push_str("// The uber-kernel: every lobe, sampler and effect, switched at run time\n");
    source.push_str(&compose::sampler_call_site(&REGISTRY.iter().collect::<Vec<_>>()));
    compose::push_all(&mut source, &[sources::LOBE_KERNEL, sources::LOBE_DRAW]);
    source.push_str(&samplers_glue(&REGISTRY.iter().collect::<Vec<_>>(), true));
    source.push_str(&effect_call_sites(&UNIFORM, true, true));
    compose::push_all(&mut source, &effect_files(true, true));
    source
}

/// The `effect` uniform of a case (`Effect` in `shaders/passes/weighted.wgsl`).
pub fn effect_uniform(kind: LobeKind, method: Method, anisotropic: bool, effects: &Effects) -> ([u32; 4], [f32; 4]) {
    let masking = if kind == LobeKind::Ward { 0 } else { effects.masking.mode() };
    ([sampler_id(kind, method), effects.fresnel.mode(), masking, u32::from(anisotropic)], effects.fresnel.params())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::Lobe;
    use crate::stats::histogram::SphereGrid;
    use glam::DVec3;

    fn job(kind: LobeKind, method: Method, anisotropic: bool) -> Job {
        let lobe = Lobe { kind, method, alpha_x: 0.3, alpha_y: if anisotropic { 0.1 } else { 0.3 } };
        Job::Lobe { lobe, incident: DVec3::new(0.6, 0.0, 0.8), grid: SphereGrid { rows: 8, cols: 16 } }
    }

    #[test]
    fn every_effect_set_and_the_uber_kernel_validate() {
        let fresnels = [Fresnel::None, Fresnel::Schlick { f0: 0.04 }, Fresnel::Conductor { eta: 0.2, k: 3.9 }, Fresnel::Dielectric { eta: 1.5 }];
        for (kind, method) in SAMPLERS {
            for fresnel in fresnels {
                for masking in Masking::ALL {
                    let effects = Effects { fresnel, masking };
                    let c = compose_effects(&job(kind, method, true), &effects, 4096, Specialisation::Specialised);
                    compose::validate("effects", &c.source).unwrap_or_else(|e| panic!("{kind:?} {method:?} {effects:?}: {e}"));
                }
            }
        }
        let c = compose_effects(&job(LobeKind::Ggx, Method::Vndf, false), &Effects::NONE, 4096, Specialisation::Uber);
        compose::validate("uber", &c.source).unwrap();
        assert!(c.constants.is_empty());
    }
}
