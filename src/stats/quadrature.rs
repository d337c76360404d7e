//! The adaptive quadrature of every expected histogram: `lobes run`'s (the f64 reference pdf of
//! lobes' own samplers, [`crate::stats::expected`]) and `lobes check`'s (a user's WGSL pdf on the
//! GPU or an f64 closure, `crate::check::quadrature`), behind one [`Integrand`].
//!
//! **The rules.** Each part is integrated with the 5 × 5 and the 3 × 3 Gauss–Legendre tensor
//! rules. The 3-point rule is exact to degree 5, the 5-point rule to degree 9, so for a smooth
//! integrand |5 × 5 − 3 × 3| estimates the 3-point rule's error and bounds the 5-point one's:
//! where it is within the [`Tolerance`] the 5 × 5 value is taken. Otherwise the part is split
//! into quarters, whose 5 × 5 sum is accepted when it agrees with the whole part's 5 × 5 value
//! within the tolerance, else each quarter is split again, down to [`Settings::max_depth`]. The
//! accepted |fine − coarse| differences are the error estimate.
//!
//! **The coordinates** ([`Rect`]): on the sphere a = 1 − |cos θ| per hemisphere and b = φ,
//! whose area element da dφ is the solid angle's, and a is exact near a pole (1 − z loses no
//! digits there, and the f32 of the GPU keeps its resolution); on a cap the same about its
//! axis; on the plane (x, y). A part at a pole is integrated in s = √a ([`Radial::RootA`]).
//!
//! **Jumps** ([`Jumps::Locate`]): agreement is not trusted where the pdf's support has an edge
//! in a part (the pdf 0 at some of its nodes, corners and sides' midpoints, > 0 at others):
//! across a jump the two rules, and a part and its quarters, can agree on a wrong value. Such a
//! part is split [`EDGE_DEPTH`] levels past the depth limit while its jump holds more than the
//! tolerance.
//!
//! **Witnesses** ([`Witnesses`]): a support narrower than the nodes' spacing (a light seen as a
//! sliver) can pass between every node of a part, where both rules give 0 and agree. A part
//! whose rules both give 0 and that holds a sample of the run is split as a part with an edge is:
//! a correct sampler's samples lie where its pdf has mass.
//!
//! **Peaks** ([`Peak`]): a peak narrower than the finest part slips between the rules' nodes,
//! and then the rules agree on a wrong value; where its direction is known, the parts about it
//! start graded toward it ([`peak_parts`]).

use super::domain::{Domain, Frame};
use super::gauss_legendre::GaussLegendre;
use super::histogram::SphereGrid;
use glam::DVec3;
use std::sync::LazyLock;

/// The 5-point rule of every part, and the 3-point rule it is checked against.
static GL5: LazyLock<GaussLegendre> = LazyLock::new(|| GaussLegendre::new(5));
static GL3: LazyLock<GaussLegendre> = LazyLock::new(|| GaussLegendre::new(3));

/// Levels past the deepest split for a part where the pdf's support has an edge (the jump is
/// located to 2⁻ᴰ of the part: bisection of the edge, a quarter at a time).
pub const EDGE_DEPTH: u32 = 4;

/// Relative rounding of a part's sum in f64 ([`CpuPdf`]).
pub const CPU_ROUNDING: f64 = 1e-13;

/// The first coordinate of a part ([`Rect`]): a = 1 − |cos θ| (on the plane, x), or s = √a.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Radial {
    A,
    RootA,
}

/// A rectangle of the quadrature's coordinates: `r` = (a0, a1, b0, b1) in hemisphere `h` (its
/// sign; 0 on the plane), its first coordinate a = 1 − |cos θ|, or, [`Radial::RootA`], s = √a: a
/// part at a pole is integrated in s (dω = da dφ = 2s ds dφ), which turns an integrable
/// singularity a^(−1/2) there — a pdf ∝ 1/sin θ (uniform in θ, as a lat-long map draws its rows)
/// or ∝ 1/√(1 − cos θ) — into a smooth integrand, where Gauss–Legendre in a converged to a value
/// 3·10⁻⁴ short (a smooth pdf stays smooth in s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub r: [f64; 4],
    pub h: f32,
    pub radial: Radial,
}

/// A part to integrate: its rectangle in (a, b), the bin it belongs to, its depth of splitting
/// and, for a quarter, its parent's 5 × 5 values (pdf, eval).
#[derive(Clone, Copy, Debug)]
pub struct Part {
    pub a: (f64, f64),
    pub b: (f64, f64),
    /// hemisphere sign on the sphere, 0 on the plane
    pub h: f32,
    pub radial: Radial,
    pub bin: u32,
    pub depth: u32,
    /// the parent's 5 × 5 estimates (pdf, eval), none for a bin's initial parts
    pub coarse: Option<(f64, f64)>,
    /// Whether an ancestor was split for a witness ([`Witnesses`]): its rules gave 0 where a
    /// sample fell, so the support there is narrower than that ancestor's nodes.
    pub hidden: bool,
}

