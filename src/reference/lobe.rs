//! A reflectance lobe with its roughness and method, sampled and evaluated in f64 through the
//! registry's references ([`super::sampler`]).

use super::sampler::{self, LobeKind, Method};
use super::{Invalid, frame, reflect};
use glam::DVec3;

/// A reflectance lobe with its roughness and sampling method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lobe {
    pub kind: LobeKind,
    pub method: Method,
    /// The roughness along the tangent frame's first axis.
    pub alpha_x: f64,
    /// The roughness along the tangent frame's second axis.
    pub alpha_y: f64,
    /// Rotated anisotropy: the angle in degrees from +x to the αx axis about the normal
    /// (counter-clockwise seen from above; [`frame`]), the scene key `alpha_angle`. 0 keeps αx
    /// along +x. Every method of
    /// `Lobe` and [`super::effects::Effects`] takes and returns world directions and turns them into
    /// this frame itself.
    pub alpha_angle: f64,
}

/// One sample of a lobe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeSample {
    /// The half vector drawn.
    pub h: DVec3,
    /// The reflected direction ωr = 2(ωi·h)h − ωi.
    pub omega_r: DVec3,
    /// The density with which h was drawn, per unit solid angle.
    pub pdf_h: f64,
    /// p(ωr) = p(h) / (4 |ωr·h|), or the method's own reflected pdf (bounded VNDF).
    pub pdf_r: f64,
    /// `None` for a valid sample, else why it is not.
    pub invalid: Option<Invalid>,
}

impl Lobe {
    /// Draws a half vector and reflects ωi about it.
    ///
    /// ```
    /// use lobes::reference::{Lobe, LobeKind, Method};
    /// let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Vndf, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 };
    /// let wi = lobes::reference::reflect::spherical(0.5, 0.0);
    /// let s = lobe.sample(wi, [0.25, 0.5]);
    /// assert!(s.invalid.is_none());
    /// assert!((s.pdf_r - lobe.pdf_r(wi, s.omega_r)).abs() < 1e-9 * s.pdf_r);
    /// ```
    pub fn sample(&self, wi: DVec3, u: [f64; 2]) -> LobeSample {
        let h = self.sample_h(wi, u);
        let omega_r = reflect::reflect(wi, h);
        let pdf_h = self.pdf_h(wi, h);
        // no reflection from below the surface, and none into it: p(ωr) = 0 there, as in pdf_r
        let pdf_r = if wi.z < 0.0 || omega_r.z <= 0.0 { 0.0 } else { self.pdf_r_of_h(wi, omega_r, h, pdf_h) };
        LobeSample { h, omega_r, pdf_h, pdf_r, invalid: Invalid::check(omega_r, pdf_r) }
    }

    /// Whether the tangent frame is turned (`alpha_angle` ≠ 0).
    pub fn is_rotated(&self) -> bool {
        self.alpha_angle != 0.0
    }

    /// World coordinates into the lobe's tangent frame (unchanged, bit for bit, when it is not
    /// rotated).
    pub fn to_local(&self, w: DVec3) -> DVec3 {
        if self.is_rotated() { self.frame().to_local(w) } else { w }
    }

    /// The lobe's tangent frame into world coordinates.
    pub fn to_world(&self, w: DVec3) -> DVec3 {
        if self.is_rotated() { self.frame().to_world(w) } else { w }
    }

    /// The rotation of the lobe's tangent frame ([`frame`]).
    pub fn frame(&self) -> frame::Frame {
        frame::Frame::new(self.alpha_angle.to_radians())
    }

    /// Its roughness (αx, αy), as the registry's functions take it.
    pub(crate) fn alpha(&self) -> sampler::Alpha {
        (self.alpha_x, self.alpha_y)
    }

    /// The f64 reference of this lobe's sampler (the registry's entry).
    fn reference(&self) -> sampler::Reference {
        let spec = sampler::find(self.kind, self.method);
        spec.reference.unwrap_or_else(|| panic!("the sampler {} has no f64 reference", spec.name()))
    }

    /// The half vector for uniforms `u`: drawn for ωi in the lobe's frame, turned back.
    pub fn sample_h(&self, wi: DVec3, u: [f64; 2]) -> DVec3 {
        self.to_world((self.reference().sample_h)(self.alpha(), self.to_local(wi), u))
    }

    /// The density of h under this lobe's sampling method, per unit solid angle (a rotation
    /// keeps solid angle, so it is the density of the frame's h for the frame's ωi).
    pub fn pdf_h(&self, wi: DVec3, h: DVec3) -> f64 {
        (self.reference().pdf_h)(self.alpha(), self.to_local(wi), self.to_local(h))
    }

    /// p(ωr) of the reflection about h: the method's own reflected density, else
    /// p(h) / (4 |ωr·h|).
    fn pdf_r_of_h(&self, wi: DVec3, wr: DVec3, h: DVec3, pdf_h: f64) -> f64 {
        match self.reference().pdf_r {
            Some(pdf_r) => pdf_r(self.alpha(), self.to_local(wi), self.to_local(h)),
            None => reflect::pdf_reflected(pdf_h, wr, h),
        }
    }

    /// The density of a valid reflected direction ωr (above the horizon); 0 below it, where
    /// samples are counted as invalid instead.
    pub fn pdf_r(&self, wi: DVec3, wr: DVec3) -> f64 {
        if wr.z <= 0.0 || wi.z < 0.0 {
            return 0.0;
        }
        let Some(h) = reflect::half_vector(wi, wr) else { return 0.0 };
        self.pdf_r_of_h(wi, wr, h, self.pdf_h(wi, h))
    }

    /// The BRDF value f(ωi, ωr) without Fresnel: Ward's (ρs = 1), or the microfacet BRDF with
    /// height-correlated Smith G2.
    pub fn eval(&self, wi: DVec3, wr: DVec3) -> f64 {
        (self.kind.spec().eval)(self.alpha(), self.to_local(wi), self.to_local(wr))
    }
}
