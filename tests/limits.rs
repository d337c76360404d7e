//! Work beyond the adapter's limits is split, and the counts stay exact: with artificially small
//! limits (`Gpu::with_limits`) — 1 KiB of workgroup storage, 7 workgroups per grid dimension and
//! storage bindings of a few KiB — every histogram equals the one made under the adapter's own
//! limits bit for bit, and bins + invalid reasons add up to the samples requested.
//!
//! Like `gpu_histogram.rs`, these need a wgpu adapter (lavapipe in CI) and fail without one.

use lobes::engine::gpu::engine::Tiling;
use lobes::engine::gpu::{Counting, Gpu, GpuEngine, GpuError};
use lobes::engine::job::{Counts, DiscreteMethod, Job, SampleRange, Scatter};
use lobes::reference::discrete::Distribution;
use lobes::reference::{Lobe, LobeKind, Method, reflect};
use lobes::stats::histogram::SphereGrid;

fn open(shrink: impl FnOnce(wgpu::Limits) -> wgpu::Limits) -> GpuEngine {
    let gpu = Gpu::with_limits(shrink).unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
    GpuEngine::new(gpu)
}

/// The adapter's own limits.
fn full() -> GpuEngine {
    open(|l| l)
}

/// 1 KiB of workgroup storage (256 words: 512 bins), 7 workgroups per dimension (49 per
/// dispatch: chunks of at most 49 · 16384 samples, folds of at most 49 · 256 cells) and storage
/// bindings of `storage_bytes`.
fn small(storage_bytes: u64) -> GpuEngine {
    open(move |mut l| {
        l.max_compute_workgroup_storage_size = 1024;
        l.max_compute_workgroups_per_dimension = 7;
        l.max_storage_buffer_binding_size = storage_bytes;
        l
    })
}

fn lobe(kind: LobeKind, method: Method, ax: f64, ay: f64, theta_deg: f64, rows: u32, cols: u32) -> Job {
    Job::Lobe {
        lobe: Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 },
        incident: reflect::spherical(theta_deg.to_radians(), 0.3),
        grid: SphereGrid { rows, cols },
        scatter: Scatter::Reflect,
    }
}

fn discrete(n: usize, method: DiscreteMethod) -> Job {
    // uneven weights with zeros, so that some bins are empty and the alias table is non-trivial
    let w: Vec<f64> = (0..n).map(|i| if i % 7 == 3 { 0.0 } else { 1.0 + (i * 37 % 101) as f64 }).collect();
    Job::Discrete { dist: Distribution::new(&w).unwrap(), method }
}

fn run(e: &mut GpuEngine, job: &Job, seed: u64, n: u64) -> lobes::engine::gpu::GpuRun {
    let r = e.histogram(job, SampleRange::whole(seed, n), &mut |_| {}).unwrap_or_else(|err| panic!("{job:?}: {err}"));
    assert_eq!(r.counts.total(), n, "bins + invalid = samples");
    r
}

/// 64-bit words of 8 bytes, one per invalid reason after the bins: a binding of `bytes` holds
/// `bytes/8 - REASONS` bins.
const REASONS: u64 = lobes::reference::Invalid::COUNT as u64;
const ODD_TILE_BYTES: u64 = 8 * (509 + REASONS); // 509 bins a tile: odd, so tiles split packed words
const GLOBAL_TILE_BYTES: u64 = 8 * (3001 + REASONS); // 3001 bins: too many for 1 KiB, global atomics

