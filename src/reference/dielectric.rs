//! The rough dielectric: light reflected by or refracted through a microfacet surface between
//! two media (Walter, Marschner, Li & Torrance 2007, "Microfacet Models for Refraction through
//! Rough Surfaces"), for GGX and Beckmann, with h drawn by the NDF or by visible normals.
//!
//! Conventions: η = η_t/η_i is the index of the medium below the surface (z < 0) relative to
//! the one above. ωi and ωo point away from the surface. Light from inside (ωi.z < 0) sees the
//! same microsurface mirrored in its tangent plane with η inverted: every function mirrors both
//! directions, (x, y, z) → (x, y, −z), works on the upper side and mirrors back (D, Λ and G1
//! depend on z only through z² or |z|, so the mirrored surface is the surface).
//!
//! On the upper side, with h drawn with density p(h) and c = ωi·h:
//! - Fresnel F(c, η): [`fresnel::dielectric`], 1 for c ≤ 0 and past the critical angle (TIR);
//!   wherever 1 − F multiplies, it is [`fresnel::dielectric_transmittance`], which keeps its
//!   digits as F → 1;
//! - reflection with probability F: ωr = 2c h − ωi, p(ωr) = F p(h) / (4 |ωr·h|) (eq. 14);
//! - otherwise refraction by Snell's law about h ([`refract`]), with the density of eq. 17,
//!   p(ωt) = (1 − F) p(h) η² |ωt·h| / (c + η ωt·h)² ([`jacobian_transmitted`]);
//! - the BSDF (eqs. 20 and 21): F D G / (4 |cos θi| |cos θo|) on the incident side and
//!   (1 − F) D G c η² |ωt·h| / (|cos θi| |cos θt| (c + η ωt·h)²) across the surface.
//!
//! A sample is valid only on the side of its event: a reflection that leaves through the
//! surface (ωr on the far side) and a refraction that stays on the incident side (ωt on the
//! near side, a microfacet tilted past the macro surface) are not directions of the BSDF; their
//! density is 0 and [`DielectricSample::valid`] is false.

use super::effects::{Effects, d, g1};
use super::fresnel;
use super::masking::Masking;
use super::sampler::Shape;
use super::reflect::{pdf_reflected, reflect};
use super::{Lobe, LobeSample, Method};
use glam::DVec3;

/// The least u₀, u₁ the h draw takes, 2⁻²⁵ (half a step of the RNG's lattice k·2⁻²⁴): u = 0 draws
/// Beckmann's visible slope at −∞, an h on the horizon with D(h) = 0, whose refraction has no
/// density (a `zero_pdf` sample that no expected count holds, once in 2²⁴ samples); the floor
/// moves that atom to a direction of positive density and leaves every other u as it is.
/// `shaders/lib/dielectric.wgsl`'s `dielectric_u` is its twin.
pub const U_FLOOR: f64 = 1.0 / 33_554_432.0; // 2⁻²⁵

/// A rough dielectric: a microfacet lobe (GGX or Beckmann, NDF or visible-normal sampling) and
/// the relative index η of the medium below.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoughDielectric {
    pub lobe: Lobe,
    pub eta: f64,
}

/// Which way a sample left the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    Reflection,
    Transmission,
}

/// One sample of a rough dielectric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricSample {
    /// The microfacet normal drawn, on the side of ωi (h·ωi > 0 unless NDF sampling drew a
    /// back-facing normal, which reflects with F = 1).
    pub h: DVec3,
    /// The scattered direction.
    pub omega_o: DVec3,
    pub event: Event,
    /// F(ωi·h), the probability with which reflection was chosen.
    pub fresnel: f64,
    /// p(h), per unit solid angle.
    pub pdf_h: f64,
    /// The density of ωo: that of its event, 0 for a sample on the wrong side.
    pub pdf_o: f64,
    /// ωo is finite, on the side of its event, with a finite positive density.
    pub valid: bool,
}

