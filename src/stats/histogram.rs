//! Binning of directions: the CPU twin of `shaders/lib/histogram.wgsl`.
//!
//! Bins are uniform in cos θ ∈ [−1, 1] (rows) and φ ∈ [−π, π) (columns), so every bin spans
//! the same solid angle 4π / (rows · cols) (Archimedes' hat-box theorem).

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A rows × cols grid over the sphere, rows over cos θ from −1 (row 0) to 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SphereGrid {
    pub rows: u32,
    pub cols: u32,
}

impl SphereGrid {
    pub fn bins(&self) -> usize {
        self.rows as usize * self.cols as usize
    }

    /// The bin of a unit direction: row ⌊(z+1)/2 · rows⌋ (z = 1 in the top row), column
    /// ⌊(φ+π)/2π · cols⌋ with φ = π wrapped to column 0 and φ = 0 at the poles.
    pub fn bin_of(&self, w: DVec3) -> usize {
        let z = w.z.clamp(-1.0, 1.0);
        let row = (((z + 1.0) * 0.5 * self.rows as f64) as u32).min(self.rows - 1);
        // at the poles φ is undefined (atan2 of two zeros depends on their signs): use φ = 0
        let t = if w.x == 0.0 && w.y == 0.0 { 0.5 } else { (w.y.atan2(w.x) + PI) / (2.0 * PI) };
        let mut col = (t.max(0.0) * self.cols as f64) as u32;
        if col >= self.cols {
            col = 0;
        }
        (row * self.cols + col) as usize
    }

    /// The cos θ edges, rows + 1 of them, from −1 to 1.
    pub fn cos_theta_edges(&self) -> Vec<f64> {
        (0..=self.rows).map(|i| -1.0 + 2.0 * i as f64 / self.rows as f64).collect()
    }

    /// The φ edges, cols + 1 of them, from −π to π.
    pub fn phi_edges(&self) -> Vec<f64> {
        (0..=self.cols).map(|j| -PI + 2.0 * PI * j as f64 / self.cols as f64).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poles_edges_and_wraparound() {
        let g = SphereGrid { rows: 4, cols: 8 };
        assert_eq!(g.bin_of(DVec3::Z), 3 * 8 + 4); // cos θ = 1 → top row; φ = 0 → column 4
        assert_eq!(g.bin_of(-DVec3::Z) / 8, 0);
        assert_eq!(g.bin_of(DVec3::new(-1.0, 0.0, 0.0)) % 8, 0); // φ = +π wraps to column 0
        assert_eq!(g.bin_of(DVec3::new(-1.0, -0.0, 0.0)) % 8, 0); // φ = −π is column 0
        assert_eq!(g.bin_of(DVec3::new(1.0, 0.0, 0.0)) / 8, 2); // z = 0 is the edge: upper row
    }
}
