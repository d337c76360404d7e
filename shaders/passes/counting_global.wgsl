#define_import_path lobes::counting
#import lobes::bindings::counts

// Bin counting straight into the chunk's global counters, for histograms too large for the
// adapter's workgroup storage (the alternative to shaders/passes/counting_workgroup.wgsl).

fn count_bin(bin: u32) {
    atomicAdd(&counts[bin], 1u);
}

fn flush_bins(lid: u32) {}
