//! Per-case outputs: `histogram.json` and PNG heat maps of the measured histogram, the
//! expected one and the signed residual (measured − expected)/√expected. Every file is
//! written to a temporary name and renamed into place, and `histogram.json` is written last,
//! so a case folder with a `histogram.json` is complete.

use super::heatmap::{self, Heatmap, Scale};
use crate::engine::job::Job;
use crate::reference::Invalid;
use crate::run::CaseResult;
use serde_json::{Value, json};
use std::path::Path;

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// Rows of a row-major grid as nested arrays.
fn nested<T: Copy + Into<Value>>(values: &[T], cols: usize) -> Value {
    Value::Array(values.chunks(cols.max(1)).map(|r| Value::Array(r.iter().map(|&v| v.into()).collect())).collect())
}

fn reasons<T: Copy + Into<Value>>(values: &[T; 4]) -> Value {
    Value::Object(Invalid::ALL.iter().zip(values).map(|(r, &v)| (r.name().to_string(), v.into())).collect())
}

/// The `histogram.json` document of a case.
pub fn histogram_json(r: &CaseResult, adapter: &str, backend: &str) -> Value {
    let case = &r.case;
    let (lobe, method, params, incident, rows, cols, edges) = match &case.job {
        Job::Lobe { lobe, incident, grid } => (
            lobe.kind.name().to_string(),
            lobe.method.name().to_string(),
            json!({"alpha_x": lobe.alpha_x, "alpha_y": lobe.alpha_y,
                   "incident_theta_deg": case.incident_deg.0, "incident_phi_deg": case.incident_deg.1}),
            json!([incident.x, incident.y, incident.z]),
            grid.rows as usize,
            grid.cols as usize,
            (json!(grid.cos_theta_edges()), json!(grid.phi_edges())),
        ),
        Job::Discrete { dist, method } => (
            "discrete".to_string(),
            format!("{method:?}").to_lowercase(),
            json!({"weights": dist.weights()}),
            Value::Null,
            1,
            dist.len(),
            (Value::Null, Value::Null),
        ),
    };
    let quadrature = r.expected.quadrature.as_ref().map(|q| {
        json!({"error_estimate": q.error_estimate, "max_error_sigma_at_1e8": q.max_error_sigma,
               "below_horizon_probability": q.below_horizon, "seconds": r.quadrature_seconds})
    });
    json!({
        "case": case.name,
        "lobe": lobe,
        "method": method,
        "params": params,
        "incident": incident,
        "samples": case.samples,
        "seed": case.seed,
        "adapter": adapter,
        "backend": backend,
        "cos_theta_edges": edges.0,
        "phi_edges": edges.1,
        "rows": rows,
        "cols": cols,
        "counts": nested(&r.counts.bins, cols),
        "expected": nested(&r.expected.bins, cols),
        "invalid": reasons(&r.counts.invalid),
        "expected_invalid": reasons(&r.expected.invalid),
        "chi2": {"statistic": r.chi2.statistic, "dof": r.chi2.dof, "p_value": r.chi2.p_value,
                 "significance": r.chi2.significance, "passed": r.chi2.passed,
                 "samples_in_zero_probability_cells": r.chi2.in_impossible_cells},
        "timing": {"gpu_seconds": r.gpu_seconds, "histogram_wall_seconds": r.histogram_seconds},
        "per_sample_check": r.angle,
        "quadrature": quadrature,
        "workgroup_counting": r.workgroup_counting,
        "weighted": r.weighted.as_ref().map(|w| weighted_json(r, w, cols)),
    })
}

/// The `weighted` section: the effects, the verdict, and per bin the albedo estimate, its f64
/// quadrature and the largest weight difference.
fn weighted_json(r: &CaseResult, w: &crate::run::WeightedResult, cols: usize) -> Value {
    let n = r.case.samples;
    let estimate: Vec<f64> = (0..w.sums.bins.len()).map(|i| w.sums.bin_albedo(i, n)).collect();
    json!({
        "effects": r.case.effects,
        "check": w.check,
        "timing": {"gpu_seconds": w.gpu_seconds, "wall_seconds": w.wall_seconds},
        "bin_albedo": nested(&estimate, cols),
        "bin_albedo_reference": nested(&w.check.reference_bins, cols),
        "bin_max_weight_error": nested(&w.sums.max_error, cols),
        "sums": w.sums,
    })
}

