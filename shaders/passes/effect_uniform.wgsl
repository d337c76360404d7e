#define_import_path lobes::effect_uniform

// The `effect` uniform of a weighted pass (EffectUniform in src/engine/gpu/weighted.rs, whose
// layout a test checks against this one).
struct Effect {
    // (sampler, fresnel, masking, anisotropic): read by the uber-kernel only; a specialised
    // kernel has them as override constants.
    modes: vec4<u32>,
    // Fresnel parameters: (f0, _, _, _) for Schlick, (eta, k, _, _) otherwise.
    fresnel: vec4<f32>,
}

@group(0) @binding(6) var<uniform> effect: Effect;
