//! Light samplers: the f64 twins of `shaders/lib/light.wgsl` and the five light modules, and
//! [`registry::LIGHTS`], the one list of them.
//!
//! Conventions (as the WGSL's): the shading point is the origin, a light is given by its
//! geometry, and a sampler maps two uniforms to a unit direction d toward the light with its
//! density per unit solid angle ([`LightSample`]); its `pdf` is that density at any d (0 off
//! the light). Sphere, spherical triangle and spherical rectangle are sampled uniformly in solid
//! angle (density 1/Ω); the disk and the area-uniform triangle by area, converted by
//! pdf_ω = pdf_A t² / |n·d| at the point t d.

pub mod disk;
pub mod rect;
pub mod registry;
pub mod sphere;
pub mod triangle;
pub mod triangle_area;

use glam::DVec3;

/// A sampled direction toward a light and its density per unit solid angle (0: no sample).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    pub d: DVec3,
    pub pdf: f64,
}

/// v in the orthonormal basis (t, b, n) around the unit vector n (Duff et al. 2017, "Building
/// an Orthonormal Basis, Revisited", listing 3): t v.x + b v.y + n v.z.
pub fn to_world(n: DVec3, v: DVec3) -> DVec3 {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = DVec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = DVec3::new(b, s + n.y * n.y * a, -n.y);
    v.x * t + v.y * bt + v.z * n
}

/// The solid angle of the triangle (p0, p0 + e1, p0 + e2) seen from the origin (Van Oosterom &
/// Strackee 1983): tan(Ω/2) = |r0·(r1×r2)| / (l0 l1 l2 + (r0·r1) l2 + (r0·r2) l1 + (r1·r2) l0),
/// the triple product written over the edges, r0·(e1×e2).
pub fn triangle_solid_angle(p0: DVec3, e1: DVec3, e2: DVec3) -> f64 {
    let (p1, p2) = (p0 + e1, p0 + e2);
    let (l0, l1, l2) = (p0.length(), p1.length(), p2.length());
    let triple = p0.dot(e1.cross(e2)).abs();
    let below = l0 * l1 * l2 + p0.dot(p1) * l2 + p0.dot(p2) * l1 + p1.dot(p2) * l0;
    2.0 * triple.atan2(below)
}

/// A density per unit area at the point t d of a light with unit normal n, per unit solid angle:
/// pdf_A t² / |n·d| (0 where the light is seen exactly edge-on).
pub fn area_to_solid_angle(pdf_area: f64, t: f64, n: DVec3, d: DVec3) -> f64 {
    let c = n.dot(d).abs();
    if c > 0.0 { pdf_area * t * t / c } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_basis_is_orthonormal_and_keeps_n() {
        for n in [DVec3::Z, -DVec3::Z, DVec3::new(0.3, -0.5, 0.2).normalize(), DVec3::new(1e-9, 0.0, -1.0).normalize()] {
            let (t, b) = (to_world(n, DVec3::X), to_world(n, DVec3::Y));
            assert!((t.length() - 1.0).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
            assert!(t.dot(b).abs() < 1e-12 && t.dot(n).abs() < 1e-12 && b.dot(n).abs() < 1e-12);
            assert!((t.cross(b) - n).length() < 1e-12, "right-handed about n");
        }
    }

    #[test]
    fn the_octant_is_an_eighth_of_the_sphere() {
        // the triangle (x, y, z) cuts the sphere's first octant: 4π/8 (Girard: three right angles)
        let o = triangle_solid_angle(DVec3::X, DVec3::Y - DVec3::X, DVec3::Z - DVec3::X);
        assert!((o - std::f64::consts::FRAC_PI_2).abs() < 1e-14, "{o}");
        // scaling a vertex along its ray changes nothing
        let o2 = triangle_solid_angle(3.0 * DVec3::X, DVec3::Y - 3.0 * DVec3::X, 0.5 * DVec3::Z - 3.0 * DVec3::X);
        assert!((o2 - o).abs() < 1e-14);
    }
}
