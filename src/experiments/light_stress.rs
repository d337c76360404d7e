//! The light samplers' hard cases (`lobes stress`, tests/stress.rs): every light of
//! [`LIGHTS`] at 10⁻⁶ sr, on the horizon and near its largest size, and the degenerate shapes —
//! a sliver triangle of near-zero and of zero area, a rectangle and a disk seen edge-on and
//! nearly so, a shading point inside the sphere and on its surface — drawn at the stress
//! uniforms ([`super::stress::uniforms`]: 0, 1 and their neighbours) on the GPU in f32 (the
//! library's WGSL through `lobes check`'s passes, [`LightPasses`]) and on the CPU in f64 (the
//! twins).
//!
//! Per sample: no NaN or infinity in d or the pdf, no negative pdf, d a unit vector where the
//! pdf is positive; a non-degenerate light's every sample valid; and the pdf function at the
//! drawn d equals the pdf the sampler reported (relative 10⁻³) for all but [`EDGE_SHARE`] of its
//! interior samples (the 64 drawn from the RNG: the stress uniforms at and next to 0 and 1 draw
//! the light's very edge, where f32 rounds either way).

use super::stress::{UNIT_BOUND_F32, UNIT_BOUND_F64, uniforms};
use crate::check::CheckError;
use crate::check::light::LightPasses;
use crate::engine::gpu::Gpu;
use crate::reference::light::registry::{LIGHTS, LightParams, LightSpec, by_name};
use glam::DVec3;
use serde::Serialize;

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

/// The case's rows: the f64 twin on the CPU, and the WGSL through `passes` (of `case.light`) if
/// given.
pub fn run_light_case(case: &LightCase, passes: Option<&LightPasses>) -> Result<Vec<LightRow>, CheckError> {
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
    if let Some(passes) = passes {
        let mut row = new("gpu f32");
        for (i, s) in passes.draws(&case.params, &us)?.into_iter().enumerate() {
            judge(&mut row, (s.d, s.pdf, s.pdf_at_d), interior(i));
        }
        rows.push(verdict(case, row, UNIT_BOUND_F32));
    }
    Ok(rows)
}

/// Every case of [`light_cases`].
pub fn run_all_lights(gpu: Option<&Gpu>) -> Result<Vec<LightRow>, CheckError> {
    // each light's passes composed once, for all of its cases
    let passes = gpu.map(|gpu| LIGHTS.iter().map(|l| Ok((l.name, LightPasses::new(gpu, l)?))).collect::<Result<Vec<_>, CheckError>>()).transpose()?;
    let mut rows = Vec::new();
    for case in light_cases() {
        let of_light = passes.as_ref().and_then(|p| p.iter().find(|(name, _)| *name == case.light.name)).map(|(_, p)| p);
        rows.extend(run_light_case(&case, of_light)?);
    }
    Ok(rows)
}
