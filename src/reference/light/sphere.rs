//! The sphere light, sampled uniformly over the cone it subtends: the CPU twin of
//! `shaders/lib/sphere_light.wgsl`. sin² θmax = r²/|c|², Ω = 2π (1 − cos θmax) with
//! 1 − cos θmax = sin² θmax / (1 + cos θmax); a point inside the sphere sees Ω = 4π.

use super::{LightSample, to_world};
use glam::DVec3;
use std::f64::consts::PI;

/// A sphere light: centre and radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub centre: DVec3,
    pub radius: f64,
}

impl Sphere {
    /// 1 − cos θmax of the cone (2 inside the sphere).
    pub fn one_minus_cos(&self) -> f64 {
        let sin2 = self.radius * self.radius / self.centre.length_squared();
        if sin2 >= 1.0 { 2.0 } else { sin2 / (1.0 + (1.0 - sin2).sqrt()) }
    }

    /// The solid angle the sphere subtends at the origin.
    pub fn solid_angle(&self) -> f64 {
        2.0 * PI * self.one_minus_cos()
    }

    /// d uniform in the cone: 1 − cos θ = u0 (1 − cos θmax), φ = 2π u1.
    pub fn sample(&self, u: [f64; 2]) -> LightSample {
        let omc_max = self.one_minus_cos();
        let omc = u[0] * omc_max;
        let sin_t = (omc * (2.0 - omc)).max(0.0).sqrt();
        let phi = 2.0 * PI * u[1];
        let local = DVec3::new(sin_t * phi.cos(), sin_t * phi.sin(), 1.0 - omc);
        LightSample { d: to_world(self.centre.normalize(), local).normalize(), pdf: 1.0 / (2.0 * PI * omc_max) }
    }

    /// The density at the unit direction d: 1/Ω inside the cone (|d × c|² ≤ r², d·c > 0).
    pub fn pdf(&self, d: DVec3) -> f64 {
        let r2 = self.radius * self.radius;
        let inside = (d.dot(self.centre) > 0.0 && d.cross(self.centre).length_squared() <= r2) || self.centre.length_squared() <= r2;
        if inside { 1.0 / self.solid_angle() } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cone_matches_its_closed_form_and_holds_its_samples() {
        for (dist, r) in [(2.0, 1.0), (1.0, 1e-3), (1.0, 0.999), (1.0, 2.0)] {
            let s = Sphere { centre: DVec3::new(0.3, -0.4, 0.5).normalize() * dist, radius: r };
            // 2π(1 − cos θmax) with cos θmax = sqrt(1 − r²/d²), an independent spelling
            let closed = if r >= dist { 4.0 * PI } else { 2.0 * PI * (1.0 - (1.0 - (r / dist).powi(2)).sqrt()) };
            assert!((s.solid_angle() / closed - 1.0).abs() < 1e-6, "{dist} {r}: {} vs {closed}", s.solid_angle());
            for u in [[0.0, 0.0], [0.5, 0.25], [0.999, 0.7], [1.0, 1.0]] {
                let x = s.sample(u);
                assert!((x.d.length() - 1.0).abs() < 1e-12);
                // the sampled direction's angle from the axis is the one u0 asked for
                let omc = 1.0 - x.d.dot(s.centre.normalize());
                assert!((omc - u[0] * s.one_minus_cos()).abs() < 1e-8 * s.one_minus_cos().max(1e-6), "{u:?}");
                if u[0] < 1.0 {
                    assert_eq!(s.pdf(x.d), x.pdf);
                }
            }
        }
    }
}
