#define_import_path lobes::ward_eval
#import lobes::math::math_exp
#import lobes::reflect::{PI, reflection_half_vector}
#import lobes::ward::ward_pdf_h
//! embed: ward

// Ward's density and BRDF for renderers that embed lobes' samplers (lobes::embed, Module::Ward);
// CPU twin: src/reference/ward.rs (pdf_h through the reflection Jacobian, eval).
// a = (alpha_x, alpha_y); wi, wr unit vectors in the local frame (normal +z), pointing away.

/// Ward's BRDF with rho_s = 1 (Ward 1992, eq. 5a; Walter 2005, eq. 1):
/// exp(-(hx^2/ax^2 + hy^2/ay^2)/hz^2) / (4 pi ax ay sqrt(cos th_i cos th_r)).
fn ward_eval(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    if (wi.z <= 0.0 || wr.z <= 0.0) {
        return 0.0;
    }
    let h = normalize(wi + wr);
    let q = h.xy / a;
    return math_exp(-dot(q, q) / (h.z * h.z)) / (4.0 * PI * a.x * a.y * sqrt(wi.z * wr.z));
}

/// The density of wr under ward_sample: p(h) / (4 |wr.h|) (Walter 2005, eq. 9); 0 for wr at or
/// below the horizon and for wi below it.
fn ward_pdf(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let h = reflection_half_vector(wi, wr);
    if (h.z <= 0.0) {
        return 0.0;
    }
    return ward_pdf_h(a, h) / (4.0 * abs(dot(wr, h)));
}

// The estimator weight f cos th_r / p(wr) of ward_sample (rho_s = 1; Walter 2005, eq. 10):
// (h.wr) cos^3 th_h sqrt(cos th_r / cos th_i), |cos th_r| past the horizon; 0 for a back-facing
// h (wi.h <= 0), which the BRDF (h = normalize(wi + wr)) never produces.
/// The estimator weight f cos θr / p(ωr) of ward_sample (ρs = 1; Walter 2005, eq. 10).
fn ward_weight(wi: vec3<f32>, h: vec3<f32>, wr: vec3<f32>) -> f32 {
    return max(dot(wi, h), 0.0) * h.z * h.z * h.z * sqrt(abs(wr.z) / wi.z);
}
