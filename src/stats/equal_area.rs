//! The octahedral equal-area map between the square and the sphere (Clarberg 2008, "Fast
//! Equal-Area Mapping of the (Hemi)Sphere using SIMD", JGT 13(3); pbrt-v4's
//! `EqualAreaSquareToSphere`, which environment maps stored as square images use). In centred
//! coordinates (s, t) ∈ [−1, 1]²: the diamond |s| + |t| ≤ 1 is the northern hemisphere, the four
//! corner triangles the southern, folded onto the diamond across its edges. With r the distance
//! from the diamond's centre in the L¹ norm and φ the angle within the quadrant,
//!
//!   r = |s| + |t| (north), z = 1 − r², ρ = √(1 − z²) = r √(2 − r²), φ = (π/2) |t| / r,
//!
//! so the area of the disc r ≤ R, 2R², maps to the cap 2π (1 − z) = 2π R²: every region of the
//! square maps to π times its area in sr (4 for the square, 4π for the sphere). The WGSL twin is
//! shaders/check/domain_equal_area.wgsl.

use glam::DVec3;
use std::f64::consts::FRAC_PI_2;

/// (|s|, |t|) of the southern triangles folded onto the diamond: the reflection across its edge
/// |s| + |t| = 1, (u, v) → (1 − v, 1 − u), which keeps v − u and so φ.
fn fold(u: f64, v: f64) -> (f64, f64) {
    (1.0 - v, 1.0 - u)
}

/// The direction at centred square coordinates (s, t) ∈ [−1, 1]² (the module's equations), its
/// components across z in the stable form: cos φ as sin((π/2) |s| / r), which keeps its digits
/// where φ is near π/2.
///
/// ```
/// use lobes::stats::equal_area::square_to_sphere;
/// assert_eq!(square_to_sphere(0.0, 0.0).z, 1.0);
/// assert_eq!(square_to_sphere(1.0, -1.0).z, -1.0);
/// let d = square_to_sphere(0.5, 0.5);
/// assert!(d.z.abs() < 1e-15 && (d.x - d.y).abs() < 1e-15);
/// ```
pub fn square_to_sphere(s: f64, t: f64) -> DVec3 {
    let (u, v) = (s.abs(), t.abs());
    let north = u + v <= 1.0;
    let (u, v) = if north { (u, v) } else { fold(u, v) };
    let r = u + v;
    let z = if north { 1.0 - r * r } else { r * r - 1.0 };
    if r == 0.0 {
        return DVec3::new(0.0, 0.0, z);
    }
    let rho = r * (2.0 - r * r).max(0.0).sqrt();
    let (x, y) = (rho * (FRAC_PI_2 * u / r).sin(), rho * (FRAC_PI_2 * v / r).sin());
    DVec3::new(if s < 0.0 { -x } else { x }, if t < 0.0 { -y } else { y }, z)
}

/// The centred square coordinates (s, t) of direction `d` (normalised here): the inverse of
/// [`square_to_sphere`]. r² = 1 − |z| in the stable form (x² + y²) / (|d| (|d| + |z|)), which
/// keeps a direction near a pole to its own precision; |s| = r (2/π) atan2(|x|, |y|) and |t| = r
/// (2/π) atan2(|y|, |x|), each accurate where it is small; the southern hemisphere folded out to
/// the corners; the signs of s and t those of x and y (−0 counted positive).
///
/// ```
/// use lobes::stats::equal_area::{sphere_to_square, square_to_sphere};
/// let (s, t) = sphere_to_square(glam::DVec3::new(0.3, -0.4, -0.866));
/// let d = square_to_sphere(s, t);
/// assert!((d - glam::DVec3::new(0.3, -0.4, -0.866).normalize()).length() < 1e-15);
/// ```
pub fn sphere_to_square(d: DVec3) -> (f64, f64) {
    let l = d.length();
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = ((x * x + y * y) / (l * (l + z))).sqrt();
    let (u, v) = if x == 0.0 && y == 0.0 { (0.0, 0.0) } else { (r * x.atan2(y) / FRAC_PI_2, r * y.atan2(x) / FRAC_PI_2) };
    let (u, v) = if d.z >= 0.0 { (u, v) } else { fold(u, v) };
    (if d.x < 0.0 { -u } else { u }, if d.y < 0.0 { -v } else { v })
}

