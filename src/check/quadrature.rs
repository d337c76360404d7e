//! The expected histogram of a user's sampler: each bin's integral of the user's WGSL pdf (and of
//! its eval) on the GPU, or of an f64 reference on the CPU, by the adaptive Gauss–Legendre
//! quadrature of [`crate::stats::quadrature`] (its rules, parts, tolerance, edges and poles),
//! with the tolerance a hundredth of a bin count's standard deviation at the run's sample count
//! N, 0.01 √(p/N), plus a thousandth of one count, plus the rounding of the sum (f32's 2·10⁻⁶ p
//! on the GPU): the quadrature error stays far below the statistical error of the histogram it is
//! compared with. A fixed rule is not enough: a lobe narrower than a bin slips between its nodes
//! (Mitsuba's fixed trapezoid rule fails correct peaked samplers for that reason).
//!
//! **No verdict from an unconverged quadrature.** A bin's error estimate (its accepted
//! |fine − coarse| differences) is held to [`MAX_QUADRATURE_SIGMA`] of its count's standard
//! deviation at N, as `lobes run` holds its f64 reference. The bins beyond it are integrated
//! again from an initial split [`REFINE_FACTOR`] times finer per axis and [`MAX_DEPTH`] + 2
//! levels deep, up to [`RETRIES`] times, and keep the new values; where a bin is still beyond it
//! ([`Integrals::converged`] says so) `lobes check` draws no verdict (exit 3).
//!
//! **Jumps and poles.** The parts of a histogram locate the edges of the pdf's support
//! ([`Jumps::Locate`], [`EDGE_DEPTH`] levels past [`MAX_DEPTH`]), and a part at a pole is
//! integrated in s = √a ([`Rect`]), where a pdf ∝ 1/sin θ is smooth.
//!
//! Sphere bins are integrated over (a, φ) with a = 1 − |cos θ| per hemisphere (see
//! `lobes_domain_point`), so that parts next to a pole keep their f32 resolution, and with φ
//! measured from the axis nearest the part (`rect_f32`), so that an edge on an axis (the seam
//! above all) is exactly where `lobes check`'s binning puts it.
//!
//! The same rules integrate a function over the whole sphere ([`WgslIntegrand`] on the GPU,
//! [`sphere_integral_f64`] on the CPU), from parts graded toward the poles rather than a
//! histogram's bins: what the microfacet identities of `tests/microfacet_identities.rs` need.

use super::gpu::{Params, Passes};

use super::{CheckError, Domain, MAX_PARAMS, Message, Setting, Source, UserSampler};
use crate::engine::gpu::Gpu;
pub use crate::stats::expected::MAX_QUADRATURE_SIGMA;
use crate::stats::domain::{Cell, SQRT_PI};
use crate::stats::histogram::SphereGrid;
pub use crate::stats::quadrature::{CpuPdf, EDGE_DEPTH, Integrand, Jumps, Leaf, Rect, SphereIntegral, sphere_integral_f64};
pub use crate::stats::quadrature::Witnesses;
use crate::stats::quadrature::{Part, Radial, Refined, Rules, Settings, Tolerance, refine, row_zones, sphere_integral, split, z_zones};
use serde::{Deserialize, Serialize};

/// Deepest split of a part (a quarter per level).
pub const MAX_DEPTH: u32 = 8;
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
    /// Bins where the pdf's support proved narrower than their parts' nodes (most of the bin's
    /// integral was found only below parts split for a witness, [`Witnesses`]) and whose observed count exceeds the
    /// integral by more than [`HIDDEN_SIGMA`] standard deviations: the parts that held no
    /// witness may hide mass that no rule sees (the tapering tip of a sliver of a light), so such
    /// a bin, left after the bins of such a support were integrated again with denser witnesses
    /// ([`Evidence::denser`]), gives no verdict ([`Integrals::support_seen`]).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub hidden_support_bins: u64,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

/// How many standard deviations of its count a bin whose support is narrower than its parts'
/// nodes may hold above its integral before it gives no verdict: past the largest excess that
/// chance gives a correct sampler on a grid of 10⁵ bins (P(Z > 5) = 2.9·10⁻⁷ a bin).
pub const HIDDEN_SIGMA: f64 = 5.0;

