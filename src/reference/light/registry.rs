//! The light registry: one [`LightSpec`] per light sampler, the single list that `lobes check`'s
//! wrapper (`UserSampler::light`), `lobes run`'s `light = "NAME"` cases, `lobes stress` and the
//! tests take their lights from. An entry names the light, its WGSL module and call sites, the
//! layout of its parameters in the check's `params: array<vec4<f32>, 4>` (16 numbers, `params[k]`
//! holding numbers 4k..4k+3), their documented range, its f64 twin, and how to build a light of
//! a given solid angle in a given direction (the tests' and the default scene's sizes).

use super::disk::Disk;
use super::rect::{Rect, centred_solid_angle};
use super::sphere::Sphere;
use super::triangle_area::Triangle;
use super::{LightSample, to_world};
use glam::DVec3;
use std::f64::consts::PI;

/// A light's 16 parameters, as `lobes check` passes them (`params[k]` = numbers 4k..4k+3).
pub type LightParams = [f64; 16];

/// One light sampler.
#[derive(Debug, Clone, Copy)]
pub struct LightSpec {
    /// Its name in scenes (`light = "sphere"`) and reports.
    pub name: &'static str,
    /// The library module defining it (`#define_import_path` of its `shaders/lib` file), also
    /// its `lobes wgsl` and `lobes::embed` module (`lobes::sphere_light` is `sphere_light`).
    pub module: &'static str,
    /// `-> LightSample`, an expression in `params: array<vec4<f32>, 4>` and `u: vec2<f32>`.
    pub sample: &'static str,
    /// Its density per unit solid angle, an expression in `params` and the unit `d: vec3<f32>`.
    pub pdf: &'static str,
    /// What the parameters are, by position (for messages and docs).
    pub layout: &'static str,
    /// The parameters the sampler is documented for (and judged over: 10⁻⁶ sr to its largest).
    pub range: &'static str,
    /// The f64 twin: the sample at u and the density at d.
    pub sample_f64: fn(&LightParams, [f64; 2]) -> LightSample,
    pub pdf_f64: fn(&LightParams, DVec3) -> f64,
    /// The light of size s (radius or circumradius) at distance 1 along the unit `axis`, facing
    /// the origin, and the solid angle of that light in closed form (for [`LightSpec::sized`]).
    pub shape: fn(DVec3, f64) -> LightParams,
    pub solid_angle_of_size: fn(f64) -> f64,
    /// The largest solid angle `shape` reaches (sr).
    pub largest: f64,
}

fn vec(p: &LightParams, k: usize) -> DVec3 {
    DVec3::new(p[4 * k], p[4 * k + 1], p[4 * k + 2])
}

fn params(vs: &[DVec3], scalars: &[(usize, f64)]) -> LightParams {
    let mut p = [0.0; 16];
    for (k, v) in vs.iter().enumerate() {
        p[4 * k..4 * k + 3].copy_from_slice(&v.to_array());
    }
    for &(i, x) in scalars {
        p[i] = x;
    }
    p
}

fn sphere(p: &LightParams) -> Sphere {
    Sphere { centre: vec(p, 0), radius: p[3] }
}

fn disk(p: &LightParams) -> Disk {
    Disk { centre: vec(p, 0), normal: vec(p, 1).normalize(), radius: p[3] }
}

fn triangle(p: &LightParams) -> Triangle {
    Triangle { p: [vec(p, 0), vec(p, 1), vec(p, 2)] }
}

fn rect(p: &LightParams) -> Rect {
    Rect { corner: vec(p, 0), ex: vec(p, 1), ey: vec(p, 2) }
}

/// The equilateral triangle of circumradius s at distance 1 along `axis`, facing the origin.
fn equilateral(axis: DVec3, s: f64) -> LightParams {
    let corner = |k: f64| axis + to_world(axis, DVec3::new(s * (2.0 * PI * k / 3.0).cos(), s * (2.0 * PI * k / 3.0).sin(), 0.0));
    params(&[corner(0.0), corner(1.0), corner(2.0)], &[])
}

fn equilateral_solid_angle(s: f64) -> f64 {
    triangle(&equilateral(DVec3::Z, s)).solid_angle()
}

