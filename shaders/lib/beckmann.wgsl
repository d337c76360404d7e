#define_import_path lobes::beckmann
#import lobes::math::{Real, UNDERFLOW_EXPONENT, math_cos, math_exp, math_log, math_sin, neg_ln}
#import lobes::erf::{INV_SQRT_PI, SLOPE_COMPLEMENT, SLOPE_GRAZING_TAN, SLOPE_NEWTON_STEPS, SLOPE_TOLERANCE, math_erfc, math_erfinv_refine, math_exp_neg_sq}
#import lobes::reflect::{LobeSample, PI, from_tan_theta, lobe_sample, reflect_about, reflect_sample}
#import lobes::microfacet::stretch

// Beckmann; CPU twin: src/reference/beckmann.rs.
// D(h) = exp(-(hx^2/ax^2 + hy^2/ay^2)/hz^2) / (pi ax ay hz^4)                 (Heitz 2014, eq. 71)
// Lambda(w) = -erfc(a)/2 + exp(-a^2)/(2 a sqrt(pi)), a = wz/|(ax wx, ay wy)|  (Heitz 2014, eq. 72)
// NDF sampling: tan th = a sqrt(-ln(1 - u1)), ph = 2 pi u2                      (Walter 2007, eqs. 28-29)
// Visible normals: Heitz & d'Eon 2014 (slope-space CDF inversion), Newton steps as in Jakob 2014.
// Written once over Real: erfc, e^{-x^2} and how far the inversion goes are the precision's
// (lobes::erf, shaders/math/erf_f32.wgsl or erf_f64.wgsl).

// A slope standing in for infinity (u at 0 or 1); from_tan_theta takes it to the horizon.
const BIG_SLOPE: Real = 1.0e15;

// erfinv(2u - 1), Giles 2010 ("Approximating the erfinv function", single precision), with
// (1 - x)(1 + x) formed as 4u(1 - u) so that no cancellation occurs near u = 0 or 1: accurate to
// f32, and the guess that f64 refines.
fn erfinv_guess(u: Real) -> Real {
    if (u <= 0.0) {
        return -BIG_SLOPE;
    }
    if (u >= 1.0) {
        return BIG_SLOPE;
    }
    var w = -math_log(4.0 * u * (1.0 - u));
    var p: Real;
    if (w < 5.0) {
        w = w - 2.5;
        p = 2.81022636e-08;
        p = 3.43273939e-07 + p * w;
        p = -3.5233877e-06 + p * w;
        p = -4.39150654e-06 + p * w;
        p = 0.00021858087 + p * w;
        p = -0.00125372503 + p * w;
        p = -0.00417768164 + p * w;
        p = 0.246640727 + p * w;
        p = 1.50140941 + p * w;
    } else {
        w = sqrt(w) - 3.0;
        p = -0.000200214257;
        p = 0.000100950558 + p * w;
        p = 0.00134934322 + p * w;
        p = -0.00367342844 + p * w;
        p = 0.00573950773 + p * w;
        p = -0.0076224613 + p * w;
        p = 0.00943887047 + p * w;
        p = 1.00167406 + p * w;
        p = 2.83297682 + p * w;
    }
    return p * (2.0 * u - 1.0);
}

// erfinv(2u - 1) to the precision's resolution.
fn erfinv_unit(u: Real) -> Real {
    return math_erfinv_refine(erfinv_guess(u), u);
}

fn beckmann_d(a: vec2<Real>, h: vec3<Real>) -> Real {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let q = h.xy / a;
    let z2 = h.z * h.z;
    let q2 = dot(q, q);
    if (q2 > UNDERFLOW_EXPONENT * z2) {
        return 0.0; // exp(-q2/hz^2) < 2^-126: underflows, and hz^4 may too (0/0)
    }
    return math_exp(-q2 / z2) / (PI * a.x * a.y * z2 * z2);
}

// G1(w) / cos th = 1 / (cos th + cos th Lambda), cos th Lambda = -cos th erfc(a)/2 + a_w e^{-a^2}/(2 sqrt(pi)),
// a_w = |(ax wx, ay wy)|, a = cos th / a_w: finite at cos th = 0 (grazing), where it is 2 sqrt(pi) / a_w.
fn beckmann_g1_over_cos(a: vec2<Real>, w: vec3<Real>) -> Real {
    let aw = length(a * w.xy);
    let c = abs(w.z);
    if (c > 10.0 * aw) {
        return 1.0 / c; // a > 10: Lambda < 1e-45
    }
    let x = c / aw;
    return 1.0 / (c - 0.5 * c * math_erfc(x) + aw * math_exp_neg_sq(x) * INV_SQRT_PI * 0.5);
}

