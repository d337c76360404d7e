//! The one dispatcher: every pass of the engine (counting, weighted, per-sample) and of the
//! tradeoff quadrature is compiled, encoded, submitted, timed and read back here.

use super::layout::{SAMPLES_PER_THREAD, WG_SIZE};
use super::context::{Gpu, GpuError};
use super::params::Params;
use crate::engine::job::SampleRange;
use std::time::{Duration, Instant};

/// How long a wait on the device sleeps before it looks at its [`Bounds`] again.
const SLICE: Duration = Duration::from_millis(50);

/// A delay before each pipeline creation, from `LOBES_TEST_CREATION_DELAY_MS`:
/// the tests' stand-in for a driver that compiles a shader for minutes (tests/hangs.rs), which
/// lavapipe does for no shader small enough to keep in a test. Unset (always, outside tests): none.
fn creation_delay() -> Duration {
    std::env::var("LOBES_TEST_CREATION_DELAY_MS").ok().and_then(|v| v.parse().ok()).map_or(Duration::ZERO, Duration::from_millis)
}

/// Lifts a bound set by [`Gpu::deadline`] or [`Gpu::stop_when`] when dropped.
#[must_use = "the bound lasts while this guard lives"]
pub struct Bound<'g> {
    gpu: &'g Gpu,
    deadline: bool,
}

impl Drop for Bound<'_> {
    fn drop(&mut self) {
        let b = &self.gpu.bounds;
        if self.deadline {
            *b.deadline.lock().unwrap() = None;
        } else {
            *b.stop.lock().unwrap() = None;
        }
    }
}

/// One pipeline dispatched over `groups` workgroups.
pub struct Step<'a> {
    pub pipeline: &'a wgpu::ComputePipeline,
    pub groups: u64,
}

/// A compute pass: its steps in order over one bind group (at `offset` where the group has a
/// dynamic uniform), and group 1 where the steps read one (a user's textures and tables,
/// `check::resources`).
pub struct Pass<'a> {
    pub label: &'a str,
    pub bind: &'a wgpu::BindGroup,
    pub offset: Option<u32>,
    pub steps: Vec<Step<'a>>,
    pub group1: Option<&'a wgpu::BindGroup>,
}

