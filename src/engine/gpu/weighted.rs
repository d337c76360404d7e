//! Runs weighted histograms (`shaders/weighted.wgsl`): per cell the exact fixed-point sum of
//! the estimator weights, and per bin the largest weight difference against eval · cos / pdf.

use super::compose::{SAMPLES_PER_THREAD, WG_SIZE};
use super::context::{Gpu, GpuError};
use super::effects::{self, Composed, Specialisation};
use super::engine::{GpuEngine, storage};
use crate::engine::job::Job;
use crate::reference::effects::Effects;
use crate::stats::weighted::WeightedSums;
use bytemuck::{Pod, Zeroable};
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

/// The `effect` uniform (`Effect` in `shaders/weighted.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct EffectUniform {
    modes: [u32; 4],
    fresnel: [f32; 4],
}

/// The layout and the cache of weighted pipelines, keyed by module source and constants: a
/// scene with many cases of one shape compiles once.
pub struct WeightedPipelines {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    cache: HashMap<String, Arc<wgpu::ComputePipeline>>,
    /// Number of weighted pipelines made so far (for tests of the cache).
    pub compiled: usize,
}

fn uniform(binding: u32, dynamic: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: dynamic, min_binding_size: None },
        count: None,
    }
}

impl WeightedPipelines {
    pub fn new(gpu: &Gpu) -> Self {
        let layout = gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lobes weighted"),
            entries: &[uniform(0, true), uniform(6, false), storage(7, false), storage(8, false)],
        });
        let pipeline_layout = gpu.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lobes weighted"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        Self { layout, pipeline_layout, cache: HashMap::new(), compiled: 0 }
    }
}

/// The result of a weighted run on the GPU.
#[derive(Debug, Clone)]
pub struct WeightedRun {
    pub sums: WeightedSums,
    /// GPU time of the weighted passes (timestamp queries), where the adapter has them.
    pub gpu_seconds: Option<f64>,
    pub wall_seconds: f64,
}

impl GpuEngine {
    /// The weighted module of `job` with `effects`, as [`GpuEngine::weighted`] compiles it.
    pub fn weighted_module(&self, job: &Job, effects: &Effects, how: Specialisation) -> Composed {
        effects::compose_effects(job, effects, self.workgroup_words(), how)
    }

