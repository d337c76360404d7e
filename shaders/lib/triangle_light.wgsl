#define_import_path lobes::triangle_light
#import lobes::light::{LightSample, light_triangle_solid_angle}
//! embed: triangle_light
//! A triangle light, uniform over its spherical triangle (Arvo 1995).

// A triangle light (vertices p0, p1, p2) sampled uniformly over the spherical triangle it
// subtends (Arvo 1995, "Stratified Sampling of Spherical Triangles"): density 1/Ω, Ω the solid
// angle of Van Oosterom & Strackee 1983 (light_triangle_solid_angle). CPU twin:
// src/reference/light/triangle.rs.
//
// Arvo's algorithm on the unit vertices a, b, c, with α the spherical angle at a: a sub-triangle
// (a, b, ĉ) of area Â = u.x Ω fixes ĉ on the arc a–c at cos(arc aĉ) = q,
//   q = ((v t − u s) cos α − v) / ((v s + u t) sin α),
//   s = sin(Â − α), t = cos(Â − α), u = t − cos α, v = s + sin α cos(arc ab),
// then d on the arc b–ĉ at cos(arc bd) = 1 − u.y (1 − ĉ·b). In f32 these are written so
// that no step subtracts nearly equal numbers for a small triangle:
// - α = atan2(|n_ab × n_ac|, n_ab·n_ac) of the planes' normals n_ab = a × (b − a), ... (acos of a
//   dot product near ±1 loses the angle);
// - u = 2 sin(Â/2) sin(α − Â/2), v = 2 sin(Â/2) cos(Â/2 − α) − sin α (1 − cos(arc ab)),
//   1 − cos(arc ab) = |a − b|²/2 (sum-to-product forms of the same expressions);
// - 1 − q = (v (1 − cos Â) + u sin Â) / ((v s + u t) sin α) (the numerator of 1 − q with
//   s sin α − t cos α = −cos Â and t sin α + s cos α = sin Â), and sin(arc aĉ) from it;
// - 1 − ĉ·b = |ĉ − b|²/2, with ĉ − b = (a − b) − (1 − q) a + sin(arc aĉ) e.

/// The solid angle of the triangle seen from the origin.
fn triangle_light_solid_angle(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> f32 {
    return light_triangle_solid_angle(p0, p1 - p0, p2 - p0);
}

// The unit vector along the part of w orthogonal to the unit vector a, from w − a (small for w
// near a): (w − a) − ((w − a)·a) a.
fn triangle_light_away(a: vec3<f32>, w_minus_a: vec3<f32>) -> vec3<f32> {
    return normalize(w_minus_a - dot(w_minus_a, a) * a);
}

// ĉ − b for the sub-triangle of area big_a (see the file's comment); a, b, c unit vectors.
fn triangle_light_c_hat_minus_b(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, big_a: f32, cos_alpha: f32, sin_alpha: f32) -> vec3<f32> {
    let sh = sin(0.5 * big_a);
    let ch = cos(0.5 * big_a);
    let s = sin(big_a) * cos_alpha - cos(big_a) * sin_alpha;
    let t = cos(big_a) * cos_alpha + sin(big_a) * sin_alpha;
    let u = 2.0 * sh * (sin_alpha * ch - cos_alpha * sh);
    let ab = a - b;
    let v = 2.0 * sh * (ch * cos_alpha + sh * sin_alpha) - sin_alpha * 0.5 * dot(ab, ab);
    let w0 = (v * 2.0 * sh * sh + u * sin(big_a)) / ((v * s + u * t) * sin_alpha);
    let w = clamp(select(w0, 0.0, !(w0 >= 0.0)), 0.0, 2.0);
    let e = triangle_light_away(a, c - a);
    return ab - w * a + sqrt(w * (2.0 - w)) * e;
}

// d uniform over the spherical triangle: Arvo's map at (u.x, u.y), density 1/Ω. A triangle of
// zero solid angle (collinear vertices, seen edge-on) gives its first vertex's direction with
// density 0.
/// A direction uniform over the spherical triangle (Arvo 1995), density 1/Ω.
fn triangle_light_sample(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>, u: vec2<f32>) -> LightSample {
    let omega = triangle_light_solid_angle(p0, p1, p2);
    let a = normalize(p0);
    if (!(omega > 0.0)) {
        return LightSample(a, 0.0);
    }
    let b = normalize(p1);
    let c = normalize(p2);
    let n_ab = cross(a, b - a);
    let n_ac = cross(a, c - a);
    let alpha = atan2(length(cross(n_ab, n_ac)), dot(n_ab, n_ac));
    let cb = triangle_light_c_hat_minus_b(a, b, c, u.x * omega, cos(alpha), sin(alpha));
    // d on the arc from b toward ĉ, 1 − cos(arc bd) = u.y (1 − ĉ·b)
    let k = u.y * 0.5 * dot(cb, cb);
    let d = (1.0 - k) * b + sqrt(max(k * (2.0 - k), 0.0)) * triangle_light_away(b, cb);
    return LightSample(normalize(d), 1.0 / omega);
}

// The density of triangle_light_sample at the unit direction d: 1/Ω where d passes through the
// triangle (the three triple products d·(p_i × p_j), over the edges, have the sign of the
// triangle's orientation; −d has the opposite signs), else 0.
/// The density of triangle_light_sample at the unit direction d: 1/Ω through the triangle, else 0.
fn triangle_light_pdf(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>, d: vec3<f32>) -> f32 {
    let omega = triangle_light_solid_angle(p0, p1, p2);
    let e0 = p1 - p0;
    let e1 = p2 - p1;
    let e2 = p0 - p2;
    let o = dot(p0, cross(e0, p2 - p0));
    let s0 = dot(d, cross(p0, e0)) * o;
    let s1 = dot(d, cross(p1, e1)) * o;
    let s2 = dot(d, cross(p2, e2)) * o;
    let inside = s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0;
    return select(0.0, 1.0 / omega, inside && omega > 0.0);
}
