#define_import_path lobes::ggx
#import lobes::math::{Real, math_cos, math_sin}
#import lobes::reflect::{LobeSample, PI, lobe_sample, reflect_about, reflect_sample}
#import lobes::microfacet::stretch
//! embed: ggx
//! GGX (Trowbridge–Reitz) microfacets. Samplers take `(a, wi, u: vec2<f32>)`; densities and the
//! BRDF `(a, wi, wr)`, with a = (αx, αy).

// GGX (Trowbridge-Reitz); CPU twin: src/reference/ggx.rs.
// D(h) = 1 / (pi ax ay (hx^2/ax^2 + hy^2/ay^2 + hz^2)^2)                (Heitz 2014, eq. 85)
// G1(w) = 2|wz| / (|wz| + |(ax wx, ay wy, wz)|)                       (Heitz 2014, eq. 86)
// NDF sampling: cos^2 th = (1-u)/(1+(a^2-1)u) as the stretch of the cosine sample (Walter 2007, eq. 35).
// Visible normals: spherical caps (Dupuy & Benyoub 2023, listing 3); bounded caps for reflection
// (Eto & Tokuyoshi 2023, listings 1-2).

/// GGX's D(h) (Heitz 2014, eq. 85).
fn ggx_d(a: vec2<Real>, h: vec3<Real>) -> Real {
    let q = h.xy / a;
    let e = dot(q, q) + h.z * h.z;
    return 1.0 / (PI * a.x * a.y * e * e);
}

/// Smith's G1(w) for GGX (Heitz 2014, eq. 86).
fn ggx_g1(a: vec2<Real>, w: vec3<Real>) -> Real {
    let z = abs(w.z);
    return 2.0 * z / (z + length(vec3<Real>(a * w.xy, w.z)));
}

/// A reflected direction with h drawn from D(h) cos θh (Walter et al. 2007, eq. 35).
fn ggx_sample_ndf(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> LobeSample {
    let phi = 2.0 * PI * u.y;
    let r = sqrt(u.x);
    let h = normalize(vec3<Real>(a * (r * vec2<Real>(math_cos(phi), math_sin(phi))), sqrt(max(1.0 - u.x, 0.0))));
    return reflect_sample(wi, h, ggx_d(a, h) * h.z);
}

// 1 - ws.z for ws = normalize(ax wx, ay wy, wz), as |v.xy|^2 / (|v| (|v| + v.z)) when v.z >= 0:
// keeps its precision as ws approaches the normal (near-specular alpha).
fn one_minus_stretched_z(a: vec2<Real>, w: vec3<Real>) -> Real {
    let v = vec3<Real>(a * w.xy, w.z);
    let len = length(v);
    if (v.z < 0.0) {
        return 1.0 - v.z / len;
    }
    return dot(v.xy, v.xy) / (len * (len + v.z));
}

// A uniform point on the unit sphere's cap z >= -b, offset by ws and unstretched; ws_minus_b is
// ws.z - b, passed in so the caller can form it without cancellation.
fn ggx_cap_sample(a: vec2<Real>, wi: vec3<Real>, ws: vec3<Real>, b: Real, ws_minus_b: Real, u: vec2<Real>) -> vec3<Real> {
    let phi = 2.0 * PI * u.x;
    // z = s - b, s = (1 - u2)(1 + b). Near-specular alpha puts b and ws.z near 1, where 1 - z^2,
    // 1 - b and z + ws.z cancel; they are formed without cancellation:
    // 1 - z^2 = (s + (1 - b)) ((1 + b) - s), 1 - b = (1 - ws.z) + (ws.z - b), z + ws.z = s + (ws.z - b).
    let s = (1.0 - u.y) * (1.0 + b);
    let one_minus_b = one_minus_stretched_z(a, wi) + ws_minus_b;
    let st = sqrt(clamp((s + one_minus_b) * ((1.0 + b) - s), 0.0, 1.0));
    let hs = vec3<Real>(st * math_cos(phi) + ws.x, st * math_sin(phi) + ws.y, s + ws_minus_b);
    if (dot(hs, hs) == 0.0) {
        // u.y = 1 at wi = +z: the rim of the cap is the single point -ws; the limit is the
        // horizon normal at azimuth phi.
        return normalize(vec3<Real>(a * vec2<Real>(math_cos(phi), math_sin(phi)), 0.0));
    }
    return normalize(vec3<Real>(a * hs.xy, hs.z));
}

// p(wr) = G1(wi) D(h) / (4 cos th_i) (Heitz 2014, eq. 38 through the reflection Jacobian), with
// G1/cos th_i = 2 / (cos th_i + t) so that it stays finite at grazing incidence: D / (2 (wi.z + t)).
/// A reflected direction with h drawn from the visible normals of ωi, by spherical caps
/// (Dupuy & Benyoub 2023).
fn ggx_sample_vndf(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> LobeSample {
    let ws = stretch(a, wi);
    let h = ggx_cap_sample(a, wi, ws, ws.z, 0.0, u);
    let t = length(vec3<Real>(a * wi.xy, wi.z));
    return lobe_sample(wi, h, reflect_about(wi, h), ggx_d(a, h) / (2.0 * (wi.z + t)));
}

// Eto & Tokuyoshi 2023, listing 1: k = (1 - a^2) s^2 / (s^2 + a^2 wi.z^2) shrinks the cap. Returned
// as 1 - k = a^2 (s^2 + wi.z^2) / (s^2 + a^2 wi.z^2), which keeps its precision as a -> 0 (k -> 1).
fn ggx_bounded_one_minus_k(a: vec2<Real>, wi: vec3<Real>) -> Real {
    let am = clamp(min(a.x, a.y), 0.0, 1.0);
    let s = 1.0 + length(wi.xy);
    let a2 = am * am;
    let s2 = s * s;
    let z2 = wi.z * wi.z;
    return a2 * (s2 + z2) / (s2 + a2 * z2);
}

// Eto & Tokuyoshi 2023, listing 2: p(wr) = D(h) / (2 (k wi.z + t)), t = |(ax wi.x, ay wi.y, wi.z)|,
// for wi.z >= 0; D(h) (t - wi.z) / (2 |(ax wi.x, ay wi.y)|^2) below the horizon.
/// A reflected direction by bounded visible normals (Eto & Tokuyoshi 2023).
fn ggx_sample_bounded(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> LobeSample {
    let ws = stretch(a, wi);
    let omk = ggx_bounded_one_minus_k(a, wi);
    let k = 1.0 - omk;
    let b = select(ws.z, k * ws.z, wi.z > 0.0);
    let h = ggx_cap_sample(a, wi, ws, b, select(0.0, omk * ws.z, wi.z > 0.0), u);
    let d = ggx_d(a, h);
    let t = length(vec3<Real>(a * wi.xy, wi.z));
    // Light from below the surface (wi.z < 0, listing 2's second case) is not reflected: pdf 0.
    return lobe_sample(wi, h, reflect_about(wi, h), d / (2.0 * (k * wi.z + t)));
}
