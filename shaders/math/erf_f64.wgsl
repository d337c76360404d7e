#define_import_path lobes::erf
#import lobes::math::{Real, math_exp}

// The Gaussian integrals of the Beckmann lobe in f64 (shaders/math/erf_f32.wgsl has the same
// names in f32): e^{-x^2}, erfc, the refinement of erf^-1, and how far shaders/lib/beckmann.wgsl
// inverts the visible-slope CDF. SPIR-V has no erf or erfc; these follow src/reference/beckmann.rs
// (the f64 reference) to the f64 resolution, where the f32 ones stop at f32's.

const INV_SQRT_PI: Real = 0.5641895835477563;
const TWO_OVER_SQRT_PI: Real = 1.1283791670955126;

// The visible-slope inversion (shaders/lib/beckmann.wgsl beckmann_visible_slope) as
// src/reference/beckmann.rs does it: steps (Halley's here, Newton's there) inside the bisection
// bracket until a step is below 4 ulps of x (up to 200 steps where C' -> 0 and only bisection
// helps); the CDF solved directly,
// as the reference does (the f32 kernels' complement form is exact only to its 4-point
// quadrature, ~1e-10 in f64); the grazing limit only past tan 1e15, where it is exact to f64.
const SLOPE_NEWTON_STEPS: i32 = 200;
const SLOPE_TOLERANCE: Real = 8.881784197001252e-16;
const SLOPE_GRAZING_TAN: Real = 1.0e15;
const SLOPE_COMPLEMENT: bool = false;

// e^{-x^2}, with the rounding error of x*x (recovered by fma) carried as e^{-l} ~ 1 - l.
fn math_exp_neg_sq(x: Real) -> Real {
    let h = x * x;
    let l = fma(x, x, -h);
    return math_exp(-h) * (1.0 - l);
}

// erfc x, relative error ~1e-12 (measured against glibc's erfc on a 0.001 grid: 1.3e-12 below
// 2.5, 5e-15 above): for |x| < 2.5, 1 - erf by the positive series
// erf z = 2/sqrt(pi) e^{-z^2} sum_n z (2 z^2)^n / (1 3 5 ... (2n + 1)) (Abramowitz & Stegun 7.1.6),
// else the continued fraction erfc z = e^{-z^2}/sqrt(pi) / (z + (1/2)/(z + 1/(z + (3/2)/(z + ...))))
// (A&S 7.1.14); erfc(-z) = 2 - erfc z.
fn math_erfc(x: Real) -> Real {
    return math_erfc_given(x, math_exp_neg_sq(x));
}

// erfc x from e = e^{-x^2} (math_exp_neg_sq(x)), which the visible-slope inversion has already
// (shaders/lib/beckmann.wgsl); both forms of math_erfc are e times a function of |x|.
fn math_erfc_given(x: Real, e: Real) -> Real {
    let z = abs(x);
    var r: Real;
    if (z < 2.5) {
        r = 1.0 - TWO_OVER_SQRT_PI * e * z * erf_series_sum(z * z);
    } else {
        r = e * INV_SQRT_PI / erfc_cf_denominator(z);
    }
    return select(r, 2.0 - r, x < 0.0);
}

// erf^{-1}(2u - 1) from Giles' f32-accurate guess x (shaders/lib/beckmann.wgsl erfinv_unit), for
// 0 < u < 1: |y| solves erfc |y| = 2 min(u, 1 - u) (exact for a uniform on the 2^-24 grid) by
// Newton steps (statrs' erf_inv in src/reference/beckmann.rs is the twin).
fn math_erfinv_refine(x: Real, u: Real) -> Real {
    let p = 2.0 * min(u, 1.0 - u);
    var t = abs(x);
    for (var i = 0; i < 8; i++) {
        let step = (math_erfc(t) - p) / (TWO_OVER_SQRT_PI * math_exp_neg_sq(t));
        t = t + step;
        if (abs(step) <= 1.0e-16 * t) {
            break;
        }
    }
    return select(t, -t, u < 0.5);
}

