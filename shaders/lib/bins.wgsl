#define_import_path lobes::bins
#import lobes::math::{Real, math_atan2}
#import lobes::reflect::PI

// The cells of the sphere's grids, one binning for the engine's kernels (shaders/lib/histogram.wgsl,
// over Real, so that the f64 kernels bin in f64) and for `lobes check`'s domains
// (shaders/check/domain_*.wgsl, Real = f32). CPU twin: SphereGrid (src/stats/histogram.rs).

// Equal-solid-angle bins: rows uniform in cos θ over [−1, 1] (cos θ = 1 in the top row),
// columns uniform in φ over [−π, π) (lobes_sphere_column). CPU twin: SphereGrid::bin_of.
fn lobes_sphere_cell(w: vec3<Real>, rows: u32, cols: u32) -> u32 {
    let z = clamp(w.z, -1.0, 1.0);
    let row = min(u32((z + 1.0) * 0.5 * Real(rows)), rows - 1u);
    return row * cols + lobes_sphere_column(w.x, w.y, cols);
}

// The column of a direction whose components across the grid's axis are (x, y): ⌊t · cols⌋ with
// t = (φ + π)/2π, φ = atan2(y, x), made exact on the axes' edges (lobes_axis_column). At a pole
// (x = y = 0) φ is undefined (atan2 of two zeros differs between implementations): 0 there.
// CPU twin: SphereGrid::column_of.
fn lobes_sphere_column(x: Real, y: Real, cols: u32) -> u32 {
    let pole = x == 0.0 && y == 0.0;
    let t = select((math_atan2(y, x) + PI) * (1.0 / (2.0 * PI)), 0.5, pole);
    // the signs, not f32(x) and f32(y), which an f64 kernel's tiny values would round to 0
    return lobes_axis_column(u32(max(t, 0.0) * Real(cols)), cols, f32(sign(x)), f32(sign(y)));
}

// The column t gives is within one of the exact one, but not exact: t rounds, and a value within
// half an ulp of t below a column's edge rounds onto it (at φ = π − 10⁻⁷ in f32, t = 1: column
// 0). On the seam (φ = ±π, an edge of every grid) and where the grid has an edge on another axis
// (φ = 0 for an even `cols`, ±π/2 too for a multiple of 4), the signs of x and y say exactly
// which side of it the direction is, and the column is moved into that half (quarter): a mirror
// lobe narrower than an ulp of t on an axis edge (φi = 0 at grazing incidence: 2 α cos θi wide)
// is split as the directions are, not by the rounding (docs/statistics.md, "Binning at the
// axes"). `col_t` is ⌊t · cols⌋ before any wrap (cols itself at t = 1 wraps to 0); only the signs
// of x and y are read; x = y = 0 is a pole, whose φ lobes_sphere_column takes as 0 (t = 1/2).
fn lobes_axis_column(col_t: u32, cols: u32, x: f32, y: f32) -> u32 {
    let wrapped = select(col_t, 0u, col_t >= cols);
    if ((x == 0.0 && y == 0.0) || cols < 2u) {
        return wrapped;
    }
    // the seam φ = ±π, an edge of every grid: column 0 lies below it (y ≤ 0), the last above
    var col = select(wrapped, cols - 1u, wrapped == 0u && y > 0.0);
    col = select(col, 0u, col == cols - 1u && y < 0.0);
    if (cols % 2u != 0u) {
        return col;
    }
    // φ in [−π, 0) (y < 0, or y = 0 at x < 0: φ = ±π, column 0) or [0, π) (y > 0, or y = 0 at x ≥ 0)
    let upper = y > 0.0 || (y == 0.0 && x >= 0.0);
    let half = cols / 2u;
    var lo = select(0u, half, upper);
    var hi = lo + half - 1u;
    if (cols % 4u == 0u && y != 0.0 && x != 0.0) {
        // φ in [−π/2, π/2) (x > 0) or outside it
        let q = cols / 4u;
        let inner = x > 0.0;
        lo = select(select(0u, 3u * q, upper), select(q, half, upper), inner);
        hi = lo + q - 1u;
    }
    return clamp(col, lo, hi);
}

// Index i of n equal intervals whose middle edge, where n is even, lies on an axis (a lat-long
// map's equator, an equal-area map's u = 1/2 or v = 1/2): kept in the first half where `first`,
// else in the second, so a sign places a point on that edge, not the coordinate's rounding. CPU
// twin: histogram::half_by_sign.
fn lobes_half_by_sign(i: u32, n: u32, first: bool) -> u32 {
    if (n % 2u != 0u) {
        return i;
    }
    return select(max(i, n / 2u), min(i, n / 2u - 1u), first);
}

// The direction at coordinates (a, b) of a quadrature rectangle of a sphere grid in hemisphere
// `h` (±1) and quadrant `k`: a = 1 − |cos θ| (the distance from the nearer pole, exact in f32
// where a peak sits at a pole) and b = φ − k π/2, φ measured from the axis nearest the rectangle
// (the host chooses k), so the direction is (s cos φ, s sin φ, h (1 − a)) with s = √(a (2 − a)),
// (cos φ, sin φ) being (cos b, sin b) turned by k quarter turns, which is exact; and the
// solid-angle element is da dφ: a rectangle's integral needs no Jacobian. So an edge on an axis
// is exactly where the binning puts it (f32(π) is 8.7·10⁻⁸ past π: with φ itself in f32 the two
// columns of the seam overlapped by twice that, 2.5 % of a grazing lobe of α 10⁻⁴ counted twice),
// and one off the axes within an ulp of b (≤ 4.7·10⁻⁸ rad) rather than of φ (2.4·10⁻⁷ near ±π).
// CPU twin: Domain::part_point (src/stats/domain.rs).
fn lobes_quadrant_direction(a: f32, b: f32, h: f32, k: u32) -> vec3<f32> {
    let s = sqrt(max(0.0, a * (2.0 - a)));
    let e = vec2<f32>(cos(b), sin(b));
    var t = e;
    t = select(t, vec2<f32>(-e.y, e.x), k == 1u);
    t = select(t, -e, k == 2u);
    t = select(t, vec2<f32>(e.y, -e.x), k == 3u);
    return vec3<f32>(s * t.x, s * t.y, h * (1.0 - a));
}
