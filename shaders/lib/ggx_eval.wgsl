#define_import_path lobes::ggx_eval
#import lobes::reflect::reflection_half_vector
#import lobes::ggx::{ggx_bounded_one_minus_k, ggx_d}
#import lobes::microfacet_eval::{microfacet_eval, microfacet_pdf_ndf, microfacet_pdf_vndf}
//! embed: ggx

// GGX densities and BRDF for renderers that embed lobes' samplers (lobes::embed, Module::Ggx);
// CPU twins: src/reference/ggx.rs and src/reference/microfacet.rs (Lobe::pdf_r, Lobe::eval).
// a = (alpha_x, alpha_y); wi, wr unit vectors in the local frame (normal +z), pointing away.
// Every density is per unit solid angle of wr and is 0 for wr at or below the horizon and for
// wi below it (light from below the surface is not reflected).

/// Smith's Lambda (Heitz 2014, eq. 86): (|(ax wx, ay wy, wz)| / |wz| - 1) / 2.
fn ggx_lambda(a: vec2<f32>, w: vec3<f32>) -> f32 {
    return 0.5 * (length(vec3<f32>(a * w.xy, w.z)) / abs(w.z) - 1.0);
}

// Height-correlated Smith G2 = 1 / (1 + Lambda(wi) + Lambda(wr)) (Heitz 2014, eq. 99), formed
// from G1 = 1 / (1 + Lambda) as G1i G1r / (G1i + G1r - G1i G1r), finite at grazing angles.
/// Height-correlated Smith G2 = 1 / (1 + Λ(ωi) + Λ(ωr)) (Heitz 2014, eq. 99).
fn ggx_g2(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let gi = 2.0 * abs(wi.z) / (abs(wi.z) + length(vec3<f32>(a * wi.xy, wi.z)));
    let gr = 2.0 * abs(wr.z) / (abs(wr.z) + length(vec3<f32>(a * wr.xy, wr.z)));
    if (gi <= 0.0 || gr <= 0.0) {
        return 0.0;
    }
    return gi * gr / (gi + gr - gi * gr);
}

// f(wi, wr) = D(h) G2(wi, wr) / (4 cos th_i cos th_r), without Fresnel (microfacet_eval).
/// The BRDF D(h) G2(ωi, ωr) / (4 cos θi cos θr), without Fresnel.
fn ggx_eval(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let h = normalize(wi + wr);
    return microfacet_eval(ggx_d(a, h), ggx_g2(a, wi, wr), wi, wr);
}

/// The density of wr under ggx_sample_ndf: D(h) cos th_h / (4 |wr.h|) (microfacet_pdf_ndf).
fn ggx_pdf_ndf(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let h = reflection_half_vector(wi, wr);
    return microfacet_pdf_ndf(ggx_d(a, h), wr, h);
}

// The density of wr under ggx_sample_vndf (microfacet_pdf_vndf), with G1(wi) / cos th_i =
// 2 / (cos th_i + t), t = |(ax wi.x, ay wi.y, wi.z)|, which stays finite at grazing incidence.
/// The density of ωr under ggx_sample_vndf.
fn ggx_pdf_vndf(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let h = reflection_half_vector(wi, wr);
    let g1_over_cos = 2.0 / (wi.z + length(vec3<f32>(a * wi.xy, wi.z)));
    return microfacet_pdf_vndf(g1_over_cos, ggx_d(a, h), wi, wr, h);
}

// The density of wr under ggx_sample_bounded (Eto & Tokuyoshi 2023, listing 2):
// D(h) / (2 (k wi.z + t)).
/// The density of ωr under ggx_sample_bounded.
fn ggx_pdf_bounded(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let h = reflection_half_vector(wi, wr);
    if (h.z <= 0.0) {
        return 0.0;
    }
    // k as the sampler forms it (shaders/lib/ggx.wgsl, Eto & Tokuyoshi 2023 listing 1)
    let k = 1.0 - ggx_bounded_one_minus_k(a, wi);
    let t = length(vec3<f32>(a * wi.xy, wi.z));
    return ggx_d(a, h) / (2.0 * (k * wi.z + t));
}

// The estimator weight f cos th_r / p(wr) of ggx_sample_vndf for f = D / (4 cos th_i cos th_r)
// (no Fresnel, no masking): with p(wr) = D / (2 (cos th_i + t)) it is (cos th_i + t) / (2 cos th_i)
// = 1 / G1(wi), whatever the sample.
/// The estimator weight f cos θr / p(ωr) of ggx_sample_vndf without Fresnel and masking: 1 / G1(ωi).
fn ggx_vndf_weight(a: vec2<f32>, wi: vec3<f32>) -> f32 {
    let t = length(vec3<f32>(a * wi.xy, wi.z));
    return (wi.z + t) / (2.0 * wi.z);
}

// The same for ggx_sample_bounded, p(wr) = D / (2 (k cos th_i + t)) (Eto & Tokuyoshi 2023,
// listing 2): (k cos th_i + t) / (2 cos th_i).
/// The same for ggx_sample_bounded.
fn ggx_bounded_weight(a: vec2<f32>, wi: vec3<f32>) -> f32 {
    let k = 1.0 - ggx_bounded_one_minus_k(a, wi);
    let t = length(vec3<f32>(a * wi.xy, wi.z));
    return (k * wi.z + t) / (2.0 * wi.z);
}
