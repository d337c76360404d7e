#define_import_path lobes::fresnel
#import lobes::math::Real
//! embed: fresnel
//! Fresnel reflectance at cos θ = ωi·h (CPU twin: `lobes::reference::fresnel`), each in [0, 1].

// Fresnel reflectance of the microfacet (or Ward half-vector) at cos th = wi.h; CPU twin:
// src/reference/fresnel.rs. Every form returns a reflectance in [0, 1].

/// Schlick 1994, eq. 24: F0 + (1 - F0) (1 - cos th)^5.
fn fresnel_schlick(c: f32, f0: f32) -> f32 {
    let m = clamp(1.0 - c, 0.0, 1.0);
    let m2 = m * m;
    return f0 + (1.0 - f0) * (m2 * m2 * m);
}

// Snell's cos th_t for cos th_i = c in [0, 1] and relative index eta = n_t / n_i, or -1 past the
// critical angle (total internal reflection, eta < 1); CPU twin: reference::fresnel::cos_transmitted.
/// Snell's cos θt for cos θi = c in [0, 1] and relative index η = nt / ni; −1 past the critical
/// angle.
fn fresnel_cos_transmitted(c: Real, eta: Real) -> Real {
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if (sin2_t >= 1.0) {
        return -1.0;
    }
    return sqrt(1.0 - sin2_t);
}

// A dielectric seen from outside, relative index eta = n_t / n_i (pbrt-v4 FrDielectric, eq. 9.5):
// 1 past the critical angle. Over Real: the rough dielectric (shaders/lib/dielectric.wgsl) also
// runs in f64 kernels. The amplitudes are written as quotients by Snell's law, without the
// cancellation of eta c - ct and c - eta ct as eta -> 1 (reference::fresnel::dielectric).
/// A dielectric's reflectance at cos θi = c, relative index η = nt / ni; 1 past the critical angle.
fn fresnel_dielectric(c: Real, eta: Real) -> Real {
    let ci = clamp(c, 0.0, 1.0);
    let ct = fresnel_cos_transmitted(ci, eta);
    // at grazing incidence (ci = 0) both amplitudes are -1, F = 1 exactly
    if (ct < 0.0 || ci == 0.0) {
        return 1.0;
    }
    let k = (eta - 1.0) * (eta + 1.0);
    let p = eta * ci + ct;
    let s = ci + eta * ct;
    let r_parl = k * (ci * ci * (eta * eta + 1.0) - 1.0) / (eta * eta * p * p);
    let r_perp = -k / (s * s);
    return 0.5 * (r_parl * r_parl + r_perp * r_perp);
}

// T = 1 - F of fresnel_dielectric without its cancellation as F -> 1: 1 - r^2 = 4ab / (a + b)^2
// for r = (a - b)/(a + b) (reference::fresnel::dielectric_transmittance).
/// 1 − fresnel_dielectric without its cancellation near the critical angle.
fn fresnel_dielectric_transmittance(c: Real, eta: Real) -> Real {
    let ci = clamp(c, 0.0, 1.0);
    let ct = fresnel_cos_transmitted(ci, eta);
    if (ct < 0.0) {
        return 0.0;
    }
    let p = eta * ci + ct;
    let s = ci + eta * ct;
    return 2.0 * eta * ci * ct * (1.0 / (p * p) + 1.0 / (s * s));
}

// Complex numbers as vec2 (re, im).
fn complex_mul(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

fn complex_div(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return complex_mul(a, vec2<f32>(b.x, -b.y)) / dot(b, b);
}

// The principal square root without cancellation (pbrt-v4 pstd::sqrt of complex).
fn complex_sqrt(z: vec2<f32>) -> vec2<f32> {
    let n = length(z);
    if (n == 0.0) {
        return vec2<f32>(0.0);
    }
    let t1 = sqrt(0.5 * (n + abs(z.x)));
    let t2 = 0.5 * z.y / t1;
    if (z.x >= 0.0) {
        return vec2<f32>(t1, t2);
    }
    return vec2<f32>(abs(t2), select(-t1, t1, z.y >= 0.0));
}

// A conductor with complex index eta + i k (pbrt-v4 FrComplex, eq. 9.6 with complex eta):
// cos th_t = sqrt(1 - sin^2 th / eta^2), r_parl = (eta c - cos th_t) / (eta c + cos th_t),
// r_perp = (c - eta cos th_t) / (c + eta cos th_t), F = (|r_parl|^2 + |r_perp|^2) / 2.
/// A conductor's reflectance at cos θi = c, complex index η + ik.
fn fresnel_conductor(c: f32, eta: f32, k: f32) -> f32 {
    let ci = clamp(c, 0.0, 1.0);
    let e = vec2<f32>(eta, k);
    let sin2_t = complex_div(vec2<f32>(1.0 - ci * ci, 0.0), complex_mul(e, e));
    let ct = complex_sqrt(vec2<f32>(1.0, 0.0) - sin2_t);
    let ec = e * ci;
    let r_parl = complex_div(ec - ct, ec + ct);
    let ect = complex_mul(e, ct);
    let r_perp = complex_div(vec2<f32>(ci, 0.0) - ect, vec2<f32>(ci, 0.0) + ect);
    return 0.5 * (dot(r_parl, r_parl) + dot(r_perp, r_perp));
}
