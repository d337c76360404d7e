#define_import_path lobes::counting
#import lobes::bindings::counts

// Bin counting straight into the chunk's global counters, for histograms too large for the
// adapter's workgroup storage (the alternative to shaders/passes/counting_workgroup.wgsl;
// src/engine/gpu/counting.rs chooses).

fn count_bin(bin: u32) {
    atomicAdd(&counts[bin], 1u);
}

fn start_counting(invocation: u32) {}

fn flush_bins(lid: u32) {}

// The chunk's count of `cell`, leaving it 0.
fn take_count(cell: u32) -> u32 {
    return atomicExchange(&counts[cell], 0u);
}
