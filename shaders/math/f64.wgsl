// f64 twins of the samplers that `lobes tradeoff` sweeps (Ward, Beckmann NDF and visible normals,
// GGX NDF, spherical caps and bounded VNDF), each line by line the same algebra as src/reference (ward.rs,
// beckmann.rs sample_ndf, ggx.rs, microfacet.rs, reflect.rs), plus f64 binning
// (src/stats/histogram.rs). Appended by src/tradeoff/variants.rs to a composed f32 kernel, whose
// `draw` and `explicit_samples` it replaces (the host adds A64, WI64 and the call site
// sampler_sample64 of the job's f64 sampler, src/reference/sampler.rs).
//
// SPIR-V's GLSL.std.450 defines sin, cos, atan2, exp and log for 16- and 32-bit floats only, so
// the f64 versions are written here: range reduction and polynomials (Cody & Waite, "Software
// Manual for the Elementary Functions", 1980: additive reduction with a two-part constant;
// Taylor series on the reduced range, truncated where the next term is below 2^-60 of the result).
// sqrt, inverseSqrt, length, normalize, dot, ldexp, floor, abs, min, max are defined for f64.

const PI64: f64 = 3.141592653589793lf;
const TWO_PI64: f64 = 6.283185307179586lf;
const PIO2_HI64: f64 = 1.5707963267948966lf;        // pi/2 rounded to f64
const PIO2_LO64: f64 = 6.123233995736766e-17lf;     // pi/2 - PIO2_HI64
const LN2_HI64: f64 = 0.6931471805599453lf;
const LN2_LO64: f64 = 2.3190468138462996e-17lf;
const SQRT2_64: f64 = 1.4142135623730951lf;
// -ln 0 stands for infinity: from_tan_theta64 takes slopes at or above it to the horizon.
const INF_SLOPE64: f64 = 1.0e300lf;

// sin x and cos x for |x| <= pi/4 + 1e-7: Taylor to x^17 and x^18 (next terms < 1e-19).
fn sincos_small64(x: f64) -> vec2<f64> {
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
    return vec2<f64>(s, c);
}

// (sin, cos) of r + q pi/2 from those of r.
fn quadrant64(sc: vec2<f64>, q: i32) -> vec2<f64> {
    switch (q & 3) {
        case 0: { return sc; }
        case 1: { return vec2<f64>(sc.y, -sc.x); }
        case 2: { return vec2<f64>(-sc.x, -sc.y); }
        default: { return vec2<f64>(-sc.y, sc.x); }
    }
}

// (sin, cos) of 2 pi u for u in [0, 1]: reduced in u, where u - q/4 is exact.
fn sincos_2pi64(u: f64) -> vec2<f64> {
    let q = floor(4.0lf * u + 0.5lf);
    return quadrant64(sincos_small64(TWO_PI64 * (u - 0.25lf * q)), i32(q));
}

// (sin, cos) of x for |x| <= 4: x - k pi/2 in two parts (Cody-Waite); k pi/2_hi is exact.
fn sincos64(x: f64) -> vec2<f64> {
    let k = floor(x / PIO2_HI64 + 0.5lf);
    let r = (x - k * PIO2_HI64) - k * PIO2_LO64;
    return quadrant64(sincos_small64(r), i32(k));
}