/// (x, y, −z): the tangent-plane mirror that puts light from inside on the upper side.
fn mirror(w: DVec3) -> DVec3 {
    DVec3::new(w.x, w.y, -w.z)
}

/// Snell refraction of ωi about the unit normal h into the medium of relative index η:
/// ωt = (c/η − cos θt) h − ωi/η with c = ωi·h > 0 ([`fresnel::cos_transmitted`]), so that
/// ωt·h = −cos θt and |ωt × h| = |ωi × h|/η. `None` for c ≤ 0 and under total internal reflection.
pub fn refract(wi: DVec3, h: DVec3, eta: f64) -> Option<DVec3> {
    let c = wi.dot(h);
    if c <= 0.0 {
        return None;
    }
    let ct = fresnel::cos_transmitted(c.min(1.0), eta)?;
    Some((c / eta - ct) * h - wi / eta)
}

/// The microfacet normal that refracts ωi into ωo (Walter 2007, eq. 16): h ∝ ωi + η ωo, turned
/// to the upper side; `None` unless ωi is in front of it and ωo behind (ωi·h > 0 > ωo·h), the
/// only configuration Snell's law produces.
pub fn refraction_half_vector(wi: DVec3, wo: DVec3, eta: f64) -> Option<DVec3> {
    let v = wi + eta * wo;
    let len = v.length();
    if !(len > 0.0 && len.is_finite()) || v.z == 0.0 {
        return None;
    }
    let h = v / len * v.z.signum();
    (wi.dot(h) > 0.0 && wo.dot(h) < 0.0).then_some(h)
}

/// dωh/dωt = η² |ωt·h| / (c + η ωt·h)² of the refraction map (Walter 2007, eq. 17) for c = ωi·h
/// and ct = |ωt·h| related by Snell's law, in the form η² ct (c + η ct)² / (1 − η²)².
///
/// Why that form: the denominator c − η ct vanishes as η → 1 (ωt → −ωi whatever h), and formed
/// as a difference it keeps only the digits that c and η ct do not share. With Snell's law,
/// η² ct² = η² − 1 + c², so (c − η ct)(c + η ct) = c² − η² ct² = 1 − η² exactly: the
/// difference becomes a quotient of a sum and 1 − η², which has no cancellation beyond that
/// of η itself.
pub fn jacobian_transmitted(c: f64, ct: f64, eta: f64) -> f64 {
    let s = c + eta * ct;
    let one_minus_eta2 = (1.0 - eta) * (1.0 + eta);
    eta * eta * ct * s * s / (one_minus_eta2 * one_minus_eta2)
}

impl RoughDielectric {
    /// Checks that the lobe has a dielectric sampler (a microfacet lobe, NDF or visible normals)
    /// and η is finite, positive and not 1 (at η = 1 refraction is the delta ωt = −ωi).
    pub fn new(lobe: Lobe, eta: f64) -> Result<Self, String> {
        if !matches!(lobe.kind.spec().shape, Shape::Microfacet(_)) {
            return Err(format!("a rough dielectric needs a microfacet lobe, not {}", lobe.kind.name()));
        }
        if !matches!(lobe.method, Method::Ndf | Method::Vndf) {
            return Err(format!("a rough dielectric samples by ndf or vndf, not {}", lobe.method.name()));
        }
        if !(eta.is_finite() && eta > 0.0) || eta == 1.0 {
            return Err(format!("eta must be finite, positive and not 1 (a surface between equal media refracts as a delta), got {eta}"));
        }
        Ok(Self { lobe, eta })
    }

    /// ωi moved to the upper side and the η seen from there: whether it was mirrored.
    fn incident(&self, wi: DVec3) -> (bool, DVec3, f64) {
        if wi.z < 0.0 { (true, mirror(wi), 1.0 / self.eta) } else { (false, wi, self.eta) }
    }

