#define_import_path lobes::masking
#import lobes::math::{Real, math_log, math_exp}
//! embed: masking
//! Smith masking-shadowing G2 from the two masking terms G1(ωi), G1(ωr) (CPU twin:
//! `lobes::reference::masking`).

// Smith masking-shadowing from the two directions' masking terms G1(wi), G1(wr) (each in [0, 1]);
// CPU twin: src/reference/masking.rs. Written with G1 = 1 / (1 + Lambda) rather than Lambda,
// so that grazing directions (Lambda -> inf, G1 -> 0) stay finite.

/// Separable G2 = G1(wi) G1(wr) (Heitz 2014, eq. 98).
fn masking_separable(gi: f32, gr: f32) -> f32 {
    return gi * gr;
}

/// Height-correlated G2 = 1 / (1 + Lambda(wi) + Lambda(wr)) (Heitz 2014, eq. 99)
/// = G1i G1r / (G1i + G1r - G1i G1r).
fn masking_height_correlated(gi: f32, gr: f32) -> f32 {
    if (gi <= 0.0 || gr <= 0.0) {
        return 0.0;
    }
    return gi * gr / (gi + gr - gi * gr);
}

// Height-correlated G2 across a rough dielectric's surface, B(1 + Lambda(wi), 1 + Lambda(wo))
// (Heitz 2014; the derivation is in src/reference/masking.rs), 1 + Lambda = 1 / G1; over Real
// (f32 and f64 kernels). 0 where a G1 is below 1e-30: B(x, y) <= B(1, y) = 1/y, so G2 <= min(gi,
// go) is below 1e-30 there, and 1/G1 stays within masking_ln_beta's range.
/// Height-correlated G2 across a rough dielectric's surface, B(1 + Λ(ωi), 1 + Λ(ωo)), from
/// G1(ωi) and G1(ωo).
fn masking_height_correlated_transmitted(gi: Real, go: Real) -> Real {
    if (!(min(gi, go) >= 1.0e-30)) {
        return 0.0;
    }
    return math_exp(masking_ln_beta(1.0 / gi, 1.0 / go));
}

// ln B(x, y) for 1 <= x, y <= 1e30, without the cancellation of lgamma(x) + lgamma(y) -
// lgamma(x + y) (terms of size ~x ln x for a result of size ~ln B; measured in f32 against f64,
// tests/dielectric_weighted.rs). With a = min(x, y) <= b = max(x, y), s = a + b, Stirling's
// ln Gamma(z) = (z - 1/2) ln z - z + ln(2 pi)/2 + d(z) (Abramowitz & Stegun 6.1.41) for z >= 8:
// 1. b < 8 (so a < 8 too): B(a, b) = B(a, b + 1) (a + b) / b (from Gamma(z + 1) = z Gamma(z))
//    until b >= 8, each step adding ln(1 + a/b), in [0, ln 2].
// 2. a >= 8: in the three Gammas the -a - b + s cancel exactly and the logarithms regroup as
//    ln B = -(a - 1/2) ln(1 + b/a) - (b - 1/2) ln(1 + a/b) - ln(s)/2 + ln(2 pi)/2
//           + d(a) + d(b) - d(s),
//    the three logarithms all <= 0 and the rest below 1 (ln(1 + a/b) is ln(s/b): formed so, the
//    rounding of s/b ~ 1 would cost (b - 1/2) ulps).
// 3. a < 8 <= b: ln Gamma(a) + ln Gamma(b) - ln Gamma(s), the last two by Stirling as
//    -(b - 1/2) ln(1 + a/b) - a ln s + a + d(b) - d(s), of size ~a ln s, and ln Gamma(a) from
//    Gamma(c) = Gamma(a) a (a + 1) ... (c - 1), c in [8, 9). Raising a by B's own recurrence
//    instead would add ~(8 - a) ln b and take it away again.
/// ln B(x, y), Euler's Beta function, for 1 ≤ x, y ≤ 1e30, without cancellation in f32.
fn masking_ln_beta(x: Real, y: Real) -> Real {
    let a = min(x, y);
    var b = max(x, y);
    var steps: Real = 0.0;
    for (; b < 8.0; b += 1.0) {
        steps += masking_ln_1p(a / b);
    }
    let s = a + b;
    if (a >= 8.0) {
        let logs = -(a - 0.5) * masking_ln_1p(b / a) - (b - 0.5) * masking_ln_1p(a / b) - 0.5 * math_log(s);
        return steps + logs + HALF_LN_2PI + (masking_stirling_d(a) + masking_stirling_d(b) - masking_stirling_d(s));
    }
    var c = a;
    var rising: Real = 1.0;
    for (; c < 8.0; c += 1.0) {
        rising *= c;
    }
    let ln_gamma_a = (c - 0.5) * math_log(c) - c + HALF_LN_2PI + masking_stirling_d(c) - math_log(rising);
    let ratio = -(b - 0.5) * masking_ln_1p(a / b) - a * math_log(s) + a + (masking_stirling_d(b) - masking_stirling_d(s));
    return steps + ln_gamma_a + ratio;
}

const HALF_LN_2PI: Real = 0.9189385332046728;

// Stirling's remainder d(z) = ln Gamma(z) - (z - 1/2) ln z + z - ln(2 pi)/2 for z >= 8: the
// series sum of B_2k / (2k (2k - 1) z^(2k - 1)) to z^-13; the next term is below 8.5e-16.
fn masking_stirling_d(z: Real) -> Real {
    let w = 1.0 / (z * z);
    var p: Real = 1.0 / 156.0;
    p = 691.0 / 360360.0 - w * p;
    p = 1.0 / 1188.0 - w * p;
    p = 1.0 / 1680.0 - w * p;
    p = 1.0 / 1260.0 - w * p;
    p = 1.0 / 360.0 - w * p;
    p = 1.0 / 12.0 - w * p;
    return p / z;
}

// ln(1 + t) for t >= 0. For t <= 1, 2 atanh(z) with z = t / (2 + t) <= 1/3, its series
// 2 z (1 + z^2/3 + z^4/5 + ...) to z^30 (the next term is below 1.7e-17 of the sum): full
// precision where the argument 1 + t of a logarithm would round (and where the builtin log of
// f32 promises only an absolute error of 2^-21, on [1/2, 2]); past 1, math_log(1 + t).
fn masking_ln_1p(t: Real) -> Real {
    if (t > 1.0) {
        return math_log(1.0 + t);
    }
    let z = t / (2.0 + t);
    let z2 = z * z;
    var p: Real = 1.0 / 31.0;
    for (var k = 29; k > 0; k -= 2) {
        p = p * z2 + 1.0 / Real(k);
    }
    return 2.0 * z * p;
}
