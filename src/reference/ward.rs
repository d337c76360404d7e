//! The Ward lobe with Walter's corrected pdf: the CPU twin of `shaders/lib/ward.wgsl`.
//!
//! B. Walter, "Notes on the Ward BRDF", Cornell PCG TR-2005-06:
//! - half-vector pdf (his eq. 9): p(h) = exp(−tan²θh (cos²φh/αx² + sin²φh/αy²)) / (π αx αy cos³θh);
//! - sampling (his eqs. 6–8): φh = atan((αy/αx) tan 2πu2) in the quadrant of 2πu2,
//!   tan²θh = −ln u1 / (cos²φh/αx² + sin²φh/αy²); isotropic: tan θh = α √(−ln u1), φh = 2πu2.
//!
//! In slope space (tan θh cos φh, tan θh sin φh) the same map reads √(−ln u1) (αx cos 2πu2,
//! αy sin 2πu2), which is what [`sample_h`] computes: it is monotone in u2 and puts φh in the
//! right quadrant without a branch. Because tan²θh·cos²φh = hx²/hz², the exponent is written
//! in Cartesian form, −(hx²/αx² + hy²/αy²)/hz², which has no tan to overflow.

use super::reflect::from_tan_theta;
use glam::DVec3;
use std::f64::consts::PI;

/// −ln u, accurate near u = 1 (where ln u = ln1p(u − 1) and u − 1 is exact) and ∞ at u = 0.
pub fn neg_ln(u: f64) -> f64 {
    if u > 0.5 { -(u - 1.0).ln_1p() } else { -u.ln() }
}

/// Walter 2005 eqs. 6–8: the half vector for uniforms (u1, u2).
pub fn sample_h(ax: f64, ay: f64, u: [f64; 2]) -> DVec3 {
    let (s, c) = (2.0 * PI * u[1]).sin_cos();
    let (sx, sy) = (ax * c, ay * s);
    let len = sx.hypot(sy);
    from_tan_theta(neg_ln(u[0]).sqrt() * len, sx / len, sy / len)
}

/// The Gaussian slope exponent (hx²/αx² + hy²/αy²)/hz² = tan²θh (cos²φh/αx² + sin²φh/αy²).
pub fn slope_exponent(ax: f64, ay: f64, h: DVec3) -> f64 {
    ((h.x / ax).powi(2) + (h.y / ay).powi(2)) / (h.z * h.z)
}

/// Walter 2005 eq. 9: p(h) over solid angle, zero for hz ≤ 0.
pub fn pdf_h(ax: f64, ay: f64, h: DVec3) -> f64 {
    if h.z <= 0.0 {
        return 0.0;
    }
    (-slope_exponent(ax, ay, h)).exp() / (PI * ax * ay * h.z.powi(3))
}

/// Ward's BRDF (Ward 1992, eq. 5a; Walter 2005 eq. 1) with ρs = 1:
/// f = exp(−tan²θh(…)) / (4π αx αy √(cos θi cos θr)), zero unless both are above the horizon.
pub fn eval(ax: f64, ay: f64, wi: DVec3, wr: DVec3) -> f64 {
    if wi.z <= 0.0 || wr.z <= 0.0 {
        return 0.0;
    }
    let h = (wi + wr).normalize();
    (-slope_exponent(ax, ay, h)).exp() / (4.0 * PI * ax * ay * (wi.z * wr.z).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tutorial_part_3_angles() {
        // α = 0.2, u1 = 0.4, u2 = 0.2: θh = atan(0.2 √(−ln 0.4)) ≈ 10.84°, φh = 72°.
        let h = sample_h(0.2, 0.2, [0.4, 0.2]);
        let theta = h.z.acos().to_degrees();
        let phi = h.y.atan2(h.x).to_degrees();
        assert!((theta - (0.2 * (-(0.4f64).ln()).sqrt()).atan().to_degrees()).abs() < 1e-12);
        assert!((theta - 10.84).abs() < 0.005, "{theta}");
        assert!((phi - 72.0).abs() < 1e-12, "{phi}");
    }

    #[test]
    fn anisotropic_sampling_matches_walters_quadrant_formula() {
        let (ax, ay) = (0.3, 0.07);
        for &u in &[[0.3, 0.1], [0.7, 0.3], [0.2, 0.6], [0.9, 0.8], [0.5, 0.999]] {
            let h = sample_h(ax, ay, u);
            let a = 2.0 * PI * u[1];
            let mut phi = ((ay / ax) * a.tan()).atan();
            // place φh in the quadrant of 2πu2
            if a.cos() < 0.0 {
                phi += PI;
            } else if a.sin() < 0.0 {
                phi += 2.0 * PI;
            }
            let tan2 = -u[0].ln() / (phi.cos().powi(2) / (ax * ax) + phi.sin().powi(2) / (ay * ay));
            let got_phi = h.y.atan2(h.x).rem_euclid(2.0 * PI);
            assert!((got_phi - phi.rem_euclid(2.0 * PI)).abs() < 1e-12);
            let got_tan2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
            assert!((got_tan2 / tan2 - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn extreme_uniforms_give_unit_vectors() {
        for u in [[0.0, 0.0], [1.0, 1.0], [0.0, 0.5], [1.0 - 1e-16, 0.25]] {
            let h = sample_h(0.1, 0.4, u);
            assert!((h.length() - 1.0).abs() < 1e-15, "{u:?} {h}");
        }
    }
}
