//! The family of χ² tests one judge runs over a histogram: Pearson's test on the fine grid, on
//! its aggregations into 2 × 2, 4 × 4, … blocks down to a handful of cells, and on its two 1-D
//! marginals, their family-wise error rate held at the case's significance by Holm's step-down
//! procedure (Holm 1979, "A simple sequentially rejective multiple test procedure").
//!
//! Why more than one grid: a defect spread smoothly over many bins adds N Σ p δ² to the
//! statistic, which must rise above the noise √(2 · dof) of the null. Aggregating 4ᵏ bins keeps
//! the signal of a defect smooth on the coarse scale (δ is the same in the coarse cell) and
//! divides dof, and with it the noise, by 4ᵏ; a sharp defect (one bin off) is averaged away by
//! the same aggregation, and the fine grid keeps seeing it (docs/statistics.md).
//!
//! Every test is Pearson's [`chi2::test`] over a partition of the fine bins into coarser cells
//! plus the invalid-sample cells, each pooling its own small cells as the fine grid does. The
//! grids are equal-area where the fine grid is: lobes' sphere grid is uniform in (cos θ, φ), a
//! plane grid in (x, y), so a block of bins is a cell of equal solid angle (or area).

use super::chi2::{self, Chi2, FamilyTest};
#[cfg(test)]
use super::domain::Domain;

/// The fewest cells an aggregated grid may have (the 2 × 4 of the default sphere grid, the
/// 2 × 2 of the plane's): coarser than that, a grid can no longer tell where the mass went.
pub const MIN_CELLS: u64 = 4;

pub use super::domain::Grid;

/// One test of the family: Pearson's χ² over the fine grid's bins grouped into `rows` × `cols`
/// cells, fine row r into ⌊r · rows / R⌋ and column c into ⌊c · cols / C⌋ (a marginal is a grid
/// with one column or one row).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Test {
    /// What the statistic is over: "64 × 128" for a grid, "cos θ" or "φ" for a marginal.
    pub name: String,
    pub rows: u32,
    pub cols: u32,
}

impl Test {
    /// The counts and expected counts of its cells, row-major.
    pub fn cells(&self, grid: Grid, counts: &[u64], expected: &[f64]) -> (Vec<u64>, Vec<f64>) {
        assert_eq!(counts.len(), grid.rows as usize * grid.cols as usize, "counts on the grid");
        assert_eq!(expected.len(), counts.len(), "expected counts on the grid");
        let cells = self.rows as usize * self.cols as usize;
        let (mut o, mut e) = (vec![0u64; cells], vec![0.0f64; cells]);
        let group = |i: u32, fine: u32, coarse: u32| (i as u64 * coarse as u64 / fine as u64) as usize;
        for r in 0..grid.rows {
            let row = group(r, grid.rows, self.rows) * self.cols as usize;
            for c in 0..grid.cols {
                let (k, fine) = (row + group(c, grid.cols, self.cols), (r * grid.cols + c) as usize);
                o[k] += counts[fine];
                e[k] += expected[fine];
            }
        }
        (o, e)
    }

    /// Its figures for the histogram `counts` against `expected` on `grid`, with the invalid
    /// cells as extra cells (Pearson's [`chi2::test`], small cells pooled).
    pub fn run(&self, grid: Grid, bins: (&[u64], &[f64]), invalid: (&[u64], &[f64]), significance: f64) -> Chi2 {
        let (mut o, mut e) = self.cells(grid, bins.0, bins.1);
        o.extend_from_slice(invalid.0);
        e.extend_from_slice(invalid.1);
        chi2::test(&o, &e, significance)
    }
}

