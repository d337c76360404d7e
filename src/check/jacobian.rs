//! The pdf against the Jacobian of the sample map, sample by sample.
//!
//! A sampler maps u ∈ [0, 1]² to a point d; where the map is smooth and one-to-one its density is
//! p(d) = 1 / |J(u)|, with |J| = |∂d/∂u₁ × ∂d/∂u₂| on the sphere (the area of the image of a unit
//! square of u, per unit solid angle) and |det ∂(x, y)/∂(u₁, u₂)| on the plane (pbrt-v4 §2.4.1,
//! "transforming between distributions"). The derivatives are central differences of the GPU's
//! map, in f64 on the host, at steps ε · 2ᵏ ([`STEPS`]; the steps below ε measure the map's
//! f32 staircase, [`SUB_STEPS`]): at each step where the map is smooth
//! (the second difference under a tenth of the first: no fold, seam or branch between lobes
//! within it), and at the three consecutive steps that agree best, the first two extrapolated
//! (Richardson) with the larger of their differences as the error. A narrow lobe needs the large steps (over 2ε its d moves
//! by little more than f32 rounding), a curved map the small ones. A sample is skipped where no
//! step is smooth (`skipped_not_smooth`) or where no two steps agree on |J| to [`UNRESOLVED`]
//! (`skipped_unresolved`: d resolved to a few ulps, an f32 staircase), and judged against
//! [`TOLERANCE`] plus what f32 leaves unknown there: twice the error of |J|, and a multiple of
//! the pdf's f32 conditioning at d (`super::CONDITIONING_ULPS`).
//! This catches a missing Jacobian factor (the reflection's 1/(4|ωr·h|), a cos θ) even where a
//! coarse histogram cannot.
//!
//! **Events.** A sampler that chooses an event with u.z (a rough dielectric reflects with
//! probability F(ωi·h), else refracts; a mixture picks a lobe) has at d the density s/|J|, where
//! s(u₁, u₂) is the share of u.z ∈ [0, 1) that makes the same choice (the 3-D map's density
//! integrated over u.z) and J is the chosen event's map. The probe pass measures s on the GPU
//! (`lobes_share` in `shaders/check/user_passes.wgsl`): the share of u.z, at u.x, u.y, u.w fixed,
//! whose sample lands on the same d within 10⁻⁶, by a scan of 256 nodes with each change bisected
//! to f32 resolution; likewise for u.w. s depends on u₁, u₂ only through the event's probability
//! (F(ωi·h)), so it is well defined wherever the map is smooth (where u ± ε crosses into another
//! event d jumps: not smooth). Its error, about 2⁻²³, stays under 10⁻³ of s because a run of u.z
//! landing on d shorter than 2⁻¹² (the step ε) is read as "d moves with u.z"; a share near 1 is
//! 1 minus a small one, bisected where it is small. Only an event narrower than 2⁻⁸ lying wholly
//! between two nodes escapes the scan. Where d moves with u.z or u.w (continuously, not by
//! events), or both choose, the probe is skipped. Another event may land on the same d (a
//! mixture's lobes overlap) and add its density there, which the map around u does not see: where
//! s < 1 the ratio p · |J| / s may exceed 1 by that much, and only a ratio below 1 is off. With
//! ∫p equal to the valid fraction (`normalization`), p ≥ each event's density leaves no room for a
//! p too large where the events do not overlap.

use super::Domain;
use super::probe::Probe;
use serde::{Deserialize, Serialize};