/// Every light sampler.
pub const LIGHTS: [LightSpec; 5] = [
    LightSpec {
        name: "sphere",
        module: "lobes::sphere_light",
        sample: "sphere_light_sample(params[0].xyz, params[0].w, u)",
        pdf: "sphere_light_pdf(params[0].xyz, params[0].w, d)",
        layout: "params[0] = (centre x, y, z, radius)",
        range: "radius > 0, the centre anywhere (inside the sphere: the whole sphere of directions)",
        sample_f64: |p, u| sphere(p).sample(u),
        pdf_f64: |p, d| sphere(p).pdf(d),
        shape: |axis, s| params(&[axis], &[(3, s)]),
        solid_angle_of_size: |s| sphere(&params(&[DVec3::Z], &[(3, s)])).solid_angle(),
        largest: 2.0 * PI,
    },
    LightSpec {
        name: "disk",
        module: "lobes::disk_light",
        sample: "disk_light_sample(params[0].xyz, normalize(params[1].xyz), params[0].w, u)",
        pdf: "disk_light_pdf(params[0].xyz, normalize(params[1].xyz), params[0].w, d)",
        layout: "params[0] = (centre x, y, z, radius), params[1].xyz = normal (normalised by lobes)",
        range: "radius > 0, the origin off the disk's plane",
        sample_f64: |p, u| disk(p).sample(u),
        pdf_f64: |p, d| disk(p).pdf(d),
        shape: |axis, s| params(&[axis, -axis], &[(3, s)]),
        solid_angle_of_size: |s| Disk::solid_angle_on_axis(1.0, s),
        largest: 2.0 * PI,
    },
    LightSpec {
        name: "triangle",
        module: "lobes::triangle_light",
        sample: "triangle_light_sample(params[0].xyz, params[1].xyz, params[2].xyz, u)",
        pdf: "triangle_light_pdf(params[0].xyz, params[1].xyz, params[2].xyz, d)",
        layout: "params[0].xyz, params[1].xyz, params[2].xyz = the vertices",
        range: "any triangle not through the origin (solid angle up to 2π)",
        sample_f64: |p, u| triangle(p).sample_spherical(u),
        pdf_f64: |p, d| triangle(p).pdf_spherical(d),
        shape: equilateral,
        solid_angle_of_size: equilateral_solid_angle,
        largest: 2.0 * PI,
    },
    LightSpec {
        name: "triangle-area",
        module: "lobes::triangle_area_light",
        sample: "triangle_area_light_sample(params[0].xyz, params[1].xyz, params[2].xyz, u)",
        pdf: "triangle_area_light_pdf(params[0].xyz, params[1].xyz, params[2].xyz, d)",
        layout: "params[0].xyz, params[1].xyz, params[2].xyz = the vertices",
        range: "any triangle of nonzero area, the origin off its plane",
        sample_f64: |p, u| triangle(p).sample_area(u),
        pdf_f64: |p, d| triangle(p).pdf_area(d),
        shape: equilateral,
        solid_angle_of_size: equilateral_solid_angle,
        largest: 2.0 * PI,
    },
    LightSpec {
        name: "rect",
        module: "lobes::rect_light",
        sample: "rect_light_sample(params[0].xyz, params[1].xyz, params[2].xyz, u)",
        pdf: "rect_light_pdf(params[0].xyz, params[1].xyz, params[2].xyz, d)",
        layout: "params[0].xyz = a corner, params[1].xyz and params[2].xyz = the two edges from it (perpendicular)",
        range: "perpendicular edges, the origin off the rectangle's plane (solid angle up to 2π)",
        sample_f64: |p, u| rect(p).sample(u),
        pdf_f64: |p, d| rect(p).pdf(d),
        shape: |axis, s| {
            let (ex, ey) = (to_world(axis, DVec3::new(2.0 * s, 0.0, 0.0)), to_world(axis, DVec3::new(0.0, 2.0 * s, 0.0)));
            params(&[axis - 0.5 * ex - 0.5 * ey, ex, ey], &[])
        },
        solid_angle_of_size: |s| centred_solid_angle(2.0 * s, 2.0 * s, 1.0),
        largest: 2.0 * PI,
    },
];

impl LightSpec {
    /// The light of solid angle `omega` (sr, below [`LightSpec::largest`]) centred on the direction
    /// at `elevation` degrees above the horizon (0: on it) and azimuth 30°, at distance 1
    /// (its size by bisection on the closed form).
    pub fn sized(&self, omega: f64, elevation: f64) -> LightParams {
        assert!(omega > 0.0 && omega < self.largest, "{}: a solid angle in (0, {}) sr", self.name, self.largest);
        let (mut lo, mut hi) = (1e-12f64, 1e6f64);
        for _ in 0..200 {
            let mid = (lo * hi).sqrt();
            if (self.solid_angle_of_size)(mid) < omega { lo = mid } else { hi = mid }
        }
        let (e, a) = (elevation.to_radians(), 30f64.to_radians());
        let axis = DVec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin());
        (self.shape)(axis, (lo * hi).sqrt())
    }

    /// The embed module's name (`sphere_light`): the module path's last part.
    pub fn module_name(&self) -> &'static str {
        self.module.rsplit("::").next().unwrap_or(self.module)
    }
}

/// The light named `name`.
pub fn by_name(name: &str) -> Option<&'static LightSpec> {
    LIGHTS.iter().find(|l| l.name == name.trim())
}

/// The names of the lights, for messages: `sphere, disk, …`.
pub fn names() -> String {
    LIGHTS.iter().map(|l| l.name).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `sized` reaches its solid angle, and the light's own solid angle (the twins' Van
    /// Oosterom–Strackee, cone and closed forms) agrees with the size's closed form.
    #[test]
    fn sized_lights_have_their_solid_angle() {
        for omega in [1e-6, 1e-2, 1.0, 5.0] {
            let s = sphere(&by_name("sphere").unwrap().sized(omega, 45.0));
            assert!((s.solid_angle() / omega - 1.0).abs() < 1e-9);
            let r = rect(&by_name("rect").unwrap().sized(omega, 0.0));
            assert!((r.solid_angle() / omega - 1.0).abs() < 1e-9, "{omega}: {}", r.solid_angle());
            let t = triangle(&by_name("triangle").unwrap().sized(omega, 90.0));
            assert!((t.solid_angle() / omega - 1.0).abs() < 1e-9);
        }
    }
}