#[test]
fn tiled_and_chunked_histograms_equal_the_untiled_ones_bit_for_bit() {
    let n = 1_000_003; // two chunks of at most 802 816 under the small limits, the last partial
    let jobs = [
        // 8192 bins; θi 60° and α 0.6 send a share below the horizon (an invalid reason)
        lobe(LobeKind::Ggx, Method::Vndf, 0.6, 0.2, 60.0, 64, 128),
        lobe(LobeKind::Beckmann, Method::Ndf, 0.4, 0.4, 75.0, 32, 96),
        lobe(LobeKind::Ward, Method::Ndf, 0.2, 0.2, 0.0, 8, 16), // 128 bins: one tile everywhere
        discrete(1000, DiscreteMethod::Cdf),
        discrete(1000, DiscreteMethod::Alias),
    ];
    let mut reference = full();
    let mut odd = small(ODD_TILE_BYTES);
    let mut global = small(GLOBAL_TILE_BYTES);
    for (i, job) in jobs.iter().enumerate() {
        let seed = 11 + i as u64;
        let want = run(&mut reference, job, seed, n);
        assert_eq!(want.tiles, 1);
        let bins = job.bins() as u64;
        for (engine, tile, workgroup) in [(&mut odd, 509, true), (&mut global, 3001, false)] {
            let tiling = engine.tiling(job).unwrap();
            assert_eq!(tiling, Tiling { tile_bins: bins.min(tile), tiles: bins.div_ceil(tile) }, "{job:?}");
            let got = run(engine, job, seed, n);
            assert_eq!(got.tiles, tiling.tiles);
            // storage bindings of a few KiB hold too few slabs: atomics, in workgroup memory
            // where the tile fits 1 KiB (packed: 512 bins)
            let in_workgroup = matches!(got.counting, Counting::Workgroup | Counting::WorkgroupPacked);
            assert_eq!(in_workgroup, workgroup || bins <= 512, "{job:?}: {:?}", got.counting);
            assert!(got.counts == want.counts, "{job:?} with {tile}-bin tiles differs from the untiled histogram");
        }
        if let Job::Lobe { .. } = job {
            assert!(want.counts.invalid.iter().sum::<u64>() > 0 || i == 2, "the test wants invalid samples: {job:?}");
        }
    }
}

#[test]
fn tiled_runs_continue_and_add_up_exactly() {
    let job = lobe(LobeKind::Ggx, Method::Bounded, 0.3, 0.3, 80.0, 32, 64); // 2048 bins, 5 tiles
    let n = 400_000;
    let mut e = small(ODD_TILE_BYTES);
    let whole = run(&mut e, &job, 5, n).counts;
    // the first 150 001 samples, then the rest on top of them on the device
    let (head, tail) = SampleRange::whole(5, n).split_at(150_001);
    let head = e.histogram(&job, head, &mut |_| {}).unwrap().counts;
    let mut seen = Vec::new();
    let tail = e.histogram_onto(&job, tail, Some(&head), &mut |d| seen.push(d)).unwrap();
    assert_eq!(tail.tiles, 5);
    assert!(tail.counts == whole, "continued tiled run differs");
    // progress runs over all tiles, never backwards, and ends at the samples of this call
    assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
    assert_eq!(seen.last(), Some(&(n - 150_001)));
    assert!(seen.len() >= 5);
    // shards on differently limited engines add up to the whole
    let (a, b) = SampleRange::whole(5, n).split_at(123_457);
    let mut a = full().histogram(&job, a, &mut |_| {}).unwrap().counts;
    let b = small(GLOBAL_TILE_BYTES).histogram(&job, b, &mut |_| {}).unwrap().counts;
    a.add(&b);
    assert!(a == whole);
}

/// The largest histogram a scene may ask for (2^24 bins) needs two tiles of lavapipe's 128 MiB
/// storage bindings; it runs, and adds up.
#[test]
fn the_largest_scene_histogram_runs_at_the_adapters_own_limits() {
    let job = lobe(LobeKind::Ggx, Method::Vndf, 0.5, 0.5, 30.0, 4096, 4096);
    let mut e = full();
    let tiling = e.tiling(&job).unwrap();
    let n = 1_000_000;
    let r = run(&mut e, &job, 9, n);
    assert_eq!(r.tiles, tiling.tiles);
    eprintln!("2^24 bins on {}: {tiling:?}, {:.2} s", e.gpu.adapter_name(), r.wall_seconds);
    // the same samples counted in bands of 1536 rows (the last one partial) give the same counts
    let mut banded = open(|mut l| {
        l.max_storage_buffer_binding_size = 8 * (4096 * 1536 + REASONS);
        l
    });
    assert_eq!(banded.tiling(&job).unwrap().tiles, 3);
    assert!(run(&mut banded, &job, 9, n).counts == r.counts);
}