/// The smallest finite-difference step in u (2⁻¹²), and the probe's margin from the edges of
/// [0, 1] is 2ε.
pub const EPS: f32 = 1.0 / 4096.0;
/// Steps of the central differences: ε · 2ᵏ⁻ˢ for k < STEPS, S = [`SUB_STEPS`] (2⁻¹⁶ … 2⁻⁵).
/// A small step is exact
/// for a curved map but reads the f32 rounding of d (≈ 6·10⁻⁸) over a change of d that a narrow
/// lobe makes tiny: GGX at α = 0.0064 moves d by ≈ 6·10⁻⁶ over 2ε, so central differences at
/// 2⁻¹² alone are off by percents. A large step averages the rounding out but meets the map's
/// curvature. Each derivative is taken at the three consecutive steps from ε up that agree best,
/// combined by Richardson extrapolation (4 D(h) − D(2h)) / 3, with the larger of |D(h) − D(2h)|
/// and |D(2h) − D(4h)| as its error (three steps: two may agree by chance on a staircase), or
/// the f32 rounding the smaller steps show, if larger ([`SUB_STEPS`]).
pub const STEPS: usize = 8 + SUB_STEPS;
/// Steps below ε (ε/16 … ε/2) that only measure the f32 staircase of the map: a correct sampler
/// whose d is resolved to treads about as long as ε (Henyey–Greenstein at g 0.99, where cos θ
/// moves by an ulp per 1.2ε of u.x near the peak; an IBL prefilter's sin θh = √(1 − cos²θh)
/// near the normal) reads the same whole number of treads per step at ε, 2ε and 4ε, three steps
/// that agree exactly on a |J| up to 40 % off. Over a step h_j below the judged ones the central
/// difference is off by the rounding of d there, |D_j − D| · 2h_j; the same rounding costs
/// Richardson's value at h up to 0.75 × that / h, which joins the error.
pub const SUB_STEPS: usize = 4;
/// Uniforms probed around each probe sample: for u.x then u.y, for each step, u + h and u − h.
pub const AROUND: usize = 4 * STEPS;
/// A sample is off when |p · |J| / share − 1| exceeds this plus its allowance (for an event:
/// 1 − p · |J| / share): twice the relative error of |J| that the steps leave (Richardson's
/// value amplifies rounding noise up to 2.3 times the steps' difference), and `ulps` (the
/// check's [`super::CONDITIONING_ULPS`]) times the pdf's f32 conditioning at d.
pub const TOLERANCE: f64 = 1e-2;
/// A probe whose steps leave |J| uncertain by more than this is skipped (`skipped_unresolved`):
/// no three steps agree, d moves by only a few f32 ulps over them (an f32 staircase).
pub const UNRESOLVED: f64 = 1e-2;
/// The check fails when more than this share of the compared samples is off.
pub const MAX_SHARE_OFF: f64 = 1e-2;
/// Fewer compared samples than this and the check does not apply.
pub const MIN_COMPARED: u64 = 100;
/// The systematic test: a smooth error of the map (a density 0.5 % off over a whole region) is
/// under [`TOLERANCE`] at every sample, but it is there at most of them. Over the probes whose
/// |J| and pdf f32 resolves to [`RESOLVED`] (allowance 2 · error + ulps · conditioning; no
/// event chosen, whose ratio may exceed 1 by another event's density), a probe is off by this
/// much when |p · |J| − 1| exceeds it plus its allowance.
pub const SYSTEMATIC_TOLERANCE: f64 = 1e-3;
/// A probe joins the systematic test where its allowance is at most this.
pub const RESOLVED: f64 = 1e-3;
/// The systematic test fails when more than half the resolved probes are off by
/// [`SYSTEMATIC_TOLERANCE`] beyond chance: a one-sided sign test of "the median of
/// |p · |J| − 1| − allowance is at most SYSTEMATIC_TOLERANCE" at this z (P ≈ 10⁻⁶ under the
/// hypothesis, the probes being independent draws).
pub const SIGN_TEST_Z: f64 = 4.75;

/// What the comparison found.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, schemars::JsonSchema)]
pub struct JacobianCheck {
    pub probed: u64,
    pub compared: u64,
    /// Samples where d moves continuously with u.z or u.w, or where both choose an event.
    pub skipped_selection: u64,
    /// Samples where the map is not smooth at any step's scale.
    pub skipped_not_smooth: u64,
    /// Samples where no two steps agree on |J| to [`UNRESOLVED`]: the map is resolved only to a
    /// few f32 ulps of d there (a staircase, such as sin θ = √(1 − cos²θ) near a pole).
    #[serde(default)]
    pub skipped_unresolved: u64,
    /// Samples with an invalid point or pdf at or around them.
    pub skipped_invalid: u64,
    /// Compared samples where the sampler chose an event with u.z or u.w (share < 1), judged by
    /// p · |J| / share.
    pub compared_events: u64,
    /// Those of them above 1 + TOLERANCE: not off (another event may land on the same d).
    pub above_events: u64,
    /// Compared samples with |p · |J| / share − 1| over TOLERANCE plus their allowance (for an
    /// event: below 1 − TOLERANCE − allowance).
    pub off: u64,
    pub share_off: f64,
    /// Median and worst p · |J| / share over the compared samples (1 for a correct pdf; no median
    /// without compared samples; an event's ratio above 1 is not the worst). The worst is the
    /// sample whose deviation is largest against its TOLERANCE + allowance.
    pub median_ratio: Option<f64>,
    pub worst_ratio: f64,
    /// The u of the worst sample.
    pub worst_u: [f32; 4],
    /// TOLERANCE + the allowance at the worst sample.
    #[serde(default)]
    pub worst_limit: f64,
    /// The largest step any compared sample's derivatives were taken at.
    #[serde(default)]
    pub largest_step: f64,
    pub tolerance: f64,
    /// Whether enough samples could be compared for a verdict.
    pub applicable: bool,
    /// The systematic test ([`SYSTEMATIC_TOLERANCE`]): the compared samples with no event whose
    /// allowance is at most [`RESOLVED`].
    #[serde(default)]
    pub resolved: u64,
    /// Those of them with |p · |J| − 1| over SYSTEMATIC_TOLERANCE plus their allowance.
    #[serde(default)]
    pub systematic_off: u64,
    /// The median of |p · |J| − 1| over the resolved samples (none without them).
    #[serde(default)]
    pub median_deviation: Option<f64>,
    #[serde(default)]
    pub systematic_tolerance: f64,
    /// The most of them that may be off: resolved / 2 + SIGN_TEST_Z · √resolved / 2.
    #[serde(default)]
    pub systematic_limit: f64,
    /// Whether the systematic test failed: more than half the resolved samples off beyond
    /// chance (only with at least [`MIN_COMPARED`] resolved samples).
    #[serde(default)]
    pub systematic: bool,
    /// A jump of the map along u.x or u.y ([`find_jump`]): several pieces of u may land on one d,
    /// and every probe is judged as an event's, off only below 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jump: Option<Jump>,
    pub passed: bool,
}

