// The sampling-and-histogram kernels. The composing host (src/engine/gpu/compose.rs) prepends the
// constants (ROWS, COLS, BINS, TILE_BINS, CELLS, WG_WORDS, and those of src/engine/gpu/layout.rs:
// WG_SIZE, SAMPLES_PER_THREAD, N_REASONS, ...), the modules a job needs, and
// `fn draw(index: vec2<u32>) -> u32`, which returns the bin of sample `index` or BINS + reason - 1.
//
// Counting is exact: per workgroup, bins are packed two to a u32 word of workgroup atomics
// (16 bits each; a workgroup draws WG_SIZE * SAMPLES_PER_THREAD <= 65535 samples), flushed into
// per-chunk u32 global counters (a chunk holds < 2^32 samples), which `fold` adds into 64-bit
// totals (lo, hi pairs with carry) after every chunk.

// Params in src/engine/gpu/params.rs, whose layout a test checks against this one.
struct Params {
    seed: vec2<u32>,
    base: vec2<u32>,
    count: u32,
    n_items: u32,
    last_positive: u32,
    tile_first: u32,
    alpha: vec2<f32>,
    _pad1: vec2<f32>,
    wi: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> counts: array<atomic<u32>>;
@group(0) @binding(2) var<storage, read_write> totals: array<vec2<u32>>;
@group(0) @binding(5) var<storage, read_write> directions_out: array<vec4<f32>>;

fn flat_group(wg: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wg.x + wg.y * nwg.x;
}

@compute @workgroup_size(WG_SIZE)
fn sample_histogram(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
) {
    let first = flat_group(wg, nwg) * (WG_SIZE * SAMPLES_PER_THREAD);
    // Per-reason counts in four registers, updated without branches (a dynamically indexed
    // private array costs a scatter per SIMD lane on CPU drivers).
    var invalid = vec4<u32>(0u);
    let count = params.count;
    let base = params.base;
    for (var k = 0u; k < SAMPLES_PER_THREAD; k++) {
        let local = first + k * WG_SIZE + lid;
        if (local < count) {
            let cell = draw(add64(base, local));
            if (cell < BINS) {
                // a pass counts the bins tile_first .. tile_first + TILE_BINS (all, untiled)
                let in_tile = cell - params.tile_first;
                if (in_tile < TILE_BINS) {
                    count_bin(in_tile);
                }
            } else {
                invalid += select(vec4<u32>(0u), vec4<u32>(1u), vec4<u32>(cell - BINS) == vec4<u32>(0u, 1u, 2u, 3u));
            }
        }
    }
    flush_bins(lid);
    for (var r = 0u; r < N_REASONS; r++) {
        if (invalid[r] != 0u) {
            atomicAdd(&counts[TILE_BINS + r], invalid[r]);
        }
    }
}

// totals[i] += counts[i] with carry into the high word; counts[i] = 0.
@compute @workgroup_size(WG_SIZE)
fn fold(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG_SIZE;
    if (i >= CELLS) {
        return;
    }
    let c = atomicExchange(&counts[i], 0u);
    let t = totals[i];
    let lo = t.x + c;
    totals[i] = vec2<u32>(lo, t.y + select(0u, 1u, lo < t.x));
}
