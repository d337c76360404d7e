// A mixture of two lobes chosen with u.z (give after ggx_vndf.wgsl): GGX reflection by visible
// normals with probability w, a cosine-weighted diffuse lobe (Malley's method over the polar
// map of the disk) otherwise. params[0].xyz = (αx, αy, w). The lobes overlap: the density of d is
//   p(d) = w p_ggx(d) + (1 − w) max(0, d.z) / π
// whichever lobe drew it (pbrt-v4's and Mitsuba's "mix" BSDFs). Incidence from below is rejected.

fn mix_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let w = params[0].z;
    if (wi.z <= 0.0) {
        return 0.0;
    }
    return w * ggx_pdf(wi, d, params) + (1.0 - w) * max(0.0, d.z) / GGX_PI;
}

fn mix_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    if (wi.z <= 0.0) {
        return vec4<f32>(0.0, 0.0, 1.0, 0.0);
    }
    var d: vec3<f32>;
    if (u.z < params[0].z) {
        let s = ggx_sample(wi, u, params);
        if (s.w <= 0.0) {
            return s;
        }
        d = s.xyz;
    } else {
        let r = sqrt(u.x);
        let phi = 2.0 * GGX_PI * u.y;
        d = vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
        // the rim of the disk, at f32 rounding, is a direction in the surface: reject it
        if (d.z <= 0.0) {
            return vec4<f32>(d, 0.0);
        }
    }
    return vec4<f32>(d, mix_pdf(wi, d, params));
}
