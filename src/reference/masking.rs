//! Smith masking-shadowing G2 from the masking terms G1(ωi) and G1(ωr); the f64 twin of
//! `shaders/lib/masking.wgsl`.
//!
//! The height-correlated forms (Heitz 2014, "Understanding the masking-shadowing function",
//! eq. 99 and its transmitted case) follow from Smith's G1 at height h, C(h)^Λ(ω) for a
//! direction seen from above and (1 − C(h))^Λ(ω) from below, C the heights' CDF: averaged over
//! the heights, a reflection keeps ∫₀¹ C^Λi C^Λo dC = 1 / (1 + Λi + Λo) and a transmission
//! ∫₀¹ C^Λi (1 − C)^Λo dC = B(1 + Λi, 1 + Λo), Euler's Beta function. By Chebyshev's integral
//! inequality the reflection's G2 is at least G1(ωi) G1(ωo) (both factors increase with C) and
//! the transmission's at most (one increases, the other decreases): a high microfacet is seen
//! from above and hidden from below.

use serde::Serialize;

/// Which masking-shadowing term multiplies the microfacet BRDF.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Masking {
    /// G = 1: no masking (the BRDF is D / (4 cos θi cos θr)).
    None,
    /// G = G1(ωi): masking of the incident direction only (Heitz 2014's "weak white furnace").
    G1,
    /// G2 = G1(ωi) G1(ωr) (Heitz 2014, eq. 98).
    Separable,
    /// G2 = 1 / (1 + Λ(ωi) + Λ(ωr)) (Heitz 2014, eq. 99); across a rough dielectric's surface
    /// B(1 + Λ(ωi), 1 + Λ(ωo)) (`Masking::g_transmitted`).
    HeightCorrelated,
}

impl Masking {
    /// G from the two directions' G1 values (in [0, 1]).
    pub fn g(self, gi: f64, gr: f64) -> f64 {
        match self {
            Masking::None => 1.0,
            Masking::G1 => gi,
            Masking::Separable => gi * gr,
            // 1 / (1 + Λi + Λr) with Λ = 1/G1 − 1, finite as G1 → 0
            Masking::HeightCorrelated if gi <= 0.0 || gr <= 0.0 => 0.0,
            Masking::HeightCorrelated => gi * gr / (gi + gr - gi * gr),
        }
    }
    /// G for a pair on opposite sides of the surface (a transmission through a rough
    /// dielectric) from the two directions' G1 values: as [`g`](Self::g), except that the
    /// height-correlated G2 is B(1 + Λ(ωi), 1 + Λ(ωo)) (module notes), with 1 + Λ = 1/G1; 0
    /// where a G1 is 0. `shaders/lib/masking.wgsl`'s `masking_height_correlated_transmitted` is
    /// its twin.
    ///
    /// ```
    /// use lobes::reference::masking::Masking;
    /// // Λ(ωi) = Λ(ωo) = 1: B(2, 2) = 1/6, below the separable 1/4 and the reflection's 1/3
    /// let hc = Masking::HeightCorrelated;
    /// assert!((hc.g_transmitted(0.5, 0.5) - 1.0 / 6.0).abs() < 1e-14);
    /// assert!((hc.g(0.5, 0.5) - 1.0 / 3.0).abs() < 1e-15);
    /// assert_eq!(Masking::Separable.g_transmitted(0.5, 0.5), 0.25);
    /// ```
    pub fn g_transmitted(self, gi: f64, go: f64) -> f64 {
        match self {
            Masking::HeightCorrelated => {
                let (x, y) = (1.0 / gi, 1.0 / go);
                if x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0 { statrs::function::beta::ln_beta(x, y).exp() } else { 0.0 }
            }
            _ => self.g(gi, go),
        }
    }
    /// The kernels' code for this term (`MASKING` in the composed WGSL).
    pub fn mode(self) -> u32 {
        self as u32
    }
    pub fn name(self) -> &'static str {
        match self {
            Masking::None => "none",
            Masking::G1 => "g1",
            Masking::Separable => "separable",
            Masking::HeightCorrelated => "height-correlated",
        }
    }
    pub const ALL: [Masking; 4] = [Masking::None, Masking::G1, Masking::Separable, Masking::HeightCorrelated];
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn height_correlated_is_one_over_one_plus_both_lambdas() {
        let (li, lr) = (0.3f64, 1.7f64);
        let (gi, gr) = (1.0 / (1.0 + li), 1.0 / (1.0 + lr));
        assert!((Masking::HeightCorrelated.g(gi, gr) - 1.0 / (1.0 + li + lr)).abs() < 1e-15);
        // correlation can only help: G2 ≥ G1 G1
        assert!(Masking::HeightCorrelated.g(gi, gr) >= Masking::Separable.g(gi, gr));
    }

    /// The transmitted height-correlated G2 against closed forms: B(1, 1) = 1,
    /// B(2, 3) = 1!·2!/4! = 1/12, B(3/2, 3/2) = Γ(3/2)²/Γ(3) = π/8, B(1, y) = 1/y (Λ(ωi) → 0
    /// leaves G1(ωo)); tests/dielectric.rs adds a quadrature of Euler's integral.
    #[test]
    fn transmitted_height_correlated_is_the_beta_function() {
        let hc = Masking::HeightCorrelated;
        let g = |x: f64, y: f64| hc.g_transmitted(1.0 / x, 1.0 / y);
        assert!((g(1.0, 1.0) - 1.0).abs() < 1e-15);
        assert!((g(2.0, 3.0) * 12.0 - 1.0).abs() < 1e-13, "{}", g(2.0, 3.0));
        assert!((g(1.5, 1.5) * 8.0 / std::f64::consts::PI - 1.0).abs() < 1e-13);
        for go in [0.9, 0.3, 1e-3] {
            for lambda_i in [1e-9, 1e-6] {
                let gi = 1.0 / (1.0 + lambda_i);
                assert!((hc.g_transmitted(gi, go) / go - 1.0).abs() < 2.0 * lambda_i * (1.0 / go).ln().max(1.0), "Λi {lambda_i} G1o {go}");
            }
        }
        assert_eq!(hc.g_transmitted(0.0, 0.5), 0.0);
        assert_eq!(hc.g_transmitted(0.5, 0.0), 0.0);
    }

    /// Chebyshev's integral inequality (module notes): across the surface the height-correlated
    /// G2 is at most the separable one, on the incident side at least, both at most min(G1),
    /// over G1 from grazing (Λ 10³) to normal.
    #[test]
    fn height_correlation_helps_reflection_and_hurts_transmission() {
        let g1s = [1.0, 0.99, 0.8, 0.5, 0.2, 0.05, 1e-3];
        for gi in g1s {
            for go in g1s {
                let (t, r, s) = (Masking::HeightCorrelated.g_transmitted(gi, go), Masking::HeightCorrelated.g(gi, go), gi * go);
                assert!(t <= s * (1.0 + 1e-12) && r >= s * (1.0 - 1e-15), "G1 {gi} {go}: transmitted {t}, reflected {r}, separable {s}");
                // B(1000, 1000) ≈ 2⁻²⁰⁰⁰ underflows to 0
                assert!(t >= 0.0 && r <= gi.min(go) * (1.0 + 1e-15), "G1 {gi} {go}");
                if gi < 1.0 && go < 1.0 {
                    assert!(t < s && r > s, "strict inside (0, 1): G1 {gi} {go}");
                }
            }
        }
    }
}
