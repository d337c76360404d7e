//! The triangle light sampled uniformly over the spherical triangle it subtends (Arvo 1995,
//! "Stratified Sampling of Spherical Triangles"), density 1/Ω with Ω of Van Oosterom & Strackee
//! 1983: the CPU twin of `shaders/lib/triangle_light.wgsl`, in the same stable forms (see that
//! file's comment: atan2 angles, sum-to-product forms of u and v, 1 − q directly, chords for
//! 1 − cos).

use super::triangle_area::Triangle;
use super::{LightSample, triangle_solid_angle};
use glam::DVec3;

/// The unit vector along the part of w orthogonal to the unit vector a, from w − a.
fn away(a: DVec3, w_minus_a: DVec3) -> DVec3 {
    (w_minus_a - w_minus_a.dot(a) * a).normalize()
}

/// ĉ − b of Arvo's sub-triangle (a, b, ĉ) of area `big_a` (unit vertices a, b, c; α at a).
fn c_hat_minus_b(a: DVec3, b: DVec3, c: DVec3, big_a: f64, (cos_alpha, sin_alpha): (f64, f64)) -> DVec3 {
    let (sh, ch) = (0.5 * big_a).sin_cos();
    let s = big_a.sin() * cos_alpha - big_a.cos() * sin_alpha;
    let t = big_a.cos() * cos_alpha + big_a.sin() * sin_alpha;
    let u = 2.0 * sh * (sin_alpha * ch - cos_alpha * sh);
    let ab = a - b;
    let v = 2.0 * sh * (ch * cos_alpha + sh * sin_alpha) - sin_alpha * 0.5 * ab.length_squared();
    let w0 = (v * 2.0 * sh * sh + u * big_a.sin()) / ((v * s + u * t) * sin_alpha);
    let w = if w0 >= 0.0 { w0.min(2.0) } else { 0.0 };
    ab - w * a + (w * (2.0 - w)).sqrt() * away(a, c - a)
}

impl Triangle {
    /// The solid angle the triangle subtends at the origin.
    pub fn solid_angle(&self) -> f64 {
        triangle_solid_angle(self.p[0], self.p[1] - self.p[0], self.p[2] - self.p[0])
    }

    /// Arvo's map at u: d uniform over the spherical triangle, density 1/Ω (the first vertex's
    /// direction with density 0 for a triangle of no solid angle).
    pub fn sample_spherical(&self, u: [f64; 2]) -> LightSample {
        let omega = self.solid_angle();
        let a = self.p[0].normalize();
        if omega.is_nan() || omega <= 0.0 {
            return LightSample { d: a, pdf: 0.0 };
        }
        let (b, c) = (self.p[1].normalize(), self.p[2].normalize());
        let (n_ab, n_ac) = (a.cross(b - a), a.cross(c - a));
        let alpha = n_ab.cross(n_ac).length().atan2(n_ab.dot(n_ac));
        let cb = c_hat_minus_b(a, b, c, u[0] * omega, (alpha.cos(), alpha.sin()));
        let k = u[1] * 0.5 * cb.length_squared();
        let d = (1.0 - k) * b + (k * (2.0 - k)).max(0.0).sqrt() * away(b, cb);
        LightSample { d: d.normalize(), pdf: 1.0 / omega }
    }

    /// The density of [`Triangle::sample_spherical`] at the unit direction d: 1/Ω where d passes
    /// through the triangle (the triple products d·(p_i × p_j) have the triangle's orientation).
    pub fn pdf_spherical(&self, d: DVec3) -> f64 {
        let omega = self.solid_angle();
        let [p0, p1, p2] = self.p;
        let o = p0.dot((p1 - p0).cross(p2 - p0));
        let inside = [(p0, p1 - p0), (p1, p2 - p1), (p2, p0 - p2)].iter().all(|&(p, e)| d.dot(p.cross(e)) * o >= 0.0);
        if inside && omega > 0.0 { 1.0 / omega } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Arvo's map sends u = (1, ·) ... to the triangle: every sample lies in it, u.y = 1 on the
    /// arc b–ĉ's end ĉ, which for u.x = 1 is c; u.y = 0 is b.
    #[test]
    fn arvos_map_hits_the_triangle_and_its_corners() {
        let small = [DVec3::new(0.3, 0.2, 1.0), DVec3::new(0.3 + 2e-3, 0.2, 1.0), DVec3::new(0.3, 0.2 + 1e-3, 1.0 + 1e-3)];
        let large = [DVec3::new(-2.0, -1.0, 0.3), DVec3::new(3.0, -1.5, 0.2), DVec3::new(0.0, 4.0, 0.5)];
        for p in [small, large] {
            let tri = Triangle { p };
            let corner = |q: DVec3, u: [f64; 2]| {
                let s = tri.sample_spherical(u);
                (s.d - q.normalize()).length()
            };
            let scale = (p[1] - p[0]).length() / p[0].length();
            assert!(corner(p[1], [0.3, 0.0]) < 1e-9 * scale.max(1e-3) && corner(p[2], [1.0, 1.0]) < 1e-7 * scale, "{p:?}");
            for u in [[0.1, 0.2], [0.5, 0.5], [0.9, 0.99], [0.999, 0.001]] {
                let s = tri.sample_spherical(u);
                assert!(tri.hit(s.d).is_some(), "{p:?} {u:?}: {:?} misses", s.d);
                assert_eq!(tri.pdf_spherical(s.d), s.pdf);
            }
        }
    }
}
