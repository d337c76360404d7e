#define_import_path lobes::disk_light
#import lobes::light::{LightSample, LIGHT_PI, light_to_world, light_area_to_solid_angle}
//! embed: disk_light
//! A disk light (centre, unit normal, radius), uniform by area.

// A disk light (centre c, unit normal n, radius r) sampled uniformly by area and converted to
// solid angle, pdf_ω = t² / (π r² |n·d|) at the point t d; CPU twin: src/reference/light/disk.rs.

// The point c + r sqrt(u.x) (cos 2πu.y, sin 2πu.y) in the disk's plane: uniform by area (the
// radius's density 2ρ/r² inverted), then its direction and density per unit solid angle.
/// A direction toward a point uniform by area on the disk (centre c, unit normal n, radius r).
fn disk_light_sample(c: vec3<f32>, n: vec3<f32>, r: f32, u: vec2<f32>) -> LightSample {
    let rho = r * sqrt(u.x);
    let phi = 2.0 * LIGHT_PI * u.y;
    let p = c + light_to_world(n, vec3<f32>(rho * cos(phi), rho * sin(phi), 0.0));
    let t = length(p);
    let d = p / t;
    return LightSample(d, light_area_to_solid_angle(1.0 / (LIGHT_PI * r * r), t, n, d));
}

// The density of disk_light_sample at the unit direction d: the ray t d meets the disk's plane
// at t = (n·c) / (n·d); inside the disk (|t d − c| <= r, t > 0) the area density converted,
// else 0.
/// The density of disk_light_sample at the unit direction d.
fn disk_light_pdf(c: vec3<f32>, n: vec3<f32>, r: f32, d: vec3<f32>) -> f32 {
    let t = dot(n, c) / dot(n, d);
    let q = t * d - c;
    let inside = t > 0.0 && dot(q, q) <= r * r;
    return select(0.0, light_area_to_solid_angle(1.0 / (LIGHT_PI * r * r), t, n, d), inside);
}
