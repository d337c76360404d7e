//! The stability suite: every sampler driven with the inputs where naive formulas break
//! (near-specular and very rough α, extreme anisotropy, normal, grazing and below-horizon
//! incidence, uniforms at 0 and 1), on the GPU in f32 and on the CPU in f64; and every rough
//! dielectric ([`dielectric_cases`]) at its own hard inputs: the critical angle, η → 1, grazing
//! light from inside and outside, α from 1e-4 to 2, η from 1/2.5 to 2.5, and u.z, which chooses
//! the event, at 0, 1 and next to F.
//!
//! For every sample it asserts: no NaN or infinity in h, ωr or p(ωr); unit directions; a
//! valid sample has a finite positive pdf; an invalid one carries its reason (the one
//! [`Invalid::check_scattered`] gives its direction, event and density); and the GPU agrees
//! with the CPU on validity (away from the horizon, where f32 and f64 may round to opposite
//! sides) and on the direction to within [`DIRECTION_BOUND`]. A dielectric's GPU sample must
//! also choose the event the f64 one chose, unless u.z lies between the two Fresnel
//! reflectances that the f32 and the f64 h give ([`event_tie`]), and its density must be the
//! f64 density to within [`DIELECTRIC_PDF_BOUND`] ([`dielectric_pdf_error`]).

use crate::engine::gpu::GpuEngine;
use crate::engine::job::{Job, Scatter};
use crate::reference::dielectric::{Event, RoughDielectric};
use crate::reference::{Invalid, Lobe, fresnel, reflect, rng, sampler};
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
/// How far the f32 kernels' c = ωi·h may lie from the f64 value of the same f32 vectors: a few
/// ulps of 1 (2⁻²¹ ≈ 4.8e-7), for the rounding of ωi to f32 and of the dot product.
pub const COS_ROUNDING: f64 = 1.0 / 2_097_152.0;
/// The f32 rounding of a Fresnel reflectance evaluated at a given c (2⁻²⁰ ≈ 9.5e-7).
pub const FRESNEL_ROUNDING: f64 = 1.0 / 1_048_576.0;
/// Largest relative difference allowed between a dielectric's GPU density and the f64 density
/// of the GPU's own h and event, away from the critical angle ([`dielectric_pdf_error`]).
pub const DIELECTRIC_PDF_BOUND: f64 = 1e-3;

/// A hard configuration of one sampler.
#[derive(Debug, Clone)]
pub struct StressCase {
    pub name: String,
    pub lobe: Lobe,
    pub incident: DVec3,
    /// A reflection, or a rough dielectric (light from either side, `incident.z < 0` from inside).
    pub scatter: Scatter,
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
    /// Samples with a NaN/∞ in h, ωr or pdf, a valid sample with pdf ≤ 0, or an invalid one
    /// whose reason is not its own.
    pub bad_values: usize,
    /// GPU rows: validity disagreements away from the horizon band, and a dielectric's event
    /// disagreements away from [`event_tie`].
    pub validity_mismatches: usize,
    /// GPU rows: worst angle between the GPU direction and the f64 one (radians).
    pub worst_angle_rad: f64,
    /// GPU rows of a dielectric: worst [`dielectric_pdf_error`], the density's relative error
    /// over its allowance (≤ 1 passes; 0 for reflections).
    pub worst_pdf_error: f64,
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
            worst_pdf_error: 0.0,
            passed: true,
        }
    }
}

pub use crate::reference::SAMPLERS;

/// The hard cases: each sampler at each hard roughness and incidence, then
/// [`dielectric_cases`].
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
        let lobe = |ax, ay| Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 };
        for (an, ax, ay) in alphas {
            out.push(StressCase { name: format!("{label} {an} 45deg"), lobe: lobe(ax, ay), incident: deg(45.0), scatter: Scatter::Reflect });
        }
        for (inn, wi) in incidents {
            out.push(StressCase { name: format!("{label} a0.3 {inn}"), lobe: lobe(0.3, 0.3), incident: wi, scatter: Scatter::Reflect });
        }
    }
    out.extend(dielectric_cases());
    out
}