/// Writes the heat maps and then `histogram.json` into `dir/<case>/`.
pub fn write_case(dir: &Path, r: &CaseResult, adapter: &str, backend: &str) -> anyhow::Result<()> {
    let folder = dir.join(&r.case.name);
    std::fs::create_dir_all(&folder)?;
    let (rows, cols, row_range, col_range) = match &r.case.job {
        Job::Lobe { grid, .. } => (grid.rows as usize, grid.cols as usize, (-1.0, 1.0), (-std::f64::consts::PI, std::f64::consts::PI)),
        Job::Discrete { dist, .. } => (1, dist.len(), (0.0, 1.0), (0.0, dist.len() as f64)),
    };
    let (row_label, col_label) = if rows == 1 { ("", "index") } else { ("cos θ", "φ") };
    let measured: Vec<f64> = r.counts.bins.iter().map(|&c| c as f64).collect();
    let residual: Vec<f64> = measured
        .iter()
        .zip(&r.expected.bins)
        .map(|(&o, &e)| if e > 0.0 { (o - e) / e.sqrt() } else if o > 0.0 { f64::NAN } else { 0.0 })
        .collect();
    let maps = [
        ("measured.png", format!("{}: measured counts", r.case.name), &measured, Scale::Sequential),
        ("expected.png", format!("{}: expected counts", r.case.name), &r.expected.bins, Scale::Sequential),
        ("residual.png", format!("{}: (measured - expected)/sqrt(expected)", r.case.name), &residual, Scale::Diverging),
    ];
    for (file, title, values, scale) in maps {
        let map = Heatmap { title: &title, rows, cols, values, scale, row_label, col_label, row_range, col_range };
        heatmap::write_png(&map, &folder.join(file))?;
    }
    if let Some(w) = &r.weighted {
        let albedo: Vec<f64> = (0..w.sums.bins.len()).map(|i| w.sums.bin_albedo(i, r.case.samples)).collect();
        let title = format!("{}: albedo per bin (sum of f cos / pdf over N)", r.case.name);
        let map = Heatmap { title: &title, rows, cols, values: &albedo, scale: Scale::Sequential, row_label, col_label, row_range, col_range };
        heatmap::write_png(&map, &folder.join("albedo.png"))?;
    }
    let doc = histogram_json(r, adapter, backend);
    write_atomic(&folder.join("histogram.json"), serde_json::to_string_pretty(&doc)?.as_bytes())?;
    Ok(())
}

/// One line of the run table.
pub fn table_row(r: &CaseResult) -> [String; 9] {
    let time = match r.gpu_seconds {
        Some(g) => format!("{g:.3} s"),
        None => format!("{:.3} s*", r.histogram_seconds),
    };
    let angle = r.angle.as_ref().map_or("-".into(), |a| format!("{:.2e} rad", a.max_angle_rad));
    [
        r.case.name.clone(),
        r.case.samples.to_string(),
        time,
        format!("{:.1}", r.chi2.statistic),
        r.chi2.dof.to_string(),
        format!("{:.4}", r.chi2.p_value),
        if r.passed() { "pass".into() } else { "FAIL".into() },
        angle,
        r.weighted.as_ref().map_or("-".into(), |w| format!("{:.5} ({:+.1e})", w.check.albedo, w.check.relative_error)),
    ]
}

pub const TABLE_HEADER: [&str; 9] = ["case", "samples", "GPU time", "chi2", "dof", "p-value", "verdict", "max angle err", "albedo (rel err)"];

/// The run table (`lobes run`, `lobes merge`).
pub fn format_table(rows: &[[String; 9]]) -> String {
    super::table::render(&TABLE_HEADER, rows.iter().map(|r| r.to_vec()))
}