#[test]
fn a_discrete_table_beyond_a_storage_binding_is_a_clear_error() {
    let job = discrete(2000, DiscreteMethod::Cdf); // 8000 bytes of CDF, binding 4112 bytes
    let mut e = small(ODD_TILE_BYTES);
    let err = e.histogram(&job, SampleRange::whole(1, 1000), &mut |_| {}).expect_err("the table cannot be bound");
    assert!(matches!(err, GpuError::TooLarge(_)), "{err:?}");
    let msg = err.to_string();
    // 4-byte CDF entries
    let (binding, weights) = (format!("max_storage_buffer_binding_size {ODD_TILE_BYTES}"), format!("at most {} weights", ODD_TILE_BYTES / 4));
    for want in ["too large for this GPU adapter", "8000 bytes", &binding, &weights] {
        assert!(msg.contains(want), "{msg}");
    }
}

#[test]
fn without_timestamp_queries_the_wall_time_is_reported() {
    let job = lobe(LobeKind::Ggx, Method::Ndf, 0.3, 0.3, 45.0, 64, 128);
    let mut with = full();
    let mut without = full();
    // as on an adapter without TIMESTAMP_QUERY: the engine asks the Gpu what it has
    without.gpu.features.remove(wgpu::Features::TIMESTAMP_QUERY);
    assert!(!without.gpu.has_timestamps());
    let a = run(&mut with, &job, 3, 300_000);
    let b = run(&mut without, &job, 3, 300_000);
    assert!(b.gpu_seconds.is_none(), "no timestamps, no GPU time");
    assert!(b.wall_seconds > 0.0);
    assert_eq!(a.gpu_seconds.is_some(), with.gpu.has_timestamps());
    assert!(a.counts == b.counts);
}

#[test]
fn counts_from_tiles_keep_64_bit_carries() {
    // a tiled run continued from counts just below 2^32 in a bin of the last tile and in an
    // invalid reason: the carries land in the high words of the right cells
    let job = lobe(LobeKind::Ggx, Method::Vndf, 0.6, 0.6, 70.0, 16, 64); // 1024 bins, 3 tiles
    let mut e = small(ODD_TILE_BYTES);
    let fresh = run(&mut e, &job, 2, 200_000).counts;
    let mut init = Counts::zeros(1024);
    let hot = fresh.bins.iter().enumerate().rev().find(|&(_, &c)| c > 0).map(|(i, _)| i).unwrap();
    assert!(hot >= 509, "a tile after the first holds a hit: {hot}");
    init.bins[hot] = u32::MAX as u64;
    init.invalid[1] = u32::MAX as u64 - 1;
    let r = e.histogram_onto(&job, SampleRange::whole(2, 200_000), Some(&init), &mut |_| {}).unwrap();
    let mut want = fresh.clone();
    want.add(&init);
    assert!(r.counts == want);
    assert!(r.counts.bins[hot] > u32::MAX as u64);
    assert!(r.counts.invalid[1] > u32::MAX as u64, "{:?}", r.counts.invalid);
}

/// Explicit samples beyond one storage binding (here 4 KiB: 85 samples of three vec4s per
/// dispatch) come back in several dispatches, equal bit for bit to one dispatch under the
/// adapter's own limits, in order.
#[test]
fn explicit_samples_are_split_to_fit_a_storage_binding() {
    let job = lobe(LobeKind::Beckmann, Method::Vndf, 0.3, 0.2, 40.0, 8, 16);
    let u: Vec<[f32; 3]> = (0..1000).map(|i| [(i as f32 + 0.5) / 1000.0, ((i * 7919) % 1000) as f32 / 1000.0, 0.0]).collect();
    let whole = full().explicit(&job, &u).unwrap();
    let split = small(4096).explicit(&job, &u).unwrap();
    assert_eq!(whole.len(), u.len());
    assert_eq!(split, whole);
}
