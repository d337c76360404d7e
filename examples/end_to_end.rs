//! lobes as a library, end to end: open the GPU, describe a case, histogram it on the GPU,
//! compute the expected counts in f64, and judge the histogram with the χ² test.
//!
//! ```sh
//! cargo run --release --example end_to_end
//! ```
//!
//! Exits with 1 if a case fails the χ² test (at 1% family-wise, Šidák over the cases) or if no
//! GPU adapter opens.

use glam::DVec3;
use lobes::engine::gpu::GpuEngine;
use lobes::engine::job::{DiscreteMethod, Job, SampleRange, Scatter};
use lobes::reference::discrete::Distribution;
use lobes::reference::{Lobe, LobeKind, Method, reflect};
use lobes::stats::chi2::sidak;
use lobes::run::compare;
use lobes::stats::expected::Quadrature;
use lobes::stats::histogram::SphereGrid;

/// One judged case.
pub struct Verdict {
    pub name: String,
    pub samples: u64,
    pub chi2: f64,
    pub dof: u64,
    pub p_value: f64,
    pub passed: bool,
    /// Largest angle between a GPU direction and its f64 twin (lobes), radians.
    pub max_angle_rad: Option<f64>,
}

/// The cases: a GGX lobe sampled by visible normals, seen at 45°, and the tutorial's discrete
/// distribution sampled with an alias table.
pub fn cases() -> Vec<(String, Job)> {
    let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Vndf, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 };
    let incident: DVec3 = reflect::spherical(45f64.to_radians(), 0.0);
    let ggx = Job::Lobe { lobe, incident, grid: SphereGrid { rows: 32, cols: 64 }, scatter: Scatter::Reflect };
    let dist = Distribution::new(&[15.0, 5.0, 5.0, 25.0, 5.0, 10.0, 15.0, 5.0, 5.0, 10.0]).expect("valid weights");
    let alias = Job::Discrete { dist, method: DiscreteMethod::Alias };
    vec![("ggx-vndf-45".into(), ggx), ("tutorial-alias".into(), alias)]
}

/// Runs every case with `samples` samples and seed `seed` on `engine`.
pub fn run(engine: &mut GpuEngine, samples: u64, seed: u64) -> anyhow::Result<Vec<Verdict>> {
    let cases = cases();
    let level = sidak(0.01, cases.len());
    let mut out = Vec::new();
    for (name, job) in cases {
        // Samples 0 .. samples of the stream keyed by `seed`, histogrammed on the GPU.
        let run = engine.histogram(&job, SampleRange::whole(seed, samples), &mut |_| {})?;
        anyhow::ensure!(run.counts.total() == samples, "{name}: every sample is counted once");
        // N × (the pdf integrated over each bin), in f64.
        let expected = compare::expected_counts(&job, samples, &Quadrature::default());
        // Pearson's χ² over the bins and the invalid-sample counters.
        let chi2 = compare::chi2_test(&run.counts, &expected, level);
        // The first 4096 GPU directions against the f64 reference, sample by sample.
        let max_angle_rad = match job {
            Job::Lobe { .. } => {
                let dirs = engine.directions(&job, SampleRange::whole(seed, 4096))?;
                Some(compare::angle_check(&job, seed, 0, &dirs).max_angle_rad)
            }
            Job::Discrete { .. } => None,
        };
        out.push(Verdict { name, samples, chi2: chi2.statistic, dof: chi2.dof, p_value: chi2.p_value, passed: chi2.passed, max_angle_rad });
    }
    Ok(out)
}

#[allow(dead_code)]
fn main() -> std::process::ExitCode {
    let mut engine = match GpuEngine::open() {
        Ok(e) => e,
        Err(e) => {
            eprintln!("error: {e}");
            return std::process::ExitCode::FAILURE;
        }
    };
    println!("adapter: {}", engine.gpu.adapter_name());
    let verdicts = match run(&mut engine, 4_000_000, 1) {
        Ok(v) => v,
        Err(e) => {
            eprintln!("error: {e:#}");
            return std::process::ExitCode::FAILURE;
        }
    };
    for v in &verdicts {
        let angle = v.max_angle_rad.map_or("-".into(), |a| format!("{a:.2e} rad"));
        println!(
            "{:<16} {} samples  chi2 {:.1} / {} dof  p = {:.4}  {}  max angle GPU vs f64: {angle}",
            v.name,
            v.samples,
            v.chi2,
            v.dof,
            v.p_value,
            if v.passed { "pass" } else { "FAIL" }
        );
    }
    if verdicts.iter().all(|v| v.passed) { std::process::ExitCode::SUCCESS } else { std::process::ExitCode::FAILURE }
}
