#define_import_path lobes::math

// The f32 math of the samplers and the binning: the transcendental functions they call, as
// math_log, math_exp, math_sin, math_cos, math_atan2 and neg_ln. This module is the f32 one (the
// WGSL builtins, plus an accurate -ln u); shaders/math/f32_fast.wgsl defines the same names with cheap
// approximations for `lobes tradeoff`'s f32-fast kernels, and the composing host
// (src/engine/gpu/compose.rs) includes one of the two. The f64 kernels (shaders/math/f64.wgsl) have
// their own f64 math: SPIR-V defines these functions for 16- and 32-bit floats only.

fn math_log(x: f32) -> f32 {
    return log(x);
}

fn math_exp(x: f32) -> f32 {
    return exp(x);
}

fn math_sin(x: f32) -> f32 {
    return sin(x);
}

fn math_cos(x: f32) -> f32 {
    return cos(x);
}

fn math_atan2(y: f32, x: f32) -> f32 {
    return atan2(y, x);
}

// -ln u. For u > 1/2, ln u = 2 atanh(s) with s = (u - 1)/(u + 1), |s| <= 1/3, summed as its
// series 2 s (1 + s^2/3 + s^4/5 + ...) to 9 terms: full f32 relative precision near u = 1,
// where the builtin log only promises an absolute error of 2^-21. u = 0 gives 3e38 ("infinity").
fn neg_ln(u: f32) -> f32 {
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
