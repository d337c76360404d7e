//! Where a sampler's points live and the grid they are binned on: the one place that knows a
//! domain's shape. A [`Domain`] says what a point is (a unit direction, or a point of a box); a
//! [`Grid`] of it says which cell a point falls in ([`Grid::cell_of`], the CPU twin of the
//! domain's binning WGSL, [`Domain::binning_wgsl`]), each cell's extent ([`Grid::cell`], what
//! the quadrature integrates), its neighbours and its centre.
//!
//! On the sphere, rows are uniform in cos θ ∈ [−1, 1] and columns in φ ∈ [−π, π), so every cell
//! spans 4π / (rows · cols) sr (Archimedes' hat-box theorem; [`SphereGrid`]); on a cap about an
//! axis, rows are uniform in 1 − cos θ′ ∈ [0, h] and columns in φ′, θ′ and φ′ measured about the
//! axis, so every cell spans 2π h / (rows · cols) sr by the same theorem; on the plane, rows are
//! uniform in y and columns in x over the box; on an environment map's texels, rows uniform in θ
//! (lat-long) or in v of the octahedral equal-area square ([`super::equal_area`]), whose cells
//! again span equal solid angles.

use super::equal_area;
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
    /// Unit directions within the spherical cap about the unit `axis` of height `height` = 1 −
    /// cos ρ (ρ the cap's angular radius, ≤ π/2): the grid fitted around a small support (a
    /// light seen from afar), binned in (1 − cos θ′, φ′) about the axis ([`Frame`]). Both are
    /// f32 values, as the GPU's binning reads them.
    Cap { axis: [f64; 3], height: f64 },
    /// Unit directions binned on the texels of a latitude–longitude map: rows uniform in θ ∈
    /// [0, π] from +z (row 0 at θ = 0, a map's first row v = 0, v = θ/π), columns in φ =
    /// atan2(y, x) over [−π, π) as the sphere's (u = (φ + π)/2π). With `rows` × `cols` the
    /// map's texels, each cell is one texel: the histogram in texel space.
    #[serde(rename = "latlong")]
    LatLong,
    /// Unit directions binned on the texels of an octahedral equal-area map (Clarberg 2008, as
    /// pbrt-v4's environment maps): the unit square, columns along u and rows along v, +z at its
    /// centre and −z at its corners ([`super::equal_area`]). Every texel spans 4π / (rows · cols)
    /// sr; with `rows` × `cols` the map's texels, the histogram in texel space.
    #[serde(rename = "equal-area")]
    EqualArea,
}

/// √π: an equal-area map's quadrature coordinates are its centred square coordinates times it,
/// so that their area is the solid angle ([`Domain::part_point`]).
pub const SQRT_PI: f64 = 1.772_453_850_905_516;

/// The orthonormal frame (t, b, axis) of a cap: Duff et al. 2017, "Building an Orthonormal
/// Basis, Revisited" (JCGT 6(1)), listing 3, whose branchless form the WGSL twin
/// (`lobes_cap_frame`, shaders/check/domain_cap.wgsl) repeats.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub t: DVec3,
    pub b: DVec3,
    pub axis: DVec3,
}

