#define_import_path lobes::histogram
#import lobes::job::{ROWS, COLS, REASON_NON_FINITE_POINT, REASON_OUTSIDE_DOMAIN, REASON_NON_FINITE_PDF, REASON_ZERO_PDF, REASON_REFRACTED_NEAR_SIDE}
#import lobes::math::{Real, math_is_finite}
#import lobes::bins::lobes_sphere_cell

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

// The bin of direction w on the job's sphere grid (shaders/lib/bins.wgsl, which `lobes check`
// bins with too). CPU twin: SphereGrid::bin_of.
fn bin_of(w: vec3<Real>) -> u32 {
    return lobes_sphere_cell(w, ROWS, COLS);
}
