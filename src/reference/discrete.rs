//! Discrete 1D distributions: the CPU twin of `shaders/lib/discrete.wgsl`.
//!
//! Weights → pmf → CDF, sampled by inverting the CDF with a binary search (pbrt-v4 §A.1,
//! "SampleDiscrete"), and Walker's alias method as built by Vose (1991), "A linear algorithm
//! for generating random numbers with a given distribution", IEEE TSE 17(9).
//!
//! The CDF is formed from prefix sums of the weights in f64 divided by the total, not by
//! summing rounded pmf values: for integer weights every CDF entry is then the correctly
//! rounded ratio, so a tie such as the tutorial's u = 0.9 = 90/100 lands exactly on its entry.

use thiserror::Error;

/// How a discrete distribution is sampled (a job's, and `lobes discrete`'s).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "check", derive(serde::Serialize, serde::Deserialize), serde(rename_all = "lowercase"))]
pub enum DiscreteMethod {
    /// Binary search for the first CDF entry ≥ u (the tutorial's rule).
    Cdf,
    /// Walker's alias table (Vose's construction), one uniform per draw.
    Alias,
}

impl DiscreteMethod {
    pub const ALL: [DiscreteMethod; 2] = [DiscreteMethod::Cdf, DiscreteMethod::Alias];

    /// The name in scene files, on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            DiscreteMethod::Cdf => "cdf",
            DiscreteMethod::Alias => "alias",
        }
    }
}

/// Why a list of weights cannot define a distribution.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum WeightsError {
    #[error("the weight list is empty; give at least one positive weight")]
    Empty,
    #[error("weight {index} is {value}; weights must be finite and ≥ 0")]
    Invalid { index: usize, value: f64 },
    #[error("all weights are zero; at least one must be positive")]
    AllZero,
    #[error("the weights sum to infinity in f64; scale them down")]
    Overflow,
}

/// One draw from a discrete distribution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscreteSample {
    pub index: usize,
    pub probability: f64,
}

/// A normalised discrete distribution with its CDF.
#[derive(Debug, Clone)]
pub struct Distribution {
    weights: Vec<f64>,
    pmf: Vec<f64>,
    cdf: Vec<f64>,
}

impl Distribution {
    /// Checks the weights and builds pmf and CDF: pmf_i = w_i / Σw, CDF_i = (Σ_{j≤i} w_j) / Σw.
    ///
    /// ```
    /// let d = lobes::reference::discrete::Distribution::new(&[1.0, 0.0, 3.0]).unwrap();
    /// assert_eq!(d.cdf(), &[0.25, 0.25, 1.0]);
    /// assert_eq!(d.sample_cdf(0.25).index, 0);
    /// assert_eq!(d.sample_cdf(0.26).index, 2);
    /// ```
    pub fn new(weights: &[f64]) -> Result<Self, WeightsError> {
        if weights.is_empty() {
            return Err(WeightsError::Empty);
        }
        if let Some((index, &value)) =
            weights.iter().enumerate().find(|(_, w)| !w.is_finite() || **w < 0.0)
        {
            return Err(WeightsError::Invalid { index, value });
        }
        let mut prefix = Vec::with_capacity(weights.len());
        let mut sum = 0.0;
        for &w in weights {
            sum += w;
            prefix.push(sum);
        }
        if sum == 0.0 {
            return Err(WeightsError::AllZero);
        }
        if !sum.is_finite() {
            return Err(WeightsError::Overflow);
        }
        let cdf: Vec<f64> = prefix.iter().map(|s| s / sum).collect();
        let pmf = weights.iter().map(|w| w / sum).collect();
        Ok(Self { weights: weights.to_vec(), pmf, cdf })
    }

    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
    pub fn pmf(&self) -> &[f64] {
        &self.pmf
    }
    pub fn cdf(&self) -> &[f64] {
        &self.cdf
    }
    pub fn len(&self) -> usize {
        self.pmf.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }

    /// CDF inversion: the first index whose CDF ≥ u and is positive, found by binary search.
    /// The "positive" clause only matters at u = 0 with leading zero weights, which the plain
    /// rule would select; u > 1 is treated as 1 (the last positive weight).
    pub fn sample_cdf(&self, u: f64) -> DiscreteSample {
        let index = first_at_least(&self.cdf, u).min(self.last_positive());
        DiscreteSample { index, probability: self.pmf[index] }
    }