// The series and the continued fraction of math_erfc as straight-line code, with no loops:
// llvmpipe ends a shader's loops after 65535 iterations per invocation, counted over all its
// loops together (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS), silently; with loops here the 255
// samples of one invocation passed it, and a 2^14-sample run counted 218 samples.
// erf_series_sum(z2) = sum_{n<48} (2 z^2)^n / (1 3 5 ... (2n + 1)) by Horner in z^2, coefficients
// c_n = c_{n-1} 2 / (2n + 1) formed in f64 (a test in src/engine/gpu/precision.rs recomputes them).
fn erf_series_sum(z2: Real) -> Real {
    var s: Real = 4.9589271245195029e-61;
    s = s * z2 + 2.3554903841467639e-59;
    s = s * z2 + 1.0953030286282452e-57;
    s = s * z2 + 4.9836287802585158e-56;
    s = s * z2 + 2.2177148072150395e-54;
    s = s * z2 + 9.6470594113854212e-53;
    s = s * z2 + 4.1000002498388044e-51;
    s = s * z2 + 1.7015001036831038e-49;
    s = s * z2 + 6.8910754199165703e-48;
    s = s * z2 + 2.7219747908670452e-46;
    s = s * z2 + 1.0479602944838124e-44;
    s = s * z2 + 3.9298511043142966e-43;
    s = s * z2 + 1.4343956530747183e-41;
    s = s * z2 + 5.0921045684152503e-40;
    s = s * z2 + 1.7567760761032612e-38;
    s = s * z2 + 5.8851998549459249e-37;
    s = s * z2 + 1.9126899528574255e-35;
    s = s * z2 + 6.0249733515008902e-34;
    s = s * z2 + 1.8376168722077716e-32;
    s = s * z2 + 5.4209697730129262e-31;
    s = s * z2 + 1.5449763853086839e-29;
    s = s * z2 + 4.2486850595988810e-28;
    s = s * z2 + 1.1259015407937035e-26;
    s = s * z2 + 2.8710489290239440e-25;
    s = s * z2 + 7.0340698761086623e-24;
    s = s * z2 + 1.6530064208855358e-22;
    s = s * z2 + 3.7192644469924554e-21;
    s = s * z2 + 7.9964185610337797e-20;
    s = s * z2 + 1.6392658050119249e-18;
    s = s * z2 + 3.1965683197732537e-17;
    s = s * z2 + 5.9136513915805188e-16;
    s = s * z2 + 1.0348889935265908e-14;
    s = s * z2 + 1.7075668393188747e-13;
    s = s * z2 + 2.6467286009442557e-12;
    s = s * z2 + 3.8377564713691707e-11;
    s = s * z2 + 5.1809712363483809e-10;
    s = s * z2 + 6.4762140454354767e-09;
    s = s * z2 + 7.4476461522507986e-08;
    s = s * z2 + 7.8200284598633391e-07;
    s = s * z2 + 7.4290270368701719e-06;
    s = s * z2 + 6.3146729813396465e-05;
    s = s * z2 + 4.7360047360047353e-04;
    s = s * z2 + 3.0784030784030778e-03;
    s = s * z2 + 1.6931216931216929e-02;
    s = s * z2 + 7.6190476190476183e-02;
    s = s * z2 + 2.6666666666666666e-01;
    s = s * z2 + 6.6666666666666663e-01;
    s = s * z2 + 1.0000000000000000e+00;
    return s;
}

// z + (1/2)/(z + 1/(z + (3/2)/(z + ...))) from 32 levels deep.
fn erfc_cf_denominator(z: Real) -> Real {
    var k = z;
    k = z + 16.0 / k;
    k = z + 15.5 / k;
    k = z + 15.0 / k;
    k = z + 14.5 / k;
    k = z + 14.0 / k;
    k = z + 13.5 / k;
    k = z + 13.0 / k;
    k = z + 12.5 / k;
    k = z + 12.0 / k;
    k = z + 11.5 / k;
    k = z + 11.0 / k;
    k = z + 10.5 / k;
    k = z + 10.0 / k;
    k = z + 9.5 / k;
    k = z + 9.0 / k;
    k = z + 8.5 / k;
    k = z + 8.0 / k;
    k = z + 7.5 / k;
    k = z + 7.0 / k;
    k = z + 6.5 / k;
    k = z + 6.0 / k;
    k = z + 5.5 / k;
    k = z + 5.0 / k;
    k = z + 4.5 / k;
    k = z + 4.0 / k;
    k = z + 3.5 / k;
    k = z + 3.0 / k;
    k = z + 2.5 / k;
    k = z + 2.0 / k;
    k = z + 1.5 / k;
    k = z + 1.0 / k;
    k = z + 0.5 / k;
    return k;
}
