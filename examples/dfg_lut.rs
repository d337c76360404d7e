//! The split-sum DFG lookup table for image-based lighting (Karis 2013, "Real Shading in Unreal
//! Engine 4"), computed by a renderer's own compute shader that embeds lobes' GGX sampler.
//!
//! ```sh
//! cargo run --release --example dfg_lut -- [OUT_DIR]      # default OUT_DIR: target/dfg
//! ```
//!
//! For each texel of a 32 × 32 grid, NdotV = (i + ½)/32 (columns) and perceptual roughness
//! r = (j + ½)/32 (rows), with GGX α = r², the shader integrates the GGX specular lobe
//! f = D G2 / (4 NdotV NdotL) (height-correlated Smith G2, no Fresnel) against NdotL, split by
//! Fresnel–Schlick's F = F0 (1 − Fc) + Fc, Fc = (1 − VdotH)⁵, into
//!
//!   A = ∫ f (1 − Fc) NdotL dωl  (the scale of F0),   B = ∫ f Fc NdotL dωl  (the bias),
//!
//! by importance sampling with `ggx_sample_vndf` (visible normals) on 16384 Hammersley points
//! per texel; the estimator is f NdotL / p(ωl) with p(ωl) the sampler's own density. It writes
//!
//! - `dfg.f32`: 32 × 32 × 2 little-endian f32, row-major: the value at byte offset
//!   4 · (2 (32 j + i) + c) is A (c = 0) or B (c = 1) of roughness row j and NdotV column i
//!   (no header; 8192 bytes), for a renderer that uploads it as it is;
//! - `dfg.npy`: the same table as a NumPy array of shape (32, 32, 2), `<f4`
//!   (`numpy.load("dfg.npy")[j, i, c]`; [`lobes::report::npy`]);
//! - `dfg.png`: the same table as an 8-bit RGB image, R = A, G = B, B = 0, row j from the top.
//!
//! It then integrates the same table on the CPU in f64 by numerical quadrature that uses no
//! sampler: over the half vector, in slope space (polar slope angle ψ, tan ψ = tan θh / α, and
//! azimuth φ, where D cos θh dωh = sin ψ cos ψ dψ dφ / π), with the φ-range cut exactly where
//! NdotL = 0, Gauss–Legendre in φ and adaptive Gauss–Legendre in ψ. It prints the largest
//! absolute difference and exits with 1 if it exceeds [`TOLERANCE`] (2 × 10⁻³, under the
//! 1/255 step of the PNG; on lavapipe the difference is about 2 × 10⁻⁴).

use anyhow::Context;
use glam::DVec3;
use lobes::embed::{self, Module};
use lobes::reference::ggx::Ggx;
use lobes::reference::microfacet;
use lobes::stats::gauss_legendre::GaussLegendre;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use wgpu::util::DeviceExt;

/// Texels per side of the table.
pub const SIZE: u32 = 32;
/// Hammersley samples per texel.
pub const SAMPLES: u32 = 1 << 14;
/// The largest allowed |GPU − f64 quadrature| over all texels and both terms.
pub const TOLERANCE: f64 = 2e-3;

/// The renderer's own kernel; everything it calls that it does not define comes from
/// `lobes::embed::wgsl(&[Module::Ggx])`.
const KERNEL: &str = r#"
struct LutParams {
    size: u32,
    samples: u32,
    _pad: vec2<u32>,
}

@group(0) @binding(0) var<uniform> lut: LutParams;
@group(0) @binding(1) var<storage, read_write> dfg_out: array<vec2<f32>>;

// Hammersley point k of n: ((k + 1/2) / n, the base-2 radical inverse of k).
fn hammersley(k: u32, n: u32) -> vec2<f32> {
    return vec2<f32>((f32(k) + 0.5) / f32(n), f32(reverseBits(k)) * 2.3283064365386963e-10);
}

@compute @workgroup_size(64)
fn dfg(@builtin(global_invocation_id) gid: vec3<u32>) {
    let texel = gid.x;
    if (texel >= lut.size * lut.size) {
        return;
    }
    let n_dot_v = (f32(texel % lut.size) + 0.5) / f32(lut.size);
    let roughness = (f32(texel / lut.size) + 0.5) / f32(lut.size);
    let a = vec2<f32>(roughness * roughness);
    let v = vec3<f32>(sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);
    var total = vec2<f32>(0.0);
    var block = vec2<f32>(0.0);
    for (var k = 0u; k < lut.samples; k++) {
        let s = lobes_ggx_sample_vndf(a, v, hammersley(k, lut.samples));
        if (s.wr.z > 0.0 && s.pdf_r > 0.0) {
            // f NdotL / p(l) with f = D G2 / (4 NdotV NdotL): D(h) cancels against the pdf's.
            let w = lobes_ggx_d(a, s.h) * lobes_ggx_g2(a, v, s.wr) / (4.0 * v.z) / s.pdf_r;
            let fc = pow(1.0 - clamp(dot(v, s.h), 0.0, 1.0), 5.0);
            block += w * vec2<f32>(1.0 - fc, fc);
        }
        if ((k & 255u) == 255u) {
            total += block;
            block = vec2<f32>(0.0);
        }
    }
    dfg_out[texel] = (total + block) / f32(lut.samples);
}
"#;

