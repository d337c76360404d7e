// F at cos th = wi.h for a weighted case with a Fresnel term: the form fresnel_mode() names
// (FRESNEL_* of the composed header, src/reference/fresnel.rs Fresnel::mode), its parameters
// from the effect uniform (shaders/passes/weighted.wgsl). fresnel_mode() is generated: an override
// constant in a specialised module, effect.modes.y in the uber-kernel.

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
