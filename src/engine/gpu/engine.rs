//! Runs a job's kernels: sampling and histogramming in chunks, exact 64-bit totals, readback.

use super::compose::{self, SAMPLES_PER_THREAD, WG_SIZE};
use super::context::{Gpu, GpuError};
use crate::engine::job::{Counts, DiscreteMethod, Job};
use crate::reference::discrete::{self, AliasTable};
use bytemuck::{Pod, Zeroable};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Instant;
use wgpu::util::DeviceExt;

/// The kernel's uniform block (`Params` in `shaders/kernel.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(super) struct Params {
    seed: [u32; 2],
    base: [u32; 2],
    count: u32,
    n_items: u32,
    last_positive: u32,
    /// First bin of the tile being counted (see [`GpuEngine::tiling`]; 0 when untiled).
    tile_first: u32,
    alpha: [f32; 2],
    _pad1: [f32; 2],
    wi: [f32; 4],
}

/// The pipelines of one composed module.
struct Kernel {
    sample: wgpu::ComputePipeline,
    fold: wgpu::ComputePipeline,
    directions: Option<wgpu::ComputePipeline>,
    explicit: Option<wgpu::ComputePipeline>,
    bin_explicit: Option<wgpu::ComputePipeline>,
    in_workgroup: bool,
}

/// How a run is cut into dispatches.
#[derive(Debug, Clone, Copy)]
pub struct Chunking {
    /// Samples per chunk (one sampling dispatch and one fold); at most 2^31.
    pub chunk_samples: u64,
    /// Chunks per submission; progress is reported after each.
    pub chunks_per_submit: u32,
}

impl Default for Chunking {
    fn default() -> Self {
        Self { chunk_samples: 1 << 26, chunks_per_submit: 4 }
    }
}

