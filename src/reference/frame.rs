//! Rotated anisotropy: the lobe's tangent frame turned about the normal. The CPU twin of
//! `frame_to_local` and `frame_to_world` in `shaders/lib/reflect.wgsl`.
//!
//! A lobe with frame angle φα has its αx axis along (cos φα, sin φα, 0) and its αy axis along
//! (−sin φα, cos φα, 0). Its densities and BRDF are those of the unrotated lobe in that frame:
//! p_φα(ωi, ωr) = p(R⁻¹ωi, R⁻¹ωr) with R the rotation by φα about +z, and it samples by drawing
//! h for R⁻¹ωi and returning R h (the reflection commutes with R). The samplers themselves never
//! see the angle.

use glam::DVec3;

/// The rotation by an angle about the normal (+z), as its cosine and sine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub cos: f64,
    pub sin: f64,
}

impl Frame {
    /// The frame turned by `angle` radians, counter-clockwise seen from above (+x towards +y).
    pub fn new(angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self { cos, sin }
    }

    /// R⁻¹w: world coordinates into the lobe's frame.
    pub fn to_local(self, w: DVec3) -> DVec3 {
        DVec3::new(self.cos * w.x + self.sin * w.y, -self.sin * w.x + self.cos * w.y, w.z)
    }

    /// R w: the lobe's frame into world coordinates.
    pub fn to_world(self, w: DVec3) -> DVec3 {
        DVec3::new(self.cos * w.x - self.sin * w.y, self.sin * w.x + self.cos * w.y, w.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quarter_turn_takes_x_to_y_and_back() {
        let f = Frame::new(std::f64::consts::FRAC_PI_2);
        assert!((f.to_world(DVec3::X) - DVec3::Y).length() < 1e-16);
        assert!((f.to_local(DVec3::Y) - DVec3::X).length() < 1e-16);
        let w = DVec3::new(0.3, -0.5, 0.81);
        let g = Frame::new(0.7);
        assert!((g.to_world(g.to_local(w)) - w).length() < 1e-15);
        assert_eq!(g.to_local(w).z, w.z);
    }
}
