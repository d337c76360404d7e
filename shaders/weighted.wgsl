// The weighted histogram: per cell, the sum of the estimator weights w = f(wi, wr) cos th_r / p(wr)
// of the samples that land there, so that sum / N estimates the directional albedo the cell
// receives; and, per bin, the largest relative difference between the sampler's own weight and
// eval(wi, wr) cos th_r / pdf(wr) formed independently. CPU twin: src/stats/weighted.rs.
//
// The composing host (src/gpu/compose.rs) prepends the effect glue: `effect_sample(u)`,
// `effect_weight(s)` (the sampler's weight with the case's Fresnel and masking) and
// `effect_check(wr)` (eval · cos th_r / pdf from the lobe's eval and pdf functions).
//
// Sums are exact and order-independent: each weight is rounded to a multiple of 2^-20 and added
// into a 64-bit fixed-point cell (lo, hi) of global atomics, the carry taken from atomicAdd's
// return value. A weight that is not finite or not below 2^23 is not summed but counted (cell
// WEIGHT_OVERFLOW), so no sample is dropped silently.

struct Effect {
    // (sampler, fresnel, masking, anisotropic): read by the uber-kernel only; a specialised
    // kernel has them as override constants.
    modes: vec4<u32>,
    // Fresnel parameters: (f0, _, _, _) for Schlick, (eta, k, _, _) otherwise.
    fresnel: vec4<f32>,
}

@group(0) @binding(6) var<uniform> effect: Effect;
// 2 words (lo, hi) per cell: CELLS cells of sum w, then sum w^2 over the bins, sum w^2 over all
// samples, and the count of weights not summed.
@group(0) @binding(7) var<storage, read_write> weight_sums: array<atomic<u32>>;
// Per bin: the f32 bits of the largest relative weight difference (non-negative f32 order as u32).
@group(0) @binding(8) var<storage, read_write> weight_error: array<atomic<u32>>;

const WEIGHT_SCALE: f32 = 1048576.0; // 2^20 (src/stats/weighted.rs)
const SQUARE_SCALE: f32 = 65536.0; // 2^16
const WEIGHT_LIMIT: f32 = 8388608.0; // 2^23
const SQUARES_BINS: u32 = CELLS;
const SQUARES_ALL: u32 = CELLS + 1u;
const WEIGHT_OVERFLOW: u32 = CELLS + 2u;

// Adds round(v * scale) (below 2^64) into the 64-bit fixed-point cell at words 2 cell, 2 cell + 1.
fn add_fixed(cell: u32, v: f32, scale: f32) {
    let x = round(v * scale);
    // x has 24 significant bits: hi and lo split it exactly.
    let hi = floor(x * (1.0 / 4294967296.0));
    let lo = u32(x - hi * 4294967296.0);
    let old = atomicAdd(&weight_sums[2u * cell], lo);
    let up = u32(hi) + select(0u, 1u, old + lo < old);
    if (up != 0u) {
        atomicAdd(&weight_sums[2u * cell + 1u], up);
    }
}

fn record_weight(cell: u32, w: f32) {
    if (w >= 0.0 && w < WEIGHT_LIMIT) {
        add_fixed(cell, w, WEIGHT_SCALE);
        add_fixed(SQUARES_ALL, w * w, SQUARE_SCALE);
        if (cell < BINS) {
            add_fixed(SQUARES_BINS, w * w, SQUARE_SCALE);
        }
    } else {
        add_fixed(WEIGHT_OVERFLOW, 1.0, 1.0);
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

@compute @workgroup_size(256)
fn weighted_histogram(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
) {
    let first = flat_group(wg, nwg) * (WG_SIZE * SAMPLES_PER_THREAD);
    for (var k = 0u; k < SAMPLES_PER_THREAD; k++) {
        let local = first + k * WG_SIZE + lid;
        if (local >= params.count) {
            break;
        }
        let u = rng_uniforms(params.seed, add64(params.base, local));
        let s = effect_sample(u.xy);
        let reason = classify(s.wr, s.pdf_r);
        let w = effect_weight(s);
        if (reason == 0u) {
            let bin = bin_of(s.wr);
            record_weight(bin, w);
            atomicMax(&weight_error[bin], relative_error_bits(w, effect_check(s.wr)));
        } else {
            record_weight(BINS + reason - 1u, w);
        }
    }
}
