#define_import_path lobes::math

// Cheap f32 approximations of the transcendental functions the samplers and the binning call,
// for `lobes tradeoff`'s "f32-fast" kernels: the math module that the composing host
// (src/engine/gpu/compose.rs) includes in place of shaders/math/f32.wgsl, with the same names
// (math_log, math_exp, math_sin, math_cos, math_atan2, neg_ln) defined at the end.
// Errors quoted are the sources' (and checked by tests/tradeoff.rs through the sampled angles).
// Only the transcendental functions differ from shaders/math/f32.wgsl: `Real` is f32 and the
// limits and the finiteness test are f32's.

alias Real = f32;

// e^-x is below the smallest normal f32 past x = 87 (shaders/math/f32.wgsl).
const UNDERFLOW_EXPONENT: Real = 87.0;

// x as two f32 (hi, lo) summing to x: (x, 0) (shaders/math/f32.wgsl).
fn f32_pair(x: vec3<Real>) -> mat2x3<f32> {
    return mat2x3<f32>(x, vec3<f32>(0.0));
}

// x is neither NaN nor +-infinity, from the bit pattern (shaders/math/f32.wgsl).
fn math_is_finite(x: Real) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// log2 by the float's bit pattern plus a rational correction of the mantissa: P. Mineiro,
// "fastapprox" (2011), fastlog2; absolute error about 1e-4.
fn fast_log2(x: f32) -> f32 {
    let vx = bitcast<u32>(x);
    let mx = bitcast<f32>((vx & 0x007fffffu) | 0x3f000000u);
    let y = f32(vx) * 1.1920928955078125e-7;
    return y - 124.22551499 - 1.498030302 * mx - 1.72587999 / (0.3520887068 + mx);
}

fn fast_log(x: f32) -> f32 {
    return 0.69314718 * fast_log2(x);
}


// 2^p by writing the exponent bits: Mineiro (2011), fastpow2; relative error about 1e-4.
fn fast_pow2(p: f32) -> f32 {
    let clipp = clamp(p, -126.0, 127.0);
    let offset = select(0.0, 1.0, clipp < 0.0);
    let w = i32(clipp);
    let z = clipp - f32(w) + offset;
    return bitcast<f32>(u32(8388608.0 * (clipp + 121.2740575 + 27.7280233 / (4.84252568 - z) - 1.49012907 * z)));
}

fn fast_exp(p: f32) -> f32 {
    return fast_pow2(1.442695040 * p);
}

// sin x: x reduced to [-pi, pi], then the parabola 4x/pi - 4x|x|/pi^2 with one correction
// step y + 0.225 (y|y| - y): N. Capens, "Fast and accurate sine/cosine" (devmaster.net, 2006);
// absolute error about 1e-3.
fn fast_sin(x: f32) -> f32 {
    let r = x - 6.28318531 * floor(x * 0.159154943 + 0.5);
    let y = 1.27323954 * r - 0.405284735 * r * abs(r);
    return 0.225 * (y * abs(y) - y) + y;
}

fn fast_cos(x: f32) -> f32 {
    return fast_sin(x + 1.57079633);
}

// atan2 from atan r ~ pi/4 r - r (|r| - 1)(0.2447 + 0.0663 |r|) on |r| <= 1 and the octant
// symmetries: S. Rajan, S. Wang, R. Inkol, A. Joyal, "Efficient approximations for the
// arctangent function", IEEE Signal Processing Magazine 23(3), 2006, eq. 9; error < 1.5e-3 rad.
fn fast_atan2(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let ay = abs(y);
    let r = min(ax, ay) / max(max(ax, ay), 1.0e-30);
    var a = 0.785398163 * r - r * (r - 1.0) * (0.2447 + 0.0663 * r);
    if (ay > ax) {
        a = 1.57079633 - a;
    }
    if (x < 0.0) {
        a = 3.14159265 - a;
    }
    return select(a, -a, y < 0.0);
}

// The names the samplers call (shaders/math/f32.wgsl).
fn math_log(x: Real) -> Real {
    return fast_log(x);
}

fn math_exp(x: Real) -> Real {
    return fast_exp(x);
}

fn math_sin(x: Real) -> Real {
    return fast_sin(x);
}

fn math_cos(x: Real) -> Real {
    return fast_cos(x);
}

fn math_atan2(y: Real, x: Real) -> Real {
    return fast_atan2(y, x);
}

// -ln u without the accurate series of shaders/math/f32.wgsl (u = 0 gives about 89, not 3e38).
fn neg_ln(u: Real) -> Real {
    return -fast_log(u);
}
