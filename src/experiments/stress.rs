//! The stability suite: every sampler driven with the inputs where naive formulas break
//! (near-specular and very rough α, extreme anisotropy, normal, grazing and below-horizon
//! incidence, uniforms at 0 and 1), on the GPU in f32 and on the CPU in f64.
//!
//! For every sample it asserts: no NaN or infinity in h, ωr or p(ωr); unit directions; a
//! valid sample has a finite positive pdf; an invalid one carries its reason; and the GPU
//! agrees with the CPU on validity (away from the horizon, where f32 and f64 may round to
//! opposite sides) and on the direction to within [`DIRECTION_BOUND`].

use crate::engine::gpu::GpuEngine;
use crate::engine::job::{Job, Scatter};
use crate::reference::{Invalid, Lobe, reflect, rng};
use crate::run::compare::angle_between;
use crate::stats::histogram::SphereGrid;
use glam::DVec3;
use serde::Serialize;

/// Largest angle allowed between a GPU f32 direction and its f64 twin, in radians.
pub const DIRECTION_BOUND: f64 = 1e-3;
/// Largest |‖v‖ − 1| allowed for an f32 unit vector (a few ulps of 1: 2⁻²⁴ ≈ 6e-8 each).
pub const UNIT_BOUND_F32: f64 = 1e-6;
/// The same for f64.
pub const UNIT_BOUND_F64: f64 = 1e-14;
/// Below this |ωr.z| a validity disagreement is a rounding tie at the horizon, not an error.
pub const HORIZON_BAND: f64 = 1e-5;

/// A hard configuration of one sampler.
#[derive(Debug, Clone)]
pub struct StressCase {
    pub name: String,
    pub lobe: Lobe,
    pub incident: DVec3,
}

/// One row of the stress table.
#[derive(Debug, Clone, Serialize)]
pub struct StressRow {
    pub case: String,
    pub kernel: String,
    pub samples: usize,
    pub valid: usize,
    /// Worst |‖v‖ − 1| over h and ωr.
    pub worst_unit_error: f64,
    /// Samples with a NaN/∞ in h, ωr or pdf, or a valid sample with pdf ≤ 0.
    pub bad_values: usize,
    /// GPU rows: validity disagreements away from the horizon band.
    pub validity_mismatches: usize,
    /// GPU rows: worst angle between the GPU direction and the f64 one (radians).
    pub worst_angle_rad: f64,
    pub passed: bool,
}

impl StressRow {
    fn new(case: &str, kernel: &str, samples: usize) -> Self {
        StressRow {
            case: case.into(),
            kernel: kernel.into(),
            samples,
            valid: 0,
            worst_unit_error: 0.0,
            bad_values: 0,
            validity_mismatches: 0,
            worst_angle_rad: 0.0,
            passed: true,
        }
    }
}

pub use crate::reference::SAMPLERS;

/// The hard cases: each sampler at each hard roughness and incidence.
pub fn cases() -> Vec<StressCase> {
    let deg = |t: f64| reflect::spherical(t.to_radians(), 0.3);
    let alphas: [(&str, f64, f64); 7] = [
        ("a1e-6", 1e-6, 1e-6),
        ("a1e-4", 1e-4, 1e-4),
        ("a1e-3", 1e-3, 1e-3),
        ("a1", 1.0, 1.0),
        ("a10", 10.0, 10.0),
        ("aniso1000", 1e-3, 1.0),
        ("aniso1/1000", 1.0, 1e-3),
    ];
    let incidents: [(&str, DVec3); 6] = [
        ("normal", DVec3::Z),
        ("89.9deg", deg(89.9)),
        ("89.999deg", deg(89.999)),
        ("90deg", DVec3::new(0.3f64.cos(), 0.3f64.sin(), 0.0)),
        ("below", deg(100.0)),
        ("45deg", deg(45.0)),
    ];
    let mut out = Vec::new();
    for (kind, method) in SAMPLERS {
        let label = format!("{}-{}", kind.name(), method.name());
        for (an, ax, ay) in alphas {
            out.push(StressCase { name: format!("{label} {an} 45deg"), lobe: Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 }, incident: deg(45.0) });
        }
        for (inn, wi) in incidents {
            out.push(StressCase { name: format!("{label} a0.3 {inn}"), lobe: Lobe { kind, method, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 }, incident: wi });
        }
    }
    out
}

/// The uniforms tried: every pair of the edge values (0, 2⁻²⁴, 0.5, the largest f32 below 1,
/// exactly 1) and 64 pairs from the RNG.
pub fn uniforms() -> Vec<[f64; 2]> {
    let edges = [0.0, 1.0 / 16_777_216.0, 0.5, 1.0 - 1.0 / 16_777_216.0, 1.0];
    let mut u: Vec<[f64; 2]> = edges.iter().flat_map(|&a| edges.iter().map(move |&b| [a, b])).collect();
    u.extend((0..64).map(|i| {
        let r = rng::uniforms(99, i);
        [r[0], r[1]]
    }));
    u
}

