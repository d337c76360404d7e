#define_import_path lobes::discrete
//! embed: discrete
//! Discrete 1D distributions by CDF inversion or Walker's alias table, from two storage buffers
//! (`DiscreteBindings` gives their numbers, `DiscreteTable` their contents).

// Discrete 1D sampling; CPU twin: src/reference/discrete.rs.
// The CDF (f64 prefix sums / total, rounded to f32 on the host) is inverted by binary search for the
// first entry with cdf >= u and cdf > 0 (pbrt-v4 SampleDiscrete; the "> 0" keeps u = 0 off leading
// zeros). The alias table is Walker's, built by Vose's method in f64 on the host.

/// The table: the CDF, or the alias table's thresholds.
@group(0) @binding(3) var<storage, read> discrete_f: array<f32>; // CDF, or alias thresholds
/// The alias table's indices.
@group(0) @binding(4) var<storage, read> discrete_u: array<u32>; // alias indices

/// The first index whose CDF ≥ u (and > 0), by binary search; up to DISCRETE_BLOCK items.
fn discrete_sample_cdf(u: f32, n: u32, last_positive: u32) -> u32 {
    var lo = 0u;
    var hi = n;
    while (lo < hi) {
        let mid = lo + (hi - lo) / 2u;
        let c = discrete_f[mid];
        if (c >= u && c > 0.0) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    return min(lo, last_positive);
}

// Two-level inversion for tables of more than DISCRETE_BLOCK entries (one 24-bit uniform and an
// f32 CDF cannot resolve them): discrete_f holds the CDF over blocks (n_blocks entries), then each
// block's own CDF. u.x picks the block, u.y the entry within it.
/// The most items discrete_sample_cdf inverts in one level.
const DISCRETE_BLOCK: u32 = 4096u;

/// The first i < n whose entry `discrete_f[first + i]` is ≥ u (binary search).
fn discrete_search(u: f32, first: u32, n: u32) -> u32 {
    var lo = 0u;
    var hi = n;
    while (lo < hi) {
        let mid = lo + (hi - lo) / 2u;
        let c = discrete_f[first + mid];
        if (c >= u && c > 0.0) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    return min(lo, n - 1u);
}

/// The same as discrete_sample_cdf for longer tables, in two levels: u.x picks a block of
/// DISCRETE_BLOCK items, u.y the item.
fn discrete_sample_cdf_blocks(u: vec2<f32>, n: u32, last_positive: u32) -> u32 {
    let n_blocks = (n + DISCRETE_BLOCK - 1u) / DISCRETE_BLOCK;
    let block = discrete_search(u.x, 0u, n_blocks);
    let start = block * DISCRETE_BLOCK;
    let len = min(DISCRETE_BLOCK, n - start);
    return min(start + discrete_search(u.y, n_blocks + start, len), last_positive);
}

/// Walker's alias table: column ⌊u.x n⌋, kept when u.y < its threshold, else its alias.
fn discrete_sample_alias(u: vec2<f32>, n: u32) -> u32 {
    let column = min(u32(u.x * f32(n)), n - 1u);
    return select(discrete_u[column], column, u.y < discrete_f[column]);
}
