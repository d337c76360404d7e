#define_import_path lobes::counting
#import lobes::job::{TILE_BINS, slabs_used}
#import lobes::params::lobes_params
#import lobes::bindings::counts

// Bin counting in per-invocation slabs, for CPU adapters (src/engine/gpu/counting.rs chooses; the
// alternative to shaders/passes/counting_workgroup.wgsl): invocation g of the SLABS counts into
// slabs[g * TILE_BINS ..][..TILE_BINS], words no other invocation touches, so a plain
// read-modify-write is exact and needs no atomic. `take_count`, in the fold after each chunk,
// adds the slabs into the chunk's counter and clears them. A chunk uses slabs_used(count) of the
// SLABS (generated in lobes::job by src/engine/gpu/compose.rs), fewer for a small chunk, so that
// the fold's pass over the slabs stays small beside the drawing. No entry wraps: it counts some of one
// chunk's samples, at most 2^31 (src/engine/gpu/dispatch.rs, Chunking).

@group(0) @binding(9) var<storage, read_write> slabs: array<u32>;

// The first word of this invocation's slab (start_counting).
var<private> slab_first: u32;

fn start_counting(invocation: u32) {
    slab_first = invocation * TILE_BINS;
}

fn count_bin(bin: u32) {
    let w = slab_first + bin;
    slabs[w] = slabs[w] + 1u;
}

fn flush_bins(lid: u32) {}

// The chunk's count of `cell` (the invalid reasons' from their atomic counters, a bin's from the
// slabs too), leaving them all 0.
fn take_count(cell: u32) -> u32 {
    var c = atomicExchange(&counts[cell], 0u);
    if (cell < TILE_BINS) {
        for (var s = 0u; s < slabs_used(lobes_params.count); s++) {
            let w = s * TILE_BINS + cell;
            c += slabs[w];
            slabs[w] = 0u;
        }
    }
    return c;
}
