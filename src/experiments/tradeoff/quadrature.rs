//! The expected histogram at fixed resolutions, for `lobes tradeoff`'s quadrature sweep: each
//! bin integrated by an n × n Gauss–Legendre product rule in (cos θ, φ) (the solid-angle
//! element is d cos θ dφ), on the CPU in f64 and on the GPU in f32 (`shaders/quadrature.wgsl`),
//! to set against the adaptive f64 quadrature of [`crate::stats::expected`].

use crate::embed::{self, Module};
use crate::engine::gpu::{GpuEngine, GpuError};
use crate::reference::{Lobe, LobeKind, Method};
use crate::stats::expected::direction;
use crate::stats::gauss_legendre::GaussLegendre;
use crate::stats::histogram::SphereGrid;
use glam::DVec3;
use rayon::prelude::*;
use std::time::Instant;
use wgpu::util::DeviceExt;

pub const QUADRATURE_WGSL: &str = include_str!("../../../shaders/quadrature.wgsl");

/// Each bin's probability under the density `pdf` (zero below the horizon) by the n × n
/// Gauss–Legendre rule per bin, in f64, rows in parallel.
pub fn fixed_probabilities(pdf: &(dyn Fn(DVec3) -> f64 + Sync), grid: SphereGrid, n: usize) -> Vec<f64> {
    let gl = GaussLegendre::new(n);
    let zs = grid.cos_theta_edges();
    let ps = grid.phi_edges();
    (0..grid.rows as usize)
        .into_par_iter()
        .flat_map_iter(|r| {
            let (zs, ps, gl) = (&zs, &ps, &gl);
            (0..grid.cols as usize).map(move |c| {
                if zs[r + 1] <= 0.0 {
                    return 0.0;
                }
                gl.integrate_2d((zs[r], zs[r + 1]), (ps[c], ps[c + 1]), |z, phi| pdf(direction(z, phi)))
            })
        })
        .collect()
}

/// The WGSL density of a lobe in `lobes::embed` and the module that holds it.
pub fn pdf_fn(lobe: &Lobe) -> (Module, &'static str) {
    match (lobe.kind, lobe.method) {
        (LobeKind::Ward, _) => (Module::Ward, "ward_pdf"),
        (LobeKind::Beckmann, Method::Ndf) => (Module::Beckmann, "beckmann_pdf_ndf"),
        (LobeKind::Beckmann, _) => (Module::Beckmann, "beckmann_pdf_vndf"),
        (LobeKind::Ggx, Method::Ndf) => (Module::Ggx, "ggx_pdf_ndf"),
        (LobeKind::Ggx, Method::Vndf) => (Module::Ggx, "ggx_pdf_vndf"),
        (LobeKind::Ggx, Method::Bounded) => (Module::Ggx, "ggx_pdf_bounded"),
    }
}

/// The composed quadrature kernel for a lobe, grid and rule size.
pub fn gpu_source(lobe: &Lobe, grid: SphereGrid, n: usize) -> String {
    let (module, pdf) = pdf_fn(lobe);
    format!(
        "{}\nconst ROWS: u32 = {}u;\nconst COLS: u32 = {}u;\nconst N_NODES: u32 = {n}u;\n{}",
        embed::wgsl(&[module]),
        grid.rows,
        grid.cols,
        QUADRATURE_WGSL.replace("PDF_FN(", &format!("{pdf}("))
    )
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct QuadParams {
    alpha: [f32; 2],
    _pad: [f32; 2],
    wi: [f32; 4],
}

/// A GPU quadrature result.
#[derive(Debug, Clone)]
pub struct GpuQuadrature {
    pub probabilities: Vec<f32>,
    /// The dispatch's GPU time (timestamp queries), where the adapter has them.
    pub gpu_seconds: Option<f64>,
    /// From submission to the end of the readback (excluding the pipeline's compilation).
    pub wall_seconds: f64,
}

/// The n × n Gauss–Legendre probabilities of every bin on the GPU in f32.
pub fn gpu_probabilities(engine: &GpuEngine, lobe: &Lobe, wi: DVec3, grid: SphereGrid, n: usize) -> Result<GpuQuadrature, GpuError> {
    let source = gpu_source(lobe, grid, n);
    crate::engine::gpu::compose::validate("tradeoff quadrature", &source)?;
    let gpu = &engine.gpu;
    let device = &gpu.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("tradeoff quadrature"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("quadrature"),
        layout: None,
        module: &module,
        entry_point: Some("quadrature"),
        compilation_options: Default::default(),
        cache: None,
    });
    let params = QuadParams {
        alpha: [lobe.alpha_x as f32, lobe.alpha_y as f32],
        _pad: [0.0; 2],
        wi: [wi.x as f32, wi.y as f32, wi.z as f32, 0.0],
    };
    let nodes: Vec<[f32; 2]> = GaussLegendre::new(n).nodes().iter().map(|&(x, w)| [x as f32, w as f32]).collect();
    let bins = grid.bins() as u64;
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("quadrature params"),
        contents: bytemuck::bytes_of(&params),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let node_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("gauss-legendre nodes"),
        contents: bytemuck::cast_slice(&nodes),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let out = engine.buffer("probabilities", bins * 4, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("quadrature"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: node_buf.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: out.as_entire_binding() },
        ],
    });
    let stamps = gpu.has_timestamps().then(|| engine.timestamp_buffers(2));
    let groups = bins.div_ceil(64);
    let max = gpu.limits.max_compute_workgroups_per_dimension as u64;
    let (gx, gy) = (groups.min(max) as u32, groups.div_ceil(max) as u32);
    let start = Instant::now();
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let ts = stamps.as_ref().map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("quadrature"), timestamp_writes: ts });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(gx, gy, 1);
    }
    if let Some((set, resolve, rd)) = &stamps {
        encoder.resolve_query_set(set, 0..2, resolve, 0);
        encoder.copy_buffer_to_buffer(resolve, 0, rd, 0, 16);
    }
    gpu.queue.submit([encoder.finish()]);
    let probabilities: Vec<f32> = bytemuck::cast_slice(&engine.read(&out, bins * 4)?).to_vec();
    let wall_seconds = start.elapsed().as_secs_f64();
    let gpu_seconds = match &stamps {
        Some((_, _, rd)) => {
            let t: Vec<u64> = bytemuck::cast_slice(&engine.read(rd, 16)?).to_vec();
            Some(t[1].saturating_sub(t[0]) as f64 * gpu.queue.get_timestamp_period() as f64 * 1e-9)
        }
        None => None,
    };
    Ok(GpuQuadrature { probabilities, gpu_seconds, wall_seconds })
}
