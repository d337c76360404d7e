#define_import_path lobes::bindings

// The resources every kernel of a job binds (group 0) besides the uniform block at binding 0
// (lobes::params, shaders/passes/params.wgsl); the weighted pass adds its own
// (shaders/passes/effect_uniform.wgsl, shaders/passes/weighted.wgsl).

// u32 counters per cell of the tile being counted (a chunk's samples), folded into `totals`
@group(0) @binding(1) var<storage, read_write> counts: array<atomic<u32>>;
// 64-bit totals per cell, (lo, hi)
@group(0) @binding(2) var<storage, read_write> totals: array<vec2<u32>>;
// per-sample results of the checks that read samples back (shaders/passes/lobe_kernel.wgsl)
@group(0) @binding(5) var<storage, read_write> directions_out: array<vec4<f32>>;