fn unit_error(v: DVec3) -> f64 {
    (v.length() - 1.0).abs()
}

fn finite(v: DVec3, pdf: f64) -> bool {
    v.is_finite() && pdf.is_finite()
}

/// Runs one case on the CPU (and on the GPU when an engine is given).
pub fn run_case(case: &StressCase, gpu: Option<&mut GpuEngine>) -> anyhow::Result<Vec<StressRow>> {
    let us = uniforms();
    let cpu: Vec<_> = us.iter().map(|&u| case.lobe.sample(case.incident, u)).collect();
    let mut rows = Vec::new();
    let mut row = StressRow::new(&case.name, "cpu f64", us.len());
    for s in &cpu {
        row.valid += usize::from(s.invalid.is_none());
        row.worst_unit_error = row.worst_unit_error.max(unit_error(s.h)).max(unit_error(s.omega_r));
        let bad = !finite(s.h, 0.0) || !finite(s.omega_r, s.pdf_r) || (s.invalid.is_none() && s.pdf_r <= 0.0);
        row.bad_values += usize::from(bad);
    }
    row.passed = row.bad_values == 0 && row.worst_unit_error <= UNIT_BOUND_F64;
    rows.push(row);
    if let Some(engine) = gpu {
        let job = Job::Lobe { lobe: case.lobe, incident: case.incident, grid: SphereGrid { rows: 2, cols: 1 }, scatter: Scatter::Reflect };
        let u32s: Vec<[f32; 3]> = us.iter().map(|u| [u[0] as f32, u[1] as f32, 0.0]).collect();
        let out = engine.explicit(&job, &u32s)?;
        let mut row = StressRow::new(&case.name, "gpu f32", us.len());
        for (g, c) in out.iter().zip(&cpu) {
            let wr = DVec3::new(g[0][0] as f64, g[0][1] as f64, g[0][2] as f64);
            let h = DVec3::new(g[1][0] as f64, g[1][1] as f64, g[1][2] as f64);
            let pdf = g[1][3] as f64;
            let valid = g[0][3] == 0.0;
            row.valid += usize::from(valid);
            row.worst_unit_error = row.worst_unit_error.max(unit_error(h)).max(unit_error(wr));
            row.bad_values += usize::from(!finite(h, 0.0) || !finite(wr, pdf) || (valid && pdf <= 0.0));
            if valid != c.invalid.is_none() {
                let at_horizon = c.omega_r.z.abs() < HORIZON_BAND || c.invalid == Some(Invalid::ZeroPdf) && case.incident.z.abs() < HORIZON_BAND;
                row.validity_mismatches += usize::from(!at_horizon);
            } else if valid && wr.is_finite() {
                row.worst_angle_rad = row.worst_angle_rad.max(angle_between(wr.normalize(), c.omega_r));
            }
        }
        row.passed = row.bad_values == 0
            && row.worst_unit_error <= UNIT_BOUND_F32
            && row.validity_mismatches == 0
            && row.worst_angle_rad <= DIRECTION_BOUND;
        rows.push(row);
    }
    Ok(rows)
}

/// The whole suite.
pub fn run_all(mut gpu: Option<&mut GpuEngine>) -> anyhow::Result<Vec<StressRow>> {
    let mut rows = Vec::new();
    for case in cases() {
        rows.extend(run_case(&case, gpu.as_deref_mut())?);
    }
    Ok(rows)
}

/// Per-sample listing of one case (u, CPU and GPU ωr, validity, pdf), for diagnosis.
pub fn details(case: &StressCase, engine: &mut GpuEngine) -> anyhow::Result<String> {
    let us = uniforms();
    let job = Job::Lobe { lobe: case.lobe, incident: case.incident, grid: SphereGrid { rows: 2, cols: 1 }, scatter: Scatter::Reflect };
    let u32s: Vec<[f32; 3]> = us.iter().map(|u| [u[0] as f32, u[1] as f32, 0.0]).collect();
    let out = engine.explicit(&job, &u32s)?;
    let mut t = format!("{}\n", case.name);
    for ((u, g), c) in us.iter().zip(&out).zip(us.iter().map(|&u| case.lobe.sample(case.incident, u))) {
        let cpu_reason = c.invalid.map_or("valid", |r| r.name());
        let gpu_reason = match g[0][3] as u32 {
            0 => "valid",
            k => Invalid::ALL[k as usize - 1].name(),
        };
        t += &format!(
            "u=({:.9}, {:.9}) cpu wr=({:+.6e}, {:+.6e}, {:+.6e}) pdf={:.4e} {cpu_reason} | gpu wr=({:+.6e}, {:+.6e}, {:+.6e}) pdf={:.4e} {gpu_reason}\n",
            u[0], u[1], c.omega_r.x, c.omega_r.y, c.omega_r.z, c.pdf_r, g[0][0], g[0][1], g[0][2], g[1][3]
        );
    }
    Ok(t)
}
