//! Smith masking-shadowing G2 from the masking terms G1(ωi) and G1(ωr); the f64 twin of
//! `shaders/lib/masking.wgsl`.

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
    /// G2 = 1 / (1 + Λ(ωi) + Λ(ωr)) (Heitz 2014, eq. 99).
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
}
