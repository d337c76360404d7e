#define_import_path lobes::weighted
#import lobes::job::{BINS, CELLS, WG_SIZE, WEIGHT_LIMIT, WEIGHT_SCALE, SQUARE_SCALE}
#import lobes::params::lobes_params
#import lobes::rng::{rng_uniforms, add64}
#import lobes::histogram::bin_of
#import lobes::lobe_kernel::lobe_classify
#import lobes::kernel::{Invocation, sample_of, samples_of}
#import lobes::effect::{effect_sample, effect_weight, effect_check}

// The weighted histogram: per cell, the sum of the estimator weights w = f(wi, wr) |cos th_r| / p(wr)
// of the samples that land there, so that sum / N estimates the directional albedo the cell
// receives; and, per bin, the largest relative difference between the sampler's own weight and
// eval(wi, wr) |cos th_r| / pdf(wr) formed independently. CPU twin: src/stats/weighted.rs. A rough
// dielectric's samples land on both sides (lobe_classify tells a wrong-side sample by its event),
// and the squares of the bins below the horizon are kept apart, for the transmitted albedo's
// standard error (the reflected one's when light comes from inside).
//
// The estimator comes from shaders/passes/effect.wgsl: `effect_sample(u)`, `effect_weight(s)`
// (the sampler's weight with the case's Fresnel and masking) and `effect_check(wr)`
// (eval · cos th_r / pdf from the lobe's eval and pdf functions).
//
// Sums are exact and order-independent: each weight is rounded to a multiple of 2^-20 and added
// into a 64-bit fixed-point cell (lo, hi) of global atomics, the carry taken from atomicAdd's
// return value. A weight that is not finite or not below 2^23 is not summed but counted (cell
// WEIGHT_OVERFLOW), so no sample is dropped silently.

// 2 words (lo, hi) per cell: CELLS cells of sum w, then sum w^2 over the bins, sum w^2 over all
// samples, the count of weights not summed, and sum w^2 over the bins below the horizon (the
// first BINS / 2: rows are even in number, from cos th = -1 up).
@group(0) @binding(7) var<storage, read_write> weight_sums: array<atomic<u32>>;
// Per bin: the f32 bits of the largest relative weight difference (non-negative f32 order as u32).
@group(0) @binding(8) var<storage, read_write> weight_error: array<atomic<u32>>;

// WEIGHT_SCALE (2^20), SQUARE_SCALE (2^16) and WEIGHT_LIMIT (2^23) come from src/stats/weighted.rs
// through the generated `lobes::job` (src/engine/gpu/layout.rs).
const SQUARES_BINS: u32 = CELLS;
const SQUARES_ALL: u32 = CELLS + 1u;
const WEIGHT_OVERFLOW: u32 = CELLS + 2u;
const SQUARES_LOWER: u32 = CELLS + 3u;

// round(v * scale) as a 64-bit integer (lo, hi), for v * scale below 2^64: the rounded value has
// 24 significant bits, so hi and lo split it exactly.
fn fixed_parts(v: f32, scale: f32) -> vec2<u32> {
    let x = round(v * scale);
    let hi = floor(x * (1.0 / 4294967296.0));
    return vec2<u32>(u32(x - hi * 4294967296.0), u32(hi));
}

// a + b in 64 bits (private accumulators).
fn add_parts(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    return vec2<u32>(lo, a.y + b.y + select(0u, 1u, lo < a.x));
}

// Adds the 64-bit p into cell `cell` (words 2 cell, 2 cell + 1), the carry from atomicAdd's old value.
fn add_fixed(cell: u32, p: vec2<u32>) {
    let old = atomicAdd(&weight_sums[2u * cell], p.x);
    let up = p.y + select(0u, 1u, old + p.x < old);
    if (up != 0u) {
        atomicAdd(&weight_sums[2u * cell + 1u], up);
    }
}

// |w - check| / check, as u32 bits for atomicMax; a NaN (or an infinite difference) is +inf.
fn relative_error_bits(w: f32, check: f32) -> u32 {
    var e = 0.0;
    if (w != check) {
        e = abs(w - check) / check;
    }
    if (!(e <= 3.0e38)) {
        return 0x7f800000u;
    }
    return bitcast<u32>(e);
}

@compute @workgroup_size(WG_SIZE)
fn weighted_histogram(at: Invocation) {
    // The sums of squares and the overflow count stay in registers until the end: one atomic
    // per invocation instead of one per sample.
    var squares_bins = vec2<u32>(0u);
    var squares_all = vec2<u32>(0u);
    var squares_lower = vec2<u32>(0u);
    var overflow = 0u;
    let first = sample_of(at, 0u);
    let n = samples_of(at, lobes_params.count);
    for (var k = 0u; k < n; k++) {
        let u = rng_uniforms(lobes_params.seed, add64(lobes_params.base, first + k * WG_SIZE));
        let s = effect_sample(u.xyz);
        let reason = lobe_classify(s);
        let w = effect_weight(s);
        if (!(w >= 0.0 && w < WEIGHT_LIMIT)) {
            overflow += 1u;
            continue;
        }
        let sq = fixed_parts(w * w, SQUARE_SCALE);
        squares_all = add_parts(squares_all, sq);
        if (reason == 0u) {
            let bin = bin_of(s.wr);
            add_fixed(bin, fixed_parts(w, WEIGHT_SCALE));
            squares_bins = add_parts(squares_bins, sq);
            if (bin < BINS / 2u) {
                squares_lower = add_parts(squares_lower, sq);
            }
            atomicMax(&weight_error[bin], relative_error_bits(w, effect_check(s.wr)));
        } else {
            add_fixed(BINS + reason - 1u, fixed_parts(w, WEIGHT_SCALE));
        }
    }
    add_fixed(SQUARES_BINS, squares_bins);
    add_fixed(SQUARES_ALL, squares_all);
    add_fixed(WEIGHT_OVERFLOW, vec2<u32>(overflow, 0u));
    add_fixed(SQUARES_LOWER, squares_lower);
}
