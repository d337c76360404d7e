//! The expected histogram of a user's sampler: each bin's integral of the user's WGSL pdf (and of
//! its eval), by adaptive Gauss–Legendre quadrature on the GPU.
//!
//! Each part of a bin is integrated with the 5 × 5 and the 3 × 3 tensor rules (as the f64
//! quadrature of `crate::stats::expected`); where they agree within the tolerance the 5 × 5 value
//! is taken, else the part is split into quarters, which are accepted when their sum agrees with
//! the whole part's 5 × 5 value, else split again, up to [`MAX_DEPTH`]. The tolerance is a
//! hundredth of a bin count's standard deviation at the run's sample count N,
//! 0.01 √(p/N), plus a thousandth of one count, plus the f32 rounding of the sum (2·10⁻⁶ p): the
//! quadrature error stays far below the statistical error of the histogram it is compared with.
//! A fixed rule is not enough: a lobe narrower than a bin slips between its nodes (Mitsuba's
//! fixed trapezoid rule fails correct peaked samplers for that reason).
//!
//! **No verdict from an unconverged quadrature.** A bin's error estimate (its accepted
//! |fine − coarse| differences) is held to [`MAX_QUADRATURE_SIGMA`] of its count's standard
//! deviation at N, as `lobes run` holds its f64 reference. The bins beyond it are integrated
//! again from an initial split [`REFINE_FACTOR`] times finer per axis and [`MAX_DEPTH`] + 2
//! levels deep, up to [`RETRIES`] times, and keep the new values; where a bin is still beyond it
//! ([`Integrals::converged`] says so) `lobes check` draws no verdict (exit 3).
//!
//! **Jumps and poles.** Agreement is not trusted where the pdf's support has an edge (the pdf 0
//! at some of a part's nodes, corners and sides' midpoints, > 0 at others): such a part is split
//! [`EDGE_DEPTH`] levels past [`MAX_DEPTH`] while its jump holds more than the tolerance, and a
//! part at a pole is integrated in s = √a ([`Rect`]), where a pdf ∝ 1/sin θ is smooth.
//!
//! Sphere bins are integrated over (a, φ) with a = 1 − |cos θ| per hemisphere (see
//! `lobes_domain_point`), so that parts next to a pole keep their f32 resolution, and with φ
//! measured from the axis nearest the part (`rect_f32`), so that an edge on an axis (the seam
//! above all) is exactly where `lobes check`'s binning puts it.
//!
//! The same rules integrate a function over the whole sphere ([`WgslIntegrand`] on the GPU,
//! [`sphere_integral_f64`] on the CPU), from parts graded toward the poles rather than a
//! histogram's bins: what the microfacet identities of `tests/microfacet_identities.rs` need.

use super::gpu::{self, Params, Passes};

use super::{CheckError, Domain, MAX_PARAMS, Source, UserSampler};
use crate::engine::gpu::Gpu;
pub use crate::stats::expected::MAX_QUADRATURE_SIGMA;
use crate::stats::gauss_legendre::GaussLegendre;
use crate::stats::domain::Cell;
use crate::stats::histogram::SphereGrid;
use serde::{Deserialize, Serialize};

/// Deepest split of a part (a quarter per level).
pub const MAX_DEPTH: u32 = 8;
/// Levels past the deepest split for a part where the pdf's support has an edge (the jump is
/// located to 2⁻ᴰ of the part: bisection of the edge, a quarter at a time).
pub const EDGE_DEPTH: u32 = 4;

/// Whether [`refine`] locates the edges of the pdf's support ([`EDGE_DEPTH`]) or trusts the
/// rules' agreement there: a sampler's pdf is judged against counts, and a jump it has is located;
/// the whole-sphere integrals of [`WgslIntegrand`] and [`sphere_integral_f64`] hold kinks
/// (max(0, ω·h)), not jumps, which their own graded parts resolve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Jumps {
    Locate,
    Trust,
}
/// The initial split of a bin per axis is at most this.
pub const MAX_INITIAL_SPLIT: u32 = 16;
/// Parts evaluated in one round at most; beyond it, parts are accepted unrefined and counted.
const MAX_PARTS: usize = 1 << 22;
/// Times the bins beyond [`MAX_QUADRATURE_SIGMA`] are integrated again, each time from an initial
/// split [`REFINE_FACTOR`] times finer per axis (its cap too) and two levels deeper.
pub const RETRIES: u32 = 2;
pub const REFINE_FACTOR: u32 = 4;
/// A bin whose observed count is this many standard deviations from its expected count is
/// integrated again too, with its eight neighbours (after the bins beyond
/// [`MAX_QUADRATURE_SIGMA`]).
pub const DISPUTED_SIGMA: f64 = 3.0;
/// Bins integrated again per retry for a dispute at most, neighbours included (a sampler far
/// from its pdf disputes thousands of bins; a quadrature that missed a ridge, a few).
pub const MAX_DISPUTED: usize = 128;

/// Per-bin integrals and what their accuracy is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Integrals {
    /// ∫ pdf over each bin (row-major).
    pub probabilities: Vec<f64>,
    /// ∫ eval over each bin (0 without eval).
    pub eval: Vec<f64>,
    /// Σ over bins of the accepted |fine − coarse| differences of the pdf's integral.
    pub error_estimate: f64,
    /// Largest bin error in units of its count's standard deviation at the run's N: the
    /// |fine − coarse| of its parts accepted unconverged summed, plus those of its converged
    /// parts in quadrature (independent errors of either sign).
    pub max_error_sigma: f64,
    /// Parts accepted at the depth limit without agreeing.
    pub unconverged_parts: u64,
    /// Parts whose pdf integral came out NaN, infinite or negative (the pdf returned such values).
    pub bad_parts: u64,
    /// Per bin, the pdf's integral over its parts left out as bad where it is finite (a pdf
    /// below 0 there makes it negative), 0 elsewhere: `probabilities` + `dropped` is the pdf's
    /// signed integral, what the pictures draw; the χ² leaves those parts out. Empty where no
    /// part was bad.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dropped: Vec<f64>,
    /// Parts evaluated in all, and refinement rounds.
    pub parts: u64,
    pub rounds: u32,
}

