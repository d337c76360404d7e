// A GGX reflection sampler by visible normals, written from the papers (not lobes' own code):
// a renderer's specular lobe, for `lobes check`. params[0].xy = (αx, αy).
//   D(h)    = 1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²)                 (Walter et al. 2007, eq. 33)
//   Λ(w)    = (−1 + √(1 + (αx² wx² + αy² wy²) / wz²)) / 2,  G1 = 1 / (1 + Λ) (Heitz 2014, eq. 72)
//   h       ~ D_wi(h) = G1(wi) max(0, wi·h) D(h) / wi.z                (Heitz 2018, JCGT 7(4))
//   d       = 2 (wi·h) h − wi,   p(d) = D_wi(h) / (4 |d·h|) = G1(wi) D(h) / (4 wi.z)
// The sampler returns reflections below the horizon too, with their density: the pdf describes
// the map on the whole sphere. Incidence from below is rejected (pdf 0).

const GGX_PI: f32 = 3.14159265358979;

fn ggx_d(h: vec3<f32>, a: vec2<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let t = h.x * h.x / (a.x * a.x) + h.y * h.y / (a.y * a.y) + h.z * h.z;
    return 1.0 / (GGX_PI * a.x * a.y * t * t);
}

fn ggx_lambda(w: vec3<f32>, a: vec2<f32>) -> f32 {
    let t2 = (a.x * a.x * w.x * w.x + a.y * a.y * w.y * w.y) / (w.z * w.z);
    return 0.5 * (-1.0 + sqrt(1.0 + t2));
}

fn ggx_g1(w: vec3<f32>, a: vec2<f32>) -> f32 {
    return 1.0 / (1.0 + ggx_lambda(w, a));
}

// Heitz 2018, listing 1: a point on the projected hemisphere of the stretched configuration.
fn ggx_visible_normal(wi: vec3<f32>, a: vec2<f32>, u: vec2<f32>) -> vec3<f32> {
    let vh = normalize(vec3<f32>(a.x * wi.x, a.y * wi.y, wi.z));
    let lensq = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if (lensq > 0.0) {
        t1 = vec3<f32>(-vh.y, vh.x, 0.0) * inverseSqrt(lensq);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u.x);
    let phi = 2.0 * GGX_PI * u.y;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * r * sin(phi);
    let nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3<f32>(a.x * nh.x, a.y * nh.y, max(0.0, nh.z)));
}

fn ggx_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let a = params[0].xy;
    let m = wi + d;
    if (wi.z <= 0.0 || dot(m, m) == 0.0) {
        return 0.0;
    }
    let h = normalize(m);
    if (dot(wi, h) <= 0.0) {
        return 0.0;
    }
    return ggx_g1(wi, a) * ggx_d(h, a) / (4.0 * wi.z);
}

fn ggx_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    if (wi.z <= 0.0) {
        return vec4<f32>(0.0, 0.0, 1.0, 0.0);
    }
    let h = ggx_visible_normal(wi, params[0].xy, u.xy);
    let d = 2.0 * dot(wi, h) * h - wi;
    return vec4<f32>(d, ggx_pdf(wi, d, params));
}

// f(wi, d) cos θd with height-correlated masking-shadowing G2 = 1 / (1 + Λ(wi) + Λ(d)) (Heitz 2014,
// eq. 99), no Fresnel: D G2 / (4 wi.z) above the horizon.
fn ggx_eval(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let a = params[0].xy;
    if (wi.z <= 0.0 || d.z <= 0.0) {
        return 0.0;
    }
    let h = normalize(wi + d);
    return ggx_d(h, a) / (4.0 * wi.z * (1.0 + ggx_lambda(wi, a) + ggx_lambda(d, a)));
}
