//! The disk light, sampled uniformly by area and converted to solid angle: the CPU twin of
//! `shaders/lib/disk_light.wgsl`.

use super::{LightSample, area_to_solid_angle, to_world};
use glam::DVec3;
use std::f64::consts::PI;

/// A disk light: centre, unit normal, radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disk {
    pub centre: DVec3,
    pub normal: DVec3,
    pub radius: f64,
}

impl Disk {
    fn pdf_area(&self) -> f64 {
        1.0 / (PI * self.radius * self.radius)
    }

    /// The point c + r sqrt(u0) (cos 2πu1, sin 2πu1) of the disk's plane, its direction and
    /// density per unit solid angle t²/(π r² |n·d|).
    pub fn sample(&self, u: [f64; 2]) -> LightSample {
        let rho = self.radius * u[0].sqrt();
        let phi = 2.0 * PI * u[1];
        let p = self.centre + to_world(self.normal, DVec3::new(rho * phi.cos(), rho * phi.sin(), 0.0));
        let t = p.length();
        let d = p / t;
        LightSample { d, pdf: area_to_solid_angle(self.pdf_area(), t, self.normal, d) }
    }

    /// The density at the unit direction d: where t d (t = n·c / n·d > 0) is in the disk.
    pub fn pdf(&self, d: DVec3) -> f64 {
        let t = self.normal.dot(self.centre) / self.normal.dot(d);
        let inside = t > 0.0 && (t * d - self.centre).length_squared() <= self.radius * self.radius;
        if inside { area_to_solid_angle(self.pdf_area(), t, self.normal, d) } else { 0.0 }
    }

    /// The solid angle of a disk seen from a point on its axis at distance h:
    /// 2π (1 − h / sqrt(h² + r²)) (the cone through its rim), for the tests.
    pub fn solid_angle_on_axis(h: f64, r: f64) -> f64 {
        2.0 * PI * (1.0 - h / (h * h + r * r).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_lie_on_the_disk_and_their_pdf_is_the_functions() {
        let disk = Disk { centre: DVec3::new(0.2, 0.1, 1.5), normal: DVec3::new(0.1, -0.3, -1.0).normalize(), radius: 0.4 };
        for u in [[0.0, 0.0], [0.3, 0.9], [0.999, 0.2]] {
            let s = disk.sample(u);
            let t = disk.normal.dot(disk.centre) / disk.normal.dot(s.d);
            let off = t * s.d - disk.centre;
            assert!(off.dot(disk.normal).abs() < 1e-12 && (off.length() - 0.4 * u[0].sqrt()).abs() < 1e-12);
            assert!((disk.pdf(s.d) / s.pdf - 1.0).abs() < 1e-12);
        }
    }
}