impl Integrals {
    /// Nothing integrated yet over `bins` bins.
    fn zero(bins: usize) -> Self {
        Self {
            probabilities: vec![0.0; bins],
            eval: vec![0.0; bins],
            error_estimate: 0.0,
            max_error_sigma: 0.0,
            unconverged_parts: 0,
            bad_parts: 0,
            dropped: vec![0.0; bins],
            parts: 0,
            rounds: 0,
        }
    }

    /// `Err` with what is wrong where a bin's error estimate is beyond [`MAX_QUADRATURE_SIGMA`] of
    /// its count's standard deviation at `samples` (after the retries of [`integrate`]): expected
    /// counts that uncertain give no verdict, neither a pass nor a fail.
    ///
    /// ```
    /// use lobes::check::quadrature::Integrals;
    /// let mut i = Integrals { probabilities: vec![0.5, 0.5], eval: vec![0.0; 2], error_estimate: 0.0, max_error_sigma: 0.05,
    ///     unconverged_parts: 0, bad_parts: 0, dropped: vec![], parts: 2, rounds: 1 };
    /// assert!(i.converged(1_000_000).is_ok());
    /// i.max_error_sigma = 2.0;
    /// assert!(i.converged(1_000_000).unwrap_err().contains("no verdict"));
    /// ```
    pub fn converged(&self, samples: u64) -> Result<(), String> {
        if self.max_error_sigma <= MAX_QUADRATURE_SIGMA {
            return Ok(());
        }
        Err(format!(
            "the quadrature of the pdf did not converge: a bin's error estimate is {:.3}σ of its count at {samples} samples (at most {MAX_QUADRATURE_SIGMA}σ gives a verdict; {} parts accepted at the depth limit or the parts' budget after {RETRIES} finer retries), so no verdict is drawn; a pdf with an edge or a peak narrower than the quadrature resolves (a small cone, a near-delta lobe) needs fewer --samples or more --bins",
            self.max_error_sigma, self.unconverged_parts
        ))
    }
}

/// The first coordinate of a part ([`Rect`]): a = 1 − |cos θ| (on the plane, x), or s = √a.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Radial {
    A,
    RootA,
}

/// A rectangle of the quadrature's coordinates: `r` = (a0, a1, b0, b1) in hemisphere `h` (its
/// sign; 0 on the plane), its first coordinate a = 1 − |cos θ|, or, [`Radial::RootA`], s = √a: a part
/// at a pole is integrated in s (dω = da dφ = 2s ds dφ), which turns an integrable singularity
/// a^(−1/2) there — a pdf ∝ 1/sin θ (uniform in θ, as a lat-long map draws its rows) or
/// ∝ 1/√(1 − cos θ) — into a smooth integrand, where Gauss–Legendre in a converged to a value
/// 3·10⁻⁴ short (a smooth pdf stays smooth in s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Rect {
    pub r: [f64; 4],
    pub h: f32,
    pub radial: Radial,
}

#[derive(Clone, Copy)]
struct Part {
    a: (f64, f64),
    b: (f64, f64),
    /// hemisphere sign on the sphere, 0 on the plane
    h: f32,
    /// what `a` is ([`Rect`])
    radial: Radial,
    bin: u32,
    depth: u32,
    /// the parent's 5 × 5 estimates (pdf, eval), none for a bin's initial parts
    coarse: Option<(f64, f64)>,
}

impl Part {
    fn quarters(&self, coarse: (f64, f64)) -> [Part; 4] {
        let am = 0.5 * (self.a.0 + self.a.1);
        let bm = 0.5 * (self.b.0 + self.b.1);
        let q = |a, b| Part { a, b, depth: self.depth + 1, coarse: Some(coarse), ..*self };
        [q((self.a.0, am), (self.b.0, bm)), q((am, self.a.1), (self.b.0, bm)), q((self.a.0, am), (bm, self.b.1)), q((am, self.a.1), (bm, self.b.1))]
    }
    fn rect(&self) -> Rect {
        Rect { r: [self.a.0, self.a.1, self.b.0, self.b.1], h: self.h, radial: self.radial }
    }
}

type Piece = ((f64, f64), (f64, f64), f32, u32);

/// The tolerance on a part whose integral is about `value`, for a run of `n` samples, where the
/// integrand is evaluated with relative rounding `rounding`.
fn tolerance(value: f64, n: f64, rounding: f64) -> f64 {
    0.01 * (value.abs() / n).sqrt() + 1e-3 / n + rounding * value.abs()
}

/// Relative rounding of a part's sum on the GPU (25 f32 terms) and of the f64 reference.
pub const GPU_ROUNDING: f64 = 2e-6;
pub const CPU_ROUNDING: f64 = 1e-13;

/// What integrates the parts: per [`Rect`] the 5 × 5 and 3 × 3 rules of the pdf and of eval, and
/// where the pdf's support has an edge in it (0 at some of the rules' nodes, its corners and the
/// midpoints of its sides, > 0 at others), the scale of the jump's mass there (the smallest value
/// > 0 seen times the area); and the relative rounding of those sums.
pub(super) trait Integrand {
    fn rules(&self, rects: &[Rect]) -> Result<Vec<([f64; 4], Option<f64>)>, CheckError>;
    fn rounding(&self) -> f64;
}

