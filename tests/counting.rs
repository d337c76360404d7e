//! The two ways of counting (src/engine/gpu/counting.rs) count alike: per-invocation slabs, which
//! lobes uses on CPU adapters, give the histogram of workgroup (or global) atomics, which it uses
//! on GPUs, bit for bit, for the same seed and samples: for lobes and the discrete samplers,
//! across chunks, tiles, small adapter limits and continued runs, with 64-bit totals that carry
//! past 2^32 and a chunk of 2^31 samples in one bin. Both strategies run on whatever adapter wgpu
//! finds (lavapipe in CI); without one these fail.

use lobes::engine::gpu::{Counting, Gpu, GpuEngine, GpuRun, Strategy};
use lobes::engine::job::{Counts, DiscreteMethod, Job, SampleRange, Scatter};
use lobes::reference::discrete::Distribution;
use lobes::reference::{Lobe, LobeKind, Method, reflect};
use lobes::stats::histogram::SphereGrid;

fn open(strategy: Strategy, shrink: impl FnOnce(wgpu::Limits) -> wgpu::Limits) -> GpuEngine {
    let gpu = Gpu::with_limits(shrink).unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
    let mut e = GpuEngine::new(gpu);
    e.force_counting = Some(strategy);
    e
}

fn engine(strategy: Strategy) -> GpuEngine {
    open(strategy, |l| l)
}

fn lobe(kind: LobeKind, method: Method, ax: f64, ay: f64, theta_deg: f64, (rows, cols): (u32, u32), scatter: Scatter) -> Job {
    Job::Lobe {
        lobe: Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 },
        incident: reflect::spherical(theta_deg.to_radians(), 0.4),
        grid: SphereGrid { rows, cols },
        scatter,
    }
}

fn discrete(n: usize, method: DiscreteMethod) -> Job {
    // uneven weights with zeros: empty bins, and a non-trivial alias table
    let w: Vec<f64> = (0..n).map(|i| if i % 5 == 2 { 0.0 } else { 1.0 + (i * 53 % 97) as f64 }).collect();
    Job::Discrete { dist: Distribution::new(&w).unwrap(), method }
}

fn run(e: &mut GpuEngine, job: &Job, range: SampleRange) -> GpuRun {
    let r = e.histogram(job, range, &mut |_| {}).unwrap_or_else(|err| panic!("{job:?}: {err}"));
    assert_eq!(r.counts.total(), range.count, "bins + invalid = samples");
    r
}

fn is_slabs(c: Counting) -> bool {
    matches!(c, Counting::Slabs { .. })
}

#[test]
fn slabs_count_exactly_as_workgroup_atomics() {
    use LobeKind::*;
    let reflect = Scatter::Reflect;
    let jobs = [
        // θi 60°, α 0.6: a share of the samples below the horizon, an invalid reason
        lobe(Ggx, Method::Vndf, 0.6, 0.2, 60.0, (64, 128), reflect),
        lobe(Ggx, Method::Ndf, 0.3, 0.3, 45.0, (64, 128), reflect),
        lobe(Ggx, Method::Bounded, 0.5, 0.5, 80.0, (32, 64), reflect),
        lobe(Beckmann, Method::Vndf, 0.4, 0.4, 75.0, (32, 96), reflect),
        lobe(Ward, Method::Ndf, 0.2, 0.1, 0.0, (8, 16), reflect),
        lobe(Ggx, Method::Vndf, 0.3, 0.3, 30.0, (64, 128), Scatter::Dielectric { eta: 1.5 }),
        discrete(1000, DiscreteMethod::Cdf),
        discrete(5000, DiscreteMethod::Cdf), // more than a block: the blocked CDF
        discrete(1000, DiscreteMethod::Alias),
    ];
    let mut atomics = engine(Strategy::Atomics);
    let mut slabs = engine(Strategy::Slabs);
    let n = 2_000_003;
    for (i, job) in jobs.iter().enumerate() {
        let range = SampleRange::whole(21 + i as u64, n);
        let want = run(&mut atomics, job, range);
        let got = run(&mut slabs, job, range);
        assert!(!is_slabs(want.counting), "{job:?}: {:?}", want.counting);
        assert!(is_slabs(got.counting), "{job:?}: {:?}", got.counting);
        assert!(got.counts == want.counts, "{job:?}: slabs and atomics counted differently");
        if let Job::Lobe { .. } = job {
            assert!(want.counts.invalid.iter().sum::<u64>() > 0 || i == 4, "the test wants invalid samples: {job:?}");
        }
    }
}

