#define_import_path lobes::effect_fresnel
#import lobes::job::{fresnel_mode, FRESNEL_SCHLICK, FRESNEL_CONDUCTOR, FRESNEL_DIELECTRIC}
#import lobes::effect_uniform::effect
#import lobes::fresnel::{fresnel_schlick, fresnel_conductor, fresnel_dielectric}

// F at cos th = wi.h for a weighted case with a Fresnel term: the form fresnel_mode() names
// (FRESNEL_*, src/reference/fresnel.rs Fresnel::mode), its parameters from the effect uniform.
// fresnel_mode() is a call site of the generated `lobes::job`: an override constant in a
// specialised module, effect.modes.y in the uber-kernel. Without a Fresnel term the case
// composes shaders/passes/no_fresnel.wgsl instead.

fn effect_fresnel(c: f32) -> f32 {
    var f = 1.0;
    switch fresnel_mode() {
        case FRESNEL_SCHLICK: { f = fresnel_schlick(c, effect.fresnel.x); }
        case FRESNEL_CONDUCTOR: { f = fresnel_conductor(c, effect.fresnel.x, effect.fresnel.y); }
        case FRESNEL_DIELECTRIC: { f = fresnel_dielectric(c, effect.fresnel.x); }
        default: {}
    }
    return f;
}
