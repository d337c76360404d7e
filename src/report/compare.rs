//! Pictures that compare a measured histogram with its expectation, written alike by `lobes run`
//! (per case) and `lobes check --out`.
//!
//! A 2-D histogram (the sphere over (cos θ, φ), or a plane over (y, x)) gets
//! - `measured.png` (counts per bin) and `expected.png` (N × ∫pdf per bin) on one shared count
//!   scale ([`Mapping::counts`]: logarithmic from a tenth of one count), so equal colours are
//!   equal counts;
//! - `residual.png`, (measured − expected)/√expected per bin, the bin's signed contribution to
//!   χ² (diverging, 0 white, over ±[`RESIDUAL_LIMIT`]; see [`residual`]); samples in a bin that
//!   expects nothing have no finite residual and are grey ("nan" on the key); a bin whose
//!   expected count is below 0 (the pdf is negative there) is magenta ("pdf < 0" on the key)
//!   here and in `expected.png`, never drawn as 0;
//! - `marginals.png`, the two marginals with their ±2σ bands ([`super::marginals`]);
//! - `residual_coarse.png`, where a coarser grid of the χ² family caught a defect that the fine
//!   grid did not ([`crate::stats::family::caught_grid`]): the residual of its blocks, where a
//!   smooth defect that reads as noise bin by bin shows (a dipole, a ring).
//!
//! Rows at the top or bottom of the grid with neither a sample nor half an expected count (the
//! lower hemisphere of a reflection lobe) are left out, and the axes show the range drawn; on
//! the sphere the columns are rotated so that the lobe's mean φ sits in the middle of the map,
//! never cut in two at its edges (φ in degrees, as a scene gives the incident direction).
//!
//! A discrete distribution gets `bars.png`: each item's count against its expectation. Every
//! picture is titled with the case's caption (name, parameters, verdict).

use super::heatmap::{self, Heatmap, Mapping, Scale};
use super::marginals::{self, Panel};
use crate::stats::chi2::MIN_EXPECTED;
use crate::stats::domain::Grid;
#[cfg(test)]
use crate::stats::domain::Domain;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::ops::Range;
use std::path::Path;

/// The file names.
pub const MEASURED_PNG: &str = "measured.png";
pub const EXPECTED_PNG: &str = "expected.png";
pub const RESIDUAL_PNG: &str = "residual.png";
pub const MARGINALS_PNG: &str = "marginals.png";
pub const RESIDUAL_COARSE_PNG: &str = "residual_coarse.png";
pub const BARS_PNG: &str = "bars.png";

/// The residual map's colour scale runs over ±5 in every picture: a correct sampler's residuals
/// are about standard normal, pale on this scale, and a bin beyond ±5 (p < 6e-7 alone) is
/// saturated whatever else the map holds, so maps compare across cases.
pub const RESIDUAL_LIMIT: f64 = 5.0;

/// The residual map's key for a bin whose expected count is below 0 ([`residual`]).
const PDF_BELOW_ZERO: &str = "pdf < 0";

/// How the bins of a histogram lie.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bins {
    /// A grid over a domain (directions, or points of a box), row-major.
    Grid(Grid),
    /// The items of a discrete distribution.
    Items(usize),
}

/// A measured histogram and its expectation.
#[derive(Debug, Clone, Copy)]
pub struct Comparison<'a> {
    pub bins: Bins,
    /// Counts per bin.
    pub measured: &'a [f64],
    /// Expected counts per bin.
    pub expected: &'a [f64],
    /// What every title starts with: the case, its parameters and its verdict.
    pub caption: &'a str,
    /// What the measured counts leave out, e.g. "12 invalid samples not shown" (may be empty).
    pub note: &'a str,
    /// The rows × cols of the coarser grid whose test caught a defect the fine grid did not, for
    /// `residual_coarse.png` (none: no such picture).
    pub coarse: Option<(usize, usize)>,
}

