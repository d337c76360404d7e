// A diffuse sampler that reports the wrong pdf with its samples, for tests/sampler.rs: cos² θ/π
// (1 − r², the square of z, where z = √(1 − r²) was meant), while diffuse_pdf(d) is right. The
// samples follow cos θ/π, so the histogram agrees with the pdf function; only the pdf the
// renderer divides by is wrong. Composed after shaders/diffuse.wgsl.

fn squared_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let s = diffuse_sample(wi, u, params);
    return vec4<f32>(s.xyz, s.z * s.w);
}
