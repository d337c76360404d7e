// BROKEN on purpose (give after ggx_vndf.wgsl and ggx_diffuse_mixture.wgsl): the mixture's pdf
// with the weights fixed at ½ and ½ while the sampler chooses GGX with probability w =
// params[0].z. At w ≠ ½ the diffuse lobe's samples where GGX adds little come with the density
// ½ p_diffuse for (1 − w) p_diffuse. `lobes check` must reject it (jacobian, chi2).

fn broken_mix_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    var half = params;
    half[0].z = 0.5;
    return mix_pdf(wi, d, half);
}

fn broken_mix_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let s = mix_sample(wi, u, params);
    return vec4<f32>(s.xyz, select(0.0, broken_mix_pdf(wi, s.xyz, params), s.w > 0.0));
}
