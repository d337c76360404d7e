//! Pearson's χ² test of a histogram against expected counts, with sparse cells pooled in the
//! manner of Mitsuba 3's `ChiSquareTest` (which also drives pbrt-v4's BSDF tests' threshold of 5),
//! except that no cell is ever left out.

use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Cells whose expected count is below this are pooled (Mitsuba 3, pbrt-v4: 5).
pub const MIN_EXPECTED: f64 = 5.0;

/// The outcome of a χ² test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Chi2 {
    pub statistic: f64,
    pub dof: u64,
    pub p_value: f64,
    /// The per-case significance level the p-value was compared with.
    pub significance: f64,
    pub passed: bool,
    /// Observed samples in cells whose expected count is exactly 0 (any rejects the sampler).
    #[serde(rename = "samples_in_zero_probability_cells")]
    pub in_impossible_cells: u64,
    /// Why the test judged nothing, where it could not: such a test never passes, whatever its
    /// p-value (absent where the test judged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub untested: Option<Untested>,
    /// The family's p-value where a family judged ([`super::family::judge`]): the smallest of
    /// its tests' Holm-adjusted p-values, which `passed` compares with the significance
    /// (`statistic`, `dof` and `p_value` above are the fine grid's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub family_p_value: Option<f64>,
    /// Every test of the family, the fine grid first: the aggregations and the marginals.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub family: Vec<FamilyTest>,
}

/// One test's figures in a verdict: its statistic, and its p-value before and after Holm's
/// adjustment for the family.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct FamilyTest {
    /// The test: "64 × 128" (a grid of rows × cols cells), "cos θ", "φ", "y" or "x" (a
    /// marginal).
    pub test: String,
    pub rows: u32,
    pub cols: u32,
    pub statistic: f64,
    /// Its degrees of freedom after pooling; a test of 0 (one cell) tests nothing and is left
    /// out of the family's count.
    pub dof: u64,
    pub p_value: f64,
    /// Holm's adjusted p-value ([`super::family::holm`]): the test rejects where it is below the significance.
    pub holm_p_value: f64,
    pub rejected: bool,
}

/// Why a χ² test judged nothing. Neither is a pass: a test that tested nothing says nothing of
/// the sampler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Untested {
    /// No sample landed in a bin: every one was rejected, so no direction was compared.
    NoValidSample,
    /// The expected counts make a single cell after pooling: 0 degrees of freedom, where the
    /// statistic is 0 whatever the samples did (one cell holds them all, the total is fixed).
    OneCell,
}

impl Untested {
    /// One line saying what happened, for the reports.
    pub fn describe(self) -> &'static str {
        match self {
            Untested::NoValidSample => "no sample was valid: every sample was rejected, so the histogram tested nothing",
            Untested::OneCell => {
                "the χ² test has 0 degrees of freedom: the expected counts make a single cell of count ≥ 5 after pooling, so it tested nothing (more samples, fewer bins or a wider lobe give it cells to compare)"
            }
        }
    }
}

/// Šidák's correction: the per-test level that keeps the family-wise level `alpha` over `tests`
/// independent tests, 1 − (1 − α)^{1/m}.
pub fn sidak(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests.max(1) as f64)
}

/// The upper tail P(X ≥ x) of the χ² distribution with `dof` degrees of freedom.
pub fn p_value(statistic: f64, dof: u64) -> f64 {
    if dof == 0 {
        return 1.0;
    }
    ChiSquared::new(dof as f64).expect("dof > 0").sf(statistic)
}

