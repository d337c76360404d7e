#define_import_path lobes::erf
#import lobes::math::{Real, math_exp}
//! embed: beckmann

// The Gaussian integrals of the Beckmann lobe in f32, for the f32 and the f32-fast kernels
// (through their math_exp): e^{-x^2}, erfc, the refinement of erf^-1, and how far
// shaders/lib/beckmann.wgsl inverts the visible-slope CDF. shaders/math/erf_f64.wgsl defines the
// same names to f64 resolution; the composing host (src/engine/gpu/library.rs) includes one of
// the two as lobes::erf.

const INV_SQRT_PI: Real = 0.5641895835477563;

// The visible-slope inversion (shaders/lib/beckmann.wgsl beckmann_visible_slope): Halley steps
// inside the bisection bracket until a step is below 1e-6 of x (f32 noise in C keeps the steps
// from shrinking below ~1e-7), at most 24 steps (3 from its first guess; where C' -> 0 only
// bisection helps); for u > 1/2 the complement of the CDF is solved, which keeps f32 precision
// as u -> 1; past tan 1e7 the grazing limit.
const SLOPE_NEWTON_STEPS: i32 = 24;
const SLOPE_TOLERANCE: Real = 1.0e-6;
const SLOPE_GRAZING_TAN: Real = 1.0e7;
const SLOPE_COMPLEMENT: bool = true;

fn math_exp_neg_sq(x: Real) -> Real {
    return math_exp(-x * x);
}

// erfc x (math_erfc_given).
fn math_erfc(x: Real) -> Real {
    return math_erfc_given(x, math_exp_neg_sq(x));
}

// erfc x from e = e^{-x^2} (math_exp_neg_sq(x)), which the visible-slope inversion has already
// (shaders/lib/beckmann.wgsl): for z = |x|, erfc z = e^{-z^2} t P(t), t = 1/(1 + z/2) (the
// variable of Numerical Recipes' "erfcc", section 6.2), P of degree 10 fitted to e^{z^2} erfc(z)/t
// over all z >= 0 (t in (0, 1]) for the least maximum relative error: 1.1e-8 in f64, below 3e-7
// evaluated in f32 (the rounding of t), so erfc's error is e^{-z^2}'s; erfc(-z) = 2 - erfc z.
fn math_erfc_given(x: Real, e: Real) -> Real {
    let t = 1.0 / (1.0 + 0.5 * abs(x));
    var p: Real = 0.042352598160505295;
    p = -0.23085767030715942 + t * p;
    p = 0.4861789345741272 + t * p;
    p = -0.44697752594947815 + t * p;
    p = 0.12708953022956848 + t * p;
    p = -0.05723251402378082 + t * p;
    p = 0.09300059080123901 + t * p;
    p = 0.17537683248519897 + t * p;
    p = 0.24688059091567993 + t * p;
    p = 0.2820938527584076 + t * p;
    p = 0.282094806432724 + t * p;
    let r = e * t * p;
    return select(2.0 - r, r, x >= 0.0);
}

// Giles' approximation (shaders/lib/beckmann.wgsl erfinv_unit) is accurate to f32 already.
fn math_erfinv_refine(x: Real, u: Real) -> Real {
    return x;
}