impl Integrals {
    /// `Err` with what is wrong where a bin's error estimate is beyond [`MAX_QUADRATURE_SIGMA`] of
    /// its count's standard deviation at `samples` (after the retries of `integrate`): expected
    /// counts that uncertain give no verdict, neither a pass nor a fail.
    ///
    /// ```
    /// use lobes::check::quadrature::Integrals;
    /// let mut i = Integrals { probabilities: vec![0.5, 0.5], eval: vec![0.0; 2], error_estimate: 0.0, max_error_sigma: 0.05,
    ///     unconverged_parts: 0, bad_parts: 0, dropped: vec![], parts: 2, rounds: 1, hidden_support_bins: 0 };
    /// assert!(i.converged(1_000_000).is_ok());
    /// i.max_error_sigma = 2.0;
    /// assert!(i.converged(1_000_000).unwrap_err().to_string().contains("no verdict"));
    /// ```
    pub fn converged(&self, samples: u64) -> Result<(), Message> {
        if self.max_error_sigma <= MAX_QUADRATURE_SIGMA {
            return Ok(());
        }
        let what = format!(
            "the quadrature of the pdf did not converge: a bin's error estimate is {:.3}σ of its count at {samples} samples (at most {MAX_QUADRATURE_SIGMA}σ gives a verdict; {} parts accepted at the depth limit or the parts' budget after {RETRIES} finer retries), so no verdict is drawn; a pdf with an edge or a peak narrower than the quadrature resolves (a small cone, a near-delta lobe) needs fewer ",
            self.max_error_sigma, self.unconverged_parts
        );
        Err(Message::text(what).setting(Setting::Samples).then(" or more ").setting(Setting::Bins))
    }

    /// `Err` with what is wrong where [`Integrals::hidden_support_bins`] holds a bin: its
    /// expected count may lack mass that the nodes did not see, and its excess decides nothing.
    ///
    /// ```
    /// use lobes::check::quadrature::Integrals;
    /// let mut i = Integrals { probabilities: vec![1.0], eval: vec![0.0], error_estimate: 0.0, max_error_sigma: 0.0,
    ///     unconverged_parts: 0, bad_parts: 0, dropped: vec![], parts: 1, rounds: 1, hidden_support_bins: 0 };
    /// assert!(i.support_seen().is_ok());
    /// i.hidden_support_bins = 2;
    /// assert!(i.support_seen().unwrap_err().to_string().contains("no verdict"));
    /// ```
    pub fn support_seen(&self) -> Result<(), Message> {
        if self.hidden_support_bins == 0 {
            return Ok(());
        }
        let what = format!(
            "the quadrature cannot see all of the pdf's support: in {} bin{} it is narrower than the quadrature's nodes (found only about the samples, as a sliver of a light and its tapering tips are) and there the samples exceed the integral by over {HIDDEN_SIGMA}σ, mass the nodes may have missed; the checks that read no integral pass, so no verdict is drawn; fewer ",
            self.hidden_support_bins,
            if self.hidden_support_bins == 1 { "" } else { "s" }
        );
        Err(Message::text(what).setting(Setting::Bins).then(" or fewer ").setting(Setting::Samples))
    }
}

/// Relative rounding of a part's sum on the GPU (25 f32 terms).
pub const GPU_ROUNDING: f64 = 2e-6;

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

impl Integrand<CheckError> for (&Passes<'_>, &Params) {
    fn rules(&self, rects: &[Rect]) -> Result<Vec<Rules>, CheckError> {
        let rects32: Vec<([f32; 4], [f32; 3])> = rects.iter().map(rect_f32).collect();
        Ok(self.0.integrate(self.1, &rects32)?.into_iter().map(|[v, e]| (v.map(f64::from), (e[0] != 0.0).then_some(e[1] as f64))).collect())
    }
    fn rounding(&self) -> f64 {
        GPU_ROUNDING
    }
    fn fine_pdf(&self, rects: &[Rect]) -> Result<Vec<f64>, CheckError> {
        let rects32: Vec<([f32; 4], [f32; 3])> = rects.iter().map(rect_f32).collect();
        Ok(self.0.integrate_pdf(self.1, &rects32)?.into_iter().map(f64::from).collect())
    }
}


/// The widest initial part on the sphere (radians): a sixteenth of a radian. A lobe's width from
/// its peak density, 0.5/√p_max, is an isotropic lobe's; a 50:1 anisotropic one (GGX α (2, 0.04)
/// at θi 10°) is a ridge far narrower than that across, and where it crosses the tall bins next
/// to a pole (0.25 rad in θ at 64 rows) the 5 × 5 and 3 × 3 rules of one part agreed on a value
/// 16 % low (∫pdf 0.99958, measured on lavapipe; split to at most 1/16 rad, 1.000000).
pub const MAX_SPHERE_WIDTH: f64 = 0.0625;

