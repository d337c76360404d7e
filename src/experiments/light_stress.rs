//! The light samplers' hard cases (`lobes stress`, tests/stress.rs): every light of
//! [`LIGHTS`] at 10⁻⁶ sr, on the horizon and near its largest size, and the degenerate shapes —
//! a sliver triangle of near-zero and of zero area, a rectangle and a disk seen edge-on and
//! nearly so, a shading point inside the sphere and on its surface — drawn at the stress
//! uniforms ([`super::stress::uniforms`]: 0, 1 and their neighbours) on the GPU in f32 (the
//! library's WGSL in a small kernel, [`light_draws`]) and on the CPU in f64 (the twins).
//!
//! Per sample: no NaN or infinity in d or the pdf, no negative pdf, d a unit vector where the
//! pdf is positive; a non-degenerate light's every sample valid; and the pdf function at the
//! drawn d equals the pdf the sampler reported (relative 10⁻³) for all but [`EDGE_SHARE`] of its
//! interior samples (the 64 drawn from the RNG: the stress uniforms at and next to 0 and 1 draw
//! the light's very edge, where f32 rounds either way).

use super::stress::{UNIT_BOUND_F32, UNIT_BOUND_F64, uniforms};
use crate::engine::gpu::Gpu;
use crate::engine::gpu::GpuError;
use crate::engine::gpu::library;
use crate::engine::gpu::precision::Precision;
use crate::reference::light::registry::{LIGHTS, LightParams, LightSpec, by_name};
use glam::DVec3;
use serde::Serialize;
use wgpu::util::DeviceExt;

/// The share of a non-degenerate light's interior samples whose pdf function may disagree with
/// the reported pdf (a sample next to the light's edge, where f32 rounds either way).
pub const EDGE_SHARE: f64 = 0.05;

/// A hard configuration of one light.
#[derive(Debug, Clone)]
pub struct LightCase {
    pub name: String,
    pub light: &'static LightSpec,
    pub params: LightParams,
    /// Of zero or near-zero solid angle: only finiteness and signs are asserted.
    pub degenerate: bool,
}

/// One row of the light stress table.
#[derive(Debug, Clone, Serialize)]
pub struct LightRow {
    pub case: String,
    pub kernel: String,
    pub samples: usize,
    /// Samples with a positive pdf.
    pub valid: usize,
    /// Samples with a NaN or ∞ in d or the pdf, or a negative pdf.
    pub bad_values: usize,
    /// Worst |‖d‖ − 1| over the valid samples.
    pub worst_unit_error: f64,
    /// Interior samples (u drawn from the RNG) with a positive pdf whose pdf function at d differs
    /// from it by more than 10⁻³, of `interior`.
    pub inconsistent: usize,
    pub interior: usize,
    pub passed: bool,
}

fn light(name: &str) -> &'static LightSpec {
    by_name(name).expect("a light of the registry")
}

fn pack(vs: &[DVec3], scalars: &[(usize, f64)]) -> LightParams {
    let mut p = [0.0; 16];
    for (k, v) in vs.iter().enumerate() {
        p[4 * k..4 * k + 3].copy_from_slice(&v.to_array());
    }
    for &(i, x) in scalars {
        p[i] = x;
    }
    p
}