    /// ωi on the upper side (mirrored in the tangent plane if it came from inside) and the
    /// relative index η seen from there, where every formula of the module notes applies.
    pub fn upper_side(&self, wi: DVec3) -> (DVec3, f64) {
        let (_, wi, eta) = self.incident(wi);
        (wi, eta)
    }

    /// Draws h from the lobe with `u[0..2]` for ωi on the upper side, and chooses reflection
    /// when `u[2]` < F(ωi·h), refraction otherwise (Walter 2007, §5.3).
    ///
    /// ```
    /// use lobes::reference::dielectric::{Event, RoughDielectric};
    /// use lobes::reference::{Lobe, LobeKind, Method, reflect::spherical};
    /// let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Vndf, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 };
    /// let glass = RoughDielectric::new(lobe, 1.5).unwrap();
    /// let wi = spherical(0.5, 0.0);
    /// let s = glass.sample(wi, [0.25, 0.5, 0.9]); // u[2] = 0.9 > F: refraction
    /// assert_eq!(s.event, Event::Transmission);
    /// assert!(s.valid && s.omega_o.z < 0.0);
    /// assert!((s.pdf_o / glass.pdf(wi, s.omega_o) - 1.0).abs() < 1e-9);
    /// ```
    pub fn sample(&self, wi: DVec3, u: [f64; 3]) -> DielectricSample {
        let (upper, _) = self.upper_side(wi);
        self.scatter(wi, self.lobe.sample_h(upper, [u[0].max(U_FLOOR), u[1].max(U_FLOOR)]), u[2])
    }

    /// Scatters ωi (either side) about the microfacet normal h, given on the upper side (where
    /// [`upper_side`](Self::upper_side) puts ωi): reflection when `u2` < F(ωi·h), refraction
    /// otherwise, with the densities of the module notes for h drawn by the lobe's sampler. The
    /// second half of [`sample`](Self::sample); `shaders/lib/dielectric.wgsl`'s
    /// `dielectric_scatter` is its twin.
    pub fn scatter(&self, wi: DVec3, h: DVec3, u2: f64) -> DielectricSample {
        let (flip, wi, eta) = self.incident(wi);
        let pdf_h = self.lobe.pdf_h(wi, h);
        let c = wi.dot(h);
        let f = fresnel::dielectric(c, eta);
        let (event, wo, pdf) = match refract(wi, h, eta).filter(|_| u2 >= f) {
            Some(wt) => (Event::Transmission, wt, fresnel::dielectric_transmittance(c, eta) * pdf_h * jacobian_transmitted(c, -wt.dot(h), eta)),
            None => {
                let wr = reflect(wi, h);
                (Event::Reflection, wr, f * pdf_reflected(pdf_h, wr, h))
            }
        };
        let on_its_side = match event {
            Event::Reflection => wo.z > 0.0,
            Event::Transmission => wo.z < 0.0,
        };
        let pdf_o = if on_its_side { pdf } else { 0.0 };
        let valid = wo.is_finite() && on_its_side && pdf_o.is_finite() && pdf_o > 0.0;
        let back = |w: DVec3| if flip { mirror(w) } else { w };
        DielectricSample { h: back(h), omega_o: back(wo), event, fresnel: f, pdf_h, pdf_o, valid }
    }