/// Initial parts per row of a grid fitted to a small support ([`Domain::Cap`]), along θ at least.
/// The support's edge crosses the cap's bins, and 0.5/√p_max says nothing of its shape: a
/// uniform light's is about its own radius. A bin of the outermost row holding a corner of a
/// spherical triangle of 10⁻² sr on the horizon, as one part, had its corner's wedge (a quarter
/// of the bin wide) fall between all 42 of the edge detector's points: 19 % of the bin's mass
/// lost, ∫pdf 0.999954 against 1 and a false `normalization` FAIL at 2¹⁸ samples (a 64 × 64
/// split of the bin: 93.9 samples expected, 102 seen, 76.3 before).
pub const CAP_PARTS_PER_ROW: f64 = 4.0;

/// The width the bins are first split to: 0.5/√p_max (p_max the largest pdf the probes reported),
/// within [10⁻⁴, 1], at most [`MAX_SPHERE_WIDTH`] on the sphere and, on a cap of `rows` rows, a
/// [`CAP_PARTS_PER_ROW`]th of a row's mean extent in θ.
pub(super) fn initial_width(p_max: f64, domain: Domain, rows: u32) -> f64 {
    let width = if p_max > 0.0 { (0.5 / p_max.sqrt()).clamp(1e-4, 1.0) } else { 0.1 };
    if !domain.directions() {
        return width;
    }
    let row = domain.cap_radius().map_or(f64::INFINITY, |radius| radius / (CAP_PARTS_PER_ROW * rows as f64));
    width.min(MAX_SPHERE_WIDTH).min(row)
}

/// A bin's piece before its split: (a range, b range, hemisphere, initial split per axis).
type Piece = ((f64, f64), (f64, f64), f32, u32);

