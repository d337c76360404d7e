//! Runs a job's kernels: sampling and histogramming in chunks, exact 64-bit totals, readback;
//! the per-sample passes; and the weighted passes of [`super::weighted`].

use super::compose;
use super::layout::{N_REASONS, WG_SIZE, binding};
use super::precision::Precision;
use super::context::{Gpu, GpuError};
use super::counting::{Counting, Strategy};
use super::dispatch::{Chunking, Pass, SamplingPasses, Step};
use super::effects::{self, PipelineSource, Specialisation};
use super::library::File;
use super::params::{ExplicitInput, Params, storage_entry};
use super::weighted::{WeightedPipelines, WeightedRun};
use crate::engine::job::{Counts, DiscreteMethod, Job, SampleRange};
use crate::reference::Invalid;
use crate::reference::discrete::{self, AliasTable};
use crate::reference::effects::Effects;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;
use wgpu::util::DeviceExt;

/// The pipelines of one composed module.
struct KernelPipelines {
    sample: wgpu::ComputePipeline,
    fold: wgpu::ComputePipeline,
    directions: Option<wgpu::ComputePipeline>,
    explicit: Option<wgpu::ComputePipeline>,
    bin_explicit: Option<wgpu::ComputePipeline>,
    counting: Counting,
}

/// The result of a GPU histogram run.
#[derive(Debug, Clone)]
pub struct GpuRun {
    pub counts: Counts,
    /// Sum of the sampling passes' GPU time from timestamp queries, where the adapter has them.
    pub gpu_seconds: Option<f64>,
    /// Wall time of the run, from the first submission to the readback.
    pub wall_seconds: f64,
    /// How the bins were counted ([`Counting::choose`]).
    pub counting: Counting,
    /// Passes over the samples: 1, or more where the histogram was split into tiles of bins to
    /// fit the adapter's storage limits (see [`GpuEngine::tiling`]).
    pub tiles: u64,
}

/// How a job's bins are split to fit the adapter: each pass draws every sample and counts the
/// bins of one tile (all bins when `tiles` is 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tiling {
    /// Bins per tile (the last tile may hold fewer).
    pub tile_bins: u64,
    /// Number of tiles, each one pass over the samples.
    pub tiles: u64,
}

impl Tiling {
    /// How a histogram of `bins` bins is split to fit `limits`: a tile's cells (its bins and
    /// the invalid reasons) must fit one storage binding as 64-bit totals, and the fold
    /// kernel's grid (one invocation per cell) the per-dimension dispatch limit. `None` where
    /// the limits hold no histogram at all.
    pub fn fit(bins: u64, limits: &wgpu::Limits) -> Option<Tiling> {
        let bytes = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let dim = limits.max_compute_workgroups_per_dimension as u64;
        let max_cells = (bytes / 8).min(dim * dim * WG_SIZE as u64).min(u32::MAX as u64);
        let tile_bins = bins.max(1).min(max_cells.checked_sub(N_REASONS as u64).filter(|&c| c > 0)?);
        Some(Tiling { tile_bins, tiles: bins.max(1).div_ceil(tile_bins) })
    }
}

/// Histograms jobs on a GPU; pipelines are cached by composed source, so cases of one shape
/// compile once.
pub struct GpuEngine {
    pub gpu: Gpu,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    cache: HashMap<String, Arc<KernelPipelines>>,
    pub chunking: Chunking,
    /// Number of modules compiled so far (for tests of the cache).
    pub compiled: usize,
    /// Pipelines of weighted histograms.
    weighted: WeightedPipelines,
    /// The arithmetic of the counting kernels it composes (f32 with the builtin functions
    /// unless `lobes::experiments::tradeoff` sets another); pipelines are cached by the composed
    /// text, which differs by precision.
    pub precision: Precision,
    /// Files put in place of the built-in ones with the same import path in the counting and
    /// per-sample kernels this engine composes: a test's deliberately broken copy of a library
    /// file (`tests/stress.rs`); empty otherwise.
    pub replaced: Vec<File>,
    /// A counting strategy asked for in place of the adapter's ([`Counting::choose`]): tests
    /// and `lobes bench` compare the two on one adapter. None otherwise.
    pub force_counting: Option<Strategy>,
}