/// The degenerate shapes (see the module doc).
fn degenerate_cases() -> Vec<LightCase> {
    let (a, b) = (DVec3::new(0.3, 0.2, 1.0), DVec3::new(-0.4, 0.1, 1.2));
    let sliver = pack(&[a, b, a + 0.5 * (b - a) + DVec3::new(0.0, 0.0, 1e-7)], &[]);
    let flat = pack(&[a, b, a + 0.5 * (b - a)], &[]);
    let edge_on_rect = pack(&[DVec3::new(1.0, -0.5, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)], &[]);
    let near_edge_on_rect = pack(&[DVec3::new(1.0, -0.5, 1e-6), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)], &[]);
    let edge_on_disk = pack(&[DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 0.0, 1.0)], &[(3, 0.2)]);
    let mut v = Vec::new();
    for (name, tri) in [("sliver", sliver), ("collinear", flat)] {
        for l in ["triangle", "triangle-area"] {
            v.push(LightCase { name: format!("{l}-{name}"), light: light(l), params: tri, degenerate: true });
        }
    }
    v.push(LightCase { name: "rect-edge-on".into(), light: light("rect"), params: edge_on_rect, degenerate: true });
    v.push(LightCase { name: "rect-nearly-edge-on".into(), light: light("rect"), params: near_edge_on_rect, degenerate: true });
    v.push(LightCase { name: "disk-edge-on".into(), light: light("disk"), params: edge_on_disk, degenerate: true });
    v.push(LightCase { name: "sphere-inside".into(), light: light("sphere"), params: pack(&[DVec3::new(0.1, 0.0, 0.2)], &[(3, 1.0)]), degenerate: false });
    v.push(LightCase { name: "sphere-touching".into(), light: light("sphere"), params: pack(&[DVec3::new(0.0, 0.6, 0.8)], &[(3, 1.0 - 1e-7)]), degenerate: false });
    v
}

/// Every light at 10⁻⁶ sr (45° up), 10⁻² sr on the horizon and 0.95 of its largest size
/// overhead, then the degenerate shapes.
pub fn light_cases() -> Vec<LightCase> {
    let mut v = Vec::new();
    for l in &LIGHTS {
        for (tag, omega, elevation) in [("1e-6sr", 1e-6, 45.0), ("horizon", 1e-2, 0.0), ("largest", 0.95 * l.largest, 90.0)] {
            v.push(LightCase { name: format!("{}-{tag}", l.name), light: l, params: l.sized(omega, elevation), degenerate: false });
        }
    }
    v.extend(degenerate_cases());
    v
}

const KERNEL: &str = "
struct LightsItem { params: array<vec4<f32>, 4>, u: vec4<f32> }
@group(0) @binding(0) var<storage, read> lights_items: array<LightsItem>;
@group(0) @binding(1) var<storage, read_write> lights_out: array<vec4<f32>>;
@compute @workgroup_size(64)
fn lights_draw(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&lights_items)) { return; }
    let params = lights_items[i].params;
    let u = lights_items[i].u.xy;
    let s = SAMPLE;
    let d = s.d;
    lights_out[2u * i] = vec4<f32>(s.d, s.pdf);
    lights_out[2u * i + 1u] = vec4<f32>(PDF, 0.0, 0.0, 0.0);
}
";

/// The light's WGSL (its library module, f32) at each (params, u) on the GPU: per item
/// [(d, reported pdf), (pdf function at d, 0, 0, 0)].
pub fn light_draws(gpu: &Gpu, spec: &LightSpec, items: &[(LightParams, [f64; 2])]) -> Result<Vec<[[f32; 4]; 2]>, GpuError> {
    let source = library::wgsl(&[spec.module], Precision::F32Accurate)? + &KERNEL.replace("SAMPLE", spec.sample).replace("PDF", spec.pdf);
    let input: Vec<f32> = items.iter().flat_map(|(p, u)| p.iter().copied().chain([u[0], u[1], 0.0, 0.0])).map(|x| x as f32).collect();
    let d = &gpu.device;
    let buffer = d.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some("light items"), contents: bytemuck::cast_slice(&input), usage: wgpu::BufferUsages::STORAGE });
    let size = items.len() as u64 * 32;
    let out = d.create_buffer(&wgpu::BufferDescriptor { label: Some("light draws"), size, usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC, mapped_at_creation: false });
    let read = d.create_buffer(&wgpu::BufferDescriptor { label: None, size, usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST, mapped_at_creation: false });
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(spec.name), source: wgpu::ShaderSource::Wgsl(source.into()) });
    let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor { label: Some("lights_draw"), layout: None, module: &module, entry_point: Some("lights_draw"), compilation_options: Default::default(), cache: None });
    let entries = [wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }, wgpu::BindGroupEntry { binding: 1, resource: out.as_entire_binding() }];
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout: &pipeline.get_bind_group_layout(0), entries: &entries });
    let mut encoder = d.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups((items.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&out, 0, &read, 0, size);
    gpu.queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    read.map_async(wgpu::MapMode::Read, 0..size, move |r| {
        let _ = tx.send(r);
    });
    let _ = d.poll(wgpu::PollType::wait_indefinitely());
    match rx.recv() {
        Ok(Ok(())) => {}
        _ => return Err(GpuError::Readback("the light draws of lobes stress".into())),
    }
    let bytes = read.get_mapped_range(0..size).map(|m| m.to_vec()).unwrap_or_default();
    read.unmap();
    Ok(bytemuck::cast_slice(&bytes).to_vec())
}