/// The bins of a rows × cols grid added into `coarse` blocks, row r into ⌊r · R′/R⌋ and column c
/// into ⌊c · C′/C⌋, as the χ² family groups them ([`crate::stats::family::Test::cells`]).
fn aggregate(values: &[f64], rows: usize, cols: usize, (cr, cc): (usize, usize)) -> Vec<f64> {
    let mut out = vec![0.0; cr * cc];
    for r in 0..rows {
        for k in 0..cols {
            out[r * cr / rows * cc + k * cc / cols] += values[r * cols + k];
        }
    }
    out
}

/// The residual of one bin as drawn: (m − e)/√e; −∞ (drawn magenta, "pdf < 0") where the
/// expected count is below 0, whatever was measured; NaN for samples where nothing is expected;
/// 0 where fewer than [`MIN_EXPECTED`] samples are expected: the χ² test judges those bins
/// pooled, and one stray sample where 0.01 is expected would read as +10 although Poisson finds
/// nothing wrong with it. (Zeroing only bins whose count is small too would leave exactly the
/// sparse bins that happen to be high, a red fringe around every lobe.)
pub fn residual(measured: f64, expected: f64) -> f64 {
    if expected < 0.0 {
        f64::NEG_INFINITY
    } else if measured > 0.0 && expected <= 0.0 {
        f64::NAN
    } else if expected < MIN_EXPECTED {
        0.0
    } else {
        (measured - expected) / expected.sqrt()
    }
}

/// The rows `first..end` of a row-major grid that hold a sample, at least half an expected
/// count or a negative expected count (a pdf below 0 is drawn, never cropped), with every row in
/// between (all rows when none does).
pub fn drawn_rows(measured: &[f64], expected: &[f64], rows: usize, cols: usize) -> Range<usize> {
    let occupied = |r: usize| {
        let cells = r * cols..(r + 1) * cols;
        measured[cells.clone()].iter().any(|&c| c > 0.0) || expected[cells.clone()].iter().sum::<f64>() >= 0.5 || expected[cells].iter().any(|&e| e < 0.0)
    };
    match ((0..rows).find(|&r| occupied(r)), (0..rows).rfind(|&r| occupied(r))) {
        (Some(first), Some(last)) => first..last + 1,
        _ => 0..rows,
    }
}

/// The column of a sphere grid drawn first, so that the expected mass's circular mean φ̄ lands in
/// the middle of the map: column 0 (φ from −π) unless the mass has a clear direction (mean
/// resultant length ≥ 0.05 of the total; an isotropic lobe has none).
pub fn first_column(expected: &[f64], cols: usize) -> usize {
    let width = 2.0 * PI / cols as f64;
    let (mut x, mut y, mut total) = (0.0, 0.0, 0.0);
    for (i, e) in expected.iter().enumerate() {
        let phi = -PI + ((i % cols) as f64 + 0.5) * width;
        (x, y, total) = (x + e * phi.cos(), y + e * phi.sin(), total + e);
    }
    if total <= 0.0 || x.hypot(y) < 0.05 * total {
        return 0;
    }
    // the map's left edge half a turn before φ̄, on a column edge: φ0 = −π + first·width ≈ φ̄ − π,
    // and where the columns allow on a multiple of 45° (so the axis ends read as round angles)
    let step = if cols.is_multiple_of(8) { cols as i64 / 8 } else { 1 };
    (((y.atan2(x) / width / step as f64).round() as i64) * step).rem_euclid(cols as i64) as usize
}

/// Writes the pictures of `c` into `dir`: the maps and `marginals.png` of a 2-D histogram,
/// `bars.png` of a discrete one.
pub fn write(dir: &Path, c: &Comparison) -> anyhow::Result<()> {
    match c.bins {
        Bins::Items(n) => {
            let panel = Panel {
                title: "samples per item, measured against expected".into(),
                x_label: "item",
                edges: (0..=n).map(|i| i as f64 - 0.5).collect(),
                measured: c.measured.to_vec(),
                expected: c.expected.to_vec(),
            };
            marginals::write_png(&dir.join(BARS_PNG), c.caption, &[panel])
        }
        Bins::Grid(grid) => write_grid(dir, c, grid),
    }
}