/// A rectangle for the GPU pass in f32: on the sphere (h ≠ 0) its φ range measured from the axis
/// nearest its centre, k quarter turns from +x, with k (`lobes_domain_point`): an edge on an axis
/// then stays exactly on it, and one off the axes is within an ulp of the offset (≤ 4.7·10⁻⁸ rad)
/// rather than of φ (f32(π) is 8.7·10⁻⁸ past π).
/// The third number is 1 where the first coordinate is s = √a ([`Rect`]).
fn rect_f32(rect: &Rect) -> ([f32; 4], [f32; 3]) {
    let (r, h, root) = (&rect.r, rect.h, if rect.radial == Radial::RootA { 1.0 } else { 0.0 });
    if h == 0.0 {
        return (r.map(|x| x as f32), [0.0, 0.0, root]);
    }
    let quarter = std::f64::consts::FRAC_PI_2;
    let k = (0.5 * (r[2] + r[3]) / quarter).round();
    let b = |x: f64| (x - k * quarter) as f32;
    ([r[0] as f32, r[1] as f32, b(r[2]), b(r[3])], [h, (k as i64).rem_euclid(4) as f32, root])
}

impl Integrand for (&Passes<'_>, &Params) {
    fn rules(&self, rects: &[Rect]) -> Result<Vec<([f64; 4], Option<f64>)>, CheckError> {
        let rects32: Vec<([f32; 4], [f32; 3])> = rects.iter().map(rect_f32).collect();
        Ok(self.0.integrate(self.1, &rects32)?.into_iter().map(|[v, e]| (v.map(f64::from), (e[0] != 0.0).then_some(e[1] as f64))).collect())
    }
    fn rounding(&self) -> f64 {
        GPU_ROUNDING
    }
}

/// An f64 pdf on the CPU: the user's reference through the library API.
pub(super) struct CpuPdf<'a> {
    pub pdf: &'a (dyn Fn(glam::DVec3) -> f64 + Send + Sync),
    pub domain: Domain,
    /// Whether its parts' support edges are looked for (`None` from [`CpuPdf::edge`] otherwise).
    pub jumps: Jumps,
}

impl CpuPdf<'_> {
    /// The point at (a, b) of a part in hemisphere h ([`Domain::part_point`]).
    fn point(&self, a: f64, b: f64, h: f32) -> glam::DVec3 {
        glam::DVec3::from(self.domain.part_point(a, b, h as f64))
    }
    /// `lobes_support_edge` in f64: the pdf at both rules' nodes, the corners and the sides'
    /// midpoints.
    fn edge(&self, rect: &Rect, rules: [&GaussLegendre; 2]) -> Option<f64> {
        if self.jumps == Jumps::Trust {
            return None;
        }
        let r = &rect.r;
        let (c, hw) = ([0.5 * (r[0] + r[1]), 0.5 * (r[2] + r[3])], [0.5 * (r[1] - r[0]), 0.5 * (r[3] - r[2])]);
        let mut points: Vec<(f64, f64)> = rules.iter().flat_map(|g| g.nodes().iter().flat_map(|&(x, _)| g.nodes().iter().map(move |&(y, _)| (x, y)))).collect();
        points.extend([-0.999, 0.0, 0.999].iter().flat_map(|&x| [-0.999, 0.0, 0.999].map(|y| (x, y))).filter(|&(x, y)| (x, y) != (0.0, 0.0)));
        let (mut zero, mut positive, mut smallest) = (false, false, f64::INFINITY);
        for (x, y) in points {
            let s = c[0] + hw[0] * x;
            let a = if rect.radial == Radial::RootA { s * s } else { s };
            let p = (self.pdf)(self.point(a, c[1] + hw[1] * y, rect.h));
            zero |= p == 0.0;
            if p > 0.0 && p.is_finite() {
                positive = true;
                smallest = smallest.min(p);
            }
        }
        let area = 4.0 * hw[0] * hw[1] * if rect.radial == Radial::RootA { 2.0 * r[1] } else { 1.0 };
        (zero && positive).then_some(smallest * area)
    }
    fn rule(&self, rect: &Rect, rule: &GaussLegendre) -> f64 {
        let r = &rect.r;
        if rect.radial == Radial::RootA {
            return rule.integrate_2d((r[0], r[1]), (r[2], r[3]), |s, b| 2.0 * s * (self.pdf)(self.point(s * s, b, rect.h)));
        }
        rule.integrate_2d((r[0], r[1]), (r[2], r[3]), |a, b| (self.pdf)(self.point(a, b, rect.h)))
    }
}

impl Integrand for CpuPdf<'_> {
    fn rules(&self, rects: &[Rect]) -> Result<Vec<([f64; 4], Option<f64>)>, CheckError> {
        use rayon::prelude::*;
        // the pair of rules the GPU pass and the f64 quadrature of stats::expected use
        let (g5, g3) = (GaussLegendre::new(5), GaussLegendre::new(3));
        Ok(rects.par_iter().map(|r| ([self.rule(r, &g5), self.rule(r, &g3), 0.0, 0.0], self.edge(r, [&g5, &g3]))).collect())
    }
    fn rounding(&self) -> f64 {
        CPU_ROUNDING
    }
}

/// The widest initial part on the sphere (radians): a sixteenth of a radian. A lobe's width from
/// its peak density, 0.5/√p_max, is an isotropic lobe's; a 50:1 anisotropic one (GGX α (2, 0.04)
/// at θi 10°) is a ridge far narrower than that across, and where it crosses the tall bins next
/// to a pole (0.25 rad in θ at 64 rows) the 5 × 5 and 3 × 3 rules of one part agreed on a value
/// 16 % low (∫pdf 0.99958, measured on lavapipe; split to at most 1/16 rad, 1.000000).
pub const MAX_SPHERE_WIDTH: f64 = 0.0625;

/// The width the bins are first split to: 0.5/√p_max (p_max the largest pdf the probes reported),
/// within [10⁻⁴, 1], and at most [`MAX_SPHERE_WIDTH`] on the sphere.
pub(super) fn initial_width(p_max: f64, domain: Domain) -> f64 {
    let width = if p_max > 0.0 { (0.5 / p_max.sqrt()).clamp(1e-4, 1.0) } else { 0.1 };
    if domain.directions() { width.min(MAX_SPHERE_WIDTH) } else { width }
}