/// The rough dielectric's hard cases, for each sampler with a dielectric (GGX and Beckmann × NDF
/// and visible normals), named `ggx-vndf glass eta1.5 a0.3 138.2deg` (θi > 90°: from inside):
/// - the critical angle from inside, θc = asin(1/η) for η 1.5, 0.01° on either side (θi 138.2°
///   refracts about the macro normal, 138.18° is past θc), at α 1e-3 (every h near the normal,
///   so the boundary is sharp) and 0.3;
/// - η → 1, where eq. 17's denominator c − η cos θt vanishes: η = 1 ± 1e-6 and 1 ± 1e-3, from
///   outside (45°) and inside (135°);
/// - grazing light from inside (179.9°, 91°, 90.01°) and from outside (89.99°);
/// - α 1e-4, 1e-3, 0.5, 2 and (1e-3, 0.5), and η 1/2.5 and 2.5, each from outside and inside.
///
/// η is taken at its f32 value (the GPU reads it as f32), so that both sides scatter at the same
/// surface: at η = 1 + 1e-6 the f32 rounding moves η − 1 by 4.6 %, which the density's
/// (1 − η²)⁻² would double.
pub fn dielectric_cases() -> Vec<StressCase> {
    let deg = |t: f64| reflect::spherical(t.to_radians(), 0.3);
    let critical = (1.0f64 / 1.5).asin().to_degrees();
    let mut configs: Vec<(String, f64, f64, f64, f64)> = Vec::new(); // (label, αx, αy, η, θi)
    for a in [1e-3, 0.3] {
        for (side, theta) in [("refracts", 180.0 - critical + 0.01), ("past-critical", 180.0 - critical - 0.01)] {
            configs.push((format!("eta1.5 a{a} {theta:.2}deg {side}"), a, a, 1.5, theta));
        }
    }
    for (en, eta) in [("1+1e-6", 1.0 + 1e-6), ("1-1e-6", 1.0 - 1e-6), ("1+1e-3", 1.0 + 1e-3), ("1-1e-3", 1.0 - 1e-3)] {
        for theta in [45.0, 135.0] {
            configs.push((format!("eta{en} a0.3 {theta}deg"), 0.3, 0.3, eta, theta));
        }
    }
    for theta in [179.9, 91.0, 90.01, 89.99] {
        configs.push((format!("eta1.5 a0.3 {theta}deg"), 0.3, 0.3, 1.5, theta));
    }
    for (an, ax, ay) in [("a1e-4", 1e-4, 1e-4), ("a1e-3", 1e-3, 1e-3), ("a0.5", 0.5, 0.5), ("a2", 2.0, 2.0), ("aniso1e-3/0.5", 1e-3, 0.5)] {
        for theta in [45.0, 135.0] {
            configs.push((format!("eta1.5 {an} {theta}deg"), ax, ay, 1.5, theta));
        }
    }
    for (en, eta) in [("1/2.5", 1.0 / 2.5), ("2.5", 2.5)] {
        for theta in [45.0, 135.0] {
            configs.push((format!("eta{en} a0.3 {theta}deg"), 0.3, 0.3, eta, theta));
        }
    }
    let mut out = Vec::new();
    for spec in sampler::REGISTRY.iter().filter(|s| s.wgsl.dielectric.is_some()) {
        for (label, ax, ay, eta, theta) in &configs {
            let lobe = Lobe { kind: spec.kind, method: spec.method, alpha_x: *ax, alpha_y: *ay, alpha_angle: 0.0 };
            let scatter = Scatter::Dielectric { eta: *eta as f32 as f64 };
            out.push(StressCase { name: format!("{} glass {label}", spec.name()), lobe, incident: deg(*theta), scatter });
        }
    }
    out
}

/// The edge values of a uniform: 0, 2⁻²⁴, ½, the largest f32 below 1 (the RNG's largest value)
/// and exactly 1 (callers only).
const EDGES: [f64; 5] = [0.0, 1.0 / 16_777_216.0, 0.5, 1.0 - 1.0 / 16_777_216.0, 1.0];

