//! Fresnel reflectance at the angle cos θ = ωi·h between the incident direction and the
//! microfacet (or Ward half vector); the f64 twin of `shaders/lib/fresnel.wgsl`.

use serde::Serialize;

/// Which Fresnel term multiplies the BRDF.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Fresnel {
    /// F = 1: a lossless mirror-like microsurface.
    None,
    /// Schlick's approximation with normal-incidence reflectance `f0` ∈ [0, 1].
    Schlick { f0: f64 },
    /// A conductor with complex index of refraction η + i k.
    Conductor { eta: f64, k: f64 },
    /// A dielectric with relative index η = n_t / n_i (reflection only).
    Dielectric { eta: f64 },
}

impl Fresnel {
    /// The reflectance at cos θ (clamped to [0, 1]).
    pub fn reflectance(&self, cos_theta: f64) -> f64 {
        match *self {
            Fresnel::None => 1.0,
            Fresnel::Schlick { f0 } => schlick(cos_theta, f0),
            Fresnel::Conductor { eta, k } => conductor(cos_theta, eta, k),
            Fresnel::Dielectric { eta } => dielectric(cos_theta, eta),
        }
    }
    /// The kernels' code for this form (`FRESNEL` in the composed WGSL).
    pub fn mode(&self) -> u32 {
        match self {
            Fresnel::None => 0,
            Fresnel::Schlick { .. } => 1,
            Fresnel::Conductor { .. } => 2,
            Fresnel::Dielectric { .. } => 3,
        }
    }
    /// The kernels' parameters: (f0) or (η, k).
    pub fn params(&self) -> [f32; 4] {
        match *self {
            Fresnel::None => [0.0; 4],
            Fresnel::Schlick { f0 } => [f0 as f32, 0.0, 0.0, 0.0],
            Fresnel::Conductor { eta, k } => [eta as f32, k as f32, 0.0, 0.0],
            Fresnel::Dielectric { eta } => [eta as f32, 0.0, 0.0, 0.0],
        }
    }
    pub fn name(&self) -> &'static str {
        match self {
            Fresnel::None => "none",
            Fresnel::Schlick { .. } => "schlick",
            Fresnel::Conductor { .. } => "conductor",
            Fresnel::Dielectric { .. } => "dielectric",
        }
    }
}

/// Schlick 1994, eq. 24: F0 + (1 − F0)(1 − cos θ)⁵.
pub fn schlick(c: f64, f0: f64) -> f64 {
    f0 + (1.0 - f0) * (1.0 - c.clamp(0.0, 1.0)).powi(5)
}

/// Snell's law: cos θt = √(1 − (1 − cos²θi)/η²) of the ray refracted at cos θi = `c` ≥ 0 into
/// the medium of relative index η = η_t/η_i; `None` at and past the critical angle (total
/// internal reflection, η < 1).
pub fn cos_transmitted(c: f64, eta: f64) -> Option<f64> {
    let sin2_t = (1.0 - c * c) / (eta * eta);
    (sin2_t < 1.0).then(|| (1.0 - sin2_t).sqrt())
}

