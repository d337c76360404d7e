#define_import_path lobes::math

// The f64 arithmetic of the samplers and the binning, written once over `Real`
// (shaders/math/f32.wgsl): `Real` is f64 here, for `lobes tradeoff`'s f64 kernels, which are the
// f32 kernels' passes and samplers composed with this module (src/engine/gpu/library.rs).
//
// Why these functions are written out rather than builtins: SPIR-V's GLSL.std.450 defines sin,
// cos, atan2, exp and log for 16- and 32-bit floats only. They are range reduction and
// polynomials (Cody & Waite, "Software Manual for the Elementary Functions", 1980: additive
// reduction with a two-part constant; Taylor series on the reduced range, truncated where the
// next term is below 2^-60 of the result). sqrt, inverseSqrt, length, normalize, dot, fma,
// ldexp, floor, abs, min, max are defined for f64.

alias Real = f64;

// e^-x is below the smallest normal f64 (2^-1022) past x = 708.
const UNDERFLOW_EXPONENT: Real = 708.0;

const PIO2_HI: Real = 1.5707963267948966;        // pi/2 rounded to f64
const PIO2_LO: Real = 6.123233995736766e-17;     // pi/2 - PIO2_HI
const LN2_HI: Real = 0.6931471805599453;
const LN2_LO: Real = 2.3190468138462996e-17;
const SQRT2: Real = 1.4142135623730951;

// sin x and cos x for |x| <= pi/4 + 1e-7: Taylor to x^17 and x^18 (next terms < 1e-19).
fn sincos_small(x: Real) -> vec2<Real> {
    let x2 = x * x;
    var s = 1.0lf / 355687428096000.0lf;          // 1/17!
    s = s * x2 - 1.0lf / 1307674368000.0lf;       // 1/15!
    s = s * x2 + 1.0lf / 6227020800.0lf;          // 1/13!
    s = s * x2 - 1.0lf / 39916800.0lf;            // 1/11!
    s = s * x2 + 1.0lf / 362880.0lf;              // 1/9!
    s = s * x2 - 1.0lf / 5040.0lf;
    s = s * x2 + 1.0lf / 120.0lf;
    s = s * x2 - 1.0lf / 6.0lf;
    s = x + x * x2 * s;
    var c = 1.0lf / 6402373705728000.0lf;         // 1/18!
    c = c * x2 - 1.0lf / 20922789888000.0lf;      // 1/16!
    c = c * x2 + 1.0lf / 87178291200.0lf;         // 1/14!
    c = c * x2 - 1.0lf / 479001600.0lf;           // 1/12!
    c = c * x2 + 1.0lf / 3628800.0lf;             // 1/10!
    c = c * x2 - 1.0lf / 40320.0lf;
    c = c * x2 + 1.0lf / 720.0lf;
    c = c * x2 - 1.0lf / 24.0lf;
    c = c * x2 + 0.5lf;
    c = 1.0lf - x2 * c;
    return vec2<Real>(s, c);
}

// (sin, cos) of r + q pi/2 from those of r.
fn quadrant(sc: vec2<Real>, q: i32) -> vec2<Real> {
    switch (q & 3) {
        case 0: { return sc; }
        case 1: { return vec2<Real>(sc.y, -sc.x); }
        case 2: { return vec2<Real>(-sc.x, -sc.y); }
        default: { return vec2<Real>(-sc.y, sc.x); }
    }
}

// (sin, cos) of x for |x| <= 7 (the samplers' angles lie in [0, 2 pi]): x - k pi/2 in two
// parts (Cody-Waite).
fn sincos(x: Real) -> vec2<Real> {
    let k = floor(x / PIO2_HI + 0.5);
    let r = (x - k * PIO2_HI) - k * PIO2_LO;
    return quadrant(sincos_small(r), i32(k));
}

fn math_sin(x: Real) -> Real {
    return sincos(x).x;
}

fn math_cos(x: Real) -> Real {
    return sincos(x).y;
}

// ln x for x in f32's normal range (every caller's argument is a uniform, 1 - u or 4u(1 - u)):
// x = m 2^e with m in [sqrt(1/2), sqrt(2)), e from the bits of f32(x) (WGSL has no bitcast of
// f64, and naga types frexp's f64 exponent as i64), ln m = 2 atanh(s) = 2 (s + s^3/3 + ...),
// s = (m - 1)/(m + 1), |s| <= 0.1716, to s^25 (next term < 1e-20 of the result).
fn math_log(x: Real) -> Real {
    var e = i32((bitcast<u32>(f32(x)) >> 23u) & 0xffu) - 127;
    var m = ldexp(x, -e);
    if (m > SQRT2) {
        m = 0.5 * m;
        e = e + 1;
    }
    let s = (m - 1.0lf) / (m + 1.0lf);
    let s2 = s * s;
    var p = 1.0lf / 25.0lf;
    p = p * s2 + 1.0lf / 23.0lf;
    p = p * s2 + 1.0lf / 21.0lf;
    p = p * s2 + 1.0lf / 19.0lf;
    p = p * s2 + 1.0lf / 17.0lf;
    p = p * s2 + 1.0lf / 15.0lf;
    p = p * s2 + 1.0lf / 13.0lf;
    p = p * s2 + 1.0lf / 11.0lf;
    p = p * s2 + 1.0lf / 9.0lf;
    p = p * s2 + 1.0lf / 7.0lf;
    p = p * s2 + 1.0lf / 5.0lf;
    p = p * s2 + 1.0lf / 3.0lf;
    let fe = Real(e);
    return fe * LN2_HI + (fe * LN2_LO + 2.0 * s * (1.0 + s2 * p));
}

