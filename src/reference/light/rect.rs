//! The rectangle light sampled uniformly over the spherical rectangle it subtends (Ureña,
//! Fajardo & King 2013, Algorithm 1), its column refined by Newton's method on the strip's Van
//! Oosterom–Strackee solid angle: the CPU twin of `shaders/lib/rect_light.wgsl` (see that
//! file's comment for the equations).

use super::{LightSample, triangle_solid_angle};
use glam::{DVec3, DVec4};

/// A rectangle light: a corner and two perpendicular edges from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rect {
    pub corner: DVec3,
    pub ex: DVec3,
    pub ey: DVec3,
}

/// The rectangle's frame: axes, (x0, y0, x1, y1) and the (negative) depth z0 of its plane.
struct Frame {
    x: DVec3,
    y: DVec3,
    z: DVec3,
    bounds: DVec4,
    depth: f64,
}

impl Frame {
    fn strip(&self, x: f64) -> f64 {
        let p0 = DVec3::new(self.bounds.x, self.bounds.y, self.depth);
        let e1 = DVec3::new(x - self.bounds.x, 0.0, 0.0);
        let e2 = DVec3::new(0.0, self.bounds.w - self.bounds.y, 0.0);
        triangle_solid_angle(p0, e1, e1 + e2) + triangle_solid_angle(p0, e1 + e2, e2)
    }

    /// Ureña et al.'s column x_u for φ = u0 Ω, through cos k and sin k (not the angle au).
    fn column(&self, phi: f64) -> f64 {
        let (z0, b) = (self.depth, self.bounds);
        let n0 = DVec3::new(0.0, z0, -b.y).normalize();
        let n2 = DVec3::new(0.0, -z0, b.w).normalize();
        let n3 = DVec3::new(z0, 0.0, -b.x).normalize();
        let corner = |ni: DVec3, nj: DVec3| (-ni.dot(nj), ni.cross(nj).length());
        let (g2, g3) = (corner(n2, n3), corner(n3, n0));
        let cos_k = g2.0 * g3.0 - g2.1 * g3.1;
        let sin_k = -(g2.1 * g3.0 + g2.0 * g3.1);
        let cos_au = cos_k * phi.cos() - sin_k * phi.sin();
        let sin_au = sin_k * phi.cos() + cos_k * phi.sin();
        let fu = (cos_au * n0.z - n2.z) / sin_au;
        let cu = (fu.signum() / (fu * fu + n0.z * n0.z).sqrt()).clamp(-1.0, 1.0);
        let xu = -(cu * z0) / (1.0 - cu * cu).max(1e-300).sqrt();
        xu.clamp(b.x, b.z)
    }

    /// Two Newton steps on strip(x) = φ, dA/dx = |z0| (h1 − h0) / (x² + z0²).
    fn refine(&self, mut x: f64, phi: f64) -> f64 {
        let b = self.bounds;
        for _ in 0..2 {
            let a2 = x * x + self.depth * self.depth;
            let dh = b.w / (a2 + b.w * b.w).sqrt() - b.y / (a2 + b.y * b.y).sqrt();
            let slope = -self.depth * dh / a2;
            if slope > 0.0 {
                x = (x - (self.strip(x) - phi) / slope).clamp(b.x, b.z);
            }
        }
        x
    }
}

impl Rect {
    fn frame(&self) -> Frame {
        let (lx, ly) = (self.ex.length(), self.ey.length());
        let (x, y) = (self.ex / lx, self.ey / ly);
        let mut z = x.cross(y);
        let mut depth = self.corner.dot(z);
        if depth > 0.0 {
            z = -z;
            depth = -depth;
        }
        let (x0, y0) = (self.corner.dot(x), self.corner.dot(y));
        Frame { x, y, z, bounds: DVec4::new(x0, y0, x0 + lx, y0 + ly), depth }
    }

    /// The solid angle of the rectangle at the origin: its two triangles'.
    pub fn solid_angle(&self) -> f64 {
        let (s, ex, ey) = (self.corner, self.ex, self.ey);
        triangle_solid_angle(s, ex, ex + ey) + triangle_solid_angle(s, ex + ey, ey)
    }

