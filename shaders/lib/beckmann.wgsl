#define_import_path lobes::beckmann
#import lobes::math::{Real, UNDERFLOW_EXPONENT, math_atan2, math_cos, math_exp, math_log, math_sin, neg_ln}
#import lobes::erf::{INV_SQRT_PI, SLOPE_COMPLEMENT, SLOPE_GRAZING_TAN, SLOPE_NEWTON_STEPS, SLOPE_TOLERANCE, math_erfc, math_erfc_given, math_erfinv_refine, math_exp_neg_sq}
#import lobes::reflect::{LobeSample, PI, from_tan_theta, lobe_sample, reflect_about, reflect_sample}
#import lobes::microfacet::stretch
//! embed: beckmann
//! Beckmann microfacets. Samplers take `(a, wi, u: vec2<f32>)`; densities and the BRDF
//! `(a, wi, wr)`, with a = (αx, αy).

// Beckmann; CPU twin: src/reference/beckmann.rs.
// D(h) = exp(-(hx^2/ax^2 + hy^2/ay^2)/hz^2) / (pi ax ay hz^4)                 (Heitz 2014, eq. 71)
// Lambda(w) = -erfc(a)/2 + exp(-a^2)/(2 a sqrt(pi)), a = wz/|(ax wx, ay wy)|  (Heitz 2014, eq. 72)
// NDF sampling: tan th = a sqrt(-ln(1 - u1)), ph = 2 pi u2                      (Walter 2007, eqs. 28-29)
// Visible normals: Heitz & d'Eon 2014 (slope-space CDF inversion), by Halley steps from Mitsuba 3's guess.
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

/// Beckmann's D(h) (Heitz 2014, eq. 71).
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

