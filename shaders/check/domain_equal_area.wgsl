#define_import_path lobes::domain
#import lobes::params::lobes_params
#import lobes::bins::lobes_half_by_sign

// The texels of an octahedral equal-area map (Clarberg 2008; pbrt-v4's environment maps) as the
// domain of `lobes check`'s passes (src/stats/domain.rs, Domain::EqualArea; the CPU twin of each
// function is in src/stats/equal_area.rs; domain_sphere.wgsl says what each function is for).
// The unit square's centred coordinates (s, t) = (2u − 1, 2v − 1): the diamond |s| + |t| ≤ 1
// is the northern hemisphere, +z at its centre, the corner triangles the southern; columns along
// u, rows along v, each texel 4π / (rows · cols) sr.

const LOBES_SQRT_PI: f32 = 1.7724539;
const LOBES_HALF_PI: f32 = 1.5707964;

// (|s|, |t|) of a southern triangle folded onto the diamond across its edge: (u, v) → (1 − v,
// 1 − u), which keeps v − u and so φ.
fn lobes_equal_area_fold(q: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(1.0 - q.y, 1.0 - q.x);
}

// The direction at centred coordinates (s, t): r = |s| + |t| on the diamond, z = ±(1 − r²),
// ρ = r √(2 − r²), φ = (π/2) |t| / r with cos φ as sin((π/2) |s| / r). CPU twin:
// equal_area::square_to_sphere.
fn lobes_square_to_sphere(s: f32, t: f32) -> vec3<f32> {
    let north = abs(s) + abs(t) <= 1.0;
    let q = select(lobes_equal_area_fold(abs(vec2<f32>(s, t))), abs(vec2<f32>(s, t)), north);
    let r = q.x + q.y;
    let z = select(r * r - 1.0, 1.0 - r * r, north);
    if (r == 0.0) {
        return vec3<f32>(0.0, 0.0, z);
    }
    let rho = r * sqrt(max(0.0, 2.0 - r * r));
    let x = rho * sin(LOBES_HALF_PI * q.x / r);
    let y = rho * sin(LOBES_HALF_PI * q.y / r);
    return vec3<f32>(select(x, -x, s < 0.0), select(y, -y, t < 0.0), z);
}

// The direction at coordinates (a, b) = √π (s, t) of a quadrature rectangle, whose area da db is
// its solid angle (h and k are the sphere's).
fn lobes_domain_point(a: f32, b: f32, h: f32, k: u32) -> vec3<f32> {
    return lobes_square_to_sphere(a / LOBES_SQRT_PI, b / LOBES_SQRT_PI);
}

// A sample's point as the domain reads it: a direction, all three components.
fn lobes_domain_coordinates(p: vec3<f32>) -> vec3<f32> {
    return p;
}

// The index of centred coordinate c among n equal intervals, c = 1 in the last; where n is even
// the middle edge (an axis) placed by the sign of the component c came from. CPU twin:
// equal_area::index.
fn lobes_equal_area_index(c: f32, n: u32, negative: bool) -> u32 {
    let i = min(u32(max((c + 1.0) * 0.5 * f32(n), 0.0)), n - 1u);
    return lobes_half_by_sign(i, n, negative);
}

// The texel of a finite sample point, or LOBES_DOMAIN_OUTSIDE where it is not a unit direction
// (within 10⁻³): r² = 1 − |z| as (x² + y²) / (|p| (|p| + |z|)), stable at the poles; |s| = r (2/π)
// atan2(|x|, |y|), |t| = r (2/π) atan2(|y|, |x|); folded out to the corners for z < 0; the signs
// of x and y. CPU twin: equal_area::sphere_to_square and Grid::cell_of.
fn lobes_domain_cell(p: vec3<f32>) -> u32 {
    let l = length(p);
    if (abs(l - 1.0) > 1e-3) {
        return LOBES_DOMAIN_OUTSIDE;
    }
    let a = abs(p);
    let r = sqrt(dot(a.xy, a.xy) / (l * (l + a.z)));
    var q = vec2<f32>(0.0, 0.0);
    if (a.x != 0.0 || a.y != 0.0) {
        q = r * vec2<f32>(atan2(a.x, a.y), atan2(a.y, a.x)) / LOBES_HALF_PI;
    }
    q = select(q, lobes_equal_area_fold(q), p.z < 0.0);
    let row = lobes_equal_area_index(select(q.y, -q.y, p.y < 0.0), lobes_params.rows, p.y < 0.0);
    let col = lobes_equal_area_index(select(q.x, -q.x, p.x < 0.0), lobes_params.cols, p.x < 0.0);
    return row * lobes_params.cols + col;
}

// What lobes_domain_cell returns for a point outside the domain.
const LOBES_DOMAIN_OUTSIDE: u32 = 0xffffffffu;
