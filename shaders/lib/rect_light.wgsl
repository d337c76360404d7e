#define_import_path lobes::rect_light
#import lobes::light::{LightSample, light_triangle_solid_angle}
//! embed: rect_light
//! A rectangle light (corner s, perpendicular edges ex, ey), uniform over its spherical rectangle
//! (Ureña, Fajardo & King 2013).

// A rectangle light (corner s, perpendicular edges ex and ey) sampled uniformly over the
// spherical rectangle it subtends (Ureña, Fajardo & King 2013, "An Area-Preserving
// Parametrization for Spherical Rectangles", EGSR, Algorithm 1); density 1/Ω, Ω the sum of its two
// triangles' Van Oosterom–Strackee solid angles. CPU twin: src/reference/light/rect.rs.
//
// In the rectangle's frame (x̂ = ex/|ex|, ŷ = ey/|ey|, ẑ = x̂ × ŷ turned so that z0 = s·ẑ < 0) its
// corners are (x0 or x1, y0 or y1, z0); n0..n3 are the unit normals of the planes through the
// origin and its edges, and g0..g3 the angles between consecutive planes. u.x fixes the
// column x where the sub-rectangle [x0, x] has u.x Ω (Ureña's equation for x_u through the angle
// au = u.x Ω + k, k = 2π − g2 − g3), u.y the height y uniformly in the cosine h between h0 and h1.
// In f32, unlike the paper's listing: the angles are atan2(|n_i × n_j|, −n_i·n_j), not acos; and
// cos au, sin au are expanded from cos k = cos(g2 + g3), sin k = −sin(g2 + g3) (products of
// the planes' own cosines and sines) and φ = u.x Ω, so that au, a number near π known only to
// 2e-7, never enters. Even so the angles' cosines carry an absolute error of ~1e-7, which
// for a light of 10⁻⁶ sr off the axis is a few percent of its solid angle; so x_u is then
// refined by two Newton steps on the equation itself, A(x) = u.x Ω, where A(x), the solid angle
// of the strip [x0, x] × [y0, y1], is Van Oosterom–Strackee's (accurate to f32 for any size) and
// dA/dx = |z0| (h1 − h0) / (x² + z0²), h = y / sqrt(x² + y² + z0²) (the plane's
// dω = |z0| dx dy / (x² + y² + z0²)^(3/2) integrated over y).

struct RectFrame {
    x: vec3<f32>,
    y: vec3<f32>,
    z: vec3<f32>,
    // x0, y0, x1, y1
    box: vec4<f32>,
    depth: f32,
}

fn rect_light_frame(s: vec3<f32>, ex: vec3<f32>, ey: vec3<f32>) -> RectFrame {
    let lx = length(ex);
    let ly = length(ey);
    let x = ex / lx;
    let y = ey / ly;
    var z = cross(x, y);
    var z0 = dot(s, z);
    if (z0 > 0.0) {
        z = -z;
        z0 = -z0;
    }
    let x0 = dot(s, x);
    let y0 = dot(s, y);
    return RectFrame(x, y, z, vec4<f32>(x0, y0, x0 + lx, y0 + ly), z0);
}

// The solid angle of the rectangle seen from the origin: its two triangles (s, s + ex, s + ex + ey)
// and (s, s + ex + ey, s + ey).
/// The solid angle of the rectangle (corner s, perpendicular edges ex, ey) seen from the origin.
fn rect_light_solid_angle(s: vec3<f32>, ex: vec3<f32>, ey: vec3<f32>) -> f32 {
    return light_triangle_solid_angle(s, ex, ex + ey) + light_triangle_solid_angle(s, ex + ey, ey);
}

// (cos, sin) of the angle between the planes of unit normals ni and nj: (−ni·nj, |ni × nj|).
fn rect_light_corner(ni: vec3<f32>, nj: vec3<f32>) -> vec2<f32> {
    return vec2<f32>(-dot(ni, nj), length(cross(ni, nj)));
}

