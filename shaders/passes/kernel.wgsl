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

// How many samples invocation `at` draws of a dispatch of `count`: its k-th, sample_of(at, k),
// for k below this (all SAMPLES_PER_THREAD in every workgroup but the last). One bound per
// invocation rather than a test per sample: the loop then runs without a per-sample mask
// (llvmpipe: ~10 % fewer instructions per sample, BENCHMARKS.md "Kernel structure").
fn samples_of(at: Invocation, count: u32) -> u32 {
    let first = sample_of(at, 0u);
    if (first >= count) {
        return 0u;
    }
    return min(SAMPLES_PER_THREAD, (count - first + WG_SIZE - 1u) / WG_SIZE);
}

@compute @workgroup_size(WG_SIZE)
fn sample_histogram(at: Invocation) {
    // Per-reason counts in registers, updated without branches (a dynamically indexed
    // private array costs a scatter per SIMD lane on CPU drivers): reasons 1-4 in a vec4, the
    // fifth (REASON_REFRACTED_NEAR_SIDE) on its own.
    var invalid = vec4<u32>(0u);
    var invalid_5 = 0u;
    let base = params.base;
    let first = sample_of(at, 0u);
    let n = samples_of(at, params.count);
    for (var k = 0u; k < n; k++) {
        let cell = draw(add64(base, first + k * WG_SIZE));
        if (cell < BINS) {
            // a pass counts the bins tile_first .. tile_first + TILE_BINS; untiled (TILE_BINS =
            // BINS, tile_first 0) all of them, with no test the compiler cannot remove
            if (TILE_BINS == BINS) {
                count_bin(cell);
            } else {
                let in_tile = cell - params.tile_first;
                if (in_tile < TILE_BINS) {
                    count_bin(in_tile);
                }
            }
        } else {
            invalid += select(vec4<u32>(0u), vec4<u32>(1u), vec4<u32>(cell - BINS) == vec4<u32>(0u, 1u, 2u, 3u));
            invalid_5 += select(0u, 1u, cell - BINS == 4u);
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
