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
pub const REPORT_JSON: &str = "report.json";
pub const POWER_JSON: &str = "power.json";

/// Every file a check writes into its folder: an owner removes them all before it runs
/// ([`super::folder::OutFolder::clean_files`]), so that none is left looking like this check's.
pub const CHECK_FILES: [&str; 8] = [REPORT_JSON, POWER_JSON, COMPOSED_WGSL, MEASURED_PNG, EXPECTED_PNG, RESIDUAL_PNG, MARGINALS_PNG, super::compare::BARS_PNG];

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
