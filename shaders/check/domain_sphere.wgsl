#define_import_path lobes::domain
#import lobes::check_params::lobes_check
#import lobes::bins::lobes_axis_column

// The sphere as the domain of `lobes check`'s passes (src/stats/domain.rs, Domain::Sphere: the
// CPU twin of each function here). The plane's twin is domain_plane.wgsl; the host composes the
// one its sampler's domain names.

// The direction at coordinates (a, b) of a quadrature rectangle in hemisphere `h` (±1) and
// quadrant `k`: a = 1 − |cos θ| (the distance from the nearer pole, exact in f32 where a peak
// sits at a pole) and b = φ − k π/2, φ measured from the axis nearest the rectangle (the host
// chooses k), so the direction is (s cos φ, s sin φ, h (1 − a)) with s = √(a (2 − a)),
// (cos φ, sin φ) being (cos b, sin b) turned by k quarter turns, which is exact; and the
// solid-angle element is da dφ: a rectangle's integral needs no Jacobian. So an edge on an axis
// is exactly where the binning puts it (f32(π) is 8.7·10⁻⁸ past π: with φ itself in f32 the two
// columns of the seam overlapped by twice that, 2.5 % of a grazing lobe of α 10⁻⁴ counted twice),
// and one off the axes within an ulp of b (≤ 4.7·10⁻⁸ rad) rather than of φ (2.4·10⁻⁷ near ±π).
fn lobes_domain_point(a: f32, b: f32, h: f32, k: u32) -> vec3<f32> {
    let s = sqrt(max(0.0, a * (2.0 - a)));
    let e = vec2<f32>(cos(b), sin(b));
    var t = e;
    t = select(t, vec2<f32>(-e.y, e.x), k == 1u);
    t = select(t, -e, k == 2u);
    t = select(t, vec2<f32>(e.y, -e.x), k == 3u);
    return vec3<f32>(s * t.x, s * t.y, h * (1.0 - a));
}

// A sample's point as the domain reads it: a direction, all three components.
fn lobes_domain_coordinates(p: vec3<f32>) -> vec3<f32> {
    return p;
}

// The bin of a finite sample point, or LOBES_DOMAIN_OUTSIDE where it is not a unit direction
// (within 10⁻³): rows uniform in cos θ over [−1, 1], columns in φ over [−π, π), φ = π wrapping
// to column 0, the column exact on the axes' edges (shaders/lib/bins.wgsl), as lobes bins its
// own lobes (shaders/lib/histogram.wgsl's bin_of, src/stats/histogram.rs).
fn lobes_domain_cell(p: vec3<f32>) -> u32 {
    if (abs(length(p) - 1.0) > 1e-3) {
        return LOBES_DOMAIN_OUTSIDE;
    }
    let z = clamp(p.z, -1.0, 1.0);
    let row = min(u32((z + 1.0) * 0.5 * f32(lobes_check.rows)), lobes_check.rows - 1u);
    var t = 0.5;
    if (p.x != 0.0 || p.y != 0.0) {
        t = (atan2(p.y, p.x) + 3.14159265358979) * (0.5 / 3.14159265358979);
    }
    // the column made exact on the axes' edges (the φ = ±π seam above all), as lobes run's
    let col = lobes_axis_column(u32(max(t, 0.0) * f32(lobes_check.cols)), lobes_check.cols, p.x, p.y);
    return row * lobes_check.cols + col;
}

// What lobes_domain_cell returns for a point outside the domain.
const LOBES_DOMAIN_OUTSIDE: u32 = 0xffffffffu;