impl Part {
    /// An initial part of `bin` over a ∈ `a`, b ∈ `b`: integrated in s = √a where it touches a
    /// pole (h ≠ 0 and a from 0), in a elsewhere.
    pub fn initial(a: (f64, f64), b: (f64, f64), h: f32, bin: u32) -> Part {
        let radial = if h != 0.0 && a.0 == 0.0 { Radial::RootA } else { Radial::A };
        let a = if radial == Radial::RootA { (0.0, a.1.sqrt()) } else { a };
        Part { a, b, h, radial, bin, depth: 0, coarse: None, hidden: false }
    }

    /// Its quarters, carrying its 5 × 5 estimates; `witnessed` where it is split for a witness.
    fn quarters(&self, coarse: (f64, f64), witnessed: bool) -> [Part; 4] {
        let am = 0.5 * (self.a.0 + self.a.1);
        let bm = 0.5 * (self.b.0 + self.b.1);
        let q = |a, b| Part { a, b, depth: self.depth + 1, coarse: Some(coarse), hidden: self.hidden || witnessed, ..*self };
        [q((self.a.0, am), (self.b.0, bm)), q((am, self.a.1), (self.b.0, bm)), q((self.a.0, am), (bm, self.b.1)), q((am, self.a.1), (bm, self.b.1))]
    }

    pub fn rect(&self) -> Rect {
        Rect { r: [self.a.0, self.a.1, self.b.0, self.b.1], h: self.h, radial: self.radial }
    }
}

/// The initial parts of `bin` over a ∈ `a`, b ∈ `b` in hemisphere `h`: the rectangle split
/// `m × m` ([`Part::initial`]).
pub fn split(a: (f64, f64), b: (f64, f64), h: f32, m: u32, bin: u32) -> Vec<Part> {
    let (da, db) = ((a.1 - a.0) / m as f64, (b.1 - b.0) / m as f64);
    (0..m)
        .flat_map(|i| (0..m).map(move |j| (i, j)))
        .map(|(i, j)| Part::initial((a.0 + i as f64 * da, a.0 + (i + 1) as f64 * da), (b.0 + j as f64 * db, b.0 + (j + 1) as f64 * db), h, bin))
        .collect()
}

/// A part's rules: (∫pdf 5 × 5, ∫pdf 3 × 3, ∫eval 5 × 5, ∫eval 3 × 3), and where the pdf's
/// support has an edge in it (0 at some of the rules' nodes, its corners and the midpoints of its
/// sides, > 0 at others), the scale of the jump's mass there (the smallest value > 0 seen times
/// the area).
pub type Rules = ([f64; 4], Option<f64>);

/// What integrates the parts ([`Rules`] per [`Rect`]), failing with `E`; and the relative
/// rounding of its sums, which the [`Tolerance`] adds.
pub trait Integrand<E> {
    fn rules(&self, rects: &[Rect]) -> Result<Vec<Rules>, E>;
    fn rounding(&self) -> f64;
    /// The first number of each part's [`Rules`] (∫pdf by the fine rule), the same value
    /// `rules` gives, where an integrand can give it alone for less.
    fn fine_pdf(&self, rects: &[Rect]) -> Result<Vec<f64>, E> {
        Ok(self.rules(rects)?.into_iter().map(|(v, _)| v[0]).collect())
    }
}

/// The tolerance on a part whose integral is about p: `sigma_fraction` of a count's standard
/// deviation at `samples` samples, √(p / N), plus `floor`, plus the integrand's rounding of p.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    pub sigma_fraction: f64,
    pub samples: f64,
    pub floor: f64,
}

impl Tolerance {
    pub fn of(&self, value: f64, rounding: f64) -> f64 {
        self.sigma_fraction * (value.abs() / self.samples).sqrt() + self.floor + rounding * value.abs()
    }
}

/// Whether [`refine`] locates the edges of the pdf's support ([`EDGE_DEPTH`]) or trusts the
/// rules' agreement there: a user's pdf is judged against counts, and a jump it has is located;
/// lobes' own densities, and whole-sphere integrals, hold kinks (max(0, ω·h)), not jumps, which
/// their parts resolve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Jumps {
    Locate,
    Trust,
}

/// How [`refine`] refines.
#[derive(Clone, Copy, Debug)]
pub struct Settings<'w> {
    pub tolerance: Tolerance,
    /// Deepest split of a part (a quarter per level; a bin's initial parts are depth 0).
    pub max_depth: u32,
    pub jumps: Jumps,
    /// Parts evaluated in one round at most; beyond it, parts are accepted unrefined and counted.
    pub max_parts: usize,
    /// Whether the accepted parts are kept ([`Refined::leaves`]).
    pub keep_leaves: bool,
    /// Samples of the run, where a part's zero is not trusted ([`Witnesses`]).
    pub witnesses: Option<&'w Witnesses>,
}

