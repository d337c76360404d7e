#define_import_path lobes::effect_fresnel

// F = 1: `lobes::effect_fresnel` of a weighted case without a Fresnel term (in place of
// shaders/passes/effect_fresnel.wgsl, so that its module holds no Fresnel code).

fn effect_fresnel(c: f32) -> f32 {
    return 1.0;
}