/// The complete WGSL module of the example: lobes' GGX (with its dependencies) + [`KERNEL`].
pub fn shader_source() -> String {
    embed::wgsl(&[Module::Ggx]) + KERNEL
}

/// The table on the GPU: `SIZE²` texels of (A, B), row-major by roughness row.
pub fn dfg_gpu(device: &wgpu::Device, queue: &wgpu::Queue, samples: u32) -> anyhow::Result<Vec<[f32; 2]>> {
    let source = shader_source();
    embed::validate(&source)?;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("dfg"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("dfg"),
        layout: None,
        module: &module,
        entry_point: Some("dfg"),
        compilation_options: Default::default(),
        cache: None,
    });
    let texels = (SIZE * SIZE) as u64;
    let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("dfg params"),
        contents: bytemuck::cast_slice(&[SIZE, samples, 0, 0]),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("dfg out"),
        size: texels * 8,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("dfg read"),
        size: texels * 8,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("dfg"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: out.as_entire_binding() },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups((texels as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&out, 0, &read, 0, texels * 8);
    queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    read.map_async(wgpu::MapMode::Read, 0..texels * 8, move |r| {
        let _ = tx.send(r);
    });
    device.poll(wgpu::PollType::wait_indefinitely())?;
    rx.recv()??;
    let data = read.get_mapped_range(0..texels * 8)?.to_vec();
    read.unmap();
    Ok(bytemuck::cast_slice::<u8, [f32; 2]>(&data).to_vec())
}

fn integrate(rule: &GaussLegendre, a: f64, b: f64, f: &mut impl FnMut(f64) -> [f64; 2]) -> [f64; 2] {
    let mut s = [0.0; 2];
    for (x, w) in rule.on(a, b) {
        let v = f(x);
        s[0] += w * v[0];
        s[1] += w * v[1];
    }
    s
}

fn adaptive(rule: &GaussLegendre, a: f64, b: f64, whole: [f64; 2], depth: u32, f: &mut impl FnMut(f64) -> [f64; 2]) -> [f64; 2] {
    let m = 0.5 * (a + b);
    let (l, r) = (integrate(rule, a, m, f), integrate(rule, m, b, f));
    let halves = [l[0] + r[0], l[1] + r[1]];
    let err = (halves[0] - whole[0]).abs().max((halves[1] - whole[1]).abs());
    if err < 1e-11 || depth == 0 {
        return halves;
    }
    let (x, y) = (adaptive(rule, a, m, l, depth - 1, f), adaptive(rule, m, b, r, depth - 1, f));
    [x[0] + y[0], x[1] + y[1]]
}

/// (A, B) of one texel in f64 by quadrature over the half vector (no sampler involved).
pub fn dfg_f64(n_dot_v: f64, roughness: f64) -> [f64; 2] {
    let alpha = roughness * roughness;
    let ggx = Ggx { ax: alpha, ay: alpha };
    let sin_v = (1.0 - n_dot_v * n_dot_v).sqrt();
    let v = DVec3::new(sin_v, 0.0, n_dot_v);
    let phi_rule = GaussLegendre::new(48);
    let psi_rule = GaussLegendre::new(10);
    // ∫ over ψ of (1/π) sin ψ cos ψ · 2 ∫_0^{φmax} G2 (V·H) / (NdotV NdotH) (1 − Fc, Fc) dφ
    // (the integrand is even in φ); NdotL = 2 (V·H) NdotH − NdotV > 0 ⟺ cos φ > c0.
    let mut inner = |psi: f64| -> [f64; 2] {
        let t = alpha * psi.tan();
        let cos_h = 1.0 / (1.0 + t * t).sqrt();
        let sin_h = t * cos_h;
        let phi_max = if sin_h * sin_v == 0.0 {
            if 2.0 * cos_h * cos_h > 1.0 { std::f64::consts::PI } else { 0.0 }
        } else {
            let c0 = (n_dot_v / (2.0 * cos_h) - n_dot_v * cos_h) / (sin_v * sin_h);
            c0.clamp(-1.0, 1.0).acos()
        };
        if phi_max == 0.0 {
            return [0.0; 2];
        }
        let mut g = |phi: f64| {
            let h = DVec3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
            let v_h = v.dot(h);
            let l = 2.0 * v_h * h - v;
            if l.z <= 0.0 || v_h <= 0.0 {
                return [0.0; 2];
            }
            let w = microfacet::g2(&ggx, v, l) * v_h / (n_dot_v * cos_h);
            let fc = (1.0 - v_h).powi(5);
            [w * (1.0 - fc), w * fc]
        };
        let s = integrate(&phi_rule, 0.0, phi_max, &mut g);
        let k = 2.0 * psi.sin() * psi.cos() / std::f64::consts::PI;
        [k * s[0], k * s[1]]
    };
    let top = std::f64::consts::FRAC_PI_2;
    let whole = integrate(&psi_rule, 0.0, top, &mut inner);
    adaptive(&psi_rule, 0.0, top, whole, 40, &mut inner)
}

