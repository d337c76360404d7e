#define_import_path lobes::domain
#import lobes::params::lobes_params
#import lobes::bins::{lobes_half_by_sign, lobes_sphere_column, lobes_quadrant_direction}

// The texels of a latitude–longitude map as the domain of `lobes check`'s passes
// (src/stats/domain.rs, Domain::LatLong: the CPU twin of each function here;
// domain_sphere.wgsl says what each function is for). Rows are uniform in θ ∈ [0, π] from +z
// (v = θ/π, row 0 at θ = 0), columns in φ = atan2(y, x) over [−π, π) as the sphere's (u = (φ +
// π)/2π): with the grid the map's texels, every cell is a texel.

// The direction at coordinates (a, b) of a quadrature rectangle, as on the sphere.
fn lobes_domain_point(a: f32, b: f32, h: f32, k: u32) -> vec3<f32> {
    return lobes_quadrant_direction(a, b, h, k);
}

// A sample's point as the domain reads it: a direction, all three components.
fn lobes_domain_coordinates(p: vec3<f32>) -> vec3<f32> {
    return p;
}

// The texel of a finite sample point, or LOBES_DOMAIN_OUTSIDE where it is not a unit direction
// (within 10⁻³): the row ⌊θ/π · rows⌋ with θ = atan2(√(x² + y²), z) (acos(z) loses half of
// f32's digits at the poles), kept in the northern half of the rows for z ≥ 0 and the southern
// for z < 0 where the rows are even (the equator is then a row edge, placed by the sign of z);
// the column as the sphere's (shaders/lib/bins.wgsl).
fn lobes_domain_cell(p: vec3<f32>) -> u32 {
    if (abs(length(p) - 1.0) > 1e-3) {
        return LOBES_DOMAIN_OUTSIDE;
    }
    let rows = lobes_params.rows;
    let theta = atan2(length(p.xy), p.z);
    let row_t = min(u32(max(theta, 0.0) * (1.0 / 3.14159265358979) * f32(rows)), rows - 1u);
    let row = lobes_half_by_sign(row_t, rows, p.z >= 0.0);
    let col = lobes_sphere_column(p.x, p.y, lobes_params.cols);
    return row * lobes_params.cols + col;
}

// What lobes_domain_cell returns for a point outside the domain.
const LOBES_DOMAIN_OUTSIDE: u32 = 0xffffffffu;
