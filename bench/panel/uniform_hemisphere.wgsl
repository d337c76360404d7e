// The correct twin of tests/fixtures/family/broken_grazing_turn.wgsl, for bench/family_panel.py:
// directions uniform over the upper hemisphere, cos θ = u.x and φ = 2π u.y − π (Archimedes:
// cos θ uniform on [0, 1] gives equal solid angle per dz), density 1 / 2π.

const UNIFORM_PI: f32 = 3.14159265358979;

fn uniform_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return select(0.0, 0.5 / UNIFORM_PI, d.z > 0.0);
}

fn uniform_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let z = u.x;
    let r = sqrt(max(0.0, 1.0 - z * z));
    let phi = 2.0 * UNIFORM_PI * u.y - UNIFORM_PI;
    let d = vec3<f32>(r * cos(phi), r * sin(phi), z);
    return vec4<f32>(d, uniform_pdf(wi, d, params));
}
