#define_import_path lobes::triangle_area_light
#import lobes::light::{LightSample, light_area_to_solid_angle}
//! embed: triangle_area_light
//! A triangle light, uniform by area.

// A triangle light (vertices p0, p1, p2) sampled uniformly by area and converted to solid angle,
// pdf_ω = t² / (A |n·d|) at the point t d; CPU twin: src/reference/light/triangle_area.rs.
// Cheaper than triangle_light's spherical triangle, with a density that grows toward an edge-on
// or near triangle (its variance, not its correctness).

// The barycentric point (1 − s, s (1 − u.y), s u.y), s = sqrt(u.x): uniform by area (Turk 1990;
// Pharr et al., PBR 3rd ed., §13.6.5), with its density per unit solid angle.
/// A direction toward a point uniform by area on the triangle (Turk 1990).
fn triangle_area_light_sample(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>, u: vec2<f32>) -> LightSample {
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let s = sqrt(u.x);
    let p = p0 + s * (1.0 - u.y) * e1 + s * u.y * e2;
    let m = cross(e1, e2);
    let area2 = length(m);
    let t = length(p);
    let d = p / t;
    let pdf = select(0.0, light_area_to_solid_angle(2.0 / area2, t, m / area2, d), area2 > 0.0);
    return LightSample(d, pdf);
}

// The density of triangle_area_light_sample at the unit direction d: where the ray t d meets
// the triangle (Möller & Trumbore 1997: t and the barycentrics by Cramer's rule), the area
// density converted, else 0.
/// The density of triangle_area_light_sample at the unit direction d.
fn triangle_area_light_pdf(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>, d: vec3<f32>) -> f32 {
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let q = cross(d, e2);
    let det = dot(e1, q);
    if (det == 0.0) {
        return 0.0;
    }
    let s = -p0;
    let b1 = dot(s, q) / det;
    let r = cross(s, e1);
    let b2 = dot(d, r) / det;
    let t = dot(e2, r) / det;
    let m = cross(e1, e2);
    let area2 = length(m);
    let inside = t > 0.0 && b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 && area2 > 0.0;
    return select(0.0, light_area_to_solid_angle(2.0 / area2, t, m / area2, d), inside);
}
