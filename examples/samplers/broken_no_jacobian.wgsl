// BROKEN on purpose (give after ggx_vndf.wgsl): the density of the half vector reported as the
// density of the reflected direction, i.e. without the reflection Jacobian 1/(4 |d·h|) of
// p(d) = D_wi(h) / (4 |d·h|). `lobes check` must reject it (chi2, jacobian).

fn broken_pdf_no_jacobian(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let m = wi + d;
    if (wi.z <= 0.0 || dot(m, m) == 0.0) {
        return 0.0;
    }
    let h = normalize(m);
    return ggx_pdf(wi, d, params) * 4.0 * abs(dot(d, h));
}

fn broken_sample_no_jacobian(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let s = ggx_sample(wi, u, params);
    return vec4<f32>(s.xyz, broken_pdf_no_jacobian(wi, s.xyz, params));
}
