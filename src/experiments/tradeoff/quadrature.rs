//! The expected histogram at fixed resolutions, for `lobes tradeoff`'s quadrature sweep: each
//! bin integrated by an n × n Gauss–Legendre product rule in (cos θ, φ) (the solid-angle
//! element is d cos θ dφ), on the CPU in f64 and on the GPU in f32 (`shaders/passes/quadrature.wgsl`),
//! to set against the adaptive f64 quadrature of [`crate::stats::expected`].

use crate::engine::gpu::dispatch::{Pass, Step};
use crate::engine::gpu::{GpuEngine, GpuError, compose};
use crate::reference::{Lobe, sampler};
use crate::stats::expected::integrate_rect;
use crate::stats::gauss_legendre::GaussLegendre;
use crate::stats::histogram::SphereGrid;
use glam::DVec3;
use rayon::prelude::*;
use std::time::Instant;
use wgpu::util::DeviceExt;


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
                integrate_rect(gl, (zs[r], zs[r + 1]), (ps[c], ps[c + 1]), &|w| pdf(w))
            })
        })
        .collect()
}

/// The composed quadrature kernel for a lobe, grid and rule size: `shaders/passes/quadrature.wgsl`
/// with a generated `lobes::job` of the grid, the rule size and the call site `sampler_pdf` of
/// the lobe's density (from the sampler registry).
pub fn gpu_source(lobe: &Lobe, grid: SphereGrid, n: usize) -> String {
    let spec = sampler::find(lobe.kind, lobe.method);
    compose::quadrature_kernel(spec, grid.rows, grid.cols, n as u32).source()
}

/// `QuadParams` of `shaders/passes/quadrature.wgsl` (`layout_tests::quad_params_layout` checks the layouts agree).
#[repr(C, align(16))]
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
    let gpu = &engine.gpu;
    let module = gpu.module("tradeoff quadrature", &gpu_source(lobe, grid, n))?;
    let pipeline = gpu.pipeline(&module, None, "quadrature", &[])?;
    let params = QuadParams {
        alpha: [lobe.alpha_x as f32, lobe.alpha_y as f32],
        _pad: [0.0; 2],
        wi: [wi.x as f32, wi.y as f32, wi.z as f32, 0.0],
    };
    let nodes: Vec<[f32; 2]> = GaussLegendre::new(n).nodes().iter().map(|&(x, w)| [x as f32, w as f32]).collect();
    let bins = grid.bins() as u64;
    let uniform = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("quadrature params"),
        contents: bytemuck::bytes_of(&params),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let node_buf = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("gauss-legendre nodes"),
        contents: bytemuck::cast_slice(&nodes),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let out = gpu.buffer("probabilities", bins * 4, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
    let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("quadrature"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: node_buf.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: out.as_entire_binding() },
        ],
    });
    let start = Instant::now();
    let steps = vec![Step { pipeline: &pipeline, groups: bins.div_ceil(64) }];
    let gpu_seconds = gpu.dispatch(&[Pass { label: "quadrature", bind: &bind, offset: None, steps, group1: None }])?;
    let probabilities: Vec<f32> = bytemuck::cast_slice(&gpu.read(&out, bins * 4)?).to_vec();
    let wall_seconds = start.elapsed().as_secs_f64();
    Ok(GpuQuadrature { probabilities, gpu_seconds, wall_seconds })
}

#[cfg(test)]
mod layout_tests {
    use super::*;
    use std::mem::{align_of, offset_of, size_of};

    #[test]
    fn quad_params_layout() {
        let lobe = Lobe { kind: crate::reference::LobeKind::Ward, method: crate::reference::Method::Ndf, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 };
        let source = gpu_source(&lobe, SphereGrid { rows: 4, cols: 8 }, 3);
        let members = [("alpha", offset_of!(QuadParams, alpha)), ("_pad", offset_of!(QuadParams, _pad)), ("wi", offset_of!(QuadParams, wi))];
        crate::engine::gpu::layout::check_struct(&source, "QuadParams", size_of::<QuadParams>(), align_of::<QuadParams>(), &members).unwrap();
    }
}
