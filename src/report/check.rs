//! The outputs of `lobes check --out DIR`: heat maps of the χ² histogram, the composed WGSL and
//! `report.json` (written last, so a folder with a `report.json` is complete); and of
//! `lobes check --power --out DIR`: `power.json`.
//!
//! The maps: `measured.png` (the GPU's counts per bin) and `expected.png` (N × ∫pdf per bin) on
//! one shared colour scale, so that equal colours are equal counts, and `residual.png`,
//! (measured − expected)/√expected per bin, the cell's contribution to χ² with its sign. Bins
//! with samples but an expected count ≤ 0 (which fail the test outright) have no finite
//! residual and are drawn grey ("nan" on the key). Rows at the top or bottom of the grid with
//! neither a sample nor an expected count (the lower hemisphere of a reflection lobe) are left
//! out, and the axis shows the range that is drawn; on the sphere, a lobe around φ = ±π is drawn
//! over φ ∈ [0, 2π) so that it is not cut in two at the map's edges.

use super::atomic::write_atomic;
use super::heatmap::{self, Heatmap, Mapping, Scale};
use super::label::compact;
use crate::check::power::PowerSweep;
use crate::check::report::Chi2Figures;
use crate::check::{Domain, Report};
use std::f64::consts::PI;
use std::path::Path;

/// The file names in the output folder.
pub const MEASURED_PNG: &str = "measured.png";
pub const EXPECTED_PNG: &str = "expected.png";
pub const RESIDUAL_PNG: &str = "residual.png";
pub const COMPOSED_WGSL: &str = "composed.wgsl";
pub const REPORT_JSON: &str = "report.json";
pub const POWER_JSON: &str = "power.json";

/// Writes the heat maps, `composed.wgsl` (the module that ran) and then `report.json` into `dir`.
pub fn write(dir: &Path, report: &Report, composed: &str) -> anyhow::Result<()> {
    write_maps(dir, report)?;
    write_atomic(&dir.join(COMPOSED_WGSL), composed.as_bytes())?;
    write_atomic(&dir.join(REPORT_JSON), serde_json::to_string_pretty(report)?.as_bytes())?;
    Ok(())
}

/// Writes `power.json` into `dir`.
pub fn write_power(dir: &Path, sweep: &PowerSweep) -> anyhow::Result<()> {
    write_atomic(&dir.join(POWER_JSON), serde_json::to_string_pretty(sweep)?.as_bytes())?;
    Ok(())
}

/// The rows `first..end` of the grid that hold a sample or at least half an expected count,
/// with every row in between (all rows when none does).
pub fn drawn_rows(report: &Report) -> std::ops::Range<usize> {
    let cols = report.cols as usize;
    let occupied = |r: usize| {
        let cells = r * cols..(r + 1) * cols;
        report.counts[cells.clone()].iter().any(|&c| c > 0) || report.expected[cells].iter().sum::<f64>() >= 0.5
    };
    let rows = report.rows as usize;
    match ((0..rows).find(|&r| occupied(r)), (0..rows).rfind(|&r| occupied(r))) {
        (Some(first), Some(last)) => first..last + 1,
        _ => 0..rows,
    }
}

/// The residual of one bin: (m − e)/√e; 0 for an empty bin that expects nothing, NaN for
/// samples where nothing is expected.
fn residual(measured: f64, expected: f64) -> f64 {
    if expected > 0.0 {
        (measured - expected) / expected.sqrt()
    } else if measured > 0.0 {
        f64::NAN
    } else {
        0.0
    }
}

/// Whether the sphere's columns are better drawn over φ ∈ [0, 2π) than [−π, π): when the
/// expected mass sits around φ = ±π (a reflection lobe for light from φ = 0), where the usual
/// range would cut it in two halves at the map's left and right edges. The mass's circular mean
/// decides (its φ is farther than π/2 from 0).
pub fn centred_on_pi(report: &Report) -> bool {
    let cols = report.cols as usize;
    if !matches!(report.domain, Domain::Sphere) || !cols.is_multiple_of(2) {
        return false;
    }
    let (mut x, mut y) = (0.0, 0.0);
    for (i, e) in report.expected.iter().enumerate() {
        let phi = -PI + (i % cols) as f64 * 2.0 * PI / cols as f64 + PI / cols as f64;
        x += e * phi.cos();
        y += e * phi.sin();
    }
    x < 0.0 && x.abs() > y.abs()
}