// -ln u of a uniform; u = 0 gives 1e300 ("infinity": from_tan_theta takes its square root to the
// horizon).
fn neg_ln(u: Real) -> Real {
    if (u <= 0.0) {
        return 1.0e300;
    }
    return -math_log(u);
}

// e^x: x = k ln 2 + r (two-part ln 2), |r| <= 0.35, Taylor to r^14 (next term < 2e-18), times
// 2^k by ldexp; 0 below -745, where e^x underflows f64 (the samplers' exponents are <= 0).
fn math_exp(x: Real) -> Real {
    if (x < -745.0) {
        return 0.0;
    }
    let k = floor(x * 1.4426950408889634lf + 0.5lf); // x / ln 2 (only picks k)
    let r = (x - k * LN2_HI) - k * LN2_LO;
    var p = 1.0lf / 87178291200.0lf;              // 1/14!
    p = p * r + 1.0lf / 6227020800.0lf;
    p = p * r + 1.0lf / 479001600.0lf;
    p = p * r + 1.0lf / 39916800.0lf;
    p = p * r + 1.0lf / 3628800.0lf;
    p = p * r + 1.0lf / 362880.0lf;
    p = p * r + 1.0lf / 40320.0lf;
    p = p * r + 1.0lf / 5040.0lf;
    p = p * r + 1.0lf / 720.0lf;
    p = p * r + 1.0lf / 120.0lf;
    p = p * r + 1.0lf / 24.0lf;
    p = p * r + 1.0lf / 6.0lf;
    p = p * r + 0.5lf;
    p = p * r + 1.0lf;
    p = p * r + 1.0lf;
    return ldexp(p, i32(k));
}

// atan2(y, x): the f32 atan2 of the scaled pair (error ~1e-7) corrected by one exact step,
// theta = theta0 + atan(d), d = (y cos theta0 - x sin theta0) / (x cos theta0 + y sin theta0),
// atan(d) = d - d^3/3 + d^5/5 (|d| < 1e-6: the rest is below 1e-36). Not both zero.
fn math_atan2(y: Real, x: Real) -> Real {
    let scale = 1.0 / max(abs(x), abs(y));
    let ys = y * scale;
    let xs = x * scale;
    let t0 = Real(atan2(f32(ys), f32(xs)));
    let sc = sincos(t0);
    let d = (ys * sc.y - xs * sc.x) / (xs * sc.y + ys * sc.x);
    let d2 = d * d;
    return t0 + d * (1.0 - d2 * (1.0 / 3.0 - d2 * 0.2));
}

// x as two f32 (columns hi, lo) with hi + lo = x to ~2^-48 relative, for reading f64 results
// back through f32 buffers. hi = x rounded to 24 bits by Veltkamp's split (Dekker 1971, "A
// floating-point technique for extending the available precision", mul12's splitting:
// g = (2^29 + 1) x, hi = g - (g - x)), so hi is exact in f32 and x - hi exact in f64. Not
// x - f64(f32(x)): Mesa 25's NIR folds f2f64(f2f32(x)) to x, which made that residual 0
// (tests/tradeoff.rs, f64_pairs_survive_the_driver). |x| >= 1e30 (and inf, NaN): (f32(x), 0).
fn f32_pair(x: vec3<Real>) -> mat2x3<f32> {
    let g = x * 536870913.0lf;
    let hi = g - (g - x);
    let big = !(abs(x) < vec3<Real>(1.0e30));
    return mat2x3<f32>(select(vec3<f32>(hi), vec3<f32>(x), big), select(vec3<f32>(x - hi), vec3<f32>(0.0), big));
}

// x is neither NaN nor +-infinity. By comparisons: WGSL has no bitcast of 64-bit values. A NaN
// fails them where the driver keeps IEEE comparisons (not guaranteed; no NaN occurred in
// tests/tradeoff.rs).
fn math_is_finite(x: Real) -> bool {
    return x == x && abs(x) <= 1.7976931348623157e308;
}