/// The index of a centred coordinate c ∈ [−1, 1] among `n` equal intervals, c = 1 in the last;
/// where `n` is even, the middle edge (an axis: c = 0 at x = 0 or y = 0) placed by `negative`,
/// the sign of the component it came from, not by c's rounding.
pub fn index(c: f64, n: u32, negative: bool) -> u32 {
    let i = (((c + 1.0) * 0.5 * n as f64).max(0.0) as u32).min(n - 1);
    super::histogram::half_by_sign(i, n, negative)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_and_its_inverse_agree_over_the_sphere() {
        // directions on a 97 × 193 grid of (cos θ, φ), both hemispheres, both poles' neighbours
        for i in 0..=96 {
            for j in 0..193 {
                let z = -1.0 + 2.0 * i as f64 / 96.0;
                let phi = std::f64::consts::TAU * j as f64 / 193.0;
                let rho = (1.0 - z * z).max(0.0).sqrt();
                let d = DVec3::new(rho * phi.cos(), rho * phi.sin(), z);
                let (s, t) = sphere_to_square(d);
                assert!(s.abs() <= 1.0 && t.abs() <= 1.0, "{d}: ({s}, {t})");
                assert!((square_to_sphere(s, t) - d).length() < 1e-14, "{d}");
            }
        }
    }

    #[test]
    fn equal_areas_of_the_square_are_equal_solid_angles() {
        // directions uniform on the sphere (z uniform in [−1, 1], φ uniform: Archimedes), by a
        // stratified 1000 × 1000 grid of (z, φ), fall evenly on the 4 × 4 cells of the square:
        // each 1/16 of them, to the grid's discretisation (a cell's edge crosses ~3000 strata)
        let n = 1000;
        let mut counts = [0u32; 16];
        for i in 0..n {
            for j in 0..n {
                let z = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let phi = std::f64::consts::TAU * (j as f64 + 0.5) / n as f64;
                let rho = (1.0 - z * z).sqrt();
                let d = DVec3::new(rho * phi.cos(), rho * phi.sin(), z);
                let (s, t) = sphere_to_square(d);
                counts[(index(t, 4, d.y < 0.0) * 4 + index(s, 4, d.x < 0.0)) as usize] += 1;
            }
        }
        for (cell, &c) in counts.iter().enumerate() {
            let share = c as f64 / (n * n) as f64;
            assert!((share - 1.0 / 16.0).abs() < 2e-4, "cell {cell}: {share}");
        }
    }

    #[test]
    fn a_direction_near_a_pole_keeps_its_digits() {
        // 10⁻⁹ rad from +z: r² = 1 − cos θ = 2 sin²(θ/2), so r = √2 sin(θ/2) ≈ θ/√2; 1 − z would
        // keep none of θ's digits in f64
        let theta: f64 = 1e-9;
        let d = DVec3::new(theta.sin(), 0.0, theta.cos());
        let (s, t) = sphere_to_square(d);
        assert!((s / (theta / 2f64.sqrt()) - 1.0).abs() < 1e-12 && t == 0.0, "({s}, {t})");
    }

    #[test]
    fn an_axis_is_placed_by_the_sign_of_its_component() {
        assert_eq!(index(0.0, 4, false), 2);
        assert_eq!(index(-1e-300, 4, true), 1);
        assert_eq!(index(-0.0, 4, true), 1);
        assert_eq!(index(1.0, 4, false), 3);
        assert_eq!(index(-1.0, 4, true), 0);
        assert_eq!(index(0.0, 3, false), 1);
    }
}