/// The parts a bin starts as: on the sphere its (a, φ) rectangle per hemisphere it touches,
/// each split `m × m` where `m` is its angular extent over `width`, at most `cap`; only the
/// bins `only` marks, where given.
fn initial_parts(domain: &Domain, rows: u32, cols: u32, width: f64, cap: u32, only: Option<&[bool]>) -> Vec<Part> {
    let mut parts = Vec::new();
    let m = |extent: f64| ((extent / width).ceil() as u32).clamp(1, cap);
    let grid = domain.grid(rows, cols);
    for bin in 0..grid.bins() as u32 {
        if only.is_some_and(|o| !o[bin as usize]) {
            continue;
        }
        let mut pieces: Vec<Piece> = Vec::new();
        match grid.cell(bin as usize) {
            Cell::Plane { x, y } => pieces.push((x, y, 0.0, m((x.1 - x.0).max(y.1 - y.0)))),
            Cell::Sphere { row, phi } => {
                for z in row_zones(rows, row) {
                    pieces.push((z.a, phi, z.h, m(z.extent(phi))));
                }
            }
            // a texel's band of θ per hemisphere it touches, cos θ as sin(π/2 − θ) (0 at the equator)
            Cell::LatLong { theta, phi } => {
                let z = |t: f64| (std::f64::consts::FRAC_PI_2 - t).sin();
                for z in z_zones(z(theta.1), z(theta.0)) {
                    pieces.push((z.a, phi, z.h, m(z.extent(phi))));
                }
            }
            // a texel of an equal-area map in (a, b) = √π (s, t), whose area is its solid angle,
            // cut where it straddles an axis (the map's derivative jumps there)
            Cell::EqualArea { s, t } => {
                let cut = |(lo, hi): (f64, f64)| if lo < 0.0 && hi > 0.0 { vec![(lo, 0.0), (0.0, hi)] } else { vec![(lo, hi)] };
                let scaled = |(lo, hi): (f64, f64)| (SQRT_PI * lo, SQRT_PI * hi);
                for (s, t) in cut(s).into_iter().flat_map(|s| cut(t).into_iter().map(move |t| (s, t))) {
                    let (a, b) = (scaled(s), scaled(t));
                    pieces.push((a, b, 0.0, m((a.1 - a.0).max(b.1 - b.0))));
                }
            }
            // a cap's cell is one piece about its axis, as a sphere's row about the pole (h = 1)
            Cell::Cap { a, phi } => {
                let theta = |a: f64| 2.0 * (0.5 * a).sqrt().asin();
                let smax = (a.1 * (2.0 - a.1)).max(0.0).sqrt();
                pieces.push((a, phi, 1.0, m((theta(a.1) - theta(a.0)).max((phi.1 - phi.0) * smax))));
            }
        }
        for (a, b, h, m) in pieces {
            parts.extend(split(a, b, h, m, bin));
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
/// Parts whose rules both give 0 where a probed sample fell are split too ([`Witnesses`]).
/// [`Integrals::converged`] says whether any bin is left beyond the limit.
pub(super) fn integrate(f: &dyn Integrand<CheckError>, domain: &Domain, rows: u32, cols: u32, width: f64, samples: u64, evidence: Option<&Evidence>) -> Result<Integrals, CheckError> {
    Ok(integrate_leaves(f, domain, rows, cols, width, samples, evidence)?.0)
}

/// What the run's samples say of where the pdf's mass lies: the histogram's counts per bin, and
/// the points of samples drawn for the purpose ([`Witnesses`]); and, where given, denser
/// witnesses drawn for the bins it is asked for.
pub struct Evidence<'a> {
    pub observed: &'a [u64],
    pub witnesses: Witnesses,
    pub denser: Option<Denser<'a>>,
}

/// What draws denser witnesses for the bins a mask marks ([`Evidence::denser`]).
pub type Denser<'a> = &'a dyn Fn(&[bool]) -> Result<Witnesses, CheckError>;

/// [`integrate`], with the parts its integrals are the sum of ([`Leaf`]).
pub(super) fn integrate_leaves(f: &dyn Integrand<CheckError>, domain: &Domain, rows: u32, cols: u32, width: f64, samples: u64, evidence: Option<&Evidence>) -> Result<(Integrals, Vec<Leaf>), CheckError> {
    let bins = (rows * cols) as usize;
    let (observed, witnesses) = (evidence.map(|e| e.observed), evidence.map(|e| &e.witnesses));
    let mut out = refine(f, initial_parts(domain, rows, cols, width, MAX_INITIAL_SPLIT, None), bins, &settings(samples, MAX_DEPTH, witnesses))?;
    for retry in 1..=RETRIES {
        let factor = REFINE_FACTOR.pow(retry);
        let cap = MAX_INITIAL_SPLIT * factor;
        let Some(over) = again(&out, domain.grid(rows, cols), cap, samples, observed) else { break };
        let parts = initial_parts(domain, rows, cols, width / factor as f64, cap, Some(&over));
        let again = refine(f, parts, bins, &settings(samples, MAX_DEPTH + 2 * retry, witnesses))?;
        replace_bins(&mut out, again, &over);
    }
    // a support narrower than the nodes whose samples exceed its integral: every bin where such
    // a support was found integrated again, as far as witnesses 64 times denser lead (the tip of
    // a tapering sliver, which 2¹⁶ of them miss)
    if let Some((denser, observed)) = evidence.and_then(|e| e.denser.map(|d| (d, e.observed)))
        && (0..bins).any(|i| hides_support(&out, i, samples, Some(observed)))
    {
        let hidden: Vec<bool> = out.hidden.iter().map(|&h| h > 0.0).collect();
        let dense = denser(&hidden)?;
        let parts = initial_parts(domain, rows, cols, width, MAX_INITIAL_SPLIT, Some(&hidden));
        let again = refine(f, parts, bins, &settings(samples, MAX_DEPTH + 2 * RETRIES, Some(&dense)))?;
        replace_bins(&mut out, again, &hidden);
    }
    let leaves = std::mem::take(&mut out.leaves);
    Ok((integrals(out, samples, observed), leaves))
}

/// `out` with the bins `over` marks (their integrals and leaves) taken from `again`.
fn replace_bins(out: &mut Refined, again: Refined, over: &[bool]) {
    for i in (0..over.len()).filter(|&i| over[i]) {
        out.pdf[i] = again.pdf[i];
        out.eval[i] = again.eval[i];
        out.error[i] = again.error[i];
        out.linear[i] = again.linear[i];
        out.unconverged[i] = again.unconverged[i];
        out.dropped[i] = again.dropped[i];
        out.hidden[i] = again.hidden[i];
    }
    out.leaves.retain(|l| !over[l.bin as usize]);
    out.leaves.extend(again.leaves.into_iter().filter(|l| over[l.bin as usize]));
    out.parts += again.parts;
    out.bad_parts = out.bad_parts.max(again.bad_parts);
    out.rounds += again.rounds;
}

/// Whether bin `i` found most of its integral only below witnessed parts (its support is
/// narrower than the nodes it started with; a part just outside a wide support's edge finds a
/// little) and its count exceeds the integral by more than [`HIDDEN_SIGMA`] standard deviations.
fn hides_support(r: &Refined, i: usize, samples: u64, observed: Option<&[u64]>) -> bool {
    let n = samples.max(1) as f64;
    let excess = observed.map_or(0.0, |o| (o[i] as f64 - n * r.pdf[i]) / (n * r.pdf[i]).max(1.0).sqrt());
    r.hidden[i] > 0.5 * r.pdf[i] && excess > HIDDEN_SIGMA
}

/// The settings of a histogram's parts at `samples` samples (the module doc's tolerance), to
/// `max_depth`, keeping the accepted parts, with the run's `witnesses`.
fn settings(samples: u64, max_depth: u32, witnesses: Option<&Witnesses>) -> Settings<'_> {
    let n = samples.max(1) as f64;
    Settings { tolerance: Tolerance { sigma_fraction: 0.01, samples: n, floor: 1e-3 / n }, max_depth, jumps: Jumps::Locate, max_parts: MAX_PARTS, keep_leaves: true, witnesses }
}

/// The bins to integrate again from an initial split of at most `cap` per axis: those beyond
/// [`MAX_QUADRATURE_SIGMA`], those with no probability where `observed` has samples, then the
/// disputed ones with their eight neighbours (a ridge goes on into them), the most disputed first,
/// as far as the parts' budget goes; `None` where there are none, or more than the budget holds.
fn again(out: &Refined, grid: crate::stats::domain::Grid, cap: u32, samples: u64, observed: Option<&[u64]>) -> Option<Vec<bool>> {
    let n = samples.max(1) as f64;
    let unseen = |i: usize, p: f64| observed.is_some_and(|o| o[i] > 0) && p <= 0.0;
    // |observed − expected| in standard deviations (at least one count), 0 without a histogram
    let dispute = |i: usize, p: f64| observed.map_or(0.0, |o| (o[i] as f64 - n * p).abs() / (n * p).max(1.0).sqrt());
    // at most (cap)² parts per hemisphere of a bin, so the parts' budget holds `room` bins
    let room = MAX_PARTS / (2 * (cap * cap) as usize);
    let mut over: Vec<bool> = out.error.iter().zip(&out.pdf).enumerate().map(|(i, (e, p))| sigmas(*e, *p, samples) > MAX_QUADRATURE_SIGMA || unseen(i, *p)).collect();
    let must = over.iter().filter(|o| **o).count();
    if must > room {
        return None;
    }
    let mut disputed: Vec<(f64, usize)> = (0..out.pdf.len()).map(|i| (dispute(i, out.pdf[i]), i)).filter(|(z, _)| *z > DISPUTED_SIGMA).collect();
    disputed.sort_by(|x, y| y.0.total_cmp(&x.0));
    let mut added = 0;
    'disputed: for &(_, i) in &disputed {
        for j in grid.neighbourhood(i) {
            if added >= (room - must).min(MAX_DISPUTED) {
                break 'disputed;
            }
            if !over[j] {
                over[j] = true;
                added += 1;
            }
        }
    }
    over.contains(&true).then_some(over)
}

