// BROKEN on purpose (give after ggx_vndf.wgsl and rough_dielectric.wgsl): rough_dielectric's
// samples with the refraction density of two classic bugs, the reflected part left right.
//   brd_no_eta2_*:      eq. 17's Jacobian without η_t², η² cos θt / (c − η cos θt)² → that / η²
//   brd_reflection_j_*: the reflection Jacobian 1/(4 |ωo·h|) used for transmission
// The samples are rough_dielectric's; the reported pdf is the pdf function's. `lobes check`
// must reject both (jacobian, chi2).

// (eq. 17's Jacobian, the wrong one of `which`: 0 without η², 1 the reflection's) for a d across
// the surface from wi, or (1, 1) elsewhere: the pdf's refracted part is rd_pdf's times the ratio.
fn brd_jacobians(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>, which: u32) -> vec2<f32> {
    let side = rd_side(wi, params);
    let eta = side.z;
    let i = vec3<f32>(wi.xy, wi.z * side.w);
    let o = vec3<f32>(d.xy, d.z * side.w);
    let v = i + eta * o;
    if (i.z <= 0.0 || o.z >= 0.0 || v.z == 0.0) {
        return vec2<f32>(1.0);
    }
    let h = normalize(v) * sign(v.z);
    let c = dot(i, h);
    let co = dot(o, h);
    if (c <= 0.0 || co >= 0.0) {
        return vec2<f32>(1.0);
    }
    let right = rd_jacobian_t(c, -co, eta);
    return vec2<f32>(right, select(right / (eta * eta), 1.0 / (4.0 * abs(co)), which == 1u));
}

fn brd_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>, which: u32) -> f32 {
    let j = brd_jacobians(wi, d, params, which);
    return rd_pdf(wi, d, params) / j.x * j.y;
}

fn brd_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>, which: u32) -> vec4<f32> {
    let s = rd_sample(wi, u, params);
    return vec4<f32>(s.xyz, select(0.0, brd_pdf(wi, s.xyz, params, which), s.w > 0.0));
}

fn brd_no_eta2_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return brd_pdf(wi, d, params, 0u);
}

fn brd_no_eta2_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    return brd_sample(wi, u, params, 0u);
}

fn brd_reflection_j_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return brd_pdf(wi, d, params, 1u);
}

fn brd_reflection_j_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    return brd_sample(wi, u, params, 1u);
}
