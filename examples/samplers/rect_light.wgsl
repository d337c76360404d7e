// A rectangular area light sampled by area, as renderers' light samplers are written: a point
// p uniform on the rectangle, relative to the shading point at the origin, with its density per
// unit area pdf_A = 1/A; its solid-angle density, for MIS, is pdf_A · |p|² / |n·d| (pbrt-v4
// §4.2.3). The rectangle is centred at c = (p0, p1, p2), axis-aligned with sides p3 (along x) and
// p4 (along y), in the plane z = p2 > 0, facing down (n = (0, 0, −1)).

fn rect_centre(params: array<vec4<f32>, 4>) -> vec3<f32> {
    return params[0].xyz;
}

fn rect_area(params: array<vec4<f32>, 4>) -> f32 {
    return params[0].w * params[1].x;
}

// (p, pdf_A): the point of the rectangle at (u.x, u.y), uniform in area.
fn rect_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let c = rect_centre(params);
    let p = c + vec3<f32>((u.x - 0.5) * params[0].w, (u.y - 0.5) * params[1].x, 0.0);
    return vec4<f32>(p, 1.0 / rect_area(params));
}

// Where the ray from the origin along d meets the light's plane, t along d (0: it does not, or
// it misses the rectangle).
fn rect_hit(d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let c = rect_centre(params);
    if (d.z <= 0.0) {
        return 0.0;
    }
    let t = c.z / d.z;
    let q = t * d - c;
    if (abs(q.x) > 0.5 * params[0].w || abs(q.y) > 0.5 * params[1].x) {
        return 0.0;
    }
    return t;
}

// The solid-angle density of rect_sample's directions: t² / (A |n·d|), |n·d| = d.z.
fn rect_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let t = rect_hit(d, params);
    if (t == 0.0) {
        return 0.0;
    }
    return t * t / (rect_area(params) * d.z);
}

// Broken: the density left per unit area, the classic MIS bug (1/A where the ray hits).
fn rect_pdf_area(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    if (rect_hit(d, params) == 0.0) {
        return 0.0;
    }
    return 1.0 / rect_area(params);
}

// Broken: converted without the cosine, t² / A.
fn rect_pdf_no_cosine(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    let t = rect_hit(d, params);
    return t * t / rect_area(params);
}

// Broken: the direction to the point with the area density, as a direction sampler would report
// it without converting (checked without --measure area).
fn rect_sample_unconverted(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let s = rect_sample(wi, u, params);
    return vec4<f32>(normalize(s.xyz), s.w);
}
