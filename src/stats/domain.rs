//! Where a sampler's points live and the grid they are binned on: the one place that knows a
//! domain's shape. A [`Domain`] says what a point is (a unit direction, or a point of a box); a
//! [`Grid`] of it says which cell a point falls in ([`Grid::cell_of`], the CPU twin of the
//! domain's binning WGSL, [`Domain::binning_wgsl`]), each cell's extent ([`Grid::cell`], what
//! the quadrature integrates), its neighbours and its centre.
//!
//! On the sphere, rows are uniform in cos θ ∈ [−1, 1] and columns in φ ∈ [−π, π), so every cell
//! spans 4π / (rows · cols) sr (Archimedes' hat-box theorem; [`SphereGrid`]); on the plane,
//! rows are uniform in y and columns in x over the box.

use super::histogram::SphereGrid;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Where the sampled points live.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "lowercase", tag = "kind")]
pub enum Domain {
    /// Unit directions anywhere on the sphere, binned in (cos θ, φ) as lobes bins its lobes.
    Sphere,
    /// Points (d.x, d.y) of the box `[x0, y0, x1, y1]`, binned on a rows × cols grid of it.
    Plane { bounds: [f64; 4] },
}

/// Why a box `[x0, y0, x1, y1]` is not one: the text a message quotes after naming its field.
#[derive(Debug, Clone, PartialEq)]
pub struct NotABox(pub [f64; 4]);

impl std::fmt::Display for NotABox {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let [x0, y0, x1, y1] = self.0;
        write!(f, "{x0},{y0},{x1},{y1} is not a box: need X0 < X1 and Y0 < Y1, all finite")
    }
}

impl Domain {
    /// The plane over the box `bounds = [x0, y0, x1, y1]`, which must have x0 < x1 and y0 < y1,
    /// all finite.
    ///
    /// ```
    /// use lobes::stats::domain::Domain;
    /// assert!(Domain::plane([0.0, 0.0, 1.0, 2.0]).is_ok());
    /// assert!(Domain::plane([1.0, 0.0, 0.0, 1.0]).is_err());
    /// ```
    pub fn plane(bounds: [f64; 4]) -> Result<Self, NotABox> {
        let [x0, y0, x1, y1] = bounds;
        let finite = bounds.iter().all(|v| v.is_finite());
        if finite && x0 < x1 && y0 < y1 { Ok(Domain::Plane { bounds }) } else { Err(NotABox(bounds)) }
    }

    /// Whether the box of a plane is one (the sphere always is a domain).
    pub fn validate(&self) -> Result<(), NotABox> {
        match *self {
            Domain::Plane { bounds } => Domain::plane(bounds).map(|_| ()),
            Domain::Sphere => Ok(()),
        }
    }

