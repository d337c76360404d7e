#define_import_path lobes::beckmann_eval
#import lobes::math::math_exp
#import lobes::reflect::reflection_half_vector
#import lobes::beckmann::{beckmann_d, beckmann_g1_over_cos}
#import lobes::erf::{INV_SQRT_PI, math_erfc}
#import lobes::microfacet_eval::{microfacet_eval, microfacet_pdf_ndf, microfacet_pdf_vndf}
//! embed: beckmann

// Beckmann densities and BRDF for renderers that embed lobes' samplers (lobes::embed,
// Module::Beckmann); CPU twins: src/reference/beckmann.rs and src/reference/microfacet.rs.
// a = (alpha_x, alpha_y); wi, wr unit vectors in the local frame (normal +z), pointing away.
// Every density is per unit solid angle of wr and is 0 for wr at or below the horizon and for
// wi below it (light from below the surface is not reflected).

// Smith's Lambda (Heitz 2014, eq. 72): -erfc(x)/2 + exp(-x^2) / (2 x sqrt(pi)),
// x = |wz| / |(ax wx, ay wy)|; 0 past x = 10 (where it is below 1e-45).
/// Smith's Λ(w) for Beckmann (Heitz 2014, eq. 72).
fn beckmann_lambda(a: vec2<f32>, w: vec3<f32>) -> f32 {
    let l = length(a * w.xy);
    let c = abs(w.z);
    if (c > 10.0 * l) {
        return 0.0;
    }
    let x = c / l;
    return -0.5 * math_erfc(x) + math_exp(-x * x) * INV_SQRT_PI / (2.0 * x);
}

/// Height-correlated Smith G2 = 1 / (1 + Lambda(wi) + Lambda(wr)) (Heitz 2014, eq. 99).
fn beckmann_g2(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    return 1.0 / (1.0 + beckmann_lambda(a, wi) + beckmann_lambda(a, wr));
}

// f(wi, wr) = D(h) G2(wi, wr) / (4 cos th_i cos th_r), without Fresnel (microfacet_eval).
/// The BRDF D(h) G2(ωi, ωr) / (4 cos θi cos θr), without Fresnel.
fn beckmann_eval(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let h = normalize(wi + wr);
    return microfacet_eval(beckmann_d(a, h), beckmann_g2(a, wi, wr), wi, wr);
}

/// The density of wr under beckmann_sample_ndf: D(h) cos th_h / (4 |wr.h|) (microfacet_pdf_ndf).
fn beckmann_pdf_ndf(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let h = reflection_half_vector(wi, wr);
    return microfacet_pdf_ndf(beckmann_d(a, h), wr, h);
}

// The density of wr under beckmann_sample_vndf (microfacet_pdf_vndf), with G1 / cos th_i in its
// grazing-stable form (beckmann_g1_over_cos).
/// The density of ωr under beckmann_sample_vndf.
fn beckmann_pdf_vndf(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let h = reflection_half_vector(wi, wr);
    return microfacet_pdf_vndf(beckmann_g1_over_cos(a, wi), beckmann_d(a, h), wi, wr, h);
}

/// Smith's G1(w) = cos th (G1 / cos th), in the form that stays finite at grazing angles.
fn beckmann_g1(a: vec2<f32>, w: vec3<f32>) -> f32 {
    return abs(w.z) * beckmann_g1_over_cos(a, w);
}

// The estimator weight f cos th_r / p(wr) of beckmann_sample_vndf for f = D / (4 cos th_i cos th_r)
// (no Fresnel, no masking): with p(wr) = G1(wi) D / (4 cos th_i) it is 1 / G1(wi).
/// The estimator weight f cos θr / p(ωr) of beckmann_sample_vndf without Fresnel and masking:
/// 1 / G1(ωi).
fn beckmann_vndf_weight(a: vec2<f32>, wi: vec3<f32>) -> f32 {
    return 1.0 / beckmann_g1(a, wi);
}