// ln x for a positive normal f32 x (the uniforms and 1 - u are exact f32 numbers): x = m 2^e
// with m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(s) = 2 (s + s^3/3 + ...), s = (m - 1)/(m + 1),
// |s| <= 0.1716, to s^25 (next term < 1e-20 of the result).
fn ln_f32_64(x: f32) -> f64 {
    let bits = bitcast<u32>(x);
    var e = i32((bits >> 23u) & 0xffu) - 127;
    var m = f64(bitcast<f32>((bits & 0x7fffffu) | 0x3f800000u));
    if (m > SQRT2_64) {
        m = 0.5lf * m;
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
    let fe = f64(e);
    return fe * LN2_HI64 + (fe * LN2_LO64 + 2.0lf * s * (1.0lf + s2 * p));
}

// -ln u of a uniform (src/reference/ward.rs neg_ln); u = 0 gives INF_SLOPE64 ("infinity").
fn neg_ln64(u: f32) -> f64 {
    if (u <= 0.0) {
        return INF_SLOPE64;
    }
    return -ln_f32_64(u);
}

// e^x for x <= 0: x = k ln 2 + r (two-part ln 2), |r| <= 0.35, Taylor to r^14 (next term
// < 2e-18), times 2^k by ldexp; 0 below -745 where e^x underflows f64.
fn exp_neg64(x: f64) -> f64 {
    if (x < -745.0lf) {
        return 0.0lf;
    }
    let k = floor(x * 1.4426950408889634lf + 0.5lf); // x / ln 2 (only picks k)
    let r = (x - k * LN2_HI64) - k * LN2_LO64;
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

// atan2(y, x) in f64: the f32 atan2 of the scaled pair (error ~1e-7) corrected by one exact
// step, theta = theta0 + atan(d), d = (y cos theta0 - x sin theta0) / (x cos theta0 + y sin theta0),
// atan(d) = d - d^3/3 + d^5/5 (|d| < 1e-6: the rest is below 1e-36). Not both zero.
fn atan2_64(y: f64, x: f64) -> f64 {
    let scale = 1.0lf / max(abs(x), abs(y));
    let ys = y * scale;
    let xs = x * scale;
    let t0 = f64(atan2(f32(ys), f32(xs)));
    let sc = sincos64(t0);
    let d = (ys * sc.y - xs * sc.x) / (xs * sc.y + ys * sc.x);
    let d2 = d * d;
    return t0 + d * (1.0lf - d2 * (1.0lf / 3.0lf - d2 * 0.2lf));
}

struct LobeSample64 {
    h: vec3<f64>,
    wr: vec3<f64>,
    pdf_r: f64,
}

fn reflect64(wi: vec3<f64>, h: vec3<f64>) -> vec3<f64> {
    return 2.0lf * dot(wi, h) * h - wi;
}

// src/reference/reflect.rs from_tan_theta: cos = 1/sqrt(1 + t^2), sin = 1/sqrt(1 + 1/t^2).
fn from_tan_theta64(t: f64, c: f64, s: f64) -> vec3<f64> {
    if (t >= INF_SLOPE64) {
        return vec3<f64>(c, s, 0.0lf);
    }
    if (t == 0.0lf) {
        return vec3<f64>(0.0lf, 0.0lf, 1.0lf);
    }
    let t2 = t * t;
    let ct = 1.0lf / sqrt(1.0lf + t2);
    let st = 1.0lf / sqrt(1.0lf + 1.0lf / t2);
    return vec3<f64>(st * c, st * s, ct);
}

// A sample with p(wr) = pdf_h / (4 |wr.h|), 0 for light from below or reflection into the surface.
fn reflect_sample64(wi: vec3<f64>, h: vec3<f64>, pdf_h: f64) -> LobeSample64 {
    let wr = reflect64(wi, h);
    var pdf = 0.0lf;
    if (wi.z >= 0.0lf && wr.z > 0.0lf) {
        pdf = pdf_h / (4.0lf * abs(dot(wr, h)));
    }
    return LobeSample64(h, wr, pdf);
}

// (hx^2/ax^2 + hy^2/ay^2) / hz^2 (src/reference/ward.rs slope_exponent).
fn slope_exponent64(a: vec2<f64>, h: vec3<f64>) -> f64 {
    let q = h.xy / a;
    return dot(q, q) / (h.z * h.z);
}

// Ward (Walter 2005, eqs. 6-9) in slope form, as src/reference/ward.rs.
fn ward_sample64(a: vec2<f64>, wi: vec3<f64>, u: vec2<f32>) -> LobeSample64 {
    let sc = sincos_2pi64(f64(u.y));
    let sx = a.x * sc.y;
    let sy = a.y * sc.x;
    let len = sqrt(sx * sx + sy * sy);
    let nl = neg_ln64(u.x);
    var t = INF_SLOPE64;
    if (nl < INF_SLOPE64) {
        t = sqrt(nl) * len;
    }
    let h = from_tan_theta64(t, sx / len, sy / len);
    var pdf_h = 0.0lf;
    if (h.z > 0.0lf) {
        pdf_h = exp_neg64(-slope_exponent64(a, h)) / (PI64 * a.x * a.y * h.z * h.z * h.z);
    }
    return reflect_sample64(wi, h, pdf_h);
}

// Beckmann NDF sampling (Walter et al. 2007, eqs. 28-29): tan th = a sqrt(-ln(1 - u1)).
fn beckmann_sample_ndf64(a: vec2<f64>, wi: vec3<f64>, u: vec2<f32>) -> LobeSample64 {
    let sc = sincos_2pi64(f64(u.y));
    let sx = a.x * sc.y;
    let sy = a.y * sc.x;
    let len = sqrt(sx * sx + sy * sy);
    let h = from_tan_theta64(sqrt(neg_ln64(1.0 - u.x)) * len, sx / len, sy / len);
    var pdf_h = 0.0lf;
    if (h.z > 0.0lf) {
        let z2 = h.z * h.z;
        pdf_h = exp_neg64(-slope_exponent64(a, h)) / (PI64 * a.x * a.y * z2 * z2) * h.z;
    }
    return reflect_sample64(wi, h, pdf_h);
}

fn ggx_d64(a: vec2<f64>, h: vec3<f64>) -> f64 {
    let q = h.xy / a;
    let e = dot(q, q) + h.z * h.z;
    return 1.0lf / (PI64 * a.x * a.y * e * e);
}

// GGX NDF sampling: the stretch of (sqrt(u) cos phi, sqrt(u) sin phi, sqrt(1 - u)) (src/reference/ggx.rs).
fn ggx_sample_ndf64(a: vec2<f64>, wi: vec3<f64>, u: vec2<f32>) -> LobeSample64 {
    let sc = sincos_2pi64(f64(u.y));
    let r = sqrt(f64(u.x));
    let z = sqrt(max(1.0lf - f64(u.x), 0.0lf));
    let h = normalize(vec3<f64>(a.x * r * sc.y, a.y * r * sc.x, z));
    var pdf_h = 0.0lf;
    if (h.z > 0.0lf) {
        pdf_h = ggx_d64(a, h) * h.z;
    }
    return reflect_sample64(wi, h, pdf_h);
}

fn one_minus_stretched_z64(a: vec2<f64>, w: vec3<f64>) -> f64 {
    let v = vec3<f64>(a * w.xy, w.z);
    let len = length(v);
    if (v.z < 0.0lf) {
        return 1.0lf - v.z / len;
    }
    return dot(v.xy, v.xy) / (len * (len + v.z));
}

// Dupuy & Benyoub 2023, listing 3, with the cancellation-free forms of src/reference/ggx.rs cap_sample.
fn ggx_cap_sample64(a: vec2<f64>, wi: vec3<f64>, ws: vec3<f64>, b: f64, ws_minus_b: f64, u: vec2<f32>) -> vec3<f64> {
    let sc = sincos_2pi64(f64(u.x));
    let s = (1.0lf - f64(u.y)) * (1.0lf + b);
    let one_minus_b = one_minus_stretched_z64(a, wi) + ws_minus_b;
    let st = sqrt(clamp((s + one_minus_b) * ((1.0lf + b) - s), 0.0lf, 1.0lf));
    let hs = vec3<f64>(st * sc.y + ws.x, st * sc.x + ws.y, s + ws_minus_b);
    if (dot(hs, hs) == 0.0lf) {
        return normalize(vec3<f64>(a.x * sc.y, a.y * sc.x, 0.0lf));
    }
    return normalize(vec3<f64>(a * hs.xy, hs.z));
}

fn stretch64(a: vec2<f64>, w: vec3<f64>) -> vec3<f64> {
    return normalize(vec3<f64>(a * w.xy, w.z));
}

// Visible normals: p(h) = G1(wi)/cos th_i max(0, wi.h) D(h), G1/cos = 2/(cos th_i + t) (Heitz 2014, eq. 38).
fn ggx_sample_vndf64(a: vec2<f64>, wi: vec3<f64>, u: vec2<f32>) -> LobeSample64 {
    let ws = stretch64(a, wi);
    let h = ggx_cap_sample64(a, wi, ws, ws.z, 0.0lf, u);
    let cos_ih = dot(wi, h);
    var pdf_h = 0.0lf;
    if (wi.z >= 0.0lf && h.z > 0.0lf && cos_ih > 0.0lf) {
        let t = length(vec3<f64>(a * wi.xy, wi.z));
        pdf_h = 2.0lf / (abs(wi.z) + t) * cos_ih * ggx_d64(a, h);
    }
    return reflect_sample64(wi, h, pdf_h);
}

// Eto & Tokuyoshi 2023, listings 1-2, as src/reference/ggx.rs sample_bounded / pdf_bounded_r.
fn ggx_sample_bounded64(a: vec2<f64>, wi: vec3<f64>, u: vec2<f32>) -> LobeSample64 {
    let ws = stretch64(a, wi);
    let am = clamp(min(a.x, a.y), 0.0lf, 1.0lf);
    let sl = 1.0lf + sqrt(wi.x * wi.x + wi.y * wi.y);
    let a2 = am * am;
    let s2 = sl * sl;
    let z2 = wi.z * wi.z;
    let omk = a2 * (s2 + z2) / (s2 + a2 * z2);
    var b = ws.z;
    var ws_minus_b = 0.0lf;
    if (wi.z > 0.0lf) {
        b = (1.0lf - omk) * ws.z;
        ws_minus_b = omk * ws.z;
    }
    let h = ggx_cap_sample64(a, wi, ws, b, ws_minus_b, u);
    let wr = reflect64(wi, h);
    var pdf = 0.0lf;
    if (wi.z >= 0.0lf && wr.z > 0.0lf && h.z > 0.0lf) {
        let t = length(vec3<f64>(a * wi.xy, wi.z));
        pdf = ggx_d64(a, h) / (2.0lf * ((1.0lf - omk) * wi.z + t));
    }
    return LobeSample64(h, wr, pdf);
}

// Reason codes of shaders/lib/histogram.wgsl, in the order of reference::Invalid::check. Nothing
// above makes an infinity (u = 0 is mapped to INF_SLOPE64), and a NaN from a degenerate input
// fails the self-comparison where the driver keeps IEEE comparisons (not guaranteed: the f32
// kernels test bit patterns instead; no NaN occurred in tests/tradeoff.rs).
fn classify64(wr: vec3<f64>, pdf: f64) -> u32 {
    if (!(all(wr == wr) && all(abs(wr) <= vec3<f64>(1.0e300lf)))) {
        return REASON_NON_FINITE_DIRECTION;
    }
    if (wr.z <= 0.0lf) {
        return REASON_BELOW_HORIZON;
    }
    if (!(pdf == pdf && abs(pdf) <= 1.0e300lf)) {
        return REASON_NON_FINITE_PDF;
    }
    if (pdf <= 0.0lf) {
        return REASON_ZERO_PDF;
    }
    return 0u;
}

// src/stats/histogram.rs SphereGrid::bin_of in f64.
fn bin_of64(w: vec3<f64>) -> u32 {
    let z = clamp(w.z, -1.0lf, 1.0lf);
    let row = min(u32((z + 1.0lf) * 0.5lf * f64(ROWS)), ROWS - 1u);
    var t = 0.5lf;
    if (w.x != 0.0lf || w.y != 0.0lf) {
        t = (atan2_64(w.y, w.x) + PI64) / TWO_PI64;
    }
    var col = u32(max(t, 0.0lf) * f64(COLS));
    if (col >= COLS) {
        col = 0u;
    }
    return row * COLS + col;
}

fn lobe_sample64(u: vec2<f32>) -> LobeSample64 {
    return sampler_sample64(A64, WI64, u);
}

fn draw(index: vec2<u32>) -> u32 {
    let s = lobe_sample64(rng_uniforms(params.seed, index).xy);
    let reason = classify64(s.wr, s.pdf_r);
    if (reason != 0u) {
        return BINS + reason - 1u;
    }
    return bin_of64(s.wr);
}

// Sample i uses explicit_u[i] and writes (hi(wr), reason), then (lo(wr), f32(pdf_r)), where
// hi = f32(x) and lo = f32(x - hi): hi + lo carries wr to ~2^-48.
@compute @workgroup_size(WG_SIZE)
fn explicit_samples(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.count) {
        return;
    }
    let s = lobe_sample64(explicit_u[i]);
    let hi = vec3<f32>(s.wr);
    let lo = vec3<f32>(s.wr - vec3<f64>(hi));
    directions_out[2u * i] = vec4<f32>(hi, f32(classify64(s.wr, s.pdf_r)));
    directions_out[2u * i + 1u] = vec4<f32>(lo, f32(s.pdf_r));
}
