#define_import_path lobes::domain
#import lobes::params::lobes_params
#import lobes::bins::{lobes_sphere_cell, lobes_quadrant_direction}

// The sphere as the domain of `lobes check`'s passes (src/stats/domain.rs, Domain::Sphere: the
// CPU twin of each function here). The plane's twin is domain_plane.wgsl; the host composes the
// one its sampler's domain names.

// The direction at coordinates (a, b) of a quadrature rectangle in hemisphere `h` and quadrant
// `k` (shaders/lib/bins.wgsl says how they are measured).
fn lobes_domain_point(a: f32, b: f32, h: f32, k: u32) -> vec3<f32> {
    return lobes_quadrant_direction(a, b, h, k);
}

// A sample's point as the domain reads it: a direction, all three components.
fn lobes_domain_coordinates(p: vec3<f32>) -> vec3<f32> {
    return p;
}

// The bin of a finite sample point, or LOBES_DOMAIN_OUTSIDE where it is not a unit direction
// (within 10⁻³): the sphere's grid (shaders/lib/bins.wgsl), as lobes bins its own lobes.
fn lobes_domain_cell(p: vec3<f32>) -> u32 {
    if (abs(length(p) - 1.0) > 1e-3) {
        return LOBES_DOMAIN_OUTSIDE;
    }
    return lobes_sphere_cell(p, lobes_params.rows, lobes_params.cols);
}

// What lobes_domain_cell returns for a point outside the domain.
const LOBES_DOMAIN_OUTSIDE: u32 = 0xffffffffu;
