#define_import_path lobes::ward
#import lobes::math::{Real, UNDERFLOW_EXPONENT, math_cos, math_exp, math_sin, neg_ln}
#import lobes::reflect::{LobeSample, PI, from_tan_theta, reflect_sample}
//! embed: ward
//! Ward's lobe, sampled and evaluated as in Walter 2005.

// The Ward lobe, Walter 2005 "Notes on the Ward BRDF"; CPU twin: src/reference/ward.rs.
// Sampling (his eqs. 6-8) in slope form: (tan th cos ph, tan th sin ph) = sqrt(-ln u1) (ax cos 2pi u2, ay sin 2pi u2).
// p(h) = exp(-(hx^2/ax^2 + hy^2/ay^2)/hz^2) / (pi ax ay hz^3) (his eq. 9, Cartesian form).

/// A half vector drawn from Ward's p(h) (Walter 2005, eqs. 6–8).
fn ward_sample_h(a: vec2<Real>, u: vec2<Real>) -> vec3<Real> {
    let phi = 2.0 * PI * u.y;
    let d = a * vec2<Real>(math_cos(phi), math_sin(phi));
    let len = length(d);
    return from_tan_theta(sqrt(neg_ln(u.x)) * len, d.x / len, d.y / len);
}

/// Ward's p(h) (Walter 2005, eq. 9).
fn ward_pdf_h(a: vec2<Real>, h: vec3<Real>) -> Real {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let q = h.xy / a;
    let q2 = dot(q, q);
    if (q2 > UNDERFLOW_EXPONENT * h.z * h.z) {
        return 0.0; // exp(-q2/hz^2) < 2^-126: underflows, and hz^3 may too (0/0)
    }
    return math_exp(-q2 / (h.z * h.z)) / (PI * a.x * a.y * h.z * h.z * h.z);
}

/// A reflected direction by Ward's half-vector sampling (Walter 2005).
fn ward_sample(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> LobeSample {
    let h = ward_sample_h(a, u);
    return reflect_sample(wi, h, ward_pdf_h(a, h));
}
