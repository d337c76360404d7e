//! `lobes tradeoff`'s outputs: `tradeoff.md` ([`tables`]), `tradeoff.png` ([`plot`]: log-log
//! error against time, one panel per sampler, one curve per precision, with the 1/√N line)
//! and `tradeoff.json`; each written under a temporary name and renamed into place.

pub mod plot;
pub mod tables;

pub use tables::{markdown, methods_table, quadrature_table, summary_table, sweep_table};

use super::output::write_atomic;
use crate::experiments::tradeoff::{MethodPoint, QuadraturePoint, Sweep};
use serde::Serialize;
use std::path::Path;

/// Everything one `lobes tradeoff` run measured.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub adapter: String,
    pub command: String,
    pub grid: [u32; 2],
    pub seed: u64,
    pub angle_samples: u32,
    /// Timed runs per measurement (medians reported).
    pub runs: u32,
    pub sweep: Sweep,
    pub methods: Vec<MethodPoint>,
    pub quadrature: Vec<QuadraturePoint>,
}

/// Writes tradeoff.png, tradeoff.json and tradeoff.md into `dir` (created if missing).
pub fn write(dir: &Path, r: &Report) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)?;
    write_atomic(&dir.join("tradeoff.png"), &super::png::encode(&plot::plot(&r.sweep)?)?)?;
    write_atomic(&dir.join("tradeoff.json"), serde_json::to_string_pretty(r)?.as_bytes())?;
    write_atomic(&dir.join("tradeoff.md"), markdown(r).as_bytes())?;
    Ok(())
}
