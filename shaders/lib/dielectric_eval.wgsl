#define_import_path lobes::dielectric_eval
#import lobes::math::Real
#import lobes::fresnel::{fresnel_dielectric, fresnel_dielectric_transmittance}
#import lobes::ggx::{ggx_d, ggx_g1}
#import lobes::beckmann::{beckmann_d, beckmann_g1_over_cos}
#import lobes::dielectric::{dielectric_upper, dielectric_jacobian_t, dielectric_ggx_ndf_pdf_h, dielectric_ggx_vndf_pdf_h, dielectric_beckmann_ndf_pdf_h, dielectric_beckmann_vndf_pdf_h}
//! embed: dielectric

// The rough dielectric's density, BSDF and estimator weight (the weighted pass,
// shaders/passes/weighted.wgsl), as shaders/lib/dielectric.wgsl samples it; f64 twin:
// src/reference/dielectric.rs (RoughDielectric::pdf, eval, weight), whose module notes give the
// equations (Walter 2007, eqs. 14, 16, 17, 20, 21). wi, wo in the lobe's frame, either side;
// eta = eta_below / eta_above. Light from inside is mirrored to the upper side with 1/eta, as
// the sampler does. The BSDF here is without G: the weighted pass multiplies in the case's
// masking (shaders/passes/effect_masking.wgsl) from G1(wi) and G1(wo), which depend on |z| only.

// A pair (wi, wo) on the upper side: i, o, the microfacet normal h that connects them (h.z > 0)
// and eta seen from i; event 1 a reflection, 2 a refraction, 0 where no microfacet connects them.
struct DielectricPair {
    i: vec3<Real>,
    o: vec3<Real>,
    h: vec3<Real>,
    eta: Real,
    event: u32,
}

// RoughDielectric::connect: h = normalize(i + o) on the incident side (eq. 13), h ∝ i + eta o
// turned up across the surface (eq. 16), which Snell's law produces only with i.h > 0 > o.h.
fn dielectric_connect(wi: vec3<Real>, wo: vec3<Real>, eta_outside: Real) -> DielectricPair {
    let flip = wi.z < 0.0;
    let i = dielectric_upper(wi);
    let o = vec3<Real>(wo.xy, select(wo.z, -wo.z, flip));
    let eta = select(eta_outside, 1.0 / eta_outside, flip);
    var h = vec3<Real>(0.0, 0.0, 1.0);
    var event = 0u;
    if (o.z > 0.0) {
        h = normalize(i + o);
        event = select(0u, 1u, h.z > 0.0 && dot(i, h) > 0.0);
    } else if (o.z < 0.0) {
        let v = i + eta * o;
        let len = length(v);
        if (len > 0.0 && v.z != 0.0) {
            h = v / len * sign(v.z);
            event = select(0u, 2u, dot(i, h) > 0.0 && dot(o, h) < 0.0);
        }
    }
    return DielectricPair(i, o, h, eta, event);
}

// p(wo) from p(h) = pdf_h: F p(h) / (4 |o.h|) reflected (eq. 14), (1 - F) p(h) dw_h/dw_t
// refracted (eq. 17).
fn dielectric_pdf_of(p: DielectricPair, pdf_h: Real) -> Real {
    let c = dot(p.i, p.h);
    if (p.event == 1u) {
        return fresnel_dielectric(c, p.eta) * pdf_h / (4.0 * abs(dot(p.o, p.h)));
    }
    if (p.event == 2u) {
        return fresnel_dielectric_transmittance(c, p.eta) * pdf_h * dielectric_jacobian_t(c, -dot(p.o, p.h), p.eta);
    }
    return 0.0;
}

