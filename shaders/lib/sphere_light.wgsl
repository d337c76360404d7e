#define_import_path lobes::sphere_light
#import lobes::light::{LightSample, LIGHT_PI, light_to_world}
//! embed: sphere_light
//! A sphere light (centre c, radius r), uniform in the cone it subtends.

// A sphere light (centre c, radius r) sampled uniformly over the cone of directions it
// subtends; CPU twin: src/reference/light/sphere.rs. The cone's half-angle θmax has
// sin² θmax = r²/|c|², and its solid angle Ω = 2π (1 − cos θmax) is computed as
//   1 − cos θmax = sin² θmax / (1 + cos θmax),
// which has no cancellation for a small light (1 − cos θmax in f32 is 0 below ~3e-8 sr).
// A shading point inside the sphere (|c| <= r) sees light in every direction: Ω = 4π.

// 1 − cos θmax of the light's cone (2 inside the sphere).
fn sphere_light_one_minus_cos(c: vec3<f32>, r: f32) -> f32 {
    let sin2 = r * r / dot(c, c);
    if (sin2 >= 1.0) {
        return 2.0;
    }
    return sin2 / (1.0 + sqrt(1.0 - sin2));
}

/// The solid angle the sphere subtends at the origin.
fn sphere_light_solid_angle(c: vec3<f32>, r: f32) -> f32 {
    return 2.0 * LIGHT_PI * sphere_light_one_minus_cos(c, r);
}

// d uniform in the cone: 1 − cos θ = u.x (1 − cos θmax), φ = 2π u.y about the axis c/|c|;
// sin θ = sqrt((1 − cos θ)(1 + cos θ)), again without the difference of nearly equal numbers.
/// A direction uniform in the cone the sphere (centre c, radius r) subtends.
fn sphere_light_sample(c: vec3<f32>, r: f32, u: vec2<f32>) -> LightSample {
    let omc_max = sphere_light_one_minus_cos(c, r);
    let omc = u.x * omc_max;
    let sin_t = sqrt(max(omc * (2.0 - omc), 0.0));
    let phi = 2.0 * LIGHT_PI * u.y;
    let local = vec3<f32>(sin_t * cos(phi), sin_t * sin(phi), 1.0 - omc);
    let d = normalize(light_to_world(normalize(c), local));
    return LightSample(d, 1.0 / (2.0 * LIGHT_PI * omc_max));
}

// The density of sphere_light_sample at the unit direction d: 1/Ω inside the cone, else 0.
// Inside is tested as |d × c|² <= r² with d·c > 0 (the ray's distance from c at most r), which
// stays exact where cos θ and cos θmax would round to the same f32.
/// The density of sphere_light_sample at the unit direction d: 1/Ω inside the cone, else 0.
fn sphere_light_pdf(c: vec3<f32>, r: f32, d: vec3<f32>) -> f32 {
    let x = cross(d, c);
    let inside = (dot(d, c) > 0.0 && dot(x, x) <= r * r) || dot(c, c) <= r * r;
    return select(0.0, 1.0 / sphere_light_solid_angle(c, r), inside);
}