/// Where the sample map jumps along u.x or u.y: a sampler choosing a lobe with u.x itself and
/// reusing it (pbrt's uRemapped: u.x < w picks lobe A with u.x/w, else lobe B with
/// (u.x − w)/(1 − w)). The map is then not one-to-one: at d the pdf is the sum of the densities
/// of every piece landing there, of which the probe's own piece, 1/|J|, is one, so pdf · |J| ≥ 1
/// and only a ratio below 1 is off (as for an event chosen with u.z).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, schemars::JsonSchema)]
pub struct Jump {
    /// 0 for u.x, 1 for u.y.
    pub axis: u8,
    /// The u of the first jump found along that axis (to 2⁻¹⁶).
    pub at: f64,
    /// Scanned lines (a probe's u with one component swept over [2ε, 1 − 2ε]) with a jump, and
    /// all scanned lines.
    pub lines: u64,
    pub scanned: u64,
}

/// Lines scanned for a jump ([`find_jump`]) at most, and nodes per line (then per refinement).
pub const JUMP_LINES: usize = 32;
const JUMP_NODES: usize = 256;
const JUMP_REFINE: usize = 16;
/// A step of d is a jump where, refined twice by [`JUMP_REFINE`] (to 2⁻¹⁶ of u), one sub-step
/// still holds this share of it (a smooth map's steps shrink by 256) and it exceeds
/// [`JUMP_MIN`].
const JUMP_SHARE: f64 = 0.5;
const JUMP_MIN: f64 = 1e-3;

/// The nodes t₀ … t_k evenly over [lo, hi] on the line through `u` along `axis`.
fn line(u: [f32; 4], axis: usize, lo: f64, hi: f64, k: usize) -> Vec<[f32; 4]> {
    (0..=k)
        .map(|j| {
            let mut v = u;
            v[axis] = (lo + (hi - lo) * j as f64 / k as f64) as f32;
            v
        })
        .collect()
}