// The BSDF without G from d = D(h): F D / (4 |cos i| |cos o|) (eq. 20), and across the surface
// (1 - F) D c dw_h/dw_t / (|cos i| |cos o|) (eq. 21: |i.h| |o.h| eta^2 / (c + eta o.h)^2 is
// c dw_h/dw_t).
fn dielectric_eval_of(p: DielectricPair, d: Real) -> Real {
    let c = dot(p.i, p.h);
    let cos = p.i.z * abs(p.o.z);
    if (p.event == 1u) {
        return fresnel_dielectric(c, p.eta) * d / (4.0 * cos);
    }
    if (p.event == 2u) {
        return fresnel_dielectric_transmittance(c, p.eta) * d * c * dielectric_jacobian_t(c, -dot(p.o, p.h), p.eta) / cos;
    }
    return 0.0;
}

/// The BSDF on GGX without G (multiply by a masking term, e.g. masking_height_correlated_transmitted).
fn dielectric_ggx_eval(a: vec2<Real>, wi: vec3<Real>, wo: vec3<Real>, eta: Real) -> Real {
    let p = dielectric_connect(wi, wo, eta);
    return dielectric_eval_of(p, ggx_d(a, p.h));
}

/// The BSDF on Beckmann without G.
fn dielectric_beckmann_eval(a: vec2<Real>, wi: vec3<Real>, wo: vec3<Real>, eta: Real) -> Real {
    let p = dielectric_connect(wi, wo, eta);
    return dielectric_eval_of(p, beckmann_d(a, p.h));
}

// The densities of the four samplers of shaders/lib/dielectric.wgsl.
/// The density of ωo under dielectric_ggx_ndf.
fn dielectric_ggx_ndf_pdf(a: vec2<Real>, wi: vec3<Real>, wo: vec3<Real>, eta: Real) -> Real {
    let p = dielectric_connect(wi, wo, eta);
    return dielectric_pdf_of(p, dielectric_ggx_ndf_pdf_h(a, p.i, p.h));
}

/// The density of ωo under dielectric_ggx_vndf.
fn dielectric_ggx_vndf_pdf(a: vec2<Real>, wi: vec3<Real>, wo: vec3<Real>, eta: Real) -> Real {
    let p = dielectric_connect(wi, wo, eta);
    return dielectric_pdf_of(p, dielectric_ggx_vndf_pdf_h(a, p.i, p.h));
}

/// The density of ωo under dielectric_beckmann_ndf.
fn dielectric_beckmann_ndf_pdf(a: vec2<Real>, wi: vec3<Real>, wo: vec3<Real>, eta: Real) -> Real {
    let p = dielectric_connect(wi, wo, eta);
    return dielectric_pdf_of(p, dielectric_beckmann_ndf_pdf_h(a, p.i, p.h));
}

/// The density of ωo under dielectric_beckmann_vndf.
fn dielectric_beckmann_vndf_pdf(a: vec2<Real>, wi: vec3<Real>, wo: vec3<Real>, eta: Real) -> Real {
    let p = dielectric_connect(wi, wo, eta);
    return dielectric_pdf_of(p, dielectric_beckmann_vndf_pdf_h(a, p.i, p.h));
}

// The estimator weight f |cos th_o| / p(wo) without G, the same for both events (the event's
// probability F or 1 - F is in f and in p alike): by the NDF it is microfacet_ndf_weight
// (shaders/lib/microfacet.wgsl, unchanged by the mirror); by visible normals 1 / G1(wi), here
// with G1 of |wi.z| (ggx_vndf_weight's (wi.z + t) / (2 wi.z) is for wi above the surface only).
/// The estimator weight f |cos θo| / p(ωo) of dielectric_ggx_vndf without G: 1 / G1(|ωi|).
fn dielectric_ggx_vndf_weight(a: vec2<Real>, wi: vec3<Real>) -> Real {
    return 1.0 / ggx_g1(a, wi);
}

/// The same for dielectric_beckmann_vndf.
fn dielectric_beckmann_vndf_weight(a: vec2<Real>, wi: vec3<Real>) -> Real {
    return 1.0 / (abs(wi.z) * beckmann_g1_over_cos(a, wi));
}
