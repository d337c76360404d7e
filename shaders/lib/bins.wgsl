#define_import_path lobes::bins

// The column of a direction on a sphere grid, where the column ⌊t · cols⌋ with t = (φ + π)/2π
// rounds: shared by the engine's binning (shaders/lib/histogram.wgsl, over Real) and by
// `lobes check`'s (shaders/check/user_passes.wgsl, f32). CPU twin: SphereGrid::bin_of
// (src/stats/histogram.rs). Its names start with `lobes_`, which `lobes check` keeps from users'
// files (src/check/gpu.rs: reserved), since it composes this module with them.

// The column t gives is within one of the exact one, but not exact: t rounds, and a value within
// half an ulp of t below a column's edge rounds onto it (at φ = π − 10⁻⁷ in f32, t = 1: column
// 0). On the seam (φ = ±π, an edge of every grid) and where the grid has an edge on another axis
// (φ = 0 for an even `cols`, ±π/2 too for a multiple of 4), the signs of x and y say exactly
// which side of it the direction is, and the column is moved into that half (quarter): a mirror
// lobe narrower than an ulp of t on an axis edge (φi = 0 at grazing incidence: 2 α cos θi wide)
// is split as the directions are, not by the rounding (docs/statistics.md, "Binning at the
// axes"). `col_t` is ⌊t · cols⌋ before any wrap (cols itself at t = 1 wraps to 0); only the signs
// of x and y are read (a caller in f64 passes f32(sign(x)), f32(sign(y))); x = y = 0 is a pole,
// whose φ the callers take as 0 (t = 1/2).
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
