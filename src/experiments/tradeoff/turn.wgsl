// The detection table's defect (lobes tradeoff, src/experiments/tradeoff/detection.rs): GGX by
// visible normals (examples/samplers/ggx_vndf.wgsl, params[0].xy = α) whose directions are
// turned about the normal by ε sin φ, ε = params[0].z radians; at ε = 0.005 it is also the
// panel's turn (tests/family.rs, tests/power.rs, bench/family_panel.py). The map
// φ ↦ φ + ε sin φ has Jacobian 1 + ε cos φ: the density is off by about ε cos φ, smoothly in φ,
// while the reported pdf is the pdf at the returned direction (pdf_consistency holds) and
// pdf · |J| is off by up to ε: under the jacobian check's pointwise 1 % for ε < 0.01, but over
// its systematic test's 0.1 % at most probes (docs/statistics.md). ε = 0 is the correct sampler.

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