impl Gpu {
    /// A bind group layout of `entries` and the pipeline layout of that one group.
    pub fn layout(&self, label: &str, entries: &[wgpu::BindGroupLayoutEntry]) -> (wgpu::BindGroupLayout, wgpu::PipelineLayout) {
        let group = self.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries });
        let pipeline = self.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&group)],
            immediate_size: 0,
        });
        (group, pipeline)
    }

    /// `source` validated by naga (errors name `what`) and made a shader module, within the
    /// bounds (`Gpu::bounded`).
    pub fn module(&self, what: &str, source: &str) -> Result<wgpu::ShaderModule, GpuError> {
        super::library::validate_module(what, source)?;
        self.module_unvalidated(what, source)
    }

    /// [`Gpu::module`] of a `source` already validated (with its errors mapped to a user's files).
    pub fn module_unvalidated(&self, what: &str, source: &str) -> Result<wgpu::ShaderModule, GpuError> {
        let (device, label, source) = (self.device.clone(), what.to_string(), source.to_string());
        self.bounded(&format!("the shader module of {what}"), move || {
            device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(&label), source: wgpu::ShaderSource::Wgsl(source.into()) })
        })
    }

    /// The compute pipeline of `entry` in `module`; `layout` None: derived from the module.
    /// The driver compiles the shader here, within the bounds (`Gpu::bounded`).
    pub fn pipeline(
        &self,
        module: &wgpu::ShaderModule,
        layout: Option<&wgpu::PipelineLayout>,
        entry: &str,
        constants: &[(&str, f64)],
    ) -> Result<wgpu::ComputePipeline, GpuError> {
        let (device, module, layout, name) = (self.device.clone(), module.clone(), layout.cloned(), entry.to_string());
        let constants: Vec<(String, f64)> = constants.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        let cache = self.pipeline_cache.as_ref().map(|c| c.cache.clone());
        let delay = creation_delay();
        self.bounded(&format!("pipeline creation of {entry} (the driver compiling the shader)"), move || {
            std::thread::sleep(delay);
            let constants: Vec<(&str, f64)> = constants.iter().map(|(k, v)| (k.as_str(), *v)).collect();
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(&name),
                layout: layout.as_ref(),
                module: &module,
                entry_point: Some(&name),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
                cache: cache.as_ref(),
            })
        })
    }

    /// Runs `create` (wgpu's parse of a shader module, the driver's compilation of a pipeline:
    /// a pathological shader can keep a driver compiling for minutes, outside any wait on the
    /// device) on a thread of its own with a [`super::stack::BIG_STACK`] stack, and waits for it
    /// in slices of [`SLICE`] against the [`Bounds`]: past the deadline, or at a stop, it fails
    /// with [`GpuError::TimedOut`] or [`GpuError::Stopped`] naming `what`, and the device is
    /// abandoned with the thread still in the driver. Nothing joins that thread, so the process
    /// can report and exit while it runs.
    fn bounded<T: Send + 'static>(&self, what: &str, create: impl FnOnce() -> T + Send + 'static) -> Result<T, GpuError> {
        self.bound_passed()?;
        *self.bounds.pass.lock().unwrap() = what.to_string();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::Builder::new()
            .name("lobes-pipeline".into())
            .stack_size(super::stack::BIG_STACK)
            .spawn(move || {
                let _ = tx.send(create());
            })
            .map_err(|e| GpuError::Lost(format!("cannot start a thread to create {what} on: {e}")))?;
        loop {
            match rx.recv_timeout(SLICE) {
                Ok(made) => return Ok(made),
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    if let Err(e) = self.bound_passed() {
                        self.bounds.abandoned.lock().unwrap().get_or_insert_with(|| e.to_string());
                        return Err(e);
                    }
                }
                // the thread panicked (wgpu panics on a validation error it cannot return)
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => return Err(GpuError::Lost(format!("{what} panicked"))),
            }
        }
    }

    /// A buffer of at least `size` bytes (16 at the least), not mapped.
    pub fn buffer(&self, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size: size.max(16), usage, mapped_at_creation: false })
    }

    /// Workgroup grid for `groups` workgroups within the per-dimension limit.
    pub fn grid(&self, groups: u64) -> (u32, u32) {
        let max = self.limits.max_compute_workgroups_per_dimension as u64;
        let x = groups.clamp(1, max);
        (x as u32, groups.div_ceil(x).max(1) as u32)
    }

    /// Encodes `passes` into one submission, each timed by timestamp queries where the adapter
    /// has them, submits it and waits for it: the passes' GPU seconds where timed.
    pub fn dispatch(&self, passes: &[Pass]) -> Result<Option<f64>, GpuError> {
        let n = 2 * passes.len() as u32;
        let queries = (self.has_timestamps() && n > 0).then(|| {
            let set = self.device.create_query_set(&wgpu::QuerySetDescriptor { label: Some("timestamps"), ty: wgpu::QueryType::Timestamp, count: n });
            let resolve = self.buffer("timestamps", n as u64 * 8, wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC);
            let read = self.buffer("timestamps read", n as u64 * 8, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
            (set, resolve, read)
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        for (i, p) in passes.iter().enumerate() {
            let timestamp_writes = queries.as_ref().map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(2 * i as u32),
                end_of_pass_write_index: Some(2 * i as u32 + 1),
            });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(p.label), timestamp_writes });
            pass.set_bind_group(0, p.bind, p.offset.as_slice());
            if let Some(g) = p.group1 {
                pass.set_bind_group(1, g, &[]);
            }
            for step in &p.steps {
                pass.set_pipeline(step.pipeline);
                let (x, y) = self.grid(step.groups);
                pass.dispatch_workgroups(x, y, 1);
            }
        }
        if let Some((set, resolve, read)) = &queries {
            encoder.resolve_query_set(set, 0..n, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, read, 0, n as u64 * 8);
        }
        let label = passes.iter().map(|p| p.label).collect::<Vec<_>>().join(", ");
        self.submit(&label, [encoder.finish()])?;
        let ticks = match &queries {
            Some((_, _, read)) => {
                let stamps: Vec<u64> = bytemuck::cast_slice(&self.read(read, n as u64 * 8)?).to_vec();
                stamps.chunks(2).map(|p| p[1].saturating_sub(p[0])).sum()
            }
            None => {
                self.wait()?;
                0
            }
        };
        self.check_errors()?;
        Ok(self.has_timestamps().then(|| ticks as f64 * self.queue.get_timestamp_period() as f64 * 1e-9))
    }

    /// Bounds the device's work by `timeout` from now, until the guard drops: a wait still
    /// unfinished then fails with [`GpuError::TimedOut`] and abandons the device ([`Bounds`](super::context::Bounds)).
    pub fn deadline(&self, timeout: Duration) -> Bound<'_> {
        *self.bounds.deadline.lock().unwrap() = Some((Instant::now() + timeout, timeout));
        Bound { gpu: self, deadline: true }
    }

    /// Stops the device's work once `stop` says so (polled), until the guard drops: submitting
    /// or waiting then fails with [`GpuError::Stopped`] (a wait abandons the device).
    pub fn stop_when(&self, stop: fn() -> bool) -> Bound<'_> {
        *self.bounds.stop.lock().unwrap() = Some(stop);
        Bound { gpu: self, deadline: false }
    }

    /// Why the device was abandoned (a wait timed out or was stopped), if it was.
    pub fn abandoned(&self) -> Option<String> {
        self.bounds.abandoned.lock().unwrap().clone()
    }

    /// The bound that has been passed, if any: the device abandoned, a stop asked for, the
    /// deadline gone by.
    fn bound_passed(&self) -> Result<(), GpuError> {
        let b = &self.bounds;
        if let Some(why) = b.abandoned.lock().unwrap().clone() {
            return Err(GpuError::Abandoned(why));
        }
        let pass = || b.pass.lock().unwrap().clone();
        if b.stop.lock().unwrap().is_some_and(|stop| stop()) {
            return Err(GpuError::Stopped(pass()));
        }
        match *b.deadline.lock().unwrap() {
            Some((at, given)) if Instant::now() >= at => Err(GpuError::TimedOut { seconds: given.as_secs_f64(), pass: pass() }),
            _ => Ok(()),
        }
    }

    /// Submits `buffers` unless a bound has been passed; `pass` names the work in messages.
    fn submit(&self, pass: &str, buffers: impl IntoIterator<Item = wgpu::CommandBuffer>) -> Result<(), GpuError> {
        self.bound_passed()?;
        *self.bounds.pass.lock().unwrap() = pass.to_string();
        self.queue.submit(buffers);
        Ok(())
    }

    /// Zeroes `buffer` on the device.
    pub fn clear(&self, buffer: &wgpu::Buffer) {
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(buffer, 0, None);
        self.queue.submit([encoder.finish()]);
    }

    /// Waits for the work submitted, in slices of [`SLICE`]: a bound passed in between gives
    /// up the wait and abandons the device ([`Bounds`]).
    fn wait(&self) -> Result<(), GpuError> {
        loop {
            match self.device.poll(wgpu::PollType::Wait { submission_index: None, timeout: Some(SLICE) }) {
                Ok(_) => return Ok(()),
                Err(wgpu::PollError::Timeout) => {
                    if let Err(e) = self.bound_passed() {
                        self.bounds.abandoned.lock().unwrap().get_or_insert_with(|| e.to_string());
                        return Err(e);
                    }
                }
                Err(e) => return Err(GpuError::Lost(e.to_string())),
            }
        }
    }

    /// Copies the first `size` bytes of `src` to the host.
    pub fn read(&self, src: &wgpu::Buffer, size: u64) -> Result<Vec<u8>, GpuError> {
        let staging = if src.usage().contains(wgpu::BufferUsages::MAP_READ) {
            src.clone()
        } else {
            let staging = self.buffer("readback", size, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
            let mut encoder = self.device.create_command_encoder(&Default::default());
            encoder.copy_buffer_to_buffer(src, 0, &staging, 0, size);
            self.bound_passed()?;
            self.queue.submit([encoder.finish()]);
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

    /// Reads back `words` 64-bit totals stored as (lo, hi) u32 pairs.
    pub fn read_u64(&self, src: &wgpu::Buffer, words: u64) -> Result<Vec<u64>, GpuError> {
        let raw: Vec<u32> = bytemuck::cast_slice(&self.read(src, words * 8)?).to_vec();
        Ok(raw.chunks(2).map(|p| p[0] as u64 | (p[1] as u64) << 32).collect())
    }
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

/// A sampling pass over a range of samples cut into chunks, one compute pass each, every
/// chunk reading its own [`Params`] at its own offset of one uniform buffer.
pub struct SamplingPasses<'g> {
    gpu: &'g Gpu,
    params: wgpu::Buffer,
    stride: u64,
    chunk: u64,
    per_submit: u64,
}

impl<'g> SamplingPasses<'g> {
    pub fn new(gpu: &'g Gpu, chunking: Chunking) -> Self {
        let per_group = (WG_SIZE * SAMPLES_PER_THREAD) as u64;
        let dim = gpu.limits.max_compute_workgroups_per_dimension as u64;
        let chunk = chunking.chunk_samples.clamp(1, (1 << 31).min(dim * dim * per_group));
        let per_submit = chunking.chunks_per_submit.max(1) as u64;
        // a dynamic offset is a multiple of the adapter's alignment
        let stride = (std::mem::size_of::<Params>() as u64).next_multiple_of(gpu.limits.min_uniform_buffer_offset_alignment as u64);
        let params = gpu.buffer("params", stride * per_submit, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        Self { gpu, params, stride, chunk, per_submit }
    }

    /// The uniform buffer to bind at `binding::PARAMS` ([`Params::bind_entry`]).
    pub fn params(&self) -> &wgpu::Buffer {
        &self.params
    }

    /// Runs `steps` once per chunk of `range` with `bind` and the chunk's `params`; `progress`
    /// is called with the samples done after each submission. The GPU seconds where timed.
    pub fn run<'a>(
        &self,
        range: SampleRange,
        bind: &'a wgpu::BindGroup,
        params: impl Fn(SampleRange) -> Params,
        steps: impl Fn(SampleRange) -> Vec<Step<'a>>,
        progress: &mut dyn FnMut(u64),
    ) -> Result<Option<f64>, GpuError> {
        let mut seconds = self.gpu.has_timestamps().then_some(0.0);
        let mut chunks = range.chunks(self.chunk).peekable();
        while chunks.peek().is_some() {
            let group: Vec<SampleRange> = chunks.by_ref().take(self.per_submit as usize).collect();
            let passes: Vec<Pass> = group
                .iter()
                .enumerate()
                .map(|(c, &chunk)| {
                    let offset = c as u64 * self.stride;
                    self.gpu.queue.write_buffer(&self.params, offset, bytemuck::bytes_of(&params(chunk)));
                    Pass { label: "sample", bind, offset: Some(offset as u32), steps: steps(chunk), group1: None }
                })
                .collect();
            let t = self.gpu.dispatch(&passes)?;
            seconds = seconds.zip(t).map(|(a, b)| a + b);
            let last = group.last().expect("a submission has chunks");
            progress(last.first + last.count - range.first);
        }
        Ok(seconds)
    }
}
