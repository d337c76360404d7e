#define_import_path lobes::erf
#import lobes::math::{Real, math_exp}

// The Gaussian integrals of the Beckmann lobe in f32, for the f32 and the f32-fast kernels
// (through their math_exp): e^{-x^2}, erfc, the refinement of erf^-1, and how far
// shaders/lib/beckmann.wgsl inverts the visible-slope CDF. shaders/math/erf_f64.wgsl defines the
// same names to f64 resolution; the composing host (src/engine/gpu/library.rs) includes one of
// the two as lobes::erf.

const INV_SQRT_PI: Real = 0.5641895835477563;

// The visible-slope inversion (shaders/lib/beckmann.wgsl beckmann_visible_slope): Newton inside
// the bisection bracket until a step is below 1e-6 of x (f32 noise in C keeps the steps from
// shrinking below ~1e-7), at most 24 steps (usually 3-5; where C' -> 0 Newton only halves the
// error); for u > 1/2 the complement of the CDF is solved, which keeps f32 precision as u -> 1;
// past tan 1e7 the grazing limit.
const SLOPE_NEWTON_STEPS: i32 = 24;
const SLOPE_TOLERANCE: Real = 1.0e-6;
const SLOPE_GRAZING_TAN: Real = 1.0e7;
const SLOPE_COMPLEMENT: bool = true;

fn math_exp_neg_sq(x: Real) -> Real {
    return math_exp(-x * x);
}

// erfc with relative error < 1.2e-7 everywhere (Numerical Recipes, 2nd ed., section 6.2, "erfcc").
fn math_erfc(x: Real) -> Real {
    let z = abs(x);
    let t = 1.0 / (1.0 + 0.5 * z);
    var p: Real = 0.17087277;
    p = -0.82215223 + t * p;
    p = 1.48851587 + t * p;
    p = -1.13520398 + t * p;
    p = 0.27886807 + t * p;
    p = -0.18628806 + t * p;
    p = 0.09678418 + t * p;
    p = 0.37409196 + t * p;
    p = 1.00002368 + t * p;
    let r = t * math_exp(-z * z - 1.26551223 + t * p);
    return select(2.0 - r, r, x >= 0.0);
}

// Giles' approximation (shaders/lib/beckmann.wgsl erfinv_unit) is accurate to f32 already.
fn math_erfinv_refine(x: Real, u: Real) -> Real {
    return x;
}
