//! Binning of directions: the CPU twin of `shaders/lib/histogram.wgsl`'s `bin_of` and
//! `shaders/lib/bins.wgsl`.
//!
//! Bins are uniform in cos θ ∈ [−1, 1] (rows) and φ ∈ [−π, π) (columns), so every bin spans
//! the same solid angle 4π / (rows · cols) (Archimedes' hat-box theorem).

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Index `i` of `n` equal intervals whose middle edge, where `n` is even, lies on an axis (the
/// equator of a lat-long map, u = ½ or v = ½ of an equal-area one): kept in the first half where
/// `first`, else in the second, so a sign, not the rounding of the coordinate, places a point on
/// that edge. The WGSL twin is `lobes_half_by_sign` (`shaders/lib/bins.wgsl`).
pub fn half_by_sign(i: u32, n: u32, first: bool) -> u32 {
    match (n.is_multiple_of(2), first) {
        (false, _) => i,
        (true, true) => i.min(n / 2 - 1),
        (true, false) => i.max(n / 2),
    }
}

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
        (row * self.cols + self.column_of(w.x, w.y)) as usize
    }

    /// The column of a direction whose components across the axis are (x, y): ⌊(φ+π)/2π ·
    /// cols⌋ with φ = atan2(y, x), φ = π wrapped to column 0, φ = 0 at x = y = 0, exact on the
    /// axes' edges (`Self::axis_exact_column`).
    pub fn column_of(&self, x: f64, y: f64) -> u32 {
        let t = if x == 0.0 && y == 0.0 { 0.5 } else { (y.atan2(x) + PI) / (2.0 * PI) };
        let mut col = (t.max(0.0) * self.cols as f64) as u32;
        if col >= self.cols {
            col = 0;
        }
        if !(x == 0.0 && y == 0.0) {
            col = self.axis_exact_column(col, x, y);
        }
        col
    }

    /// `col`, from the rounded t, moved across the seam by the sign of y, and into the half (for an
    /// even `cols`) and quarter (for a multiple of 4) of the grid that the signs of x and y put w in: on the axes' edges
    /// (φ = 0, ±π/2, ±π) the column is exact, whatever t rounded to (φ = π − 1e-17 gives t = 1,
    /// column 0, in f64 as φ = π − 1e-7 does in f32). The WGSL twin is `lobes_axis_column`
    /// (`shaders/lib/bins.wgsl`), which the engine's `bin_of` and `lobes check`'s binning share.
    fn axis_exact_column(&self, col: u32, x: f64, y: f64) -> u32 {
        // the seam φ = ±π, an edge of every grid: column 0 lies below it (y ≤ 0), the last above
        let col = match col {
            0 if y > 0.0 && self.cols > 1 => self.cols - 1,
            c if c == self.cols - 1 && y < 0.0 && self.cols > 1 => 0,
            c => c,
        };
        if !self.cols.is_multiple_of(2) {
            return col;
        }
        // φ ∈ [0, π) for y > 0, or y = 0 at x ≥ 0; else [−π, 0) (y = ±0 at x < 0 is φ = ±π: column 0)
        let upper = y > 0.0 || (y == 0.0 && x >= 0.0);
        let half = self.cols / 2;
        let (mut lo, mut n) = (if upper { half } else { 0 }, half);
        if self.cols.is_multiple_of(4) && y != 0.0 && x != 0.0 {
            // φ ∈ [−π/2, π/2) for x > 0
            let q = self.cols / 4;
            lo = match (x > 0.0, upper) {
                (true, true) => half,
                (true, false) => q,
                (false, true) => 3 * q,
                (false, false) => 0,
            };
            n = q;
        }
        col.clamp(lo, lo + n - 1)
    }

    /// Whether the left edge of column `c` is one that `axis_exact_column` decides by the signs of
    /// x and y, exactly: the seam, and φ = 0 and ±π/2 where the columns divide them. Any other
    /// column edge is where the rounded t puts it (about 2·10⁻⁷ rad in f32).
    pub fn exact_phi_edge(&self, c: u32) -> bool {
        let cols = self.cols;
        c == 0 || (cols.is_multiple_of(2) && c == cols / 2) || (cols.is_multiple_of(4) && (c == cols / 4 || c == 3 * cols / 4))
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

    /// Beside an axis edge, closer than t resolves: φ = π − 1e-17 is the last column (t rounds
    /// to 1, which would wrap to column 0), φ = −1e-17 the column below φ = 0's, and so on.
    #[test]
    fn axis_edges_are_exact_below_the_rounding_of_t() {
        let g = SphereGrid { rows: 1, cols: 8 };
        let e = 1e-17;
        for (w, col) in [
            ((-1.0, e), 7),
            ((-1.0, -e), 0),
            ((1.0, e), 4),
            ((1.0, -e), 3),
            ((e, 1.0), 5),
            ((-e, 1.0), 6),
            ((e, -1.0), 2),
            ((-e, -1.0), 1),
        ] {
            assert_eq!(g.bin_of(DVec3::new(w.0, w.1, 0.0)), col, "{w:?}");
        }
        // the seam is an edge of every grid, an odd one too
        assert_eq!(SphereGrid { rows: 1, cols: 3 }.bin_of(DVec3::new(-1.0, e, 0.0)), 2);
        assert_eq!(SphereGrid { rows: 1, cols: 3 }.bin_of(DVec3::new(-1.0, -e, 0.0)), 0);
    }

    /// The edges called exact are the axes' that the columns divide, and `bin_of` places each of
    /// them to 10⁻¹⁷ rad on either side.
    #[test]
    fn exact_phi_edges_are_the_axes() {
        for (cols, exact) in [(8, vec![0, 2, 4, 6]), (6, vec![0, 3]), (5, vec![0])] {
            let g = SphereGrid { rows: 1, cols };
            assert_eq!((0..cols).filter(|&c| g.exact_phi_edge(c)).collect::<Vec<_>>(), exact, "{cols} columns");
            for &c in &exact {
                // an axis: its direction exactly (f64's sin π is 1.2e-16, not 0)
                let phi = g.phi_edges()[c as usize];
                let (s, co) = (phi.sin().round(), phi.cos().round());
                // turned by ±1e-17 about z: above the edge column c, below it the one before
                let turn = |e: f64| DVec3::new(co - e * s, s + e * co, 0.0);
                assert_eq!(g.bin_of(turn(1e-17)), c as usize, "{cols} columns, edge {c}");
                assert_eq!(g.bin_of(turn(-1e-17)), ((c + cols - 1) % cols) as usize, "{cols} columns, edge {c}");
            }
        }
    }
}