/// The family's tests on `grid`, the fine grid first: its aggregations, each halving both
/// axes (rounding up) while it keeps at least [`MIN_CELLS`] cells, then the marginal over each
/// axis of two cells or more; a grid met twice is tested once.
///
/// ```
/// use lobes::stats::{domain::Domain, family::tests};
/// let names: Vec<String> = tests(Domain::Sphere.grid(64, 128)).into_iter().map(|t| t.name).collect();
/// assert_eq!(names, ["64 × 128", "32 × 64", "16 × 32", "8 × 16", "4 × 8", "2 × 4", "cos θ", "φ"]);
/// ```
pub fn tests(grid: Grid) -> Vec<Test> {
    let mut shapes = vec![(grid.rows, grid.cols)];
    let (mut r, mut c) = (grid.rows, grid.cols);
    loop {
        let next = (r.div_ceil(2), c.div_ceil(2));
        if next == (r, c) || (next.0 as u64) * (next.1 as u64) < MIN_CELLS {
            break;
        }
        (r, c) = next;
        shapes.push(next);
    }
    let mut out: Vec<Test> = shapes.into_iter().map(|(rows, cols)| Test { name: format!("{rows} × {cols}"), rows, cols }).collect();
    for (rows, cols, axis) in [(grid.rows, 1, grid.domain.axes()[0]), (1, grid.cols, grid.domain.axes()[1])] {
        if rows * cols >= 2 && !out.iter().any(|t| (t.rows, t.cols) == (rows, cols)) {
            out.push(Test { name: axis.to_string(), rows, cols });
        }
    }
    out
}

/// Holm's adjusted p-values, in the order given: with p₍₁₎ ≤ … ≤ p₍ₘ₎ sorted,
/// p̃₍ᵢ₎ = min(1, max_{j ≤ i} (m − j + 1) p₍ⱼ₎). Rejecting the tests whose p̃ < α holds the
/// family-wise error rate at α under any dependence between the tests; the family rejects
/// something exactly when m · min p < α (Bonferroni's), and Holm's rejects more of its tests.
///
/// ```
/// // m = 4: sorted 0.01, 0.02, 0.03, 0.5 → 4·0.01, max(0.04, 3·0.02), max(0.06, 2·0.03), 0.5
/// let adjusted = lobes::stats::family::holm(&[0.5, 0.01, 0.03, 0.02]);
/// let want = [0.5, 0.04, 0.06, 0.06];
/// assert!(adjusted.iter().zip(want).all(|(a, w)| (a - w).abs() < 1e-15), "{adjusted:?}");
/// ```
pub fn holm(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let mut adjusted = vec![1.0; m];
    let mut running: f64 = 0.0;
    for (j, &i) in order.iter().enumerate() {
        running = running.max(((m - j) as f64 * p[i]).min(1.0));
        adjusted[i] = running;
    }
    adjusted
}

/// The judge of a sampler's histogram, the one `lobes run`, `lobes merge` and `lobes check`
/// judge by: [`chi2::judge`] on the fine grid (its figures are the verdict's statistic, dof and
/// p-value; no valid sample or a single cell is never a pass), and every test of [`tests`] with
/// Holm's adjustment. It passes where the fine grid tested something and no test rejects at
/// `significance`: the family's p-value, Holm's smallest, is at least `significance`.
///
/// ```
/// use lobes::stats::{domain::Domain, family::judge};
/// // 4 × 4 bins, a smooth tilt: +1.5 % in the left half, −1.5 % in the right, 10⁵ samples.
/// // The fine grid: χ² = 16 · 94²/6250 = 22.6 on 15 dof, p = 0.09; the 2 × 2 grid and the x
/// // marginal: the same 22.6 on 3 dof, p = 4.9e-5 each, Holm's 4 · 4.9e-5 = 2.0e-4.
/// let expected = vec![6250.0; 16];
/// let counts: Vec<u64> = (0..16).map(|i| if i % 4 < 2 { 6344 } else { 6156 }).collect();
/// let t = judge(Domain::UNIT_SQUARE.grid(4, 4), (&counts, &expected), (&[0], &[0.0]), 0.01);
/// assert!(!t.passed && t.family[0].p_value > 0.05);
/// assert_eq!(t.family.iter().filter(|f| f.rejected).map(|f| f.test.as_str()).collect::<Vec<_>>(), ["2 × 2", "x"]);
/// ```
pub fn judge(grid: Grid, bins: (&[u64], &[f64]), invalid: (&[u64], &[f64]), significance: f64) -> Chi2 {
    let mut verdict = chi2::judge(bins, invalid, significance);
    let tests = tests(grid);
    let figures: Vec<Chi2> =
        tests.iter().enumerate().map(|(k, t)| if k == 0 { verdict.clone() } else { t.run(grid, bins, invalid, significance) }).collect();
    // only tests of dof > 0 count: a single cell tests nothing
    let judged: Vec<usize> = (0..tests.len()).filter(|&k| figures[k].dof > 0).collect();
    let adjusted = holm(&judged.iter().map(|&k| figures[k].p_value).collect::<Vec<_>>());
    let mut holm_p = vec![1.0; tests.len()];
    for (&k, a) in judged.iter().zip(adjusted) {
        holm_p[k] = a;
    }
    verdict.family = tests
        .iter()
        .zip(&figures)
        .zip(&holm_p)
        .map(|((t, f), &h)| FamilyTest {
            test: t.name.clone(),
            rows: t.rows,
            cols: t.cols,
            statistic: f.statistic,
            dof: f.dof,
            p_value: f.p_value,
            holm_p_value: h,
            rejected: h < significance,
        })
        .collect();
    let family_p = holm_p.iter().copied().fold(1.0, f64::min);
    verdict.family_p_value = Some(family_p);
    verdict.passed = verdict.untested.is_none() && family_p >= significance;
    verdict
}