impl Frame {
    pub fn of(axis: [f64; 3]) -> Self {
        let n = DVec3::from(axis);
        // the sign as the WGSL's select(−1, 1, n.z ≥ 0) takes it (+1 at −0)
        let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Frame { t: DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), b: DVec3::new(b, sign + n.y * n.y * a, -n.y), axis: n }
    }

    /// A direction's 1 − cos θ′ about the axis in the stable form |d × n|² / (|d| (|d| + d·n))
    /// (1 − cos θ′ itself loses every digit for a cap of 10⁻³ rad in f32), and its components
    /// (x, y) across it: ((1 − cos θ′), x, y).
    pub fn local(&self, d: DVec3) -> (f64, f64, f64) {
        let l = d.length();
        let z = d.dot(self.axis);
        let a = if z > 0.0 { d.cross(self.axis).length_squared() / (l * (l + z)) } else { 1.0 - z / l };
        (a, d.dot(self.t), d.dot(self.b))
    }

    /// The direction at local coordinates (a = 1 − cos θ′, φ′).
    pub fn direction(&self, a: f64, phi: f64) -> DVec3 {
        let s = (a * (2.0 - a)).max(0.0).sqrt();
        s * phi.cos() * self.t + s * phi.sin() * self.b + (1.0 - a) * self.axis
    }
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

    /// The cap about `axis` (a direction, normalised here) of height 1 − cos ρ = `height` ∈ (0,
    /// 1], both rounded to f32 as the GPU reads them; `None` for an axis that is not a
    /// direction or a height out of range.
    ///
    /// ```
    /// use lobes::stats::domain::Domain;
    /// let cap = Domain::cap([0.0, 0.0, 2.0], 1e-4).unwrap();
    /// assert!(cap.directions());
    /// assert!(Domain::cap([0.0, 0.0, 1.0], 1.5).is_none());
    /// ```
    pub fn cap(axis: [f64; 3], height: f64) -> Option<Self> {
        let n = DVec3::from(axis).normalize_or_zero();
        let axis = [n.x as f32 as f64, n.y as f32 as f64, n.z as f32 as f64];
        let height = height as f32 as f64;
        (n != DVec3::ZERO && height > 0.0 && height <= 1.0).then_some(Domain::Cap { axis, height })
    }

    /// Whether the box of a plane is one (the sphere and a cap always are domains).
    pub fn validate(&self) -> Result<(), NotABox> {
        match *self {
            Domain::Plane { bounds } => Domain::plane(bounds).map(|_| ()),
            Domain::Sphere | Domain::Cap { .. } | Domain::LatLong | Domain::EqualArea => Ok(()),
        }
    }

    /// A cap's frame.
    pub fn frame(&self) -> Option<Frame> {
        self.as_cap().map(|(axis, _)| Frame::of(axis))
    }

    /// A cap's axis and height.
    pub fn as_cap(&self) -> Option<([f64; 3], f64)> {
        match *self {
            Domain::Cap { axis, height } => Some((axis, height)),
            _ => None,
        }
    }

    /// A cap's angular radius ρ = 2 asin √(h/2), from h = 1 − cos ρ without its cancellation;
    /// `None` for the domains that are not fitted to a support.
    pub fn cap_radius(&self) -> Option<f64> {
        self.as_cap().map(|(_, height)| 2.0 * (0.5 * height).sqrt().asin())
    }

    /// Whether it is the (cos θ, φ) grid of the whole sphere: the grid `lobes run`'s lobes are
    /// binned on, and the only one a cap is fitted within ([`crate::check::support`]).
    pub fn is_sphere(&self) -> bool {
        matches!(self, Domain::Sphere)
    }

    /// The solid angle it spans (sr): 4π, a cap's 2π h; `None` on the plane.
    pub fn solid_angle(&self) -> Option<f64> {
        match *self {
            Domain::Sphere | Domain::LatLong | Domain::EqualArea => Some(4.0 * std::f64::consts::PI),
            Domain::Cap { height, .. } => Some(2.0 * std::f64::consts::PI * height),
            Domain::Plane { .. } => None,
        }
    }

    /// Its name in scene files, flags and output files: `sphere`, `plane`, `latlong`,
    /// `equal-area` or `cap` (a cap is fitted, not named by users: [`Self::NAMES`] leaves it out).
    pub fn name(&self) -> &'static str {
        match self {
            Domain::Sphere => "sphere",
            Domain::Plane { .. } => "plane",
            Domain::Cap { .. } => "cap",
            Domain::LatLong => "latlong",
            Domain::EqualArea => "equal-area",
        }
    }

    /// What its grid bins, in words for captions: `the sphere`, `the plane`, `a cap fitted to its
    /// samples`, `a lat-long map's texels`, `an equal-area map's texels`.
    pub fn in_words(&self) -> &'static str {
        match self {
            Domain::Sphere => "the sphere",
            Domain::Plane { .. } => "the plane",
            Domain::Cap { .. } => "a cap fitted to its samples",
            Domain::LatLong => "a lat-long map's texels",
            Domain::EqualArea => "an equal-area map's texels",
        }
    }

    /// [`Self::in_words`] of the domain called `name` ([`Self::name`]), for a record that keeps
    /// only its name; `None` for a name no domain has.
    pub fn words_for_name(name: &str) -> Option<&'static str> {
        let cap = Domain::Cap { axis: [0.0, 0.0, 1.0], height: 1.0 };
        [Domain::Sphere, Domain::UNIT_SQUARE, cap, Domain::LatLong, Domain::EqualArea].into_iter().find(|d| d.name() == name).map(|d| d.in_words())
    }

    /// The plane over the unit square `[0, 0, 1, 1]`.
    pub const UNIT_SQUARE: Domain = Domain::Plane { bounds: [0.0, 0.0, 1.0, 1.0] };

    /// The names of a grid's axes, rows' then columns': `["cos θ", "φ"]` on the sphere, `["y",
    /// "x"]` on the plane, `["θ", "φ"]` on a lat-long map, `["v", "u"]` on an equal-area one.
    pub fn axes(&self) -> [&'static str; 2] {
        match self {
            Domain::Sphere => ["cos θ", "φ"],
            Domain::Plane { .. } => ["y", "x"],
            Domain::Cap { .. } => ["1 − cos θ′", "φ′"],
            Domain::LatLong => ["θ", "φ"],
            Domain::EqualArea => ["v", "u"],
        }
    }

    /// Whether a grid's columns wrap around (φ = −π is φ = π), so the first column neighbours
    /// the last (an equal-area map's edges fold onto themselves instead, across their midpoints).
    pub fn columns_wrap(&self) -> bool {
        matches!(self, Domain::Sphere | Domain::Cap { .. } | Domain::LatLong)
    }

    /// Whether a picture may start its wrapping columns where the density is not cut in two (a
    /// lobe about φ = ±π drawn whole); a lat-long map is drawn as its texture lies, from u = 0.
    pub fn pictures_turn_columns(&self) -> bool {
        matches!(self, Domain::Sphere | Domain::Cap { .. })
    }

    /// A picture's axes, rows' then columns': each label and the range it spans (cos θ over
    /// [−1, 1] and φ in degrees over [−180, 180) on the sphere; y and x over the box).
    pub fn picture_axes(&self) -> [(&'static str, (f64, f64)); 2] {
        match *self {
            Domain::Sphere => [("cos θ", (-1.0, 1.0)), ("φ (degrees)", (-180.0, 180.0))],
            Domain::Plane { bounds: [x0, y0, x1, y1] } => [("y", (y0, y1)), ("x", (x0, x1))],
            Domain::Cap { height, .. } => [("1 − cos θ′ (θ′ from the cap's axis)", (0.0, height)), ("φ′ (degrees)", (-180.0, 180.0))],
            Domain::LatLong => [("θ (degrees; texel row v = θ/180°)", (0.0, 180.0)), ("φ (degrees; u = (φ + 180°)/360°)", (-180.0, 180.0))],
            Domain::EqualArea => [("v (texel row; +z at the centre, −z at the corners)", (0.0, 1.0)), ("u (texel column)", (0.0, 1.0))],
        }
    }

    /// The domain of unit directions named `name` ([`Self::name`]: `sphere`, `latlong` or
    /// `equal-area`); `None` for `plane`, which needs its box ([`Self::plane`]), and for other
    /// names.
    ///
    /// ```
    /// use lobes::stats::domain::Domain;
    /// assert_eq!(Domain::of_directions("latlong"), Some(Domain::LatLong));
    /// assert_eq!(Domain::of_directions("plane"), None);
    /// ```
    pub fn of_directions(name: &str) -> Option<Domain> {
        [Domain::Sphere, Domain::LatLong, Domain::EqualArea].into_iter().find(|d| d.name() == name)
    }

    /// The names [`Domain::name`] gives, for messages that list them.
    pub const NAMES: [&'static str; 4] = ["sphere", "plane", "latlong", "equal-area"];

    /// Whether a point is a direction from a shading point lit from an incident direction, so
    /// that incidence, frames, half vectors and solid angle apply to it.
    pub fn directions(&self) -> bool {
        matches!(self, Domain::Sphere | Domain::Cap { .. } | Domain::LatLong | Domain::EqualArea)
    }

    /// Whether f32 binning places its column edges off the axes coarser than a sample's own
    /// rounding: on the sphere, where φ = atan2(y, x) rounds to 2·10⁻⁷ rad near ±π wherever the
    /// direction is (`quadrature::edge_strips`). On the plane x and y themselves are binned; on
    /// a cap, φ′ comes from the direction's components across the axis, whose rounding is the
    /// sample's own.
    pub fn rounds_phi_edges(&self) -> bool {
        self.is_sphere()
    }

    /// A point as the domain reads it: a direction as it is, a point of the plane as (x, y, 0)
    /// (a sampler's z there is not part of its sample).
    pub fn point(&self, d: [f64; 3]) -> [f64; 3] {
        if self.directions() { d } else { [d[0], d[1], 0.0] }
    }

    /// The point at coordinates (a, b) of a quadrature part: on the sphere in hemisphere `h`
    /// (±1), with a = 1 − |cos θ| and b = φ, the direction (s cos φ, s sin φ, h (1 − a)),
    /// s = √(a (2 − a)), whose solid-angle element is da dφ; on a cap the same about its axis
    /// ([`Frame::direction`], h = 1); on the plane the point (a, b, 0); on an equal-area map
    /// (h = 0) the direction at centred square coordinates (s, t) = (a, b)/√π
    /// ([`super::equal_area::square_to_sphere`]), so that da db = π ds dt is the solid angle.
    /// The f64 twin of `lobes_domain_point` ([`Domain::binning_wgsl`]).
    pub fn part_point(&self, a: f64, b: f64, h: f64) -> [f64; 3] {
        match self {
            Domain::Sphere | Domain::LatLong => {
                let s = (a * (2.0 - a)).max(0.0).sqrt();
                [s * b.cos(), s * b.sin(), h * (1.0 - a)]
            }
            Domain::Cap { axis, .. } => Frame::of(*axis).direction(a, b).into(),
            Domain::Plane { .. } => [a, b, 0.0],
            Domain::EqualArea => equal_area::square_to_sphere(a / SQRT_PI, b / SQRT_PI).into(),
        }
    }

    /// [`Domain::part_point`] with b given as (b, cos b, sin b) and a cap's `frame` given, so
    /// that a quadrature computes them once per node of its rule rather than per point.
    pub fn part_point_at(&self, frame: Option<&Frame>, a: f64, (b, cos, sin): (f64, f64, f64), h: f32) -> DVec3 {
        let s = || (a * (2.0 - a)).max(0.0).sqrt();
        match (self, frame) {
            (Domain::Plane { .. }, _) => DVec3::new(a, b, 0.0),
            (Domain::EqualArea, _) => DVec3::from(self.part_point(a, b, 0.0)),
            (Domain::Cap { .. }, Some(frame)) => s() * cos * frame.t + s() * sin * frame.b + (1.0 - a) * frame.axis,
            _ => DVec3::new(s() * cos, s() * sin, h as f64 * (1.0 - a)),
        }
    }

    /// The coordinates (a, b, hemisphere) of a quadrature part at point `p`: the inverse of
    /// [`Domain::part_point`], b in [−π, π] as the grid's columns.
    ///
    /// ```
    /// use lobes::stats::domain::Domain;
    /// let (a, b, h) = Domain::Sphere.part_coordinates([0.0, -0.6, -0.8]);
    /// assert!((a - 0.2).abs() < 1e-15 && (b + std::f64::consts::FRAC_PI_2).abs() < 1e-15 && h == -1.0);
    /// let p = Domain::Sphere.part_point(a, b, h as f64);
    /// assert!((p[1] + 0.6).abs() < 1e-15 && (p[2] + 0.8).abs() < 1e-15);
    /// ```
    pub fn part_coordinates(&self, p: [f64; 3]) -> (f64, f64, f32) {
        match self {
            Domain::Sphere | Domain::LatLong => (1.0 - p[2].abs(), p[1].atan2(p[0]), if p[2] < 0.0 { -1.0 } else { 1.0 }),
            Domain::Cap { axis, .. } => {
                let (a, x, y) = Frame::of(*axis).local(DVec3::from(p));
                (a, y.atan2(x), 1.0)
            }
            Domain::Plane { .. } => (p[0], p[1], 0.0),
            Domain::EqualArea => {
                let (s, t) = equal_area::sphere_to_square(DVec3::from(p));
                (SQRT_PI * s, SQRT_PI * t, 0.0)
            }
        }
    }

    /// The box of a plane.
    pub fn bounds(&self) -> Option<[f64; 4]> {
        match *self {
            Domain::Plane { bounds } => Some(bounds),
            Domain::Sphere | Domain::Cap { .. } | Domain::LatLong | Domain::EqualArea => None,
        }
    }

    /// What the GPU's binning reads from its uniforms: the plane's box, a cap's (axis,
    /// height); unused on the sphere.
    pub fn uniform_bounds(&self) -> [f32; 4] {
        match *self {
            Domain::Cap { axis: [x, y, z], height } => [x as f32, y as f32, z as f32, height as f32],
            _ => self.bounds().map_or([0.0; 4], |b| b.map(|v| v as f32)),
        }
    }

    /// The histogram's rows × cols unless asked for others: cells of about equal extent in
    /// both axes (64 × 128 over cos θ × φ on the sphere, 64 × 64 on the plane); on a cap 16 × 32,
    /// as many cells as a support of 0.8 sr gets on the sphere, with the outer row's width in
    /// θ′ (3 % of ρ) far above f32's resolution of a direction even at 10⁻⁶ sr.
    pub fn default_grid(&self) -> (u32, u32) {
        match self {
            Domain::Sphere => (64, 128),
            Domain::Plane { .. } => (64, 64),
            Domain::Cap { .. } => (16, 32),
            Domain::LatLong => (32, 64),
            Domain::EqualArea => (64, 64),
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
            Domain::Cap { .. } => "shaders/check/domain_cap.wgsl",
            Domain::LatLong => "shaders/check/domain_latlong.wgsl",
            Domain::EqualArea => "shaders/check/domain_equal_area.wgsl",
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
    /// The 1 − cos θ′ and φ′ ranges of a cell of a cap.
    Cap { a: (f64, f64), phi: (f64, f64) },
    /// The θ and φ ranges of a texel of a lat-long map.
    LatLong { theta: (f64, f64), phi: (f64, f64) },
    /// The ranges of centred square coordinates s = 2u − 1 and t = 2v − 1 of a texel of an
    /// equal-area map ([`super::equal_area`]).
    EqualArea { s: (f64, f64), t: (f64, f64) },
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
            Domain::Cap { height, .. } => {
                let phi = SphereGrid { rows: self.rows, cols: self.cols }.phi_edges();
                let da = height / self.rows as f64;
                Cell::Cap { a: (r as f64 * da, (r + 1) as f64 * da), phi: (phi[c as usize], phi[c as usize + 1]) }
            }
            Domain::LatLong => {
                let phi = SphereGrid { rows: self.rows, cols: self.cols }.phi_edges();
                let theta = latlong_theta_edges(self.rows);
                Cell::LatLong { theta: (theta[r as usize], theta[r as usize + 1]), phi: (phi[c as usize], phi[c as usize + 1]) }
            }
            Domain::EqualArea => {
                let edge = |i: u32, n: u32| 2.0 * i as f64 / n as f64 - 1.0;
                Cell::EqualArea { s: (edge(c, self.cols), edge(c + 1, self.cols)), t: (edge(r, self.rows), edge(r + 1, self.rows)) }
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
                    Domain::Cap { height, .. } => {
                        let phi = -std::f64::consts::PI + 2.0 * std::f64::consts::PI * c / cols as f64;
                        self.domain.part_point(height * r / rows as f64, phi, 1.0)
                    }
                    Domain::LatLong => {
                        let (theta, phi) = (std::f64::consts::PI * r / rows as f64, -std::f64::consts::PI + 2.0 * std::f64::consts::PI * c / cols as f64);
                        [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()]
                    }
                    Domain::EqualArea => equal_area::square_to_sphere(2.0 * c / cols as f64 - 1.0, 2.0 * r / rows as f64 - 1.0).into(),
                }
            })
            .collect()
    }

    /// Cell `bin` and its (up to) eight neighbours, the cell first; columns wrap around on the
    /// sphere (φ = −π is φ = π), not on the plane or an equal-area map.
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
    /// unit length ([`SphereGrid::bin_of`]), on a cap such a direction with 1 − cos θ′ ≤ h
    /// ([`Frame::local`], its column as the sphere's), on the plane (x, y) inside the box, its far
    /// edges in the last row and column. The CPU twin of `lobes_domain_cell` ([`Domain::binning_wgsl`]).
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
            Domain::Cap { axis, height } => {
                let d = DVec3::from(p);
                let (a, x, y) = Frame::of(axis).local(d);
                if (d.length() - 1.0).abs() > 1e-3 || a.is_nan() || a > height {
                    return None;
                }
                let row = ((a / height * self.rows as f64) as u32).min(self.rows - 1);
                Some((row * self.cols + SphereGrid { rows: self.rows, cols: self.cols }.column_of(x, y)) as usize)
            }
            Domain::LatLong => {
                let d = DVec3::from(p);
                ((d.length() - 1.0).abs() <= 1e-3).then(|| (latlong_row(d, self.rows) * self.cols + SphereGrid { rows: self.rows, cols: self.cols }.column_of(d.x, d.y)) as usize)
            }
            Domain::EqualArea => {
                let d = DVec3::from(p);
                let (s, t) = equal_area::sphere_to_square(d);
                let (row, col) = (equal_area::index(t, self.rows, d.y < 0.0), equal_area::index(s, self.cols, d.x < 0.0));
                ((d.length() - 1.0).abs() <= 1e-3).then_some((row * self.cols + col) as usize)
            }
        }
    }
}

