#define_import_path lobes::bindings

// The resources every kernel of a job binds (group 0); the weighted pass adds its own
// (shaders/passes/effect_uniform.wgsl, shaders/passes/weighted.wgsl).

// Params in src/engine/gpu/params.rs, whose layout a test checks against this one.
struct Params {
    seed: vec2<u32>,
    base: vec2<u32>,
    count: u32,
    n_items: u32,
    last_positive: u32,
    tile_first: u32,
    alpha: vec2<f32>,
    frame: vec2<f32>,
    // wi in xyz, a dielectric's eta in w (0 for a reflection)
    wi: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
// u32 counters per cell of the tile being counted (a chunk's samples), folded into `totals`
@group(0) @binding(1) var<storage, read_write> counts: array<atomic<u32>>;
// 64-bit totals per cell, (lo, hi)
@group(0) @binding(2) var<storage, read_write> totals: array<vec2<u32>>;
// per-sample results of the checks that read samples back (shaders/passes/lobe_kernel.wgsl)
@group(0) @binding(5) var<storage, read_write> directions_out: array<vec4<f32>>;
