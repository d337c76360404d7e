#define_import_path lobes::kernel
#import lobes::job::{BINS, CELLS, COUNT_WG, SAMPLES_PER_THREAD, SLABS, TILE_BINS, WG_SIZE, slabs_used}
#import lobes::params::lobes_params
#import lobes::bindings::{counts, totals}
#import lobes::rng::add64
#import lobes::counting::{count_bin, flush_bins, start_counting, take_count}
#import lobes::draw::draw

// The sampling-and-histogram kernels of every job. `lobes::job` is the job's generated module
// (src/engine/gpu/compose.rs: its grid, tile and the constants of src/engine/gpu/layout.rs);
// `draw(index)` (shaders/passes/lobe_draw.wgsl or discrete_draw.wgsl) returns the bin of sample
// `index` or BINS + reason - 1.
//
// Counting is exact: the counting module (lobes::counting, src/engine/gpu/counting.rs) counts a
// chunk's samples in workgroup atomics (a u32 per bin, or two 16-bit counters a word: a workgroup
// draws WG_SIZE * SAMPLES_PER_THREAD <= 65535 samples) flushed into per-chunk u32 global
// counters, in those counters directly, or in per-invocation slabs on CPU adapters; a chunk holds
// at most 2^31 samples, and `fold` adds each chunk's counts into 64-bit totals (lo, hi pairs with
// carry).

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

// The samples invocation `at` counts of a dispatch of `count`: first + k * stride for k < n, as
// (first, stride, n). With atomics (SLABS 0) the blocks of sample_of; with slabs invocation g of
// the slabs_used(count) (workgroups of COUNT_WG) takes g, g + used, g + 2 used, ...; invocations
// past those take none.
fn counted_samples(at: Invocation, count: u32) -> vec3<u32> {
    if (SLABS == 0u) {
        return vec3<u32>(sample_of(at, 0u), WG_SIZE, samples_of(at, count));
    }
    // (not 0 here, but naga refuses a division by the constant 0 even where dead)
    let slabs = max(slabs_used(count), 1u);
    let g = invocation_of(at);
    if (g >= slabs || g >= count) {
        return vec3<u32>(0u, 1u, 0u);
    }
    return vec3<u32>(g, slabs, (count - g + slabs - 1u) / slabs);
}

// The index of invocation `at` within the counting dispatch.
fn invocation_of(at: Invocation) -> u32 {
    return (at.wg.x + at.wg.y * at.nwg.x) * COUNT_WG + at.lid;
}

@compute @workgroup_size(COUNT_WG)
fn sample_histogram(at: Invocation) {
    // Per-reason counts in registers, updated without branches (a dynamically indexed
    // private array costs a scatter per SIMD lane on CPU drivers): reasons 1-4 in a vec4, the
    // fifth (REASON_REFRACTED_NEAR_SIDE) on its own.
    var invalid = vec4<u32>(0u);
    var invalid_5 = 0u;
    let base = lobes_params.base;
    let span = counted_samples(at, lobes_params.count);
    start_counting(invocation_of(at));
    for (var k = 0u; k < span.z; k++) {
        let cell = draw(add64(base, span.x + k * span.y));
        if (cell < BINS) {
            // a pass counts the bins tile_first .. tile_first + TILE_BINS; untiled (TILE_BINS =
            // BINS, tile_first 0) all of them, with no test the compiler cannot remove
            if (TILE_BINS == BINS) {
                count_bin(cell);
            } else {
                let in_tile = cell - lobes_params.tile_first;
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

// totals[i] += the chunk's count of cell i (take_count: counts[i], and the slabs where the
// counting module has them) with carry into the high word; the chunk's counters are left 0.
@compute @workgroup_size(WG_SIZE)
fn fold(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG_SIZE;
    if (i >= CELLS) {
        return;
    }
    let c = take_count(i);
    let t = totals[i];
    let lo = t.x + c;
    totals[i] = vec2<u32>(lo, t.y + select(0u, 1u, lo < t.x));
}
