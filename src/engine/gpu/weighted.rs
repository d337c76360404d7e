//! Runs weighted histograms (`shaders/passes/weighted.wgsl`): per cell the exact fixed-point sum of
//! the estimator weights, and per bin the largest weight difference against eval · cos / pdf.

use super::context::{Gpu, GpuError};
use super::dispatch::{Chunking, SamplingPasses, Step};
use super::effects::{self, PipelineSource};
use super::layout::{N_REASONS, WEIGHT_EXTRA_CELLS, binding, sampling_groups};
use super::params::{Params, storage_entry};
use crate::engine::job::{Job, SampleRange};
use crate::reference::effects::Effects;
use crate::stats::weighted::WeightedSums;
use bytemuck::{Pod, Zeroable};
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

/// The `effect` uniform (`Effect` in `shaders/passes/weighted.wgsl`; `tests::effect_layout` checks
/// the two layouts agree).
#[repr(C, align(16))]
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

impl WeightedPipelines {
    pub fn new(gpu: &Gpu) -> Self {
        let effect = wgpu::BindGroupLayoutEntry {
            binding: binding::EFFECT,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        };
        let (layout, pipeline_layout) = gpu.layout("lobes weighted", &[Params::layout_entry(), effect, storage_entry(binding::WEIGHT_SUMS, false), storage_entry(binding::WEIGHT_ERROR, false)]);
        Self { layout, pipeline_layout, cache: HashMap::new(), compiled: 0 }
    }

    fn pipeline(&mut self, gpu: &Gpu, job: &Job, composed: &PipelineSource) -> Result<Arc<wgpu::ComputePipeline>, GpuError> {
        let key = composed.key();
        if let Some(p) = self.cache.get(&key) {
            return Ok(p.clone());
        }
        let what = format!("{} (weighted)", super::compose::describe(job));
        let module = gpu.module(&what, &composed.source)?;
        let pipeline = Arc::new(gpu.pipeline(&module, Some(&self.pipeline_layout), "weighted_histogram", &composed.constants)?);
        gpu.check_errors()?;
        self.compiled += 1;
        self.cache.insert(key, pipeline.clone());
        Ok(pipeline)
    }

    /// Sums the weights of the samples of `range` of `job` (a lobe) with `effects`, run by
    /// `composed` (see [`super::GpuEngine::weighted_with`]).
    pub fn run(
        &mut self,
        gpu: &Gpu,
        chunking: Chunking,
        job: &Job,
        effects: &Effects,
        composed: &PipelineSource,
        range: SampleRange,
    ) -> Result<WeightedRun, GpuError> {
        let Job::Lobe { lobe, .. } = job else { panic!("weighted histograms are for lobe jobs") };
        let bins = job.bins() as u64;
        // 2 words (lo, hi) per cell: the bins, one per invalid reason, then Σw² over the bins,
        // Σw² over all samples, the overflow count and Σw² over the bins below the horizon
        // (`shaders/passes/weighted.wgsl`).
        let words = 2 * (bins + (N_REASONS + WEIGHT_EXTRA_CELLS) as u64);
        if words * 4 > gpu.limits.max_storage_buffer_binding_size {
            return Err(GpuError::TooLarge(format!(
                "{}: a weighted histogram of {bins} bins needs {} bytes in one storage buffer, over this adapter's max_storage_buffer_binding_size {}; use fewer bins",
                super::compose::describe(job),
                words * 4,
                gpu.limits.max_storage_buffer_binding_size
            )));
        }
        let pipeline = self.pipeline(gpu, job, composed)?;
        let passes = SamplingPasses::new(gpu, chunking);
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let sums = gpu.buffer("weight sums", words * 4, storage);
        let errors = gpu.buffer("weight errors", bins * 4, storage);
        let (modes, fresnel) = effects::effect_uniform(lobe.kind, lobe.method, lobe.alpha_x != lobe.alpha_y, effects);
        let effect = gpu.buffer("effect", 32, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        gpu.queue.write_buffer(&effect, 0, bytemuck::bytes_of(&EffectUniform { modes, fresnel }));
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lobes weighted"),
            layout: &self.layout,
            entries: &[
                Params::bind_entry(passes.params()),
                wgpu::BindGroupEntry { binding: binding::EFFECT, resource: effect.as_entire_binding() },
                wgpu::BindGroupEntry { binding: binding::WEIGHT_SUMS, resource: sums.as_entire_binding() },
                wgpu::BindGroupEntry { binding: binding::WEIGHT_ERROR, resource: errors.as_entire_binding() },
            ],
        });
        let start = Instant::now();
        let steps = |chunk: SampleRange| vec![Step { pipeline: &pipeline, groups: sampling_groups(chunk.count) }];
        let gpu_seconds = passes.run(range, &bind, |chunk| Params::new(job, chunk), steps, &mut |_| {})?;
        let cells = gpu.read_u64(&sums, words / 2)?;
        let max_error: Vec<f32> = bytemuck::cast_slice(&gpu.read(&errors, bins * 4)?).to_vec();
        gpu.check_errors()?;
        let wall_seconds = start.elapsed().as_secs_f64();
        let n = bins as usize;
        let extra = n + N_REASONS as usize;
        let sums = WeightedSums {
            bins: cells[..n].to_vec(),
            invalid: cells[n..extra].try_into().expect("one cell per reason"),
            squares_bins: cells[extra],
            squares_all: cells[extra + 1],
            overflow: cells[extra + 2],
            squares_lower: cells[extra + 3],
            max_error,
        };
        Ok(WeightedRun { sums, gpu_seconds, wall_seconds })
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{align_of, offset_of, size_of};

    #[test]
    fn effect_layout() {
        let lobe = crate::reference::Lobe { kind: crate::reference::LobeKind::Ggx, method: crate::reference::Method::Vndf, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 };
        let job = Job::Lobe { lobe, incident: glam::DVec3::Z, grid: crate::stats::histogram::SphereGrid { rows: 4, cols: 8 }, scatter: crate::engine::job::Scatter::Reflect };
        let source = effects::compose_effects(&job, &Effects::NONE, crate::engine::gpu::Counting::Workgroup, effects::Specialisation::Uber).source;
        let members = [("modes", offset_of!(EffectUniform, modes)), ("fresnel", offset_of!(EffectUniform, fresnel))];
        super::super::layout::check_struct(&source, "Effect", size_of::<EffectUniform>(), align_of::<EffectUniform>(), &members).unwrap();
    }
}