/// Points where samples of the run fell, per bin, in the parts' coordinates (a, b, hemisphere:
/// [`Domain::part_coordinates`]): a part whose two rules both give 0 and that holds one is split
/// as far as a part with an edge of the support ([`EDGE_DEPTH`]). A triangle light 0.6 × 3·10⁻⁴
/// rad lying along a row of the sphere's grid passes between the nodes of most of the parts it
/// crosses, and its bins' first integrals held 0.70 of its mass. Where the pdf is truly 0 at a
/// sample, the split parts stay 0 and the sample still fails the test.
#[derive(Clone, Debug, Default)]
pub struct Witnesses {
    by_bin: Vec<Vec<(f64, f64, f32)>>,
}

impl Witnesses {
    /// The witnesses of `points` on `grid`, each in the bin [`super::domain::Grid::cell_of`]
    /// gives it (points outside the domain are left out).
    ///
    /// ```
    /// use lobes::stats::domain::Domain;
    /// use lobes::stats::quadrature::Witnesses;
    /// let w = Witnesses::new(&Domain::Sphere.grid(8, 16), [[0.0, 0.6, 0.8], [0.0, 0.0, 2.0]]);
    /// assert_eq!(w.len(), 1);
    /// ```
    pub fn new(grid: &super::domain::Grid, points: impl IntoIterator<Item = [f64; 3]>) -> Self {
        let mut by_bin = vec![Vec::new(); grid.bins()];
        for p in points {
            let c = grid.domain.part_coordinates(p);
            // a coordinate that is not a number is inside no part
            if let Some(bin) = grid.cell_of(p).filter(|_| c.0.is_finite() && c.1.is_finite()) {
                by_bin[bin].push(c);
            }
        }
        // by their first coordinate, which `hold` searches
        for w in &mut by_bin {
            w.sort_by(|p, q| p.0.total_cmp(&q.0));
        }
        Witnesses { by_bin }
    }

    /// How many points are held.
    pub fn len(&self) -> usize {
        self.by_bin.iter().map(Vec::len).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether `part` holds one (its bounds included; a part at a pole is in s = √a). The bin's
    /// witnesses are sorted by a, and s = √a keeps that order: only those from the first with a
    /// coordinate ≥ the part's lower bound to the last ≤ its upper bound are looked at (a narrow
    /// lobe's 2¹⁶ witnesses share one bin with millions of parts).
    fn hold(&self, part: &Part) -> bool {
        // √a below 0 is no number, inside no part: placed before every bound, the order holds
        let a = |a: f64| if part.radial != Radial::RootA { a } else if a < 0.0 { f64::NEG_INFINITY } else { a.sqrt() };
        let Some(w) = self.by_bin.get(part.bin as usize) else { return false };
        let first = w.partition_point(|&(x, ..)| a(x) < part.a.0);
        w[first..].iter().take_while(|&&(x, ..)| a(x) <= part.a.1).any(|&(_, b, h)| h == part.h && part.b.0 <= b && b <= part.b.1)
    }
}

/// A part whose 5 × 5 value was summed into its bin's integral (an accepted initial part, or each
/// of the four quarters accepted together), with that value: a fixed partition on which to
/// integrate a perturbed pdf.
#[derive(Clone, Copy, Debug)]
pub struct Leaf {
    pub rect: Rect,
    pub bin: u32,
    pub value: f64,
    /// Whether the edge detector saw a jump of the pdf in it (a support's edge crosses it).
    pub edge: bool,
}

/// What [`refine`] gives per bin, and in all.
#[derive(Clone, Debug, Default)]
pub struct Refined {
    /// ∫pdf and ∫eval per bin.
    pub pdf: Vec<f64>,
    pub eval: Vec<f64>,
    /// The error estimate a verdict is held to: the |fine − coarse| of parts accepted unconverged
    /// summed, plus those of converged parts summed in quadrature (each bounds a part's error of
    /// either sign; their plain sum over the k parts of a finely split bin grows as k while the
    /// error of the bin grows as √k).
    pub error: Vec<f64>,
    /// The plain sum of every accepted part's |fine − coarse|.
    pub linear: Vec<f64>,
    /// Parts accepted at the depth limit (or past the parts' budget) without agreeing.
    pub unconverged: Vec<u64>,
    /// The pdf's integral over the parts left out as bad (NaN, infinite or negative) where finite.
    pub dropped: Vec<f64>,
    /// The pdf's integral over parts found below a witnessed part ([`Part::hidden`]): mass of a
    /// support narrower than the nodes of the parts the bin started as, where the parts that
    /// held no witness may hide more, which no rule estimates.
    pub hidden: Vec<f64>,
    pub bad_parts: u64,
    /// Parts evaluated in all, and rounds.
    pub parts: u64,
    pub rounds: u32,
    pub leaves: Vec<Leaf>,
}

impl Refined {
    fn zero(bins: usize) -> Self {
        Refined { pdf: vec![0.0; bins], eval: vec![0.0; bins], error: vec![0.0; bins], linear: vec![0.0; bins], unconverged: vec![0; bins], dropped: vec![0.0; bins], hidden: vec![0.0; bins], ..Default::default() }
    }