/// A reflected direction with h drawn from D(h) cos θh (Walter et al. 2007, eqs. 28–29).
fn beckmann_sample_ndf(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> LobeSample {
    let phi = 2.0 * PI * u.y;
    let d = a * vec2<Real>(math_cos(phi), math_sin(phi));
    let len = length(d);
    let h = from_tan_theta(sqrt(neg_ln(1.0 - u.x)) * len, d.x / len, d.y / len);
    // D(h) h_z (beckmann_d) with its exponential e^{-tan^2 th / len^2} known: 1 - u.x; 0 at u.x = 1,
    // the horizon
    return reflect_sample(wi, h, select(0.0, (1.0 - u.x) / (PI * a.x * a.y * h.z * h.z * h.z), u.x < 1.0));
}

// Heitz & d'Eon 2014: the unnormalised CDF of the visible slope, C(x) = erfc(-x)/2 + tan e^{-x^2}/(2 sqrt(pi)),
// and its complement D(x) = C(hi) - C(x) in closed form, (erfc(x) - erfc(hi))/2 - tan (e^{-x^2} - e^{-hi^2})/(2 sqrt(pi))
// = erfc(x)/2 - tan e^{-x^2}/(2 sqrt(pi)) - k_hi, which keeps f32 precision as u -> 1 where C(x) -> C(hi):
// (C, D) from one erfc |x| and e = e^{-x^2} (math_exp_neg_sq(x), which erfc shares: math_erfc_given).
fn beckmann_visible_cdf_rest(x: Real, e: Real, tan_t: Real, k_hi: Real) -> vec2<Real> {
    let r = math_erfc_given(abs(x), e);
    let gauss = 0.5 * tan_t * INV_SQRT_PI * e;
    return vec2<Real>(0.5 * select(r, 2.0 - r, x > 0.0) + gauss, 0.5 * select(2.0 - r, r, x >= 0.0) - gauss - k_hi);
}

// D(x) within 0.5 of hi = cot th, where the closed form's two terms cancel: the integral of
// tan (hi - t) e^{-t^2}/sqrt(pi) over [x, hi] (the density (1 - t tan) written without
// cancellation) by 4-point Gauss-Legendre.
fn beckmann_visible_rest_near_top(x: Real, tan_t: Real, hi: Real) -> Real {
    let d = hi - x;
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

// What the visible-normal draw needs of the case (a, wi) alone: the stretched wi's azimuth
// (cs = (cos, sin)) and tan th, the top of the slope bracket (hi: cot th, or 6 nearer the normal),
// C(hi) (top), the complement's k_hi (beckmann_visible_cdf_rest), the first guess's exponent and
// scale (beckmann_visible_slope), and G1(wi) / cos th_i.
struct BeckmannVisibleCase {
    cs: vec2<Real>,
    tan_t: Real,
    hi: Real,
    hi_is_cot: bool,
    top: Real,
    k_hi: Real,
    guess_fit: Real,
    guess_scale: Real,
    g1_over_cos: Real,
}

fn beckmann_visible_case_of(a: vec2<Real>, wi: vec3<Real>) -> BeckmannVisibleCase {
    var c: BeckmannVisibleCase;
    let ws = stretch(a, wi);
    let st = length(ws.xy);
    c.cs = vec2<Real>(1.0, 0.0);
    if (st > 0.0) {
        c.cs = ws.xy / st;
    }
    c.tan_t = select(st / ws.z, 1.0e30, ws.z <= 1.0e-30);
    c.hi_is_cot = c.tan_t > 1.0 / 6.0;
    c.hi = select(6.0, 1.0 / c.tan_t, c.hi_is_cot);
    let at_hi = beckmann_visible_cdf_rest(c.hi, math_exp_neg_sq(c.hi), c.tan_t, 0.0);
    c.top = at_hi.x;
    c.k_hi = at_hi.y; // D(hi) = 0
    // Mitsuba 3's fitted first guess (microfacet.h, sample_visible_11) in the erf domain,
    // erf(x0) = erf(hi) - (1 + erf(hi)) (1 - u)^fit, fit = 1 + th (-0.876 + th (0.4265 - 0.0594 th)),
    // th the stretched wi's; written as x0 = erf^-1(2 v - 1), v = guess_scale (1 - (1 - u)^fit).
    let th = math_atan2(st, ws.z);
    c.guess_fit = 1.0 + th * (-0.876 + th * (0.4265 - 0.0594 * th));
    c.guess_scale = 1.0 - 0.5 * math_erfc(c.hi);
    c.g1_over_cos = beckmann_g1_over_cos(a, wi);
    return c;
}

// The case of the last draw and its (a, wi), kept per invocation: a counting kernel's invocation
// draws SAMPLES_PER_THREAD samples of one case, and llvmpipe compiles the loop without hoisting
// what does not change in it (gallivm runs no loop-invariant code motion), so the case's erfc,
// exponentials and atan2 are worked out once per invocation rather than once per sample.
var<private> beckmann_case: BeckmannVisibleCase;
var<private> beckmann_case_a: vec2<Real>;
var<private> beckmann_case_wi: vec3<Real>;
var<private> beckmann_case_known: bool = false;

fn beckmann_visible_case(a: vec2<Real>, wi: vec3<Real>) -> BeckmannVisibleCase {
    if (!beckmann_case_known || any(a != beckmann_case_a) || any(wi != beckmann_case_wi)) {
        beckmann_case = beckmann_visible_case_of(a, wi);
        beckmann_case_a = a;
        beckmann_case_wi = wi;
        beckmann_case_known = true;
    }
    return beckmann_case;
}

// The slope x with C(x) = u C(hi): Halley steps (C' = (1 - x tan) e^{-x^2}/sqrt(pi),
// C'' = -(tan + 2 x (1 - x tan)) e^{-x^2}/sqrt(pi)) kept inside a bisection bracket, until a step
// moves x by less than SLOPE_TOLERANCE relative (at most SLOPE_NEWTON_STEPS: lobes::erf); from
// Mitsuba's first guess, 3 steps for every tan th (the last one the step that shows convergence);
// [-6, 6] holds all but 1e-16 of the mass, and every root for u on the 2^-24 grid of the uniforms.
fn beckmann_visible_slope(c: BeckmannVisibleCase, u: Real) -> Real {
    let tan_t = c.tan_t;
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
    var hi = c.hi;
    // For u > 1/2 the complement is solved (SLOPE_COMPLEMENT): D(x) = (1 - u) C(hi), (1 - u)
    // exact on the 2^-24 grid.
    let upper = SLOPE_COMPLEMENT && u > 0.5;
    let goal = select(u * c.top, (1.0 - u) * c.top, upper);
    var x = clamp(erfinv_guess(c.guess_scale * (1.0 - math_exp(c.guess_fit * math_log(1.0 - u)))), lo, hi);
    for (var i = 0; i < SLOPE_NEWTON_STEPS; i++) {
        let e = math_exp_neg_sq(x);
        // f increases with x in both forms: C(x) - goal, or goal - D(x)
        let cdf_rest = beckmann_visible_cdf_rest(x, e, tan_t, c.k_hi);
        var f = select(cdf_rest.x - goal, goal - cdf_rest.y, upper);
        if (upper && c.hi_is_cot && c.hi - x < 0.5) {
            f = goal - beckmann_visible_rest_near_top(x, tan_t, c.hi);
        }
        hi = select(hi, x, f > 0.0);
        lo = select(x, lo, f > 0.0);
        // Halley, x - 2 f C' / (2 C'^2 - f C''), with e/sqrt(pi) cancelled from C' and C''
        let q = 1.0 - x * tan_t;
        let ep = e * INV_SQRT_PI;
        let den = 2.0 * q * q * ep + f * (tan_t + 2.0 * x * q);
        let halley = x - 2.0 * f * q / den;
        let next = select(0.5 * (lo + hi), halley, q * ep > 1.0e-30 && den > 0.0 && halley >= lo && halley <= hi);
        let done = abs(next - x) <= SLOPE_TOLERANCE * max(1.0, abs(x));
        x = next;
        if (done) {
            break;
        }
    }
    return x;
}

// Rotate the alpha = 1 slopes (x from beckmann_visible_slope, y a unit Gaussian's) by phi_i,
// unstretch; h = normalize(-slope, 1).
fn beckmann_visible_h(a: vec2<Real>, c: BeckmannVisibleCase, u: vec2<Real>) -> vec3<Real> {
    let x = beckmann_visible_slope(c, u.x);
    let y = erfinv_unit(u.y);
    let sl = a * vec2<Real>(c.cs.x * x - c.cs.y * y, c.cs.y * x + c.cs.x * y);
    let len = length(sl);
    if (len == 0.0) {
        return vec3<Real>(0.0, 0.0, 1.0);
    }
    return from_tan_theta(len, -sl.x / len, -sl.y / len);
}

// Stretch, sample the alpha = 1 slopes, rotate by phi_i, unstretch (beckmann_visible_h).
fn beckmann_sample_vndf_h(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> vec3<Real> {
    return beckmann_visible_h(a, beckmann_visible_case(a, wi), u);
}

// p(wr) = G1(wi) D(h) / (4 cos th_i), zero for light from below the surface.
/// A reflected direction with h drawn from the visible normals of ωi (Heitz & d'Eon 2014).
fn beckmann_sample_vndf(a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>) -> LobeSample {
    let c = beckmann_visible_case(a, wi);
    let h = beckmann_visible_h(a, c, u);
    return lobe_sample(wi, h, reflect_about(wi, h), c.g1_over_cos * beckmann_d(a, h) * 0.25);
}
