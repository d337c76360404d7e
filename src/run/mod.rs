//! Running a case end to end: histogram on the GPU (or the CPU engine), expected counts in f64,
//! the χ² verdict and the per-sample check.

use crate::engine::cpu;
use crate::engine::gpu::{GpuEngine, GpuError, WeightedRun};
use crate::engine::job::{Counts, Job, SampleRange};
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

/// The samples `first .. first + count` of a case.
fn samples(case: &Case, first: u64, count: u64) -> SampleRange {
    SampleRange { seed: case.seed, first, count }
}

/// The weighted sums of samples `first .. first + samples` of a case with effects, with the
/// specialised module on the GPU.
pub fn weighted_sums(backend: &mut Backend, case: &Case, first: u64, count: u64) -> anyhow::Result<WeightedRun> {
    let effects = case.effects.as_ref().expect("a weighted case");
    let range = samples(case, first, count);
    Ok(match backend {
        Backend::Gpu(engine) => engine.weighted(&case.job, effects, range, Specialisation::Specialised)?,
        Backend::Cpu => {
            let t = Instant::now();
            let sums = cpu::weighted(&case.job, effects, range);
            WeightedRun { sums, gpu_seconds: None, wall_seconds: t.elapsed().as_secs_f64() }
        }
    })
}

/// Judges the weighted sums of a whole case.
pub fn judge_weighted(case: &Case, run: WeightedRun, significance: f64) -> WeightedResult {
    let effects = case.effects.as_ref().expect("a weighted case");
    let check = weighted::albedo_check(&case.job, effects, &run.sums, case.samples, significance, &Quadrature::default());
    WeightedResult { sums: run.sums, check, gpu_seconds: run.gpu_seconds, wall_seconds: run.wall_seconds }
}

/// The histogram of some samples of a case, and its times.
#[derive(Debug, Clone)]
pub struct HistogramRun {
    pub counts: Counts,
    /// GPU time of the sampling passes (timestamp queries), where there are any.
    pub gpu_seconds: Option<f64>,
    pub wall_seconds: f64,
    /// Whether the GPU counted bins in workgroup memory (None on the CPU engine).
    pub workgroup_counting: Option<bool>,
}

/// Histograms samples `first .. first + count` of a case on `backend`.
pub fn histogram(backend: &mut Backend, case: &Case, first: u64, count: u64, progress: &mut dyn FnMut(u64)) -> anyhow::Result<HistogramRun> {
    let range = samples(case, first, count);
    Ok(match backend {
        Backend::Gpu(engine) => {
            let r = engine.histogram(&case.job, range, progress)?;
            HistogramRun { counts: r.counts, gpu_seconds: r.gpu_seconds, wall_seconds: r.wall_seconds, workgroup_counting: Some(r.workgroup_counting) }
        }
        Backend::Cpu => {
            let t = Instant::now();
            let counts = cpu::histogram(&case.job, range);
            progress(count);
            HistogramRun { counts, gpu_seconds: None, wall_seconds: t.elapsed().as_secs_f64(), workgroup_counting: None }
        }
    })
}

/// The verdict on the counts of a whole case.
#[derive(Debug, Clone)]
pub struct Verdict {
    pub expected: ExpectedCounts,
    pub chi2: Chi2,
    /// Time of the f64 quadrature of the expected counts.
    pub quadrature_seconds: f64,
    /// The per-sample check, on the GPU for a lobe.
    pub angle: Option<AngleCheck>,
}

/// Judges counts of a whole case: expected counts, χ² at `significance`, per-sample check.
pub fn judge(backend: &mut Backend, case: &Case, counts: Counts, significance: f64) -> anyhow::Result<Verdict> {
    let t = Instant::now();
    let expected = compare::expected_counts(&case.job, case.samples, &Quadrature::default());
    let quadrature_seconds = t.elapsed().as_secs_f64();
    let chi2 = compare::chi2_test(&counts, &expected, significance);
    let angle = match (backend, &case.job) {
        (Backend::Gpu(engine), Job::Lobe { .. }) => {
            let n = ANGLE_CHECK_SAMPLES.min(case.samples.min(u32::MAX as u64) as u32);
            let dirs = engine.directions(&case.job, samples(case, 0, n as u64))?;
            Some(compare::angle_check(&case.job, case.seed, 0, &dirs))
        }
        _ => None,
    };
    Ok(Verdict { expected, chi2, quadrature_seconds, angle })
}

/// Runs one case: all its samples, then the verdict.
pub fn run_case(backend: &mut Backend, case: &Case, significance: f64, progress: &mut dyn FnMut(u64)) -> anyhow::Result<CaseResult> {
    let HistogramRun { counts, gpu_seconds, wall_seconds: histogram_seconds, workgroup_counting } = histogram(backend, case, 0, case.samples, progress)?;
    anyhow::ensure!(
        counts.total() == case.samples,
        "case '{}': {} samples counted for {} requested",
        case.name,
        counts.total(),
        case.samples
    );
    let Verdict { expected, chi2, quadrature_seconds, angle } = judge(backend, case, counts.clone(), significance)?;
    let weighted = match &case.effects {
        Some(_) => Some(judge_weighted(case, weighted_sums(backend, case, 0, case.samples)?, significance)),
        None => None,
    };
    Ok(CaseResult { case: case.clone(), counts, expected, chi2, gpu_seconds, histogram_seconds, quadrature_seconds, angle, workgroup_counting, weighted })
}

/// Whether `err` left the GPU device unusable, so that `lobes run` moves the remaining cases
/// to the CPU engine ([`GpuError::is_device_lost`] anywhere in its chain).
pub fn device_lost(err: &anyhow::Error) -> bool {
    err.chain().any(|e| e.downcast_ref::<GpuError>().is_some_and(GpuError::is_device_lost))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lost_device_moves_the_run_to_the_cpu_and_an_inconsistent_tile_does_not() {
        let lost = anyhow::Error::new(GpuError::Lost("Parent device is lost".into())).context("case 'a'");
        assert!(device_lost(&lost));
        let tile = anyhow::Error::new(GpuError::Inconsistent("tile 1 of 3 counted invalid samples".into())).context("case 'a'");
        assert!(!device_lost(&tile));
        assert!(!device_lost(&anyhow::anyhow!("writing the outputs failed")));
    }
}
