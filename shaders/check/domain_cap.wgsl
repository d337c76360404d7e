#define_import_path lobes::domain
#import lobes::params::lobes_params
#import lobes::bins::{lobes_sphere_column, lobes_quadrant_direction}

// A spherical cap fitted around a small support as the domain of `lobes check`'s passes
// (src/stats/domain.rs, Domain::Cap: the CPU twin of each function here; domain_sphere.wgsl says
// what each function is for). The uniforms' `bounds` hold the cap's unit axis n (xyz) and its
// height h = 1 − cos ρ (w). Rows are uniform in a = 1 − cos θ′ over [0, h] and columns in φ′,
// both about n in the frame (t, b, n): every cell spans 2π h / (rows · cols) sr.

// The frame (t, b, n) of Duff et al. 2017, "Building an Orthonormal Basis, Revisited" (JCGT
// 6(1)), listing 3; Frame::of is its f64 twin.
fn lobes_cap_frame(n: vec3<f32>) -> mat3x3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return mat3x3<f32>(vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), vec3<f32>(b, sign + n.y * n.y * a, -n.y), n);
}

// The direction at (a, b) of a quadrature rectangle, as on the sphere (h = 1: the cap's axis is
// its pole, and b is φ′ measured from the local axis k quarter turns from t), turned into the
// cap's frame: the local direction's components across n keep their f32 resolution, so a cap of
// 10⁻³ rad is resolved to an ulp of its radius, not of 1.
fn lobes_domain_point(a: f32, b: f32, h: f32, k: u32) -> vec3<f32> {
    return lobes_cap_frame(lobes_params.bounds.xyz) * lobes_quadrant_direction(a, b, 1.0, k);
}

// A sample's point as the domain reads it: a direction, all three components.
fn lobes_domain_coordinates(p: vec3<f32>) -> vec3<f32> {
    return p;
}

// The bin of a finite sample point, or LOBES_DOMAIN_OUTSIDE where it is not a unit direction
// (within 10⁻³) or lies outside the cap: a = |p × n|² / (|p| (|p| + p·n)), the stable form of
// 1 − cos θ′ (which in f32 has no digit left for a cap of 10⁻³ rad), the column of (p·t, p·b) as
// the sphere's (shaders/lib/bins.wgsl).
fn lobes_domain_cell(p: vec3<f32>) -> u32 {
    let l = length(p);
    let f = lobes_cap_frame(lobes_params.bounds.xyz);
    let z = dot(p, f[2]);
    if (abs(l - 1.0) > 1e-3 || z <= 0.0) {
        return LOBES_DOMAIN_OUTSIDE;
    }
    let c = cross(p, f[2]);
    let a = dot(c, c) / (l * (l + z));
    let height = lobes_params.bounds.w;
    if (!(a <= height)) {
        return LOBES_DOMAIN_OUTSIDE;
    }
    let row = min(u32(a / height * f32(lobes_params.rows)), lobes_params.rows - 1u);
    let x = dot(p, f[0]);
    let y = dot(p, f[1]);
    let col = lobes_sphere_column(x, y, lobes_params.cols);
    return row * lobes_params.cols + col;
}

// What lobes_domain_cell returns for a point outside the domain.
const LOBES_DOMAIN_OUTSIDE: u32 = 0xffffffffu;
