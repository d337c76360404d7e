#define_import_path lobes::params

// The uniform block of every pass, `lobes run`'s sampling kernels and `lobes check`'s passes
// alike: Params in src/engine/gpu/params.rs, whose layout a test checks against this one. Each
// pass reads the fields its job has and the host leaves the others 0. The name starts with
// `lobes_`, which `lobes check` keeps from users' files, since it composes this module with them.
struct LobesParams {
    // the dispatch's samples: the seed, the index of its first sample (lo, hi), how many
    seed: vec2<u32>,
    base: vec2<u32>,
    count: u32,
    // a discrete job's items and the last with a positive weight
    n_items: u32,
    last_positive: u32,
    // the first bin of the tile being counted (0 when untiled)
    tile_first: u32,
    // a built-in lobe's alpha and the (cos, sin) of its frame angle
    alpha: vec2<f32>,
    frame: vec2<f32>,
    // wi in xyz, a dielectric's eta in w (0 for a reflection)
    wi: vec4<f32>,
    // a user's sampler: its 16 numbers, zero-padded
    user: array<vec4<f32>, 4>,
    // the plane's box (x0, y0, x1, y1); a sphere's: unused
    bounds: vec4<f32>,
    // the finite-difference step of `lobes check`'s probe pass
    eps: f32,
    // the samples each invocation of `lobes check`'s weights pass draws
    samples_per_thread: u32,
    // `lobes check`'s histogram grid (its binning reads it; the counting kernel's are constants)
    rows: u32,
    cols: u32,
}

@group(0) @binding(0) var<uniform> lobes_params: LobesParams;