/// The parts a bin starts as: on the sphere its (a, φ) rectangle per hemisphere it touches,
/// each split `m × m` where `m` is its angular extent over `width`, at most `cap`; only the
/// bins `only` marks, where given.
fn initial_parts(domain: &Domain, rows: u32, cols: u32, width: f64, cap: u32, only: Option<&[bool]>) -> Vec<Part> {
    let mut parts = Vec::new();
    let split = |extent: f64| ((extent / width).ceil() as u32).clamp(1, cap);
    let grid = domain.grid(rows, cols);
    for bin in 0..grid.bins() as u32 {
        if only.is_some_and(|o| !o[bin as usize]) {
            continue;
        }
        // (a range, b range, hemisphere, initial split per axis)
        let mut pieces: Vec<Piece> = Vec::new();
        match grid.cell(bin as usize) {
            Cell::Plane { x, y } => pieces.push((x, y, 0.0, split((x.1 - x.0).max(y.1 - y.0)))),
            Cell::Sphere { row, phi } => {
                for z in row_zones(rows, row) {
                    pieces.push((z.a, phi, z.h, split(z.dtheta.max((phi.1 - phi.0) * z.smax))));
                }
            }
            // a cap's cell is one piece about its axis, as a sphere's row about the pole (h = 1)
            Cell::Cap { a, phi } => {
                let theta = |a: f64| 2.0 * (0.5 * a).sqrt().asin();
                let smax = (a.1 * (2.0 - a.1)).max(0.0).sqrt();
                pieces.push((a, phi, 1.0, split((theta(a.1) - theta(a.0)).max((phi.1 - phi.0) * smax))));
            }
        }
        for (a, b, h, m) in pieces {
            let (da, db) = ((a.1 - a.0) / m as f64, (b.1 - b.0) / m as f64);
            for i in 0..m {
                let a = (a.0 + i as f64 * da, a.0 + (i + 1) as f64 * da);
                // a part at a pole in s = √a ([`Rect`])
                let radial = if h != 0.0 && a.0 == 0.0 { Radial::RootA } else { Radial::A };
                let a = if radial == Radial::RootA { (0.0, a.1.sqrt()) } else { a };
                for j in 0..m {
                    parts.push(Part { a, b: (b.0 + j as f64 * db, b.0 + (j + 1) as f64 * db), h, radial, bin, depth: 0, coarse: None });
                }
            }
        }
    }
    parts
}

/// Integrates the user's pdf and eval over every bin. `width` is the narrowest feature expected,
/// in radians on the sphere or domain units on the plane; `samples` the run's sample count.
/// Bins whose error estimate is beyond [`MAX_QUADRATURE_SIGMA`] are integrated again, finer
/// (the module doc), and so are bins that the integral gives no probability where the
/// histogram `observed` (per bin, where given) has samples: a spot of the pdf smaller than the
/// nodes' spacing gives 0 by both rules, which agree (Beckmann visible normals at α 0.3, θi
/// 89.9°: the lobe's tail below the horizon, 0.0017 rad deep, in one bin of 64 × 128, 37.2
/// samples of 2²² by f64 quadrature of the f64 pdf, 36 observed, 0 expected before). Where the
/// pdf is 0 there, the finer integral is 0 too and the samples still fail the test. So are the
/// bins whose observed count is more than [`DISPUTED_SIGMA`] standard deviations from the
/// integral's, with their neighbours, the most disputed first as far as the parts' budget goes: a ridge narrower than the
/// nodes' spacing gives both rules the same wrong value (Beckmann visible normals at α (0.05,
/// 0.001), θi 80°, φi 20°: a bin below the horizon got 9.8 samples of 2²⁴ where the f64 pdf
/// integrates to 74.1, by a 8000 × 8000 midpoint rule and by 6000 × 6000 slopes of h, and 68–77
/// were observed at seeds 1–4). A finer integral tends to the pdf's, not to the histogram's: a
/// sampler that puts samples where its pdf does not fails as before.
/// [`Integrals::converged`] says whether any bin is left beyond the limit.
pub(super) fn integrate(f: &dyn Integrand, domain: &Domain, rows: u32, cols: u32, width: f64, samples: u64, observed: Option<&[u64]>) -> Result<Integrals, CheckError> {
    Ok(integrate_leaves(f, domain, rows, cols, width, samples, observed)?.0)
}