    /// Two-level CDF inversion for tables too long for one 24-bit uniform or an f32 CDF
    /// (more than [`BLOCK`] entries): u0 picks a block of [`BLOCK`] entries by the CDF over
    /// blocks, u1 picks the entry by the block's own CDF. P(i) = P(block) · P(i | block), each
    /// level resolved to 2⁻²⁴ of its own range.
    pub fn sample_blocks(&self, u0: f64, u1: f64) -> DiscreteSample {
        let totals = block_cdf(&self.cdf);
        let block = first_at_least(&totals, u0).min(totals.len() - 1);
        let start = block * BLOCK;
        let local = local_cdf(&self.cdf, block);
        let index = (start + first_at_least(&local, u1).min(local.len() - 1)).min(self.last_positive());
        DiscreteSample { index, probability: self.pmf[index] }
    }

    /// CDF inversion as the GPU does it: one uniform up to [`BLOCK`] entries, two-level above.
    pub fn sample_cdf_gpu_layout(&self, u0: f64, u1: f64) -> DiscreteSample {
        if self.len() <= BLOCK { self.sample_cdf(u0) } else { self.sample_blocks(u0, u1) }
    }

    fn last_positive(&self) -> usize {
        self.pmf.iter().rposition(|&p| p > 0.0).expect("checked in new")
    }
}

/// Entries per block of the two-level CDF (and the largest table sampled with one uniform).
pub const BLOCK: usize = 4096;

/// The CDF over blocks of [`BLOCK`] entries: the global CDF at each block's last entry.
pub fn block_cdf(cdf: &[f64]) -> Vec<f64> {
    cdf.chunks(BLOCK).map(|c| *c.last().unwrap()).collect()
}

/// Block `b`'s own CDF: (CDF_i − CDF before the block) / (the block's mass), 0s for an empty block.
pub fn local_cdf(cdf: &[f64], b: usize) -> Vec<f64> {
    let before = if b == 0 { 0.0 } else { cdf[b * BLOCK - 1] };
    let chunk = &cdf[b * BLOCK..((b + 1) * BLOCK).min(cdf.len())];
    let mass = chunk.last().unwrap() - before;
    chunk.iter().map(|c| if mass > 0.0 { ((c - before) / mass).min(1.0) } else { 0.0 }).collect()
}

/// Binary search for the first `i` with `cdf[i] ≥ u` and `cdf[i] > 0`; `cdf.len()` if none.
/// Both conditions are monotone in `i`, so the predicate is too.
pub fn first_at_least(cdf: &[f64], u: f64) -> usize {
    cdf.partition_point(|&c| !(c >= u && c > 0.0))
}

/// Walker's alias table, built by Vose's method in f64.
///
/// Column `i` keeps itself with probability `threshold[i]` and otherwise yields `alias[i]`.
#[derive(Debug, Clone)]
pub struct AliasTable {
    pub threshold: Vec<f64>,
    pub alias: Vec<u32>,
    pmf: Vec<f64>,
}