/// The integrals per bin of `r` and what their accuracy is at `samples` samples, against the
/// histogram's counts `observed` where given.
fn integrals(r: Refined, samples: u64, observed: Option<&[u64]>) -> Integrals {
    let hidden_support_bins = (0..r.pdf.len()).filter(|&i| hides_support(&r, i, samples, observed)).count() as u64;
    let dropped = if r.dropped.iter().all(|d| *d == 0.0) { Vec::new() } else { r.dropped };
    Integrals {
        hidden_support_bins,
        max_error_sigma: r.error.iter().zip(&r.pdf).map(|(e, p)| sigmas(*e, *p, samples)).fold(0.0, f64::max),
        error_estimate: r.linear.iter().sum(),
        unconverged_parts: r.unconverged.iter().sum(),
        probabilities: r.pdf,
        eval: r.eval,
        bad_parts: r.bad_parts,
        dropped,
        parts: r.parts,
        rounds: r.rounds,
    }
}

/// How far the integral over `leaves` moves when the pdf is evaluated by each integrand of
/// `perturbed` (the same pdf at inputs a few ulps off) instead of the one that gave the leaves'
/// values: the largest |Σ (perturbed − value)| over the leaves where both are finite and ≥ 0. On a
/// fixed partition the quadrature's own error cancels, and what is left is what the f32
/// evaluation of the pdf does to the integral, coherent errors (a reflected axis a rounding
/// longer than 1, a constant rounded in a subexpression) included, incoherent ones averaged as
/// the integral averages them.
pub(super) fn sensitivity(perturbed: &[&dyn Integrand<CheckError>], leaves: &[Leaf]) -> Result<f64, CheckError> {
    let rects: Vec<Rect> = leaves.iter().map(|l| l.rect).collect();
    let mut worst: f64 = 0.0;
    for f in perturbed {
        let values = f.fine_pdf(&rects)?;
        let shift: f64 = leaves.iter().zip(&values).filter(|(l, v)| v.is_finite() && **v >= 0.0 && l.value.is_finite() && l.value >= 0.0).map(|(l, v)| v - l.value).sum();
        worst = worst.max(shift.abs());
    }
    Ok(worst)
}

