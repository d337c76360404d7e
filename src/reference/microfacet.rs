//! What Beckmann and GGX share: the normal distribution D, Smith's Λ and G1, and the densities
//! of the two ways of sampling a half vector. The CPU twin of `shaders/lib/microfacet.wgsl`.
//!
//! - NDF sampling draws h with density D(h) cos θh (Walter et al. 2007, eq. 24's normalisation
//!   ∫ D(h) cos θh dωh = 1).
//! - Visible-normal sampling draws h with density D_ωi(h) = G1(ωi) max(0, ωi·h) D(h) / cos θi
//!   (Heitz 2014, "Understanding the Masking-Shadowing Function", eq. 38), whose reflected
//!   density is p(ωr) = G1(ωi) D(h) / (4 cos θi).

use glam::DVec3;

/// A microfacet normal distribution with its Smith masking function.
pub trait Microfacet {
    /// D(h): the distribution of normals, per unit solid angle.
    fn d(&self, h: DVec3) -> f64;
    /// Smith's Λ(ω) (Heitz 2014, eq. 72 for Beckmann, eq. 86 for GGX).
    fn lambda(&self, w: DVec3) -> f64;
    /// G1(ω) = 1 / (1 + Λ(ω)) (Heitz 2014, eq. 43).
    fn g1(&self, w: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(w))
    }
    /// G1(ω) / cos θ, in a form that stays finite as cos θ → 0 (grazing incidence), where
    /// G1 → 0 and cos θ → 0 together.
    fn g1_over_cos(&self, w: DVec3) -> f64 {
        self.g1(w) / w.z
    }
    /// A half vector with density D(h) cos θh.
    fn sample_ndf(&self, u: [f64; 2]) -> DVec3;
    /// A half vector with density D_ωi(h) (visible normals).
    fn sample_vndf(&self, wi: DVec3, u: [f64; 2]) -> DVec3;
}

/// Density of NDF sampling: D(h) cos θh, zero for hz ≤ 0.
pub fn pdf_ndf(m: &impl Microfacet, h: DVec3) -> f64 {
    if h.z <= 0.0 { 0.0 } else { m.d(h) * h.z }
}

/// Density of visible-normal sampling (Heitz 2014, eq. 38): G1(ωi) max(0, ωi·h) D(h) / cos θi,
/// with G1/cos θi taken in its stable form (finite at θi = 90°). Zero for ωi below the horizon.
pub fn pdf_vndf(m: &impl Microfacet, wi: DVec3, h: DVec3) -> f64 {
    let cos_ih = wi.dot(h);
    if wi.z < 0.0 || h.z <= 0.0 || cos_ih <= 0.0 {
        return 0.0;
    }
    m.g1_over_cos(wi) * cos_ih * m.d(h)
}

/// Height-correlated Smith G2 (Heitz 2014, eq. 99): 1 / (1 + Λ(ωi) + Λ(ωr)).
pub fn g2(m: &impl Microfacet, wi: DVec3, wr: DVec3) -> f64 {
    1.0 / (1.0 + m.lambda(wi) + m.lambda(wr))
}

/// The microfacet BRDF without Fresnel (Walter et al. 2007, eq. 20, F = 1):
/// f = D(h) G2(ωi, ωr) / (4 cos θi cos θr).
pub fn eval(m: &impl Microfacet, wi: DVec3, wr: DVec3) -> f64 {
    if wi.z <= 0.0 || wr.z <= 0.0 {
        return 0.0;
    }
    let h = (wi + wr).normalize();
    m.d(h) * g2(m, wi, wr) / (4.0 * wi.z * wr.z)
}

/// The direction ωi stretched into the α = 1 configuration and renormalised:
/// normalize(αx ωx, αy ωy, ωz) (Heitz 2018, "Sampling the GGX Distribution of Visible
/// Normals", listing 1 step 1).
pub fn stretch(ax: f64, ay: f64, w: DVec3) -> DVec3 {
    DVec3::new(ax * w.x, ay * w.y, w.z).normalize()
}
