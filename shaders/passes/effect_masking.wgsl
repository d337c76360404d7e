#define_import_path lobes::effect_masking
#import lobes::job::{masking_mode, masking_across, sampler_g1, MASKING_G1, MASKING_SEPARABLE, MASKING_HEIGHT_CORRELATED}
#import lobes::masking::{masking_separable, masking_height_correlated, masking_height_correlated_transmitted}

// G(wi, wr) for a weighted case with masking: the term masking_mode() names (MASKING_*,
// src/reference/masking.rs Masking::mode), from the sampler's G1 (sampler_g1, the registry's
// call site). masking_mode() is a call site of the generated `lobes::job`: an override constant
// in a specialised module, effect.modes.z in the uber-kernel. Without masking the case composes
// shaders/passes/no_masking.wgsl instead. masking_across(wi, wr), also generated, is whether
// the pair lies across a rough dielectric's surface (wi.z wr.z < 0; false for a reflection lobe,
// whose wr below the horizon is a wrong-side reflection), where the height-correlated G2 takes
// its transmitted form (reference::masking::Masking::g_transmitted).

fn effect_masking(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let gi = sampler_g1(a, wi);
    var g = 1.0;
    switch masking_mode() {
        case MASKING_G1: { g = gi; }
        case MASKING_SEPARABLE: { g = masking_separable(gi, sampler_g1(a, wr)); }
        case MASKING_HEIGHT_CORRELATED: {
            let gr = sampler_g1(a, wr);
            if (masking_across(wi, wr)) {
                g = masking_height_correlated_transmitted(gi, gr);
            } else {
                g = masking_height_correlated(gi, gr);
            }
        }
        default: {}
    }
    return g;
}
