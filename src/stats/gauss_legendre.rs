//! Gauss–Legendre quadrature: the n-point rule on [−1, 1], mapped to an interval, and its
//! tensor product on a rectangle. The one rule behind the adaptive expected counts
//! ([`crate::stats::expected`]), `lobes tradeoff`'s fixed rules and the reference's tests.

/// The n-point Gauss–Legendre rule: exact on [−1, 1] for polynomials of degree ≤ 2n − 1.
///
/// ```
/// use lobes::stats::gauss_legendre::GaussLegendre;
/// // 3 points integrate x⁴ exactly: ∫₀² x⁴ dx = 32/5
/// let v: f64 = GaussLegendre::new(3).on(0.0, 2.0).map(|(x, w)| w * x.powi(4)).sum();
/// assert!((v - 6.4).abs() < 1e-14);
/// ```
#[derive(Debug, Clone)]
pub struct GaussLegendre {
    nodes: Vec<(f64, f64)>,
}

impl GaussLegendre {
    /// The nodes are the roots of Pₙ, found by Newton's method from Tricomi's first guess
    /// cos(π(i + ¾)/(n + ½)); the weights are 2 / ((1 − x²) Pₙ'(x)²) (Abramowitz & Stegun
    /// 25.4.29; Numerical Recipes §4.5, `gauleg`).
    pub fn new(n: usize) -> Self {
        assert!(n >= 1, "a Gauss–Legendre rule needs at least one node");
        let mut nodes = vec![(0.0, 0.0); n];
        for i in 0..n.div_ceil(2) {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(n, x);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let dp = legendre(n, x).1; // at the converged root, not the last iterate
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            nodes[i] = (-x, w);
            nodes[n - 1 - i] = (x, w);
        }
        if n % 2 == 1 {
            nodes[n / 2].0 = 0.0; // the middle root of an odd Pₙ, exactly
        }
        Self { nodes }
    }

    /// The (node, weight) pairs on [−1, 1], nodes increasing.
    pub fn nodes(&self) -> &[(f64, f64)] {
        &self.nodes
    }

    /// The (node, weight) pairs mapped to [a, b].
    pub fn on(&self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
        self.nodes.iter().map(move |&(x, w)| (c + h * x, h * w))
    }

    /// ∫ f over [a, b] by this rule, each part halved until its halves' sum agrees with the
    /// whole within `tol` times the part's share of [a, b] (so the total error is about `tol`),
    /// at most 30 times: for integrands smooth on [a, b], whose kinks and jumps the caller
    /// makes endpoints.
    ///
    /// ```
    /// use lobes::stats::gauss_legendre::GaussLegendre;
    /// // ∫₀¹ √x dx = 2/3: the square root's singular derivative at 0 is refined towards
    /// let v = GaussLegendre::new(7).integrate_adaptive(0.0, 1.0, 1e-12, &|x: f64| x.sqrt());
    /// assert!((v - 2.0 / 3.0).abs() < 1e-11);
    /// ```
    pub fn integrate_adaptive(&self, a: f64, b: f64, tol: f64, f: &impl Fn(f64) -> f64) -> f64 {
        self.integrate_adaptive_n(a, b, tol, &|x| [f(x)])[0]
    }

    /// [`integrate_adaptive`](Self::integrate_adaptive) of N integrands at once, on the same
    /// nodes (each f evaluated once per node), a part accepted when every component agrees.
    pub fn integrate_adaptive_n<const N: usize>(&self, a: f64, b: f64, tol: f64, f: &impl Fn(f64) -> [f64; N]) -> [f64; N] {
        let whole = self.sum_on(a, b, f);
        self.refine(a, b, whole, tol / (b - a).abs(), f, 0)
    }

    fn sum_on<const N: usize>(&self, a: f64, b: f64, f: &impl Fn(f64) -> [f64; N]) -> [f64; N] {
        let mut sum = [0.0; N];
        for (x, w) in self.on(a, b) {
            for (s, v) in sum.iter_mut().zip(f(x)) {
                *s += w * v;
            }
        }
        sum
    }

    fn refine<const N: usize>(&self, a: f64, b: f64, whole: [f64; N], tol_per_length: f64, f: &impl Fn(f64) -> [f64; N], depth: u32) -> [f64; N] {
        let m = 0.5 * (a + b);
        let (left, right) = (self.sum_on(a, m, f), self.sum_on(m, b, f));
        let both: [f64; N] = std::array::from_fn(|k| left[k] + right[k]);
        let agree = (0..N).all(|k| (both[k] - whole[k]).abs() <= tol_per_length * (b - a).abs());
        if agree || depth >= 30 {
            return both;
        }
        let (l, r) = (self.refine(a, m, left, tol_per_length, f, depth + 1), self.refine(m, b, right, tol_per_length, f, depth + 1));
        std::array::from_fn(|k| l[k] + r[k])
    }

