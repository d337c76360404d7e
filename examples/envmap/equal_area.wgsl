// An environment map stored as an octahedral equal-area square of N × N texels (Clarberg 2008,
// the layout of pbrt-v4's ImageInfiniteLight), sampled as renderers sample it: a texel chosen in
// proportion to its weight, a point uniform in it, mapped to the sphere by the equal-area map,
// whose Jacobian is constant (dω = 4π du dv). A direction's density is then w / Σw · N² / 4π.
// The weights are integers given in closed form (a sky brighter towards the horizon and a sun of
// two texels) so that the file stands alone; params[0].x is their sum, Σw = 825 for N = 16
// (docs/lights-and-environment-maps.md computes it).

const EA_N: u32 = 16u;
const EA_PI: f32 = 3.14159265358979;

// The weight of texel (column i, row j): 40 at the sun, else 1 to 4 from the texel's centre's
// L¹ distance from the square's centre (0 at +z, 1 on the horizon, 2 at −z), plus a ripple.
fn ea_weight(i: u32, j: u32) -> f32 {
    if (j == 5u && (i == 11u || i == 12u)) {
        return 40.0;
    }
    let c = abs(vec2<f32>(f32(i), f32(j)) + 0.5 - 0.5 * f32(EA_N)) * (2.0 / f32(EA_N));
    let band = 3u - min(u32(abs(c.x + c.y - 1.0) * 3.0), 2u);
    return f32(band + (i + 2u * j) % 2u);
}

// The interval of a running sum that holds `goal`, over the weights of row j (`row` true:
// column i's weight at step i) or over the rows' sums (row sums at step j): (the step, the
// fraction of its interval below goal), as pbrt's PiecewiseConstant2D draws a row by its
// marginal and then a column by the row's conditional, each uniform remapped into its interval.
fn ea_find(goal: f32, row: bool, j: u32) -> vec2<f32> {
    var below = 0.0;
    for (var k = 0u; k < EA_N; k++) {
        var w = 0.0;
        if (row) {
            w = ea_weight(k, j);
        } else {
            for (var i = 0u; i < EA_N; i++) {
                w += ea_weight(i, k);
            }
        }
        if (goal < below + w || k == EA_N - 1u) {
            return vec2<f32>(f32(k), clamp((goal - below) / w, 0.0, 1.0));
        }
        below += w;
    }
    return vec2<f32>(0.0);
}

// The texel (column, row) and the point in it of the uniforms (u.x for the column, u.y for the
// row).
fn ea_texel(u: vec4<f32>, total: f32) -> vec4<f32> {
    let row = ea_find(u.y * total, false, 0u);
    var row_sum = 0.0;
    for (var i = 0u; i < EA_N; i++) {
        row_sum += ea_weight(i, u32(row.x));
    }
    let col = ea_find(u.x * row_sum, true, u32(row.x));
    return vec4<f32>(col.x, row.x, col.y, row.y);
}

// (u, v) ∈ [0, 1]² to the sphere: in c = 2 (u, v) − 1, r = 1 − |1 − |c.x| − |c.y||, z = ±(1 − r²)
// (+ inside the diamond |c.x| + |c.y| ≤ 1), φ = (π/4) ((|c.y| − |c.x|) / r + 1) in the quadrant
// of c's signs, and the direction's length across z r √(2 − r²).
fn ea_square_to_sphere(p: vec2<f32>) -> vec3<f32> {
    let c = 2.0 * p - 1.0;
    let a = abs(c);
    let inside = 1.0 - (a.x + a.y);
    let r = 1.0 - abs(inside);
    let phi = select((a.y - a.x) / r + 1.0, 1.0, r == 0.0) * 0.25 * EA_PI;
    let z = select(r * r - 1.0, 1.0 - r * r, inside >= 0.0);
    let k = r * sqrt(max(0.0, 2.0 - r * r));
    return vec3<f32>(select(1.0, -1.0, c.x < 0.0) * cos(phi) * k, select(1.0, -1.0, c.y < 0.0) * sin(phi) * k, z);
}

// The inverse: r = √(1 − |z|), the quadrant's angle as a fraction f = (2/π) atan2(|y|, |x|),
// (|c.x|, |c.y|) = (r (1 − f), r f) inside the diamond, mirrored across its edge for z < 0.
fn ea_sphere_to_square(d: vec3<f32>) -> vec2<f32> {
    let a = abs(d);
    let r = sqrt(max(0.0, 1.0 - a.z));
    let f = atan2(a.y, a.x) * (2.0 / EA_PI);
    var c = vec2<f32>(r * (1.0 - f), r * f);
    if (d.z < 0.0) {
        c = vec2<f32>(1.0 - c.y, 1.0 - c.x);
    }
    c = vec2<f32>(select(1.0, -1.0, d.x < 0.0), select(1.0, -1.0, d.y < 0.0)) * c;
    return 0.5 * (c + 1.0);
}

// The density per solid angle of texel (i, j).
fn ea_density(i: u32, j: u32, total: f32) -> f32 {
    return ea_weight(i, j) / total * f32(EA_N * EA_N) / (4.0 * EA_PI);
}

fn ea_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let p = ea_sphere_to_square(d);
    let i = min(u32(p.x * f32(EA_N)), EA_N - 1u);
    let j = min(u32(p.y * f32(EA_N)), EA_N - 1u);
    return ea_density(i, j, params[0].x);
}

fn ea_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let c = ea_texel(u, params[0].x);
    let p = (c.xy + c.zw) / f32(EA_N);
    return vec4<f32>(ea_square_to_sphere(p), ea_density(u32(c.x), u32(c.y), params[0].x));
}

// Broken: the texel's point mapped by the octahedral map that encodes normals (Cigolle et al.
// 2014: the octahedron |x| + |y| + |z| = 1 normalised), which is not equal-area: each texel is
// chosen with its right probability, but the region it maps to is not the map's texel and the
// density within it is not constant.
fn ea_sample_octahedral(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let t = ea_texel(u, params[0].x);
    let c = 2.0 * (t.xy + t.zw) / f32(EA_N) - 1.0;
    var d = vec3<f32>(c, 1.0 - abs(c.x) - abs(c.y));
    if (d.z < 0.0) {
        d = vec3<f32>((1.0 - abs(c.yx)) * select(vec2<f32>(1.0), vec2<f32>(-1.0), c < vec2<f32>(0.0)), d.z);
    }
    return vec4<f32>(normalize(d), ea_density(u32(t.x), u32(t.y), params[0].x));
}

// Broken: the texel's column and row swapped where its point is placed (the pdf is the chosen
// texel's).
fn ea_sample_transposed(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let c = ea_texel(u, params[0].x);
    let p = (c.yx + c.zw) / f32(EA_N);
    return vec4<f32>(ea_square_to_sphere(p), ea_density(u32(c.x), u32(c.y), params[0].x));
}