/// How far a direction's f32 rounding may place it (radians): an ulp of 1, 2⁻²³, the step of a
/// unit vector's components and of the intermediates of magnitude about 1 that a light's pdf
/// forms from it (the point t d on the light, t d − s).
pub const DIRECTION_RESOLUTION: f64 = 1.0 / 8_388_608.0;

/// How far ∫pdf over `leaves` moves when every direction moves [`DIRECTION_RESOLUTION`] away
/// from the axis of the cap they lie on, or toward it: the larger |Σ (moved − value)|. Each part
/// is moved by da = sin θ δ (a = 1 − cos θ about the axis) with its measure kept, which moves a
/// support's edge across the nodes by δ: the mass within f32's resolution of the edge, about
/// (its length)·(the pdf there)·δ, which no ulp of the pdf's other inputs shows (a light's solid
/// angle is the same at every scale). A rectangle light of 10⁻⁴ sr overhead: its f32 pdf
/// integrates to 1.000020 (its f32 solid angle is within 2·10⁻⁷ of the f64 one: the rest is
/// where its edges are), a false `normalization` FAIL at 2²⁰ samples without this. Parts about
/// the axis (in s = √a) hold no edge of a support the cap was fitted around, and stay; so do
/// parts in which the edge detector saw no jump (the mass moved is the edge's: moving the parts
/// inside a support only moves its smooth pdf, and those were 84 % of the leaves of the
/// rectangle above, for 6 % of its figure).
pub(super) fn direction_sensitivity(f: &dyn Integrand<CheckError>, leaves: &[Leaf]) -> Result<f64, CheckError> {
    let moved = |delta: f64| -> Vec<Leaf> {
        leaves
            .iter()
            .filter(|l| l.edge)
            .map(|l| {
                let [a0, a1, ..] = l.rect.r;
                let da = if l.rect.radial == Radial::A { (0.5 * (a0 + a1) * (2.0 - 0.5 * (a0 + a1))).max(0.0).sqrt() * delta } else { 0.0 };
                let mut rect = l.rect;
                if a0 + da >= 0.0 {
                    rect.r[0] += da;
                    rect.r[1] += da;
                }
                Leaf { rect, ..*l }
            })
            .collect()
    };
    let mut worst: f64 = 0.0;
    for delta in [DIRECTION_RESOLUTION, -DIRECTION_RESOLUTION] {
        worst = worst.max(sensitivity(&[f], &moved(delta))?);
    }
    Ok(worst)
}


/// How far from a bin edge f32 may put a sample: from a column edge off the axes, the binning
/// (radians: the column ⌊(atan2(y, x) + π)/2π · cols⌋ rounds atan2, whose result near ±π steps
/// by 2.4·10⁻⁷, and t; measured within about 2·10⁻⁷ on lavapipe, taken as 2 ulps of π; edges
/// on an axis are exact, `lobes_axis_column`); from a row edge, the sampler's own rounding of
/// cos θ = d.z, a few ulps of 1 (a light whose edge lies in the plane of a row edge, as one lying
/// on the surface's plane does at cos θ = 0: its samples on that edge land on either side).
pub const EDGE_RESOLUTION: f64 = 5e-7;
/// An edge whose strip of ±[`EDGE_RESOLUTION`] holds more than this many standard deviations of
/// the smaller of its two bins' counts (what f32 may move across it, at worst) cannot be placed
/// by the binning as the quadrature places it; the χ² judges its two bins as one cell.
pub const EDGE_SIGMA: f64 = 0.3;