    /// Adds an accepted value to its bin; `converged` errors go into the bin's sum of squares
    /// (`error` holds those until [`refine`] ends).
    fn accept(&mut self, part: &Part, pdf: f64, eval: f64, err: f64, converged: bool, squares: &mut [f64]) {
        let b = part.bin as usize;
        if part.hidden {
            self.hidden[b] += pdf;
        }
        self.pdf[b] += pdf;
        self.eval[b] += eval;
        self.linear[b] += err;
        self.unconverged[b] += u64::from(!converged);
        if converged {
            squares[b] += err * err;
        } else {
            self.error[b] += err;
        }
    }

    fn drop_bad(&mut self, bin: u32, values: &[[f64; 4]]) {
        self.bad_parts += 1;
        self.dropped[bin as usize] += values.iter().map(|v| if v[0].is_finite() { v[0] } else { 0.0 }).sum::<f64>();
    }
}

/// One round of [`refine`]: the parts, their rules, and the settings.
struct Round<'a> {
    pending: &'a [Part],
    values: Vec<[f64; 4]>,
    edges: Vec<Option<f64>>,
    settings: &'a Settings<'a>,
    rounding: f64,
}

impl Round<'_> {
    fn tolerance(&self, v: f64) -> f64 {
        self.settings.tolerance.of(v, self.rounding)
    }
    fn agree(&self, fine: f64, coarse: f64) -> bool {
        (fine - coarse).abs() <= self.tolerance(fine)
    }
    /// Whether part `k` holds an edge of the support whose jump is above the tolerance, and may be
    /// split on ([`EDGE_DEPTH`] levels past the limit).
    fn edged(&self, k: usize) -> bool {
        let s = self.settings;
        s.jumps == Jumps::Locate && self.pending[k].depth < s.max_depth + EDGE_DEPTH && self.edges[k].is_some_and(|scale| scale > self.tolerance(scale))
    }
    /// Whether part `k`'s rules both give the pdf 0 where a sample fell ([`Witnesses`]), and it
    /// may be split on (as an edge).
    fn witnessed(&self, k: usize) -> bool {
        let (s, [p5, p3, ..]) = (self.settings, self.values[k]);
        p5 == 0.0 && p3 == 0.0 && self.pending[k].depth < s.max_depth + EDGE_DEPTH && s.witnesses.is_some_and(|w| w.hold(&self.pending[k]))
    }

    /// Initial part `i`: accepted where its two rules agree (pdf and eval) and no edge is in it,
    /// or where the budget is spent; else quartered into `next`.
    fn initial(&self, i: usize, out: &mut Refined, squares: &mut [f64], next: &mut Vec<Part>) {
        let (part, v) = (self.pending[i], self.values[i]);
        let [p5, p3, e5, e3] = v;
        if bad(&v) {
            out.drop_bad(part.bin, &[v]);
        } else if (!self.edged(i) && !self.witnessed(i) && self.agree(p5, p3) && self.agree(e5, e3)) || next.len() + 4 > self.settings.max_parts {
            out.accept(&part, p5, e5, (p5 - p3).abs(), self.agree(p5, p3), squares);
            if self.settings.keep_leaves {
                out.leaves.push(Leaf { rect: part.rect(), bin: part.bin, value: p5, edge: self.edges[i].is_some() });
            }
        } else {
            next.extend(part.quarters((p5, e5), self.witnessed(i)));
        }
    }

    /// The four quarters from `i` on, of one parent: accepted together where their sum agrees with
    /// the parent's 5 × 5 value (pdf and eval) and no edge is in them, or at the depth limit, or
    /// where the budget is spent; else each quartered into `next`.
    fn quarters(&self, i: usize, (cp, ce): (f64, f64), out: &mut Refined, squares: &mut [f64], next: &mut Vec<Part>) {
        let (part, group) = (self.pending[i], &self.values[i..i + 4]);
        if group.iter().any(bad) {
            return out.drop_bad(part.bin, group);
        }
        let fine: f64 = group.iter().map(|v| v[0]).sum();
        let fine_e: f64 = group.iter().map(|v| v[2]).sum();
        let agree = self.agree(fine, cp) && self.agree(fine_e, ce);
        let edge = (i..i + 4).any(|k| self.edged(k) || self.witnessed(k));
        if (!edge && (agree || part.depth >= self.settings.max_depth)) || next.len() + 16 > self.settings.max_parts {
            out.accept(&part, fine, fine_e, (fine - cp).abs(), agree, squares);
            if self.settings.keep_leaves {
                let edges = &self.edges[i..i + 4];
                out.leaves.extend(self.pending[i..i + 4].iter().zip(group).zip(edges).map(|((q, v), e)| Leaf { rect: q.rect(), bin: q.bin, value: v[0], edge: e.is_some() }));
            }
        } else {
            for (k, (q, v)) in self.pending[i..i + 4].iter().zip(group).enumerate() {
                next.extend(q.quarters((v[0], v[2]), self.witnessed(i + k)));
            }
        }
    }
}