/// Judges one sample (d, reported pdf, pdf function at d; u in the interior) into `row`.
fn judge(row: &mut LightRow, (d, pdf, pdf_fn): (DVec3, f64, f64), interior: bool) {
    if !(d.is_finite() && pdf.is_finite() && pdf_fn.is_finite()) || pdf < 0.0 || pdf_fn < 0.0 {
        row.bad_values += 1;
        return;
    }
    if pdf > 0.0 {
        row.valid += 1;
        row.worst_unit_error = row.worst_unit_error.max((d.length() - 1.0).abs());
        if interior {
            row.interior += 1;
            row.inconsistent += usize::from((pdf_fn / pdf - 1.0).abs() > 1e-3);
        }
    }
}

fn verdict(case: &LightCase, mut row: LightRow, unit_bound: f64) -> LightRow {
    let edge = (EDGE_SHARE * row.interior as f64).floor() as usize;
    row.passed = row.bad_values == 0 && row.worst_unit_error <= unit_bound && (case.degenerate || row.inconsistent <= edge) && (case.degenerate || row.valid == row.samples);
    row
}

/// The case's rows: the f64 twin on the CPU, and the WGSL on `gpu` if given.
pub fn run_light_case(case: &LightCase, gpu: Option<&Gpu>) -> Result<Vec<LightRow>, GpuError> {
    let us = uniforms();
    // the last 64 of the stress uniforms are the RNG's, away from 0 and 1
    let interior = |i: usize| i + 64 >= us.len();
    let new = |kernel: &str| LightRow { case: case.name.clone(), kernel: kernel.into(), samples: us.len(), valid: 0, bad_values: 0, worst_unit_error: 0.0, inconsistent: 0, interior: 0, passed: true };
    let mut cpu = new("cpu f64");
    for (i, u) in us.iter().enumerate() {
        let s = (case.light.sample_f64)(&case.params, *u);
        judge(&mut cpu, (s.d, s.pdf, (case.light.pdf_f64)(&case.params, s.d)), interior(i));
    }
    let mut rows = vec![verdict(case, cpu, UNIT_BOUND_F64)];
    if let Some(gpu) = gpu {
        let items: Vec<(LightParams, [f64; 2])> = us.iter().map(|u| (case.params, *u)).collect();
        let mut row = new("gpu f32");
        for (i, [s, f]) in light_draws(gpu, case.light, &items)?.into_iter().enumerate() {
            judge(&mut row, (DVec3::new(s[0] as f64, s[1] as f64, s[2] as f64), s[3] as f64, f[0] as f64), interior(i));
        }
        rows.push(verdict(case, row, UNIT_BOUND_F32));
    }
    Ok(rows)
}

/// Every case of [`light_cases`].
pub fn run_all_lights(gpu: Option<&Gpu>) -> Result<Vec<LightRow>, GpuError> {
    let mut rows = Vec::new();
    for case in light_cases() {
        rows.extend(run_light_case(&case, gpu)?);
    }
    Ok(rows)
}
