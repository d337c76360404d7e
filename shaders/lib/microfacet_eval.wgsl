#define_import_path lobes::microfacet_eval
//! embed: microfacet

// The BRDF and the densities that every microfacet lobe forms alike from its own D(h) and G
// terms (shaders/lib/ggx_eval.wgsl, beckmann_eval.wgsl evaluate those and call these); CPU twin:
// src/reference/microfacet.rs. wi, wr unit vectors in the local frame (normal +z), pointing
// away; h the half vector of shaders/lib/reflect.wgsl reflection_half_vector (vec3(0) where
// wr is not counted).

/// f(wi, wr) = D(h) G2(wi, wr) / (4 cos th_i cos th_r), without Fresnel (Walter et al. 2007,
/// eq. 20), from d = D(h) and g2 = G2(wi, wr); 0 with either direction at or below the horizon.
fn microfacet_eval(d: f32, g2: f32, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    if (wi.z <= 0.0 || wr.z <= 0.0) {
        return 0.0;
    }
    return d * g2 / (4.0 * wi.z * wr.z);
}

/// The density of wr when h is drawn from the NDF, p(h) = D(h) cos th_h, through the reflection
/// Jacobian 1 / (4 |wr.h|) (Walter et al. 2007, eqs. 14 and 38), from d = D(h).
fn microfacet_pdf_ndf(d: f32, wr: vec3<f32>, h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    return d * h.z / (4.0 * abs(dot(wr, h)));
}

// The density of wr when h is drawn from the visible normals of wi, p(h) = G1(wi) max(0, wi.h)
// D(h) / cos th_i (Heitz 2014, eq. 38), through the same Jacobian, from g1_over_cos =
// G1(wi) / cos th_i (each lobe's grazing-stable form) and d = D(h).
/// The density of ωr when h is drawn from the visible normals of ωi (Heitz 2014, eq. 38),
/// from g1_over_cos = G1(ωi) / cos θi and d = D(h).
fn microfacet_pdf_vndf(g1_over_cos: f32, d: f32, wi: vec3<f32>, wr: vec3<f32>, h: vec3<f32>) -> f32 {
    let cos_ih = dot(wi, h);
    if (h.z <= 0.0 || cos_ih <= 0.0) {
        return 0.0;
    }
    return g1_over_cos * cos_ih * d / (4.0 * abs(dot(wr, h)));
}