// The column x_u of Ureña et al.'s Algorithm 1 for φ = u.x Ω (see the file's comment).
fn rect_light_column(f: RectFrame, phi: f32) -> f32 {
    let z0 = f.depth;
    let n0 = normalize(vec3<f32>(0.0, z0, -f.box.y));
    let n2 = normalize(vec3<f32>(0.0, -z0, f.box.w));
    let n1 = normalize(vec3<f32>(-z0, 0.0, f.box.z));
    let n3 = normalize(vec3<f32>(z0, 0.0, -f.box.x));
    let g2 = rect_light_corner(n2, n3);
    let g3 = rect_light_corner(n3, n0);
    // k = 2π − g2 − g3: cos k = cos(g2 + g3), sin k = −sin(g2 + g3)
    let cos_k = g2.x * g3.x - g2.y * g3.y;
    let sin_k = -(g2.y * g3.x + g2.x * g3.y);
    let cos_au = cos_k * cos(phi) - sin_k * sin(phi);
    let sin_au = sin_k * cos(phi) + cos_k * sin(phi);
    let b0 = n0.z;
    let b1 = n2.z;
    let fu = (cos_au * b0 - b1) / sin_au;
    let cu = clamp(sign(fu) / sqrt(fu * fu + b0 * b0), -1.0, 1.0);
    let xu = -(cu * z0) / sqrt(max(1.0 - cu * cu, 1.0e-30));
    return clamp(xu, f.box.x, f.box.z);
}

// The solid angle of the strip [x0, x] × [y0, y1] of the rectangle, in its frame.
fn rect_light_strip(f: RectFrame, x: f32) -> f32 {
    let p0 = vec3<f32>(f.box.x, f.box.y, f.depth);
    let e1 = vec3<f32>(x - f.box.x, 0.0, 0.0);
    let e2 = vec3<f32>(0.0, f.box.w - f.box.y, 0.0);
    return light_triangle_solid_angle(p0, e1, e1 + e2) + light_triangle_solid_angle(p0, e1 + e2, e2);
}

// x_u refined by Newton's method on rect_light_strip(f, x) = phi (see the file's comment).
fn rect_light_refine(f: RectFrame, x_start: f32, phi: f32) -> f32 {
    var x = x_start;
    for (var i = 0; i < 2; i++) {
        let a2 = x * x + f.depth * f.depth;
        let dh = f.box.w / sqrt(a2 + f.box.w * f.box.w) - f.box.y / sqrt(a2 + f.box.y * f.box.y);
        let slope = -f.depth * dh / a2;
        let step = (rect_light_strip(f, x) - phi) / slope;
        x = clamp(select(x, x - step, slope > 0.0), f.box.x, f.box.z);
    }
    return x;
}

// d uniform over the spherical rectangle, density 1/Ω. A rectangle of zero solid angle (seen
// edge-on, or an edge of length 0) gives its corner's direction with density 0.
/// A direction uniform over the spherical rectangle (Ureña, Fajardo & King 2013), density 1/Ω.
fn rect_light_sample(s: vec3<f32>, ex: vec3<f32>, ey: vec3<f32>, u: vec2<f32>) -> LightSample {
    let omega = rect_light_solid_angle(s, ex, ey);
    if (!(omega > 0.0)) {
        return LightSample(normalize(s), 0.0);
    }
    let f = rect_light_frame(s, ex, ey);
    let xu = rect_light_refine(f, rect_light_column(f, u.x * omega), u.x * omega);
    // the height: h = y / sqrt(dist² + y²) uniform between its values at y0 and y1
    let dist2 = xu * xu + f.depth * f.depth;
    let h0 = f.box.y / sqrt(dist2 + f.box.y * f.box.y);
    let h1 = f.box.w / sqrt(dist2 + f.box.w * f.box.w);
    let hv = h0 + u.y * (h1 - h0);
    let one_minus_h2 = (1.0 - hv) * (1.0 + hv);
    let yv = select(f.box.w, hv * sqrt(dist2) / sqrt(one_minus_h2), one_minus_h2 > 1.0e-12);
    let p = xu * f.x + clamp(yv, f.box.y, f.box.w) * f.y + f.depth * f.z;
    return LightSample(normalize(p), 1.0 / omega);
}

// The density of rect_light_sample at the unit direction d: 1/Ω where the ray t d (t > 0) meets
// the rectangle, else 0.
/// The density of rect_light_sample at the unit direction d: 1/Ω through the rectangle, else 0.
fn rect_light_pdf(s: vec3<f32>, ex: vec3<f32>, ey: vec3<f32>, d: vec3<f32>) -> f32 {
    let n = cross(ex, ey);
    let t = dot(n, s) / dot(n, d);
    let q = t * d - s;
    let a = dot(q, ex) / dot(ex, ex);
    let b = dot(q, ey) / dot(ey, ey);
    let inside = t > 0.0 && a >= 0.0 && a <= 1.0 && b >= 0.0 && b <= 1.0;
    let omega = rect_light_solid_angle(s, ex, ey);
    return select(0.0, 1.0 / omega, inside && omega > 0.0);
}
