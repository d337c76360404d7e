//! The median of repeated measurements (run times): robust to the odd slow run.

/// The median of `v`, the upper one for an even count (no averaging: it is always one of the
/// measurements). Panics on an empty `v`.
///
/// ```
/// use lobes::stats::median::median;
/// assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
/// assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 3.0);
/// ```
pub fn median(mut v: Vec<f64>) -> f64 {
    assert!(!v.is_empty(), "the median of no measurements");
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