/// The whole table in f64, in the layout of [`dfg_gpu`].
pub fn dfg_reference() -> Vec<[f64; 2]> {
    (0..SIZE * SIZE)
        .into_par_iter()
        .map(|texel| {
            let n_dot_v = ((texel % SIZE) as f64 + 0.5) / SIZE as f64;
            let roughness = ((texel / SIZE) as f64 + 0.5) / SIZE as f64;
            dfg_f64(n_dot_v, roughness)
        })
        .collect()
}

/// Writes `dfg.f32`, `dfg.npy` and `dfg.png` into `dir`.
pub fn write_outputs(dir: &Path, lut: &[[f32; 2]]) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let raw: Vec<u8> = lut.iter().flat_map(|t| t.iter().flat_map(|x| x.to_le_bytes())).collect();
    lobes::report::atomic::write_atomic(&dir.join("dfg.f32"), &raw)?;
    let flat: Vec<f32> = lut.iter().flatten().copied().collect();
    let npy = lobes::report::npy::encode(&[SIZE as usize, SIZE as usize, 2], &flat);
    lobes::report::atomic::write_atomic(&dir.join("dfg.npy"), &npy)?;
    let to8 = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    let rgb: Vec<u8> = lut.iter().flat_map(|t| [to8(t[0]), to8(t[1]), 0]).collect();
    let img = image::RgbImage::from_raw(SIZE, SIZE, rgb).expect("SIZE × SIZE RGB texels");
    lobes::report::atomic::write_atomic(&dir.join("dfg.png"), &lobes::report::png::encode(&img)?)?;
    Ok(())
}

/// What a run produced.
pub struct Report {
    pub adapter: String,
    pub lut: Vec<[f32; 2]>,
    pub reference: Vec<[f64; 2]>,
    /// max |GPU − f64| over texels and both terms, and where (texel, term).
    pub max_error: f64,
    pub worst: (usize, usize),
    pub gpu_seconds: f64,
    pub reference_seconds: f64,
}

/// Computes the table on the GPU, writes it to `dir`, and compares it with the f64 quadrature.
pub fn run(dir: &Path) -> anyhow::Result<Report> {
    let gpu = lobes::engine::gpu::Gpu::new()?;
    let t = std::time::Instant::now();
    let lut = dfg_gpu(&gpu.device, &gpu.queue, SAMPLES)?;
    let gpu_seconds = t.elapsed().as_secs_f64();
    write_outputs(dir, &lut)?;
    let t = std::time::Instant::now();
    let reference = dfg_reference();
    let reference_seconds = t.elapsed().as_secs_f64();
    let mut max_error = 0.0f64;
    let mut worst = (0, 0);
    for (texel, (g, r)) in lut.iter().zip(&reference).enumerate() {
        for c in 0..2 {
            let e = (g[c] as f64 - r[c]).abs();
            let e = if e.is_nan() { f64::INFINITY } else { e }; // a NaN texel fails
            if e > max_error {
                max_error = e;
                worst = (texel, c);
            }
        }
    }
    Ok(Report { adapter: gpu.adapter_name(), lut, reference, max_error, worst, gpu_seconds, reference_seconds })
}

#[allow(dead_code)]
fn main() -> std::process::ExitCode {
    let dir = std::env::args_os().nth(1).map_or_else(|| PathBuf::from("target/dfg"), PathBuf::from);
    let report = match run(&dir) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e:#}");
            return std::process::ExitCode::FAILURE;
        }
    };
    let (texel, c) = report.worst;
    println!("adapter: {}", report.adapter);
    println!(
        "DFG table {SIZE}x{SIZE}, {SAMPLES} GGX VNDF samples per texel: GPU {:.3} s; f64 quadrature {:.3} s",
        report.gpu_seconds, report.reference_seconds
    );
    println!(
        "max |GPU - f64| = {:.3e} (tolerance {TOLERANCE:.0e}) at NdotV {:.4}, roughness {:.4}, term {}",
        report.max_error,
        ((texel as u32 % SIZE) as f64 + 0.5) / SIZE as f64,
        ((texel as u32 / SIZE) as f64 + 0.5) / SIZE as f64,
        ["A (scale)", "B (bias)"][c]
    );
    println!("wrote {}, {} and {}", dir.join("dfg.f32").display(), dir.join("dfg.npy").display(), dir.join("dfg.png").display());
    if report.max_error > TOLERANCE {
        eprintln!("error: the GPU table differs from the f64 quadrature by more than {TOLERANCE:.0e}");
        return std::process::ExitCode::FAILURE;
    }
    std::process::ExitCode::SUCCESS
}
