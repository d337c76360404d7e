//! How the counting kernel counts a tile's bins: the one choice, a function of the adapter's
//! device type and limits ([`Counting::choose`]), and what each choice needs of the host. The
//! kernel counts `lobes run`'s jobs and `lobes check`'s histogram alike (`src/check/gpu.rs`
//! composes it with a user's sampler as its draw).
//!
//! - On a GPU, workgroup atomics (`shaders/passes/counting_workgroup.wgsl`): a u32 counter per
//!   bin in workgroup memory, or two 16-bit counters a word where only half fits, flushed to the
//!   chunk's global counters once per workgroup; where neither fits, one storage-buffer atomic
//!   per sample (`counting_global.wgsl`).
//! - On a CPU adapter (lavapipe, wgpu's [`wgpu::DeviceType::Cpu`]), per-invocation slabs
//!   (`counting_slabs.wgsl`): each of `slabs` invocations owns `tile_bins` plain u32 counters of
//!   a storage buffer, which no other invocation touches, so it adds without atomics; the fold
//!   after each chunk adds the slabs into the chunk's counters. llvmpipe runs a workgroup's
//!   invocations as SIMD lanes of one thread and must serialise their atomics on a shared
//!   histogram; a probe kernel (GGX NDF, 64 × 128 bins, Mesa 25.0.7, 2²⁵ samples) ran 1.37e8
//!   samples/s with workgroup atomics and 1.55e8 with slabs (BENCHMARKS.md, "Counting on a CPU
//!   adapter", has this engine's figures).
//!
//! Counts are exact either way: a slab entry counts some of one chunk's samples, and a chunk
//! holds at most 2³¹ ([`super::dispatch::Chunking`]), so no u32 entry, and no sum of them into
//! the chunk's u32 counter, can wrap; the fold carries each chunk's counters into the 64-bit
//! totals as before.

/// Invocations per workgroup of the slab kernel: one SIMD group of llvmpipe at 256 bits (8
/// f32 lanes), as the probe above ran it.
pub const SLAB_WORKGROUP: u32 = 8;
/// The most bytes the slabs of one pass may take (with the adapter's storage binding limit).
pub const SLAB_BUDGET_BYTES: u64 = 64 << 20;
/// Fewest slab workgroups worth having: fewer leave a CPU's threads idle, and then atomics are
/// the better choice.
const MIN_SLAB_GROUPS: u32 = 16;
/// Slab workgroups per host thread (lavapipe runs one worker thread per core), so that the
/// workgroups balance over the threads; at least [`MIN_SLAB_GROUPS`] · 4.
const SLAB_GROUPS_PER_THREAD: u32 = 8;

/// The strategy, for [`crate::engine::gpu::GpuEngine::force_counting`] (tests and `lobes bench`
/// compare the two on one adapter).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strategy {
    /// Workgroup atomics (or global ones where the tile does not fit), as on a GPU.
    Atomics,
    /// Per-invocation slabs, as on a CPU adapter.
    Slabs,
}

/// How a kernel counts its tile's bins.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Counting {
    /// A u32 workgroup atomic per bin.
    Workgroup,
    /// Two 16-bit workgroup counters per u32 word.
    WorkgroupPacked,
    /// A storage-buffer atomic per sample.
    Global,
    /// `slabs` invocations, each with its own `tile_bins` u32 counters in a storage buffer.
    Slabs { slabs: u32 },
}

impl Counting {
    /// The counting of a tile of `tile_bins` bins on an adapter of `device` type with `limits`:
    /// slabs on a CPU adapter where they fit, workgroup atomics elsewhere ([`Counting::atomics`]).
    /// `force` (tests, `lobes bench`) asks for one strategy; slabs that do not fit the limits
    /// fall back to atomics, which the returned value says.
    pub fn choose(device: wgpu::DeviceType, limits: &wgpu::Limits, tile_bins: u32, force: Option<Strategy>) -> Counting {
        let wanted = force.unwrap_or(if device == wgpu::DeviceType::Cpu { Strategy::Slabs } else { Strategy::Atomics });
        let words = limits.max_compute_workgroup_storage_size / 4;
        match wanted {
            Strategy::Slabs => Self::slabs(limits, tile_bins, host_threads()).unwrap_or(Self::atomics(words, tile_bins)),
            Strategy::Atomics => Self::atomics(words, tile_bins),
        }
    }

    /// Workgroup atomics where the tile fits `workgroup_words` words of workgroup storage
    /// (unpacked first: llvmpipe ran it ~1.1× as fast as the packed one), else global atomics.
    pub fn atomics(workgroup_words: u32, tile_bins: u32) -> Counting {
        if tile_bins <= workgroup_words {
            Counting::Workgroup
        } else if tile_bins.div_ceil(2) <= workgroup_words {
            Counting::WorkgroupPacked
        } else {
            Counting::Global
        }
    }