/// Which tests caught the defect, for a verdict's line: the fine grid first where it rejected,
/// then the others by Holm p-value, three at most, and the fine grid's p where it did not
/// reject: "caught at 2 × 4: p = 9.2e-10 (Holm 7.4e-9), 4 × 8: p = 2.6e-7 (Holm 1.8e-6), φ: p =
/// 8.0e-4 (Holm 4.8e-3) and 1 more; 64 × 128: p = 6.2e-1". `None` where no test of the family
/// rejected (or the verdict has no family).
pub fn caught(c: &Chi2) -> Option<String> {
    let fine = c.family.first()?;
    let mut rejected: Vec<&FamilyTest> = c.family.iter().skip(1).filter(|t| t.rejected).collect();
    rejected.sort_by(|a, b| a.holm_p_value.total_cmp(&b.holm_p_value));
    if fine.rejected {
        rejected.insert(0, fine);
    }
    if rejected.is_empty() {
        return None;
    }
    let shown: Vec<String> = rejected.iter().take(3).map(|t| format!("{}: p = {:.1e} (Holm {:.1e})", t.test, t.p_value, t.holm_p_value)).collect();
    let more = if rejected.len() > 3 { format!(" and {} more", rejected.len() - 3) } else { String::new() };
    let fine = if fine.rejected { String::new() } else { format!("; {}: p = {:.1e}", fine.test, fine.p_value) };
    Some(format!("caught at {}{more}{fine}", shown.join(", ")))
}

/// The rows × cols of the grid (both > 1: not a marginal) that caught a defect the fine grid did
/// not, with the smallest Holm p-value: the level whose residual shows it.
pub fn caught_grid(c: &Chi2) -> Option<(usize, usize)> {
    if c.family.first().is_none_or(|fine| fine.rejected) {
        return None;
    }
    let grids = c.family.iter().filter(|t| t.rejected && t.rows > 1 && t.cols > 1);
    grids.min_by(|a, b| a.holm_p_value.total_cmp(&b.holm_p_value)).map(|t| (t.rows as usize, t.cols as usize))
}

