#define_import_path lobes::histogram
#import lobes::job::{ROWS, COLS, REASON_NON_FINITE_DIRECTION, REASON_BELOW_HORIZON, REASON_NON_FINITE_PDF, REASON_ZERO_PDF, REASON_REFRACTED_NEAR_SIDE}
#import lobes::math::{Real, math_atan2, math_is_finite}
#import lobes::reflect::PI

// Binning and exact counting; CPU twin: src/stats/histogram.rs. ROWS and COLS are the job's
// grid and REASON_* the codes of src/engine/gpu/layout.rs, from the generated `lobes::job`.
// Cell layout: BINS bins, then one counter per invalid reason (codes 1..N_REASONS, in the order of
// reference::Invalid::ALL): non-finite direction, below horizon, non-finite pdf, zero pdf,
// refracted near side.
const F32_MAX: f32 = 3.40282347e38;

// 0 for a valid sample, else the reason code: the first that applies in the order of
// reference::Invalid::check, chosen by selects from the last to the first (no branches: a SIMD
// driver runs every branch anyway, under a mask). Over Real, as the samplers (lobes::math), so
// that the f64 kernels bin in f64.
fn classify(wr: vec3<Real>, pdf: Real) -> u32 {
    return classify_scattered(vec3<Real>(0.0, 0.0, 1.0), wr, pdf, true);
}

// The same for a direction that may leave on either side, seen from wi (a rough dielectric's,
// shaders/lib/dielectric.wgsl), with its event: a reflection on the far side of the surface is
// below the horizon, a refraction on wi's side (or either on the surface) refracted near side;
// the order matches reference::Invalid::check_scattered. classify's constant wi and event fold
// away at compile time.
fn classify_scattered(wi: vec3<Real>, wo: vec3<Real>, pdf: Real, reflected: bool) -> u32 {
    let side = select(wo.z, -wo.z, wi.z < 0.0);
    var reason = select(0u, REASON_ZERO_PDF, pdf <= 0.0);
    reason = select(reason, REASON_NON_FINITE_PDF, !math_is_finite(pdf));
    reason = select(reason, REASON_REFRACTED_NEAR_SIDE, !reflected && side >= 0.0);
    reason = select(reason, REASON_BELOW_HORIZON, reflected && side <= 0.0);
    let finite = math_is_finite(wo.x) && math_is_finite(wo.y) && math_is_finite(wo.z);
    return select(reason, REASON_NON_FINITE_DIRECTION, !finite);
}

// Equal-solid-angle bins: rows uniform in cos th over [-1, 1], columns uniform in phi over
// [-pi, pi); phi = pi wraps to column 0, cos th = 1 falls in the top row.
fn bin_of(w: vec3<Real>) -> u32 {
    let z = clamp(w.z, -1.0, 1.0);
    let row = min(u32((z + 1.0) * 0.5 * Real(ROWS)), ROWS - 1u);
    // At the poles phi is undefined (atan2 of two zeros differs between implementations): use 0.
    let pole = w.x == 0.0 && w.y == 0.0;
    let t = select((math_atan2(w.y, w.x) + PI) * (1.0 / (2.0 * PI)), 0.5, pole);
    let col = u32(max(t, 0.0) * Real(COLS));
    return row * COLS + axis_exact_column(select(col, 0u, col >= COLS), w.x, w.y, pole);
}

// The column t gives is within one of the exact one, but not exact: t rounds, and a value within
// half an ulp of t below a column's edge rounds onto it (at phi = pi - 1e-7, t = 1: column 0).
// On the seam (phi = +-pi, an edge of every grid) and where the grid has an edge on another axis
// (phi = 0 for an even COLS, +-pi/2 too for a multiple of 4), the signs of x and y say exactly which side of it w is, and the column is
// moved into that half (quarter): a mirror lobe narrower than an ulp of t on an axis edge
// (phi_i = 0 at grazing incidence: 2 alpha cos th_i wide) is split as w itself is, not by the
// rounding (docs/statistics.md). CPU twin: SphereGrid::bin_of.
fn axis_exact_column(col_t: u32, x: Real, y: Real, pole: bool) -> u32 {
    if (pole || COLS < 2u) {
        return col_t;
    }
    // the seam phi = +-pi, an edge of every grid: column 0 lies below it (y <= 0), the last above
    var col = select(col_t, COLS - 1u, col_t == 0u && y > 0.0);
    col = select(col, 0u, col == COLS - 1u && y < 0.0);
    if (COLS % 2u != 0u) {
        return col;
    }
    // phi in [-pi, 0) (y < 0, or y = 0 at x < 0: phi = -pi or pi, column 0) or [0, pi) (y > 0, or y = 0 at x >= 0)
    let upper = y > 0.0 || (y == 0.0 && x >= 0.0);
    let half = COLS / 2u;
    var lo = select(0u, half, upper);
    var hi = lo + half - 1u;
    if (COLS % 4u == 0u && y != 0.0 && x != 0.0) {
        // phi in [-pi/2, pi/2) (x > 0) or outside it
        let q = COLS / 4u;
        let inner = x > 0.0;
        lo = select(select(0u, 3u * q, upper), select(q, half, upper), inner);
        hi = lo + q - 1u;
    }
    return clamp(col, lo, hi);
}