impl GpuEngine {
    pub fn new(gpu: Gpu) -> Self {
        let entries = [
            Params::layout_entry(),
            storage_entry(binding::COUNTS, false),
            storage_entry(binding::TOTALS, false),
            storage_entry(binding::INPUT, true),
            storage_entry(binding::ALIASES, true),
            storage_entry(binding::DIRECTIONS, false),
            storage_entry(binding::SLABS, false),
        ];
        let (layout, pipeline_layout) = gpu.layout("lobes kernel", &entries);
        let weighted = WeightedPipelines::new(&gpu);
        Self { gpu, layout, pipeline_layout, cache: HashMap::new(), chunking: Chunking::default(), compiled: 0, weighted, precision: Precision::F32Accurate, replaced: Vec::new(), force_counting: None }
    }

    /// Opens the default adapter.
    pub fn open() -> Result<Self, GpuError> {
        Ok(Self::new(Gpu::new()?))
    }

    /// How a tile of `tile_bins` bins is counted on this adapter ([`Counting::choose`]).
    pub fn counting(&self, tile_bins: u32) -> Counting {
        Counting::choose(self.gpu.info.device_type, &self.gpu.limits, tile_bins, self.force_counting)
    }

    /// The composed WGSL for `job` on this adapter, counting `tile` bins (all when `None`).
    pub fn source(&self, job: &Job, tile: Option<u32>) -> String {
        let tile_bins = tile.unwrap_or(job.bins() as u32);
        let mut kernel = compose::kernel(job, self.counting(tile_bins), tile_bins, self.precision);
        kernel.chosen.extend(self.replaced.iter().cloned());
        kernel.source()
    }

    /// The largest storage buffer of counters this adapter binds, in bytes.
    fn max_storage_bytes(&self) -> u64 {
        self.gpu.limits.max_storage_buffer_binding_size.min(self.gpu.limits.max_buffer_size)
    }

    /// How `job`'s histogram is split to fit this adapter's limits ([`Tiling::fit`]). An error
    /// if the job cannot run here at all (a discrete table larger than a storage binding).
    pub fn tiling(&self, job: &Job) -> Result<Tiling, GpuError> {
        let limits = &self.gpu.limits;
        let bytes = self.max_storage_bytes();
        let dim = limits.max_compute_workgroups_per_dimension as u64;
        let what = compose::describe(job);
        let limit_names = format!(
            "max_storage_buffer_binding_size {}, max_buffer_size {}",
            limits.max_storage_buffer_binding_size, limits.max_buffer_size
        );
        if let Job::Discrete { dist, .. } = job {
            let table = dist.len() as u64 * 4;
            if table > bytes {
                return Err(GpuError::TooLarge(format!(
                    "{what}: its table needs {table} bytes in one storage buffer and this adapter binds at most {bytes} ({limit_names}); use at most {} weights",
                    bytes / 4
                )));
            }
        }
        Tiling::fit(job.bins() as u64, limits).ok_or_else(|| {
            GpuError::TooLarge(format!("{what}: this adapter's limits hold no histogram ({limit_names}, max_compute_workgroups_per_dimension {dim})"))
        })
    }

    fn kernel(&mut self, job: &Job) -> Result<Arc<KernelPipelines>, GpuError> {
        self.kernel_tiled(job, None)
    }

    /// The kernel of `job`, counting all bins (`tile` None) or the `tile` bins from
    /// `params.tile_first` on.
    fn kernel_tiled(&mut self, job: &Job, tile: Option<u32>) -> Result<Arc<KernelPipelines>, GpuError> {
        let source = self.source(job, tile);
        let counting = self.counting(tile.unwrap_or(job.bins() as u32));
        if let Some(k) = self.cache.get(&source) {
            return Ok(k.clone());
        }
        let module = self.gpu.module(&compose::describe(job), &source)?;
        let pipeline = |entry: &str| self.gpu.pipeline(&module, Some(&self.pipeline_layout), entry, &[]);
        let lobe = matches!(job, Job::Lobe { .. });
        let kernel = Arc::new(KernelPipelines {
            sample: pipeline("sample_histogram")?,
            fold: pipeline("fold")?,
            directions: lobe.then(|| pipeline("directions")).transpose()?,
            explicit: lobe.then(|| pipeline("explicit_samples")).transpose()?,
            bin_explicit: lobe.then(|| pipeline("bin_explicit")).transpose()?,
            counting,
        });
        self.gpu.check_errors()?;
        self.compiled += 1;
        self.cache.insert(source, kernel.clone());
        Ok(kernel)
    }

