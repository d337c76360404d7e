//! The triangle light sampled uniformly by area and converted to solid angle: the CPU twin of
//! `shaders/lib/triangle_area_light.wgsl`.

use super::{LightSample, area_to_solid_angle};
use glam::DVec3;

/// A triangle light: its vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangle {
    pub p: [DVec3; 3],
}

impl Triangle {
    /// The unnormalised normal e1 × e2 (twice the area long).
    pub fn normal2(&self) -> DVec3 {
        (self.p[1] - self.p[0]).cross(self.p[2] - self.p[0])
    }

    /// The barycentric point (1 − s, s (1 − u1), s u1), s = sqrt(u0), and its density
    /// t² / (A |n·d|) per unit solid angle (0 for a triangle of no area).
    pub fn sample_area(&self, u: [f64; 2]) -> LightSample {
        let (e1, e2) = (self.p[1] - self.p[0], self.p[2] - self.p[0]);
        let s = u[0].sqrt();
        let p = self.p[0] + s * (1.0 - u[1]) * e1 + s * u[1] * e2;
        let m = self.normal2();
        let area2 = m.length();
        let (t, d) = (p.length(), p.normalize());
        LightSample { d, pdf: if area2 > 0.0 { area_to_solid_angle(2.0 / area2, t, m / area2, d) } else { 0.0 } }
    }

    /// Where the ray t d, t > 0, meets the triangle (Möller & Trumbore 1997): its distance t.
    pub fn hit(&self, d: DVec3) -> Option<f64> {
        let (e1, e2) = (self.p[1] - self.p[0], self.p[2] - self.p[0]);
        let q = d.cross(e2);
        let det = e1.dot(q);
        if det == 0.0 {
            return None;
        }
        let s = -self.p[0];
        let b1 = s.dot(q) / det;
        let r = s.cross(e1);
        let b2 = d.dot(r) / det;
        let t = e2.dot(r) / det;
        (t > 0.0 && b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0).then_some(t)
    }

    /// The density of [`Triangle::sample_area`] at the unit direction d.
    pub fn pdf_area(&self, d: DVec3) -> f64 {
        let m = self.normal2();
        let area2 = m.length();
        match self.hit(d) {
            Some(t) if area2 > 0.0 => area_to_solid_angle(2.0 / area2, t, m / area2, d),
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_hit_the_triangle_with_the_functions_pdf() {
        let tri = Triangle { p: [DVec3::new(-0.5, 0.2, 1.0), DVec3::new(0.6, -0.1, 1.2), DVec3::new(0.1, 0.7, 0.8)] };
        for u in [[0.01, 0.0], [0.3, 0.9], [0.99, 0.5]] {
            let s = tri.sample_area(u);
            let t = tri.hit(s.d).expect("the sample's ray meets the triangle");
            // the barycentric point the sample was built from
            let w = u[0].sqrt();
            let p = tri.p[0] + w * (1.0 - u[1]) * (tri.p[1] - tri.p[0]) + w * u[1] * (tri.p[2] - tri.p[0]);
            assert!((t * s.d - p).length() < 1e-12);
            assert!((tri.pdf_area(s.d) / s.pdf - 1.0).abs() < 1e-12);
        }
        assert_eq!(tri.pdf_area(-tri.p[0].normalize()), 0.0, "the opposite direction");
    }
}