/// The uniforms tried: every pair of `EDGES` and 64 pairs from the RNG.
pub fn uniforms() -> Vec<[f64; 2]> {
    let mut u: Vec<[f64; 2]> = EDGES.iter().flat_map(|&a| EDGES.iter().map(move |&b| [a, b])).collect();
    u.extend((0..64).map(|i| {
        let r = rng::uniforms(99, i);
        [r[0], r[1]]
    }));
    u
}

/// A dielectric's uniforms: every pair of `EDGES` with u.z at 0, ½, 1 − 2⁻²⁴ and 1; 64 triples
/// from the RNG; and 32 pairs from the RNG with u.z at the event threshold, the f32 value of the
/// f64 F(ωi·h) and its two f32 neighbours (within [0, 1]). Every value is an f32, so the GPU
/// reads the uniforms the CPU uses.
pub fn dielectric_uniforms(glass: &RoughDielectric, wi: DVec3) -> Vec<[f64; 3]> {
    let mut u: Vec<[f64; 3]> = Vec::new();
    for a in EDGES {
        for b in EDGES {
            u.extend([0.0, 0.5, EDGES[3], 1.0].map(|c| [a, b, c]));
        }
    }
    u.extend((0..64).map(|i| {
        let r = rng::uniforms(99, i);
        [r[0], r[1], r[2]]
    }));
    for i in 0..32 {
        let r = rng::uniforms(7, i);
        let f = glass.sample(wi, [r[0], r[1], 0.0]).fresnel as f32;
        u.extend([f.next_down(), f, f.next_up()].into_iter().filter(|z| (0.0..=1.0).contains(z)).map(|z| [r[0], r[1], z as f64]));
    }
    u
}

fn unit_error(v: DVec3) -> f64 {
    (v.length() - 1.0).abs()
}

fn finite(v: DVec3, pdf: f64) -> bool {
    v.is_finite() && pdf.is_finite()
}

/// One sample as the checks see it, drawn in f64 or read back from the GPU.
#[derive(Debug, Clone, Copy)]
struct Drawn {
    h: DVec3,
    /// The scattered direction (ωr for a reflection lobe).
    wo: DVec3,
    pdf: f64,
    invalid: Option<Invalid>,
    /// A reflection (always, for a reflection lobe), else a refraction.
    reflected: bool,
    /// A GPU reason code that names no reason.
    unknown_reason: bool,
    /// A dielectric's microfacet grazing ωi, |ωi·h| < [`COS_ROUNDING`]: at ωi·h = 0, F = 1
    /// reflects ωi through the surface (ωr = −ωi) and T = 0 refracts it with no density, and the
    /// kernel, which reads the event from the signs of ωi·h and ωo·h (`lobe_classify`), may
    /// name the reason of either event for such an invalid sample (Beckmann's visible normals
    /// put h there at u₁ = 1).
    grazing_h: bool,
}

impl Drawn {
    /// Whether a NaN/∞, a valid sample without a finite positive density, or an invalid one
    /// without its own reason: the one [`Invalid::check_scattered`] gives (ωo, event, pdf) seen
    /// from `seen_from` (ωi for a dielectric, +z for a reflection lobe, as [`Invalid::check`]).
    fn bad(&self, seen_from: DVec3) -> bool {
        self.unknown_reason
            || !finite(self.h, 0.0)
            || !finite(self.wo, self.pdf)
            || (self.invalid.is_none() && self.pdf <= 0.0)
            || !(self.grazing_h && self.invalid.is_some()) && self.invalid != Invalid::check_scattered(seen_from, self.wo, self.pdf, self.reflected)
    }
}

/// The rough dielectric of a case, if it is one.
fn glass(case: &StressCase) -> Option<RoughDielectric> {
    match case.scatter {
        Scatter::Reflect => None,
        Scatter::Dielectric { eta } => Some(RoughDielectric::new(case.lobe, eta).expect("a stress case is a valid dielectric")),
    }
}

/// The uniforms of a case, u.z = 0 for a reflection (which does not read it).
fn case_uniforms(case: &StressCase) -> Vec<[f64; 3]> {
    match glass(case) {
        None => uniforms().into_iter().map(|[a, b]| [a, b, 0.0]).collect(),
        Some(g) => dielectric_uniforms(&g, case.incident),
    }
}

