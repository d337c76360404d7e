// The Henyey–Greenstein phase function, sampled exactly: a sphere sampler for `lobes check`.
// params[0].x = g ∈ (−1, 1), the mean cosine (g > 0 scatters forward). wi points away from the
// scattering point, towards where the light came from, so forward is −wi and cos θ = d·(−wi).
//   p(cos θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2})            (Henyey & Greenstein 1941)
// Sampling inverts the CDF of cos θ:
//   cos θ = (1 + g² − ((1 − g²) / (1 − g + 2g u))²) / (2g),  uniform for |g| < 10⁻³.

const HG_PI: f32 = 3.14159265358979;

fn hg_density(g: f32, cos_theta: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * HG_PI * denom * sqrt(denom));
}

// An orthonormal basis around the unit vector n (Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited", JCGT 6(1)).
fn hg_basis(n: vec3<f32>) -> mat3x3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return mat3x3<f32>(vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x), vec3<f32>(b, s + n.y * n.y * a, -n.y), n);
}

fn hg_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let g = params[0].x;
    var c = 1.0 - 2.0 * u.x;
    if (abs(g) >= 1e-3) {
        let t = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
        c = (1.0 + g * g - t * t) / (2.0 * g);
    }
    c = clamp(c, -1.0, 1.0);
    let s = sqrt(max(0.0, 1.0 - c * c));
    let phi = 2.0 * HG_PI * u.y;
    let d = hg_basis(-wi) * vec3<f32>(s * cos(phi), s * sin(phi), c);
    return vec4<f32>(d, hg_density(g, c));
}

fn hg_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return hg_density(params[0].x, clamp(dot(-wi, d), -1.0, 1.0));
}

// The phase function itself: weights are exactly 1 and the albedo is 1.
fn hg_eval(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return hg_pdf(wi, d, params);
}
