//! The expected histogram at fixed resolutions, for `lobes tradeoff`'s quadrature sweep: each
//! bin integrated by an n × n Gauss–Legendre product rule in (cos θ, φ) (the solid-angle
//! element is d cos θ dφ), on the CPU in f64 and on the GPU in f32 (`shaders/quadrature.wgsl`),
//! to set against the adaptive f64 quadrature of [`crate::stats::expected`].

use crate::embed::{self, Module};
use crate::engine::gpu::dispatch::{Pass, Step};
use crate::engine::gpu::{GpuEngine, GpuError};
use crate::reference::{Lobe, LobeKind, Method};
use crate::stats::expected::direction;
use crate::stats::histogram::SphereGrid;
use glam::DVec3;
use rayon::prelude::*;
use std::time::Instant;
use wgpu::util::DeviceExt;

pub const QUADRATURE_WGSL: &str = include_str!("../../../shaders/quadrature.wgsl");

/// The n-point Gauss–Legendre nodes and weights on [−1, 1]: the roots of Pₙ by Newton's method
/// from Tricomi's first guess cos(π(i − ¼)/(n + ½)), Pₙ by its three-term recurrence, weights
/// 2 / ((1 − x²) Pₙ'(x)²) (Abramowitz & Stegun 25.4.29; Numerical Recipes §4.5, `gauleg`).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    assert!(n >= 1);
    let mut out = vec![(0.0, 0.0); n];
    for i in 0..n.div_ceil(2) {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 1 { x } else { p1 };
            let pm = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * pn - pm) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out[i] = (-x, w);
        out[n - 1 - i] = (x, w);
    }
    if n % 2 == 1 {
        out[n / 2].0 = 0.0;
    }
    out
}

/// Each bin's probability under the density `pdf` (zero below the horizon) by the n × n
/// Gauss–Legendre rule per bin, in f64, rows in parallel.
pub fn fixed_probabilities(pdf: &(dyn Fn(DVec3) -> f64 + Sync), grid: SphereGrid, n: usize) -> Vec<f64> {
    let nodes = gauss_legendre(n);
    let zs = grid.cos_theta_edges();
    let ps = grid.phi_edges();
    (0..grid.rows as usize)
        .into_par_iter()
        .flat_map_iter(|r| {
            let (zs, ps, nodes) = (&zs, &ps, &nodes);
            (0..grid.cols as usize).map(move |c| {
                let (z0, z1) = (zs[r], zs[r + 1]);
                if z1 <= 0.0 {
                    return 0.0;
                }
                let (p0, p1) = (ps[c], ps[c + 1]);
                let (hz, cz, hp, cp) = (0.5 * (z1 - z0), 0.5 * (z1 + z0), 0.5 * (p1 - p0), 0.5 * (p1 + p0));
                let mut sum = 0.0;
                for &(xi, wi) in nodes {
                    for &(xj, wj) in nodes {
                        sum += wi * wj * pdf(direction(cz + hz * xi, cp + hp * xj));
                    }
                }
                sum * hz * hp
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
    let gpu = &engine.gpu;
    let module = gpu.module("tradeoff quadrature", &gpu_source(lobe, grid, n))?;
    let pipeline = gpu.pipeline(&module, None, "quadrature", &[]);
    let params = QuadParams {
        alpha: [lobe.alpha_x as f32, lobe.alpha_y as f32],
        _pad: [0.0; 2],
        wi: [wi.x as f32, wi.y as f32, wi.z as f32, 0.0],
    };
    let nodes: Vec<[f32; 2]> = gauss_legendre(n).iter().map(|&(x, w)| [x as f32, w as f32]).collect();
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
    let gpu_seconds = gpu.dispatch(&[Pass { label: "quadrature", bind: &bind, offset: None, steps }])?;
    let probabilities: Vec<f32> = bytemuck::cast_slice(&gpu.read(&out, bins * 4)?).to_vec();
    let wall_seconds = start.elapsed().as_secs_f64();
    Ok(GpuQuadrature { probabilities, gpu_seconds, wall_seconds })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_nodes_and_exactness() {
        // A&S 25.4.30, n = 5
        let g = gauss_legendre(5);
        assert!((g[4].0 - 0.906_179_845_938_664).abs() < 1e-15 && (g[4].1 - 0.236_926_885_056_189_1).abs() < 1e-15);
        assert_eq!(g[2].0, 0.0);
        // n points integrate x^(2n-1) and x^(2n-2) exactly on [-1, 1]
        for n in [1, 2, 3, 4, 8, 16] {
            let g = gauss_legendre(n);
            let even: f64 = g.iter().map(|&(x, w)| w * x.powi(2 * n as i32 - 2)).sum();
            let odd: f64 = g.iter().map(|&(x, w)| w * x.powi(2 * n as i32 - 1)).sum();
            assert!((even - 2.0 / (2 * n - 1) as f64).abs() < 1e-14, "n {n}: {even}");
            assert!(odd.abs() < 1e-14);
        }
    }
}