/// A part's rules are bad where the pdf's or eval's integral is NaN, infinite or negative.
fn bad(v: &[f64; 4]) -> bool {
    !(v[0].is_finite() && v[1].is_finite() && v[0] >= 0.0 && v[1] >= 0.0)
}

/// Integrates `pending`, the initial parts of `bins` bins, refining each as the module doc says,
/// a round of parts at a time (one call of [`Integrand::rules`] per round).
pub fn refine<E>(f: &dyn Integrand<E>, mut pending: Vec<Part>, bins: usize, settings: &Settings<'_>) -> Result<Refined, E> {
    let mut out = Refined::zero(bins);
    let mut squares = vec![0.0; bins];
    let rounding = f.rounding();
    while !pending.is_empty() {
        out.rounds += 1;
        out.parts += pending.len() as u64;
        let rects: Vec<Rect> = pending.iter().map(Part::rect).collect();
        let (values, edges) = f.rules(&rects)?.into_iter().unzip();
        let round = Round { pending: &pending, values, edges, settings, rounding };
        let mut next = Vec::new();
        let mut i = 0;
        while i < pending.len() {
            match pending[i].coarse {
                None => {
                    round.initial(i, &mut out, &mut squares, &mut next);
                    i += 1;
                }
                Some(coarse) => {
                    round.quarters(i, coarse, &mut out, &mut squares, &mut next);
                    i += 4;
                }
            }
        }
        pending = next;
    }
    for (e, sq) in out.error.iter_mut().zip(&squares) {
        *e += sq.sqrt();
    }
    Ok(out)
}

/// An f64 pdf on the CPU over a domain's parts ([`Domain::part_point`]).
pub struct CpuPdf<'a> {
    pub pdf: &'a (dyn Fn(DVec3) -> f64 + Sync),
    pub domain: Domain,
    /// Whether its parts' support edges are looked for (the edge of [`Rules`] is `None` otherwise).
    pub jumps: Jumps,
    frame: Option<Frame>,
}

impl<'a> CpuPdf<'a> {
    pub fn new(pdf: &'a (dyn Fn(DVec3) -> f64 + Sync), domain: Domain, jumps: Jumps) -> Self {
        CpuPdf { pdf, domain, jumps, frame: domain.frame() }
    }

    /// The point at (a, b) of a part in hemisphere h, given (b, cos b, sin b).
    fn point(&self, a: f64, b: (f64, f64, f64), h: f32) -> DVec3 {
        self.domain.part_point_at(self.frame.as_ref(), a, b, h)
    }

    /// ∫∫ pdf over `rect` by `rule`'s tensor product, in s = √a (dω = 2s ds db) for
    /// [`Radial::RootA`].
    fn rule(&self, rect: &Rect, rule: &GaussLegendre) -> f64 {
        let r = &rect.r;
        let bs: Vec<(f64, (f64, f64, f64))> = rule.on(r[2], r[3]).map(|(b, w)| (w, (b, b.cos(), b.sin()))).collect();
        rule.on(r[0], r[1])
            .map(|(x, wx)| {
                let (a, jacobian) = if rect.radial == Radial::RootA { (x * x, 2.0 * x) } else { (x, 1.0) };
                wx * jacobian * bs.iter().map(|&(wb, b)| wb * (self.pdf)(self.point(a, b, rect.h))).sum::<f64>()
            })
            .sum()
    }

