#define_import_path lobes::rng
//! embed: rng
//! Counter-based uniforms, bit-identical to lobes' CPU twin (`lobes::reference::rng::uniforms`).

// Counter-based uniforms; the CPU twin is src/reference/rng.rs.
// pcg4d: Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 9(3), 2020.
// Sample `index` (a 64-bit counter as lo, hi) of the run keyed by the 64-bit `seed`
// draws pcg4d(index.lo, index.hi, seed.lo, seed.hi); integer-only, so bit-identical to the CPU.

/// The 4D hash pcg4d (Jarzynski & Olano 2020).
fn pcg4d(v_in: vec4<u32>) -> vec4<u32> {
    var v = v_in * 1664525u + 1013904223u;
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    v ^= v >> vec4<u32>(16u);
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    return v;
}

/// Top 24 bits times 2^-24: a uniform in [0, 1 - 2^-24], exact in f32.
fn rng_to_unit(bits: vec4<u32>) -> vec4<f32> {
    return vec4<f32>(bits >> vec4<u32>(8u)) * (1.0 / 16777216.0);
}

/// Four uniforms of sample `index` (a 64-bit counter as (lo, hi)) of the stream keyed by `seed`
/// (lo, hi), each a multiple of 2⁻²⁴ in [0, 1); bit-identical to the CPU twin.
fn rng_uniforms(seed: vec2<u32>, index: vec2<u32>) -> vec4<f32> {
    return rng_to_unit(pcg4d(vec4<u32>(index.x, index.y, seed.x, seed.y)));
}

/// 64-bit counter (lo, hi) plus a 32-bit offset, with carry.
fn add64(a: vec2<u32>, b: u32) -> vec2<u32> {
    let lo = a.x + b;
    return vec2<u32>(lo, a.y + select(0u, 1u, lo < a.x));
}
