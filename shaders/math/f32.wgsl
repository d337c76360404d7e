#define_import_path lobes::math
//! embed: math
//! The arithmetic the samplers are written over, as the WGSL builtins, and −ln u accurate near 1;
//! in the plain text also `LobesReal`, the type the files are written over (an alias of f32).

// The arithmetic of the samplers and the binning, which are written once over `Real`: this
// module makes `Real` f32 and defines the functions they call (math_log, math_exp, math_sin,
// math_cos, math_atan2, neg_ln, math_is_finite, f32_pair) and the limits of the precision, as the WGSL
// builtins plus an accurate -ln u. shaders/math/f32_fast.wgsl defines the same names with cheap
// approximations (`lobes tradeoff`'s f32-fast kernels), shaders/math/f64.wgsl over f64; the
// composing host (src/engine/gpu/library.rs) includes one of the three as lobes::math.

alias Real = f32;

/// e^-x is below the smallest normal f32 (2^-126) past x = 87: densities return 0 there
/// rather than a denormal over a denormal.
const UNDERFLOW_EXPONENT: Real = 87.0;

/// ln x (the builtin).
fn math_log(x: Real) -> Real {
    return log(x);
}

/// e^x (the builtin).
fn math_exp(x: Real) -> Real {
    return exp(x);
}

/// sin x (the builtin).
fn math_sin(x: Real) -> Real {
    return sin(x);
}

/// cos x (the builtin).
fn math_cos(x: Real) -> Real {
    return cos(x);
}

/// atan2(y, x) (the builtin).
fn math_atan2(y: Real, x: Real) -> Real {
    return atan2(y, x);
}

// x as two f32 (hi, lo) summing to x: (x, 0) here (shaders/math/f64.wgsl splits an f64).
fn f32_pair(x: vec3<Real>) -> mat2x3<f32> {
    return mat2x3<f32>(x, vec3<f32>(0.0));
}

// x is neither NaN nor +-infinity, from the bit pattern (without relying on IEEE comparisons of
// NaN being false, which drivers may optimise away).
/// x is neither NaN nor ±infinity.
fn math_is_finite(x: Real) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// -ln u. For u > 1/2, ln u = 2 atanh(s) with s = (u - 1)/(u + 1), |s| <= 1/3, summed as its
// series 2 s (1 + s^2/3 + s^4/5 + ...) to 9 terms: full f32 relative precision near u = 1,
// where the builtin log only promises an absolute error of 2^-21. u = 0 gives 3e38 ("infinity").
/// −ln u, accurate near u = 1; u = 0 gives 3e38.
fn neg_ln(u: Real) -> Real {
    if (u <= 0.0) {
        return 3.0e38;
    }
    if (u <= 0.5) {
        return -log(u);
    }
    let s = (u - 1.0) / (u + 1.0);
    let s2 = s * s;
    var p = 1.0 / 17.0;
    p = p * s2 + 1.0 / 15.0;
    p = p * s2 + 1.0 / 13.0;
    p = p * s2 + 1.0 / 11.0;
    p = p * s2 + 1.0 / 9.0;
    p = p * s2 + 1.0 / 7.0;
    p = p * s2 + 1.0 / 5.0;
    p = p * s2 + 1.0 / 3.0;
    p = p * s2 + 1.0;
    return -2.0 * s * p;
}
