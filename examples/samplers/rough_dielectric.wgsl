// A rough dielectric (rough glass) for `lobes check`: GGX visible normals over ggx_vndf.wgsl
// (give that file first), reflection with probability F and refraction otherwise (Walter et al.
// 2007, "Microfacet Models for Refraction through Rough Surfaces"). The f32 twin of lobes' f64
// reference, src/reference/dielectric.rs, which tests/dielectric.rs judges it against.
// params[0].xyz = (αx, αy, η), η = η_below / η_above; u.xy draw h, u.z chooses the event.
//   light from inside (wi.z < 0): mirror z, use 1/η, mirror the result back
//   h ~ D_wi(h) = G1(wi) (wi·h) D(h) / wi.z, c = wi·h
//   reflection:  d = 2c h − wi,                    p = F G1 D / (4 wi.z)
//   refraction:  d = (c/η − cos θt) h − wi/η,     p = T G1 c D / wi.z · J,
//                J = η² cos θt / (c − η cos θt)²  (eq. 17) = η² cos θt (c + η cos θt)² / (1 − η²)²
// J and T = 1 − F are in forms without cancellation (η → 1; F → 1 near the critical angle), see
// docs/rough-dielectric.md. A reflection through the surface or a refraction that stays on the
// incident side is rejected (pdf 0), as is light exactly along the surface.

// Snell's cos θt for cos θi = c in [0, 1], or −1 past the critical angle.
fn rd_cos_t(c: f32, eta: f32) -> f32 {
    let s2 = (1.0 - c * c) / (eta * eta);
    if (s2 >= 1.0) {
        return -1.0;
    }
    return sqrt(1.0 - s2);
}

fn rd_fresnel(c: f32, eta: f32) -> f32 {
    let ci = clamp(c, 0.0, 1.0);
    let ct = rd_cos_t(ci, eta);
    if (ct < 0.0) {
        return 1.0;
    }
    let rp = (eta * ci - ct) / (eta * ci + ct);
    let rs = (ci - eta * ct) / (ci + eta * ct);
    return 0.5 * (rp * rp + rs * rs);
}

// 1 − F as 2ηc cos θt (1/(ηc + cos θt)² + 1/(c + η cos θt)²): 1 − r² = 4ab/(a + b)².
fn rd_transmittance(c: f32, eta: f32) -> f32 {
    let ci = clamp(c, 0.0, 1.0);
    let ct = rd_cos_t(ci, eta);
    if (ct < 0.0) {
        return 0.0;
    }
    let p = eta * ci + ct;
    let s = ci + eta * ct;
    return 2.0 * eta * ci * ct * (1.0 / (p * p) + 1.0 / (s * s));
}

fn rd_jacobian_t(c: f32, ct: f32, eta: f32) -> f32 {
    let s = c + eta * ct;
    let k = (1.0 - eta) * (1.0 + eta);
    return eta * eta * ct * s * s / (k * k);
}

// (αx, αy, η seen from wi's side, +1 or −1 for the mirror of z).
fn rd_side(wi: vec3<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    if (wi.z < 0.0) {
        return vec4<f32>(params[0].xy, 1.0 / params[0].z, -1.0);
    }
    return vec4<f32>(params[0].xyz, 1.0);
}

// The density of d, mirrored to wi's upper side: reflected part there, refracted part across.
fn rd_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let side = rd_side(wi, params);
    let a = side.xy;
    let eta = side.z;
    let i = vec3<f32>(wi.xy, wi.z * side.w);
    let o = vec3<f32>(d.xy, d.z * side.w);
    if (i.z <= 0.0) {
        return 0.0;
    }
    if (o.z > 0.0) {
        let h = normalize(i + o);
        let c = dot(i, h);
        if (c <= 0.0) {
            return 0.0;
        }
        return rd_fresnel(c, eta) * ggx_g1(i, a) * ggx_d(h, a) / (4.0 * i.z);
    }
    let v = i + eta * o;
    if (o.z == 0.0 || v.z == 0.0) {
        return 0.0;
    }
    let h = normalize(v) * sign(v.z);
    let c = dot(i, h);
    let co = dot(o, h);
    if (c <= 0.0 || co >= 0.0) {
        return 0.0;
    }
    return rd_transmittance(c, eta) * ggx_g1(i, a) * c * ggx_d(h, a) / i.z * rd_jacobian_t(c, -co, eta);
}

// The reported pdf is rd_pdf of the sample's direction, as a renderer's eval/pdf forms both from
// d: near the critical angle T ∝ cos θt magnifies an f32 ulp of c = wi·h, and the h drawn and the
// h recomputed from d differ by such ulps (up to 5e-2 relative in T, measured at θi 140°, η 1.5).
fn rd_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let side = rd_side(wi, params);
    let a = side.xy;
    let eta = side.z;
    let i = vec3<f32>(wi.xy, wi.z * side.w);
    if (i.z <= 0.0) {
        return vec4<f32>(0.0, 0.0, 1.0, 0.0);
    }
    let h = ggx_visible_normal(i, a, u.xy);
    let c = dot(i, h);
    let ct = rd_cos_t(min(c, 1.0), eta);
    var o: vec3<f32>;
    var on_its_side: bool;
    if (c <= 0.0 || ct < 0.0 || u.z < rd_fresnel(c, eta)) {
        o = 2.0 * c * h - i;
        on_its_side = o.z > 0.0;
    } else {
        o = (c / eta - ct) * h - i / eta;
        on_its_side = o.z < 0.0;
    }
    let d = vec3<f32>(o.xy, o.z * side.w);
    return vec4<f32>(d, select(0.0, rd_pdf(wi, d, params), on_its_side));
}

// f |cos θo| with the dielectric's F and T and height-correlated masking-shadowing
// G2 = 1 / (1 + Λ(wi) + Λ(d)) (Heitz 2014, eq. 99, used for both events as pbrt-v4 does): the
// sampler's density with G1(wi) replaced by G2.
fn rd_eval(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let a = rd_side(wi, params).xy;
    if (wi.z == 0.0 || d.z == 0.0) {
        return 0.0;
    }
    let g2 = 1.0 / (1.0 + ggx_lambda(wi, a) + ggx_lambda(d, a));
    return rd_pdf(wi, d, params) * g2 / ggx_g1(wi, a);
}
