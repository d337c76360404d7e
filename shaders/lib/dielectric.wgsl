#define_import_path lobes::dielectric
#import lobes::math::Real
#import lobes::reflect::{LobeSample, reflect_about}
#import lobes::fresnel::{fresnel_cos_transmitted, fresnel_dielectric, fresnel_dielectric_transmittance}
#import lobes::ggx::{ggx_d, ggx_sample_ndf, ggx_sample_vndf}
#import lobes::beckmann::{beckmann_d, beckmann_g1_over_cos, beckmann_sample_ndf, beckmann_sample_vndf_h}
//! embed: dielectric
//! The rough dielectric (Walter, Marschner, Li & Torrance 2007) on GGX or Beckmann, reflection
//! and refraction, light from either side; `eta` = η below / η above. Samplers take
//! `(a, wi, u: vec3<f32>, eta)`, densities and BSDFs `(a, wi, wo, eta)`.

// The rough dielectric (Walter, Marschner, Li & Torrance 2007); f64 twin:
// src/reference/dielectric.rs (RoughDielectric::sample), whose module notes give the equations.
// eta = eta_below / eta_above. Light from inside (wi.z < 0) is mirrored in the tangent plane
// (z -> -z) with 1/eta, sampled on the upper side and mirrored back. u.xy draw h with the lobe's
// sampler, u.z chooses reflection (u.z < F) or refraction. The returned LobeSample holds the
// scattered direction in `wr` and its density in `pdf_r`: 0 for a sample on the wrong side of its
// event (a reflection through the surface, a refraction that stays on the incident side).

// dw_h/dw_t of Walter 2007, eq. 17, as eta^2 ct (c + eta ct)^2 / (1 - eta^2)^2: the denominator
// c - eta ct vanishes as eta -> 1 and is formed as a quotient instead
// (reference::dielectric::jacobian_transmitted).
fn dielectric_jacobian_t(c: Real, ct: Real, eta: Real) -> Real {
    let s = c + eta * ct;
    let k = (1.0 - eta) * (1.0 + eta);
    return eta * eta * ct * s * s / (k * k);
}

// wi on its upper side: (x, y, |z|).
fn dielectric_upper(wi: vec3<Real>) -> vec3<Real> {
    return vec3<Real>(wi.xy, abs(wi.z));
}

// Scatters wi (either side) about h, drawn with density pdf_h for dielectric_upper(wi): reflection
// with probability F, refraction otherwise, as RoughDielectric::sample.
fn dielectric_scatter(wi: vec3<Real>, h: vec3<Real>, pdf_h: Real, u: Real, eta_outside: Real) -> LobeSample {
    let flip = wi.z < 0.0;
    let i = dielectric_upper(wi);
    let eta = select(eta_outside, 1.0 / eta_outside, flip);
    let c = dot(i, h);
    let ct = fresnel_cos_transmitted(min(c, 1.0), eta);
    let f = fresnel_dielectric(c, eta);
    var o: vec3<Real>;
    var pdf: Real;
    var on_its_side: bool;
    if (c <= 0.0 || ct < 0.0 || u < f) {
        o = reflect_about(i, h);
        pdf = f * pdf_h / (4.0 * abs(dot(o, h)));
        on_its_side = o.z > 0.0;
    } else {
        o = (c / eta - ct) * h - i / eta;
        pdf = fresnel_dielectric_transmittance(c, eta) * pdf_h * dielectric_jacobian_t(c, -dot(o, h), eta);
        on_its_side = o.z < 0.0;
    }
    let m = select(Real(1.0), Real(-1.0), flip);
    return LobeSample(vec3<Real>(h.xy, h.z * m), vec3<Real>(o.xy, o.z * m), select(0.0, pdf, on_its_side));
}

// The samplers: h by the lobe's own sampler for the upper-side wi, p(h) as its f64 twin's pdf_h.

