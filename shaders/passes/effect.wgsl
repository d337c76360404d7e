#define_import_path lobes::effect
#import lobes::job::{effect_anisotropic, sampler_sample, sampler_weight, sampler_eval, sampler_pdf}
#import lobes::params::lobes_params
#import lobes::reflect::LobeSample
#import lobes::effect_fresnel::effect_fresnel
#import lobes::effect_masking::effect_masking

// The estimator of a weighted histogram (shaders/passes/weighted.wgsl calls it): the sampler drawn with
// the case's roughness, its weight with the case's Fresnel and masking, and the independent
// check eval cos th_r / pdf. CPU twin: src/reference/effects.rs.
//
// What it calls is chosen by the composing host (src/engine/gpu/effects.rs): the call sites of
// the generated `lobes::job` (sampler_sample, sampler_weight, sampler_eval, sampler_pdf: the
// registry's, src/reference/sampler.rs; effect_anisotropic()), and effect_fresnel and
// effect_masking from shaders/passes/effect_fresnel.wgsl and effect_masking.wgsl where the
// case has the effect, else from no_fresnel.wgsl and no_masking.wgsl (1).

fn effect_alpha() -> vec2<f32> {
    return select(lobes_params.alpha.xx, lobes_params.alpha, effect_anisotropic());
}

fn effect_sample(u: vec3<f32>) -> LobeSample {
    return sampler_sample(effect_alpha(), lobes_params.wi.xyz, u);
}

// w = F(wi.h) G(wi, wr) w_0: the sampler's closed-form weight (src/reference/effects.rs).
fn effect_weight(s: LobeSample) -> f32 {
    let a = effect_alpha();
    let wi = lobes_params.wi.xyz;
    return effect_fresnel(dot(wi, s.h)) * effect_masking(a, wi, s.wr) * sampler_weight(a, wi, s);
}

// eval(wi, wr) |cos th_r| / pdf(wr), each formed on its own from wr (h = normalize(wi + wr); a
// rough dielectric's eval forms its own h, which may lie across the surface).
fn effect_check(wr: vec3<f32>) -> f32 {
    let a = effect_alpha();
    let wi = lobes_params.wi.xyz;
    let h = normalize(wi + wr);
    let f = effect_fresnel(dot(wi, h)) * effect_masking(a, wi, wr) * sampler_eval(a, wi, wr, h);
    return f * abs(wr.z) / sampler_pdf(a, wi, wr);
}
