#define_import_path lobes::domain
#import lobes::params::lobes_params

// The plane's box as the domain of `lobes check`'s passes (src/stats/domain.rs, Domain::Plane:
// the CPU twin of each function here); the sphere's twin is domain_sphere.wgsl, which says what
// each function is for.

// The point (a, b) of a quadrature rectangle (its coordinates are x and y; h and k are the
// sphere's).
fn lobes_domain_point(a: f32, b: f32, h: f32, k: u32) -> vec3<f32> {
    return vec3<f32>(a, b, 0.0);
}

// A sample's point as the domain reads it: (x, y); the sampler's z is not part of it.
fn lobes_domain_coordinates(p: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(p.xy, 0.0);
}

// The bin of a finite sample point, or LOBES_DOMAIN_OUTSIDE outside the box (its far edges in the
// last row and column): rows uniform in y, columns in x, over the bounds.
fn lobes_domain_cell(p: vec3<f32>) -> u32 {
    let lo = lobes_params.bounds.xy;
    let hi = lobes_params.bounds.zw;
    if (any(p.xy < lo) || any(p.xy > hi)) {
        return LOBES_DOMAIN_OUTSIDE;
    }
    let t = (p.xy - lo) / (hi - lo);
    let col = min(u32(t.x * f32(lobes_params.cols)), lobes_params.cols - 1u);
    let row = min(u32(t.y * f32(lobes_params.rows)), lobes_params.rows - 1u);
    return row * lobes_params.cols + col;
}

// What lobes_domain_cell returns for a point outside the domain.
const LOBES_DOMAIN_OUTSIDE: u32 = 0xffffffffu;
