//! The outputs of `lobes check --out DIR`: heat maps of the χ² histogram, the composed WGSL and
//! `report.json` (written last, so a folder with a `report.json` is complete); and of
//! `lobes check --power --out DIR`: `power.json`.
//!
//! The pictures are those of [`super::compare`] (`measured.png`, `expected.png`, `residual.png`,
//! `marginals.png`), titled with the sampler and its verdict.

use super::atomic::write_atomic;
use super::compare::{self, Bins, Comparison};
use crate::check::power::PowerSweep;
use crate::check::report::Chi2Figures;
use crate::check::Report;
use std::path::Path;

/// The file names in the output folder (and the pictures', [`super::compare`]).
pub use super::compare::{EXPECTED_PNG, MARGINALS_PNG, MEASURED_PNG, RESIDUAL_PNG};
pub const COMPOSED_WGSL: &str = "composed.wgsl";
pub const HISTOGRAM_WGSL: &str = "composed_histogram.wgsl";
pub const REPORT_JSON: &str = "report.json";
pub const POWER_JSON: &str = "power.json";

/// Every file a check writes into its folder: an owner removes them all before it runs
/// ([`super::folder::OutFolder::clean_files`]), so that none is left looking like this check's.
pub const CHECK_FILES: [&str; 10] = [REPORT_JSON, POWER_JSON, COMPOSED_WGSL, HISTOGRAM_WGSL, MEASURED_PNG, EXPECTED_PNG, RESIDUAL_PNG, super::compare::RESIDUAL_COARSE_PNG, MARGINALS_PNG, super::compare::BARS_PNG];

/// Writes the heat maps, the two modules that ran (`composed.wgsl`, lobes' passes with the
/// user's files, and `composed_histogram.wgsl`, the histogram's) and then `report.json` into
/// `dir`.
pub fn write(dir: &Path, report: &Report, [passes, histogram]: &[String; 2]) -> anyhow::Result<()> {
    write_maps(dir, report)?;
    write_atomic(&dir.join(COMPOSED_WGSL), passes.as_bytes())?;
    write_atomic(&dir.join(HISTOGRAM_WGSL), histogram.as_bytes())?;
    write_atomic(&dir.join(REPORT_JSON), serde_json::to_string_pretty(report)?.as_bytes())?;
    Ok(())
}

/// Writes `power.json` into `dir`.
pub fn write_power(dir: &Path, sweep: &PowerSweep) -> anyhow::Result<()> {
    write_atomic(&dir.join(POWER_JSON), serde_json::to_string_pretty(sweep)?.as_bytes())?;
    Ok(())
}

fn write_maps(dir: &Path, report: &Report) -> anyhow::Result<()> {
    let bins = Bins::Grid(report.grid());
    let counts: Vec<f64> = report.counts.iter().map(|&c| c as f64).collect();
    let invalid: u64 = report.invalid.iter().sum();
    let verdict = report.figures::<Chi2Figures>().map_or_else(
        || (if report.passed { "pass" } else { "FAIL" }).to_string(),
        |c| super::caption::verdict(report.passed, &c.chi2),
    );
    let caption = format!("{} ({} samples): {verdict}", report.sampler, report.samples);
    let note = if invalid > 0 { format!("{invalid} invalid samples not shown") } else { String::new() };
    let coarse = report.figures::<Chi2Figures>().and_then(|c| crate::stats::family::caught_grid(&c.chi2));
    compare::write(dir, &Comparison { bins, measured: &counts, expected: &report.expected, caption: &caption, note: &note, coarse })
}

#[cfg(test)]
mod tests {
    use super::super::compare::{Bins, Comparison, write as draw};
    use super::*;
    use crate::stats::domain::Domain;

    /// Every picture a check can draw (the coarse grid's residual among them) is one the next
    /// check, or run, into the same folder removes first: none is left from an earlier failure.
    #[test]
    fn every_picture_drawn_is_cleaned_next_time() {
        let dir = tempfile::tempdir().unwrap();
        let lobe: Vec<f64> = (0..32).map(|i| if i / 8 >= 2 { 50.0 + (i % 8) as f64 } else { 0.0 }).collect();
        let c = Comparison { bins: Bins::Grid(Domain::Sphere.grid(4, 8)), measured: &lobe, expected: &lobe, caption: "lobe", note: "", coarse: Some((2, 4)) };
        draw(dir.path(), &c).unwrap();
        let items = Comparison { bins: Bins::Items(3), measured: &[1.0, 2.0, 3.0], expected: &[1.0, 2.0, 3.0], caption: "d", note: "", coarse: None };
        draw(dir.path(), &items).unwrap();
        let names: Vec<String> = std::fs::read_dir(dir.path()).unwrap().map(|f| f.unwrap().file_name().into_string().unwrap()).collect();
        assert!(names.len() >= 6, "{names:?}");
        for name in &names {
            assert!(CHECK_FILES.contains(&name.as_str()) && super::super::folder::CASE_FILES.contains(&name.as_str()), "{name} is drawn but not cleaned");
        }
    }
}