/// The caption, and under it what the picture shows.
fn title(c: &Comparison, what: &str) -> String {
    format!("{}\n{what}", c.caption)
}

fn write_grid(dir: &Path, c: &Comparison, grid: Grid) -> anyhow::Result<()> {
    let (rows, cols) = (grid.rows as usize, grid.cols as usize);
    draw(dir, c, grid, None)?;
    match c.coarse {
        Some((cr, cc)) if cr > 1 && cc > 1 && (cr, cc) != (rows, cols) && c.measured.len() == rows * cols => {
            let (measured, expected) = (aggregate(c.measured, rows, cols, (cr, cc)), aggregate(c.expected, rows, cols, (cr, cc)));
            let coarse = grid.domain.grid(cr as u32, cc as u32);
            draw(dir, &Comparison { bins: Bins::Grid(coarse), measured: &measured, expected: &expected, coarse: None, ..*c }, coarse, Some(RESIDUAL_COARSE_PNG))
        }
        _ => Ok(()),
    }
}

/// The maps and marginals of a grid; with `residual_only`, its residual map alone into that file
/// (a coarse grid's, titled with its size).
fn draw(dir: &Path, c: &Comparison, grid: Grid, residual_only: Option<&str>) -> anyhow::Result<()> {
    let (rows, cols) = (grid.rows as usize, grid.cols as usize);
    anyhow::ensure!(
        c.measured.len() == rows * cols && c.expected.len() == rows * cols,
        "a {rows} × {cols} histogram with {} measured and {} expected bins",
        c.measured.len(),
        c.expected.len()
    );
    let drawn = drawn_rows(c.measured, c.expected, rows, cols);
    // columns that wrap around (φ) start where the lobe is not cut in two
    let first = if grid.domain.pictures_turn_columns() { first_column(c.expected, cols) } else { 0 };
    // the drawn rows, each from column `first` round to the one before it
    let cells = |values: &[f64]| -> Vec<f64> {
        drawn.clone().flat_map(|r| (0..cols).map(move |k| values[r * cols + (k + first) % cols])).collect()
    };
    let (measured, expected) = (cells(c.measured), cells(c.expected));
    let residuals: Vec<f64> = measured.iter().zip(&expected).map(|(&m, &e)| residual(m, e)).collect();

    let [(row_label, (r0, r1)), (col_label, (c0, c1))] = grid.domain.picture_axes();
    // the column axis from column `first`, one period long
    let (start, period) = (c0 + first as f64 * (c1 - c0) / cols as f64, c1 - c0);
    let (c0, c1) = (start, start + period);
    let row_edge = |r: usize| r0 + (r1 - r0) * r as f64 / rows as f64;
    let col_edge = |k: usize| c0 + (c1 - c0) * k as f64 / cols as f64;
    let base = Heatmap {
        title: "",
        rows: drawn.len(),
        cols,
        values: &[],
        scale: Scale::Sequential,
        row_label,
        col_label,
        row_range: (row_edge(drawn.start), row_edge(drawn.end)),
        col_range: (c0, c1),
        marked_key: "",
    };
    let measured_title = if c.note.is_empty() { "measured counts".to_string() } else { format!("measured counts ({})", c.note) };
    let clipped = if residuals.iter().any(|r| r.abs() > RESIDUAL_LIMIT) { format!(", colours clipped at ±{RESIDUAL_LIMIT}") } else { String::new() };
    let grey = if residuals.iter().any(|r| r.is_nan()) { "; grey: samples where nothing is expected" } else { "" };
    let pooled = format!("; 0 where under {MIN_EXPECTED} are expected (pooled by χ²)");
    // a pdf below 0 somewhere: those bins magenta ("pdf < 0") on the expected and the residual
    // map (never drawn as 0), the rest on the counts' shared scale
    let negative = expected.iter().filter(|&&e| e < 0.0).count();
    let lowest = expected.iter().copied().fold(0.0, f64::min);
    let expected_drawn: Vec<f64> = expected.iter().map(|&e| if e < 0.0 { f64::NEG_INFINITY } else { e }).collect();
    // one scale for both maps, over the counts and the expectation at or above 0
    let counts = Mapping::counts(&[&measured[..], &expected_drawn[..]].concat());
    let expected_title = if negative == 0 {
        "expected counts, N × ∫pdf (same colour scale)".to_string()
    } else {
        format!("expected counts, N × ∫pdf (same colour scale); magenta: {negative} bins below 0 (down to {}), where the pdf is negative", super::label::compact(lowest))
    };
    let below = if negative > 0 { format!("; magenta: {negative} bins whose expected count is below 0") } else { String::new() };
    let residual_title = format!("(measured − expected)/√expected{pooled}{clipped}{grey}{below}");
    if let Some(file) = residual_only {
        let what = format!("{residual_title}, in {rows} × {cols} blocks: the grid whose χ² test caught the defect");
        return heatmap::write_png_scaled(
            &Heatmap { title: &title(c, &what), values: &residuals, scale: Scale::Diverging, marked_key: PDF_BELOW_ZERO, ..base },
            Mapping::Symmetric { lim: RESIDUAL_LIMIT },
            &dir.join(file),
        )
        .map_err(Into::into);
    }
    let maps = [
        (MEASURED_PNG, title(c, &measured_title), &measured, Scale::Sequential, counts),
        (EXPECTED_PNG, title(c, &expected_title), &expected_drawn, Scale::Sequential, counts),
        (
            RESIDUAL_PNG,
            title(c, &residual_title),
            &residuals,
            Scale::Diverging,
            Mapping::Symmetric { lim: RESIDUAL_LIMIT },
        ),
    ];
    // The maps are independent: encoded in parallel; the marginals follow once all three are
    // written (a map that cannot be written stops the case's pictures there, as before).
    maps.par_iter().try_for_each(|(file, title, values, scale, mapping)| {
        let marked_key = if *file == MEASURED_PNG { "" } else { PDF_BELOW_ZERO };
        heatmap::write_png_scaled(&Heatmap { title, values, scale: *scale, marked_key, ..base }, *mapping, &dir.join(file))
    })?;

    let axes = [(row_label, (drawn.start..=drawn.end).map(row_edge).collect()), (col_label, (0..=cols).map(col_edge).collect())];
    write_marginals(dir, c.caption, axes, (&measured, &expected), cols)
}

