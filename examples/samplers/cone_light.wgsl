// A sphere light as renderers sample it from a shading point outside it: directions uniform in
// the cone that the sphere subtends (pbrt-v4 §6.2.4, "Sampling the cone of directions"), the
// cone of half-angle ρ about the direction (θ, φ) = (p0, p1) in radians, sin ρ = p2 (the
// sphere's radius over its distance). Uniform in solid angle: pdf = 1 / (2π (1 − cos ρ)).
// 1 − cos is taken in the stable form 2 sin²(ρ/2) = sin²ρ / (1 + cos ρ), and a direction's
// 1 − cos θ′ about the axis as |d × n|² / (1 + d·n): 1 − cos itself has no digit left in f32
// for a cone of 10⁻³ rad.

fn cone_axis(params: array<vec4<f32>, 4>) -> vec3<f32> {
    let t = params[0].x;
    let p = params[0].y;
    return vec3<f32>(sin(t) * cos(p), sin(t) * sin(p), cos(t));
}

// 1 − cos ρ from sin ρ.
fn cone_height(params: array<vec4<f32>, 4>) -> f32 {
    let s = params[0].z;
    return s * s / (1.0 + sqrt(max(0.0, 1.0 - s * s)));
}

// An orthonormal frame about n (Duff et al. 2017, JCGT 6(1), listing 3).
fn cone_frame(n: vec3<f32>) -> mat3x3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return mat3x3<f32>(vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), vec3<f32>(b, sign + n.y * n.y * a, -n.y), n);
}

fn cone_pdf_value(params: array<vec4<f32>, 4>) -> f32 {
    return 1.0 / (6.28318530717959 * cone_height(params));
}

// (d, pdf): 1 − cos θ′ = u.x (1 − cos ρ), φ′ = 2π u.y.
fn cone_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let a = u.x * cone_height(params);
    let s = sqrt(max(0.0, a * (2.0 - a)));
    let phi = 6.28318530717959 * u.y;
    let d = cone_frame(cone_axis(params)) * vec3<f32>(s * cos(phi), s * sin(phi), 1.0 - a);
    return vec4<f32>(d, cone_pdf_value(params));
}

fn cone_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let n = cone_axis(params);
    let z = dot(d, n);
    let c = cross(d, n);
    if (z <= 0.0 || dot(c, c) / (1.0 + z) > cone_height(params)) {
        return 0.0;
    }
    return cone_pdf_value(params);
}

// Broken: 1 − cos ρ in the naive form, 1 − √(1 − sin²ρ), which loses its digits for a small cone
// (at ρ = 10⁻³ it is 0 in f32, at 10⁻² off by 2 %): the samples' cone and the pdf are wrong.
fn cone_sample_naive(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let s2 = params[0].z * params[0].z;
    let h = 1.0 - sqrt(1.0 - s2);
    let a = u.x * h;
    let s = sqrt(max(0.0, a * (2.0 - a)));
    let phi = 6.28318530717959 * u.y;
    let d = cone_frame(cone_axis(params)) * vec3<f32>(s * cos(phi), s * sin(phi), 1.0 - a);
    return vec4<f32>(d, 1.0 / (6.28318530717959 * h));
}

// Broken: a 5 % warp of the radial coordinate inside the cone (u.x^1.05), its pdf unchanged.
fn cone_sample_warped(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    return cone_sample(wi, vec4<f32>(pow(u.x, 1.05), u.y, u.z, u.w), params);
}
