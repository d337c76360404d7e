// A deliberately wrong diffuse pdf, for tests/sampler.rs: cos θ / (2π), the normalisation of a
// uniform hemisphere (1 / 2π) mixed up with the cosine's. The same wrong value is what the
// sampler reports, as when a renderer computes both from one helper, so the sampler and its pdf
// agree with each other and only the distribution of the samples shows the bug.
// Composed after shaders/diffuse.wgsl, whose functions it calls.

fn half_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return 0.5 * diffuse_pdf(wi, d, params);
}

fn half_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let s = diffuse_sample(wi, u, params);
    return vec4<f32>(s.xyz, 0.5 * s.w);
}
