//! Effects: what multiplies a lobe's BRDF besides its distribution (Fresnel, Smith masking),
//! and the estimator weight w = f(ωi, ωr) cos θr / p(ωr) each sampler returns. The f64 twin of
//! the effect glue that `src/engine/gpu/compose.rs` writes around `shaders/passes/weighted.wgsl`.
//!
//! With effects, a lobe's BRDF is
//! - microfacet (Walter et al. 2007, eq. 20): f = F(ωi·h) D(h) G(ωi, ωr) / (4 cos θi cos θr);
//! - Ward (ρs = 1): f = F(ωi·h) f_Ward(ωi, ωr); Ward has no Smith masking.
//!
//! The weights are formed in closed form per sampler (the D's cancel), then multiplied by F and
//! G. For a sample below the horizon, |cos θr| is used, so that Σ w / N over every sample
//! estimates ∫ over the whole sphere of f |cos θr| (Heitz 2014's weak white furnace: 1 for
//! F = 1 and G = G1(ωi)), while the weights of the bins estimate the directional albedo
//! ∫ over the hemisphere of f cos θr.

use super::fresnel::Fresnel;
use super::ggx::Ggx;
use super::masking::Masking;
use super::sampler::{MicrofacetTerms, Shape};
use super::{Lobe, LobeSample, Method};
use glam::DVec3;
use serde::Serialize;

/// The effects of a case: its Fresnel term and its masking-shadowing term.
///
/// ```
/// use lobes::reference::effects::Effects;
/// use lobes::reference::{Lobe, LobeKind, Method, fresnel::Fresnel, masking::Masking, reflect::spherical};
/// let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Vndf, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 };
/// let wi = spherical(0.6, 0.0);
/// let e = Effects { fresnel: Fresnel::Schlick { f0: 0.04 }, masking: Masking::HeightCorrelated };
/// let s = lobe.sample(wi, [0.3, 0.7]);
/// // the sampler's closed-form weight is f cos θr / p(ωr)
/// let direct = e.eval(&lobe, wi, s.omega_r) * s.omega_r.z / lobe.pdf_r(wi, s.omega_r);
/// assert!((e.weight(&lobe, wi, &s) - direct).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize, schemars::JsonSchema)]
pub struct Effects {
    pub fresnel: Fresnel,
    pub masking: Masking,
}

impl Effects {
    /// No Fresnel, no masking: f = D / (4 cos θi cos θr) (or Ward's BRDF).
    pub const NONE: Effects = Effects { fresnel: Fresnel::None, masking: Masking::None };
}

/// The D, G1 and Λ of a microfacet lobe; `None` for a lobe of its own shape.
fn microfacet(l: &Lobe) -> Option<MicrofacetTerms> {
    match l.kind.spec().shape {
        Shape::Microfacet(terms) => Some(terms),
        Shape::Own { .. } => None,
    }
}

/// D(h) of a microfacet lobe.
pub(crate) fn d(l: &Lobe, h: DVec3) -> f64 {
    let terms = microfacet(l).unwrap_or_else(|| panic!("{} is not a microfacet lobe", l.kind.name()));
    (terms.d)(l.alpha(), h)
}

/// Smith's G1(ω) of a microfacet lobe in its grazing-stable form (|cos θ| for ω below the
/// horizon); 1 for a lobe without masking (Ward).
pub(crate) fn g1(l: &Lobe, w: DVec3) -> f64 {
    microfacet(l).map_or(1.0, |terms| (terms.g1)(l.alpha(), w))
}

impl Effects {
    /// The BRDF f(ωi, ωr) with these effects; 0 unless both directions are above the horizon.
    pub fn eval(&self, l: &Lobe, wi: DVec3, wr: DVec3) -> f64 {
        if wi.z <= 0.0 || wr.z <= 0.0 {
            return 0.0;
        }
        let (wi, wr) = (l.to_local(wi), l.to_local(wr));
        let h = (wi + wr).normalize();
        let f = self.fresnel.reflectance(wi.dot(h));
        let (spec, a) = (l.kind.spec(), l.alpha());
        match spec.shape {
            Shape::Own { .. } => f * (spec.eval)(a, wi, wr),
            Shape::Microfacet(t) => f * (t.d)(a, h) * self.masking.g((t.g1)(a, wi), (t.g1)(a, wr)) / (4.0 * wi.z * wr.z),
        }
    }