    /// The densities over h (per unit solid angle of h, for ωi on the upper side) of the two
    /// kinds of wrong-side samples of [`sample`](Self::sample): a reflection that leaves
    /// through the surface (p(h) F, or p(h) where refraction is impossible) and a refraction
    /// that stays on the incident side (p(h) (1 − F)). Their integrals are the expected shares
    /// of [`Invalid::OutsideDomain`](super::Invalid) and [`Invalid::RefractedNearSide`](super::Invalid).
    pub fn wrong_side_h(&self, wi: DVec3, h: DVec3) -> (f64, f64) {
        let (wi, eta) = self.upper_side(wi);
        let pdf_h = self.lobe.pdf_h(wi, h);
        if pdf_h <= 0.0 || pdf_h.is_nan() {
            return (0.0, 0.0);
        }
        let c = wi.dot(h);
        match refract(wi, h, eta) {
            Some(wt) => {
                let reflected = if reflect(wi, h).z > 0.0 { 0.0 } else { fresnel::dielectric(c, eta) * pdf_h };
                let refracted = if wt.z < 0.0 { 0.0 } else { fresnel::dielectric_transmittance(c, eta) * pdf_h };
                (reflected, refracted)
            }
            None => (if reflect(wi, h).z > 0.0 { 0.0 } else { pdf_h }, 0.0),
        }
    }

    /// The values of h.z at which [`wrong_side_h`](Self::wrong_side_h) can jump, over the
    /// microfacets at c = ωi·h (ωi on the upper side, η seen from there, [`upper_side`](Self::upper_side)):
    /// h.z = 0, below which no microfacet lies; the reflection's horizon, 2c h.z = ωi.z
    /// (ωr = 2c h − ωi); the refraction's, (c/η − cos θt) h.z = ωi.z/η (ωt of [`refract`]).
    /// At fixed c each indicator is monotone in h.z, so between these values the densities are
    /// smooth: the expected counts integrate them piece by piece.
    pub fn wrong_side_h_z_breaks(wi: DVec3, eta: f64, c: f64) -> Vec<f64> {
        let mut breaks = vec![0.0];
        if c > 0.0 {
            breaks.push(wi.z / (2.0 * c));
            if let Some(ct) = fresnel::cos_transmitted(c.min(1.0), eta) {
                breaks.push(wi.z / (c - eta * ct));
            }
        }
        breaks.retain(|t| t.is_finite());
        breaks
    }

    /// The microfacet normal of the pair (ωi, ωo) on the upper side, its event and η seen from
    /// ωi, with both directions moved there; `None` where no microfacet connects them.
    fn connect(&self, wi: DVec3, wo: DVec3) -> Option<(DVec3, DVec3, DVec3, Event, f64)> {
        let (flip, wi, eta) = self.incident(wi);
        let wo = if flip { mirror(wo) } else { wo };
        if wo.z > 0.0 {
            let h = (wi + wo).normalize();
            (h.z > 0.0 && wi.dot(h) > 0.0).then_some((wi, wo, h, Event::Reflection, eta))
        } else if wo.z < 0.0 {
            refraction_half_vector(wi, wo, eta).map(|h| (wi, wo, h, Event::Transmission, eta))
        } else {
            None
        }
    }

