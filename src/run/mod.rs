//! Running a case end to end: [`run_case`] samples a range of it on the GPU (or the CPU engine),
//! [`judge`] computes the expected counts in f64 and the verdicts. A whole run is one range;
//! scale-out runs shards of it ([`shard`]) and adds them up ([`merge`]) before judging.
//! [`record`] holds the parts of the output files that shard files and `histogram.json` share.
//! A user's WGSL sampler runs whole through the checks of `lobes check` ([`user`]).

pub mod compare;
pub mod merge;
pub mod record;
pub mod shard;
pub mod user;

use crate::engine::cpu;
use crate::engine::gpu::effects::Specialisation;
use crate::engine::gpu::{GpuEngine, GpuError, WeightedRun};
use crate::engine::job::{Counts, Job, SampleRange};
use crate::scene::Case;
use crate::stats::chi2::Chi2;
use compare::{AngleCheck, ExpectedCounts};
use crate::stats::expected::Quadrature;
use crate::stats::weighted::{AlbedoCheck, WeightedSums};
use std::ops::Range;
use std::time::Instant;

/// Samples regenerated on the CPU for the per-sample check.
pub const ANGLE_CHECK_SAMPLES: u32 = 4096;

/// Where histograms are made.
pub enum Backend {
    Gpu(Box<GpuEngine>),
    /// The f64 reference on all cores, when asked for (`lobes run --cpu`).
    Cpu,
}

