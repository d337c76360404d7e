//! Modules for weighted histograms: a case's lobe and sampler, its Fresnel and masking terms,
//! composed into one WGSL module that holds only the code those effects need.
//!
//! Two levels of specialisation:
//! - composition: a module includes the shader files of its lobe only, `shaders/fresnel.wgsl`
//!   only with a Fresnel term, `shaders/masking.wgsl` only with masking;
//! - override constants: what is left to choose inside a file (which Fresnel form, which
//!   masking term, isotropic or not) is a `switch` on a WGSL `override`, fixed when the
//!   pipeline is made, so the driver folds the branch away.
//!
//! The uber-kernel ([`Specialisation::Uber`]) is the opposite, for measuring what generality
//! costs: every lobe, sampler and effect in one module, all switched at run time from the
//! `effect` uniform.

use super::compose::{self, sources};
use crate::engine::job::Job;
use crate::reference::effects::Effects;
use crate::reference::fresnel::Fresnel;
use crate::reference::masking::Masking;
use crate::reference::sampler::{self, REGISTRY, SamplerSpec, Wgsl};
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

/// A glue function `fn NAME(ARGS) -> RET` returning one expression per sampler: directly in a
/// specialised module, by a run-time switch on the sampler id in the uber-kernel.
fn sampler_fn(name: &str, args: &str, ret: &str, arms: &[(u32, String)]) -> String {
    if let [(_, only)] = arms {
        return format!("fn {name}({args}) -> {ret} {{\n    return {only};\n}}\n");
    }
    let mut body = format!("fn {name}({args}) -> {ret} {{\n    var r: {ret};\n    switch effect.modes.x {{\n");
    for (i, (id, expr)) in arms.iter().enumerate() {
        let label = if i + 1 == arms.len() { "default".to_string() } else { format!("case {id}u") };
        body.push_str(&format!("        {label}: {{ r = {expr}; }}\n"));
    }
    body.push_str("    }\n    return r;\n}\n");
    body
}

/// The glue of the samplers `samplers` (one in a specialised module, all in the uber-kernel).
fn samplers_glue(samplers: &[&SamplerSpec], masking: bool) -> String {
    let arms = |f: &dyn Fn(&Wgsl) -> String| -> Vec<(u32, String)> { samplers.iter().map(|s| (s.id(), f(&s.wgsl))).collect() };
    let mut src = String::new();
    src.push_str(&sampler_fn("sampler_sample", "a: vec2<f32>, wi: vec3<f32>, u: vec2<f32>", "LobeSample", &arms(&|w| format!("{}(a, wi, u)", w.sample))));
    src.push_str(&sampler_fn("sampler_weight", "a: vec2<f32>, wi: vec3<f32>, s: LobeSample", "f32", &arms(&|w| w.weight.into())));
    src.push_str(&sampler_fn("sampler_eval", "a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>, h: vec3<f32>", "f32", &arms(&|w| w.eval.into())));
    src.push_str(&sampler_fn("sampler_pdf", "a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>", "f32", &arms(&|w| w.pdf.into())));
    if masking {
        src.push_str(&sampler_fn("sampler_g1", "a: vec2<f32>, w: vec3<f32>", "f32", &arms(&|w| w.g1.unwrap_or("1.0").into())));
    }
    src
}

/// `effect_fresnel(c)`: F at cos θ = ωi·h, the form chosen by `selector`; 1 without Fresnel.
fn fresnel_glue(selector: Option<&str>) -> String {
    let Some(sel) = selector else { return "fn effect_fresnel(c: f32) -> f32 {\n    return 1.0;\n}\n".into() };
    format!(
        "fn effect_fresnel(c: f32) -> f32 {{
    var f = 1.0;
    switch {sel} {{
        case FRESNEL_SCHLICK: {{ f = fresnel_schlick(c, effect.fresnel.x); }}
        case FRESNEL_CONDUCTOR: {{ f = fresnel_conductor(c, effect.fresnel.x, effect.fresnel.y); }}
        case FRESNEL_DIELECTRIC: {{ f = fresnel_dielectric(c, effect.fresnel.x); }}
        default: {{}}
    }}
    return f;
}}
"
    )
}

/// `effect_masking(a, wi, wr)`: G, the term chosen by `selector`; 1 without masking.
fn masking_glue(selector: Option<&str>) -> String {
    let Some(sel) = selector else {
        return "fn effect_masking(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {\n    return 1.0;\n}\n".into();
    };
    format!(
        "fn effect_masking(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {{
    let gi = sampler_g1(a, wi);
    var g = 1.0;
    switch {sel} {{
        case MASKING_G1: {{ g = gi; }}
        case MASKING_SEPARABLE: {{ g = masking_separable(gi, sampler_g1(a, wr)); }}
        case MASKING_HEIGHT_CORRELATED: {{ g = masking_height_correlated(gi, sampler_g1(a, wr)); }}
        default: {{}}
    }}
    return g;
}}
"
    )
}