    /// The discrete tables (`binding::INPUT`: f32 CDF or thresholds, `binding::ALIASES`: u32
    /// aliases).
    fn tables(&self, job: &Job) -> (wgpu::Buffer, wgpu::Buffer) {
        let (f, u): (Vec<f32>, Vec<u32>) = match job {
            Job::Discrete { dist, method: DiscreteMethod::Cdf } if dist.len() > discrete::BLOCK => {
                let cdf = dist.cdf();
                let blocks = discrete::block_cdf(cdf);
                let local = (0..blocks.len()).flat_map(|b| discrete::local_cdf(cdf, b));
                (blocks.iter().copied().chain(local).map(|c| c as f32).collect(), vec![0])
            }
            Job::Discrete { dist, method: DiscreteMethod::Cdf } => (dist.cdf().iter().map(|&c| c as f32).collect(), vec![0]),
            Job::Discrete { dist, method: DiscreteMethod::Alias } => {
                let t = AliasTable::new(dist);
                (t.threshold.iter().map(|&x| x as f32).collect(), t.alias.clone())
            }
            Job::Lobe { .. } => (vec![0.0], vec![0]),
        };
        let make = |label, contents: &[u8]| {
            self.gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        (make("discrete f32", bytemuck::cast_slice(&f)), make("discrete u32", bytemuck::cast_slice(&u)))
    }

    /// Histograms the samples of `range`; `progress` is called with the number of samples done
    /// after each submission.
    pub fn histogram(&mut self, job: &Job, range: SampleRange, progress: &mut dyn FnMut(u64)) -> Result<GpuRun, GpuError> {
        self.histogram_onto(job, range, None, progress)
    }

    /// As [`GpuEngine::histogram`], adding onto `initial` counts on the device (the 64-bit
    /// totals start from them): a run can continue an earlier one exactly.
    pub fn histogram_onto(
        &mut self,
        job: &Job,
        range: SampleRange,
        initial: Option<&Counts>,
        progress: &mut dyn FnMut(u64),
    ) -> Result<GpuRun, GpuError> {
        let tiling = self.tiling(job)?;
        let kernel = match tiling.tiles {
            1 => self.kernel(job)?,
            _ => self.kernel_tiled(job, Some(tiling.tile_bins as u32))?,
        };
        let bins = job.bins() as u64;
        let tile_bins = tiling.tile_bins;
        let cells = tile_bins + N_REASONS as u64;
        if let Some(init) = initial {
            assert_eq!(init.bins.len() as u64, bins, "initial counts must match the job's bins");
        }
        let gpu = &self.gpu;
        let passes = SamplingPasses::new(gpu, self.chunking);
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let counts = gpu.buffer("chunk counts", cells * 4, storage);
        let totals = gpu.buffer("totals", cells * 8, storage);
        let dirs = gpu.buffer("directions (unused)", 16, wgpu::BufferUsages::STORAGE);
        // the slabs start at 0 (wgpu zeroes a new buffer) and the fold leaves them 0
        let slabs = gpu.buffer("slabs", kernel.counting.slab_bytes(tile_bins as u32), wgpu::BufferUsages::STORAGE);
        let (tf, tu) = self.tables(job);
        let bind = self.bind_group([passes.params(), &counts, &totals, &tf, &tu, &dirs, &slabs]);
        let steps = |chunk: SampleRange| {
            vec![
                Step { pipeline: &kernel.sample, groups: kernel.counting.groups(chunk.count) },
                Step { pipeline: &kernel.fold, groups: cells.div_ceil(WG_SIZE as u64) },
            ]
        };

        let start = Instant::now();
        let mut gpu_seconds = gpu.has_timestamps().then_some(0.0);
        let mut result = Counts::zeros(bins as usize);
        // Each tile is one pass over all the samples, counting the bins tile_first ..
        // tile_first + tile_bins; every pass also counts the invalid reasons, which are taken
        // from the first pass and must agree in the others.
        for tile in 0..tiling.tiles {
            let tile_first = tile * tile_bins;
            let tile_len = tile_bins.min(bins - tile_first);
            // The 64-bit totals start from the initial counts of the tile's cells, or zero.
            if let Some(init) = initial {
                let mut words = vec![0u32; 2 * cells as usize];
                let tile_counts = &init.bins[tile_first as usize..(tile_first + tile_len) as usize];
                for (i, &c) in tile_counts.iter().chain(std::iter::repeat_n(&0, (tile_bins - tile_len) as usize)).chain(&init.invalid).enumerate() {
                    words[2 * i] = c as u32;
                    words[2 * i + 1] = (c >> 32) as u32;
                }
                gpu.queue.write_buffer(&totals, 0, bytemuck::cast_slice(&words));
            } else if tile > 0 {
                gpu.clear(&totals);
            }
            let params = |chunk| Params::new(job, chunk).tile(tile_first as u32);
            let mut tile_progress = |done: u64| progress(((tile as u128 * range.count as u128 + done as u128) / tiling.tiles as u128) as u64);
            let seconds = passes.run(range, &bind, params, steps, &mut tile_progress)?;
            gpu_seconds = gpu_seconds.zip(seconds).map(|(a, b)| a + b);
            let cells64 = gpu.read_u64(&totals, cells)?;
            gpu.check_errors()?;
            result.bins[tile_first as usize..(tile_first + tile_len) as usize].copy_from_slice(&cells64[..tile_len as usize]);
            let invalid: [u64; Invalid::COUNT] = cells64[tile_bins as usize..].try_into().expect("one cell per invalid reason");
            if tile == 0 {
                result.invalid = invalid;
            } else if invalid != result.invalid {
                return Err(GpuError::Inconsistent(format!(
                    "tile {tile} of {} counted invalid samples {invalid:?} where tile 0 counted {:?}: the same samples drew differently",
                    tiling.tiles, result.invalid
                )));
            }
        }
        Ok(GpuRun {
            counts: result,
            gpu_seconds,
            wall_seconds: start.elapsed().as_secs_f64(),
            counting: kernel.counting,
            tiles: tiling.tiles,
        })
    }

    /// The GPU's f32 reflected directions of the samples of `range` (at most the grid's
    /// workgroups per dimension × 256 of them), each with the reason code of its validity
    /// (0: valid) in `w`.
    pub fn directions(&mut self, job: &Job, range: SampleRange) -> Result<Vec<[f32; 4]>, GpuError> {
        let kernel = self.kernel(job)?;
        let Some(pipeline) = &kernel.directions else { return Ok(Vec::new()) };
        let (tf, _) = self.tables(job);
        self.per_sample(pipeline, job, range, &tf, 1)
    }

    /// The GPU's samples for explicit uniforms u.xyz (u.xy draw h, u.z chooses a dielectric's
    /// event, as `RoughDielectric::sample`'s `u[2]`), in f32: per sample `[ωr, reason]`,
    /// `[h, pdf_r]` and `[ωr − f32(ωr), 0]` (the rest of an f64 kernel's ωr; 0 in f32 kernels).
    /// As many dispatches as the adapter's storage bindings and grid need.
    pub fn explicit(&mut self, job: &Job, u: &[[f32; 3]]) -> Result<Vec<[[f32; 4]; 3]>, GpuError> {
        const PER: u64 = 3;
        let kernel = self.kernel(job)?;
        let Some(pipeline) = &kernel.explicit else { return Ok(Vec::new()) };
        let most = (self.max_storage_bytes() / (16 * PER)).min(self.gpu.limits.max_compute_workgroups_per_dimension as u64 * WG_SIZE as u64);
        let mut out = Vec::with_capacity(u.len());
        for part in u.chunks(most.max(1) as usize) {
            let part: Vec<ExplicitInput> = part.iter().map(|&u| ExplicitInput::new(u)).collect();
            let input = self.gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("explicit u"),
                contents: bytemuck::cast_slice(&part),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let samples = self.per_sample(pipeline, job, SampleRange::whole(0, part.len() as u64), &input, PER)?;
            out.extend(samples.chunks(PER as usize).map(|p| [p[0], p[1], p[2]]));
        }
        Ok(out)
    }

    /// The GPU's bins (`shaders/lib/histogram.wgsl`'s `bin_of`, on `job`'s grid) of f32 directions.
    pub fn bins_of(&mut self, job: &Job, dirs: &[[f32; 3]]) -> Result<Vec<u32>, GpuError> {
        let kernel = self.kernel(job)?;
        let Some(pipeline) = &kernel.bin_explicit else { return Ok(Vec::new()) };
        let packed: Vec<ExplicitInput> = dirs.iter().map(|&d| ExplicitInput::new(d)).collect();
        let input = self.gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("explicit directions"),
            contents: bytemuck::cast_slice(&packed),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let out = self.per_sample(pipeline, job, SampleRange::whole(0, dirs.len() as u64), &input, 1)?;
        Ok(out.iter().map(|v| v[0] as u32).collect())
    }

    /// Runs a one-thread-per-sample entry point over `range`, reading `input` at `binding::INPUT` and
    /// writing `per` vec4s per sample.
    fn per_sample(&self, pipeline: &wgpu::ComputePipeline, job: &Job, range: SampleRange, input: &wgpu::Buffer, per: u64) -> Result<Vec<[f32; 4]>, GpuError> {
        let gpu = &self.gpu;
        let groups = range.count.div_ceil(WG_SIZE as u64);
        let (gx, gy) = gpu.grid(groups);
        assert_eq!(gy, 1, "directions: at most {} samples per call", gx as u64 * WG_SIZE as u64);
        let size = range.count * 16 * per;
        let params = gpu.buffer("params", std::mem::size_of::<Params>() as u64, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        let out = gpu.buffer("per-sample output", size, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        let unused = || gpu.buffer("unused", 16, wgpu::BufferUsages::STORAGE);
        gpu.queue.write_buffer(&params, 0, bytemuck::bytes_of(&Params::new(job, range)));
        let bind = self.bind_group([&params, &unused(), &unused(), input, &unused(), &out, &unused()]);
        gpu.dispatch(&[Pass { label: "per sample", bind: &bind, offset: Some(0), steps: vec![Step { pipeline, groups }], group1: None }])?;
        let bytes = gpu.read(&out, size)?;
        gpu.check_errors()?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// The kernel's bind group: the parameters, counts, totals, input, aliases, directions and
    /// slabs, each at its [`binding`].
    fn bind_group(&self, buffers: [&wgpu::Buffer; 7]) -> wgpu::BindGroup {
        let [params, rest @ ..] = buffers;
        let mut entries = vec![Params::bind_entry(params)];
        let bindings = [binding::COUNTS, binding::TOTALS, binding::INPUT, binding::ALIASES, binding::DIRECTIONS, binding::SLABS];
        entries.extend(rest.iter().zip(bindings).map(|(b, binding)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() }));
        self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("lobes kernel"), layout: &self.layout, entries: &entries })
    }

    /// The weighted module of `job` with `effects`, as [`GpuEngine::weighted`] compiles it.
    pub fn weighted_module(&self, job: &Job, effects: &Effects, how: Specialisation) -> PipelineSource {
        effects::compose_effects(job, effects, self.counting(job.bins() as u32), how)
    }

    /// Number of weighted pipelines compiled so far (one per distinct module and constants).
    pub fn weighted_pipelines_built(&self) -> usize {
        self.weighted.compiled
    }

    /// Sums the weights of the samples of `range` of `job` (a lobe) with `effects`, with the
    /// specialised module or the uber-kernel.
    pub fn weighted(&mut self, job: &Job, effects: &Effects, range: SampleRange, how: Specialisation) -> Result<WeightedRun, GpuError> {
        let composed = self.weighted_module(job, effects, how);
        self.weighted_with(job, effects, &composed, range)
    }

    /// As [`GpuEngine::weighted`] with a module of the caller's (from
    /// [`GpuEngine::weighted_module`], possibly altered: the tests break a weight on purpose
    /// and check that the verdict catches it).
    pub fn weighted_with(&mut self, job: &Job, effects: &Effects, composed: &PipelineSource, range: SampleRange) -> Result<WeightedRun, GpuError> {
        self.weighted.run(&self.gpu, self.chunking, job, effects, composed, range)
    }
}