fn write_maps(dir: &Path, report: &Report) -> anyhow::Result<()> {
    let (rows, cols) = (report.rows as usize, report.cols as usize);
    let drawn = drawn_rows(report);
    // columns drawn in turn: all of them, starting at column `first`
    let first = if centred_on_pi(report) { cols / 2 } else { 0 };
    let cells = |values: &[f64]| -> Vec<f64> {
        drawn.clone().flat_map(|r| (0..cols).map(move |c| r * cols + (c + first) % cols)).map(|i| values[i]).collect()
    };
    let counts: Vec<f64> = report.counts.iter().map(|&c| c as f64).collect();
    let measured = cells(&counts);
    let expected = cells(&report.expected);
    let residuals: Vec<f64> = measured.iter().zip(&expected).map(|(&m, &e)| residual(m, e)).collect();

    // the row axis over the drawn rows: cos θ on the sphere, y on the plane
    let (row_label, col_label, (r0, r1), col_range) = match report.domain {
        Domain::Sphere if first > 0 => ("cos θ", "φ", (-1.0, 1.0), (0.0, 2.0 * PI)),
        Domain::Sphere => ("cos θ", "φ", (-1.0, 1.0), (-PI, PI)),
        Domain::Plane { bounds: [x0, y0, x1, y1] } => ("y", "x", (y0, y1), (x0, x1)),
    };
    let edge = |r: usize| r0 + (r1 - r0) * r as f64 / rows as f64;
    let row_range = (edge(drawn.start), edge(drawn.end));
    let invalid: u64 = report.invalid.iter().sum();
    let valid = report.samples - invalid;

    // one colour scale for measured and expected: fitted to the counts and to every expected
    // count of at least 1 (a log scale then starts at one count, as for counts alone)
    let shared: Vec<f64> = measured.iter().copied().chain(expected.iter().copied().filter(|&e| e >= 1.0)).collect();
    let counts_scale = Mapping::fit(Scale::Sequential, &shared);
    let measured_title = format!("measured: counts of {valid} valid samples ({invalid} invalid not shown)");
    let expected_title = format!("expected: {} × ∫pdf over each bin (same colour scale)", report.samples);
    let p = report.figures::<Chi2Figures>().map_or(String::new(), |c| format!(", χ² p = {}", compact(c.chi2.p_value)));
    let grey = if residuals.iter().any(|r| r.is_nan()) { "; grey: samples in bins where ∫pdf ≤ 0" } else { "" };
    let residual_title = format!("residual (measured − expected)/√expected{p}{grey}");
    let base = Heatmap {
        title: "",
        rows: drawn.len(),
        cols,
        values: &[],
        scale: Scale::Sequential,
        row_label,
        col_label,
        row_range,
        col_range,
    };
    heatmap::write_png_scaled(&Heatmap { title: &measured_title, values: &measured, ..base }, counts_scale, &dir.join(MEASURED_PNG))?;
    heatmap::write_png_scaled(&Heatmap { title: &expected_title, values: &expected, ..base }, counts_scale, &dir.join(EXPECTED_PNG))?;
    heatmap::write_png(&Heatmap { title: &residual_title, values: &residuals, scale: Scale::Diverging, ..base }, &dir.join(RESIDUAL_PNG))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 8 sphere report whose counts and expectation are `mass` per bin.
    fn report(mass: impl Fn(usize, usize) -> f64) -> Report {
        let (rows, cols) = (4, 8);
        let expected: Vec<f64> = (0..rows * cols).map(|i| mass(i / cols, i % cols)).collect();
        Report {
            format_version: crate::check::report::REPORT_VERSION,
            passed: true,
            checks: vec![],
            sampler: "s/p in t.wgsl".into(),
            domain: Domain::Sphere,
            samples: expected.iter().sum::<f64>() as u64,
            rows: rows as u32,
            cols: cols as u32,
            adapter: "test".into(),
            gpu_seconds: None,
            wall_seconds: 0.0,
            counts: expected.iter().map(|&e| e as u64).collect(),
            invalid: [0; 4],
            expected,
        }
    }

    #[test]
    fn empty_rows_at_the_edges_are_left_out_and_a_lobe_at_pi_is_centred() {
        // a reflection lobe: the upper two rows (cos θ ≥ 0), around φ = ±π (columns 0 and 7)
        let lobe = report(|r, c| if r >= 2 && (c == 0 || c == 7) { 100.0 } else if r >= 2 { 1.0 } else { 0.0 });
        assert_eq!(drawn_rows(&lobe), 2..4);
        assert!(centred_on_pi(&lobe));
        // a lobe around φ = 0 (columns 3 and 4) stays on [−π, π); a row between occupied
        // rows is drawn even when empty
        let forward = report(|r, c| if r != 1 && (c == 3 || c == 4) { 100.0 } else { 0.0 });
        assert_eq!(drawn_rows(&forward), 0..4);
        assert!(!centred_on_pi(&forward));
        // nothing anywhere: every row
        assert_eq!(drawn_rows(&report(|_, _| 0.0)), 0..4);
    }

    #[test]
    fn residuals_of_empty_and_impossible_bins() {
        assert_eq!(residual(0.0, 0.0), 0.0);
        assert!(residual(3.0, 0.0).is_nan());
        assert_eq!(residual(12.0, 4.0), 4.0);
    }
}
