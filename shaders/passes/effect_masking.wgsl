#define_import_path lobes::effect_masking
#import lobes::job::{masking_mode, sampler_g1, MASKING_G1, MASKING_SEPARABLE, MASKING_HEIGHT_CORRELATED}
#import lobes::masking::{masking_separable, masking_height_correlated}

// G(wi, wr) for a weighted case with masking: the term masking_mode() names (MASKING_*,
// src/reference/masking.rs Masking::mode), from the sampler's G1 (sampler_g1, the registry's
// call site). masking_mode() is a call site of the generated `lobes::job`: an override constant
// in a specialised module, effect.modes.z in the uber-kernel. Without masking the case composes
// shaders/passes/no_masking.wgsl instead.

fn effect_masking(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let gi = sampler_g1(a, wi);
    var g = 1.0;
    switch masking_mode() {
        case MASKING_G1: { g = gi; }
        case MASKING_SEPARABLE: { g = masking_separable(gi, sampler_g1(a, wr)); }
        case MASKING_HEIGHT_CORRELATED: { g = masking_height_correlated(gi, sampler_g1(a, wr)); }
        default: {}
    }
    return g;
}
