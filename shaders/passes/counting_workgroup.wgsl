#define_import_path lobes::counting
#import lobes::job::{WG_SIZE, WG_WORDS}
#import lobes::bindings::counts

// Bin counting in workgroup memory: two 16-bit counters per u32 word (WG_WORDS = ceil(BINS / 2)),
// flushed to the chunk's global counters once per workgroup. Used when WG_WORDS words fit the
// adapter's workgroup storage (else shaders/passes/counting_global.wgsl).

var<workgroup> wg_bins: array<atomic<u32>, WG_WORDS>;

fn count_bin(bin: u32) {
    atomicAdd(&wg_bins[bin >> 1u], 1u << ((bin & 1u) * 16u));
}

fn flush_bins(lid: u32) {
    workgroupBarrier();
    for (var w = lid; w < WG_WORDS; w += WG_SIZE) {
        let v = atomicLoad(&wg_bins[w]);
        if ((v & 0xffffu) != 0u) {
            atomicAdd(&counts[2u * w], v & 0xffffu);
        }
        if ((v >> 16u) != 0u) {
            atomicAdd(&counts[2u * w + 1u], v >> 16u);
        }
    }
}
