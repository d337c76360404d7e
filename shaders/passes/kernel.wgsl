#define_import_path lobes::kernel
#import lobes::job::{BINS, CELLS, SAMPLES_PER_THREAD, TILE_BINS, WG_SIZE}
#import lobes::bindings::{params, counts, totals}
#import lobes::rng::add64
#import lobes::counting::{count_bin, flush_bins}
#import lobes::draw::draw

// The sampling-and-histogram kernels of every job. `lobes::job` is the job's generated module
// (src/engine/gpu/compose.rs: its grid, tile and the constants of src/engine/gpu/layout.rs);
// `draw(index)` (shaders/passes/lobe_draw.wgsl or discrete_draw.wgsl) returns the bin of sample
// `index` or BINS + reason - 1.
//
// Counting is exact: per workgroup, bins are packed two to a u32 word of workgroup atomics
// (16 bits each; a workgroup draws WG_SIZE * SAMPLES_PER_THREAD <= 65535 samples), flushed into
// per-chunk u32 global counters (a chunk holds < 2^32 samples), which `fold` adds into 64-bit
// totals (lo, hi pairs with carry) after every chunk.

// Where an invocation of a sampling pass is (sample_histogram, and weighted_histogram in
// shaders/passes/weighted.wgsl).
struct Invocation {
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
}

// The index within the dispatch of the k-th sample of invocation `at`: workgroups draw
// consecutive blocks of WG_SIZE * SAMPLES_PER_THREAD samples, interleaved over their invocations.
fn sample_of(at: Invocation, k: u32) -> u32 {
    return (at.wg.x + at.wg.y * at.nwg.x) * (WG_SIZE * SAMPLES_PER_THREAD) + k * WG_SIZE + at.lid;
}

@compute @workgroup_size(WG_SIZE)
fn sample_histogram(at: Invocation) {
    // Per-reason counts in registers, updated without branches (a dynamically indexed
    // private array costs a scatter per SIMD lane on CPU drivers): reasons 1-4 in a vec4, the
    // fifth (REASON_REFRACTED_NEAR_SIDE) on its own.
    var invalid = vec4<u32>(0u);
    var invalid_5 = 0u;
    let count = params.count;
    let base = params.base;
    for (var k = 0u; k < SAMPLES_PER_THREAD; k++) {
        let local = sample_of(at, k);
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
                invalid_5 += select(0u, 1u, cell - BINS == 4u);
            }
        }
    }
    flush_bins(at.lid);
    for (var r = 0u; r < 4u; r++) {
        if (invalid[r] != 0u) {
            atomicAdd(&counts[TILE_BINS + r], invalid[r]);
        }
    }
    if (invalid_5 != 0u) {
        atomicAdd(&counts[TILE_BINS + 4u], invalid_5);
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