/// The f64 sample of `u`: [`Lobe::sample`] for a reflection lobe, or
/// [`RoughDielectric::sample`] with its reason from [`Invalid::check_scattered`].
fn cpu_sample(case: &StressCase, glass: Option<&RoughDielectric>, u: [f64; 3]) -> Drawn {
    match glass {
        None => {
            let s = case.lobe.sample(case.incident, [u[0], u[1]]);
            Drawn { h: s.h, wo: s.omega_r, pdf: s.pdf_r, invalid: s.invalid, reflected: true, unknown_reason: false, grazing_h: false }
        }
        Some(g) => {
            let s = g.sample(case.incident, u);
            let reflected = s.event == Event::Reflection;
            // the sampler's own verdict, with the reason check_scattered gives (an invalid sample
            // that check_scattered finds valid gets one it cannot match, so `bad` counts it)
            let reason = Invalid::check_scattered(case.incident, s.omega_o, s.pdf_o, reflected);
            let invalid = if s.valid { None } else { Some(reason.unwrap_or(Invalid::NonFinitePoint)) };
            Drawn { h: s.h, wo: s.omega_o, pdf: s.pdf_o, invalid, reflected, unknown_reason: false, grazing_h: case.incident.dot(s.h).abs() < COS_ROUNDING }
        }
    }
}

/// A GPU sample of [`GpuEngine::explicit`]. A dielectric's event is the one its reason or side
/// names (a valid sample on ωi's side, or one below the horizon, reflected; a valid one across,
/// or one refracted near side, refracted), else read from h as `lobe_classify`
/// (`shaders/passes/lobe_kernel.wgsl`) reads it: ωr·h keeps the sign of ωi·h, ωt·h turns it.
/// (Read from the f32 h in f64, that sign is a tie at a grazing microfacet, ωi·h ≈ 0, which
/// reflects with F = 1.)
fn gpu_sample(case: &StressCase, g: &[[f32; 4]; 3]) -> Drawn {
    let v = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let (wo, h) = (v(g[0]), v(g[1]));
    let code = g[0][3];
    let invalid = Invalid::ALL.into_iter().find(|r| r.code() as f32 == code);
    let wi = case.incident;
    let reflected = match (case.scatter, invalid) {
        (Scatter::Reflect, _) | (_, Some(Invalid::OutsideDomain)) => true,
        (_, Some(Invalid::RefractedNearSide)) => false,
        (_, None) => wo.z * wi.z > 0.0,
        _ => wi.dot(h) * wo.dot(h) >= 0.0,
    };
    let grazing_h = !matches!(case.scatter, Scatter::Reflect) && wi.dot(h).abs() < COS_ROUNDING;
    Drawn { h, wo, pdf: g[1][3] as f64, invalid, reflected, unknown_reason: code != 0.0 && invalid.is_none(), grazing_h }
}

/// Whether a dielectric's GPU and f64 samples may choose different events: u.z lies between
/// the Fresnel reflectances F(ωi·h) of the GPU's h and of the f64 h, with c widened by
/// [`COS_ROUNDING`] and F by [`FRESNEL_ROUNDING`]. The two h differ by the f32 error of the
/// sampling map (up to ~1e-4 rad at grazing incidence), and near the critical angle F's slope
/// is infinite (F = 1 − O(√(c − cos θc))), so there a rounding of c moves F by ~√ε. F is
/// monotone in c (the unpolarised reflectance grows with the angle of incidence up to total
/// reflection), so its range over the interval of c is that of its ends.
pub fn event_tie(glass: &RoughDielectric, wi: DVec3, h_gpu: DVec3, h_cpu: DVec3, uz: f64) -> bool {
    let (_, eta) = glass.upper_side(wi);
    // ωi·h is the same on the mirrored (upper) side: both are mirrored
    let (cg, cc) = (wi.dot(h_gpu.normalize()), wi.dot(h_cpu));
    let f = |c: f64| fresnel::dielectric(c.clamp(0.0, 1.0), eta);
    let (a, b) = (f(cg.min(cc) - COS_ROUNDING), f(cg.max(cc) + COS_ROUNDING));
    (a.min(b) - FRESNEL_ROUNDING..=a.max(b) + FRESNEL_ROUNDING).contains(&uz)
}

