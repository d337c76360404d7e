// BROKEN on purpose (give after beckmann_vndf.wgsl): the visible-normal pdf with the rational
// approximation of the Beckmann G1 that Mitsuba 3.9.1 uses (microfacet.h, smith_g1: "a fast and
// accurate (<0.35% rel. error) rational approximation"; Walter et al. 2007, eq. 27):
//   G1 ≈ (3.535 a + 2.181 a²) / (1 + 2.276 a + 2.577 a²) for a < 1.6, else 1.
// The samples are exact; the pdf is off by up to 0.35% near grazing incidence. A χ² test sees
// it only with enough samples: `lobes check --power` shows from how many.

fn mitsuba_g1(w: vec3<f32>, a: vec2<f32>) -> f32 {
    let s = length(vec2<f32>(a.x * w.x, a.y * w.y));
    if (s == 0.0) {
        return 1.0;
    }
    let b = w.z / s;
    if (b >= 1.6) {
        return 1.0;
    }
    return (3.535 * b + 2.181 * b * b) / (1.0 + 2.276 * b + 2.577 * b * b);
}

fn mitsuba_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return beck_pdf_with(wi, d, params[0].xy, mitsuba_g1(wi, params[0].xy));
}

fn mitsuba_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let s = beck_sample(wi, u, params);
    return vec4<f32>(s.xyz, mitsuba_pdf(wi, s.xyz, params));
}