    /// Slabs for `threads` host threads within the limits: as many workgroups of
    /// [`SLAB_WORKGROUP`] as balance over the threads, fewer where the slabs would pass
    /// [`SLAB_BUDGET_BYTES`], the storage binding limit or the dispatch grid; None where fewer
    /// than `MIN_SLAB_GROUPS` would fit.
    pub fn slabs(limits: &wgpu::Limits, tile_bins: u32, threads: u32) -> Option<Counting> {
        let slab_bytes = tile_bins.max(1) as u64 * 4;
        let bytes = SLAB_BUDGET_BYTES.min(limits.max_storage_buffer_binding_size).min(limits.max_buffer_size);
        let dim = limits.max_compute_workgroups_per_dimension as u64;
        let wanted = (SLAB_GROUPS_PER_THREAD * threads.max(1)).max(4 * MIN_SLAB_GROUPS) as u64;
        let groups = wanted.min(bytes / (slab_bytes * SLAB_WORKGROUP as u64)).min(dim * dim);
        (groups >= MIN_SLAB_GROUPS as u64).then(|| Counting::Slabs { slabs: groups as u32 * SLAB_WORKGROUP })
    }

    /// Its name in outputs (`histogram.json`'s `counting`, `lobes bench`).
    pub fn name(self) -> &'static str {
        match self {
            Counting::Workgroup => "workgroup",
            Counting::WorkgroupPacked => "workgroup-packed",
            Counting::Global => "global",
            Counting::Slabs { .. } => "slabs",
        }
    }

    /// The strategy it belongs to.
    pub fn strategy(self) -> Strategy {
        match self {
            Counting::Slabs { .. } => Strategy::Slabs,
            _ => Strategy::Atomics,
        }
    }

    /// Invocations per workgroup of the counting kernel (`COUNT_WG` in `lobes::job`).
    pub fn workgroup_size(self) -> u32 {
        match self {
            Counting::Slabs { .. } => SLAB_WORKGROUP,
            _ => super::layout::WG_SIZE,
        }
    }

    /// Workgroups of the counting kernel for a chunk of `count` samples: a block of
    /// WG_SIZE · SAMPLES_PER_THREAD samples each with atomics, one per [`SLAB_WORKGROUP`] slabs
    /// whatever the count.
    pub fn groups(self, count: u64) -> u64 {
        match self {
            Counting::Slabs { slabs } => (slabs / SLAB_WORKGROUP) as u64,
            _ => super::layout::sampling_groups(count),
        }
    }

    /// Bytes of the slab buffer for `tile_bins` bins (0 without slabs).
    pub fn slab_bytes(self, tile_bins: u32) -> u64 {
        match self {
            Counting::Slabs { slabs } => slabs as u64 * tile_bins as u64 * 4,
            _ => 0,
        }
    }
}

/// Threads the host offers (lavapipe's worker threads: one per core).
fn host_threads() -> u32 {
    std::thread::available_parallelism().map_or(1, |n| n.get() as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_adapters_count_in_slabs_and_gpus_in_workgroup_memory() {
        let limits = wgpu::Limits { max_compute_workgroup_storage_size: 32768, ..wgpu::Limits::default() };
        let cpu = Counting::choose(wgpu::DeviceType::Cpu, &limits, 8192, None);
        assert_eq!(cpu.strategy(), Strategy::Slabs, "{cpu:?}");
        for gpu in [wgpu::DeviceType::DiscreteGpu, wgpu::DeviceType::IntegratedGpu, wgpu::DeviceType::Other] {
            assert_eq!(Counting::choose(gpu, &limits, 8192, None), Counting::Workgroup);
            assert_eq!(Counting::choose(gpu, &limits, 16384, None), Counting::WorkgroupPacked);
            assert_eq!(Counting::choose(gpu, &limits, 16385, None), Counting::Global);
        }
        assert_eq!(Counting::choose(wgpu::DeviceType::Cpu, &limits, 8192, Some(Strategy::Atomics)), Counting::Workgroup);
        assert_eq!(Counting::choose(wgpu::DeviceType::DiscreteGpu, &limits, 8192, Some(Strategy::Slabs)).strategy(), Strategy::Slabs);
    }

    #[test]
    fn slabs_fit_the_budget_the_binding_and_the_grid() {
        let limits = wgpu::Limits::default();
        // 2 threads: 64 workgroups of 8, 512 slabs of 32 KiB (16 MiB) for 64 × 128 bins
        assert_eq!(Counting::slabs(&limits, 8192, 2), Some(Counting::Slabs { slabs: 512 }));
        // 64 threads: 512 workgroups wanted, 256 fit the 64 MiB budget
        assert_eq!(Counting::slabs(&limits, 8192, 64), Some(Counting::Slabs { slabs: 2048 }));
        // each slab within the budget, and the total too
        for (bins, threads) in [(1, 1), (8192, 2), (100_000, 4), (1 << 20, 2)] {
            if let Some(c) = Counting::slabs(&limits, bins, threads) {
                assert!(c.slab_bytes(bins) <= SLAB_BUDGET_BYTES, "{bins} {threads}");
            }
        }
        // a table of 2^20 items: 4 MiB a slab, fewer than 16 workgroups fit: atomics
        assert_eq!(Counting::slabs(&limits, 1 << 20, 2), None);
        assert_eq!(Counting::choose(wgpu::DeviceType::Cpu, &limits, 1 << 20, None), Counting::Global);
        // a small storage binding holds fewer slabs
        let small = wgpu::Limits { max_storage_buffer_binding_size: 16 * 8 * 4 * 100, ..limits.clone() };
        assert_eq!(Counting::slabs(&small, 100, 2), Some(Counting::Slabs { slabs: 128 }));
        let grid = wgpu::Limits { max_compute_workgroups_per_dimension: 5, ..limits };
        assert_eq!(Counting::slabs(&grid, 64, 2), Some(Counting::Slabs { slabs: 25 * 8 }));
    }
}