// u.xy for the h draw, at least 2^-25 (reference::dielectric::U_FLOOR): the RNG's u = 0 (one value
// of its lattice k 2^-24, probability 2^-24) draws Beckmann's visible slope at -infinity, an h on
// the horizon with D(h) = 0, and a refraction about it would have no density at all (a zero_pdf
// sample that the expected counts cannot hold). Half a lattice step moves that atom to a
// direction of positive density; every other u is unchanged.
fn dielectric_u(u: vec3<Real>) -> vec2<Real> {
    return max(u.xy, vec2<Real>(2.98023223876953125e-8));
}

// p(h) of each sampler for the upper-side i, as its f64 twin's pdf_h (also the densities of
// shaders/lib/dielectric_eval.wgsl). NDF: D(h) cos th_h.
fn dielectric_ggx_ndf_pdf_h(a: vec2<Real>, i: vec3<Real>, h: vec3<Real>) -> Real {
    return ggx_d(a, h) * h.z;
}

// Visible normals: G1(i) max(0, i.h) D(h) / i.z, with G1/i.z = 2 / (i.z + t) (shaders/lib/ggx.wgsl).
fn dielectric_ggx_vndf_pdf_h(a: vec2<Real>, i: vec3<Real>, h: vec3<Real>) -> Real {
    let t = length(vec3<Real>(a * i.xy, i.z));
    return 2.0 * max(dot(i, h), 0.0) * ggx_d(a, h) / (i.z + t);
}

fn dielectric_beckmann_ndf_pdf_h(a: vec2<Real>, i: vec3<Real>, h: vec3<Real>) -> Real {
    return beckmann_d(a, h) * h.z;
}

fn dielectric_beckmann_vndf_pdf_h(a: vec2<Real>, i: vec3<Real>, h: vec3<Real>) -> Real {
    return beckmann_g1_over_cos(a, i) * max(dot(i, h), 0.0) * beckmann_d(a, h);
}

/// A scattered direction of the rough dielectric on GGX, h from the NDF: u.xy draw h, u.z
/// chooses reflection (u.z < F) or refraction; `pdf_r` is 0 for a sample on the wrong side of
/// its event.
fn dielectric_ggx_ndf(a: vec2<Real>, wi: vec3<Real>, u: vec3<Real>, eta: Real) -> LobeSample {
    let i = dielectric_upper(wi);
    let h = ggx_sample_ndf(a, i, dielectric_u(u)).h;
    return dielectric_scatter(wi, h, dielectric_ggx_ndf_pdf_h(a, i, h), u.z, eta);
}

/// The same with h from GGX's visible normals.
fn dielectric_ggx_vndf(a: vec2<Real>, wi: vec3<Real>, u: vec3<Real>, eta: Real) -> LobeSample {
    let i = dielectric_upper(wi);
    let h = ggx_sample_vndf(a, i, dielectric_u(u)).h;
    return dielectric_scatter(wi, h, dielectric_ggx_vndf_pdf_h(a, i, h), u.z, eta);
}

/// The same on Beckmann, h from the NDF.
fn dielectric_beckmann_ndf(a: vec2<Real>, wi: vec3<Real>, u: vec3<Real>, eta: Real) -> LobeSample {
    let i = dielectric_upper(wi);
    let h = beckmann_sample_ndf(a, i, dielectric_u(u)).h;
    return dielectric_scatter(wi, h, dielectric_beckmann_ndf_pdf_h(a, i, h), u.z, eta);
}

/// The same on Beckmann, h from the visible normals.
fn dielectric_beckmann_vndf(a: vec2<Real>, wi: vec3<Real>, u: vec3<Real>, eta: Real) -> LobeSample {
    let i = dielectric_upper(wi);
    let h = beckmann_sample_vndf_h(a, i, dielectric_u(u));
    return dielectric_scatter(wi, h, dielectric_beckmann_vndf_pdf_h(a, i, h), u.z, eta);
}