    /// Its name in scene files, flags and output files: `sphere` or `plane`.
    pub fn name(&self) -> &'static str {
        match self {
            Domain::Sphere => "sphere",
            Domain::Plane { .. } => "plane",
        }
    }

    /// The plane over the unit square `[0, 0, 1, 1]`.
    pub const UNIT_SQUARE: Domain = Domain::Plane { bounds: [0.0, 0.0, 1.0, 1.0] };

    /// The names of a grid's axes, rows' then columns': `["cos θ", "φ"]` on the sphere, `["y",
    /// "x"]` on the plane.
    pub fn axes(&self) -> [&'static str; 2] {
        match self {
            Domain::Sphere => ["cos θ", "φ"],
            Domain::Plane { .. } => ["y", "x"],
        }
    }

    /// Whether a grid's columns wrap around (φ = −π is φ = π), so the first column neighbours
    /// the last.
    pub fn columns_wrap(&self) -> bool {
        self.directions()
    }

    /// A picture's axes, rows' then columns': each label and the range it spans (cos θ over
    /// [−1, 1] and φ in degrees over [−180, 180) on the sphere; y and x over the box).
    pub fn picture_axes(&self) -> [(&'static str, (f64, f64)); 2] {
        match *self {
            Domain::Sphere => [("cos θ", (-1.0, 1.0)), ("φ (degrees)", (-180.0, 180.0))],
            Domain::Plane { bounds: [x0, y0, x1, y1] } => [("y", (y0, y1)), ("x", (x0, x1))],
        }
    }

    /// The names [`Domain::name`] gives, for messages that list them.
    pub const NAMES: [&'static str; 2] = ["sphere", "plane"];

    /// Whether a point is a direction from a shading point lit from an incident direction, so
    /// that incidence, frames, half vectors and solid angle apply to it.
    pub fn directions(&self) -> bool {
        matches!(self, Domain::Sphere)
    }

    /// A point as the domain reads it: a direction as it is, a point of the plane as (x, y, 0)
    /// (a sampler's z there is not part of its sample).
    pub fn point(&self, d: [f64; 3]) -> [f64; 3] {
        if self.directions() { d } else { [d[0], d[1], 0.0] }
    }

    /// The point at coordinates (a, b) of a quadrature part: on the sphere in hemisphere `h`
    /// (±1), with a = 1 − |cos θ| and b = φ, the direction (s cos φ, s sin φ, h (1 − a)),
    /// s = √(a (2 − a)), whose solid-angle element is da dφ; on the plane the point (a, b, 0).
    /// The f64 twin of `lobes_domain_point` ([`Domain::binning_wgsl`]).
    pub fn part_point(&self, a: f64, b: f64, h: f64) -> [f64; 3] {
        match self {
            Domain::Sphere => {
                let s = (a * (2.0 - a)).max(0.0).sqrt();
                [s * b.cos(), s * b.sin(), h * (1.0 - a)]
            }
            Domain::Plane { .. } => [a, b, 0.0],
        }
    }

    /// The box of a plane.
    pub fn bounds(&self) -> Option<[f64; 4]> {
        match *self {
            Domain::Plane { bounds } => Some(bounds),
            Domain::Sphere => None,
        }
    }

    /// The box the GPU's binning reads from its uniforms (unused on the sphere).
    pub fn uniform_bounds(&self) -> [f32; 4] {
        self.bounds().map_or([0.0; 4], |b| b.map(|v| v as f32))
    }

    /// The histogram's rows × cols unless asked for others: cells of about equal extent in
    /// both axes (64 × 128 over cos θ × φ on the sphere, 64 × 64 on the plane).
    pub fn default_grid(&self) -> (u32, u32) {
        match self {
            Domain::Sphere => (64, 128),
            Domain::Plane { .. } => (64, 64),
        }
    }

    /// The grid of `rows` × `cols` cells over it.
    pub fn grid(self, rows: u32, cols: u32) -> Grid {
        Grid { domain: self, rows, cols }
    }

    /// The WGSL file (its path in the repository) that maps the quadrature's coordinates to a point and a
    /// sample to its cell (`lobes::domain`), the GPU twin of [`Grid::cell_of`].
    pub fn binning_wgsl(&self) -> &'static str {
        match self {
            Domain::Sphere => "shaders/check/domain_sphere.wgsl",
            Domain::Plane { .. } => "shaders/check/domain_plane.wgsl",
        }
    }
}

/// A `rows` × `cols` grid over a domain, its cells numbered row-major.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub domain: Domain,
    pub rows: u32,
    pub cols: u32,
}

/// One cell's extent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cell {
    /// Row `row` of the sphere (its cos θ range is [`SphereGrid::cos_theta_edges`]') and the
    /// φ range of its column.
    Sphere { row: u32, phi: (f64, f64) },
    /// The x and y ranges of a cell of the plane.
    Plane { x: (f64, f64), y: (f64, f64) },
}

impl Grid {
    /// The number of cells.
    pub fn bins(&self) -> usize {
        self.rows as usize * self.cols as usize
    }

    /// The extent of cell `bin`.
    pub fn cell(&self, bin: usize) -> Cell {
        let (r, c) = (bin as u32 / self.cols, bin as u32 % self.cols);
        match self.domain {
            Domain::Sphere => {
                let phi = SphereGrid { rows: self.rows, cols: self.cols }.phi_edges();
                Cell::Sphere { row: r, phi: (phi[c as usize], phi[c as usize + 1]) }
            }
            Domain::Plane { bounds: [x0, y0, x1, y1] } => {
                let (dx, dy) = ((x1 - x0) / self.cols as f64, (y1 - y0) / self.rows as f64);
                Cell::Plane { x: (x0 + c as f64 * dx, x0 + (c + 1) as f64 * dx), y: (y0 + r as f64 * dy, y0 + (r + 1) as f64 * dy) }
            }
        }
    }

    /// The centre of every cell, row-major: on the sphere the direction at the middle of its
    /// cos θ and φ ranges, on the plane the point (x, y, 0).
    pub fn centres(&self) -> Vec<[f64; 3]> {
        let (rows, cols) = (self.rows, self.cols);
        (0..rows * cols)
            .map(|k| {
                let (r, c) = ((k / cols) as f64 + 0.5, (k % cols) as f64 + 0.5);
                match self.domain {
                    Domain::Sphere => {
                        let z = -1.0 + 2.0 * r / rows as f64;
                        let phi = -std::f64::consts::PI + 2.0 * std::f64::consts::PI * c / cols as f64;
                        let s = (1.0 - z * z).max(0.0).sqrt();
                        [s * phi.cos(), s * phi.sin(), z]
                    }
                    Domain::Plane { bounds: [x0, y0, x1, y1] } => [x0 + (x1 - x0) * c / cols as f64, y0 + (y1 - y0) * r / rows as f64, 0.0],
                }
            })
            .collect()
    }

