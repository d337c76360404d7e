#define_import_path lobes::check_params

// The uniform block of the passes of `lobes check` (shaders/check/user_passes.wgsl, and the
// wrappers of the generated `lobes::user`, which pass on the user's numbers): Params in
// src/check/gpu.rs, whose layout a test checks against this one.
struct LobesCheckParams {
    // the user's 16 numbers, zero-padded
    user: array<vec4<f32>, 4>,
    wi: vec4<f32>,
    // plane: (x0, y0, x1, y1); sphere: unused
    bounds: vec4<f32>,
    seed: vec2<u32>,
    base: vec2<u32>,
    count: u32,
    // finite-difference step of the probe pass
    eps: f32,
    samples_per_thread: u32,
    // the histogram's grid
    rows: u32,
    cols: u32,
    // per-invocation slabs of the histogram (0: global atomics)
    slabs: u32,
    _pad_b: u32,
    _pad_c: u32,
}

@group(0) @binding(0) var<uniform> lobes_check: LobesCheckParams;