    /// `lobes_support_edge` in f64: the pdf at both rules' nodes, the corners and the sides'
    /// midpoints.
    fn edge(&self, rect: &Rect) -> Option<f64> {
        if self.jumps == Jumps::Trust {
            return None;
        }
        let r = &rect.r;
        let (c, hw) = ([0.5 * (r[0] + r[1]), 0.5 * (r[2] + r[3])], [0.5 * (r[1] - r[0]), 0.5 * (r[3] - r[2])]);
        let mut points: Vec<(f64, f64)> = [&*GL5, &*GL3].iter().flat_map(|g| g.nodes().iter().flat_map(|&(x, _)| g.nodes().iter().map(move |&(y, _)| (x, y)))).collect();
        points.extend([-0.999, 0.0, 0.999].iter().flat_map(|&x| [-0.999, 0.0, 0.999].map(|y| (x, y))).filter(|&(x, y)| (x, y) != (0.0, 0.0)));
        let (mut zero, mut positive, mut smallest) = (false, false, f64::INFINITY);
        for (x, y) in points {
            let s = c[0] + hw[0] * x;
            let a = if rect.radial == Radial::RootA { s * s } else { s };
            let b = c[1] + hw[1] * y;
            let p = (self.pdf)(self.point(a, (b, b.cos(), b.sin()), rect.h));
            zero |= p == 0.0;
            if p > 0.0 && p.is_finite() {
                positive = true;
                smallest = smallest.min(p);
            }
        }
        let area = 4.0 * hw[0] * hw[1] * if rect.radial == Radial::RootA { 2.0 * r[1] } else { 1.0 };
        (zero && positive).then_some(smallest * area)
    }
}

impl<E> Integrand<E> for CpuPdf<'_> {
    fn rules(&self, rects: &[Rect]) -> Result<Vec<Rules>, E> {
        use rayon::prelude::*;
        Ok(rects.par_iter().map(|r| ([self.rule(r, &GL5), self.rule(r, &GL3), 0.0, 0.0], self.edge(r))).collect())
    }
    fn rounding(&self) -> f64 {
        CPU_ROUNDING
    }
}

/// The part of a band of cos θ (a row of a sphere grid) in one hemisphere, in the quadrature's
/// coordinate a = 1 − |cos θ| ([`Domain::part_point`]): its a range, the hemisphere's sign, its
/// extent in θ and the largest sin θ in it.
pub struct Zone {
    pub a: (f64, f64),
    pub h: f32,
    pub dtheta: f64,
    pub smax: f64,
}

impl Zone {
    /// Its angular extent: the larger of its span in θ and its widest span in φ over `phi`.
    pub fn extent(&self, phi: (f64, f64)) -> f64 {
        self.dtheta.max((phi.1 - phi.0) * self.smax)
    }
}

/// The zones of row `r` of a sphere grid of `rows` rows.
pub fn row_zones(rows: u32, r: u32) -> Vec<Zone> {
    let z = SphereGrid { rows, cols: 1 }.cos_theta_edges();
    z_zones(z[r as usize], z[r as usize + 1])
}

/// The zones of the band cos θ ∈ [z0, z1]: its parts in each hemisphere (as [`row_zones`]).
pub fn z_zones(z0: f64, z1: f64) -> Vec<Zone> {
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

/// Edges of `range` graded toward `at` (clamped into it): `at` ± 4⁻ᵏ of the range, k = 1, 2, …
/// while the step is above `finest`, with the range's ends and `at`.
fn graded_edges(range: (f64, f64), at: f64, finest: f64) -> Vec<f64> {
    let at = at.clamp(range.0, range.1);
    let extent = range.1 - range.0;
    let mut edges = vec![range.0, at, range.1];
    let mut d = extent / 4.0;
    while d > finest {
        edges.extend([at - d, at + d]);
        d /= 4.0;
    }
    edges.retain(|x| (range.0..=range.1).contains(x));
    edges.sort_by(f64::total_cmp);
    edges.dedup();
    edges
}

/// A narrow peak of the density: its direction and its angular width (radians).
#[derive(Debug, Clone, Copy)]
pub struct Peak {
    pub direction: DVec3,
    pub width: f64,
}

/// The initial parts of `zone` × `phi` (of `bin`) graded toward `peak`, where the peak lies
/// within the zone's own extent of it and is narrower than a part of an even split into at most
/// `max_split` per axis could resolve; else `None`.
///
/// A peak narrower than the finest part slips between the rules' nodes, and then the rules
/// agree on a wrong value (GGX VNDF at α 1e-8, θi 30°: 84 % of the mass missed). Its direction is
/// known (a reflection lobe's mirror direction, where h = n): the part is cut at edges graded
/// toward it by factors of 4 in a and φ, down to a quarter of its width there (in a: sin θ · w,
/// or w²/2 at a pole; in φ: w cos θ / sin θ), so that the parts next to it are smaller than the
/// peak and those away from it no larger than their distance from it.
pub fn peak_parts(zone: &Zone, phi: (f64, f64), bin: u32, peak: Peak, max_split: u32) -> Option<Vec<Part>> {
    let point = |a: f64, b: f64| DVec3::from(Domain::Sphere.part_point(a, b, zone.h as f64));
    // the peak's a in this hemisphere, and the turn of φ closest to the zone
    let zp = peak.direction.z.clamp(-1.0, 1.0);
    if zp * (zone.h as f64) < 0.0 {
        return None; // in the other hemisphere
    }
    let ap = 1.0 - zone.h as f64 * zp;
    let mut pp = peak.direction.y.atan2(peak.direction.x);
    pp += std::f64::consts::TAU * ((0.5 * (phi.0 + phi.1) - pp) / std::f64::consts::TAU).round();
    let (ac, pc) = (ap.clamp(zone.a.0, zone.a.1), pp.clamp(phi.0, phi.1));
    let (near, at) = (point(ac, pc), point(ap, pp));
    let nearest = near.cross(at).length().atan2(near.dot(at));
    let extent = zone.extent(phi);
    let w = peak.width.max(nearest);
    // Across the plane of incidence the mirror lobe is narrower by cos θ: a tilt δ of h there
    // turns ωr = 2(ωi·h)h − ωi by 2 cos θi δ, against 2δ within the plane (at θi 89°, 57 times).
    let across = w * zp.abs().max(w);
    if nearest > extent || across * max_split as f64 >= extent {
        return None;
    }
    let sin_p = (ap * (2.0 - ap)).max(0.0).sqrt();
    let as_ = graded_edges(zone.a, ac, 0.25 * (sin_p * w).max(0.5 * w * w));
    let ps = if w < sin_p { graded_edges(phi, pc, 0.25 * across / sin_p) } else { vec![phi.0, phi.1] };
    Some(as_.windows(2).flat_map(|a| ps.windows(2).map(move |p| Part::initial((a[0], a[1]), (p[0], p[1]), zone.h, bin))).collect())
}

/// ∫ f(d) dω over the unit sphere ([`sphere_integral`]).
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
/// parts of its own size in a, which bins uniform in cos θ reach only past the depth limit for w
/// below ~10⁻² (a microfacet D with α = 10⁻³); the even bands keep the parts away from the pole
/// small, where a kink such as max(0, ω·h)'s crosses them.
const POLE_BANDS: i32 = 30;
const EVEN_BANDS: i32 = 6;
const AZIMUTH_PARTS: u32 = 64;

/// The tolerance of a sphere integral: as a histogram's at 10¹² samples, a part's tolerance
/// 10⁻⁸ √(its integral) plus a thousandth of a count plus the rounding of its sum (f32's 2·10⁻⁶ on the GPU), to
/// 8 levels.
pub const SPHERE_SETTINGS: Settings<'static> = Settings {
    tolerance: Tolerance { sigma_fraction: 0.01, samples: 1e12, floor: 1e-3 / 1e12 },
    max_depth: 8,
    jumps: Jumps::Trust,
    max_parts: 1 << 22,
    keep_leaves: false,
    witnesses: None,
};