    /// ∫∫ f(x, y) over [x.0, x.1] × [y.0, y.1] by the tensor-product rule.
    pub fn integrate_2d(&self, x: (f64, f64), y: (f64, f64), f: impl Fn(f64, f64) -> f64) -> f64 {
        let (hx, cx) = (0.5 * (x.1 - x.0), 0.5 * (x.1 + x.0));
        let (hy, cy) = (0.5 * (y.1 - y.0), 0.5 * (y.1 + y.0));
        let mut sum = 0.0;
        for &(xi, wi) in &self.nodes {
            for &(yj, wj) in &self.nodes {
                sum += wi * wj * f(cx + hx * xi, cy + hy * yj);
            }
        }
        sum * hx * hy
    }
}

/// (Pₙ(x), Pₙ'(x)): the recurrence k Pₖ = (2k − 1) x Pₖ₋₁ − (k − 1) Pₖ₋₂ from P₀ = 1, and
/// Pₙ' = n (x Pₙ − Pₙ₋₁) / (x² − 1) (A&S 22.7.10, 22.8.5), for |x| < 1.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p, mut p_prev) = (1.0, 0.0); // P₀, P₋₁
    for k in 1..=n {
        (p, p_prev) = (((2 * k - 1) as f64 * x * p - (k - 1) as f64 * p_prev) / k as f64, p);
    }
    (p, n as f64 * (x * p - p_prev) / (x * x - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-15 * b.abs().max(1.0) // a few ulps
    }

    #[test]
    fn nodes_and_weights_match_the_closed_forms() {
        // n = 3: ±√(3/5), 0 with weights 5/9, 8/9.
        let g = GaussLegendre::new(3);
        let want3 = [(-(0.6f64).sqrt(), 5.0 / 9.0), (0.0, 8.0 / 9.0), ((0.6f64).sqrt(), 5.0 / 9.0)];
        for (got, want) in g.nodes().iter().zip(want3) {
            assert!(close(got.0, want.0) && close(got.1, want.1), "{got:?} vs {want:?}");
        }
        // n = 5: ±(1/3)√(5 ∓ 2√(10/7)) with weights (322 ± 13√70)/900, and 0 with 128/225.
        let g = GaussLegendre::new(5);
        let (r, s70) = ((10.0f64 / 7.0).sqrt(), 70f64.sqrt());
        let inner = ((5.0 - 2.0 * r).sqrt() / 3.0, (322.0 + 13.0 * s70) / 900.0);
        let outer = ((5.0 + 2.0 * r).sqrt() / 3.0, (322.0 - 13.0 * s70) / 900.0);
        let want5 = [(-outer.0, outer.1), (-inner.0, inner.1), (0.0, 128.0 / 225.0), inner, outer];
        for (got, want) in g.nodes().iter().zip(want5) {
            assert!(close(got.0, want.0) && close(got.1, want.1), "{got:?} vs {want:?}");
        }
        // A&S table 25.4, n = 5, to the table's 15 digits
        assert!((g.nodes()[4].0 - 0.906_179_845_938_664).abs() < 1e-15);
        assert!((g.nodes()[4].1 - 0.236_926_885_056_189).abs() < 1e-15);
    }

    #[test]
    fn n_points_integrate_degree_2n_minus_1_exactly() {
        for n in [1, 2, 3, 4, 8, 16, 64] {
            let g = GaussLegendre::new(n);
            let even: f64 = g.nodes().iter().map(|&(x, w)| w * x.powi(2 * n as i32 - 2)).sum();
            let odd: f64 = g.nodes().iter().map(|&(x, w)| w * x.powi(2 * n as i32 - 1)).sum();
            assert!((even - 2.0 / (2 * n - 1) as f64).abs() < 1e-14, "n {n}: {even}");
            assert!(odd.abs() < 1e-14, "n {n}: {odd}");
            assert!((g.nodes().iter().map(|p| p.1).sum::<f64>() - 2.0).abs() < 1e-14);
        }
    }

    #[test]
    fn tensor_rule_on_a_rectangle() {
        // ∫₀¹∫₂³ x³ y² dy dx = (1/4)(19/3), exact for 2 points per axis
        let v = GaussLegendre::new(2).integrate_2d((0.0, 1.0), (2.0, 3.0), |x, y| x.powi(3) * y * y);
        assert!((v - 19.0 / 12.0).abs() < 1e-15, "{v}");
    }
}