/// Pearson's test. Cells are sorted by expected count; those with expected < 5 are summed into
/// a pool, and a pooled cell is emitted each time the pool's expected count reaches 5, as in
/// Mitsuba 3 (`chi2` in `mitsuba/core/math.h`, which waits for it to exceed 5). Sorted, the
/// small cells all come first, and a pool left below 5 at the end holds the largest of them:
/// it is merged into the pooled cell emitted last, its neighbour in expectation (or, when no
/// pooled cell was emitted, into the smallest cell ≥ 5; a lone pool becomes the only cell).
/// **Mitsuba drops that leftover pool** from the statistic and the degrees of freedom; here
/// every sample counts (nothing is dropped), so mass misplaced among the sparsest cells still
/// shows. Observed counts in cells with expected exactly 0 reject outright.
/// dof = cells − 1 (the total is fixed).
///
/// ```
/// let t = lobes::stats::chi2::test(&[10, 20, 30], &[10.0, 20.0, 30.0], 0.01);
/// assert_eq!((t.statistic, t.dof, t.passed), (0.0, 2, true));
/// ```
pub fn test(observed: &[u64], expected: &[f64], significance: f64) -> Chi2 {
    assert_eq!(observed.len(), expected.len());
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    // (observed, expected) per cell: the pooled cells first, then the cells ≥ 5, both increasing
    let mut cells: Vec<(f64, f64)> = Vec::new();
    let mut pooled_cells = 0;
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    let mut impossible = 0;
    for i in order {
        let (o, e) = (observed[i] as f64, expected[i]);
        if e <= 0.0 {
            impossible += observed[i];
        } else if e < MIN_EXPECTED {
            pool_o += o;
            pool_e += e;
            if pool_e >= MIN_EXPECTED {
                cells.push((pool_o, pool_e));
                pooled_cells += 1;
                (pool_o, pool_e) = (0.0, 0.0);
            }
        } else {
            cells.push((o, e));
        }
    }
    if pool_e > 0.0 {
        // the last pooled cell, else the smallest cell ≥ 5
        match cells.get_mut(pooled_cells.max(1) - 1) {
            Some(c) => {
                c.0 += pool_o;
                c.1 += pool_e;
            }
            None => cells.push((pool_o, pool_e)),
        }
    }
    let statistic: f64 = cells.iter().map(|(o, e)| (o - e) * (o - e) / e).sum();
    let dof = cells.len().saturating_sub(1) as u64;
    let p = if impossible > 0 { 0.0 } else { p_value(statistic, dof) };
    let untested = (dof == 0).then_some(Untested::OneCell);
    Chi2 { statistic, dof, p_value: p, significance, passed: p >= significance && untested.is_none(), in_impossible_cells: impossible, untested, family_p_value: None, family: Vec::new() }
}