/// The largest step of d between consecutive valid nodes of `at` (the map at [`line`]'s nodes),
/// with its index.
fn largest_step(at: &[[f32; 4]], domain: Domain) -> Option<(usize, f64)> {
    let valid = |v: &[f32; 4]| v.iter().all(|x| x.is_finite()) && v[3] > 0.0;
    at.windows(2)
        .enumerate()
        .filter(|(_, w)| valid(&w[0]) && valid(&w[1]))
        .map(|(j, w)| (j, norm(sub(domain.point(v3(w[1])), domain.point(v3(w[0]))))))
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// The sample map at a list of uniforms, as the check's map pass evaluates it.
pub type MapPass<'a> = dyn Fn(&[[f32; 4]]) -> Result<Vec<[f32; 4]>, super::CheckError> + 'a;

/// Whether the sample map jumps along u.x or u.y: on the lines through the first [`JUMP_LINES`]
/// of `probes` (u with a valid sample) along each axis, the largest step of d over
/// `JUMP_NODES` nodes, refined twice around its largest sub-step; `map` evaluates the sampler
/// at uniforms (the check's map pass). A smooth map's largest sub-step shrinks with the step; a
/// jump's stays.
pub fn find_jump(probes: &[[f32; 4]], domain: Domain, map: &MapPass) -> Result<Option<Jump>, super::CheckError> {
    let margin = 2.0 * EPS as f64;
    for axis in 0..2 {
        // (u, the interval [lo, hi] of the largest step, that step) per line
        let mut lines: Vec<([f32; 4], f64, f64, f64)> = Vec::new();
        let nodes: Vec<[f32; 4]> = probes.iter().flat_map(|u| line(*u, axis, margin, 1.0 - margin, JUMP_NODES)).collect();
        let at = map(&nodes)?;
        for (u, at) in probes.iter().zip(at.chunks(JUMP_NODES + 1)) {
            if let Some((j, step)) = largest_step(at, domain) {
                let h = (1.0 - 2.0 * margin) / JUMP_NODES as f64;
                lines.push((*u, margin + j as f64 * h, margin + (j + 1) as f64 * h, step));
            }
        }
        let scanned = lines.len() as u64;
        let mut current: Vec<([f32; 4], f64, f64, f64)> = lines.clone();
        for _ in 0..2 {
            let nodes: Vec<[f32; 4]> = current.iter().flat_map(|(u, lo, hi, _)| line(*u, axis, *lo, *hi, JUMP_REFINE)).collect();
            let at = map(&nodes)?;
            current = current
                .iter()
                .zip(at.chunks(JUMP_REFINE + 1))
                .map(|(&(u, lo, hi, _), at)| match largest_step(at, domain) {
                    Some((j, step)) => {
                        let h = (hi - lo) / JUMP_REFINE as f64;
                        (u, lo + j as f64 * h, lo + (j + 1) as f64 * h, step)
                    }
                    None => (u, lo, hi, 0.0),
                })
                .collect();
        }
        let jumps: Vec<f64> = lines.iter().zip(&current).filter(|(l, c)| c.3 > JUMP_MIN && c.3 >= JUMP_SHARE * l.3).map(|(_, c)| 0.5 * (c.1 + c.2)).collect();
        if let Some(&at) = jumps.first() {
            return Ok(Some(Jump { axis: axis as u8, at, lines: jumps.len() as u64, scanned }));
        }
    }
    Ok(None)
}

fn v3(v: [f32; 4]) -> [f64; 3] {
    [v[0] as f64, v[1] as f64, v[2] as f64]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Step k: ε · 2ᵏ⁻ˢ.
fn step(k: usize) -> f32 {
    EPS * (1u32 << k) as f32 / (1u32 << SUB_STEPS) as f32
}

/// The uniforms around `u` that the Jacobian needs (`AROUND` of them, in the order the module
/// doc says): a step that would leave [0, 1] gives u itself, which [`judge`] knows not to use.
pub fn around(u: [f32; 4]) -> [[f32; 4]; AROUND] {
    let mut out = [u; AROUND];
    for axis in 0..2 {
        for k in 0..STEPS {
            let (plus, minus) = (u[axis] + step(k), u[axis] - step(k));
            if plus <= 1.0 && minus >= 0.0 {
                out[(axis * STEPS + k) * 2][axis] = plus;
                out[(axis * STEPS + k) * 2 + 1][axis] = minus;
            }
        }
    }
    out
}

/// ∂d/∂u along one axis: Richardson's value and its error estimate (absolute), at step `h`.
struct Derivative {
    value: [f64; 3],
    error: f64,
    h: f64,
}

/// Whether the reported density jumps within a step, from its value `p0` at u to `plus` and
/// `minus` at u ± h: one side changes by more than [`DENSITY_JUMP`] and by more than
/// [`JUMP_ASYMMETRY`] times the other. A smooth density changes alike on both sides of u (to
/// first order in h); a piecewise-constant one (an environment map's texels, a table's bins)
/// changes on one side only where an edge lies within the step, and there the map's own slope
/// changes too, so no central difference across it is the Jacobian at u (it averages the two
/// sides': 4.6 % off at a texel edge of a 64 × 32 lat-long map).
fn density_jumps(p0: f64, plus: f64, minus: f64) -> bool {
    let (up, down) = ((plus - p0).abs(), (p0 - minus).abs());
    let (big, small) = (up.max(down), up.min(down));
    big > DENSITY_JUMP * p0 && big > JUMP_ASYMMETRY * small
}

/// A change of the reported density within a step that may be a jump: the pdf's consistency
/// limit, [`super::PDF_CONSISTENCY_LIMIT`].
pub const DENSITY_JUMP: f64 = 1e-3;
/// How many times one side's change of the density must exceed the other's to be a jump: a
/// smooth density's two sides differ by a factor up to e^(h p'/p) (3 where it changes by a
/// factor 3 over the step, a step too coarse for its derivative anyway).
pub const JUMP_ASYMMETRY: f64 = 8.0;

/// The derivative of the map along `axis` at `u` from the samples `at` of [`around`]`(u)`
/// (this axis's 2 · STEPS), or `None` where no two consecutive steps are smooth. `p0` is the
/// density reported at u.
fn derivative(u: [f32; 4], axis: usize, d0: [f64; 3], p0: f64, at: &[[f32; 4]], domain: Domain) -> Option<Derivative> {
    let point = |v: [f32; 4]| domain.point(v3(v));
    let d0 = domain.point(d0);
    // the central difference at each usable step: both points valid, and smooth there (the second
    // difference under a tenth of the first: no fold, seam or branch between lobes within it;
    // and no jump of the density, [`density_jumps`])
    let steps = around(u);
    let steps = &steps[axis * 2 * STEPS..(axis + 1) * 2 * STEPS];
    // (the raw central difference and its span too, smooth or not: what f32 does at small steps)
    let raw: Vec<Option<([f64; 3], f64, bool)>> = (0..STEPS)
        .map(|k| {
            let (p, m) = (at[2 * k], at[2 * k + 1]);
            let span = steps[2 * k][axis] as f64 - steps[2 * k + 1][axis] as f64;
            let valid = |v: [f32; 4]| v.iter().all(|x| x.is_finite()) && v[3] > 0.0;
            if span <= 0.0 || !valid(p) || !valid(m) {
                return None;
            }
            let (p, m) = (point(p), point(m));
            let first = sub(p, m);
            let second = norm([p[0] - 2.0 * d0[0] + m[0], p[1] - 2.0 * d0[1] + m[1], p[2] - 2.0 * d0[2] + m[2]]);
            let jump = density_jumps(p0, at[2 * k][3] as f64, at[2 * k + 1][3] as f64);
            Some((scale(first, 1.0 / span), span, norm(first) > 0.0 && second <= 0.1 * norm(first) && !jump))
        })
        .collect();
    let diffs: Vec<Option<[f64; 3]>> = raw.iter().map(|r| r.and_then(|(d, _, smooth)| smooth.then_some(d))).collect();
    // three consecutive steps must agree: two alone may agree by chance on a staircase whose
    // treads are as long as the steps
    (SUB_STEPS..STEPS - 2)
        .filter_map(|k| {
            let (a, b, c) = (diffs[k]?, diffs[k + 1]?, diffs[k + 2]?);
            let value = scale(sub(scale(a, 4.0), b), 1.0 / 3.0);
            // The f32 staircase of the map ([`SUB_STEPS`]): at each smaller step j the central
            // difference is off by its rounding (δ₊ − δ₋)/(2h_j), so |D_j − D| · 2h_j measures
            // the rounding of d there (a flat tread, D_j = 0, reads |D| · 2h_j); the same rounding
            // costs Richardson's value at h up to (4/(2h) + 1/(4h))/3 = 0.75/h times that.
            let rounding = raw[..k].iter().flatten().map(|(d, span, _)| norm(sub(*d, value)) * span).fold(0.0, f64::max);
            let h = step(k) as f64;
            Some(Derivative { value, error: norm(sub(a, b)).max(norm(sub(b, c))).max(0.75 * rounding / h), h: step(k + 1) as f64 })
        })
        .min_by(|x, y| (x.error / norm(x.value)).total_cmp(&(y.error / norm(y.value))))
}

/// |J| of the map at a probed sample with the share of its event and its relative error, or why
/// it cannot be compared.
enum Local {
    Jacobian { j: f64, share: f64, error: f64, h: f64 },
    Selection,
    NotSmooth,
    Unresolved,
    Invalid,
}

fn local(probe: &Probe, u: [f32; 4], at: &[[f32; 4]; AROUND], domain: Domain) -> Local {
    let finite = [probe.sample].iter().chain(&probe.neighbours).flatten().chain(&[probe.share_z, probe.share_w]).all(|x| x.is_finite());
    if !finite || probe.reported_pdf() <= 0.0 || !(probe.pdf > 0.0 && probe.pdf.is_finite()) {
        return Local::Invalid;
    }
    // the neighbours at the smallest step, as the probe pass drew them
    if probe.neighbours.iter().any(|v| v[3] <= 0.0) {
        return Local::Invalid;
    }
    // shares of u.z and u.w: 1 unused, < 0 d moves with it (user_passes.wgsl: lobes_share)
    let (sz, sw) = (probe.share_z as f64, probe.share_w as f64);
    if sz < 0.0 || sw < 0.0 || (sz < 1.0 && sw < 1.0) {
        return Local::Selection;
    }
    let d0 = v3(probe.sample);
    let p0 = probe.reported_pdf() as f64;
    let (Some(a), Some(b)) = (derivative(u, 0, d0, p0, &at[..2 * STEPS], domain), derivative(u, 1, d0, p0, &at[2 * STEPS..], domain)) else {
        return Local::NotSmooth;
    };
    // |∂d/∂u₁ × ∂d/∂u₂|: on the plane (z = 0) the cross product's norm is |det ∂(x, y)/∂(u₁, u₂)|
    let area = norm(cross(a.value, b.value));
    if area == 0.0 {
        return Local::NotSmooth;
    }
    // |δ(a × b)| ≤ |δa| |b| + |a| |δb|
    let error = (a.error * norm(b.value) + norm(a.value) * b.error) / area;
    if error > UNRESOLVED {
        return Local::Unresolved;
    }
    Local::Jacobian { j: area, share: sz.min(sw), error, h: a.h.max(b.h) }
}

/// Compares the pdf function at each probed sample with share / |J|: `u` are the probed
/// uniforms, `at` the map at [`around`] each of them, `conditioning` the pdf's f32 conditioning
/// at each probe's d (0 where unknown) and `ulps` its multiple allowed.
/// With `jump` (the map is not one-to-one, [`find_jump`]) every probe is judged as an event's.
pub fn judge(probes: &[Probe], u: &[[f32; 4]], at: &[[[f32; 4]; AROUND]], conditioning: &[f64], ulps: f64, domain: Domain, jump: Option<Jump>) -> JacobianCheck {
    let mut c = JacobianCheck {
        probed: probes.len() as u64,
        compared: 0,
        skipped_selection: 0,
        skipped_not_smooth: 0,
        skipped_unresolved: 0,
        skipped_invalid: 0,
        compared_events: 0,
        above_events: 0,
        off: 0,
        share_off: 0.0,
        median_ratio: None,
        worst_ratio: 1.0,
        worst_u: [0.0; 4],
        worst_limit: TOLERANCE,
        largest_step: 0.0,
        tolerance: TOLERANCE,
        applicable: false,
        resolved: 0,
        systematic_off: 0,
        median_deviation: None,
        systematic_tolerance: SYSTEMATIC_TOLERANCE,
        systematic_limit: 0.0,
        systematic: false,
        jump,
        passed: true,
    };
    let mut ratios = Vec::new();
    let mut deviations = Vec::new();
    let mut worst = 0.0;
    for (((p, u), at), kappa) in probes.iter().zip(u).zip(at).zip(conditioning) {
        match local(p, *u, at, domain) {
            Local::Invalid => c.skipped_invalid += 1,
            Local::Selection => c.skipped_selection += 1,
            Local::NotSmooth => c.skipped_not_smooth += 1,
            Local::Unresolved => c.skipped_unresolved += 1,
            Local::Jacobian { j, share, error, h } => {
                let ratio = p.pdf as f64 * j / share;
                ratios.push(ratio);
                c.largest_step = c.largest_step.max(h);
                let limit = TOLERANCE + 2.0 * error + ulps * kappa;
                let event = share < 1.0 || jump.is_some();
                let deviation = if event { (1.0 - ratio).max(0.0) } else { (ratio - 1.0).abs() };
                let allowance = limit - TOLERANCE;
                if !event && allowance <= RESOLVED {
                    deviations.push(deviation);
                    c.systematic_off += u64::from(deviation > SYSTEMATIC_TOLERANCE + allowance);
                }
                c.compared_events += event as u64;
                c.above_events += (event && ratio > 1.0 + limit) as u64;
                if deviation > limit {
                    c.off += 1;
                }
                if deviation / limit > worst {
                    worst = deviation / limit;
                    c.worst_ratio = ratio;
                    c.worst_u = *u;
                    c.worst_limit = limit;
                }
            }
        }
    }
    c.compared = ratios.len() as u64;
    if !ratios.is_empty() {
        ratios.sort_by(f64::total_cmp);
        c.median_ratio = Some(ratios[ratios.len() / 2]);
        c.share_off = c.off as f64 / c.compared as f64;
    }
    c.applicable = c.compared >= MIN_COMPARED;
    c.resolved = deviations.len() as u64;
    if !deviations.is_empty() {
        deviations.sort_by(f64::total_cmp);
        c.median_deviation = Some(deviations[deviations.len() / 2]);
    }
    let n = c.resolved as f64;
    c.systematic_limit = n / 2.0 + SIGN_TEST_Z * n.sqrt() / 2.0;
    c.systematic = c.resolved >= MIN_COMPARED && c.systematic_off as f64 > c.systematic_limit;
    c.passed = !c.applicable || (c.share_off <= MAX_SHARE_OFF && !c.systematic);
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit square's plane, where these maps live.
    const PLANE: Domain = Domain::UNIT_SQUARE;

    /// The probe of the uniform map onto the plane's unit square (|J| = 1) at (0.3, 0.6), with a
    /// pdf and the shares of u.z and u.w.
    /// A probe whose pdf function gives `pdf` at d, with u.z's and u.w's shares `shares`.
    fn with(sample: [f32; 4], neighbours: [[f32; 4]; 4], shares: [f32; 2], pdf: f32) -> Probe {
        Probe { sample, neighbours, share_z: shares[0], share_w: shares[1], pdf, eval: 0.0, length: 0.0, _pad: [0.0; 3] }
    }

    fn probe(pdf: f32, shares: [f32; 2]) -> Probe {
        let (e, x, y) = (EPS, 0.3f32, 0.6f32);
        with([x, y, 0.0, pdf], [[x + e, y, 0.0, pdf], [x - e, y, 0.0, pdf], [x, y + e, 0.0, pdf], [x, y - e, 0.0, pdf]], shares, pdf)
    }

    fn judged(pdf: f32, shares: [f32; 2]) -> JacobianCheck {
        let n = MIN_COMPARED as usize;
        let u = [0.3, 0.6, 0.0, 0.0];
        let at = around(u).map(|v| [v[0], v[1], 0.0, pdf]);
        judge(&vec![probe(pdf, shares); n], &vec![u; n], &vec![at; n], &vec![0.0; n], 4.0, PLANE, None)
    }

    /// The probe of `map` at `u` with pdf `pdf` (shares 1), and the map around it.
    fn probed(map: impl Fn([f32; 4]) -> [f32; 4], u: [f32; 4], pdf: f32) -> (Probe, [[f32; 4]; AROUND]) {
        let neighbours = [(0, EPS), (0, -EPS), (1, EPS), (1, -EPS)].map(|(axis, s)| {
            let mut v = u;
            v[axis] += s;
            map(v)
        });
        (with(map(u), neighbours, [1.0, 1.0], pdf), around(u).map(map))
    }

    fn judge_all(p: Probe, u: [f32; 4], at: [[f32; 4]; AROUND]) -> JacobianCheck {
        let n = MIN_COMPARED as usize;
        judge(&vec![p; n], &vec![u; n], &vec![at; n], &vec![0.0; n], 4.0, PLANE, None)
    }

    /// The probe u of the two tests below.
    const U: [f32; 4] = [0.3, 0.6, 0.0, 0.0];

    /// d = (u.x, slope · u.y) on the plane with a rounding error σ in d.y: +σ on the side of
    /// larger u.y than U's, −σ on the other (the worst case for a central difference); the
    /// reported pdf is the exact density 1/slope.
    fn noisy(slope: f64, sigma: f64) -> impl Fn([f32; 4]) -> [f32; 4] {
        move |v: [f32; 4]| {
            let noise = sigma * (v[1] as f64 - U[1] as f64).signum() * (v[1] != U[1]) as u8 as f64;
            [v[0], (slope * v[1] as f64 + noise) as f32, 0.0, (1.0 / slope) as f32]
        }
    }

    /// Slope 10⁻³ with σ = 3·10⁻⁸ (half an ulp of d ≈ 0.6, f32's rounding): at step 2⁻¹² the
    /// difference reads |J| 12 % high, the steps of 2⁻⁷ … 2⁻⁵ agree to 0.3 %, and the ratio there
    /// is 1 within the allowance; a pdf of half the density is off.
    #[test]
    fn a_map_resolved_only_by_large_steps_is_judged_at_them() {
        let (p, at) = probed(noisy(1e-3, 3e-8), U, 1e3);
        let c = judge_all(p, U, at);
        assert!(c.passed && c.compared == MIN_COMPARED && (c.median_ratio.unwrap() - 1.0).abs() < 2e-2 && c.largest_step >= 1.0 / 64.0, "{c:?}");
        let (p, at) = probed(noisy(1e-3, 3e-8), U, 500.0);
        let c = judge_all(p, U, at);
        assert!(!c.passed && (c.worst_ratio - 0.5).abs() < 2e-2, "{c:?}");
    }

    /// An f32 staircase: d.y = slope · u.y rounded to treads 1.2ε long (Henyey–Greenstein at g
    /// 0.99 near its peak). At ε, 2ε and 4ε the differences count whole treads and can agree
    /// exactly on a slope that is not the map's; the steps below ε show the treads, and the probe
    /// is skipped or judged at steps long enough to average them, never read as off.
    #[test]
    fn a_staircase_is_not_read_as_a_wrong_jacobian() {
        let tread = 1.2 * EPS as f64;
        let slope = 1e-3;
        for shift in [0.0, 0.1, 0.3, 0.5, 0.7, 0.9] {
            let stairs = move |v: [f32; 4]| [v[0], (slope * tread * (v[1] as f64 / tread + shift).floor()) as f32, 0.0, (1.0 / slope) as f32];
            let (p, at) = probed(stairs, U, 1e3);
            let c = judge_all(p, U, at);
            assert!(c.passed && c.off == 0, "shift {shift}: {c:?}");
        }
    }

    /// A smooth error of the map: d = (u.x + ε sin(2π u.x)/(2π), u.y) on the plane, |J| = 1 + ε
    /// cos(2π u.x), reported pdf 1, at 400 probes spread over u.x. At ε = 0.5 % every probe is
    /// within the pointwise 1 %, but |ε cos| exceeds 0.1 % at 87 % of them (|cos| > 0.2): the
    /// systematic test fails. At ε = 0.15 % it exceeds 0.1 % plus the allowance at about half
    /// (|cos| > ⅔: 208 of the 400), within the sign test's margin (at most 200 + 4.75 · 20/2 =
    /// 247): the test passes; the correct map (ε = 0) has no probe off.
    #[test]
    fn a_smooth_error_under_the_tolerance_is_seen_systematically() {
        let judged = |eps: f64| {
            let map = move |v: [f32; 4]| {
                let x = v[0] as f64;
                [(x + eps * (2.0 * std::f64::consts::PI * x).sin() / (2.0 * std::f64::consts::PI)) as f32, v[1], 0.0, 1.0]
            };
            let (mut probes, mut us, mut ats) = (Vec::new(), Vec::new(), Vec::new());
            for i in 0..400 {
                let u = [0.01 + 0.98 * (i as f32 + 0.5) / 400.0, 0.5, 0.0, 0.0];
                let (p, at) = probed(map, u, 1.0);
                probes.push(p);
                us.push(u);
                ats.push(at);
            }
            judge(&probes, &us, &ats, &vec![0.0; 400], 4.0, PLANE, None)
        };
        let c = judged(5e-3);
        assert!(c.share_off == 0.0 && c.resolved == 400 && c.systematic && !c.passed, "{c:?}");
        assert!((c.median_deviation.unwrap() - 5e-3 * std::f64::consts::FRAC_1_SQRT_2).abs() < 2e-4, "{c:?}");
        let c = judged(1.5e-3);
        assert!(!c.systematic && c.passed && (150..248).contains(&c.systematic_off), "{c:?}");
        let c = judged(0.0);
        assert!(c.passed && c.systematic_off == 0 && c.median_deviation.unwrap() < 1e-5, "{c:?}");
    }

    /// Slope 10⁻² with σ = 10⁻⁵: no three steps agree to 1 %, and the probe is skipped as
    /// unresolved, not judged.
    #[test]
    fn an_unresolved_map_is_skipped_and_counted() {
        let (p, at) = probed(noisy(1e-2, 1e-5), U, 100.0);
        let c = judge_all(p, U, at);
        assert!(c.compared == 0 && c.skipped_unresolved == MIN_COMPARED && !c.applicable && c.passed, "{c:?}");
    }

    /// |J| = 1: a pdf of 1 matches, 2 does not.
    #[test]
    fn identity_map_on_the_plane() {
        let good = judged(1.0, [1.0, 1.0]);
        assert!(good.applicable && good.passed && (good.median_ratio.unwrap() - 1.0).abs() < 1e-3, "{good:?}");
        assert_eq!(good.compared_events, 0);
        let bad = judged(2.0, [1.0, 1.0]);
        assert!(bad.applicable && !bad.passed && (bad.worst_ratio - 2.0).abs() < 1e-3, "{bad:?}");
    }

    /// An event of probability ¼ chosen with u.z (or u.w) has density ¼ / |J|: pdf ¼ matches, ⅛
    /// is off by ½; ½ (another event landing there too) is above, not off.
    #[test]
    fn an_event_is_judged_by_its_share() {
        for shares in [[0.25, 1.0], [1.0, 0.25]] {
            let good = judged(0.25, shares);
            assert!(good.passed && good.compared_events == MIN_COMPARED && (good.median_ratio.unwrap() - 1.0).abs() < 1e-6, "{good:?}");
            let low = judged(0.125, shares);
            assert!(!low.passed && (low.worst_ratio - 0.5).abs() < 1e-6, "{low:?}");
            let high = judged(0.5, shares);
            assert!(high.passed && high.off == 0 && high.above_events == MIN_COMPARED && high.worst_ratio == 1.0, "{high:?}");
        }
    }

    /// A lobe choice made with u.x and reused (pbrt's uRemapped) on the plane: u.x < ½ maps
    /// (2u.x, u.y), else (2u.x − 1, u.y), onto the unit square, two pieces over one d. The jump at
    /// u.x = ½ is found on every line along u.x, at ½, and not along u.y; the identity map has
    /// none, nor has a steep smooth one (x = u.x⁸).
    #[test]
    fn a_jump_along_u_x_is_found() {
        let lines: Vec<[f32; 4]> = (0..JUMP_LINES).map(|i| [0.5, (i as f32 + 0.5) / JUMP_LINES as f32, 0.0, 0.0]).collect();
        let found = |f: fn([f32; 4]) -> [f32; 4]| find_jump(&lines, PLANE, &|us| Ok(us.iter().map(|u| f(*u)).collect())).unwrap();
        let jump = found(|u| [if u[0] < 0.5 { 2.0 * u[0] } else { 2.0 * u[0] - 1.0 }, u[1], 0.0, 0.5]).expect("a jump");
        assert!(jump.axis == 0 && (jump.at - 0.5).abs() < 1e-4 && jump.lines == JUMP_LINES as u64 && jump.scanned == JUMP_LINES as u64, "{jump:?}");
        assert_eq!(found(|u| [u[0], u[1], 0.0, 1.0]), None);
        assert_eq!(found(|u| [u[0].powi(8), u[1], 0.0, 1.0]), None);
    }

    /// With the jump, a probe whose pdf is twice its own piece's density (the other piece lands on
    /// the same d) is not off; one whose pdf is half that density is.
    #[test]
    fn a_non_injective_map_is_judged_one_sided() {
        let n = MIN_COMPARED as usize;
        let u = [0.3, 0.6, 0.0, 0.0];
        let jump = Some(Jump { axis: 0, at: 0.5, lines: 32, scanned: 32 });
        for (pdf, passes) in [(2.0f32, true), (0.5, false)] {
            let at = around(u).map(|v| [v[0], v[1], 0.0, pdf]);
            let c = judge(&vec![probe(pdf, [1.0, 1.0]); n], &vec![u; n], &vec![at; n], &vec![0.0; n], 4.0, PLANE, jump);
            assert_eq!(c.passed, passes, "pdf {pdf}: {c:?}");
        }
    }

    /// d moving continuously with u.z or u.w (share −1), or events chosen by both: skipped.
    #[test]
    fn continuous_or_double_choices_are_skipped() {
        for shares in [[-1.0, 1.0], [1.0, -1.0], [0.5, 0.5]] {
            let c = judged(1.0, shares);
            assert!(c.compared == 0 && c.skipped_selection == MIN_COMPARED && !c.applicable && c.passed, "{c:?}");
        }
    }
}