    /// d uniform over the spherical rectangle, density 1/Ω (the corner with density 0 for a
    /// rectangle of no solid angle).
    pub fn sample(&self, u: [f64; 2]) -> LightSample {
        let omega = self.solid_angle();
        if omega.is_nan() || omega <= 0.0 {
            return LightSample { d: self.corner.normalize(), pdf: 0.0 };
        }
        let f = self.frame();
        let xu = f.refine(f.column(u[0] * omega), u[0] * omega);
        let (b, dist2) = (f.bounds, xu * xu + f.depth * f.depth);
        let h0 = b.y / (dist2 + b.y * b.y).sqrt();
        let h1 = b.w / (dist2 + b.w * b.w).sqrt();
        let hv = h0 + u[1] * (h1 - h0);
        let one_minus_h2 = (1.0 - hv) * (1.0 + hv);
        let yv = if one_minus_h2 > 1e-12 { hv * dist2.sqrt() / one_minus_h2.sqrt() } else { b.w };
        let p = xu * f.x + yv.clamp(b.y, b.w) * f.y + f.depth * f.z;
        LightSample { d: p.normalize(), pdf: 1.0 / omega }
    }

    /// The density at the unit direction d: 1/Ω where the ray t d, t > 0, meets the rectangle.
    pub fn pdf(&self, d: DVec3) -> f64 {
        let n = self.ex.cross(self.ey);
        let t = n.dot(self.corner) / n.dot(d);
        let q = t * d - self.corner;
        let (a, b) = (q.dot(self.ex) / self.ex.length_squared(), q.dot(self.ey) / self.ey.length_squared());
        let inside = t > 0.0 && (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b);
        let omega = self.solid_angle();
        if inside && omega > 0.0 { 1.0 / omega } else { 0.0 }
    }
}

/// The solid angle of a w × h rectangle centred on the axis at distance z:
/// 4 asin(sin(atan(w/2z)) sin(atan(h/2z))), a closed form independent of Van Oosterom–Strackee.
pub fn centred_solid_angle(w: f64, h: f64, z: f64) -> f64 {
    4.0 * ((w / (2.0 * z)).atan().sin() * (h / (2.0 * z)).atan().sin()).asin()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn the_solid_angle_matches_the_centred_closed_form() {
        for (w, h, z) in [(1.0, 1.0, 1.0), (2e-3, 5e-4, 1.0), (40.0, 30.0, 0.5)] {
            let r = Rect { corner: DVec3::new(-w / 2.0, -h / 2.0, z), ex: DVec3::new(w, 0.0, 0.0), ey: DVec3::new(0.0, h, 0.0) };
            let closed = centred_solid_angle(w, h, z);
            assert!((r.solid_angle() / closed - 1.0).abs() < 1e-9, "{w}×{h} at {z}: {} vs {closed}", r.solid_angle());
        }
        assert!((centred_solid_angle(2.0, 2.0, 1.0) - 2.0 * PI / 3.0).abs() < 1e-12, "a cube's face: 4π/6");
    }

    /// The strip [x0, x_u] holds u0 Ω exactly (the column solves Ureña's equation), and every
    /// sample lies on the rectangle with the pdf function's density.
    #[test]
    fn the_column_holds_its_share_and_samples_hit_the_rectangle() {
        let rects = [
            Rect { corner: DVec3::new(0.3, -0.2, 1.0), ex: DVec3::new(0.8, 0.0, 0.0), ey: DVec3::new(0.0, 0.6, 0.0) },
            Rect { corner: DVec3::new(1.0, 0.5, 0.2), ex: DVec3::new(0.0, 1e-3, 0.0), ey: DVec3::new(0.0, 0.0, 1e-3) },
        ];
        for r in rects {
            let f = r.frame();
            for u in [[0.05, 0.5], [0.5, 0.1], [0.95, 0.9]] {
                let x = f.refine(f.column(u[0] * r.solid_angle()), u[0] * r.solid_angle());
                assert!((f.strip(x) / (u[0] * r.solid_angle()) - 1.0).abs() < 1e-9, "{r:?} {u:?}");
                // the closed form alone, before Newton, is already close (the refinement polishes)
                let x0 = f.column(u[0] * r.solid_angle());
                assert!((x0 - x).abs() < 1e-6 * (f.bounds.z - f.bounds.x), "{r:?}: Ureña's x {x0} vs {x}");
                let s = r.sample(u);
                assert_eq!(r.pdf(s.d), s.pdf, "{r:?} {u:?}");
            }
        }
    }
}