/// Per bin of the sphere grid, the pdf's integral over the strips within [`EDGE_RESOLUTION`] of
/// its left and lower edges: the samples that f32 may put on the other side of the edge than
/// the quadrature does.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeStrips {
    /// Of its left column edge, where that edge is off the axes (0 elsewhere).
    pub column: Vec<f64>,
    /// Of its lower row edge, where one bin beside it holds a count and the other none (0
    /// elsewhere, and in the bottom row).
    pub row: Vec<f64>,
}

/// The [`EdgeStrips`] of the sphere grid, where the bins beside an edge hold a count at N =
/// `samples` (0 elsewhere). By the same adaptive rules, each strip split along its edge like a
/// bin; the row strips' parts accumulate after the column strips' (bin + rows · cols).
pub(super) fn edge_strips(f: &dyn Integrand<CheckError>, rows: u32, cols: u32, width: f64, samples: u64, probabilities: &[f64]) -> Result<EdgeStrips, CheckError> {
    let bins = (rows * cols) as usize;
    let n = samples.max(1) as f64;
    let held = |i: u32, j: u32| n * (probabilities[i as usize] + probabilities[j as usize]) >= 1.0;
    let grid = SphereGrid { rows, cols };
    let (phi, z) = (grid.phi_edges(), grid.cos_theta_edges());
    let mut parts = Vec::new();
    for r in 0..rows {
        for c in (0..cols).filter(|&c| !grid.exact_phi_edge(c)).filter(|&c| held(r * cols + c, r * cols + c - 1)) {
            let b = (phi[c as usize] - EDGE_RESOLUTION, phi[c as usize] + EDGE_RESOLUTION);
            for zone in row_zones(rows, r) {
                let m = ((zone.dtheta / width).ceil() as u32).clamp(1, MAX_INITIAL_SPLIT);
                let da = (zone.a.1 - zone.a.0) / m as f64;
                for i in 0..m {
                    let a = (zone.a.0 + i as f64 * da, zone.a.0 + (i + 1) as f64 * da);
                    parts.push(Part { a, b, h: zone.h, radial: Radial::A, bin: r * cols + c, depth: 0, coarse: None, hidden: false });
                }
            }
        }
    }
    // a row edge between a bin with a count and one without: where a support's edge lies on it
    // (f32 moving samples between two bins that both hold counts is the column edges' case, of
    // the binning's atan2; the rows' cos θ = d.z is binned as the sampler rounded it)
    let bare = |i: u32| n * probabilities[i as usize] < 1.0;
    for r in 1..rows {
        let band = z_zones(z[r as usize] - EDGE_RESOLUTION, z[r as usize] + EDGE_RESOLUTION);
        for c in (0..cols).filter(|&c| held(r * cols + c, (r - 1) * cols + c) && bare(r * cols + c) != bare((r - 1) * cols + c)) {
            for zone in &band {
                let (b0, b1) = (phi[c as usize], phi[c as usize + 1]);
                let m = (((b1 - b0) * zone.smax / width).ceil() as u32).clamp(1, MAX_INITIAL_SPLIT);
                let db = (b1 - b0) / m as f64;
                for i in 0..m {
                    let b = (b0 + i as f64 * db, b0 + (i + 1) as f64 * db);
                    parts.push(Part { a: zone.a, b, h: zone.h, radial: Radial::A, bin: bins as u32 + r * cols + c, depth: 0, coarse: None, hidden: false });
                }
            }
        }
    }
    if parts.is_empty() {
        return Ok(EdgeStrips { column: vec![0.0; bins], row: vec![0.0; bins] });
    }
    let mut column = refine(f, parts, 2 * bins, &Settings { keep_leaves: false, ..settings(samples, MAX_DEPTH, None) })?.pdf;
    let row = column.split_off(bins);
    Ok(EdgeStrips { column, row })
}

/// The edges joined by [`join_unresolved_edges`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Joined {
    pub columns: usize,
    pub rows: usize,
}

