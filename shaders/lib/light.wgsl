#define_import_path lobes::light
//! embed: light
//! What the light samplers share (CPU twin: `lobes::reference::light`). The shading point is the
//! origin; a light sampler returns a unit direction toward the light and its density per unit
//! solid angle (0: no sample).

/// A sampled direction toward a light and its density per unit solid angle (0: no sample, as for
/// a light of zero solid angle).
struct LightSample {
    d: vec3<f32>,
    pdf: f32,
}

/// π.
const LIGHT_PI: f32 = 3.141592653589793;

// v in the orthonormal basis (t, b, n) around the unit vector n: t v.x + b v.y + n v.z. The basis
// of Duff et al. 2017 ("Building an Orthonormal Basis, Revisited", JCGT 6(1), listing 3): one
// branch, on the sign of n.z, and no division by a small number.
/// v in an orthonormal basis about the unit vector n (Duff et al. 2017).
fn light_to_world(n: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = vec3<f32>(b, s + n.y * n.y * a, -n.y);
    return v.x * t + v.y * bt + v.z * n;
}

// The solid angle of the triangle (p0, p0 + e1, p0 + e2) seen from the origin (Van Oosterom &
// Strackee 1983, for vertices r_i of lengths l_i):
//   tan(Ω/2) = |r0·(r1×r2)| / (l0 l1 l2 + (r0·r1) l2 + (r0·r2) l1 + (r1·r2) l0),
// with the triple product written over the edges, r0·(e1×e2), which keeps it accurate for a
// small, far triangle (no difference of nearly equal cross products). atan2 takes the angle past
// π/2 (a triangle of more than a hemisphere's half).
/// The solid angle of the triangle (p0, p0 + e1, p0 + e2) seen from the origin (Van Oosterom &
/// Strackee 1983).
fn light_triangle_solid_angle(p0: vec3<f32>, e1: vec3<f32>, e2: vec3<f32>) -> f32 {
    let p1 = p0 + e1;
    let p2 = p0 + e2;
    let l0 = length(p0);
    let l1 = length(p1);
    let l2 = length(p2);
    let triple = abs(dot(p0, cross(e1, e2)));
    let below = l0 * l1 * l2 + dot(p0, p1) * l2 + dot(p0, p2) * l1 + dot(p1, p2) * l0;
    return 2.0 * atan2(triple, below);
}

// A density per unit area at the point t d of a light whose unit normal is n, per unit solid
// angle at the origin: pdf_ω = pdf_A t² / |n·d| (d a unit vector; the area-to-solid-angle
// Jacobian). 0 where the light is seen exactly edge-on (no direction reaches it there).
/// A density per unit area at the point t d of a light of unit normal n, per unit solid angle at
/// the origin: pdf_A t² / |n·d|.
fn light_area_to_solid_angle(pdf_area: f32, t: f32, n: vec3<f32>, d: vec3<f32>) -> f32 {
    let c = abs(dot(n, d));
    return select(0.0, pdf_area * t * t / c, c > 0.0);
}