/// A dielectric's GPU density against the f64 density of the same event about the GPU's own h
/// (p(h) F / (4|ωr·h|), or p(h) T times eq. 17, with the f32 h taken as f64): the relative
/// error over its allowance, [`DIELECTRIC_PDF_BOUND`] plus what a rounding δc of c = ωi·h by
/// [`COS_ROUNDING`] does where the density is ill-conditioned in c. At a grazing microfacet
/// (c → 0) a reflection's 1/(4|ωr·h|) = 1/(4c) and a refraction's T ∝ c move by δc/c. Near
/// the critical angle T and eq. 17 are ∝ cos θt, and η² cos²θt = η² − 1 + c² moves by 2c δc: a
/// relative 2c δc / (η² cos²θt), twice. Taking the
/// GPU's h keeps the sampling map's f32 error out (D magnifies it by 1/α at near-specular α),
/// so what is judged is the density's own arithmetic, the refraction Jacobian as η → 1 above
/// all. `None` where the f64 scatter about that h takes the other event (c within rounding of
/// the critical angle) or gives no valid sample.
///
/// From inside, the f32 kernels refract with f32(1/η) (`dielectric_scatter`): at
/// η = f32(1 − 1e-6) it is 6.0e-8 from 1/η, 6 % of 1 − η, and the density's (1 − η²)⁻² moves by
/// 11 %. The kernel samples the surface of that index, and its density is judged as that
/// surface's.
pub fn dielectric_pdf_error(glass: &RoughDielectric, wi: DVec3, h: DVec3, pdf: f64, reflected: bool) -> Option<f64> {
    let inside = wi.z < 0.0;
    let glass = if inside { RoughDielectric { eta: 1.0 / (1.0 / glass.eta as f32) as f64, ..*glass } } else { *glass };
    let h = h.normalize();
    let upper = if inside { DVec3::new(h.x, h.y, -h.z) } else { h };
    let s = glass.scatter(wi, upper, if reflected { 0.0 } else { 1.0 });
    if (s.event == Event::Reflection) != reflected || !s.valid {
        return None;
    }
    let (_, eta) = glass.upper_side(wi);
    let (c, ct) = (wi.dot(s.h), s.omega_o.dot(s.h).abs());
    let critical = if reflected { 0.0 } else { 2.0 * 2.0 * c * COS_ROUNDING / (eta * eta * ct * ct) };
    let allowed = DIELECTRIC_PDF_BOUND + COS_ROUNDING / c + critical;
    Some((pdf - s.pdf_o).abs() / s.pdf_o / allowed)
}