impl AliasTable {
    /// Vose's construction. Round-off can leave entries in one list when the other runs out;
    /// such an entry keeps itself (threshold 1) unless its weight is zero, in which case it is
    /// pointed at a positive entry so that a zero weight is never selected.
    pub fn new(dist: &Distribution) -> Self {
        let n = dist.len();
        let scaled: Vec<f64> = dist.pmf().iter().map(|p| p * n as f64).collect();
        let mut threshold = scaled.clone();
        let mut alias: Vec<u32> = (0..n as u32).collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            alias[s] = l as u32;
            threshold[l] = (threshold[l] + threshold[s]) - 1.0;
            if threshold[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        let fallback = dist.last_positive();
        for i in large.into_iter().chain(small) {
            if dist.pmf()[i] > 0.0 {
                threshold[i] = 1.0;
            } else {
                threshold[i] = 0.0;
                alias[i] = fallback as u32;
            }
        }
        for t in &mut threshold {
            *t = t.clamp(0.0, 1.0);
        }
        Self { threshold, alias, pmf: dist.pmf().to_vec() }
    }

    /// Samples with two uniforms: column ⌊u0·n⌋ (clamped to n−1 for u0 = 1), kept if u1 < threshold.
    pub fn sample(&self, u0: f64, u1: f64) -> DiscreteSample {
        let n = self.threshold.len();
        let column = ((u0 * n as f64) as usize).min(n - 1);
        let index = if u1 < self.threshold[column] { column } else { self.alias[column] as usize };
        DiscreteSample { index, probability: self.pmf[index] }
    }

    /// Samples with one uniform, reusing its fraction for the coin: u0 = u, u1 = frac(u·n)
    /// (the classic single-uniform alias lookup, used where a caller gives one number).
    pub fn sample_one(&self, u: f64) -> DiscreteSample {
        let n = self.threshold.len() as f64;
        let x = u * n;
        let column = x.floor().min(n - 1.0);
        self.sample(u, x - column)
    }

    /// The distribution the table actually encodes: P(i) = (t_i + Σ_{j: alias_j = i, j≠i} (1 − t_j)) / n.
    pub fn encoded_pmf(&self) -> Vec<f64> {
        let n = self.threshold.len();
        let mut p = vec![0.0; n];
        for (j, (&t, &a)) in self.threshold.iter().zip(&self.alias).enumerate() {
            p[j] += t / n as f64;
            p[a as usize] += (1.0 - t) / n as f64;
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TUTORIAL: [f64; 10] = [15., 5., 5., 25., 5., 10., 15., 5., 5., 10.];

    #[test]
    fn tutorial_cdf_is_exact_and_u_on_entries_selects_that_entry() {
        let d = Distribution::new(&TUTORIAL).unwrap();
        let expect = [0.15, 0.2, 0.25, 0.5, 0.55, 0.65, 0.8, 0.85, 0.9, 1.0];
        assert_eq!(d.cdf(), &expect);
        // The tutorial's rule, first CDF ≥ u: 0.5 → 3 (25), 0.25 → 2 (5), 0.9 → 8 (5), 0.65 → 5 (10).
        let got: Vec<usize> = [0.5, 0.25, 0.9, 0.65].iter().map(|&u| d.sample_cdf(u).index).collect();
        assert_eq!(got, [3, 2, 8, 5]);
    }

    #[test]
    fn summing_rounded_pmf_drifts_and_a_strict_rule_flips_the_tie() {
        // Summing the rounded pmf 0.15 + 0.05 + … in f64 drifts: the ninth entry comes out as
        // 0.9000000000000001 and the last as 1.0000000000000002, not 1. Here the drift is upward,
        // so "first CDF ≥ u" still picks index 8 at u = 0.9 (and so does "first CDF > u" on this
        // drifted CDF). On the exact CDF the strict rule "first CDF > u" picks index 9 (weight
        // 10), the tutorial's answer.
        let mut s = 0.0;
        let naive: Vec<f64> = TUTORIAL.iter().map(|w| { s += w / 100.0; s }).collect();
        assert_eq!(naive[8], 0.9000000000000001);
        assert!(naive[9] > 1.0);
        assert_eq!(first_at_least(&naive, 0.9), 8);
        assert_eq!(naive.partition_point(|&c| c <= 0.9), 8);
        let exact = Distribution::new(&TUTORIAL).unwrap();
        assert_eq!(exact.cdf().partition_point(|&c| c <= 0.9), 9);
    }

    #[test]
    fn zero_weights_are_never_selected() {
        let d = Distribution::new(&[0.0, 0.0, 2.0, 0.0, 1.0, 0.0]).unwrap();
        let a = AliasTable::new(&d);
        for u in [0.0, 1e-300, 0.3, 2.0 / 3.0, 0.7, 1.0 - 1e-16, 1.0] {
            assert!(d.weights()[d.sample_cdf(u).index] > 0.0, "cdf u={u}");
            assert!(d.weights()[a.sample_one(u).index] > 0.0, "alias u={u}");
            for u1 in [0.0, 0.5, 1.0] {
                assert!(d.weights()[a.sample(u, u1).index] > 0.0, "alias u={u} u1={u1}");
            }
        }
    }

    #[test]
    fn alias_table_encodes_the_pmf() {
        let d = Distribution::new(&TUTORIAL).unwrap();
        let a = AliasTable::new(&d);
        for (p, q) in a.encoded_pmf().iter().zip(d.pmf()) {
            assert!((p - q).abs() < 1e-15);
        }
    }

    #[test]
    fn bad_weights_are_errors() {
        assert_eq!(Distribution::new(&[]).unwrap_err(), WeightsError::Empty);
        assert_eq!(Distribution::new(&[0.0, 0.0]).unwrap_err(), WeightsError::AllZero);
        assert!(matches!(Distribution::new(&[1.0, -1.0]), Err(WeightsError::Invalid { index: 1, .. })));
        assert!(matches!(Distribution::new(&[f64::NAN]), Err(WeightsError::Invalid { index: 0, .. })));
        assert!(matches!(Distribution::new(&[f64::INFINITY]), Err(WeightsError::Invalid { .. })));
        assert_eq!(Distribution::new(&[f64::MAX, f64::MAX]).unwrap_err(), WeightsError::Overflow);
    }
}
