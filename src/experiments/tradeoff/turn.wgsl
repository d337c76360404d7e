// The detection table's defect (lobes tradeoff, src/experiments/tradeoff/detection.rs): GGX by
// visible normals (examples/samplers/ggx_vndf.wgsl, params[0].xy = α) whose directions are
// turned about the normal by ε sin φ, ε = params[0].z radians, as
// tests/fixtures/family/broken_turn.wgsl does with ε = 0.005. The map φ ↦ φ + ε sin φ has
// Jacobian 1 + ε cos φ: the density is off by about ε cos φ, smoothly in φ, while the reported
// pdf is the pdf at the returned direction (pdf_consistency holds) and pdf · |J| is off by ε
// (under the jacobian check's 1 % for ε < 0.01). ε = 0 is the correct sampler.

fn turn_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return ggx_pdf(wi, d, params);
}

fn turn_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let s = ggx_sample(wi, u, params);
    if (s.w <= 0.0) {
        return s;
    }
    let t = params[0].z * sin(atan2(s.y, s.x));
    let c = cos(t);
    let n = sin(t);
    let d = vec3<f32>(c * s.x - n * s.y, n * s.x + c * s.y, s.z);
    return vec4<f32>(d, ggx_pdf(wi, d, params));
}