/// [`integrate`], with the parts its integrals are the sum of ([`Leaf`]).
pub(super) fn integrate_leaves(f: &dyn Integrand, domain: &Domain, rows: u32, cols: u32, width: f64, samples: u64, observed: Option<&[u64]>) -> Result<(Integrals, Vec<Leaf>), CheckError> {
    let bins = (rows * cols) as usize;
    let (mut out, mut b) = refine(f, initial_parts(domain, rows, cols, width, MAX_INITIAL_SPLIT, None), bins, samples, MAX_DEPTH, Jumps::Locate)?;
    let mut rounds = out.rounds;
    let n = samples.max(1) as f64;
    let unseen = |i: usize, p: f64| observed.is_some_and(|o| o[i] > 0) && p <= 0.0;
    // |observed − expected| in standard deviations (at least one count), 0 without a histogram
    let dispute = |i: usize, p: f64| observed.map_or(0.0, |o| (o[i] as f64 - n * p).abs() / (n * p).max(1.0).sqrt());
    for retry in 1..=RETRIES {
        let factor = REFINE_FACTOR.pow(retry);
        // at most (cap)² parts per hemisphere of a bin, so the parts' budget holds `room` bins
        let cap = MAX_INITIAL_SPLIT * factor;
        let room = MAX_PARTS / (2 * (cap * cap) as usize);
        let mut over: Vec<bool> =
            b.error.iter().zip(&out.probabilities).enumerate().map(|(i, (e, p))| sigmas(*e, *p, samples) > MAX_QUADRATURE_SIGMA || unseen(i, *p)).collect();
        let must = over.iter().filter(|o| **o).count();
        if must > room {
            break;
        }
        // then the disputed bins with their eight neighbours (a ridge goes on into them), the most
        // disputed first, as far as the budget goes
        let mut disputed: Vec<(f64, usize)> =
            (0..bins).map(|i| (dispute(i, out.probabilities[i]), i)).filter(|(z, _)| *z > DISPUTED_SIGMA).collect();
        disputed.sort_by(|x, y| y.0.total_cmp(&x.0));
        let mut added = 0;
        'disputed: for &(_, i) in &disputed {
            for j in domain.grid(rows, cols).neighbourhood(i) {
                if added >= (room - must).min(MAX_DISPUTED) {
                    break 'disputed;
                }
                if !over[j] {
                    over[j] = true;
                    added += 1;
                }
            }
        }
        if !over.contains(&true) {
            break;
        }
        let parts = initial_parts(domain, rows, cols, width / factor as f64, cap, Some(&over));
        let (again, a) = refine(f, parts, bins, samples, MAX_DEPTH + 2 * retry, Jumps::Locate)?;
        for i in (0..bins).filter(|&i| over[i]) {
            out.probabilities[i] = again.probabilities[i];
            out.eval[i] = again.eval[i];
            b.error[i] = a.error[i];
            b.linear[i] = a.linear[i];
            b.unconverged[i] = a.unconverged[i];
            out.dropped[i] = again.dropped[i];
        }
        b.leaves.retain(|l| !over[l.bin as usize]);
        b.leaves.extend(a.leaves.into_iter().filter(|l| over[l.bin as usize]));
        out.parts += again.parts;
        out.bad_parts = out.bad_parts.max(again.bad_parts);
        rounds += again.rounds;
    }
    out.rounds = rounds;
    if out.dropped.iter().all(|d| *d == 0.0) {
        out.dropped.clear();
    }
    out.unconverged_parts = b.unconverged.iter().sum();
    out.error_estimate = b.linear.iter().sum();
    out.max_error_sigma = b.error.iter().zip(&out.probabilities).map(|(e, p)| sigmas(*e, *p, samples)).fold(0.0, f64::max);
    Ok((out, b.leaves))
}

/// How far the integral over `leaves` moves when the pdf is evaluated by each integrand of
/// `perturbed` (the same pdf at inputs a few ulps off) instead of the one that gave the leaves'
/// values: the largest |Σ (perturbed − value)| over the leaves where both are finite and ≥ 0. On a
/// fixed partition the quadrature's own error cancels, and what is left is what the f32
/// evaluation of the pdf does to the integral, coherent errors (a reflected axis a rounding
/// longer than 1, a constant rounded in a subexpression) included, incoherent ones averaged as
/// the integral averages them.
pub(super) fn sensitivity(perturbed: &[&dyn Integrand], leaves: &[Leaf]) -> Result<f64, CheckError> {
    let rects: Vec<Rect> = leaves.iter().map(|l| l.rect).collect();
    let mut worst: f64 = 0.0;
    for f in perturbed {
        let values: Vec<[f64; 4]> = f.rules(&rects)?.into_iter().map(|(v, _)| v).collect();
        let shift: f64 = leaves.iter().zip(&values).filter(|(l, v)| v[0].is_finite() && v[0] >= 0.0 && l.value.is_finite() && l.value >= 0.0).map(|(l, v)| v[0] - l.value).sum();
        worst = worst.max(shift.abs());
    }
    Ok(worst)
}

/// How far from a column edge off the axes `lobes check`'s f32 binning may put it (radians): the
/// column ⌊(atan2(y, x) + π)/2π · cols⌋ rounds atan2 (whose result near ±π steps by 2.4·10⁻⁷)
/// and t; measured within about 2·10⁻⁷ on lavapipe, taken as 2 ulps of π. Edges on an axis are
/// exact (`lobes_axis_column`).
pub const EDGE_RESOLUTION: f64 = 5e-7;
/// A column edge whose strip of ±[`EDGE_RESOLUTION`] holds more than this many standard
/// deviations of the smaller of its two bins' counts (what f32 may move across it, at worst)
/// cannot be placed by the binning as the quadrature places it; the χ² judges its two bins as
/// one cell.
pub const EDGE_SIGMA: f64 = 0.3;

/// The part of row `r` of a sphere grid in each hemisphere it touches, in the quadrature's
/// coordinate a = 1 − |cos θ| (`lobes_domain_point`): its a range, the hemisphere's sign, its
/// extent in θ and the largest sin θ in it.
struct Zone {
    a: (f64, f64),
    h: f32,
    dtheta: f64,
    smax: f64,
}

fn row_zones(rows: u32, r: u32) -> Vec<Zone> {
    let z = SphereGrid { rows, cols: 1 }.cos_theta_edges();
    let (z0, z1) = (z[r as usize], z[r as usize + 1]);
    [(z0.max(0.0), z1.max(0.0), 1.0f32), (z0.min(0.0), z1.min(0.0), -1.0)]
        .into_iter()
        .filter(|(lo, hi, _)| hi > lo)
        .map(|(lo, hi, h)| Zone {
            a: (1.0 - hi.abs().max(lo.abs()), 1.0 - hi.abs().min(lo.abs())),
            h,
            dtheta: lo.clamp(-1.0, 1.0).acos() - hi.clamp(-1.0, 1.0).acos(),
            smax: (1.0 - lo.abs().min(hi.abs()).powi(2)).sqrt(),
        })
        .collect()
}

