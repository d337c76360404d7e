#define_import_path lobes::effect_masking

// G = 1: `lobes::effect_masking` of a weighted case without masking (in place of
// shaders/passes/effect_masking.wgsl, so that its module holds no masking code).

fn effect_masking(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    return 1.0;
}