    /// Cell `bin` and its (up to) eight neighbours, the cell first; columns wrap around on the
    /// sphere (φ = −π is φ = π), not on the plane.
    pub fn neighbourhood(&self, bin: usize) -> Vec<usize> {
        let (rows, cols) = (self.rows as i64, self.cols as i64);
        let (r, c) = (bin as i64 / cols, bin as i64 % cols);
        let wrap = self.domain.columns_wrap();
        let mut out = vec![bin];
        for (dr, dc) in [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)] {
            let (rr, mut cc) = (r + dr, c + dc);
            if wrap {
                cc = cc.rem_euclid(cols);
            }
            if (0..rows).contains(&rr) && (0..cols).contains(&cc) && (rr, cc) != (r, c) {
                out.push((rr * cols + cc) as usize);
            }
        }
        out
    }

    /// The cell of a point, `None` outside the domain: on the sphere a direction within 10⁻³ of
    /// unit length ([`SphereGrid::bin_of`]), on the plane (x, y) inside the box, its far edges
    /// in the last row and column. The CPU twin of `lobes_domain_cell` ([`Domain::binning_wgsl`]).
    pub fn cell_of(&self, p: [f64; 3]) -> Option<usize> {
        match self.domain {
            Domain::Sphere => {
                let d = DVec3::from(p);
                ((d.length() - 1.0).abs() <= 1e-3).then(|| SphereGrid { rows: self.rows, cols: self.cols }.bin_of(d))
            }
            Domain::Plane { bounds: [x0, y0, x1, y1] } => {
                let inside = (x0..=x1).contains(&p[0]) && (y0..=y1).contains(&p[1]);
                let index = |t: f64, n: u32| ((t * n as f64) as u32).min(n - 1);
                let (col, row) = (index((p[0] - x0) / (x1 - x0), self.cols), index((p[1] - y0) / (y1 - y0), self.rows));
                inside.then_some((row * self.cols + col) as usize)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_of_the_sphere_spans_four_pi_over_the_cells() {
        // ∫ over a cell of dω = Δ(cos θ) Δφ, the same for every cell (hat-box theorem)
        let g = Domain::Sphere.grid(8, 16);
        let z = SphereGrid { rows: 8, cols: 16 }.cos_theta_edges();
        for bin in 0..g.bins() {
            let Cell::Sphere { row, phi } = g.cell(bin) else { panic!("a sphere cell") };
            let area = (z[row as usize + 1] - z[row as usize]) * (phi.1 - phi.0);
            assert!((area - 4.0 * std::f64::consts::PI / 128.0).abs() < 1e-12, "cell {bin}: {area}");
        }
    }

    #[test]
    fn every_centre_falls_in_its_own_cell() {
        for g in [Domain::Sphere.grid(7, 12), Domain::plane([-1.0, 2.0, 3.0, 2.5]).unwrap().grid(5, 9)] {
            for (bin, c) in g.centres().into_iter().enumerate() {
                assert_eq!(g.cell_of(c), Some(bin), "{g:?}: the centre {c:?}");
            }
        }
    }

    #[test]
    fn points_outside_are_in_no_cell() {
        let plane = Domain::plane([0.0, 0.0, 1.0, 1.0]).unwrap().grid(4, 4);
        assert_eq!(plane.cell_of([1.0, 1.0, 0.0]), Some(15), "the far corner is in the last cell");
        assert_eq!(plane.cell_of([1.0 + 1e-12, 0.5, 0.0]), None);
        assert_eq!(Domain::Sphere.grid(4, 4).cell_of([0.0, 0.0, 1.01]), None, "not a unit direction");
    }

    #[test]
    fn neighbours_wrap_in_phi_on_the_sphere_only() {
        // cell 0 (row 0, column 0) of a 3 × 4 grid
        let mut sphere = Domain::Sphere.grid(3, 4).neighbourhood(0);
        sphere.sort();
        assert_eq!(sphere, vec![0, 1, 3, 4, 5, 7]);
        let mut plane = Domain::plane([0.0, 0.0, 1.0, 1.0]).unwrap().grid(3, 4).neighbourhood(0);
        plane.sort();
        assert_eq!(plane, vec![0, 1, 4, 5]);
    }

    #[test]
    fn a_box_must_be_one() {
        for b in [[0.0, 0.0, 0.0, 1.0], [0.0, 1.0, 1.0, 0.0], [0.0, 0.0, f64::INFINITY, 1.0], [f64::NAN, 0.0, 1.0, 1.0]] {
            assert!(Domain::plane(b).is_err(), "{b:?}");
        }
        assert_eq!(Domain::plane([0.0, 0.0, 1.0, 1.0]).unwrap().name(), "plane");
        assert_eq!(Domain::NAMES, [Domain::Sphere.name(), Domain::Plane { bounds: [0.0, 0.0, 1.0, 1.0] }.name()]);
    }
}
