//! The GGX (Trowbridge–Reitz) distribution: the CPU twin of `shaders/lib/ggx.wgsl`.
//!
//! - D(h) = 1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²) (Heitz 2014, eq. 85, in Cartesian form
//!   so that no tan θ appears).
//! - Λ(ω) = (√(1 + (αx² ωx² + αy² ωy²)/ωz²) − 1) / 2 (Heitz 2014, eq. 86), used as
//!   G1 = 2|ωz| / (|ωz| + √(ωz² + αx² ωx² + αy² ωy²)), which is finite at ωz = 0.
//! - NDF sampling: cos²θh = (1 − u) / (1 + (α² − 1) u) (Walter et al. 2007, eq. 35–36 solved
//!   for cos θ rather than tan θ), computed as the stretch of the cosine-weighted α = 1 sample
//!   (√u cos φ, √u sin φ, √(1 − u)) by (αx, αy, 1): its normalisation is exactly that cos θh.
//! - Visible normals by spherical caps: Dupuy & Benyoub 2023, "Sampling Visible GGX Normals with
//!   Spherical Caps", listing 3.
//! - Bounded VNDF for reflection: Eto & Tokuyoshi 2023, "Bounded VNDF Sampling for Smith–GGX
//!   Reflections", listings 1–2.

use super::microfacet::{Microfacet, stretch};
use glam::DVec3;
use std::f64::consts::PI;

/// 1 − ωs.z for ωs = normalize(αx ωx, αy ωy, ωz), as |v.xy|² / (|v| (|v| + v.z)) when v.z ≥ 0,
/// which keeps its precision as ωs approaches the normal (near-specular α).
pub fn one_minus_stretched_z(ax: f64, ay: f64, w: DVec3) -> f64 {
    let v = DVec3::new(ax * w.x, ay * w.y, w.z);
    let len = v.length();
    if v.z < 0.0 {
        return 1.0 - v.z / len;
    }
    (v.x * v.x + v.y * v.y) / (len * (len + v.z))
}

#[derive(Debug, Clone, Copy)]
pub struct Ggx {
    pub ax: f64,
    pub ay: f64,
}

impl Ggx {
    /// √(ωz² + αx² ωx² + αy² ωy²): the length of ω stretched by (αx, αy, 1), "t" in Eto 2023.
    fn stretched_len(&self, w: DVec3) -> f64 {
        DVec3::new(self.ax * w.x, self.ay * w.y, w.z).length()
    }

    /// Eto & Tokuyoshi 2023, listing 1: k, the factor that shrinks the spherical cap so that
    /// fewer reflected directions fall below the horizon.
    pub fn bounded_k(&self, wi: DVec3) -> f64 {
        1.0 - self.bounded_one_minus_k(wi)
    }

    /// 1 − k = a² (s² + ωi.z²) / (s² + a² ωi.z²), exact algebra on listing 1's k that keeps its
    /// precision as a → 0, where k → 1.
    pub fn bounded_one_minus_k(&self, wi: DVec3) -> f64 {
        let a = self.ax.min(self.ay).clamp(0.0, 1.0);
        let s = 1.0 + wi.x.hypot(wi.y);
        let (a2, s2, z2) = (a * a, s * s, wi.z * wi.z);
        a2 * (s2 + z2) / (s2 + a2 * z2)
    }

    /// Eto & Tokuyoshi 2023, listing 1: the cap's lower bound is −b instead of −ωs.z.
    pub fn sample_bounded(&self, wi: DVec3, u: [f64; 2]) -> DVec3 {
        let ws = stretch(self.ax, self.ay, wi);
        let (b, ws_minus_b) = if wi.z > 0.0 {
            let omk = self.bounded_one_minus_k(wi);
            ((1.0 - omk) * ws.z, omk * ws.z)
        } else {
            (ws.z, 0.0)
        };
        self.cap_sample(wi, ws, b, ws_minus_b, u)
    }