/// Per bin of the sphere grid, the pdf's integral over the strip within [`EDGE_RESOLUTION`] of
/// its left column edge, where that edge is off the axes and the bins beside it hold a count at
/// N = `samples` (0 elsewhere): the samples whose column f32 may decide otherwise than the
/// quadrature's edge. By the same adaptive rules, each strip split along θ like a bin.
pub(super) fn edge_strips(f: &dyn Integrand, rows: u32, cols: u32, width: f64, samples: u64, probabilities: &[f64]) -> Result<Vec<f64>, CheckError> {
    let bins = (rows * cols) as usize;
    let n = samples.max(1) as f64;
    let grid = SphereGrid { rows, cols };
    let phi = grid.phi_edges();
    let mut parts = Vec::new();
    for r in 0..rows {
        for c in (0..cols).filter(|&c| !grid.exact_phi_edge(c)) {
            let bin = r * cols + c;
            if n * (probabilities[bin as usize] + probabilities[bin as usize - 1]) < 1.0 {
                continue;
            }
            let b = (phi[c as usize] - EDGE_RESOLUTION, phi[c as usize] + EDGE_RESOLUTION);
            for z in row_zones(rows, r) {
                let m = ((z.dtheta / width).ceil() as u32).clamp(1, MAX_INITIAL_SPLIT);
                let da = (z.a.1 - z.a.0) / m as f64;
                for i in 0..m {
                    parts.push(Part { a: (z.a.0 + i as f64 * da, z.a.0 + (i + 1) as f64 * da), b, h: z.h, radial: Radial::A, bin, depth: 0, coarse: None });
                }
            }
        }
    }
    if parts.is_empty() {
        return Ok(vec![0.0; bins]);
    }
    Ok(refine(f, parts, bins, samples, MAX_DEPTH, Jumps::Locate)?.0.probabilities)
}

/// The counts and expected counts the χ² judges: where an off-axis column edge is closer to the
/// lobe than f32 binning resolves ([`EDGE_SIGMA`] of `strips`), the bins beside it as one cell
/// (the right one's count and expectation moved into the left one, and on along a run of such
/// edges), with the number of edges so joined. The choice depends on the pdf alone, never on the
/// counts, so the test stays a χ² test of a fixed partition.
pub fn join_unresolved_edges(counts: &[u64], expected: &[f64], strips: &[f64], rows: u32, cols: u32, samples: u64) -> (Vec<u64>, Vec<f64>, usize) {
    let original = expected;
    let (mut counts, mut expected) = (counts.to_vec(), expected.to_vec());
    let n = samples.max(1) as f64;
    let mut joined = 0;
    for r in 0..rows as usize {
        let row = r * cols as usize;
        let mut target = row;
        for c in 0..cols as usize {
            let i = row + c;
            let unresolved = c > 0 && strips[i] > 0.0 && n * strips[i] > EDGE_SIGMA * original[i].min(original[i - 1]).max(1.0).sqrt();
            if unresolved {
                counts[target] += counts[i];
                expected[target] += expected[i];
                counts[i] = 0;
                expected[i] = 0.0;
                joined += 1;
            } else {
                target = i;
            }
        }
    }
    (counts, expected, joined)
}

/// A bin's error `e` in units of its count's standard deviation √(N p) at N = `samples`, taken
/// as at least one count (as [`crate::stats::expected::Expected::max_error_sigma_at`]).
fn sigmas(e: f64, p: f64, samples: u64) -> f64 {
    let n = samples.max(1) as f64;
    e / (p.max(1.0 / n) / n).sqrt()
}

/// Per bin, what [`refine`] knows of its error: the estimate a verdict is held to (the
/// |fine − coarse| of parts accepted unconverged summed, plus those of converged parts summed in
/// quadrature: each is a bound on a part's error of either sign, and their plain sum over the
/// k parts of a finely split bin grows as k while the error of the bin grows as √k), the plain
/// sum of every part's (`error_estimate`), and the parts accepted unconverged.
struct Bins {
    error: Vec<f64>,
    linear: Vec<f64>,
    unconverged: Vec<u64>,
    leaves: Vec<Leaf>,
}

/// A part whose 5 × 5 value was summed into its bin's integral (an accepted initial part, or each
/// of the four quarters accepted together), with that value: the fixed partition on which
/// [`sensitivity`] integrates a perturbed pdf.
#[derive(Clone, Copy)]
pub(super) struct Leaf {
    rect: Rect,
    bin: u32,
    value: f64,
}