/// The test of a sampler's histogram, the one `lobes run`, `lobes merge` and `lobes check` judge
/// by: Pearson's [`test()`] over the bins and the invalid-sample cells together, where a histogram
/// with no sample in any bin is [`Untested::NoValidSample`] (it never passes) and one whose
/// cells pool into one is [`Untested::OneCell`].
///
/// ```
/// use lobes::stats::chi2::{judge, Untested};
/// // every sample rejected, and a pdf of 0 that expects just that: χ² = 0, yet no pass
/// let t = judge((&[0, 0], &[0.0, 0.0]), (&[1000], &[1000.0]), 0.01);
/// assert_eq!((t.statistic, t.passed, t.untested), (0.0, false, Some(Untested::NoValidSample)));
/// ```
pub fn judge(bins: (&[u64], &[f64]), invalid: (&[u64], &[f64]), significance: f64) -> Chi2 {
    let observed: Vec<u64> = bins.0.iter().chain(invalid.0).copied().collect();
    let expected: Vec<f64> = bins.1.iter().chain(invalid.1).copied().collect();
    let mut t = test(&observed, &expected, significance);
    if bins.0.iter().all(|&o| o == 0) {
        t.untested = Some(Untested::NoValidSample);
        t.passed = false;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form for even dof 2k: P(X ≥ x) = e^{−x/2} Σ_{j<k} (x/2)^j / j!.
    fn sf_even(x: f64, dof: u64) -> f64 {
        let (h, mut term, mut sum) = (x / 2.0, 1.0, 0.0);
        for j in 0..dof / 2 {
            if j > 0 {
                term *= h / j as f64;
            }
            sum += term;
        }
        (-h).exp() * sum
    }

    #[test]
    fn p_values_match_closed_forms_and_tables() {
        for dof in [2, 4, 10, 50, 200] {
            for x in [0.5, 3.0, dof as f64, 2.0 * dof as f64 + 20.0] {
                let (got, want) = (p_value(x, dof), sf_even(x, dof));
                assert!((got - want).abs() <= 1e-10 * want.max(1e-300) + 1e-15, "dof {dof} x {x}: {got} vs {want}");
            }
        }
        // Published critical values (Abramowitz & Stegun table 26.8): P = 0.05 and 0.01 points.
        assert!((p_value(3.841458820694124, 1) - 0.05).abs() < 1e-12);
        assert!((p_value(18.307038053275146, 10) - 0.05).abs() < 1e-12);
        assert!((p_value(6.634896601021214, 1) - 0.01).abs() < 1e-12);
        assert!((p_value(124.342, 100) - 0.05).abs() < 1e-4);
        // the tail, not the CDF: large statistics give small p
        assert!(p_value(1000.0, 10) < 1e-100);
        assert!(p_value(0.0, 10) == 1.0);
    }

    #[test]
    fn sidak_level() {
        assert!((sidak(0.01, 1) - 0.01).abs() < 1e-15);
        let a = sidak(0.01, 20);
        assert!(((1.0 - a).powi(20) - 0.99).abs() < 1e-12);
    }

    #[test]
    fn pooling_and_impossible_cells() {
        // three cells of expectation 2 pool into one of 6: dof = 2 with the two big cells
        let t = test(&[2, 2, 2, 50, 50], &[2.0, 2.0, 2.0, 50.0, 50.0], 0.01);
        assert_eq!(t.dof, 2);
        assert_eq!(t.statistic, 0.0);
        let t = test(&[1, 100], &[0.0, 101.0], 0.01);
        assert_eq!((t.in_impossible_cells, t.passed), (1, false));
    }

    /// The leftover pool joins the last pooled cell, worked by hand. Expected counts sorted:
    /// 1, 1.5, 2.5 | 3, 3.5 | 4 | 10, 20, observed 0, 2, 1 | 5, 4 | 6 | 12, 15. Pools:
    /// (o 3, e 5), then (9, 6.5); the leftover (6, 4) joins the second: (15, 10.5).
    /// χ² = (3 − 5)²/5 + (15 − 10.5)²/10.5 + (12 − 10)²/10 + (15 − 20)²/20
    ///    = 4/5 + 27/14 + 2/5 + 5/4 = 613/140, over 4 cells: dof 3.
    /// (Merged into the first pooled cell instead, it would be 0 + 6.25/6.5 + 2/5 + 5/4 ≈ 2.61.)
    #[test]
    fn leftover_pool_joins_the_last_pooled_cell() {
        let expected = [20.0, 1.0, 3.5, 4.0, 2.5, 10.0, 1.5, 3.0];
        let observed = [15, 0, 4, 6, 1, 12, 2, 5];
        let t = test(&observed, &expected, 0.01);
        assert_eq!(t.dof, 3);
        assert!((t.statistic - 613.0 / 140.0).abs() < 1e-14, "{}", t.statistic);
        // no pooled cell before the leftover: it joins the smallest cell ≥ 5
        // (o 3 + 6, e 2 + 8) and (9, 9): χ² = 1/10 + 0, dof 1
        let t = test(&[2, 1, 6, 9], &[1.0, 1.0, 8.0, 9.0], 0.01);
        assert_eq!(t.dof, 1);
        assert!((t.statistic - 0.1).abs() < 1e-15, "{}", t.statistic);
        // only small cells, never reaching 5: one cell, dof 0, p = 1, and no pass
        let t = test(&[1, 2], &[1.0, 2.0], 0.01);
        assert_eq!((t.dof, t.statistic, t.p_value), (0, 0.0, 1.0));
        assert_eq!((t.passed, t.untested), (false, Some(Untested::OneCell)));
    }

    /// Issue 24 item 2: GGX at α = 1e-12 seen by a quadrature that misses its peak, 10⁶
    /// samples all in the mirror bin, against 5e-11 expected in the bins and 10⁶ below the
    /// horizon. Pooled, every bin joins the below-horizon cell: one cell, χ² = 0 on 0 dof,
    /// which read p = 1, pass. So did a single sample.
    #[test]
    fn zero_degrees_of_freedom_never_pass() {
        let mut bins = vec![0u64; 64];
        bins[40] = 1_000_000;
        let expected = vec![5e-11 / 64.0; 64];
        let t = judge((&bins, &expected), (&[0, 0], &[1e6 - 5e-11, 0.0]), 0.01);
        assert_eq!((t.dof, t.passed, t.untested), (0, false, Some(Untested::OneCell)), "{t:?}");
        let t = judge((&[1, 0, 0], &[0.5, 0.3, 0.2]), (&[0], &[0.0]), 0.01);
        assert_eq!((t.dof, t.passed, t.untested), (0, false, Some(Untested::OneCell)), "{t:?}");
        // two cells test something
        let t = judge((&[500, 500], &[500.0, 500.0]), (&[0], &[0.0]), 0.01);
        assert_eq!((t.dof, t.passed, t.untested), (1, true, None));
    }

    /// Issue 24 item 1: a sampler that rejects every sample, with a pdf of 0 that agrees.
    #[test]
    fn no_valid_sample_never_passes() {
        // its reasons split over two cells of ≥ 5 (dof 1, χ² = 0): still no pass
        let t = judge((&[0; 8], &[0.0; 8]), (&[600, 400], &[600.0, 400.0]), 0.01);
        assert_eq!((t.dof, t.statistic, t.passed, t.untested), (1, 0.0, false, Some(Untested::NoValidSample)));
        // where the pdf expected valid samples, the statistic rejects too
        let t = judge((&[0; 4], &[250.0; 4]), (&[1000], &[0.0]), 0.01);
        assert_eq!((t.passed, t.untested), (false, Some(Untested::NoValidSample)));
    }

    #[test]
    fn rejects_a_shifted_histogram() {
        let e = vec![1000.0; 20];
        let mut o = vec![1000u64; 20];
        o[0] = 1200;
        o[1] = 800;
        assert!(!test(&o, &e, 0.01).passed);
    }
}
