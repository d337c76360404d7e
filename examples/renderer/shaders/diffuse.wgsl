// The renderer's diffuse lobe: a Lambertian BRDF sampled cosine-weighted by Malley's method.
//
// Local shading frame: the normal is +z; wi points away from the surface (towards the viewer or
// the light it came from); θ is measured from +z and φ from +x. params[0].x is the albedo.
//
//   f(wi, wo) = albedo / π                          for wi.z > 0 and wo.z > 0
//   pdf(wo)   = cos θo / π                          (solid angle; 0 below the surface)
//   eval      = f · cos θo = albedo · cos θo / π    so eval / pdf = albedo exactly
//
// Malley's method: a uniform point (x, y) of the unit disk, lifted to the hemisphere,
// wo = (x, y, √(1 − x² − y²)). The disk's density is 1/π per unit area and dA = cos θo dω, so the
// direction's density is cos θo / π. The disk point comes from the concentric map of
// Shirley & Chiu (1997), "A Low Distortion Map Between Disk and Square", which keeps the
// stratification of u. Incident directions from below (wi.z ≤ 0) are rejected: pdf 0.

const DIFFUSE_PI: f32 = 3.14159265358979;

// The concentric map of the square [0, 1]² onto the unit disk.
fn diffuse_concentric_disk(u: vec2<f32>) -> vec2<f32> {
    let o = 2.0 * u - vec2<f32>(1.0);
    if (o.x == 0.0 && o.y == 0.0) {
        return vec2<f32>(0.0);
    }
    var r: f32;
    var theta: f32;
    if (abs(o.x) > abs(o.y)) {
        r = o.x;
        theta = (DIFFUSE_PI / 4.0) * (o.y / o.x);
    } else {
        r = o.y;
        theta = DIFFUSE_PI / 2.0 - (DIFFUSE_PI / 4.0) * (o.x / o.y);
    }
    return r * vec2<f32>(cos(theta), sin(theta));
}

fn diffuse_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    if (wi.z <= 0.0) {
        return vec4<f32>(0.0, 0.0, 1.0, 0.0);
    }
    let p = diffuse_concentric_disk(u.xy);
    let z = sqrt(max(0.0, 1.0 - dot(p, p)));
    // z = 0 (the rim of the disk, at f32 rounding) is a direction in the surface: reject it.
    return vec4<f32>(p, z, z / DIFFUSE_PI);
}

fn diffuse_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    if (wi.z <= 0.0) {
        return 0.0;
    }
    return max(0.0, d.z) / DIFFUSE_PI;
}

fn diffuse_eval(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return params[0].x * diffuse_pdf(wi, d, params);
}