    /// The density of ωo under [`sample`](Self::sample): the reflected part on the incident
    /// side, the refracted part across the surface, 0 on the horizon.
    pub fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let Some((wi, wo, h, event, eta)) = self.connect(wi, wo) else { return 0.0 };
        let c = wi.dot(h);
        let f = fresnel::dielectric(c, eta);
        let pdf_h = self.lobe.pdf_h(wi, h);
        match event {
            Event::Reflection => f * pdf_reflected(pdf_h, wo, h),
            Event::Transmission => fresnel::dielectric_transmittance(c, eta) * pdf_h * jacobian_transmitted(c, -wo.dot(h), eta),
        }
    }

    /// The estimator weight f |cos θo| / p(ωo) of a sample with masking `masking` (f as
    /// [`eval`](Self::eval)), in the sampler's closed form, the same for both events (F or 1 − F
    /// is in f and p alike): [`Effects::weight`] without Fresnel or masking on the upper side,
    /// (ωi·h)⁺ / (cos θi cos θh) by the NDF and 1 / G1(ωi) by visible normals, times the G of
    /// the pair that `eval` uses (G1(ωo) of |cos θo|; where ωo lies across the surface, the
    /// transmitted form, for a wrong-side reflection too). It
    /// depends on h alone for G = G1(ωi), so over every sample, the wrong-side ones included,
    /// Σ w / N estimates the white furnace's ∫ p(h) w dh = G1(ωi) (1 + Λ(ωi)) = 1
    /// ([`Effects::furnace`]).
    pub fn weight(&self, wi: DVec3, s: &DielectricSample, masking: Masking) -> f64 {
        let (flip, wi, _) = self.incident(wi);
        let up = |w: DVec3| if flip { mirror(w) } else { w };
        let upper = LobeSample { h: up(s.h), omega_r: up(s.omega_o), pdf_h: s.pdf_h, pdf_r: s.pdf_o, invalid: None };
        Effects::NONE.weight(&self.lobe, wi, &upper) * self.masking(wi, upper.omega_r, masking)
    }

    /// G of the pair (ωi, ωo) moved to the upper side: `masking` of G1(ωi) and G1(ωo) (of
    /// |cos θo|), in its transmitted form ([`Masking::g_transmitted`]) where ωo lies across the
    /// surface.
    fn masking(&self, wi: DVec3, wo: DVec3, masking: Masking) -> f64 {
        let l = &self.lobe;
        let (gi, go) = (g1(l, l.to_local(wi)), g1(l, l.to_local(wo)));
        if wo.z < 0.0 { masking.g_transmitted(gi, go) } else { masking.g(gi, go) }
    }

    /// The BSDF f(ωi, ωo) with the dielectric's own Fresnel term and masking `masking` of
    /// G1(ωi), G1(ωo) (Walter 2007, eqs. 20 and 21). The height-correlated G2 is Heitz 2014's
    /// 1 / (1 + Λ(ωi) + Λ(ωo)) on the incident side and B(1 + Λ(ωi), 1 + Λ(ωo)) across the
    /// surface ([`Masking::g_transmitted`]; pbrt-v4 uses the reflection's form for both events).
    pub fn eval(&self, wi: DVec3, wo: DVec3, masking: Masking) -> f64 {
        let Some((wi, wo, h, event, eta)) = self.connect(wi, wo) else { return 0.0 };
        let l = &self.lobe;
        let c = wi.dot(h);
        let f = fresnel::dielectric(c, eta);
        let dg = d(l, l.to_local(h)) * self.masking(wi, wo, masking);
        let cos = wi.z * wo.z.abs();
        match event {
            Event::Reflection => f * dg / (4.0 * cos),
            Event::Transmission => fresnel::dielectric_transmittance(c, eta) * dg * c * jacobian_transmitted(c, -wo.dot(h), eta) / cos,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::LobeKind;
    use crate::reference::reflect::spherical;

    fn lobe(kind: LobeKind, method: Method, ax: f64, ay: f64) -> Lobe {
        Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 }
    }

    const KINDS: [(LobeKind, Method); 4] =
        [(LobeKind::Ggx, Method::Ndf), (LobeKind::Ggx, Method::Vndf), (LobeKind::Beckmann, Method::Ndf), (LobeKind::Beckmann, Method::Vndf)];

    /// u = 0, the RNG's lowest value, draws Beckmann's visible slope at −∞ (an h on the horizon,
    /// D = 0): without U_FLOOR the refraction about it had no density (seed 1, θi 125°, η 1.5,
    /// α 0.3: sample 2014833 failed `lobes run`'s χ² as an impossible zero_pdf). With it, every
    /// sampler gives a refraction of positive density there, from both sides.
    #[test]
    fn the_lowest_uniform_refracts_with_a_density() {
        for (kind, method) in KINDS {
            let glass = RoughDielectric::new(lobe(kind, method, 0.3, 0.3), 1.5).unwrap();
            for theta in [0.7, 125f64.to_radians()] {
                for u in [[0.0, 0.5, 0.999], [0.5, 0.0, 0.999], [0.0, 0.0, 0.999]] {
                    let wi = spherical(theta, 0.3);
                    let s = glass.sample(wi, u);
                    // a refraction across the surface (one that stays on wi's side is a
                    // wrong-side sample, counted as such, with an expected count of its own)
                    if s.event == Event::Transmission && s.omega_o.z * wi.z < 0.0 {
                        assert!(s.valid && s.pdf_o > 0.0, "{kind:?} {method:?} θi {theta} u {u:?}: {s:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn fresnel_is_symmetric_across_the_interface_and_total_past_the_critical_angle() {
        // normal incidence: ((η − 1)/(η + 1))² from either side
        assert!((fresnel::dielectric(1.0, 1.5) - 0.04).abs() < 1e-15);
        assert!((fresnel::dielectric(1.0, 1.0 / 1.5) - 0.04).abs() < 1e-15);
        // Stokes: a ray and its reversed refraction see the same reflectance
        for eta in [1.33, 2.5, 1.0 / 2.5] {
            for c in [0.05, 0.3, 0.7, 0.99] {
                let Some(ct) = fresnel::cos_transmitted(c, eta) else { continue };
                let (f, back) = (fresnel::dielectric(c, eta), fresnel::dielectric(ct, 1.0 / eta));
                assert!((f - back).abs() < 1e-13, "η {eta} c {c}: {f} vs {back}");
            }
        }
        // from glass (η = 1/1.5) the critical angle is asin(1/1.5): cos θc = √5/3
        let cos_c = 5f64.sqrt() / 3.0;
        assert_eq!(fresnel::dielectric(cos_c * (1.0 - 1e-9), 1.0 / 1.5), 1.0);
        assert!(fresnel::dielectric(cos_c * (1.0 + 1e-9), 1.0 / 1.5) < 1.0);
        assert!(fresnel::cos_transmitted(cos_c * (1.0 - 1e-9), 1.0 / 1.5).is_none());
    }

    #[test]
    fn refraction_obeys_snell_and_reverses() {
        let wi = spherical(0.4, 0.3);
        let h = spherical(0.25, 2.0);
        for eta in [1.5, 1.0 / 1.5, 2.5, 1.0 + 1e-6] {
            let wt = refract(wi, h, eta).unwrap();
            assert!((wt.length() - 1.0).abs() < 1e-15);
            // sin θt = sin θi / η, in the plane of ωi and h, behind h
            assert!((wt.cross(h).length() * eta - wi.cross(h).length()).abs() < 1e-15);
            assert!(wt.dot(wi.cross(h)).abs() < 1e-15 && wt.dot(h) < 0.0);
            // the reversed ray refracts back (seen from below: normal −h, index 1/η)
            assert!((refract(wt, -h, 1.0 / eta).unwrap() - wi).length() < 1e-14, "η {eta}");
            assert!((refraction_half_vector(wi, wt, eta).unwrap() - h).length() < 1e-9, "η {eta}");
        }
        // past the critical angle there is no refracted ray
        assert!(refract(spherical(1.2, 0.0), DVec3::Z, 1.0 / 1.5).is_none());
    }

    /// h, ωt (where it refracts) and ωr of one u.
    type Images = (DVec3, Option<DVec3>, DVec3);

    /// The refraction Jacobian dωh/dωt against the finite-difference Jacobian of the map
    /// u → h(u) → ωt(u): the ratio of the solid angles the two images of a small square of u
    /// span, |∂h/∂u₀ × ∂h/∂u₁| / |∂ωt/∂u₀ × ∂ωt/∂u₁|. Reflection's 1/(4|ωr·h|) likewise.
    #[test]
    fn jacobians_match_finite_differences_of_the_sample_map() {
        let l = lobe(LobeKind::Ggx, Method::Vndf, 0.4, 0.25);
        let wi = spherical(0.7, 0.4);
        let step = 1e-6;
        for eta in [1.5, 1.0 / 1.5, 2.5, 1.0 / 2.5, 1.01] {
            for u in [[0.3, 0.4], [0.7, 0.2], [0.55, 0.8], [0.1, 0.6]] {
                let map = |u0: f64, u1: f64| {
                    let h = l.sample_h(wi, [u0, u1]);
                    (h, refract(wi, h, eta), reflect(wi, h))
                };
                let at = |du: [f64; 2]| map(u[0] + du[0], u[1] + du[1]);
                let d = |f: &dyn Fn(&Images) -> DVec3, axis: usize| {
                    let mut e = [0.0; 2];
                    e[axis] = step;
                    let (p, m) = (at(e), at([-e[0], -e[1]]));
                    (f(&p) - f(&m)) / (2.0 * step)
                };
                let (h, wt, wr) = map(u[0], u[1]);
                let Some(wt) = wt else { continue };
                let area = |f: &dyn Fn(&Images) -> DVec3| d(f, 0).cross(d(f, 1)).length();
                let area_h = area(&|s| s.0);
                let fd_t = area_h / area(&|s| s.1.unwrap());
                let fd_r = area_h / area(&|s| s.2);
                let jt = jacobian_transmitted(wi.dot(h), -wt.dot(h), eta);
                assert!((fd_t / jt - 1.0).abs() < 1e-5, "η {eta} u {u:?}: finite differences {fd_t}, eq. 17 {jt}");
                assert!((fd_r * 4.0 * wr.dot(h).abs() - 1.0).abs() < 1e-5, "reflection η {eta} u {u:?}");
            }
        }
    }

    /// The stable Jacobian equals Walter's eq. 17 as written, η² ct / (c − η ct)², where that
    /// has digits to spare, and keeps its own where eq. 17's difference cancels (η → 1).
    #[test]
    fn the_stable_jacobian_is_eq_17_without_its_cancellation() {
        let (wi, h) = (spherical(0.6, 0.0), spherical(0.2, 0.0));
        let eq17 = |c: f64, ct: f64, eta: f64| eta * eta * ct / (c - eta * ct).powi(2);
        for eta in [1.5, 1.0 / 1.5, 2.5, 1.0 / 2.5] {
            let wt = refract(wi, h, eta).unwrap();
            let (c, ct) = (wi.dot(h), -wt.dot(h));
            assert!((jacobian_transmitted(c, ct, eta) / eq17(c, ct, eta) - 1.0).abs() < 1e-13, "η {eta}");
        }
        // η = 1 + 2⁻³⁰: ct agrees with c to ~9 digits, and (c − η ct)² is left with ~7; the
        // stable form keeps ~15 and is checked against its own value at η written as 1 + ε
        // expanded to first order: J ≈ ct (2c)² / (2ε)² (1 + O(ε)).
        let eps = 2f64.powi(-30);
        let eta = 1.0 + eps;
        let wt = refract(wi, h, eta).unwrap();
        let (c, ct) = (wi.dot(h), -wt.dot(h));
        let first_order = ct * (2.0 * c).powi(2) / (2.0 * eps).powi(2);
        let stable = jacobian_transmitted(c, ct, eta);
        assert!((stable / first_order - 1.0).abs() < 1e-8, "{stable} vs {first_order}");
        let naive = eq17(c, ct, eta);
        assert!((naive / stable - 1.0).abs() > 1e-8, "eq. 17 as written lost digits at η = 1 + 2⁻³⁰: {naive} vs {stable}");
    }

    /// Walter 2007's BTDF is reciprocal up to the squared indices: f_t(ωi, ωo)/η_o² =
    /// f_t(ωo, ωi)/η_i² (the radiance of eq. 21 is not symmetric, its η_o² is), here with
    /// η_i = 1 above and η_o = η below, the reversed path computed from inside.
    #[test]
    fn the_btdf_is_reciprocal_up_to_the_squared_indices() {
        for (kind, method) in KINDS {
            let d = RoughDielectric::new(lobe(kind, method, 0.35, 0.2), 1.5).unwrap();
            for (wi, wo) in [(spherical(0.4, 0.1), spherical(2.6, 3.0)), (spherical(1.2, 0.0), spherical(2.2, 2.5)), (spherical(0.1, 1.0), spherical(3.0, -2.0))] {
                let (there, back) = (d.eval(wi, wo, Masking::HeightCorrelated), d.eval(wo, wi, Masking::HeightCorrelated));
                assert!(there > 0.0, "{kind:?} {method:?}");
                assert!((there / (d.eta * d.eta) / back - 1.0).abs() < 1e-12, "{kind:?} {method:?}: {there} vs {back}");
                // reflection is symmetric outright
                let wr = DVec3::new(-wi.x, -wi.y, wi.z).lerp(DVec3::Z, 0.3).normalize();
                let (r1, r2) = (d.eval(wi, wr, Masking::Separable), d.eval(wr, wi, Masking::Separable));
                assert!((r1 / r2 - 1.0).abs() < 1e-12);
            }
        }
    }

    /// The closed-form weight of every valid sample equals eval · |cos θo| / pdf formed from ωo
    /// alone, for both events, from both sides, with each masking term the weighted pass takes.
    #[test]
    fn weights_equal_eval_cos_over_pdf() {
        let mut events = [0; 2];
        for (kind, method) in KINDS {
            let d = RoughDielectric::new(Lobe { alpha_angle: 30.0, ..lobe(kind, method, 0.5, 0.3) }, 1.5).unwrap();
            for wi in [spherical(0.5, 0.2), spherical(2.3, 0.7)] {
                for k in 0..40 {
                    let u = crate::reference::rng::uniforms(5, k);
                    let s = d.sample(wi, [u[0], u[1], u[2]]);
                    if !s.valid {
                        continue;
                    }
                    events[s.event as usize] += 1;
                    for masking in Masking::ALL {
                        let direct = d.eval(wi, s.omega_o, masking) * s.omega_o.z.abs() / d.pdf(wi, s.omega_o);
                        let w = d.weight(wi, &s, masking);
                        assert!((w / direct - 1.0).abs() < 1e-9, "{kind:?} {method:?} {wi} {masking:?} {:?}: {w} vs {direct}", s.event);
                    }
                }
            }
        }
        assert!(events[0] > 20 && events[1] > 100, "{events:?}");
    }

    /// Every sample's density equals [`RoughDielectric::pdf`] of its direction, formed from ωo
    /// alone, and from inside the surface the mirror makes it the outside's with 1/η.
    #[test]
    fn sampled_densities_match_the_density_of_the_direction() {
        let mut events = [0; 2];
        for (kind, method) in KINDS {
            for eta in [1.5, 1.0 / 1.5, 2.5] {
                let d = RoughDielectric::new(lobe(kind, method, 0.5, 0.3), eta).unwrap();
                for wi in [spherical(0.5, 0.2), spherical(1.45, -1.0), spherical(2.5, 0.7)] {
                    for k in 0..40 {
                        let u = crate::reference::rng::uniforms(3, k);
                        let s = d.sample(wi, [u[0], u[1], u[2]]);
                        if !s.valid {
                            continue;
                        }
                        events[s.event as usize] += 1;
                        let p = d.pdf(wi, s.omega_o);
                        assert!((s.pdf_o / p - 1.0).abs() < 1e-9, "{kind:?} {method:?} η {eta} {wi} {u:?}: {} vs {p}", s.pdf_o);
                        let inside = RoughDielectric::new(d.lobe, 1.0 / eta).unwrap();
                        assert!((inside.pdf(mirror(wi), mirror(s.omega_o)) / p - 1.0).abs() < 1e-12);
                    }
                }
            }
        }
        assert!(events[0] > 100 && events[1] > 100, "{events:?}");
    }
}
