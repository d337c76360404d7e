//! The half-vector → reflected-direction change of variables: the CPU twin of
//! `shaders/lib/reflect.wgsl`.
//!
//! ωr = 2(ωi·h)h − ωi, and since dωh/dωr = 1/(4|ωr·h|) (tutorial part 2; Walter et al. 2007,
//! eq. 14), p(ωr) = p(ωh) / (4 |ωr·ωh|).

use glam::DVec3;

/// Mirror reflection of ωi about the unit half vector h: ωr = 2(ωi·h)h − ωi.
pub fn reflect(wi: DVec3, h: DVec3) -> DVec3 {
    2.0 * wi.dot(h) * h - wi
}

/// The Jacobian dωh/dωr = 1/(4|ωr·h|) of the reflection map.
pub fn jacobian(wr: DVec3, h: DVec3) -> f64 {
    1.0 / (4.0 * wr.dot(h).abs())
}

/// p(ωr) from p(ωh) (tutorial part 2): p(ωr) = p(ωh) / (4 |ωr·ωh|).
pub fn pdf_reflected(pdf_h: f64, wr: DVec3, h: DVec3) -> f64 {
    pdf_h * jacobian(wr, h)
}

/// The unit half vector of ωi and ωr, or `None` where it is undefined (ωr = −ωi).
pub fn half_vector(wi: DVec3, wr: DVec3) -> Option<DVec3> {
    let h = wi + wr;
    let len = h.length();
    (len > 0.0 && len.is_finite()).then(|| h / len)
}

/// Unit direction from polar angle θ and azimuth φ (radians), normal on +z.
pub fn spherical(theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// Unit direction whose polar angle has tangent `tan_theta` and whose azimuth is the unit
/// vector `(cos_phi, sin_phi)`. cos θ = 1/√(1+tan²θ) and sin θ = 1/√(1+1/tan²θ) stay exact at
/// tan θ = 0 and tan θ = ∞ (u at 0 or 1), where tan θ·cos θ would give 0·∞.
pub fn from_tan_theta(tan_theta: f64, cos_phi: f64, sin_phi: f64) -> DVec3 {
    let t2 = tan_theta * tan_theta;
    let cos_t = 1.0 / (1.0 + t2).sqrt();
    let sin_t = 1.0 / (1.0 + 1.0 / t2).sqrt();
    DVec3::new(sin_t * cos_phi, sin_t * sin_phi, cos_t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tutorial_part_2_in_plane_jacobian() {
        // θi = 45°, θh = 15°, in plane: ωi·ωh = cos 30°, p(ωr) = 0.5 / (4 cos 30°) = 0.1443…
        let wi = spherical(45f64.to_radians(), 0.0);
        let h = spherical(15f64.to_radians(), 0.0);
        let wr = reflect(wi, h);
        let p = pdf_reflected(0.5, wr, h);
        assert!((p - 0.5 / (4.0 * 30f64.to_radians().cos())).abs() < 1e-15);
        assert!((p - 0.144).abs() < 5e-4);
        assert!((wr.length() - 1.0).abs() < 1e-15);
        // reflection about h: the half vector of ωi and ωr is h again
        assert!((half_vector(wi, wr).unwrap() - h).length() < 1e-15);
    }

    #[test]
    fn from_tan_theta_limits() {
        assert_eq!(from_tan_theta(0.0, 1.0, 0.0), DVec3::Z);
        let h = from_tan_theta(f64::INFINITY, 0.0, 1.0);
        assert_eq!(h, DVec3::Y);
        let h = from_tan_theta(1.0, 1.0, 0.0);
        assert!((h - DVec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-15);
    }
}