/// What `shaders/weighted.wgsl` calls, in terms of the glue above.
const EFFECT_GLUE: &str = "
fn effect_alpha() -> vec2<f32> {
    return select(params.alpha.xx, params.alpha, ANISOTROPIC_SEL);
}

fn effect_sample(u: vec2<f32>) -> LobeSample {
    return sampler_sample(effect_alpha(), params.wi.xyz, u);
}

// w = F(wi.h) G(wi, wr) w_0: the sampler's closed-form weight (src/reference/effects.rs).
fn effect_weight(s: LobeSample) -> f32 {
    let a = effect_alpha();
    let wi = params.wi.xyz;
    return effect_fresnel(dot(wi, s.h)) * effect_masking(a, wi, s.wr) * sampler_weight(a, wi, s);
}

// eval(wi, wr) cos th_r / pdf(wr), each formed on its own from wr (h = normalize(wi + wr)).
fn effect_check(wr: vec3<f32>) -> f32 {
    let a = effect_alpha();
    let wi = params.wi.xyz;
    let h = normalize(wi + wr);
    let f = effect_fresnel(dot(wi, h)) * effect_masking(a, wi, wr) * sampler_eval(a, wi, wr, h);
    return f * wr.z / sampler_pdf(a, wi, wr);
}
";

/// The weighted module of a lobe `job` with `effects`: the counting module of the job (so
/// that one module serves both passes of the case), the effect files it needs, the glue and
/// `shaders/weighted.wgsl`.
pub fn compose_effects(job: &Job, effects: &Effects, workgroup_words: u32, how: Specialisation) -> Composed {
    let Job::Lobe { lobe, .. } = job else { panic!("effects apply to lobe jobs only") };
    match how {
        Specialisation::Specialised => {
            let spec = sampler::find(lobe.kind, lobe.method);
            let mut source = compose::compose(job, workgroup_words);
            source.push('\n');
            compose::push_all(&mut source, &spec.wgsl.eval_files.iter().map(|f| sources::file(f)).collect::<Vec<_>>());
            let mut constants = vec![("ANISOTROPIC", f64::from(u8::from(lobe.alpha_x != lobe.alpha_y)))];
            source.push_str("override ANISOTROPIC: bool = true;\n");
            let fresnel = effects.fresnel != Fresnel::None;
            let masking = effects.masking != Masking::None && lobe.kind != LobeKind::Ward;
            if fresnel {
                source.push_str("override FRESNEL: u32 = 1u;\n");
                constants.push(("FRESNEL", effects.fresnel.mode() as f64));
                source.push_str(sources::FRESNEL);
            }
            if masking {
                source.push_str("override MASKING: u32 = 1u;\n");
                constants.push(("MASKING", effects.masking.mode() as f64));
                source.push_str(sources::MASKING);
            }
            source.push_str(&samplers_glue(&[spec], masking));
            source.push_str(&fresnel_glue(fresnel.then_some("FRESNEL")));
            source.push_str(&masking_glue(masking.then_some("MASKING")));
            source.push_str(&EFFECT_GLUE.replace("ANISOTROPIC_SEL", "ANISOTROPIC"));
            source.push_str(sources::WEIGHTED);
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
    let mut source = compose::header(job, workgroup_words, job.bins() as u32);
    source.push_str("// The uber-kernel: every lobe, sampler and effect, switched at run time\n");
    let mut files: Vec<&str> = Vec::new();
    for spec in &REGISTRY {
        for f in compose::sampler_files(spec, true) {
            if !files.contains(&f) {
                files.push(f);
            }
        }
    }
    files.extend([sources::FRESNEL, sources::MASKING]);
    compose::push_all(&mut source, &files);
    source.push_str(&sources::LOBE_KERNEL.replace("SAMPLE_FN", "sampler_sample"));
    source.push_str(&samplers_glue(&REGISTRY.iter().collect::<Vec<_>>(), true));
    source.push_str(&fresnel_glue(Some("effect.modes.y")));
    source.push_str(&masking_glue(Some("effect.modes.z")));
    source.push_str(&EFFECT_GLUE.replace("ANISOTROPIC_SEL", "effect.modes.w != 0u"));
    source.push_str(sources::WEIGHTED);
    source
}

/// The `effect` uniform of a case (`Effect` in `shaders/weighted.wgsl`).
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