    /// The weight w = f cos θr / p(ωr) of a sample drawn by `l`'s method (|cos θr| below the
    /// horizon, see the module notes), from each sampler's closed form:
    /// - NDF sampling, p(ωr) = D cos θh / (4 |ωr·h|): w = F G (ωi·h)⁺ / (cos θi cos θh);
    /// - visible normals, p(ωr) = G1(ωi) D / (4 cos θi): w = F G / G1(ωi);
    /// - bounded VNDF, p(ωr) = D / (2 (k cos θi + t)): w = F G (k cos θi + t) / (2 cos θi);
    /// - Ward, p(ωr) = p(h) / (4 |ωr·h|): w = F (ωi·h)⁺ cos³θh √(|cos θr| / cos θi) (Walter 2005, eq. 10).
    pub fn weight(&self, l: &Lobe, wi: DVec3, s: &LobeSample) -> f64 {
        let (wi, h, wr) = (l.to_local(wi), l.to_local(s.h), l.to_local(s.omega_r));
        let f = self.fresnel.reflectance(wi.dot(h));
        let t = match l.kind.spec().shape {
            Shape::Own { weight } => return weight(f, wi, h, wr),
            Shape::Microfacet(t) => t,
        };
        let a = l.alpha();
        let g1_i = (t.g1)(a, wi);
        let g = self.masking.g(g1_i, (t.g1)(a, wr));
        let base = match l.method {
            Method::Ndf => wi.dot(h).max(0.0) / (wi.z * h.z),
            Method::Vndf => 1.0 / g1_i,
            Method::Bounded => {
                let m = Ggx { ax: l.alpha_x, ay: l.alpha_y };
                let t = DVec3::new(l.alpha_x * wi.x, l.alpha_y * wi.y, wi.z).length();
                (m.bounded_k(wi) * wi.z + t) / (2.0 * wi.z)
            }
        };
        f * g * base
    }

    /// The weak white furnace test (Heitz 2014, "Understanding the masking-shadowing function"): with F = 1 the integral of
    /// f |cos θr| over the whole sphere is 1 for G = G1(ωi), and 1 / G1(ωi) = 1 + Λ(ωi) for
    /// G = 1 (the projected area of the visible microfacets over that of the surface). `None`
    /// for the other effects, which have no closed form, and for bounded VNDF sampling, whose
    /// shrunk cap never draws some of the normals that reflect below the horizon (its sphere
    /// total falls short of the furnace by design; its hemisphere albedo does not).
    pub fn furnace(&self, l: &Lobe, wi: DVec3) -> Option<f64> {
        let terms = microfacet(l)?;
        if self.fresnel != Fresnel::None || l.method == Method::Bounded {
            return None;
        }
        let wi = l.to_local(wi);
        let lambda = || (terms.lambda)(l.alpha(), wi);
        match self.masking {
            Masking::G1 => Some(1.0),
            Masking::None => Some(1.0 + lambda()),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::LobeKind;
    use crate::reference::reflect::spherical;

    #[test]
    fn weights_equal_eval_cos_over_pdf() {
        let wi = spherical(0.9, 0.4);
        let effects = Effects { fresnel: Fresnel::Conductor { eta: 0.2, k: 3.9 }, masking: Masking::HeightCorrelated };
        for (kind, method) in [
            (LobeKind::Ggx, Method::Ndf),
            (LobeKind::Ggx, Method::Vndf),
            (LobeKind::Ggx, Method::Bounded),
            (LobeKind::Beckmann, Method::Ndf),
            (LobeKind::Beckmann, Method::Vndf),
        ] {
            let l = Lobe { kind, method, alpha_x: 0.4, alpha_y: 0.2, alpha_angle: 0.0 };
            let mut checked = 0;
            for u in [[0.1, 0.2], [0.5, 0.9], [0.8, 0.35], [0.3, 0.55], [0.05, 0.7]] {
                let s = l.sample(wi, u);
                if s.invalid.is_some() {
                    continue; // below the horizon: no pdf to divide by
                }
                checked += 1;
                let direct = effects.eval(&l, wi, s.omega_r) * s.omega_r.z / l.pdf_r(wi, s.omega_r);
                let w = effects.weight(&l, wi, &s);
                assert!((w - direct).abs() < 1e-12 * direct, "{kind:?} {method:?} {u:?}: {w} vs {direct}");
            }
            assert!(checked >= 3, "{kind:?} {method:?}: only {checked} samples above the horizon");
        }
        let l = Lobe { kind: LobeKind::Ward, method: Method::Ndf, alpha_x: 0.3, alpha_y: 0.1, alpha_angle: 0.0 };
        let e = Effects { fresnel: Fresnel::Schlick { f0: 0.04 }, masking: Masking::None };
        let s = l.sample(wi, [0.3, 0.6]);
        let direct = e.eval(&l, wi, s.omega_r) * s.omega_r.z / l.pdf_r(wi, s.omega_r);
        assert!((e.weight(&l, wi, &s) - direct).abs() < 1e-12 * direct);
    }
}