fn beckmann_sample_ndf(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> LobeSample {
    let phi = 2.0 * PI * u.y;
    let d = a * vec2<Real>(math_cos(phi), math_sin(phi));
    let len = length(d);
    let h = from_tan_theta(sqrt(neg_ln(1.0 - u.x)) * len, d.x / len, d.y / len);
    return reflect_sample(wi, h, beckmann_d(a, h) * h.z);
}

// Heitz & d'Eon 2014: unnormalised CDF of the visible slope, C(x) = erfc(-x)/2 + tan e^{-x^2}/(2 sqrt(pi)).
fn beckmann_visible_cdf(x: Real, tan_t: Real) -> Real {
    return 0.5 * math_erfc(-x) + 0.5 * tan_t * INV_SQRT_PI * math_exp_neg_sq(x);
}

// The complement D(x) = C(hi) - C(x), which keeps f32 precision as u -> 1 where C(x) -> C(hi).
// Closed form (erfc(x) - erfc(hi))/2 - tan (e^{-x^2} - e^{-hi^2})/(2 sqrt(pi)); within 0.5 of
// hi = cot th, where the two terms cancel, the integral of tan (hi - t) e^{-t^2}/sqrt(pi) over
// [x, hi] (the density (1 - t tan) written without cancellation) by 4-point Gauss-Legendre.
// k_hi = erfc(hi)/2 - tan e^{-hi^2}/(2 sqrt(pi)), the closed form's constant part.
fn beckmann_visible_rest(x: Real, tan_t: Real, hi: Real, hi_is_cot: bool, k_hi: Real) -> Real {
    let d = hi - x;
    if (hi_is_cot && d < 0.5) {
        let gx = array<Real, 4>(0.0694318442, 0.3300094782, 0.6699905218, 0.9305681558);
        let gw = array<Real, 4>(0.1739274226, 0.3260725774, 0.3260725774, 0.1739274226);
        var integral: Real = 0.0;
        for (var k = 0; k < 4; k++) {
            let s = d * gx[k];
            let t = hi - s;
            integral += gw[k] * s * math_exp_neg_sq(t);
        }
        return integral * d * tan_t * INV_SQRT_PI;
    }
    return 0.5 * math_erfc(x) - 0.5 * tan_t * INV_SQRT_PI * math_exp_neg_sq(x) - k_hi;
}

// The slope x with C(x) = u C(cot): Newton steps (C' = (1 - x tan) e^{-x^2}/sqrt(pi)) kept inside a
// bisection bracket, until a step moves x by less than SLOPE_TOLERANCE relative (at most
// SLOPE_NEWTON_STEPS: lobes::erf); [-6, 6] holds all but 1e-16 of the mass, and every root for
// u on the 2^-24 grid of the uniforms.
fn beckmann_visible_slope(tan_t: Real, u: Real) -> Real {
    if (u <= 0.0) {
        return -BIG_SLOPE;
    }
    if (u >= 1.0) {
        // the top of the support, x = cot th (where the visible density vanishes)
        return select(BIG_SLOPE, 1.0 / tan_t, tan_t > 1.0 / BIG_SLOPE);
    }
    if (tan_t > SLOPE_GRAZING_TAN) {
        // th = 90 deg: the density tends to 2|x| e^{-x^2} on x <= 0, with CDF e^{-x^2}.
        return -sqrt(neg_ln(u));
    }
    var lo: Real = -6.0;
    var hi: Real = 6.0;
    if (tan_t > 1.0 / 6.0) {
        hi = 1.0 / tan_t;
    }
    let top = beckmann_visible_cdf(hi, tan_t);
    let hi_is_cot = tan_t > 1.0 / 6.0;
    // For u > 1/2 the complement is solved (SLOPE_COMPLEMENT): D(x) = (1 - u) C(hi), (1 - u)
    // exact on the 2^-24 grid.
    let upper = SLOPE_COMPLEMENT && u > 0.5;
    let goal = select(u * top, (1.0 - u) * top, upper);
    let top_hi = hi;
    let k_hi = 0.5 * math_erfc(hi) - 0.5 * tan_t * INV_SQRT_PI * math_exp_neg_sq(hi);
    // First guess: the Gaussian quantile near normal incidence; near grazing, where
    // C(x) ~ tan e^{-x^2}/(2 sqrt(pi)) dominates, the inverse of that limit, -sqrt(-ln u).
    var x = clamp(select(erfinv_guess(u), -sqrt(neg_ln(u)), tan_t > 2.0), lo, hi);
    for (var i = 0; i < SLOPE_NEWTON_STEPS; i++) {
        // f increases with x in both forms: C(x) - goal, or goal - D(x)
        var f: Real;
        if (upper) {
            f = goal - beckmann_visible_rest(x, tan_t, top_hi, hi_is_cot, k_hi);
        } else {
            f = beckmann_visible_cdf(x, tan_t) - goal;
        }
        if (f > 0.0) {
            hi = x;
        } else {
            lo = x;
        }
        let df = (1.0 - x * tan_t) * math_exp_neg_sq(x) * INV_SQRT_PI;
        var next = 0.5 * (lo + hi);
        if (df > 1.0e-30) {
            let newton = x - f / df;
            if (newton >= lo && newton <= hi) {
                next = newton;
            }
        }
        let done = abs(next - x) <= SLOPE_TOLERANCE * max(1.0, abs(x));
        x = next;
        if (done) {
            break;
        }
    }
    return x;
}

// Stretch, sample the alpha = 1 slopes, rotate by phi_i, unstretch; h = normalize(-slope, 1).
fn beckmann_sample_vndf_h(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> vec3<Real> {
    let ws = stretch(a, wi);
    let st = length(ws.xy);
    var cs = vec2<Real>(1.0, 0.0);
    if (st > 0.0) {
        cs = ws.xy / st;
    }
    let x = beckmann_visible_slope(select(st / ws.z, 1.0e30, ws.z <= 1.0e-30), u.x);
    let y = erfinv_unit(u.y);
    let sl = a * vec2<Real>(cs.x * x - cs.y * y, cs.y * x + cs.x * y);
    let len = length(sl);
    if (len == 0.0) {
        return vec3<Real>(0.0, 0.0, 1.0);
    }
    return from_tan_theta(len, -sl.x / len, -sl.y / len);
}

// p(wr) = G1(wi) D(h) / (4 cos th_i), zero for light from below the surface.
fn beckmann_sample_vndf(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> LobeSample {
    let h = beckmann_sample_vndf_h(a, wi, u);
    return lobe_sample(wi, h, reflect_about(wi, h), beckmann_g1_over_cos(a, wi) * beckmann_d(a, h) * 0.25);
}
