// A diffuse sampler whose samples are off by a fraction of a percent, for tests/sampler.rs: u.x
// is bent by u ↦ u + 4ε u (1 − u) before the concentric map, so the density of the samples is
// cos θ/π divided by 1 + 4ε (1 − 2u), off by up to ±4ε = ±0.4 % with ε = 10⁻³, while the sampler
// still reports cos θ/π. (A bent table, a slightly wrong polynomial fit, an f32 shortcut in
// the sampling routine do this.) Composed after shaders/diffuse.wgsl.

const SKEWED_EPS: f32 = 1e-3;

fn skewed_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let x = u.x + 4.0 * SKEWED_EPS * u.x * (1.0 - u.x);
    return diffuse_sample(wi, vec4<f32>(x, u.yzw), params);
}