/// Integrates `pending`, the initial parts of `bins` bins, refining each as the module doc says
/// down to `max_depth`; with each bin's error estimate and its parts accepted unconverged.
fn refine(f: &dyn Integrand, mut pending: Vec<Part>, bins: usize, samples: u64, max_depth: u32, jumps: Jumps) -> Result<(Integrals, Bins), CheckError> {
    let n = samples.max(1) as f64;
    let rounding = f.rounding();
    let tolerance = |v: f64, n: f64| tolerance(v, n, rounding);
    let mut out = Integrals::zero(bins);
    // per bin: the errors of parts accepted unconverged, summed, and of converged parts, squared
    let mut bin_error = vec![0.0; bins];
    let mut bin_converged_sq = vec![0.0; bins];
    let mut bin_linear = vec![0.0; bins];
    let mut bin_unconverged = vec![0u64; bins];
    let mut leaves = Vec::new();
    while !pending.is_empty() {
        out.rounds += 1;
        out.parts += pending.len() as u64;
        let rects: Vec<Rect> = pending.iter().map(Part::rect).collect();
        let (values, edges): (Vec<[f64; 4]>, Vec<Option<f64>>) = f.rules(&rects)?.into_iter().unzip();
        // a part where the support has an edge holding more than the tolerance is split on to
        // [`EDGE_DEPTH`] levels past `max_depth`, whatever its rules say: across a jump the two
        // rules (and a part and its quarters) can agree on a wrong value, and a corner of the
        // support can lie beyond every node (a uniform cap of 0.05 rad: ∫pdf 0.99967)
        let edged = |k: usize, depth: u32| jumps == Jumps::Locate && depth < max_depth + EDGE_DEPTH && edges[k].is_some_and(|scale| scale > tolerance(scale, n));
        let mut next = Vec::new();
        let mut accept = |out: &mut Integrals, part: &Part, pdf: f64, eval: f64, err: f64, converged: bool| {
            out.probabilities[part.bin as usize] += pdf;
            out.eval[part.bin as usize] += eval;
            bin_linear[part.bin as usize] += err;
            if converged {
                bin_converged_sq[part.bin as usize] += err * err;
            } else {
                bin_error[part.bin as usize] += err;
            }
        };
        let bad = |v: &[f64; 4]| !(v[0].is_finite() && v[1].is_finite() && v[0] >= 0.0 && v[1] >= 0.0);
        let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
        let room = |len: usize| len + 4 <= MAX_PARTS;
        let mut i = 0;
        while i < pending.len() {
            let part = pending[i];
            match part.coarse {
                None => {
                    let v = values[i];
                    let [p5, p3, e5, e3] = v;
                    if bad(&v) {
                        out.bad_parts += 1;
                        out.dropped[part.bin as usize] += finite(v[0]);
                    } else if (!edged(i, part.depth) && (p5 - p3).abs() <= tolerance(p5, n) && (e5 - e3).abs() <= tolerance(e5, n)) || !room(next.len()) {
                        let converged = (p5 - p3).abs() <= tolerance(p5, n);
                        bin_unconverged[part.bin as usize] += u64::from(!converged);
                        accept(&mut out, &part, p5, e5, (p5 - p3).abs(), converged);
                        leaves.push(Leaf { rect: part.rect(), bin: part.bin, value: p5 });
                    } else {
                        next.extend(part.quarters((p5, e5)));
                    }
                    i += 1;
                }
                Some((cp, ce)) => {
                    // four consecutive quarters of one parent
                    let group = &values[i..i + 4];
                    if group.iter().any(bad) {
                        out.bad_parts += 1;
                        out.dropped[part.bin as usize] += group.iter().map(|v| finite(v[0])).sum::<f64>();
                        i += 4;
                        continue;
                    }
                    let fine: f64 = group.iter().map(|v| v[0]).sum();
                    let fine_e: f64 = group.iter().map(|v| v[2]).sum();
                    let agree = (fine - cp).abs() <= tolerance(fine, n) && (fine_e - ce).abs() <= tolerance(fine_e, n);
                    let edge = (i..i + 4).any(|k| edged(k, part.depth));
                    if (agree && !edge) || (part.depth >= max_depth && !edge) || !room(next.len() + 12) {
                        bin_unconverged[part.bin as usize] += u64::from(!agree);
                        accept(&mut out, &part, fine, fine_e, (fine - cp).abs(), agree);
                        leaves.extend(pending[i..i + 4].iter().zip(group).map(|(q, v)| Leaf { rect: q.rect(), bin: q.bin, value: v[0] }));
                    } else {
                        for (k, q) in pending[i..i + 4].iter().enumerate() {
                            next.extend(q.quarters((group[k][0], group[k][2])));
                        }
                    }
                    i += 4;
                }
            }
        }
        pending = next;
    }
    out.unconverged_parts = bin_unconverged.iter().sum();
    out.error_estimate = bin_linear.iter().sum();
    for (e, sq) in bin_error.iter_mut().zip(&bin_converged_sq) {
        *e += sq.sqrt();
    }
    out.max_error_sigma = bin_error.iter().zip(&out.probabilities).map(|(e, p)| sigmas(*e, *p, samples)).fold(0.0, f64::max);
    Ok((out, Bins { error: bin_error, linear: bin_linear, unconverged: bin_unconverged, leaves }))
}

/// ∫ f(d) dω over the unit sphere ([`WgslIntegrand::integrate`], [`sphere_integral_f64`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereIntegral {
    pub value: f64,
    /// Σ over parts of the accepted |fine − coarse| differences.
    pub error_estimate: f64,
    /// Parts accepted at the depth limit without agreeing.
    pub unconverged_parts: u64,
    /// Parts whose integral came out NaN, infinite or negative (left out of `value`).
    pub bad_parts: u64,
    /// Parts evaluated in all.
    pub parts: u64,
}

/// A sphere integral's parts: per hemisphere, bands of a = 1 − |cos θ| doubling away from the
/// pole, [0, 2⁻³⁰], [2⁻³⁰, 2⁻²⁹], …, [2⁻⁷, 2⁻⁶], then 2⁶ − 1 even bands of 2⁻⁶ to the equator,
/// each cut into `AZIMUTH_PARTS` in φ. A peak at a pole of width w (a ≈ w²/2) then starts on
/// parts of its own size in a, which bins uniform in cos θ reach only past [`MAX_DEPTH`] for w
/// below ~10⁻² (a microfacet D with α = 10⁻³); the even bands keep the parts away from the pole
/// small, where a kink such as max(0, ω·h)'s crosses them.
const POLE_BANDS: i32 = 30;
const EVEN_BANDS: i32 = 6;
const AZIMUTH_PARTS: u32 = 64;

/// The sample count of the tolerance (module doc) for a sphere integral: 10¹², a part's
/// tolerance 10⁻⁸ √(its integral) plus the rounding of its sum (f32's 2·10⁻⁶ on the GPU).
const SPHERE_SAMPLES: u64 = 1_000_000_000_000;

fn graded_parts() -> Vec<Part> {
    let step = 2f64.powi(-EVEN_BANDS);
    let graded = (0..POLE_BANDS - EVEN_BANDS).map(|k| 2f64.powi(k - POLE_BANDS));
    let even = (1..=1 << EVEN_BANDS).map(|k| k as f64 * step);
    let edges: Vec<f64> = std::iter::once(0.0).chain(graded).chain(even).collect();
    let dphi = std::f64::consts::TAU / AZIMUTH_PARTS as f64;
    let mut parts = Vec::new();
    for h in [1.0f32, -1.0] {
        for band in edges.windows(2) {
            for j in 0..AZIMUTH_PARTS {
                let b = (-std::f64::consts::PI + j as f64 * dphi, -std::f64::consts::PI + (j + 1) as f64 * dphi);
                parts.push(Part { a: (band[0], band[1]), b, h, radial: Radial::A, bin: 0, depth: 0, coarse: None });
            }
        }
    }
    parts
}