/// The test with the smallest Holm p-value: the level that caught a defect, or came closest.
pub fn strongest(c: &Chi2) -> Option<&FamilyTest> {
    c.family.iter().min_by(|a, b| a.holm_p_value.total_cmp(&b.holm_p_value))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::chi2::Untested;

    #[test]
    fn the_family_of_each_grid() {
        let names = |g: Grid| tests(g).into_iter().map(|t| (t.name, t.rows, t.cols)).collect::<Vec<_>>();
        let plane = names(Domain::UNIT_SQUARE.grid(64, 64));
        assert_eq!(plane.iter().map(|t| t.0.as_str()).collect::<Vec<_>>(), ["64 × 64", "32 × 32", "16 × 16", "8 × 8", "4 × 4", "2 × 2", "y", "x"]);
        // odd sizes round up; a 1-D table aggregates along its one axis and has no marginal
        assert_eq!(names(Domain::Sphere.grid(5, 6)), [("5 × 6".into(), 5, 6), ("3 × 3".into(), 3, 3), ("2 × 2".into(), 2, 2), ("cos θ".into(), 5, 1), ("φ".into(), 1, 6)]);
        assert_eq!(names(Domain::Sphere.grid(1, 20)), [("1 × 20".into(), 1, 20), ("1 × 10".into(), 1, 10), ("1 × 5".into(), 1, 5)]);
        assert_eq!(names(Domain::Sphere.grid(1, 1)), [("1 × 1".into(), 1, 1)]);
        assert_eq!(names(Domain::Sphere.grid(2, 1)).len(), 1);
    }

    /// The cells of an aggregation, summed by hand: 3 × 4 into 2 × 2 groups rows {0, 1}, {2}
    /// (⌊r · 2/3⌋) and columns {0, 1}, {2, 3}.
    #[test]
    #[allow(clippy::identity_op, reason = "the sums spell out each group's cell indices, 0 included")]
    fn aggregated_cells() {
        let counts: Vec<u64> = (0..12).collect();
        let expected: Vec<f64> = (0..12).map(|i| i as f64 + 0.5).collect();
        let t = Test { name: "2 × 2".into(), rows: 2, cols: 2 };
        let (o, e) = t.cells(Domain::UNIT_SQUARE.grid(3, 4), &counts, &expected);
        assert_eq!(o, [0 + 1 + 4 + 5, 2 + 3 + 6 + 7, 8 + 9, 10 + 11]);
        assert_eq!(e, [12.0, 20.0, 18.0, 22.0]);
        // the marginals
        let (o, _) = Test { name: "y".into(), rows: 3, cols: 1 }.cells(Domain::UNIT_SQUARE.grid(3, 4), &counts, &expected);
        assert_eq!(o, [6, 22, 38]);
        let (o, _) = Test { name: "x".into(), rows: 1, cols: 4 }.cells(Domain::UNIT_SQUARE.grid(3, 4), &counts, &expected);
        assert_eq!(o, [12, 15, 18, 21]);
    }

    /// The aggregated χ² of a known multinomial, by hand: 2 × 2 bins of expectation 25 each,
    /// observed 30, 30 / 20, 20. Fine: 4 · 25/25 = 4 on 3 dof; rows (60 | 40 against 50 | 50):
    /// 2 · 100/50 = 4 on 1 dof, p = P(χ²₁ ≥ 4) = erfc(√2) = 0.0455; columns (50 | 50): 0.
    #[test]
    fn aggregated_statistic_by_hand() {
        let t = judge(Domain::UNIT_SQUARE.grid(2, 2), (&[30, 30, 20, 20], &[25.0; 4]), (&[0], &[0.0]), 0.01);
        let f = |name: &str| t.family.iter().find(|x| x.test == name).unwrap().clone();
        assert_eq!(t.family.len(), 3, "{:?}", t.family); // 2 × 2, y, x
        assert!((f("2 × 2").statistic - 4.0).abs() < 1e-12 && f("2 × 2").dof == 3);
        assert!((f("y").statistic - 4.0).abs() < 1e-12 && f("y").dof == 1);
        assert!((f("y").p_value - libm::erfc(2f64.sqrt())).abs() < 1e-12, "{}", f("y").p_value);
        assert_eq!((f("x").statistic, f("x").dof, f("x").p_value), (0.0, 1, 1.0));
        // P(χ²₃ ≥ 4) = erfc(√2) + √(8/π) e^{−2} (the odd-dof closed form)
        let p3 = libm::erfc(2f64.sqrt()) + (8.0 / std::f64::consts::PI).sqrt() * (-2f64).exp();
        assert!((t.p_value - p3).abs() < 1e-12, "{} vs {p3}", t.p_value);
        // Holm over the three: sorted 0.0455 (×3), 0.2615 (×2), 1
        assert!((f("y").holm_p_value - 3.0 * libm::erfc(2f64.sqrt())).abs() < 1e-12);
        assert!((f("2 × 2").holm_p_value - 2.0 * p3).abs() < 1e-12);
        assert_eq!(t.family_p_value, Some(f("y").holm_p_value));
        assert!(t.passed);
        // at a level above 3 × 0.0455 the rows' marginal rejects, and names itself
        let t = judge(Domain::UNIT_SQUARE.grid(2, 2), (&[30, 30, 20, 20], &[25.0; 4]), (&[0], &[0.0]), 0.2);
        assert!(!t.passed);
        assert_eq!(caught(&t).unwrap(), "caught at y: p = 4.6e-2 (Holm 1.4e-1); 2 × 2: p = 2.6e-1");
    }

    /// Holm against Bonferroni and by hand (Holm 1979's step-down).
    #[test]
    fn holm_procedure() {
        // one test: unchanged
        assert_eq!(holm(&[0.03]), [0.03]);
        // m = 3: sorted 0.01, 0.03, 0.04 → 3 · 0.01 = 0.03, 2 · 0.03 = 0.06, max(0.06, 0.04) = 0.06
        let a = holm(&[0.01, 0.04, 0.03]);
        for (got, want) in a.iter().zip([0.03, 0.06, 0.06]) {
            assert!((got - want).abs() < 1e-15, "{a:?}");
        }
        // capped at 1, ties kept
        assert_eq!(holm(&[0.6, 0.6]), [1.0, 1.0]);
        // never below the raw p, never above Bonferroni's m · p
        let p = [0.2, 1e-5, 0.004, 0.5, 0.011, 0.049];
        for (a, p) in holm(&p).iter().zip(p) {
            assert!(*a >= p && *a <= (6.0 * p).min(1.0));
        }
    }

    /// The family-wise error rate under the null, by simulation: multinomial draws from the
    /// expected counts themselves (a correct sampler), 2000 of them: rejections stay near or
    /// below α = 0.05 (binomial: P(X ≥ 140 | n 2000, p 0.05) < 1e-6), and the fine grid alone
    /// rejects at about α.
    #[test]
    fn family_error_rate_under_the_null() {
        let grid = Domain::Sphere.grid(8, 16);
        let p: Vec<f64> = (0..128).map(|i| 1.0 + 0.5 * ((i % 16) as f64 * 0.4).sin() + 0.1 * (i / 16) as f64).collect();
        let total: f64 = p.iter().sum();
        let n = 20_000u64;
        let expected: Vec<f64> = p.iter().map(|x| n as f64 * x / total).collect();
        let cdf: Vec<f64> = p.iter().scan(0.0, |s, x| { *s += x / total; Some(*s) }).collect();
        let mut state = 0x1234_5678_9abc_def1u64;
        let mut uniform = || {
            // splitmix64
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut family, mut fine) = (0, 0);
        for _ in 0..2000 {
            let mut counts = vec![0u64; 128];
            for _ in 0..n {
                let u = uniform();
                counts[cdf.partition_point(|&c| c < u).min(127)] += 1;
            }
            let t = judge(grid, (&counts, &expected), (&[0], &[0.0]), 0.05);
            family += usize::from(!t.passed);
            fine += usize::from(t.p_value < 0.05);
        }
        assert!(family < 140, "{family} of 2000 families rejected at α = 0.05");
        assert!((60..140).contains(&fine), "the fine grid alone rejected {fine} of 2000");
    }

    /// A smooth defect the fine grid cannot see and a coarse level can: 64 × 128 bins, density
    /// (1 + ε cos φ) at ε = 1 %, 10⁶ samples, plus a checkerboard of ±√e (χ² ≈ 1 a bin at the
    /// fine grid, like noise, and cancelling in every 2 × 2 block). The fine grid's signal
    /// N ε²/2 = 50 hides in its noise √(2 · 8191) = 128; at 2 × 4 the signal, 50 · sinc²(π/4)
    /// = 40.5 on 7 dof, has p ≈ 10⁻⁶.
    #[test]
    fn coarse_levels_see_a_smooth_defect() {
        let grid = Domain::Sphere.grid(64, 128);
        let n = 1e6f64;
        let e = n / 8192.0;
        let expected = vec![e; 8192];
        // counts of the defect's mean plus a fixed, null-like noise: ±√e alternating by bin
        let counts: Vec<u64> = (0..8192)
            .map(|i| {
                let phi = -std::f64::consts::PI + (i % 128) as f64 * 2.0 * std::f64::consts::PI / 128.0 + std::f64::consts::PI / 128.0;
                let noise = if (i + i / 128) % 2 == 0 { e.sqrt() } else { -e.sqrt() };
                (e * (1.0 + 0.01 * phi.cos()) + noise).round() as u64
            })
            .collect();
        let t = judge(grid, (&counts, &expected), (&[0], &[0.0]), 0.01);
        assert!(t.family[0].p_value > 0.01, "the fine grid sees only noise: {:?}", t.family[0]);
        assert!(!t.passed);
        assert!(caught_grid(&t).is_some_and(|(r, c)| r > 1 && c > 1 && r < 64));
        let caught = caught(&t).unwrap();
        assert!(caught.starts_with("caught at") && caught.ends_with(&format!("64 × 128: p = {:.1e}", t.p_value)), "{caught}");
    }

    /// The verdict's line: the fine grid first where it caught it, then by Holm p, three at most.
    #[test]
    fn caught_names_the_strongest_tests() {
        let test = |name: &str, p: f64, holm: f64| FamilyTest { test: name.into(), rows: 2, cols: 2, statistic: 0.0, dof: 3, p_value: p, holm_p_value: holm, rejected: holm < 0.01 };
        let mut c = chi2::test(&[10, 10], &[10.0, 10.0], 0.01);
        c.family = vec![test("64 × 128", 0.5, 1.0), test("8 × 16", 1e-4, 5e-4), test("4 × 8", 1e-6, 7e-6), test("2 × 4", 1e-3, 3e-3), test("φ", 2e-3, 4e-3)];
        assert_eq!(caught(&c).unwrap(), "caught at 4 × 8: p = 1.0e-6 (Holm 7.0e-6), 8 × 16: p = 1.0e-4 (Holm 5.0e-4), 2 × 4: p = 1.0e-3 (Holm 3.0e-3) and 1 more; 64 × 128: p = 5.0e-1");
        c.family[0] = test("64 × 128", 1e-9, 8e-9);
        assert!(caught(&c).unwrap().starts_with("caught at 64 × 128: p = 1.0e-9 (Holm 8.0e-9), 4 × 8: "));
        assert!(!caught(&c).unwrap().contains("; 64 × 128"));
        c.family.iter_mut().for_each(|t| t.rejected = false);
        assert_eq!(caught(&c), None);
    }

    #[test]
    fn untested_outcomes_keep_working() {
        // no valid sample: never a pass, whatever the family says
        let t = judge(Domain::Sphere.grid(2, 4), (&[0; 8], &[0.0; 8]), (&[600, 400], &[600.0, 400.0]), 0.01);
        assert_eq!((t.passed, t.untested), (false, Some(Untested::NoValidSample)));
        // one cell after pooling: the family's tests all have dof 0 and count for nothing
        let mut bins = vec![0u64; 64];
        bins[40] = 1_000_000;
        let t = judge(Domain::Sphere.grid(8, 8), (&bins, &[5e-11 / 64.0; 64]), (&[0, 0], &[1e6 - 5e-11, 0.0]), 0.01);
        assert_eq!((t.passed, t.untested, t.family_p_value), (false, Some(Untested::OneCell), Some(1.0)));
        assert!(t.family.iter().all(|f| f.dof == 0 && !f.rejected));
        // samples where none may be: rejected at the fine grid, p = 0
        let t = judge(Domain::Sphere.grid(2, 2), (&[1, 100, 100, 100], &[0.0, 101.0, 100.0, 100.0]), (&[0], &[0.0]), 0.01);
        assert_eq!((t.passed, t.in_impossible_cells, t.family[0].rejected), (false, 1, true));
    }
}