fn sphere_parts() -> Vec<Part> {
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
                parts.push(Part { a: (band[0], band[1]), b, h, radial: Radial::A, bin: 0, depth: 0, coarse: None, hidden: false });
            }
        }
    }
    parts
}

/// ∫ f(d) dω over the unit sphere by `f`'s rules, from `sphere_parts`.
pub fn sphere_integral<E>(f: &dyn Integrand<E>) -> Result<SphereIntegral, E> {
    let i = refine(f, sphere_parts(), 1, &SPHERE_SETTINGS)?;
    Ok(SphereIntegral { value: i.pdf[0], error_estimate: i.linear[0], unconverged_parts: i.unconverged[0], bad_parts: i.bad_parts, parts: i.parts })
}

/// ∫ f(d) dω over the unit sphere in f64 on the CPU, by the rules and parts of
/// [`sphere_integral`].
///
/// ```
/// use lobes::stats::quadrature::sphere_integral_f64;
/// // ∫ max(0, cos θ) dω = π
/// let i = sphere_integral_f64(&|d| d.z.max(0.0));
/// assert!((i.value - std::f64::consts::PI).abs() < 1e-12);
/// ```
pub fn sphere_integral_f64(f: &(dyn Fn(DVec3) -> f64 + Sync)) -> SphereIntegral {
    let cpu = CpuPdf::new(f, Domain::Sphere, Jumps::Trust);
    match sphere_integral::<std::convert::Infallible>(&cpu) {
        Ok(i) => i,
        Err(never) => match never {},
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cpu_refine(f: &(dyn Fn(DVec3) -> f64 + Sync), parts: Vec<Part>, bins: usize, settings: &Settings) -> Refined {
        let cpu = CpuPdf::new(f, Domain::Sphere, settings.jumps);
        match refine::<std::convert::Infallible>(&cpu, parts, bins, settings) {
            Ok(r) => r,
            Err(never) => match never {},
        }
    }

    /// A uniform density over cos θ ∈ [0.5, 0.75] (a ∈ [0.25, 0.5]), φ ∈ [0, 1]: 0.25 / 4π.
    #[test]
    fn uniform_density_gives_equal_bins() {
        let f = |_w: DVec3| 1.0 / (4.0 * std::f64::consts::PI);
        let v = cpu_refine(&f, split((0.25, 0.5), (0.0, 1.0), 1.0, 1, 0), 1, &SPHERE_SETTINGS).pdf[0];
        assert!((v - 0.25 / (4.0 * std::f64::consts::PI)).abs() < 1e-16);
    }

    /// A part at the pole is integrated in s = √a, where a density ∝ 1/sin θ is smooth:
    /// ∫ 1/sin θ dω over the cap θ ≤ π/3 is 2π · π/3.
    #[test]
    fn pole_part_resolves_one_over_sin_theta() {
        let f = |w: DVec3| 1.0 / (w.x * w.x + w.y * w.y).sqrt();
        let parts = split((0.0, 0.5), (-std::f64::consts::PI, std::f64::consts::PI), 1.0, 4, 0);
        let v = cpu_refine(&f, parts, 1, &SPHERE_SETTINGS).pdf[0];
        let exact = 2.0 * std::f64::consts::PI * std::f64::consts::PI / 3.0;
        assert!((v - exact).abs() < 1e-9 * exact, "{v} against {exact}");
    }

    /// A narrow peak at a known direction, graded toward: a normalised Gaussian cap of width 10⁻³
    /// rad about θ = 30° keeps its mass 1 in the bin that holds it.
    #[test]
    fn graded_parts_find_a_narrow_peak() {
        let w = 1e-3;
        let at = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
        let f = move |d: DVec3| (-(1.0 - d.dot(at)) / (w * w)).exp() / (2.0 * std::f64::consts::PI * w * w);
        let zone = &row_zones(4, 3)[0];
        let phi = (-0.5, 0.5);
        let parts = peak_parts(zone, phi, 0, Peak { direction: at, width: w }, 16).expect("a narrow peak inside the bin");
        let v = cpu_refine(&f, parts, 1, &SPHERE_SETTINGS).pdf[0];
        assert!((v - 1.0).abs() < 1e-6, "{v}");
    }

    /// A strip narrower than the nodes' spacing: density 1/w on x ∈ [179/512, 179/512 + w) of the
    /// unit square, w = 2⁻¹⁰, whose integral is 1 (its edges on the parts' edges at depth 10, where
    /// the edges' parts hold the strip whole or not at all). No node of the square's rules, nor of
    /// its quarters' to depth 4, falls on it, so both rules give 0 and agree; with samples of it
    /// as witnesses the parts holding them are split until the strip is found and its edges
    /// located.
    #[test]
    fn witnesses_find_a_strip_between_the_nodes() {
        let (x0, w) = (179.0 / 512.0, 1.0 / 1024.0);
        let f = |p: DVec3| if (x0..x0 + w).contains(&p.x) { 1.0 / w } else { 0.0 };
        let domain = Domain::Plane { bounds: [0.0, 0.0, 1.0, 1.0] };
        let cpu = CpuPdf::new(&f, domain, Jumps::Locate);
        let settings = Settings { tolerance: Tolerance { sigma_fraction: 0.01, samples: 1e6, floor: 1e-9 }, jumps: Jumps::Locate, ..SPHERE_SETTINGS };
        let refined = |settings: &Settings| match refine::<std::convert::Infallible>(&cpu, split((0.0, 1.0), (0.0, 1.0), 0.0, 64, 0), 1, settings) {
            Ok(r) => r,
            Err(never) => match never {},
        };
        let unseen = refined(&settings);
        assert_eq!((unseen.pdf[0], unseen.hidden[0]), (0.0, 0.0));
        let witnesses = Witnesses::new(&domain.grid(1, 1), (0..256).map(|k| [x0 + 0.5 * w, (k as f64 + 0.5) / 256.0, 0.0]));
        let seen = refined(&Settings { witnesses: Some(&witnesses), ..settings });
        assert!((seen.pdf[0] - 1.0).abs() < 1e-9, "{}", seen.pdf[0]);
        // all of it found below the witnessed part: a support narrower than the first nodes
        assert_eq!(seen.hidden[0], seen.pdf[0]);
        // a strip 8 times wider, which the nodes of the first parts (1/64 wide) see: witnesses on
        // it split nothing that gave 0
        let wide = |p: DVec3| if (0.25..0.25 + 8.0 * w).contains(&p.x) { 1.0 / (8.0 * w) } else { 0.0 };
        let cpu = CpuPdf::new(&wide, domain, Jumps::Locate);
        let witnesses = Witnesses::new(&domain.grid(1, 1), (0..256).map(|k| [0.25 + 4.0 * w, (k as f64 + 0.5) / 256.0, 0.0]));
        let r = match refine::<std::convert::Infallible>(&cpu, split((0.0, 1.0), (0.0, 1.0), 0.0, 64, 0), 1, &Settings { witnesses: Some(&witnesses), ..settings }) {
            Ok(r) => r,
            Err(never) => match never {},
        };
        assert!((r.pdf[0] - 1.0).abs() < 1e-6 && r.hidden[0] == 0.0, "{} {}", r.pdf[0], r.hidden[0]);
    }
}
