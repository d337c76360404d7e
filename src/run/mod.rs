//! Running a case end to end: histogram on the GPU (or the CPU engine), expected counts in f64,
//! the χ² verdict and the per-sample check.

use crate::engine::cpu;
use crate::engine::gpu::GpuEngine;
use crate::engine::job::{Counts, Job};
use crate::scene::Case;
use crate::stats::chi2::Chi2;
use crate::stats::compare::{self, AngleCheck, ExpectedCounts};
use crate::stats::expected::Quadrature;
use crate::stats::weighted::{self, AlbedoCheck, WeightedSums};
use crate::engine::gpu::effects::Specialisation;
use std::time::Instant;

/// Samples regenerated on the CPU for the per-sample check.
pub const ANGLE_CHECK_SAMPLES: u32 = 4096;

/// Where histograms are made.
pub enum Backend {
    Gpu(Box<GpuEngine>),
    /// The f64 reference on all cores, where no GPU adapter exists.
    Cpu,
}

impl Backend {
    /// The GPU if an adapter opens, else the CPU engine after a warning naming the fix.
    pub fn open_or_cpu() -> Backend {
        match GpuEngine::open() {
            Ok(e) => Backend::Gpu(Box::new(e)),
            Err(e) => {
                eprintln!("warning: {e}\nwarning: running on the CPU reference engine instead (f64, all cores)");
                Backend::Cpu
            }
        }
    }

    pub fn adapter(&self) -> String {
        match self {
            Backend::Gpu(e) => e.gpu.adapter_name(),
            Backend::Cpu => format!("cpu (f64 reference, {} threads)", rayon::current_num_threads()),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Backend::Gpu(_) => "gpu",
            Backend::Cpu => "cpu",
        }
    }
}

/// Everything a case produced.
#[derive(Debug, Clone)]
pub struct CaseResult {
    pub case: Case,
    pub counts: Counts,
    pub expected: ExpectedCounts,
    pub chi2: Chi2,
    pub gpu_seconds: Option<f64>,
    pub histogram_seconds: f64,
    pub quadrature_seconds: f64,
    pub angle: Option<AngleCheck>,
    pub workgroup_counting: Option<bool>,
    /// The weighted histogram and its verdict, for a case with effects.
    pub weighted: Option<WeightedResult>,
}

/// A case's weighted histogram: the sums, their verdict, and the time of the weighted pass.
#[derive(Debug, Clone)]
pub struct WeightedResult {
    pub sums: WeightedSums,
    pub check: AlbedoCheck,
    pub gpu_seconds: Option<f64>,
    pub wall_seconds: f64,
}

impl CaseResult {
    /// The case's verdict: the χ² test, and the albedo checks where the case is weighted.
    pub fn passed(&self) -> bool {
        self.chi2.passed && self.weighted.as_ref().is_none_or(|w| w.check.passed)
    }
}

/// The weighted sums of samples `first .. first + samples` of a case with effects, with the
/// specialised module on the GPU: (sums, GPU seconds, wall seconds).
pub fn weighted_sums(backend: &mut Backend, case: &Case, first: u64, samples: u64) -> anyhow::Result<(WeightedSums, Option<f64>, f64)> {
    let effects = case.effects.as_ref().expect("a weighted case");
    Ok(match backend {
        Backend::Gpu(engine) => {
            let r = engine.weighted(&case.job, effects, case.seed, first, samples, Specialisation::Specialised)?;
            (r.sums, r.gpu_seconds, r.wall_seconds)
        }
        Backend::Cpu => {
            let t = Instant::now();
            let sums = cpu::weighted(&case.job, effects, case.seed, first, samples);
            (sums, None, t.elapsed().as_secs_f64())
        }
    })
}

/// Judges the weighted sums of a whole case.
pub fn judge_weighted(case: &Case, sums: WeightedSums, gpu_seconds: Option<f64>, wall_seconds: f64, significance: f64) -> WeightedResult {
    let effects = case.effects.as_ref().expect("a weighted case");
    let check = weighted::albedo_check(&case.job, effects, &sums, case.samples, significance, &Quadrature::default());
    WeightedResult { sums, check, gpu_seconds, wall_seconds }
}

/// Histograms samples `first .. first + samples` of a case on `backend`.
pub fn histogram(
    backend: &mut Backend,
    case: &Case,
    first: u64,
    samples: u64,
    progress: &mut dyn FnMut(u64),
) -> anyhow::Result<(Counts, Option<f64>, f64, Option<bool>)> {
    Ok(match backend {
        Backend::Gpu(engine) => {
            let r = engine.histogram(&case.job, case.seed, first, samples, progress)?;
            (r.counts, r.gpu_seconds, r.wall_seconds, Some(r.workgroup_counting))
        }
        Backend::Cpu => {
            let t = Instant::now();
            let c = cpu::histogram(&case.job, case.seed, first, samples);
            progress(samples);
            (c, None, t.elapsed().as_secs_f64(), None)
        }
    })
}

/// Judges counts of a whole case: expected counts, χ² at `significance`, per-sample check.
pub fn judge(backend: &mut Backend, case: &Case, counts: Counts, significance: f64) -> anyhow::Result<(ExpectedCounts, Chi2, f64, Option<AngleCheck>)> {
    let t = Instant::now();
    let expected = compare::expected_counts(&case.job, case.samples, &Quadrature::default());
    let quadrature_seconds = t.elapsed().as_secs_f64();
    let chi2 = compare::chi2_test(&counts, &expected, significance);
    let angle = match (backend, &case.job) {
        (Backend::Gpu(engine), Job::Lobe { .. }) => {
            let n = ANGLE_CHECK_SAMPLES.min(case.samples.min(u32::MAX as u64) as u32);
            let dirs = engine.directions(&case.job, case.seed, 0, n)?;
            Some(compare::angle_check(&case.job, case.seed, 0, &dirs))
        }
        _ => None,
    };
    Ok((expected, chi2, quadrature_seconds, angle))
}

/// Runs one case: all its samples, then the verdict.
pub fn run_case(backend: &mut Backend, case: &Case, significance: f64, progress: &mut dyn FnMut(u64)) -> anyhow::Result<CaseResult> {
    let (counts, gpu_seconds, histogram_seconds, workgroup_counting) = histogram(backend, case, 0, case.samples, progress)?;
    anyhow::ensure!(
        counts.total() == case.samples,
        "case '{}': {} samples counted for {} requested",
        case.name,
        counts.total(),
        case.samples
    );
    let (expected, chi2, quadrature_seconds, angle) = judge(backend, case, counts.clone(), significance)?;
    let weighted = match &case.effects {
        Some(_) => {
            let (sums, gpu, wall) = weighted_sums(backend, case, 0, case.samples)?;
            Some(judge_weighted(case, sums, gpu, wall, significance))
        }
        None => None,
    };
    Ok(CaseResult { case: case.clone(), counts, expected, chi2, gpu_seconds, histogram_seconds, quadrature_seconds, angle, workgroup_counting, weighted })
}
