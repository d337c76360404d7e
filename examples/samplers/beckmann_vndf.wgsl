// A Beckmann reflection sampler by visible normals, for `lobes check`: params[0].xy = (αx, αy).
//   D(h)  = exp(−(hx²/αx² + hy²/αy²) / hz²) / (π αx αy hz⁴)                (Walter et al. 2007, eq. 25)
//   Λ(w)  = (erf(a) − 1) / 2 + exp(−a²) / (2 a √π),  a = 1 / (α tan θ) with α of w's azimuth
//                                                                            (Walter et al. 2007, eq. 27)
//   h     ~ G1(wi) max(0, wi·h) D(h) / wi.z, by Heitz & d'Eon 2014 with Jakob's numerical inversion
//           of the slope CDF (as in Mitsuba 3's microfacet.h, sample_visible_11)
//   d     = 2 (wi·h) h − wi,   p(d) = G1(wi) D(h) / (4 wi.z)
// erf by Abramowitz & Stegun 7.1.26 (|error| ≤ 1.5·10⁻⁷), erf⁻¹ by Giles 2010 (single precision).

const BECK_PI: f32 = 3.14159265358979;
const BECK_INV_SQRT_PI: f32 = 0.564189583547756;

fn beck_erf(x: f32) -> f32 {
    let t = 1.0 / (1.0 + 0.3275911 * abs(x));
    let y = 1.0 - t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429)))) * exp(-x * x);
    return select(-y, y, x >= 0.0);
}

// Giles, "Approximating the erfinv function", GPU Computing Gems Jade, 2011.
fn beck_erfinv(x: f32) -> f32 {
    var w = -log(max((1.0 - x) * (1.0 + x), 1e-30));
    var p: f32;
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
    return p * x;
}

fn beck_d(h: vec3<f32>, a: vec2<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let z2 = h.z * h.z;
    return exp(-(h.x * h.x / (a.x * a.x) + h.y * h.y / (a.y * a.y)) / z2) / (BECK_PI * a.x * a.y * z2 * z2);
}

// 1 / (α tan θ) of w, with α along w's azimuth: wz / |(αx wx, αy wy)|.
fn beck_a(w: vec3<f32>, a: vec2<f32>) -> f32 {
    return w.z / length(vec2<f32>(a.x * w.x, a.y * w.y));
}

// The exact G1 = 1 / (1 + Λ).
fn beck_g1(w: vec3<f32>, a: vec2<f32>) -> f32 {
    let s = length(vec2<f32>(a.x * w.x, a.y * w.y));
    if (s == 0.0) {
        return 1.0;
    }
    let b = w.z / s;
    let lambda = 0.5 * (beck_erf(b) - 1.0) + 0.5 * BECK_INV_SQRT_PI * exp(-b * b) / b;
    return 1.0 / (1.0 + lambda);
}

// The slopes of the visible normals of the unit-roughness configuration seen at cos θ.
fn beck_visible_slopes(cos_theta: f32, u: vec2<f32>) -> vec2<f32> {
    let y = beck_erfinv(2.0 * u.y - 1.0);
    let tan_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta)) / cos_theta;
    if (tan_theta < 1e-6) {
        return vec2<f32>(beck_erfinv(2.0 * u.x - 1.0), y);
    }
    let cot = 1.0 / tan_theta;
    let maxval = beck_erf(cot);
    let theta = acos(cos_theta);
    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    var b = maxval - (1.0 + maxval) * pow(1.0 - u.x, fit);
    let normalization = 1.0 / (1.0 + maxval + BECK_INV_SQRT_PI * tan_theta * exp(-cot * cot));
    var lo = -1.0;
    var hi = maxval;
    for (var i = 0; i < 10; i++) {
        if (!(b >= lo && b <= hi)) {
            b = 0.5 * (lo + hi);
        }
        let inv = beck_erfinv(b);
        let value = normalization * (1.0 + b + BECK_INV_SQRT_PI * tan_theta * exp(-inv * inv)) - u.x;
        let derivative = normalization * (1.0 - inv * tan_theta);
        if (abs(value) < 1e-6) {
            break;
        }
        if (value > 0.0) {
            hi = b;
        } else {
            lo = b;
        }
        b -= value / derivative;
    }
    return vec2<f32>(beck_erfinv(b), y);
}

fn beck_visible_normal(wi: vec3<f32>, a: vec2<f32>, u: vec2<f32>) -> vec3<f32> {
    let ws = normalize(vec3<f32>(a.x * wi.x, a.y * wi.y, wi.z));
    let r = length(ws.xy);
    var cs = vec2<f32>(1.0, 0.0);
    if (r > 0.0) {
        cs = ws.xy / r;
    }
    let s = beck_visible_slopes(ws.z, u);
    let slope = vec2<f32>((cs.x * s.x - cs.y * s.y) * a.x, (cs.y * s.x + cs.x * s.y) * a.y);
    return normalize(vec3<f32>(-slope.x, -slope.y, 1.0));
}

fn beck_pdf_with(wi: vec3<f32>, d: vec3<f32>, a: vec2<f32>, g1: f32) -> f32 {
    let m = wi + d;
    if (wi.z <= 0.0 || dot(m, m) == 0.0) {
        return 0.0;
    }
    let h = normalize(m);
    if (dot(wi, h) <= 0.0) {
        return 0.0;
    }
    return g1 * beck_d(h, a) / (4.0 * wi.z);
}

fn beck_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return beck_pdf_with(wi, d, params[0].xy, beck_g1(wi, params[0].xy));
}

fn beck_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    if (wi.z <= 0.0) {
        return vec4<f32>(0.0, 0.0, 1.0, 0.0);
    }
    let h = beck_visible_normal(wi, params[0].xy, u.xy);
    let d = 2.0 * dot(wi, h) * h - wi;
    return vec4<f32>(d, beck_pdf(wi, d, params));
}