    /// Eto & Tokuyoshi 2023, listing 2: the reflected density, for ωr above the horizon:
    /// D(h) / (2 (k ωi.z + t)) for ωi.z ≥ 0, D(h) (t − ωi.z) / (2 |(αx ωi.x, αy ωi.y)|²) otherwise.
    pub fn pdf_bounded_r(&self, wi: DVec3, h: DVec3) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let d = self.d(h);
        let t = self.stretched_len(wi);
        if wi.z >= 0.0 {
            d / (2.0 * (self.bounded_k(wi) * wi.z + t))
        } else {
            let l2 = (self.ax * wi.x).powi(2) + (self.ay * wi.y).powi(2);
            d * (t - wi.z) / (2.0 * l2)
        }
    }

    /// A uniform point on the unit sphere's cap z ≥ −b, offset by ωs and unstretched
    /// (Dupuy & Benyoub 2023, listing 3; b = ωs.z there).
    fn cap_sample(&self, wi: DVec3, ws: DVec3, b: f64, ws_minus_b: f64, u: [f64; 2]) -> DVec3 {
        let (sp, cp) = (2.0 * PI * u[0]).sin_cos();
        // z = s − b with s = (1 − u2)(1 + b). Near-specular α puts b and ωs.z near 1, where
        // 1 − z², 1 − b and z + ωs.z all cancel; they are formed from differences computed
        // without cancellation: 1 − z² = (s + (1 − b)) ((1 + b) − s), 1 − b = (1 − ωs.z) + (ωs.z − b),
        // z + ωs.z = s + (ωs.z − b).
        let s = (1.0 - u[1]) * (1.0 + b);
        let one_minus_b = one_minus_stretched_z(self.ax, self.ay, wi) + ws_minus_b;
        let sin_t = ((s + one_minus_b) * ((1.0 + b) - s)).clamp(0.0, 1.0).sqrt();
        let hs = DVec3::new(sin_t * cp + ws.x, sin_t * sp + ws.y, s + ws_minus_b);
        if hs.length_squared() == 0.0 {
            // u2 = 1 puts the point on the cap's rim z = −b; for the plain VNDF (b = ωs.z) at
            // ωi = +z the whole rim is the single point −ωs, so hs = 0 and normalize() would
            // give NaN. The limit u2 → 1 there is the horizon normal at azimuth 2πu1 (the rim
            // maps to the normals with hs.z = 0), which is what is returned.
            return DVec3::new(self.ax * cp, self.ay * sp, 0.0).normalize();
        }
        DVec3::new(self.ax * hs.x, self.ay * hs.y, hs.z).normalize()
    }
}

impl Microfacet for Ggx {
    fn d(&self, h: DVec3) -> f64 {
        let e = (h.x / self.ax).powi(2) + (h.y / self.ay).powi(2) + h.z * h.z;
        1.0 / (PI * self.ax * self.ay * e * e)
    }

    fn lambda(&self, w: DVec3) -> f64 {
        (self.stretched_len(w) / w.z.abs() - 1.0) / 2.0
    }

    fn g1(&self, w: DVec3) -> f64 {
        let z = w.z.abs();
        2.0 * z / (z + self.stretched_len(w))
    }

    /// G1/cos θ = 2 / (cos θ + t), t = |(αx ωx, αy ωy, ωz)|: finite at cos θ = 0.
    fn g1_over_cos(&self, w: DVec3) -> f64 {
        2.0 / (w.z.abs() + self.stretched_len(w))
    }

    fn sample_ndf(&self, u: [f64; 2]) -> DVec3 {
        let (sp, cp) = (2.0 * PI * u[1]).sin_cos();
        let r = u[0].sqrt();
        let z = (1.0 - u[0]).max(0.0).sqrt();
        DVec3::new(self.ax * r * cp, self.ay * r * sp, z).normalize()
    }

    fn sample_vndf(&self, wi: DVec3, u: [f64; 2]) -> DVec3 {
        let ws = stretch(self.ax, self.ay, wi);
        self.cap_sample(wi, ws, ws.z, 0.0, u)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ndf_sampling_matches_the_cos_theta_formula() {
        let g = Ggx { ax: 0.3, ay: 0.3 };
        for u in [0.0, 0.1, 0.5, 0.9, 1.0 - 1e-12] {
            let h = g.sample_ndf([u, 0.37]);
            let cos2 = (1.0 - u) / (1.0 + (0.09 - 1.0) * u);
            assert!((h.z * h.z - cos2).abs() < 1e-14, "u={u}");
        }
        assert_eq!(g.sample_ndf([1.0, 0.0]).z, 0.0);
    }

    #[test]
    fn g1_matches_lambda() {
        let g = Ggx { ax: 0.5, ay: 0.2 };
        let w = DVec3::new(0.6, 0.3, 0.5).normalize();
        assert!((g.g1(w) - 1.0 / (1.0 + g.lambda(w))).abs() < 1e-15);
    }

    #[test]
    fn bounded_k_of_one_is_the_plain_vndf() {
        // α = 1 gives k = 0 (the cap is the whole hemisphere offset), α → 0 gives k → 1.
        let wi = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
        assert_eq!(Ggx { ax: 1.0, ay: 1.0 }.bounded_k(wi), 0.0);
        assert!((Ggx { ax: 1e-9, ay: 1e-9 }.bounded_k(wi) - 1.0).abs() < 1e-12);
    }
}