impl Backend {
    /// The CPU engine if `cpu`, else the GPU; no adapter is an error naming the fix (never a
    /// silent move to the CPU, which would run no WGSL kernel at all).
    pub fn open(cpu: bool) -> Result<Backend, GpuError> {
        if cpu { Ok(Backend::Cpu) } else { GpuEngine::open().map(|e| Backend::Gpu(Box::new(e))) }
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
    /// How the GPU counted ([`crate::engine::gpu::Counting::name`]); None on the CPU engine or
    /// where merged shards counted differently.
    pub counting: Option<String>,
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

/// What samples `range` of a case produced, before any verdict: the raw material of a shard
/// file and, added over shards ([`Sampled::add`]), of a merged case.
#[derive(Debug, Clone)]
pub struct Sampled {
    pub counts: Counts,
    pub gpu_seconds: Option<f64>,
    pub wall_seconds: f64,
    pub counting: Option<String>,
    /// The per-sample check: only for a range that starts at sample 0, on the GPU.
    pub angle: Option<AngleCheck>,
    /// The weighted pass of a case with effects.
    pub weighted: Option<WeightedRun>,
}

impl Sampled {
    /// Adds the results of another range of the same case (shards add exactly): counts and
    /// sums add, times add (GPU time only where both have it), the counting is kept
    /// where both agree, and the per-sample check is whichever range has one.
    pub fn add(&mut self, other: &Sampled) {
        self.counts.add(&other.counts);
        self.gpu_seconds = self.gpu_seconds.zip(other.gpu_seconds).map(|(a, b)| a + b);
        self.wall_seconds += other.wall_seconds;
        if self.counting != other.counting {
            self.counting = None;
        }
        if self.angle.is_none() {
            self.angle.clone_from(&other.angle);
        }
        if let (Some(a), Some(b)) = (&mut self.weighted, &other.weighted) {
            a.sums.add(&b.sums);
            a.gpu_seconds = a.gpu_seconds.zip(b.gpu_seconds).map(|(x, y)| x + y);
            a.wall_seconds += b.wall_seconds;
        }
    }
}

/// Samples `range` of a case on `backend`: the histogram, the per-sample check where the
/// range starts at sample 0 (GPU only: the first [`ANGLE_CHECK_SAMPLES`] directions against
/// f64), and the weighted sums of a case with effects. `lobes run` runs `0 .. samples`,
/// `lobes run --shard I/N` its shard's range.
pub fn run_case(backend: &mut Backend, case: &Case, range: Range<u64>, progress: &mut dyn FnMut(u64)) -> anyhow::Result<Sampled> {
    let (first, n) = (range.start, range.end - range.start);
    let samples = SampleRange { seed: case.seed, first, count: n };
    let mut sampled = match backend {
        Backend::Gpu(engine) => {
            let r = engine.histogram(&case.job, samples, progress)?;
            let counting = Some(r.counting.name().to_string());
            Sampled { counts: r.counts, gpu_seconds: r.gpu_seconds, wall_seconds: r.wall_seconds, counting, angle: None, weighted: None }
        }
        Backend::Cpu => {
            let t = Instant::now();
            let counts = cpu::histogram(&case.job, samples);
            progress(n);
            Sampled { counts, gpu_seconds: None, wall_seconds: t.elapsed().as_secs_f64(), counting: None, angle: None, weighted: None }
        }
    };
    let total = sampled.counts.total();
    anyhow::ensure!(total == n, "case '{}': {total} samples counted for {n} requested", case.name);
    if let (Backend::Gpu(engine), Job::Lobe { .. }) = (&mut *backend, &case.job)
        && first == 0
    {
        let k = ANGLE_CHECK_SAMPLES.min(case.samples.min(u32::MAX as u64) as u32);
        let dirs = engine.directions(&case.job, SampleRange::whole(case.seed, k as u64))?;
        sampled.angle = Some(compare::angle_check(&case.job, case.seed, 0, &dirs));
    }
    if let Some(effects) = &case.effects {
        sampled.weighted = Some(match backend {
            Backend::Gpu(engine) => engine.weighted(&case.job, effects, samples, Specialisation::Specialised)?,
            Backend::Cpu => {
                let t = Instant::now();
                let sums = cpu::weighted(&case.job, effects, samples);
                WeightedRun { sums, gpu_seconds: None, wall_seconds: t.elapsed().as_secs_f64() }
            }
        });
    }
    Ok(sampled)
}

/// A case's expected counts in f64 (the adaptive quadrature of its pdf over the bins) and the
/// seconds they took. They depend on the case only, not on its samples: `lobes run` computes
/// them on another thread while the GPU samples.
pub struct Expected {
    pub counts: ExpectedCounts,
    pub seconds: f64,
}

impl Expected {
    pub fn of(case: &Case) -> Self {
        let t = Instant::now();
        let counts = compare::expected_counts(&case.job, case.samples, &Quadrature::default());
        Self { counts, seconds: t.elapsed().as_secs_f64() }
    }
}

/// Judges all samples of a case (one range `0 .. samples`, or its shards added up) against
/// its [`Expected`] counts: the χ² test at per-case `significance`, and the albedo checks of
/// a weighted case.
pub fn judge(case: &Case, sampled: Sampled, expected: Expected, significance: f64) -> anyhow::Result<CaseResult> {
    let Sampled { counts, gpu_seconds, wall_seconds, counting, angle, weighted } = sampled;
    anyhow::ensure!(
        counts.total() == case.samples,
        "case '{}': {} samples counted for {} requested",
        case.name,
        counts.total(),
        case.samples
    );
    let Expected { counts: expected, seconds: quadrature_seconds } = expected;
    compare::converged(&expected, case.samples).map_err(anyhow::Error::msg)?;
    let chi2 = compare::chi2_test(&counts, &expected, significance);
    let weighted = match (&case.effects, weighted) {
        (None, _) => None,
        (Some(effects), Some(w)) => {
            let check = compare::albedo_check(&case.job, effects, &w.sums, case.samples, significance, &Quadrature::default());
            Some(WeightedResult { sums: w.sums, check, gpu_seconds: w.gpu_seconds, wall_seconds: w.wall_seconds })
        }
        (Some(_), None) => anyhow::bail!("case '{}' is weighted but has no weighted sums", case.name),
    };
    Ok(CaseResult {
        case: case.clone(),
        counts,
        expected,
        chi2,
        gpu_seconds,
        histogram_seconds: wall_seconds,
        quadrature_seconds,
        angle,
        counting,
        weighted,
    })
}

/// Whether `err` left the GPU device unusable, so that `lobes run` runs no further case on it
/// ([`GpuError::is_device_lost`] anywhere in its chain).
pub fn device_lost(err: &anyhow::Error) -> bool {
    err.chain().any(|e| e.downcast_ref::<GpuError>().is_some_and(GpuError::is_device_lost))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lost_device_stops_the_run_and_an_inconsistent_tile_does_not() {
        let lost = anyhow::Error::new(GpuError::Lost("Parent device is lost".into())).context("case 'a'");
        assert!(device_lost(&lost));
        let tile = anyhow::Error::new(GpuError::Inconsistent("tile 1 of 3 counted invalid samples".into())).context("case 'a'");
        assert!(!device_lost(&tile));
        assert!(!device_lost(&anyhow::anyhow!("writing the outputs failed")));
    }
}