/// The θ edges of a lat-long map's `rows` rows, from 0 to π.
pub fn latlong_theta_edges(rows: u32) -> Vec<f64> {
    (0..=rows).map(|i| std::f64::consts::PI * i as f64 / rows as f64).collect()
}

/// The row of direction `d` on a lat-long map of `rows` rows: ⌊θ/π · rows⌋ with θ =
/// atan2(√(x² + y²), z) (accurate at the poles, where acos(z) loses half its digits), in the
/// northern half of the rows for z ≥ 0 and the southern for z < 0 where `rows` is even (the
/// equator, a row edge, placed by the sign of z as the sphere's axis columns are by signs).
/// The CPU twin of `lobes_domain_cell` (shaders/check/domain_latlong.wgsl).
pub fn latlong_row(d: DVec3, rows: u32) -> u32 {
    let theta = d.x.hypot(d.y).atan2(d.z);
    let row = ((theta / std::f64::consts::PI * rows as f64) as u32).min(rows - 1);
    super::histogram::half_by_sign(row, rows, d.z >= 0.0)
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
    fn a_texel_of_a_latlong_map_is_its_cell() {
        // 4 × 8 texels: the direction at texel (row j, column i)'s centre, θ = π (j + ½)/4 and
        // φ = 2π (i + ½)/8 − π, falls in cell 8 j + i; the texels' solid angles (cos θ0 − cos θ1)
        // Δφ add to 4π
        let g = Domain::LatLong.grid(4, 8);
        let mut total = 0.0;
        for bin in 0..g.bins() {
            let (j, i) = ((bin / 8) as f64, (bin % 8) as f64);
            let (theta, phi) = (std::f64::consts::PI * (j + 0.5) / 4.0, std::f64::consts::TAU * (i + 0.5) / 8.0 - std::f64::consts::PI);
            let d = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
            assert_eq!(g.cell_of(d), Some(bin), "texel {j}, {i}");
            let Cell::LatLong { theta, phi } = g.cell(bin) else { panic!("a texel") };
            assert!((theta.0 - std::f64::consts::PI * j / 4.0).abs() < 1e-15 && (phi.1 - phi.0 - std::f64::consts::TAU / 8.0).abs() < 1e-15);
            total += (theta.0.cos() - theta.1.cos()) * (phi.1 - phi.0);
        }
        assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-12, "{total}");
        // the equator (a row edge of an even grid) by the sign of z, the poles in the first and last rows
        assert_eq!(g.cell_of([1.0, 0.0, 0.0]).map(|c| c / 8), Some(1));
        assert_eq!(g.cell_of([1.0, 0.0, -1e-300]).map(|c| c / 8), Some(2));
        assert_eq!(g.cell_of([0.0, 0.0, 1.0]).map(|c| c / 8), Some(0));
        assert_eq!(g.cell_of([1e-9, 0.0, -1.0]).map(|c| c / 8), Some(3));
        assert_eq!(g.cell_of([0.0, 0.0, 2.0]), None, "not a direction");
    }

    #[test]
    fn a_texel_of_an_equal_area_map_is_its_cell() {
        // 6 × 4 texels (rows × columns): points of a 9 × 9 grid inside each texel, mapped to the
        // sphere, fall in that texel, and their quadrature coordinates are √π times the centred
        // square's; the texels' areas in those coordinates add to 4π
        let g = Domain::EqualArea.grid(6, 4);
        let mut total = 0.0;
        for bin in 0..g.bins() {
            let Cell::EqualArea { s, t } = g.cell(bin) else { panic!("a texel") };
            total += SQRT_PI * (s.1 - s.0) * SQRT_PI * (t.1 - t.0);
            for (x, y) in (0..9).flat_map(|i| (0..9).map(move |j| ((i as f64 + 0.5) / 9.0, (j as f64 + 0.5) / 9.0))) {
                let (sx, ty) = (s.0 + x * (s.1 - s.0), t.0 + y * (t.1 - t.0));
                let d = Domain::EqualArea.part_point(SQRT_PI * sx, SQRT_PI * ty, 0.0);
                assert_eq!(g.cell_of(d), Some(bin), "({sx}, {ty})");
                let (a, b, h) = Domain::EqualArea.part_coordinates(d);
                assert!((a - SQRT_PI * sx).abs() < 1e-13 && (b - SQRT_PI * ty).abs() < 1e-13 && h == 0.0, "({sx}, {ty})");
            }
        }
        assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-12, "{total}");
        // +z at the centre (an axis of an even grid: by the signs), −z at a corner, the sign of
        // a component deciding the middle edge
        let g = Domain::EqualArea.grid(4, 4);
        assert_eq!(g.cell_of([0.0, 0.0, 1.0]), Some(2 * 4 + 2));
        assert_eq!(g.cell_of([-1e-9, -1e-9, 1.0]), Some(4 + 1));
        assert_eq!(g.cell_of([1e-9, 1e-9, -1.0]), Some(15));
        assert_eq!(g.cell_of([0.0, 0.0, 1.1]), None, "not a direction");
    }

    #[test]
    fn a_cell_of_a_cap_spans_its_solid_angle_over_the_cells() {
        // a cap of ρ = 10⁻³ rad: a Monte Carlo of directions uniform in the cone (the cos θ′
        // uniform on [cos ρ, 1]: Archimedes again) falls in each of the 4 × 8 cells equally, and
        // a cell's extent is 2π h / 32 sr, h = 2 sin²(ρ/2)
        let rho: f64 = 1e-3;
        let cap = Domain::cap([0.3, -0.4, 0.5], 2.0 * (0.5 * rho).sin().powi(2)).unwrap();
        let Domain::Cap { axis, height } = cap else { panic!() };
        let g = cap.grid(4, 8);
        let frame = Frame::of(axis);
        let mut counts = [0u32; 32];
        let n = 65_536;
        for i in 0..n {
            // a stratified (a, φ) pair: a uniform on [0, h], φ uniform
            let (u, v) = (((i % 256) as f64 + 0.5) / 256.0, ((i / 256) as f64 + 0.5) / 256.0);
            let d = frame.direction(u * height, std::f64::consts::TAU * v - std::f64::consts::PI);
            counts[g.cell_of(d.into()).expect("inside the cap")] += 1;
        }
        assert!(counts.iter().all(|&c| c == n / 32), "{counts:?}");
        for bin in 0..g.bins() {
            let Cell::Cap { a, phi } = g.cell(bin) else { panic!("a cap cell") };
            let sr = (a.1 - a.0) * (phi.1 - phi.0);
            assert!((sr - cap.solid_angle().unwrap() / 32.0).abs() < 1e-18, "cell {bin}: {sr}");
        }
        // the cone's edge: just inside and just outside (the f32 resolution is 6·10⁻⁸ rad)
        let inside = frame.direction(height * (1.0 - 1e-3), 0.1);
        let outside = frame.direction(height * (1.0 + 1e-3), 0.1);
        assert!(g.cell_of(inside.into()).is_some_and(|c| c / 8 == 3));
        assert_eq!(g.cell_of(outside.into()), None);
        assert_eq!(g.cell_of((-frame.axis).into()), None, "the antipode");
    }

    #[test]
    fn a_caps_frame_is_orthonormal_and_right_handed() {
        for axis in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.3, -0.4, 0.866], [1e-9, 0.0, -1.0]] {
            let f = Frame::of(DVec3::from(axis).normalize().into());
            for (u, v) in [(f.t, f.b), (f.b, f.axis), (f.axis, f.t)] {
                assert!(u.dot(v).abs() < 1e-12 && (u.length() - 1.0).abs() < 1e-12, "{axis:?}");
            }
            assert!((f.t.cross(f.b) - f.axis).length() < 1e-12, "{axis:?}");
        }
    }

    #[test]
    fn every_centre_falls_in_its_own_cell() {
        for g in [Domain::Sphere.grid(7, 12), Domain::plane([-1.0, 2.0, 3.0, 2.5]).unwrap().grid(5, 9), Domain::cap([0.0, 1.0, 0.1], 3e-6).unwrap().grid(5, 12), Domain::LatLong.grid(7, 12), Domain::LatLong.grid(6, 10), Domain::EqualArea.grid(8, 8), Domain::EqualArea.grid(5, 7)] {
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
        assert_eq!(Domain::NAMES, [Domain::Sphere.name(), Domain::Plane { bounds: [0.0, 0.0, 1.0, 1.0] }.name(), Domain::LatLong.name(), Domain::EqualArea.name()]);
    }

    #[test]
    fn every_name_has_its_words() {
        for name in Domain::NAMES.into_iter().chain(["cap"]) {
            let words = Domain::words_for_name(name).unwrap_or_else(|| panic!("{name}"));
            assert!(!words.is_empty() && words != "the sphere" || name == "sphere", "{name}: {words}");
        }
        assert_eq!(Domain::words_for_name("torus"), None);
    }
}
