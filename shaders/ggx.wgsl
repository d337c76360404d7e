// GGX (Trowbridge-Reitz); CPU twin: src/reference/ggx.rs.
// D(h) = 1 / (pi ax ay (hx^2/ax^2 + hy^2/ay^2 + hz^2)^2)                (Heitz 2014, eq. 85)
// G1(w) = 2|wz| / (|wz| + |(ax wx, ay wy, wz)|)                       (Heitz 2014, eq. 86)
// NDF sampling: cos^2 th = (1-u)/(1+(a^2-1)u) as the stretch of the cosine sample (Walter 2007, eq. 35).
// Visible normals: spherical caps (Dupuy & Benyoub 2023, listing 3); bounded caps for reflection
// (Eto & Tokuyoshi 2023, listings 1-2).

fn ggx_d(a: vec2<f32>, h: vec3<f32>) -> f32 {
    let q = h.xy / a;
    let e = dot(q, q) + h.z * h.z;
    return 1.0 / (PI * a.x * a.y * e * e);
}

fn ggx_g1(a: vec2<f32>, w: vec3<f32>) -> f32 {
    let z = abs(w.z);
    return 2.0 * z / (z + length(vec3<f32>(a * w.xy, w.z)));
}

fn ggx_sample_ndf(a: vec2<f32>, wi: vec3<f32>, u: vec2<f32>) -> LobeSample {
    let phi = 2.0 * PI * u.y;
    let r = sqrt(u.x);
    let h = normalize(vec3<f32>(a * (r * vec2<f32>(cos(phi), sin(phi))), sqrt(max(1.0 - u.x, 0.0))));
    return reflect_sample(wi, h, ggx_d(a, h) * h.z);
}

// A uniform point on the unit sphere's cap z >= -b, offset by ws and unstretched.
fn ggx_cap_sample(a: vec2<f32>, ws: vec3<f32>, b: f32, u: vec2<f32>) -> vec3<f32> {
    let phi = 2.0 * PI * u.x;
    let z = (1.0 - u.y) * (1.0 + b) - b;
    let st = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    let hs = vec3<f32>(st * cos(phi), st * sin(phi), z) + ws;
    return normalize(vec3<f32>(a * hs.xy, hs.z));
}

// p(wr) = G1(wi) D(h) / (4 cos th_i) (Heitz 2014, eq. 38 through the reflection Jacobian).
fn ggx_sample_vndf(a: vec2<f32>, wi: vec3<f32>, u: vec2<f32>) -> LobeSample {
    let ws = stretch(a, wi);
    let h = ggx_cap_sample(a, ws, ws.z, u);
    return LobeSample(h, reflect_about(wi, h), ggx_g1(a, wi) * ggx_d(a, h) / (4.0 * wi.z));
}

// Eto & Tokuyoshi 2023, listing 1: k shrinks the cap.
fn ggx_bounded_k(a: vec2<f32>, wi: vec3<f32>) -> f32 {
    let am = clamp(min(a.x, a.y), 0.0, 1.0);
    let s = 1.0 + length(wi.xy);
    let a2 = am * am;
    let s2 = s * s;
    return (1.0 - a2) * s2 / (s2 + a2 * wi.z * wi.z);
}

// Eto & Tokuyoshi 2023, listing 2: p(wr) = D(h) / (2 (k wi.z + t)), t = |(ax wi.x, ay wi.y, wi.z)|,
// for wi.z >= 0; D(h) (t - wi.z) / (2 |(ax wi.x, ay wi.y)|^2) below the horizon.
fn ggx_sample_bounded(a: vec2<f32>, wi: vec3<f32>, u: vec2<f32>) -> LobeSample {
    let ws = stretch(a, wi);
    let k = ggx_bounded_k(a, wi);
    let b = select(ws.z, k * ws.z, wi.z > 0.0);
    let h = ggx_cap_sample(a, ws, b, u);
    let d = ggx_d(a, h);
    let t = length(vec3<f32>(a * wi.xy, wi.z));
    var pdf: f32;
    if (wi.z >= 0.0) {
        pdf = d / (2.0 * (k * wi.z + t));
    } else {
        let l = a * wi.xy;
        pdf = d * (t - wi.z) / (2.0 * dot(l, l));
    }
    return LobeSample(h, reflect_about(wi, h), pdf);
}
