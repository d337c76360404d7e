#define_import_path lobes::histogram
#import lobes::job::{ROWS, COLS, REASON_NON_FINITE_POINT, REASON_OUTSIDE_DOMAIN, REASON_NON_FINITE_PDF, REASON_ZERO_PDF, REASON_REFRACTED_NEAR_SIDE}
#import lobes::math::{Real, math_atan2, math_is_finite}
#import lobes::reflect::PI
#import lobes::bins::lobes_axis_column

// Binning and exact counting; CPU twin: src/stats/histogram.rs. ROWS and COLS are the job's
// grid and REASON_* the codes of src/reference/invalid.rs, from the generated `lobes::job`.
// Cell layout: BINS bins, then one counter per invalid reason (codes 1..REASON_COUNT, in the
// order of reference::Invalid::ALL): non-finite point, outside the domain (for a lobe: below
// the horizon), non-finite pdf, zero pdf, refracted near side.
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
    reason = select(reason, REASON_OUTSIDE_DOMAIN, reflected && side <= 0.0);
    let finite = math_is_finite(wo.x) && math_is_finite(wo.y) && math_is_finite(wo.z);
    return select(reason, REASON_NON_FINITE_POINT, !finite);
}

// Equal-solid-angle bins: rows uniform in cos th over [-1, 1], columns uniform in phi over
// [-pi, pi); phi = pi wraps to column 0, cos th = 1 falls in the top row. The column t gives is
// made exact on the axes' edges by lobes_axis_column (shaders/lib/bins.wgsl), which `lobes
// check` bins with too. CPU twin: SphereGrid::bin_of.
fn bin_of(w: vec3<Real>) -> u32 {
    let z = clamp(w.z, -1.0, 1.0);
    let row = min(u32((z + 1.0) * 0.5 * Real(ROWS)), ROWS - 1u);
    // At the poles phi is undefined (atan2 of two zeros differs between implementations): use 0.
    let pole = w.x == 0.0 && w.y == 0.0;
    let t = select((math_atan2(w.y, w.x) + PI) * (1.0 / (2.0 * PI)), 0.5, pole);
    // the signs, not f32(w.x) and f32(w.y), which an f64 kernel's tiny values would round to 0
    return row * COLS + lobes_axis_column(u32(max(t, 0.0) * Real(COLS)), COLS, f32(sign(w.x)), f32(sign(w.y)));
}
