#define_import_path lobes::counting
#import lobes::job::{WG_SIZE, WG_WORDS, WG_BINS_PER_WORD}
#import lobes::bindings::counts

// Bin counting in workgroup memory, flushed to the chunk's global counters once per workgroup:
// a u32 counter per bin where the tile's bins fit the adapter's workgroup storage
// (WG_BINS_PER_WORD 1, WG_WORDS = BINS), else two 16-bit counters per u32 word (WG_BINS_PER_WORD 2,
// WG_WORDS = ceil(BINS / 2)); where neither fits, shaders/passes/counting_global.wgsl instead, and
// on CPU adapters shaders/passes/counting_slabs.wgsl (src/engine/gpu/counting.rs chooses). The unpacked counter adds a constant 1, which llvmpipe
// need not form per lane: ~1.1x the samples/s of the packed one there (BENCHMARKS.md "Kernel structure").

var<workgroup> wg_bins: array<atomic<u32>, WG_WORDS>;

fn start_counting(invocation: u32) {}

fn count_bin(bin: u32) {
    if (WG_BINS_PER_WORD == 1u) {
        atomicAdd(&wg_bins[bin], 1u);
    } else {
        atomicAdd(&wg_bins[bin >> 1u], 1u << ((bin & 1u) * 16u));
    }
}

fn flush_bins(lid: u32) {
    workgroupBarrier();
    for (var w = lid; w < WG_WORDS; w += WG_SIZE) {
        let v = atomicLoad(&wg_bins[w]);
        if (WG_BINS_PER_WORD == 1u) {
            if (v != 0u) {
                atomicAdd(&counts[w], v);
            }
        } else {
            if ((v & 0xffffu) != 0u) {
                atomicAdd(&counts[2u * w], v & 0xffffu);
            }
            if ((v >> 16u) != 0u) {
                atomicAdd(&counts[2u * w + 1u], v >> 16u);
            }
        }
    }
}

// The chunk's count of `cell`, leaving it 0.
fn take_count(cell: u32) -> u32 {
    return atomicExchange(&counts[cell], 0u);
}