/// The marginals of the drawn cells (`cols` a row): sums over the columns of each row, and over
/// the rows of each column, against the axes' labels and edges.
fn write_marginals(dir: &Path, caption: &str, axes: [(&'static str, Vec<f64>); 2], (measured, expected): (&[f64], &[f64]), cols: usize) -> anyhow::Result<()> {
    let row_sums = |v: &[f64]| -> Vec<f64> { v.chunks(cols).map(|row| row.iter().sum()).collect() };
    let col_sums = |v: &[f64]| -> Vec<f64> { (0..cols).map(|k| v.iter().skip(k).step_by(cols).sum()).collect() };
    let [(row_label, row_edges), (col_label, col_edges)] = axes;
    let panels = [
        Panel { title: format!("over {row_label}"), x_label: row_label, edges: row_edges, measured: row_sums(measured), expected: row_sums(expected) },
        Panel { title: format!("over {col_label}"), x_label: col_label, edges: col_edges, measured: col_sums(measured), expected: col_sums(expected) },
    ];
    marginals::write_png(&dir.join(MARGINALS_PNG), caption, &panels)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 8 grid whose values are `mass(row, col)`.
    fn grid(mass: impl Fn(usize, usize) -> f64) -> Vec<f64> {
        (0..32).map(|i| mass(i / 8, i % 8)).collect()
    }

    #[test]
    fn empty_rows_at_the_edges_are_left_out_and_the_lobe_is_centred() {
        // a reflection lobe: the upper two rows (cos θ ≥ 0), around φ = ±π (columns 0 and 7)
        let lobe = grid(|r, c| if r >= 2 && (c == 0 || c == 7) { 100.0 } else if r >= 2 { 1.0 } else { 0.0 });
        assert_eq!(drawn_rows(&lobe, &lobe, 4, 8), 2..4);
        // φ̄ = π: the map runs over [0, 2π), columns 4..8 then 0..4
        assert_eq!(first_column(&lobe, 8), 4);
        // a lobe around φ = 0 (columns 3 and 4) stays on [−π, π); a row between occupied
        // rows is drawn even when empty
        let forward = grid(|r, c| if r != 1 && (c == 3 || c == 4) { 100.0 } else { 0.0 });
        assert_eq!(drawn_rows(&forward, &forward, 4, 8), 0..4);
        assert_eq!(first_column(&forward, 8), 0);
        // a lobe in columns 1 and 2 (φ ∈ [−3π/4, −π/4), φ̄ = −π/2) is drawn from column 6
        // (φ from π/2): columns 6 7 0 1 2 3 4 5, the lobe either side of the middle
        let side = grid(|_, c| if c == 1 || c == 2 { 10.0 } else { 1.0 });
        assert_eq!(first_column(&side, 8), 6);
        // with 16 columns the edge moves in steps of 2 columns (45°): a lobe in column 5
        // (φ̄ = −56.25°) is drawn around the middle −45°, from column 14 (φ from 135°)
        let side16: Vec<f64> = (0..64).map(|i| if i % 16 == 5 { 10.0 } else { 1.0 }).collect();
        assert_eq!(first_column(&side16, 16), 14);
        // no direction (isotropic) or nothing at all: as binned
        assert_eq!(first_column(&grid(|_, _| 1.0), 8), 0);
        let zero = grid(|_, _| 0.0);
        assert_eq!(first_column(&zero, 8), 0);
        assert_eq!(drawn_rows(&zero, &zero, 4, 8), 0..4);
        // samples alone keep a row
        let stray = grid(|r, c| if r == 0 && c == 0 { 1.0 } else { 0.0 });
        assert_eq!(drawn_rows(&stray, &zero, 4, 8), 0..1);
        // and so does a negative expected count (a pdf below 0), though the row's sum is < 0.5
        let below = grid(|r, c| if r == 0 && c == 0 { -3.0 } else if r == 3 { 10.0 } else { 0.0 });
        assert_eq!(drawn_rows(&zero, &below, 4, 8), 0..4);
    }

    #[test]
    fn residuals_of_empty_and_impossible_bins() {
        assert_eq!(residual(0.0, 0.0), 0.0);
        assert!(residual(3.0, 0.0).is_nan());
        assert_eq!(residual(1.0, 0.01), 0.0, "a stray sample in a pooled bin");
        assert_eq!(residual(12.0, 4.0), 0.0);
        assert_eq!(residual(16.0, 25.0), -1.8);
        assert_eq!(residual(13.0, 9.0), 4.0 / 3.0);
        // a negative expectation (the pdf below 0) is marked whatever was measured
        assert_eq!(residual(0.0, -2.0), f64::NEG_INFINITY);
        assert_eq!(residual(7.0, -1e-9), f64::NEG_INFINITY);
    }

    /// A pdf below 0 in some bins: `expected.png` and `residual.png` draw them magenta with the
    /// key "pdf < 0", `measured.png` not; the rows holding them are not cropped.
    #[test]
    fn negative_expected_counts_are_drawn() {
        use crate::report::colour::MARKED;
        let dir = tempfile::tempdir().unwrap();
        // 4 × 8: a lobe in the upper rows, −3 expected in row 0's columns 0 and 1, nothing
        // measured in rows 0 and 1
        let expected = grid(|r, c| if r >= 2 { 100.0 } else if r == 0 && c < 2 { -3.0 } else { 0.0 });
        let measured = grid(|r, _| if r >= 2 { 100.0 } else { 0.0 });
        let c = Comparison { bins: Bins::Grid(Domain::Sphere.grid(4, 8)), measured: &measured, expected: &expected, caption: "negative", note: "", coarse: None };
        write(dir.path(), &c).unwrap();
        let read = |f: &str| image::open(dir.path().join(f)).unwrap().to_rgb8();
        let count = |img: &image::RgbImage, rgb: [u8; 3]| img.pixels().filter(|p| p.0 == rgb).count();
        let residual = read(RESIDUAL_PNG);
        let magenta = count(&residual, MARKED.0);
        // two cells (each at least 32 px wide on a map of 8 columns) and the key's swatch
        assert!(magenta > 2 * 32 * 4, "{magenta} magenta pixels");
        let expected_png = count(&read(EXPECTED_PNG), MARKED.0);
        assert!(expected_png > 2 * 32 * 4, "{expected_png} magenta pixels");
        assert_eq!(count(&read(MEASURED_PNG), MARKED.0), 0);
        // without negative bins: no magenta
        let plain = grid(|r, _| if r >= 2 { 100.0 } else { 0.0 });
        write(dir.path(), &Comparison { expected: &plain, ..c }).unwrap();
        assert_eq!(count(&read(RESIDUAL_PNG), MARKED.0), 0);
        assert_eq!(count(&read(EXPECTED_PNG), MARKED.0), 0);
    }

    /// Blocks as the χ² family groups them: 3 × 4 into 2 × 2 takes rows {0, 1}, {2} and
    /// columns {0, 1}, {2, 3}.
    #[test]
    fn aggregated_blocks() {
        let v: Vec<f64> = (0..12).map(f64::from).collect();
        assert_eq!(aggregate(&v, 3, 4, (2, 2)), [10.0, 18.0, 17.0, 21.0]);
    }

    #[test]
    fn the_pictures_of_a_grid_and_of_items() {
        let dir = tempfile::tempdir().unwrap();
        let lobe = grid(|r, c| if r >= 2 { 50.0 + 10.0 * c as f64 } else { 0.0 });
        let c = Comparison { bins: Bins::Grid(Domain::Sphere.grid(4, 8)), measured: &lobe, expected: &lobe, caption: "lobe", note: "", coarse: None };
        write(dir.path(), &c).unwrap();
        for png in [MEASURED_PNG, EXPECTED_PNG, RESIDUAL_PNG, MARGINALS_PNG] {
            assert!(dir.path().join(png).is_file(), "{png}");
        }
        assert!(!dir.path().join(RESIDUAL_COARSE_PNG).exists());
        // the grid that caught a defect: its residual in blocks
        write(dir.path(), &Comparison { coarse: Some((2, 4)), ..c }).unwrap();
        assert!(dir.path().join(RESIDUAL_COARSE_PNG).is_file());
        // two drawn rows: the map is as tall as its smallest size, not four rows
        let items = Comparison { bins: Bins::Items(3), measured: &[1.0, 2.0, 3.0], expected: &[1.0, 2.0, 3.0], caption: "d", note: "", coarse: None };
        write(dir.path(), &items).unwrap();
        assert!(dir.path().join(BARS_PNG).is_file());
        let short = Comparison { measured: &lobe[..5], ..c };
        assert!(write(dir.path(), &short).is_err());
    }
}
