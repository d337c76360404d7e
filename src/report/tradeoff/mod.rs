//! `lobes tradeoff`'s outputs: `tradeoff.md` ([`markdown`], with the [`tables`]), `tradeoff.png` ([`plot`]: log-log
//! error against time, one panel per sampler, one curve per precision, with the 1/√N line)
//! and `tradeoff.json`; each written under a temporary name and renamed into place.

pub mod plot;
pub mod tables;

pub use tables::{methods_table, quadrature_table, summary_table, sweep_table};

use super::atomic::write_atomic;
use crate::experiments::tradeoff::detection::Detection;
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
    /// The detection table (`--parts detection`): null when not run.
    pub detection: Option<Detection>,
}

/// The whole markdown document.
pub fn markdown(r: &Report) -> String {
    let mut s = format!(
        "# lobes tradeoff\n\n`{}`\n\nAdapter: {}. Grid {} × {} (cos θ × φ), seed {}. Times: median of {} run(s); GPU timestamps where the \
         adapter has them (on lavapipe they measure CPU time), else wall time.\n\n",
        r.command, r.adapter, r.grid[0], r.grid[1], r.seed, r.runs
    );
    let lobe_line = r.sweep.lobes.first().map_or(String::new(), |l| format!("α = {}, θi = {}°", l.alpha, l.incident_theta_deg));
    s += &format!(
        "## Samples × precision ({lobe_line})\n\n\
         L1 = Σ |count/N − p| over all cells (bins and invalid reasons), p from the adaptive f64 quadrature. \
         \"noise\" = the L1 an exact sampler has on average at this N (Σ E|X − Np|/N, X Poisson): L1 / noise near 1 means the \
         histogram is as close as sampling noise allows; a ratio that grows with N is a bias the precision cannot hide any more. \
         The angle is the largest angle between a kernel's ωr and the f64 reference's for the same uniforms, over the first {} \
         samples (the f64 kernel's directions come back as f32 hi + lo pairs).\n\n",
        r.angle_samples
    );
    s += &summary_table(&r.sweep);
    s += "\n";
    s += &sweep_table(&r.sweep);
    if !r.methods.is_empty() {
        s += "\n## GGX visible normals: spherical caps against bounded VNDF\n\n\
              Time from a GPU histogram run (f32-accurate kernel); w = f(ωi, ωr) cos θr / p(ωr) (BRDF without Fresnel, \
              height-correlated G2; 0 for a reflection below the horizon), computed in f64 from the f64 reference samples of the \
              same uniforms; its mean estimates the directional albedo, checked against the quadrature of f cos θr. \
              Higher efficiency = less variance per unit time.\n\n";
        s += &methods_table(&r.methods);
    }
    if !r.quadrature.is_empty() {
        s += "\n## Expected histogram: quadrature rule against cost\n\n\
              gl-n: n × n Gauss–Legendre points per bin, no subdivision, on the CPU in f64 and on the GPU in f32. Errors are \
              max over cells with expected count ≥ 5 at 10⁸ samples of |p − p_adaptive| / √(p_adaptive / 10⁸): the error in \
              standard deviations of a count at 10⁸ samples (the adaptive row gives its own error estimate). GPU time: \
              the dispatch, compilation excluded.\n\n";
        s += &quadrature_table(&r.quadrature);
    }
    if let Some(d) = &r.detection {
        s += &format!(
            "\n## Samples to catch a defect: the family against the fine grid\n\n\
             GGX visible normals (α {}, θi {}°) turned about the normal by ε sin φ (density off by about ε cos φ; \
             src/experiments/tradeoff/turn.wgsl; the panel's turn is ε = 0.005). Each cell: the smallest N = 2^k from which the test rejects \
             (p < {}) in at least {:.0} % of {} seeds, at N and at every larger N measured; the search doubles N until the family \
             and the fine grid reject in every seed, so \"> N\" says the test had not by the last N. A test alone: its own p < α \
             (the fine grid alone is the test before the family); the family: Holm's smallest p < α, the check's verdict. \
             Seconds: one whole `lobes check` at that N on this adapter, t = {:.2} s + N × {:.3e} s (the line through whole checks \
             at the smallest and largest N). {} × {} bins.\n\n",
            d.alpha,
            d.incident_theta_deg,
            d.significance,
            100.0 * d.power,
            d.seeds,
            d.fixed_seconds,
            d.seconds_per_sample,
            d.rows,
            d.cols
        );
        s += &tables::detection_table(d);
    }
    s
}

/// Writes tradeoff.png, tradeoff.json and tradeoff.md into `dir` (created if missing).
pub fn write(dir: &Path, r: &Report) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)?;
    write_atomic(&dir.join("tradeoff.png"), &super::png::encode(&plot::plot(&r.sweep)?)?)?;
    write_atomic(&dir.join("tradeoff.json"), serde_json::to_string_pretty(r)?.as_bytes())?;
    write_atomic(&dir.join("tradeoff.md"), markdown(r).as_bytes())?;
    Ok(())
}
