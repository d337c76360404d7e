#define_import_path lobes::microfacet
#import lobes::math::Real
//! embed: microfacet
//! What the microfacet lobes share: the stretch to α = 1, and the BRDF and densities of a lobe
//! from its D and G terms.

// Shared microfacet helpers; CPU twin: src/reference/microfacet.rs.

/// normalize(ax wx, ay wy, wz): w stretched to the alpha = 1 configuration (Heitz 2018, listing 1).
fn stretch(a: vec2<Real>, w: vec3<Real>) -> vec3<Real> {
    return normalize(vec3<Real>(a * w.xy, w.z));
}

// The estimator weight f cos th_r / p(wr) of NDF sampling (h drawn with density D(h) cos th_h)
// for f = D / (4 cos th_i cos th_r), before Fresnel and masking: with p(wr) = D cos th_h / (4 |wr.h|),
// it is (wi.h) / (cos th_i cos th_h); 0 for a back-facing h (wi.h <= 0), which f excludes.
/// The estimator weight f cos θr / p(ωr) of NDF sampling, before Fresnel and masking:
/// (ωi·h) / (cos θi cos θh).
fn microfacet_ndf_weight(wi: vec3<Real>, h: vec3<Real>) -> Real {
    return max(dot(wi, h), 0.0) / (wi.z * h.z);
}