/// The counts and expected counts the χ² judges: where an edge is closer to the pdf's mass than
/// f32 resolves ([`EDGE_SIGMA`] of its strip), the bins beside it as one cell (every bin of a
/// set so linked moved into its first), with the edges so joined. The choice depends on the pdf
/// alone, never on the counts, so the test stays a χ² test of a fixed partition.
pub fn join_unresolved_edges(counts: &[u64], expected: &[f64], strips: &EdgeStrips, rows: u32, cols: u32, samples: u64) -> (Vec<u64>, Vec<f64>, Joined) {
    let n = samples.max(1) as f64;
    let cols = cols as usize;
    let unresolved = |i: usize, j: usize, strip: f64| strip > 0.0 && n * strip > EDGE_SIGMA * expected[i].min(expected[j]).max(1.0).sqrt();
    let mut first: Vec<usize> = (0..counts.len()).collect();
    let mut joined = Joined::default();
    for i in 0..(rows as usize * cols) {
        if i % cols > 0 && unresolved(i, i - 1, strips.column[i]) {
            link(&mut first, i, i - 1);
            joined.columns += 1;
        }
        if i >= cols && unresolved(i, i - cols, strips.row[i]) {
            link(&mut first, i, i - cols);
            joined.rows += 1;
        }
    }
    let (mut judged_counts, mut judged_expected) = (vec![0; counts.len()], vec![0.0; counts.len()]);
    for i in 0..counts.len() {
        let k = root(&mut first, i);
        judged_counts[k] += counts[i];
        judged_expected[k] += expected[i];
    }
    (judged_counts, judged_expected, joined)
}

/// The first bin of the set `i` is in (a union–find forest whose roots are each set's least bin).
fn root(first: &mut [usize], mut i: usize) -> usize {
    while first[i] != i {
        first[i] = first[first[i]];
        i = first[i];
    }
    i
}

/// Puts the sets of bins `i` and `j` together.
fn link(first: &mut [usize], i: usize, j: usize) {
    let (a, b) = (root(first, i), root(first, j));
    first[a.max(b)] = a.min(b);
}

/// A bin's error `e` in units of its count's standard deviation √(N p) at N = `samples`, taken
/// as at least one count (as [`crate::stats::expected::Expected::max_error_sigma_at`]).
fn sigmas(e: f64, p: f64, samples: u64) -> f64 {
    let n = samples.max(1) as f64;
    e / (p.max(1.0 / n) / n).sqrt()
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
        Ok(Self { passes: Passes::new(gpu, &sampler)? })
    }

    /// ∫ function(wi, d, params) dω(d) over the unit sphere; `params` are at most 16 numbers,
    /// zero-padded into `params: array<vec4<f32>, 4>` as `lobes check --params` are.
    pub fn integrate(&self, params: &[f64], wi: glam::DVec3) -> Result<SphereIntegral, CheckError> {
        if params.len() > MAX_PARAMS {
            return Err(CheckError::Input(format!("{} params given, at most {MAX_PARAMS} fit `params: array<vec4<f32>, 4>`", params.len())));
        }
        let p = Params { user: Params::user_numbers(params), wi: [wi.x as f32, wi.y as f32, wi.z as f32, 0.0], ..bytemuck::Zeroable::zeroed() };
        sphere_integral::<CheckError>(&(&self.passes, &p))
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
    let dynamic: Vec<&dyn Integrand<CheckError>> = integrands.iter().map(|i| i as &dyn Integrand<CheckError>).collect();
    sensitivity(&dynamic, leaves)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bins joined across a column edge and a row edge form one cell in the first bin of the
    /// set, sums kept; an edge whose strip holds less than its bins' spread is left alone.
    #[test]
    fn unresolved_edges_join_their_bins() {
        // 3 × 3 bins; the edge left of bin 4 and the one below bin 7 unresolved, the one left of
        // bin 2 resolved (its strip under 0.3 σ of the smaller of bins 1 and 2)
        let counts: Vec<u64> = (1..=9).collect();
        let expected: Vec<f64> = vec![100.0; 9];
        let (mut column, mut row) = (vec![0.0; 9], vec![0.0; 9]);
        column[4] = 1e-2;
        row[7] = 1e-2;
        column[2] = 1e-6;
        let (c, e, joined) = join_unresolved_edges(&counts, &expected, &EdgeStrips { column, row }, 3, 3, 1000);
        assert_eq!(joined, Joined { columns: 1, rows: 1 });
        assert_eq!(c, vec![1, 2, 3, 4 + 5 + 8, 0, 6, 7, 0, 9]);
        assert_eq!(e.iter().sum::<f64>(), 900.0);
        assert_eq!((e[3], e[4], e[7]), (300.0, 0.0, 0.0));
    }
}