fn sphere_integral(f: &dyn Integrand) -> Result<SphereIntegral, CheckError> {
    let (i, _) = refine(f, graded_parts(), 1, SPHERE_SAMPLES, MAX_DEPTH, Jumps::Trust)?;
    Ok(SphereIntegral { value: i.probabilities[0], error_estimate: i.error_estimate, unconverged_parts: i.unconverged_parts, bad_parts: i.bad_parts, parts: i.parts })
}

/// ∫ f(d) dω over the unit sphere in f64 on the CPU, by the rules and parts of [`WgslIntegrand`].
///
/// ```
/// use lobes::check::quadrature::sphere_integral_f64;
/// // ∫ max(0, cos θ) dω = π
/// let i = sphere_integral_f64(&|d| d.z.max(0.0));
/// assert!((i.value - std::f64::consts::PI).abs() < 1e-12);
/// ```
pub fn sphere_integral_f64(f: &(dyn Fn(glam::DVec3) -> f64 + Send + Sync)) -> SphereIntegral {
    sphere_integral(&CpuPdf { pdf: f, domain: Domain::Sphere, jumps: Jumps::Trust }).expect("the CPU rules do not fail")
}

/// A WGSL function `fn name(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32`
/// (the signature of `lobes check`'s pdf), compiled once with lobes' quadrature pass and
/// integrated over the unit sphere in d on the GPU, in f32, for any `params` and `wi`.
///
/// ```no_run
/// use lobes::check::{Source, quadrature::WgslIntegrand};
/// let gpu = lobes::engine::gpu::Gpu::new()?;
/// // the cosine density max(0, cos θ) / π integrates to 1
/// let text = "fn cosine(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 { return max(d.z, 0.0) / 3.14159265; }";
/// let f = WgslIntegrand::new(&gpu, vec![Source { name: "cosine.wgsl".into(), text: text.into() }], "cosine")?;
/// assert!((f.integrate(&[], glam::DVec3::Z)?.value - 1.0).abs() < 1e-5);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct WgslIntegrand<'g> {
    passes: Passes<'g>,
}

/// The sampler the passes' module needs to compose (it holds every pass); the quadrature pass
/// never calls it.
const UNSAMPLED: &str = "quadrature_integrand_unsampled";

impl<'g> WgslIntegrand<'g> {
    /// Composes `sources` (which define `function`) with the quadrature pass; errors point at
    /// the sources' file:line:column as `lobes check`'s do.
    pub fn new(gpu: &'g Gpu, mut sources: Vec<Source>, function: &str) -> Result<Self, CheckError> {
        sources.push(Source {
            name: "the quadrature's unused sampler (src/check/quadrature.rs)".into(),
            text: format!("fn {UNSAMPLED}(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{ return vec4<f32>(0.0); }}\n"),
        });
        let sampler = UserSampler { sources, sample: UNSAMPLED.into(), pdf: function.into(), eval: None, domain: Domain::Sphere, conventions: Default::default(), composition: Default::default() };
        sampler.validate()?;
        Ok(Self { passes: Passes::new(gpu, &gpu::compose(&sampler)?)? })
    }

    /// ∫ function(wi, d, params) dω(d) over the unit sphere; `params` are at most 16 numbers,
    /// zero-padded into `params: array<vec4<f32>, 4>` as `lobes check --params` are.
    pub fn integrate(&self, params: &[f64], wi: glam::DVec3) -> Result<SphereIntegral, CheckError> {
        if params.len() > MAX_PARAMS {
            return Err(CheckError::Input(format!("{} params given, at most {MAX_PARAMS} fit `params: array<vec4<f32>, 4>`", params.len())));
        }
        let mut p: Params = bytemuck::Zeroable::zeroed();
        for (i, v) in params.iter().enumerate() {
            p.user[i / 4][i % 4] = *v as f32;
        }
        p.wi = [wi.x as f32, wi.y as f32, wi.z as f32, 0.0];
        sphere_integral(&(&self.passes, &p))
    }
}

/// `x` one ulp farther from 0 (`outward`) or nearer to it; 0 and non-finite values as they are.
fn ulp_step(x: f32, outward: bool) -> f32 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    f32::from_bits(if outward { x.to_bits() + 1 } else { x.to_bits() - 1 })
}

/// The check's parameters with the pdf's inputs moved by an ulp, for [`sensitivity`]: wi a
/// rounding longer (every component outward), wi turned by about an ulp (x and y outward, z
/// inward), and where the user's numbers hold a non-integer (a roughness, an asymmetry g), those
/// one ulp outward and one inward. Integers (an exponent, a mode flag) stay as they are: an ulp
/// would turn a flag into another pdf, and an exponent's ulp moves nothing a rounding does not.
pub(super) fn perturbed_params(p: &Params) -> Vec<Params> {
    let turn = |signs: [bool; 3]| {
        let mut q = *p;
        for (c, outward) in signs.into_iter().enumerate() {
            q.wi[c] = ulp_step(p.wi[c], outward);
        }
        q
    };
    let mut out = vec![turn([true; 3]), turn([true, true, false])];
    if p.user.iter().flatten().any(|x| x.fract() != 0.0) {
        for outward in [true, false] {
            let mut q = *p;
            for x in q.user.iter_mut().flatten() {
                if x.fract() != 0.0 {
                    *x = ulp_step(*x, outward);
                }
            }
            out.push(q);
        }
    }
    out
}

/// [`sensitivity`] of the WGSL pdf on the GPU at `params` ([`perturbed_params`]).
pub(super) fn f32_sensitivity(passes: &Passes, params: &Params, leaves: &[Leaf]) -> Result<f64, CheckError> {
    let perturbed = perturbed_params(params);
    let integrands: Vec<(&Passes, &Params)> = perturbed.iter().map(|q| (passes, q)).collect();
    let dynamic: Vec<&dyn Integrand> = integrands.iter().map(|i| i as &dyn Integrand).collect();
    sensitivity(&dynamic, leaves)
}