    fn weighted_pipeline(&mut self, job: &Job, composed: &Composed) -> Result<Arc<wgpu::ComputePipeline>, GpuError> {
        let key = composed.key();
        if let Some(p) = self.weighted.cache.get(&key) {
            return Ok(p.clone());
        }
        let what = format!("{} (weighted)", super::compose::describe(job));
        super::compose::validate(&what, &composed.source)?;
        let device = &self.gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(&what),
            source: wgpu::ShaderSource::Wgsl(composed.source.as_str().into()),
        });
        let pipeline = Arc::new(device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("weighted_histogram"),
            layout: Some(&self.weighted.pipeline_layout),
            module: &module,
            entry_point: Some("weighted_histogram"),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &composed.constants, ..Default::default() },
            cache: None,
        }));
        self.check_errors()?;
        self.weighted.compiled += 1;
        self.weighted.cache.insert(key, pipeline.clone());
        Ok(pipeline)
    }

    /// Number of weighted pipelines compiled so far (one per distinct module and constants).
    pub fn weighted_pipelines_built(&self) -> usize {
        self.weighted.compiled
    }

    /// Sums the weights of samples `first .. first + samples` of `job` (a lobe) with `effects`,
    /// with the specialised module or the uber-kernel.
    pub fn weighted(
        &mut self,
        job: &Job,
        effects: &Effects,
        seed: u64,
        first: u64,
        samples: u64,
        how: Specialisation,
    ) -> Result<WeightedRun, GpuError> {
        let composed = self.weighted_module(job, effects, how);
        self.weighted_with(job, effects, &composed, seed, first, samples)
    }

    /// As [`GpuEngine::weighted`] with a module of the caller's (from
    /// [`GpuEngine::weighted_module`], possibly altered: the tests break a weight on purpose
    /// and check that the verdict catches it).
    pub fn weighted_with(
        &mut self,
        job: &Job,
        effects: &Effects,
        composed: &Composed,
        seed: u64,
        first: u64,
        samples: u64,
    ) -> Result<WeightedRun, GpuError> {
        let Job::Lobe { lobe, .. } = job else { panic!("weighted histograms are for lobe jobs") };
        let bins = job.bins() as u64;
        // 2 words (lo, hi) per cell: the bins, the 4 invalid reasons, then Σw² over the bins,
        // Σw² over all samples and the overflow count (`shaders/weighted.wgsl`).
        let words = 2 * (bins + 4 + 3);
        if words * 4 > self.gpu.limits.max_storage_buffer_binding_size {
            return Err(GpuError::TooLarge(format!(
                "{}: a weighted histogram of {bins} bins needs {} bytes in one storage buffer, over this adapter's max_storage_buffer_binding_size {}; use fewer bins",
                super::compose::describe(job),
                words * 4,
                self.gpu.limits.max_storage_buffer_binding_size
            )));
        }
        let pipeline = self.weighted_pipeline(job, composed)?;

        let per_group = (WG_SIZE * SAMPLES_PER_THREAD) as u64;
        let dim = self.gpu.limits.max_compute_workgroups_per_dimension as u64;
        let chunk = self.chunking.chunk_samples.clamp(1, (1 << 31).min(dim * dim * per_group));
        let chunks = samples.div_ceil(chunk).max(1);
        let stride = self.param_stride();
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let sums = self.buffer("weight sums", words * 4, storage);
        let errors = self.buffer("weight errors", bins * 4, storage);
        let params = self.buffer("params", stride * chunks, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        let (modes, fresnel) = effects::effect_uniform(lobe.kind, lobe.method, lobe.alpha_x != lobe.alpha_y, effects);
        let effect = self.buffer("effect", 32, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        self.gpu.queue.write_buffer(&effect, 0, bytemuck::bytes_of(&EffectUniform { modes, fresnel }));
        let bind = self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lobes weighted"),
            layout: &self.weighted.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &params,
                        offset: 0,
                        size: wgpu::BufferSize::new(std::mem::size_of::<super::engine::Params>() as u64),
                    }),
                },
                wgpu::BindGroupEntry { binding: 6, resource: effect.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 7, resource: sums.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 8, resource: errors.as_entire_binding() },
            ],
        });
        let queries = self.gpu.has_timestamps().then(|| self.timestamp_buffers(2 * chunks as u32));
        let start = Instant::now();
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        for c in 0..chunks {
            let base = c * chunk;
            let count = chunk.min(samples - base.min(samples));
            let p = GpuEngine::params(job, seed, first + base, count as u32);
            self.gpu.queue.write_buffer(&params, c * stride, bytemuck::bytes_of(&p));
            let ts = queries.as_ref().map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(2 * c as u32),
                end_of_pass_write_index: Some(2 * c as u32 + 1),
            });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("weighted"), timestamp_writes: ts });
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[(c * stride) as u32]);
            let (gx, gy) = self.grid(count.div_ceil(per_group));
            pass.dispatch_workgroups(gx, gy, 1);
        }
        if let Some((set, resolve, read)) = &queries {
            encoder.resolve_query_set(set, 0..2 * chunks as u32, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, read, 0, 2 * chunks * 8);
        }
        self.gpu.queue.submit([encoder.finish()]);
        let gpu_seconds = match &queries {
            Some((_, _, read)) => {
                let stamps: Vec<u64> = bytemuck::cast_slice(&self.read(read, 2 * chunks * 8)?).to_vec();
                let ticks: u64 = stamps.chunks(2).map(|p| p[1].saturating_sub(p[0])).sum();
                Some(ticks as f64 * self.gpu.queue.get_timestamp_period() as f64 * 1e-9)
            }
            None => None,
        };
        let raw: Vec<u32> = bytemuck::cast_slice(&self.read(&sums, words * 4)?).to_vec();
        let max_error: Vec<f32> = bytemuck::cast_slice(&self.read(&errors, bins * 4)?).to_vec();
        self.check_errors()?;
        let wall_seconds = start.elapsed().as_secs_f64();
        let cells: Vec<u64> = raw.chunks(2).map(|p| p[0] as u64 | (p[1] as u64) << 32).collect();
        let n = bins as usize;
        let sums = WeightedSums {
            bins: cells[..n].to_vec(),
            invalid: cells[n..n + 4].try_into().expect("four reasons"),
            squares_bins: cells[n + 4],
            squares_all: cells[n + 5],
            overflow: cells[n + 6],
            max_error,
        };
        Ok(WeightedRun { sums, gpu_seconds, wall_seconds })
    }
}
