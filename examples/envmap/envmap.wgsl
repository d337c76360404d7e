// A lat-long environment map sampled as renderers sample it (pbrt-v4's ImageInfiniteLight with a
// PiecewiseConstant2D): the texture, and CDF tables built from it on the CPU (make.py), bound
// where the renderer binds them. Texel (column i, row j) covers φ ∈ 2π [i, i+1)/W − π and
// θ ∈ π [j, j+1)/H; its weight is f = luminance · sin θ_centre. A point (u, v) of the unit
// square has density f / ∫f (p0 = ∫f over the square), and the direction θ = π v, φ = 2π u − π
// has density f / (∫f · 2π² sin θ) (dω = 2π² sin θ du dv for this map).

@group(0) @binding(0) var env_radiance: texture_2d<f32>;
// the rows' CDF, H + 1 values from 0 to 1
@group(0) @binding(1) var<storage, read> env_marginal: array<f32>;
// each row's CDF over its columns, H rows of W + 1 values
@group(0) @binding(2) var<storage, read> env_conditional: array<f32>;

const ENV_PI: f32 = 3.14159265358979;

fn env_luminance(c: vec4<f32>) -> f32 {
    return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
}

// f of texel (i, j).
fn env_weight(i: u32, j: u32) -> f32 {
    let h = f32(textureDimensions(env_radiance).y);
    return env_luminance(textureLoad(env_radiance, vec2<u32>(i, j), 0)) * sin(ENV_PI * (f32(j) + 0.5) / h);
}

// The interval k of the CDF cdf[first .. first + n] holding u: the largest k < n with
// cdf[first + k] ≤ u (binary search), as a marginal or a row's conditional.
fn env_find_marginal(n: u32, u: f32) -> u32 {
    var lo = 0u;
    var hi = n;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (env_marginal[mid] <= u) { lo = mid; } else { hi = mid; }
    }
    return lo;
}

fn env_find_conditional(first: u32, n: u32, u: f32) -> u32 {
    var lo = 0u;
    var hi = n;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (env_conditional[first + mid] <= u) { lo = mid; } else { hi = mid; }
    }
    return lo;
}

// The direction at (u, v) of the unit square.
fn env_direction(u: f32, v: f32) -> vec3<f32> {
    let theta = ENV_PI * v;
    let phi = 2.0 * ENV_PI * u - ENV_PI;
    return vec3<f32>(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
}

// The density per solid angle of a direction in texel (i, j) at sin θ = s.
fn env_density(i: u32, j: u32, s: f32, integral: f32) -> f32 {
    if (s <= 0.0) {
        return 0.0;
    }
    return env_weight(i, j) / (integral * 2.0 * ENV_PI * ENV_PI * s);
}

// (row j, fraction in it, column i, fraction in it) of the uniforms u.x (row), u.y (column),
// searching the conditional CDF of row `row_of(j)`.
fn env_cells(u: vec4<f32>, shift: u32) -> vec4<f32> {
    let dims = textureDimensions(env_radiance);
    let j = env_find_marginal(dims.y, u.x);
    let dv = (u.x - env_marginal[j]) / max(env_marginal[j + 1u] - env_marginal[j], 1e-30);
    let row = min(j + shift, dims.y - 1u) * (dims.x + 1u);
    let i = env_find_conditional(row, dims.x, u.y);
    let du = (u.y - env_conditional[row + i]) / max(env_conditional[row + i + 1u] - env_conditional[row + i], 1e-30);
    return vec4<f32>(f32(j), clamp(dv, 0.0, 1.0), f32(i), clamp(du, 0.0, 1.0));
}

fn env_sample_at(u: vec4<f32>, params: array<vec4<f32>, 4>, shift: u32, corners: bool, sin_jacobian: bool) -> vec4<f32> {
    let dims = vec2<f32>(textureDimensions(env_radiance));
    var c = env_cells(u, shift);
    if (corners) {
        c = vec4<f32>(c.x, 0.0, c.z, 0.0);
    }
    let v = (c.x + c.y) / dims.y;
    let uu = (c.z + c.w) / dims.x;
    let d = env_direction(uu, v);
    var s = sin(ENV_PI * v);
    if (!sin_jacobian) {
        s = 1.0;
    }
    return vec4<f32>(d, env_density(u32(c.z), u32(c.x), s, params[0].x));
}

fn env_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    return env_sample_at(u, params, 0u, false, true);
}

fn env_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let dims = textureDimensions(env_radiance);
    let s = length(d.xy);
    let theta = atan2(s, d.z);
    let phi = atan2(d.y, d.x);
    let j = min(u32(theta / ENV_PI * f32(dims.y)), dims.y - 1u);
    let i = min(u32((phi + ENV_PI) / (2.0 * ENV_PI) * f32(dims.x)), dims.x - 1u);
    return env_density(i, j, s, params[0].x);
}

// Broken: the density without the map's sin θ (a pdf per (u, v) scaled as if per solid angle).
fn env_sample_no_sin(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    return env_sample_at(u, params, 0u, false, false);
}

// Broken: the conditional CDF searched in the next row.
fn env_sample_wrong_row(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    return env_sample_at(u, params, 1u, false, true);
}

// Broken: every sample at its texel's corner.
fn env_sample_corners(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    return env_sample_at(u, params, 0u, true, true);
}