/// The result of a GPU histogram run.
#[derive(Debug, Clone)]
pub struct GpuRun {
    pub counts: Counts,
    /// Sum of the sampling passes' GPU time from timestamp queries, where the adapter has them.
    pub gpu_seconds: Option<f64>,
    /// Wall time of the run, from the first submission to the readback.
    pub wall_seconds: f64,
    /// Whether bins were counted in workgroup memory (else in global atomics).
    pub workgroup_counting: bool,
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

/// Histograms jobs on a GPU; pipelines are cached by composed source, so cases of one shape
/// compile once.
pub struct GpuEngine {
    pub gpu: Gpu,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    cache: HashMap<String, Arc<Kernel>>,
    errors: Arc<Mutex<Option<String>>>,
    pub chunking: Chunking,
    /// Number of modules compiled so far (for tests of the cache).
    pub compiled: usize,
    /// Pipelines of weighted histograms (`src/engine/gpu/weighted.rs`).
    pub(super) weighted: super::weighted::WeightedPipelines,
    /// Rewrites each composed module before it is compiled (`None`: as composed); pipelines
    /// are cached by the rewritten text. `lobes::experiments::tradeoff` sets it for its precision variants.
    pub rewrite: Option<Rewrite>,
}

/// A rewrite of a job's composed WGSL (see [`GpuEngine::rewrite`]).
pub type Rewrite = Arc<dyn Fn(&Job, String) -> String + Send + Sync>;

pub(super) fn storage(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl GpuEngine {
    pub fn new(gpu: Gpu) -> Self {
        let errors = Arc::new(Mutex::new(None));
        let sink = errors.clone();
        gpu.device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().unwrap().get_or_insert_with(|| e.to_string());
        }));
        let uniform = wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
            },
            count: None,
        };
        let layout = gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lobes kernel"),
            entries: &[uniform, storage(1, false), storage(2, false), storage(3, true), storage(4, true), storage(5, false)],
        });
        let pipeline_layout = gpu.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lobes kernel"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let weighted = super::weighted::WeightedPipelines::new(&gpu);
        Self { gpu, layout, pipeline_layout, cache: HashMap::new(), errors, chunking: Chunking::default(), compiled: 0, weighted, rewrite: None }
    }

    /// Opens the default adapter.
    pub fn open() -> Result<Self, GpuError> {
        Ok(Self::new(Gpu::new()?))
    }

    pub(super) fn check_errors(&self) -> Result<(), GpuError> {
        match self.errors.lock().unwrap().take() {
            Some(e) => Err(GpuError::Lost(e)),
            None => Ok(()),
        }
    }

    pub(super) fn workgroup_words(&self) -> u32 {
        self.gpu.limits.max_compute_workgroup_storage_size / 4
    }

    /// The composed WGSL for `job` on this adapter.
    pub fn source(&self, job: &Job) -> String {
        compose::compose(job, self.workgroup_words())
    }

    /// The largest storage buffer of counters this adapter binds, in bytes.
    fn max_storage_bytes(&self) -> u64 {
        self.gpu.limits.max_storage_buffer_binding_size.min(self.gpu.limits.max_buffer_size)
    }

    /// How `job`'s histogram is split to fit this adapter's limits: a tile's cells (its bins and
    /// the four invalid reasons) must fit one storage binding as 64-bit totals, and the fold
    /// kernel's grid (one invocation per cell) the per-dimension dispatch limit. An error if
    /// the job cannot run here at all (a discrete table larger than a storage binding).
    pub fn tiling(&self, job: &Job) -> Result<Tiling, GpuError> {
        let limits = &self.gpu.limits;
        let bytes = self.max_storage_bytes();
        let dim = limits.max_compute_workgroups_per_dimension as u64;
        let max_cells = (bytes / 8).min(dim * dim * WG_SIZE as u64).min(u32::MAX as u64);
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
        if max_cells < 5 {
            return Err(GpuError::TooLarge(format!(
                "{what}: this adapter's limits hold no histogram ({limit_names}, max_compute_workgroups_per_dimension {dim})"
            )));
        }
        let bins = (job.bins() as u64).max(1);
        let tile_bins = bins.min(max_cells - 4);
        Ok(Tiling { tile_bins, tiles: bins.div_ceil(tile_bins) })
    }

    fn kernel(&mut self, job: &Job) -> Result<Arc<Kernel>, GpuError> {
        self.kernel_tiled(job, None)
    }

    /// The kernel of `job`, counting all bins (`tile` None) or the `tile` bins from
    /// `params.tile_first` on.
    fn kernel_tiled(&mut self, job: &Job, tile: Option<u32>) -> Result<Arc<Kernel>, GpuError> {
        let (source, in_workgroup) = match tile {
            None => (self.source(job), job.bins().div_ceil(2) as u32 <= self.workgroup_words()),
            Some(t) => (compose::compose_tile(job, self.workgroup_words(), t), t.div_ceil(2) <= self.workgroup_words()),
        };
        let source = match &self.rewrite {
            Some(rewrite) => rewrite(job, source),
            None => source,
        };
        if let Some(k) = self.cache.get(&source) {
            return Ok(k.clone());
        }
        let what = compose::describe(job);
        compose::validate(&what, &source)?;
        let device = &self.gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(&what),
            source: wgpu::ShaderSource::Wgsl(source.as_str().into()),
        });
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&self.pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let kernel = Arc::new(Kernel {
            sample: pipeline("sample_histogram"),
            fold: pipeline("fold"),
            directions: matches!(job, Job::Lobe { .. }).then(|| pipeline("directions")),
            explicit: matches!(job, Job::Lobe { .. }).then(|| pipeline("explicit_samples")),
            bin_explicit: matches!(job, Job::Lobe { .. }).then(|| pipeline("bin_explicit")),
            in_workgroup,
        });
        self.check_errors()?;
        self.compiled += 1;
        self.cache.insert(source, kernel.clone());
        Ok(kernel)
    }

    pub(super) fn params(job: &Job, seed: u64, base: u64, count: u32) -> Params {
        let mut p = Params {
            seed: [seed as u32, (seed >> 32) as u32],
            base: [base as u32, (base >> 32) as u32],
            count,
            n_items: 0,
            last_positive: 0,
            tile_first: 0,
            alpha: [0.0; 2],
            _pad1: [0.0; 2],
            wi: [0.0; 4],
        };
        match job {
            Job::Lobe { lobe, incident, .. } => {
                p.alpha = [lobe.alpha_x as f32, lobe.alpha_y as f32];
                p.wi = [incident.x as f32, incident.y as f32, incident.z as f32, 0.0];
            }
            Job::Discrete { dist, .. } => {
                p.n_items = dist.len() as u32;
                p.last_positive = dist.pmf().iter().rposition(|&x| x > 0.0).unwrap_or(0) as u32;
            }
        }
        p
    }

    /// The discrete tables (binding 3: f32 CDF or thresholds, binding 4: u32 aliases).
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

    /// A buffer of at least `size` bytes (16 at the least), not mapped.
    pub(crate) fn buffer(&self, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.gpu.device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size: size.max(16), usage, mapped_at_creation: false })
    }

    pub(super) fn param_stride(&self) -> u64 {
        (self.gpu.limits.min_uniform_buffer_offset_alignment as u64).max(std::mem::size_of::<Params>() as u64)
    }

    /// Workgroup grid for `groups` workgroups within the per-dimension limit.
    pub(super) fn grid(&self, groups: u64) -> (u32, u32) {
        let max = self.gpu.limits.max_compute_workgroups_per_dimension as u64;
        let x = groups.clamp(1, max);
        (x as u32, groups.div_ceil(x).max(1) as u32)
    }

    /// Histograms samples `first .. first + samples` of the run keyed by `seed`; `progress`
    /// is called with the number of samples done after each submission.
    pub fn histogram(
        &mut self,
        job: &Job,
        seed: u64,
        first: u64,
        samples: u64,
        progress: &mut dyn FnMut(u64),
    ) -> Result<GpuRun, GpuError> {
        self.histogram_onto(job, seed, first, samples, None, progress)
    }

    /// As [`GpuEngine::histogram`], adding onto `initial` counts on the device (the 64-bit
    /// totals start from them): a run can continue an earlier one exactly.
    pub fn histogram_onto(
        &mut self,
        job: &Job,
        seed: u64,
        first: u64,
        samples: u64,
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
        let cells = tile_bins + 4;
        if let Some(init) = initial {
            assert_eq!(init.bins.len() as u64, bins, "initial counts must match the job's bins");
        }
        let per_group = (WG_SIZE * SAMPLES_PER_THREAD) as u64;
        let max_groups = self.gpu.limits.max_compute_workgroups_per_dimension as u64 * self.gpu.limits.max_compute_workgroups_per_dimension as u64;
        let chunk = self.chunking.chunk_samples.clamp(1, (1 << 31).min(max_groups * per_group));
        let per_submit = self.chunking.chunks_per_submit.max(1) as u64;
        let stride = self.param_stride();
        let use_ts = self.gpu.has_timestamps();

        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let counts = self.buffer("chunk counts", cells * 4, storage);
        let totals = self.buffer("totals", cells * 8, storage);
        let params = self.buffer("params", stride * per_submit, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        let dirs = self.buffer("directions (unused)", 16, wgpu::BufferUsages::STORAGE);
        let (tf, tu) = self.tables(job);
        let bind = self.bind_group(&params, &counts, &totals, &tf, &tu, &dirs);
        let queries = use_ts.then(|| self.timestamp_buffers(2 * per_submit as u32));

        let start = Instant::now();
        let mut gpu_ticks = 0u64;
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
                self.gpu.queue.write_buffer(&totals, 0, bytemuck::cast_slice(&words));
            } else if tile > 0 {
                let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
                encoder.clear_buffer(&totals, 0, None);
                self.gpu.queue.submit([encoder.finish()]);
            }
            let mut done = 0u64;
            while done < samples {
                let n_chunks = (samples - done).div_ceil(chunk).min(per_submit);
                let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
                for c in 0..n_chunks {
                    let base = done + c * chunk;
                    let count = chunk.min(samples - base);
                    let mut p = Self::params(job, seed, first + base, count as u32);
                    p.tile_first = tile_first as u32;
                    self.gpu.queue.write_buffer(&params, c * stride, bytemuck::bytes_of(&p));
                    let ts = queries.as_ref().map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(2 * c as u32),
                        end_of_pass_write_index: Some(2 * c as u32 + 1),
                    });
                    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("sample"), timestamp_writes: ts });
                    let offset = (c * stride) as u32;
                    pass.set_bind_group(0, &bind, &[offset]);
                    pass.set_pipeline(&kernel.sample);
                    let (gx, gy) = self.grid(count.div_ceil(per_group));
                    pass.dispatch_workgroups(gx, gy, 1);
                    pass.set_pipeline(&kernel.fold);
                    let (fx, fy) = self.grid(cells.div_ceil(WG_SIZE as u64));
                    pass.dispatch_workgroups(fx, fy, 1);
                }
                if let Some((set, resolve, read)) = &queries {
                    let n = 2 * n_chunks as u32;
                    encoder.resolve_query_set(set, 0..n, resolve, 0);
                    encoder.copy_buffer_to_buffer(resolve, 0, read, 0, n as u64 * 8);
                }
                self.gpu.queue.submit([encoder.finish()]);
                if let Some((_, _, read)) = &queries {
                    let stamps: Vec<u64> = bytemuck::cast_slice(&self.read(read, 2 * n_chunks * 8)?).to_vec();
                    gpu_ticks += stamps.chunks(2).map(|p| p[1].saturating_sub(p[0])).sum::<u64>();
                } else {
                    self.wait()?;
                }
                self.check_errors()?;
                done += n_chunks * chunk.min(samples - done);
                done = done.min(samples);
                progress(((tile as u128 * samples as u128 + done as u128) / tiling.tiles as u128) as u64);
            }
            let raw: Vec<u32> = bytemuck::cast_slice(&self.read(&totals, cells * 8)?).to_vec();
            self.check_errors()?;
            let cells64: Vec<u64> = raw.chunks(2).map(|p| p[0] as u64 | (p[1] as u64) << 32).collect();
            result.bins[tile_first as usize..(tile_first + tile_len) as usize].copy_from_slice(&cells64[..tile_len as usize]);
            let invalid: [u64; 4] = cells64[tile_bins as usize..].try_into().expect("four invalid reasons");
            if tile == 0 {
                result.invalid = invalid;
            } else if invalid != result.invalid {
                return Err(GpuError::Lost(format!(
                    "tile {tile} of {} counted invalid samples {invalid:?} where tile 0 counted {:?}: the same samples drew differently",
                    tiling.tiles, result.invalid
                )));
            }
        }
        let wall_seconds = start.elapsed().as_secs_f64();
        let period = self.gpu.queue.get_timestamp_period() as f64 * 1e-9;
        Ok(GpuRun {
            counts: result,
            gpu_seconds: use_ts.then_some(gpu_ticks as f64 * period),
            wall_seconds,
            workgroup_counting: kernel.in_workgroup,
            tiles: tiling.tiles,
        })
    }

    /// The GPU's f32 reflected directions of samples `first .. first + count`, each with the
    /// reason code of its validity (0: valid) in `w`.
    pub fn directions(&mut self, job: &Job, seed: u64, first: u64, count: u32) -> Result<Vec<[f32; 4]>, GpuError> {
        let kernel = self.kernel(job)?;
        let Some(pipeline) = &kernel.directions else { return Ok(Vec::new()) };
        let (tf, _) = self.tables(job);
        self.per_sample(pipeline, job, seed, first, count, &tf, 1)
    }

    /// The GPU's f32 samples for explicit uniforms: per sample `[ωr, reason]` and `[h, pdf_r]`.
    pub fn explicit(&mut self, job: &Job, u: &[[f32; 2]]) -> Result<Vec<[[f32; 4]; 2]>, GpuError> {
        let kernel = self.kernel(job)?;
        let Some(pipeline) = &kernel.explicit else { return Ok(Vec::new()) };
        let input = self.gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("explicit u"),
            contents: bytemuck::cast_slice(u),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let out = self.per_sample(pipeline, job, 0, 0, u.len() as u32, &input, 2)?;
        Ok(out.chunks(2).map(|p| [p[0], p[1]]).collect())
    }

    /// The GPU's bins (`shaders/histogram.wgsl`'s `bin_of`, on `job`'s grid) of f32 directions.
    pub fn bins_of(&mut self, job: &Job, dirs: &[[f32; 3]]) -> Result<Vec<u32>, GpuError> {
        let kernel = self.kernel(job)?;
        let Some(pipeline) = &kernel.bin_explicit else { return Ok(Vec::new()) };
        let packed: Vec<[f32; 2]> = dirs.iter().flat_map(|d| [[d[0], d[1]], [d[2], 0.0]]).collect();
        let input = self.gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("explicit directions"),
            contents: bytemuck::cast_slice(&packed),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let out = self.per_sample(pipeline, job, 0, 0, dirs.len() as u32, &input, 1)?;
        Ok(out.iter().map(|v| v[0] as u32).collect())
    }

    /// Runs a one-thread-per-sample entry point writing `per` vec4s per sample.
    #[allow(clippy::too_many_arguments)]
    fn per_sample(
        &self,
        pipeline: &wgpu::ComputePipeline,
        job: &Job,
        seed: u64,
        first: u64,
        count: u32,
        input: &wgpu::Buffer,
        per: u64,
    ) -> Result<Vec<[f32; 4]>, GpuError> {
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let params = self.buffer("params", self.param_stride(), wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        let dirs = self.buffer("per-sample output", count as u64 * 16 * per, storage);
        let dummy = self.buffer("unused", 16, wgpu::BufferUsages::STORAGE);
        let dummy2 = self.buffer("unused", 16, wgpu::BufferUsages::STORAGE);
        let dummy3 = self.buffer("unused", 16, wgpu::BufferUsages::STORAGE);
        self.gpu.queue.write_buffer(&params, 0, bytemuck::bytes_of(&Self::params(job, seed, first, count)));
        let bind = self.bind_group(&params, &dummy, &dummy2, input, &dummy3, &dirs);
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[0]);
            let (gx, gy) = self.grid((count as u64).div_ceil(WG_SIZE as u64));
            assert_eq!(gy, 1, "directions: at most {} samples per call", gx as u64 * WG_SIZE as u64);
            pass.dispatch_workgroups(gx, 1, 1);
        }
        self.gpu.queue.submit([encoder.finish()]);
        let bytes = self.read(&dirs, count as u64 * 16 * per)?;
        self.check_errors()?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    fn bind_group(
        &self,
        params: &wgpu::Buffer,
        counts: &wgpu::Buffer,
        totals: &wgpu::Buffer,
        tf: &wgpu::Buffer,
        tu: &wgpu::Buffer,
        dirs: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        fn whole(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }
        }
        self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lobes kernel"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: params,
                        offset: 0,
                        size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
                    }),
                },
                whole(1, counts),
                whole(2, totals),
                whole(3, tf),
                whole(4, tu),
                whole(5, dirs),
            ],
        })
    }

    /// A timestamp query set of `n` queries with its resolve and read-back buffers.
    pub(crate) fn timestamp_buffers(&self, n: u32) -> (wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer) {
        let set = self.gpu.device.create_query_set(&wgpu::QuerySetDescriptor { label: Some("timestamps"), ty: wgpu::QueryType::Timestamp, count: n });
        let resolve = self.buffer("timestamps", n as u64 * 8, wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC);
        let read = self.buffer("timestamps read", n as u64 * 8, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        (set, resolve, read)
    }

    pub(super) fn wait(&self) -> Result<(), GpuError> {
        self.gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| GpuError::Lost(e.to_string()))?;
        Ok(())
    }

    /// Copies the first `size` bytes of `src` to the host.
    pub(crate) fn read(&self, src: &wgpu::Buffer, size: u64) -> Result<Vec<u8>, GpuError> {
        let staging = if src.usage().contains(wgpu::BufferUsages::MAP_READ) {
            src.clone()
        } else {
            let staging = self.buffer("readback", size, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
            let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
            encoder.copy_buffer_to_buffer(src, 0, &staging, 0, size);
            self.gpu.queue.submit([encoder.finish()]);
            staging
        };
        let (tx, rx) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, 0..size, move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv().map_err(|e| GpuError::Readback(e.to_string()))?.map_err(|e| GpuError::Readback(e.to_string()))?;
        let data = staging.get_mapped_range(0..size).map_err(|e| GpuError::Readback(e.to_string()))?.to_vec();
        staging.unmap();
        Ok(data)
    }
}