/// A dielectric seen from the side of ωi, η = η_t/η_i (pbrt-v4 `FrDielectric`, eq. 9.5);
/// 1 past the critical angle.
///
/// The amplitudes r∥ = (ηc − cos θt)/(ηc + cos θt) and r⊥ = (c − η cos θt)/(c + η cos θt) are
/// differences that cancel as η → 1 (cos θt → c): in f32 at η = 1 + 1e-6 they kept one digit,
/// and F (the density of a reflected sample) was off by up to 12 % (`lobes stress`). With
/// Snell's law, η² cos²θt = η² − 1 + c², each is a quotient instead:
/// r⊥ = (1 − η²)/(c + η cos θt)² and r∥ = (η² − 1)(c²(η² + 1) − 1)/(η² (ηc + cos θt)²), whose
/// last factor vanishes at Brewster's angle (cos²θB = 1/(1 + η²)), a zero and not a
/// cancellation. `shaders/lib/fresnel.wgsl`'s `fresnel_dielectric` is the twin.
pub fn dielectric(c: f64, eta: f64) -> f64 {
    let ci = c.clamp(0.0, 1.0);
    // at grazing incidence both amplitudes are −1: F = 1 exactly, which the quotients below
    // reach only to the rounding of η² cos²θt against η² − 1
    let Some(ct) = cos_transmitted(ci, eta).filter(|_| ci > 0.0) else { return 1.0 };
    let eta2_minus_1 = (eta - 1.0) * (eta + 1.0);
    let r_parl = eta2_minus_1 * (ci * ci * (eta * eta + 1.0) - 1.0) / (eta * eta * (eta * ci + ct).powi(2));
    let r_perp = -eta2_minus_1 / (ci + eta * ct).powi(2);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// The transmittance T = 1 − F of [`dielectric`], formed without the cancellation of 1 − F as
/// F → 1 (near the critical angle and at grazing incidence, where T is what a refraction's
/// density is made of): for r = (a − b)/(a + b), 1 − r² = 4ab/(a + b)², so
/// T = 2ηc cos θt (1/(ηc + cos θt)² + 1/(c + η cos θt)²); 0 past the critical angle.
pub fn dielectric_transmittance(c: f64, eta: f64) -> f64 {
    let ci = c.clamp(0.0, 1.0);
    let Some(ct) = cos_transmitted(ci, eta) else { return 0.0 };
    2.0 * eta * ci * ct * ((eta * ci + ct).powi(-2) + (ci + eta * ct).powi(-2))
}

/// Complex numbers as (re, im), just what the conductor's Fresnel equations need.
#[derive(Clone, Copy)]
struct C(f64, f64);

impl C {
    fn mul(self, b: C) -> C {
        C(self.0 * b.0 - self.1 * b.1, self.0 * b.1 + self.1 * b.0)
    }
    fn div(self, b: C) -> C {
        let d = b.0 * b.0 + b.1 * b.1;
        C((self.0 * b.0 + self.1 * b.1) / d, (self.1 * b.0 - self.0 * b.1) / d)
    }
    fn add(self, b: C) -> C {
        C(self.0 + b.0, self.1 + b.1)
    }
    fn sub(self, b: C) -> C {
        C(self.0 - b.0, self.1 - b.1)
    }
    fn norm2(self) -> f64 {
        self.0 * self.0 + self.1 * self.1
    }
    /// The principal square root, without cancellation (pbrt-v4 `pstd::sqrt`).
    fn sqrt(self) -> C {
        let n = self.0.hypot(self.1);
        if n == 0.0 {
            return C(0.0, 0.0);
        }
        let t1 = (0.5 * (n + self.0.abs())).sqrt();
        let t2 = 0.5 * self.1 / t1;
        if self.0 >= 0.0 { C(t1, t2) } else { C(t2.abs(), t1.copysign(self.1)) }
    }
}

/// A conductor with complex index η + i k (pbrt-v4 `FrComplex`): eq. 9.6 with complex η.
pub fn conductor(c: f64, eta: f64, k: f64) -> f64 {
    let ci = c.clamp(0.0, 1.0);
    let e = C(eta, k);
    let sin2_t = C(1.0 - ci * ci, 0.0).div(e.mul(e));
    let ct = C(1.0, 0.0).sub(sin2_t).sqrt();
    let ec = C(eta * ci, k * ci);
    let r_parl = ec.sub(ct).div(ec.add(ct));
    let ect = e.mul(ct);
    let r_perp = C(ci, 0.0).sub(ect).div(C(ci, 0.0).add(ect));
    0.5 * (r_parl.norm2() + r_perp.norm2())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_matches_the_closed_forms() {
        // At normal incidence both polarisations give ((η − 1)² + k²) / ((η + 1)² + k²).
        let (eta, k) = (0.2, 3.9);
        let f0 = ((eta - 1.0f64).powi(2) + k * k) / ((eta + 1.0f64).powi(2) + k * k);
        assert!((conductor(1.0, eta, k) - f0).abs() < 1e-14);
        assert!((dielectric(1.0, 1.5) - 0.04).abs() < 1e-15);
        assert!((schlick(1.0, 0.04) - 0.04).abs() < 1e-15);
    }

    #[test]
    fn conductor_with_no_absorption_is_the_dielectric() {
        for c in [0.05, 0.3, 0.7, 1.0] {
            assert!((conductor(c, 1.5, 0.0) - dielectric(c, 1.5)).abs() < 1e-14, "cos {c}");
        }
    }

    #[test]
    fn transmittance_is_one_minus_reflectance_and_keeps_its_digits_near_the_critical_angle() {
        for eta in [1.5, 1.0 / 1.5, 2.5] {
            for c in [0.2, 0.5, 0.9, 1.0] {
                assert!((dielectric_transmittance(c, eta) + dielectric(c, eta) - 1.0).abs() < 1e-15, "η {eta} c {c}");
            }
        }
        // just inside the critical angle from glass (cos θt ~ 1e-7): to first order in cos θt,
        // T = 2 cos θt (1/(ηc) + η/c), which 1 − F gets to only ~9 digits
        let eta: f64 = 1.0 / 1.5;
        let c = (1.0 - eta * eta * (1.0 - 1e-14f64)).sqrt();
        let ct = cos_transmitted(c, eta).unwrap();
        let first_order = 2.0 * ct * (1.0 / (eta * c) + eta / c);
        assert!(ct < 1e-6 && (dielectric_transmittance(c, eta) / first_order - 1.0).abs() < 1e-6, "cos θt {ct}");
        assert_eq!(dielectric_transmittance(c * 0.999, eta), 0.0);
    }

    /// As η → 1 the amplitudes are differences of nearly equal numbers; the quotient form keeps
    /// its digits. At η = 1 + ε, r⊥ = −ε/(2c²) and r∥ = ε(2c² − 1)/(2c²) to first order, so
    /// F = ε² (1 + (2c² − 1)²)/(8c⁴) (1 + O(ε/c²)); at ε = 2⁻⁴⁰ the differences as written keep
    /// ~4 digits of F, and the quotients ~15. Away from η = 1 both forms agree.
    #[test]
    fn dielectric_keeps_its_digits_as_eta_goes_to_one() {
        let as_written = |c: f64, eta: f64| {
            let ct = cos_transmitted(c, eta).unwrap();
            let (p, s) = ((eta * c - ct) / (eta * c + ct), (c - eta * ct) / (c + eta * ct));
            0.5 * (p * p + s * s)
        };
        for eta in [1.5, 1.0 / 1.5, 2.5, 1.0 / 2.5, 1.33] {
            for c in [0.05, 0.3, 0.6, 0.99, 1.0] {
                if cos_transmitted(c, eta).is_some() {
                    assert!((dielectric(c, eta) / as_written(c, eta) - 1.0).abs() < 1e-13, "η {eta} c {c}");
                }
            }
        }
        let eps = 2f64.powi(-40);
        for c in [0.3f64, 0.6, 0.9] {
            let first_order = eps * eps * (1.0 + (2.0 * c * c - 1.0).powi(2)) / (8.0 * c.powi(4));
            assert!((dielectric(c, 1.0 + eps) / first_order - 1.0).abs() < 1e-9, "c {c}");
        }
        assert!((as_written(0.6, 1.0 + eps) / (eps * eps * (1.0 + 0.28f64.powi(2)) / (8.0 * 0.6f64.powi(4))) - 1.0).abs() > 1e-6);
    }

    #[test]
    fn grazing_incidence_reflects_everything() {
        assert_eq!(dielectric(0.0, 1.5), 1.0);
        assert!((conductor(0.0, 0.2, 3.9) - 1.0).abs() < 1e-12);
        assert_eq!(schlick(0.0, 0.04), 1.0);
        // total internal reflection from the denser side, past asin(1/1.5)'s complement
        assert_eq!(dielectric(0.5, 1.0 / 1.5), 1.0);
    }
}