/// A chunk's slabs are cleared by its fold: many chunks of odd sizes in several submissions, and
/// a run continued on the device from earlier counts, give the one-chunk histogram.
#[test]
fn slabs_are_exact_across_chunks_and_continued_runs() {
    let job = lobe(LobeKind::Beckmann, Method::Ndf, 0.3, 0.3, 40.0, (64, 128), Scatter::Reflect);
    let range = SampleRange::whole(8, 1_500_001);
    let want = run(&mut engine(Strategy::Atomics), &job, range).counts;
    let mut e = engine(Strategy::Slabs);
    assert_eq!(run(&mut e, &job, range).counts, want);
    e.chunking.chunk_samples = 99_991;
    e.chunking.chunks_per_submit = 3;
    assert_eq!(run(&mut e, &job, range).counts, want, "16 chunks");
    let (head, tail) = range.split_at(700_001);
    let head = run(&mut e, &job, head).counts;
    let whole = e.histogram_onto(&job, tail, Some(&head), &mut |_| {}).unwrap().counts;
    assert_eq!(whole, want, "continued from the head's counts");
}

/// Under small limits the slabs shrink to fit (and fall back to atomics where too few fit, which
/// the run reports); the counts stay those of the adapter's own limits. A grid of 7 × 3
/// workgroups holds 21 where 20 fit the binding, so one workgroup has no slabs and must count
/// nothing; 7 workgroups a dimension also split 20 000 items into tiles of 12 539, each counted in
/// slabs.
#[test]
fn slabs_under_small_limits_equal_the_full_limits_bit_for_bit() {
    let ward = lobe(LobeKind::Ward, Method::Ndf, 0.2, 0.2, 20.0, (8, 16), Scatter::Reflect); // 128 bins: 512 bytes a slab
    let big = lobe(LobeKind::Ggx, Method::Vndf, 0.3, 0.3, 45.0, (64, 128), Scatter::Reflect);
    let table = discrete(20_000, DiscreteMethod::Alias);
    let n = 1_000_003;
    let mut reference = engine(Strategy::Atomics);
    // 20 workgroups of 8 slabs of 128 bins fit 80 KiB, 7 a grid dimension
    let mut small = open(Strategy::Slabs, |mut l| {
        l.max_storage_buffer_binding_size = 20 * 8 * 512;
        l.max_compute_workgroups_per_dimension = 7;
        l
    });
    let got = run(&mut small, &ward, SampleRange::whole(3, n));
    assert_eq!(got.counting, Counting::Slabs { slabs: 160 });
    assert_eq!(got.counts, run(&mut reference, &ward, SampleRange::whole(3, n)).counts);
    // 8192 bins: 32 KiB a slab, none fit: workgroup atomics, and said so
    let got = run(&mut small, &big, SampleRange::whole(4, n));
    assert!(!is_slabs(got.counting), "{:?}", got.counting);
    assert_eq!(got.counts, run(&mut reference, &big, SampleRange::whole(4, n)).counts);
    // tiles: 7 × 7 workgroups of 256 fold at most 12 544 cells
    let mut grid = open(Strategy::Slabs, |mut l| {
        l.max_compute_workgroups_per_dimension = 7;
        l
    });
    let tiling = grid.tiling(&table).unwrap();
    assert_eq!((tiling.tile_bins, tiling.tiles), (12_539, 2));
    let got = run(&mut grid, &table, SampleRange::whole(5, n));
    assert!(is_slabs(got.counting) && got.tiles == 2, "{:?}, {} tiles", got.counting, got.tiles);
    assert_eq!(got.counts, run(&mut reference, &table, SampleRange::whole(5, n)).counts);
}

/// The largest chunk, 2^31 samples, all in one bin: the slabs' entries (2^31 / slabs each) add
/// into the chunk's u32 counter to 2^31 exactly, and the 64-bit totals carry past 2^32 from
/// counts just below it. The counts are known without the GPU: one item of weight 1 takes
/// every sample.
#[test]
fn a_chunk_of_two_to_the_31_in_one_bin_carries_into_64_bits() {
    let job = Job::Discrete { dist: Distribution::new(&[1.0]).unwrap(), method: DiscreteMethod::Cdf };
    let mut e = engine(Strategy::Slabs);
    e.chunking.chunk_samples = 1 << 31;
    let n = 1u64 << 31;
    let near = (1u64 << 32) - 3;
    let initial = Counts { bins: vec![near], invalid: [0, 0, 0, u32::MAX as u64, 0] };
    let got = e.histogram_onto(&job, SampleRange::whole(1, n), Some(&initial), &mut |_| {}).unwrap();
    assert!(is_slabs(got.counting), "{:?}", got.counting);
    assert_eq!(got.counts.bins, vec![near + n]);
    assert_eq!(got.counts.invalid, initial.invalid);
}