/// Runs one case on the CPU (and on the GPU when an engine is given).
pub fn run_case(case: &StressCase, gpu: Option<&mut GpuEngine>) -> anyhow::Result<Vec<StressRow>> {
    let us = case_uniforms(case);
    let glass = glass(case);
    let wi = case.incident;
    let seen_from = if glass.is_some() { wi } else { DVec3::Z };
    let cpu: Vec<Drawn> = us.iter().map(|&u| cpu_sample(case, glass.as_ref(), u)).collect();
    let mut rows = Vec::new();
    let mut row = StressRow::new(&case.name, "cpu f64", us.len());
    for s in &cpu {
        row.valid += usize::from(s.invalid.is_none());
        row.worst_unit_error = row.worst_unit_error.max(unit_error(s.h)).max(unit_error(s.wo));
        row.bad_values += usize::from(s.bad(seen_from));
    }
    row.passed = row.bad_values == 0 && row.worst_unit_error <= UNIT_BOUND_F64;
    rows.push(row);
    if let Some(engine) = gpu {
        let out = gpu_samples(case, &us, engine)?;
        let mut row = StressRow::new(&case.name, "gpu f32", us.len());
        for ((g, c), u) in out.iter().zip(&cpu).zip(&us) {
            let valid = g.invalid.is_none();
            row.valid += usize::from(valid);
            row.worst_unit_error = row.worst_unit_error.max(unit_error(g.h)).max(unit_error(g.wo));
            row.bad_values += usize::from(g.bad(seen_from));
            let grazing = (g.grazing_h || c.grazing_h) && !valid && c.invalid.is_some();
            if g.reflected != c.reflected {
                let tie = grazing || glass.as_ref().is_some_and(|gl| event_tie(gl, wi, g.h, c.h, u[2]));
                row.validity_mismatches += usize::from(!tie);
            } else if valid != c.invalid.is_none() {
                // ωo on the horizon, or (zero_pdf) ωi or a dielectric's microfacet normal on it,
                // where p(h) = 0 in f64 and the f32 h.z may round to the other side of 0
                let at_horizon = c.wo.z.abs() < HORIZON_BAND
                    || c.invalid == Some(Invalid::ZeroPdf) && (wi.z.abs() < HORIZON_BAND || glass.is_some() && c.h.z.abs() < HORIZON_BAND);
                row.validity_mismatches += usize::from(!at_horizon);
            } else if valid && g.wo.is_finite() {
                row.worst_angle_rad = row.worst_angle_rad.max(angle_between(g.wo.normalize(), c.wo));
                if let Some(e) = glass.as_ref().and_then(|gl| dielectric_pdf_error(gl, wi, g.h, g.pdf, g.reflected)) {
                    row.worst_pdf_error = row.worst_pdf_error.max(e);
                }
            }
        }
        row.passed = row.bad_values == 0
            && row.worst_unit_error <= UNIT_BOUND_F32
            && row.validity_mismatches == 0
            && row.worst_angle_rad <= DIRECTION_BOUND
            && row.worst_pdf_error <= 1.0;
        rows.push(row);
    }
    Ok(rows)
}

/// The GPU's samples of a case for the uniforms `us` (as f32, which every one of them is).
fn gpu_samples(case: &StressCase, us: &[[f64; 3]], engine: &mut GpuEngine) -> anyhow::Result<Vec<Drawn>> {
    let job = Job::Lobe { lobe: case.lobe, incident: case.incident, grid: SphereGrid { rows: 2, cols: 1 }, scatter: case.scatter };
    let u32s: Vec<[f32; 3]> = us.iter().map(|u| u.map(|x| x as f32)).collect();
    Ok(engine.explicit(&job, &u32s)?.iter().map(|g| gpu_sample(case, g)).collect())
}

/// The whole suite.
pub fn run_all(mut gpu: Option<&mut GpuEngine>) -> anyhow::Result<Vec<StressRow>> {
    let mut rows = Vec::new();
    for case in cases() {
        rows.extend(run_case(&case, gpu.as_deref_mut())?);
    }
    Ok(rows)
}

/// Per-sample listing of one case (u, CPU and GPU directions, pdfs, events, validity), for
/// diagnosis.
pub fn details(case: &StressCase, engine: &mut GpuEngine) -> anyhow::Result<String> {
    let us = case_uniforms(case);
    let glass = glass(case);
    let gpu = gpu_samples(case, &us, engine)?;
    let mut t = format!("{}\n", case.name);
    let event = |d: &Drawn| if d.reflected { "r" } else { "t" };
    for (u, g) in us.iter().zip(&gpu) {
        let c = cpu_sample(case, glass.as_ref(), *u);
        let reason = |d: &Drawn| d.invalid.map_or("valid", |r| r.name());
        t += &format!(
            "u=({:.9}, {:.9}, {:.9}) cpu wo=({:+.6e}, {:+.6e}, {:+.6e}) {} pdf={:.4e} {} | gpu wo=({:+.6e}, {:+.6e}, {:+.6e}) {} pdf={:.4e} {}\n",
            u[0], u[1], u[2], c.wo.x, c.wo.y, c.wo.z, event(&c), c.pdf, reason(&c), g.wo.x, g.wo.y, g.wo.z, event(g), g.pdf, reason(g)
        );
    }
    Ok(t)
}
