//! `lobes tradeoff`: accuracy against cost. For each lobe it sweeps the sample count and the
//! kernel's precision ([`Precision`]: f32 with fast approximations, f32 with the builtin
//! functions, f64) and reports per point the time, the χ² test, the L1 distance of the
//! normalised histogram from the expected one and the largest per-sample angle against the f64
//! reference; it compares GGX's two visible-normal samplers (spherical caps and bounded VNDF) by
//! time per sample and by the variance of the albedo estimator; and it measures the expected
//! histogram's quadrature at fixed resolutions on the CPU (f64) and the GPU (f32) against the
//! adaptive f64 quadrature that `lobes run` uses; and ([`detection`]) the samples and seconds
//! each χ² test needs to catch a defect of size ε at 90 % power.

pub mod detection;
pub mod quadrature;
pub use crate::engine::gpu::precision::Precision;

use crate::engine::gpu::GpuEngine;
use crate::engine::job::{Counts, Job, SampleRange, Scatter};
use crate::reference::{Invalid, Lobe, LobeKind, Method, SAMPLERS, reflect, rng, sampler};
use crate::stats::chi2;
use crate::run::compare::{self, AngleCheck, ExpectedCounts};
use crate::stats::expected::{self, Quadrature, REFERENCE_SAMPLES};
use crate::stats::histogram::SphereGrid;
use crate::stats::median::median;
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use statrs::function::gamma::ln_gamma;
use std::time::Instant;

/// The histogram grid of every sweep: 64 rows over cos θ × 128 columns over φ (as `lobes bench`).
pub const GRID: SphereGrid = SphereGrid { rows: 64, cols: 128 };

/// A sampler: lobe and method, named `ggx-vndf`, `ward-ndf`, ….
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sampler {
    pub kind: LobeKind,
    pub method: Method,
}

impl Sampler {
    /// Every sampler of the registry ([`crate::reference::sampler::REGISTRY`]), in its order.
    pub const ALL: [Sampler; SAMPLERS.len()] = {
        let mut out = [Sampler { kind: LobeKind::Ward, method: Method::Ndf }; SAMPLERS.len()];
        let mut i = 0;
        while i < SAMPLERS.len() {
            out[i] = Sampler { kind: SAMPLERS[i].0, method: SAMPLERS[i].1 };
            i += 1;
        }
        out
    };

    pub fn name(&self) -> String {
        format!("{}-{}", self.kind.name(), self.method.name())
    }

    pub fn parse(s: &str) -> Option<Sampler> {
        Sampler::ALL.into_iter().find(|x| x.name() == s.trim())
    }

    pub fn lobe(&self, alpha: f64) -> Lobe {
        Lobe { kind: self.kind, method: self.method, alpha_x: alpha, alpha_y: alpha, alpha_angle: 0.0 }
    }
}

/// What the sample-count × precision sweep runs.
#[derive(Debug, Clone)]
pub struct SweepSettings {
    pub samplers: Vec<Sampler>,
    pub precisions: Vec<Precision>,
    pub alpha: f64,
    pub incident_theta_deg: f64,
    /// Sample counts 2^k for k = min, min + step, … ≤ max.
    pub log2_min: u32,
    pub log2_max: u32,
    pub log2_step: u32,
    /// One sampler swept further, to 2^`long_log2_max`.
    pub long: Option<Sampler>,
    pub long_log2_max: u32,
    pub seed: u64,
    /// Samples regenerated on the CPU in f64 for the per-sample angle (the first ones of the run).
    pub angle_samples: u32,
    /// Timed runs per point; the median time is reported (the counts of every run must agree).
    pub runs: usize,
    /// A point whose predicted time (the previous point's seconds per sample × N) exceeds this
    /// is not run but reported as skipped.
    pub max_point_seconds: f64,
}

impl Default for SweepSettings {
    fn default() -> Self {
        Self {
            samplers: Sampler::ALL.to_vec(),
            precisions: Precision::ALL.to_vec(),
            alpha: 0.3,
            incident_theta_deg: 45.0,
            log2_min: 16,
            log2_max: 26,
            log2_step: 2,
            long: Some(Sampler { kind: LobeKind::Ggx, method: Method::Vndf }),
            long_log2_max: 28,
            seed: 1,
            angle_samples: 1 << 18,
            runs: 1,
            max_point_seconds: 20.0,
        }
    }
}

impl SweepSettings {
    /// The sample counts of a sampler.
    pub fn counts(&self, s: Sampler) -> Vec<u64> {
        let max = if self.long == Some(s) { self.long_log2_max.max(self.log2_max) } else { self.log2_max };
        (self.log2_min..=max).step_by(self.log2_step.max(1) as usize).map(|k| 1u64 << k).collect()
    }
}

/// One point of the sweep.
#[derive(Debug, Clone, Serialize)]
pub struct SweepPoint {
    pub sampler: String,
    pub precision: Precision,
    pub samples: u64,
    pub wall_seconds: f64,
    /// From timestamp queries, where the adapter has them.
    pub gpu_seconds: Option<f64>,
    pub chi2: f64,
    pub dof: u64,
    pub p_value: f64,
    /// Σ over cells (bins and invalid reasons) of |count/N − expected/N|.
    pub l1: f64,
    /// What L1 would be on average for an exact sampler at this N: Σ E|X − λ|/N with
    /// X ~ Poisson(λ = N p) per cell.
    pub l1_noise: f64,
    /// The per-sample check (the same for every N of a sampler and precision).
    pub angle: AngleCheck,
}

impl SweepPoint {
    /// The time used for plots and per-sample costs: GPU time where measured, else wall time.
    pub fn seconds(&self) -> f64 {
        self.gpu_seconds.unwrap_or(self.wall_seconds)
    }
}

/// A precision that could not run for a sampler, and why.
#[derive(Debug, Clone, Serialize)]
pub struct Unavailable {
    pub sampler: String,
    pub precision: Precision,
    pub reason: String,
}

/// The expected-count facts of one sampler, shared by its points.
#[derive(Debug, Clone, Serialize)]
pub struct SweepLobe {
    pub sampler: String,
    pub alpha: f64,
    pub incident_theta_deg: f64,
    /// Σ sqrt(2 p / π) over cells: L1 ≈ this / √N for an exact sampler once counts are large.
    pub l1_noise_coefficient: f64,
    pub quadrature_max_error_sigma_at_1e8: f64,
}

/// A point not run because it would take longer than the limit.
#[derive(Debug, Clone, Serialize)]
pub struct Skipped {
    pub sampler: String,
    pub precision: Precision,
    pub samples: u64,
    /// The previous point's seconds per sample × this N (one run).
    pub predicted_seconds: f64,
}

#[derive(Debug, Clone, Serialize, Default)]
pub struct Sweep {
    pub lobes: Vec<SweepLobe>,
    pub points: Vec<SweepPoint>,
    pub unavailable: Vec<Unavailable>,
    pub skipped: Vec<Skipped>,
}

/// Cell probabilities (bins, then the invalid reasons) of a lobe job.
fn cell_probabilities(e: &ExpectedCounts) -> Vec<f64> {
    e.bins.iter().chain(&e.invalid).copied().collect()
}

/// E|X − λ| for X ~ Poisson(λ): 2 e^{−λ} λ^{⌊λ⌋+1} / ⌊λ⌋! (the mean absolute deviation of the
/// Poisson distribution; Johnson, Kemp & Kotz, "Univariate Discrete Distributions", 3rd ed., §4.3).
pub fn poisson_mean_abs_dev(lambda: f64) -> f64 {
    if lambda <= 0.0 {
        return 0.0;
    }
    let k = lambda.floor();
    (2f64.ln() - lambda + (k + 1.0) * lambda.ln() - ln_gamma(k + 1.0)).exp()
}

/// The L1 distance Σ |c/N − p| of counts from cell probabilities.
pub fn l1_distance(counts: &Counts, p: &[f64]) -> f64 {
    let n = counts.total() as f64;
    counts.bins.iter().chain(&counts.invalid).zip(p).map(|(&c, &q)| (c as f64 / n - q).abs()).sum()
}

/// Why `precision` cannot run `sampler` on this engine, if it cannot.
pub fn unavailable(engine: &GpuEngine, sampler: Sampler, precision: Precision) -> Option<String> {
    if precision != Precision::F64 {
        return None;
    }
    if !engine.gpu.has_f64() {
        return Some(format!("the adapter '{}' has no SHADER_F64", engine.gpu.info.name));
    }
    if !sampler::find(sampler.kind, sampler.method).wgsl.f64 {
        return Some(format!("no f64 kernel for {} (its WGSL is written in f32, not over Real)", sampler.name()));
    }
    None
}

/// The GPU directions of samples 0 .. n of `job` under the engine's current precision against
/// the f64 reference. The directions come back as f32 hi + lo pairs (lo = 0 in f32 kernels).
pub fn angle_error(engine: &mut GpuEngine, job: &Job, seed: u64, n: u32) -> anyhow::Result<AngleCheck> {
    let Job::Lobe { lobe, incident, .. } = job else { anyhow::bail!("angle_error: a lobe job") };
    // u.z = 0: the sweep's jobs reflect, and u.z only chooses a dielectric's event
    let u: Vec<[f32; 3]> = (0..n as u64)
        .map(|i| {
            let r = rng::uniforms(seed, i);
            [r[0] as f32, r[1] as f32, 0.0]
        })
        .collect();
    let gpu = engine.explicit(job, &u)?;
    let pairs: Vec<(Option<DVec3>, Option<DVec3>)> = gpu
        .par_iter()
        .zip(u.par_iter())
        .map(|(g, u)| {
            let s = lobe.sample(*incident, [u[0] as f64, u[1] as f64]);
            let hi = DVec3::new(g[0][0] as f64, g[0][1] as f64, g[0][2] as f64);
            let w = hi + DVec3::new(g[2][0] as f64, g[2][1] as f64, g[2][2] as f64);
            ((g[0][3] == 0.0).then_some(w), s.invalid.is_none().then_some(s.omega_r))
        })
        .collect();
    Ok(AngleCheck::from_pairs(pairs))
}

/// The job of a sampler at the sweep's α and θi.
pub fn sweep_job(s: Sampler, alpha: f64, theta_deg: f64) -> Job {
    Job::Lobe { lobe: s.lobe(alpha), incident: reflect::spherical(theta_deg.to_radians(), 0.0), grid: GRID, scatter: Scatter::Reflect }
}

/// Runs the sample-count × precision sweep; `log` receives progress lines.
pub fn sweep(engine: &mut GpuEngine, set: &SweepSettings, log: &mut dyn FnMut(&str)) -> anyhow::Result<Sweep> {
    let mut out = Sweep::default();
    for &s in &set.samplers {
        let job = sweep_job(s, set.alpha, set.incident_theta_deg);
        let unit = compare::expected_counts(&job, 1, &Quadrature::default());
        let p = cell_probabilities(&unit);
        out.lobes.push(SweepLobe {
            sampler: s.name(),
            alpha: set.alpha,
            incident_theta_deg: set.incident_theta_deg,
            l1_noise_coefficient: p.iter().map(|&q| (2.0 * q / std::f64::consts::PI).sqrt()).sum(),
            quadrature_max_error_sigma_at_1e8: unit.quadrature.as_ref().map_or(0.0, |q| q.max_error_sigma),
        });
        for &prec in &set.precisions {
            if let Some(reason) = unavailable(engine, s, prec) {
                log(&format!("{} {}: unavailable ({reason})", s.name(), prec.name()));
                out.unavailable.push(Unavailable { sampler: s.name(), precision: prec, reason });
                continue;
            }
            engine.precision = prec;
            let result = sweep_one(engine, set, s, &job, &p, prec, log);
            engine.precision = Precision::F32Accurate;
            let (points, skipped) = result?;
            out.points.extend(points);
            out.skipped.extend(skipped);
        }
    }
    Ok(out)
}

fn sweep_one(
    engine: &mut GpuEngine,
    set: &SweepSettings,
    s: Sampler,
    job: &Job,
    p: &[f64],
    prec: Precision,
    log: &mut dyn FnMut(&str),
) -> anyhow::Result<(Vec<SweepPoint>, Vec<Skipped>)> {
    engine.histogram(job, SampleRange::whole(set.seed ^ 0x5eed, 1 << 16), &mut |_| {})?; // compile and warm up
    let angle = angle_error(engine, job, set.seed, set.angle_samples)?;
    let mut points: Vec<SweepPoint> = Vec::new();
    let mut skipped = Vec::new();
    for n in set.counts(s) {
        if let Some(last) = points.last() {
            let predicted = last.seconds() / last.samples as f64 * n as f64;
            if predicted > set.max_point_seconds {
                log(&format!("{} {} 2^{}: skipped, ~{predicted:.0} s predicted (limit {} s)", s.name(), prec.name(), n.trailing_zeros(), set.max_point_seconds));
                skipped.push(Skipped { sampler: s.name(), precision: prec, samples: n, predicted_seconds: predicted });
                continue;
            }
        }
        let (r, wall_seconds, gpu_seconds) = timed_histogram(engine, job, set.seed, n, set.runs)?;
        anyhow::ensure!(r.counts.total() == n, "{} {}: {} samples counted for {n}", s.name(), prec.name(), r.counts.total());
        let expected: Vec<f64> = p.iter().map(|q| q * n as f64).collect();
        let observed: Vec<u64> = r.counts.bins.iter().chain(&r.counts.invalid).copied().collect();
        let test = chi2::test(&observed, &expected, 0.01);
        let point = SweepPoint {
            sampler: s.name(),
            precision: prec,
            samples: n,
            wall_seconds,
            gpu_seconds,
            chi2: test.statistic,
            dof: test.dof,
            p_value: test.p_value,
            l1: l1_distance(&r.counts, p),
            l1_noise: p.iter().map(|&q| poisson_mean_abs_dev(q * n as f64)).sum::<f64>() / n as f64,
            angle: angle.clone(),
        };
        log(&format!(
            "{} {} 2^{}: {:.3} s, chi2/dof {:.3}, p {:.3}, L1 {:.2e} (noise {:.2e}), max angle {:.1e} rad",
            s.name(),
            prec.name(),
            n.trailing_zeros(),
            point.seconds(),
            point.chi2 / point.dof.max(1) as f64,
            point.p_value,
            point.l1,
            point.l1_noise,
            angle.max_angle_rad
        ));
        points.push(point);
    }
    Ok((points, skipped))
}

/// `runs` histograms of samples 0 .. n: the first run's result with the median wall and GPU
/// times; every run must count exactly the same.
fn timed_histogram(engine: &mut GpuEngine, job: &Job, seed: u64, n: u64, runs: usize) -> anyhow::Result<(crate::engine::gpu::GpuRun, f64, Option<f64>)> {
    let first = engine.histogram(job, SampleRange::whole(seed, n), &mut |_| {})?;
    let (mut wall, mut gpu) = (vec![first.wall_seconds], first.gpu_seconds.map(|g| vec![g]));
    for _ in 1..runs.max(1) {
        let r = engine.histogram(job, SampleRange::whole(seed, n), &mut |_| {})?;
        anyhow::ensure!(r.counts == first.counts, "two runs of the same samples counted differently");
        wall.push(r.wall_seconds);
        if let (Some(g), Some(v)) = (r.gpu_seconds, gpu.as_mut()) {
            v.push(g);
        }
    }
    Ok((first, median(wall), gpu.map(median)))
}

/// Spherical caps against bounded VNDF at one roughness and incidence.
#[derive(Debug, Clone, Serialize)]
pub struct MethodPoint {
    pub alpha: f64,
    pub incident_theta_deg: f64,
    pub method: String,
    /// GPU histogram run (f32-accurate kernel) for the time per sample.
    pub gpu_samples: u64,
    pub seconds: f64,
    pub timing: &'static str,
    pub ns_per_sample: f64,
    /// Samples of the albedo estimator (f64 reference samples of the same uniforms).
    pub estimator_samples: u64,
    /// Share of samples reflected below the horizon (weight 0).
    pub below_horizon: f64,
    /// Mean of w = f(ωi, ωr) cos θr / p(ωr) (0 for invalid samples): the albedo estimate.
    pub mean: f64,
    /// Per-sample variance of w.
    pub variance: f64,
    /// ∫ f cos θr dωr by adaptive f64 quadrature, for comparison with `mean`.
    pub albedo_quadrature: f64,
    /// 1 / (variance × seconds per sample): higher is better.
    pub efficiency: f64,
}

/// Settings of the caps-vs-bounded comparison.
#[derive(Debug, Clone)]
pub struct MethodSettings {
    pub alphas: Vec<f64>,
    pub thetas_deg: Vec<f64>,
    pub gpu_samples: u64,
    pub estimator_samples: u64,
    pub seed: u64,
    /// Timed GPU runs per point; the median is reported.
    pub runs: usize,
}

impl Default for MethodSettings {
    fn default() -> Self {
        Self { alphas: vec![0.1, 0.5, 1.0], thetas_deg: vec![30.0, 60.0, 85.0], gpu_samples: 1 << 24, estimator_samples: 1 << 20, seed: 2, runs: 1 }
    }
}

/// Mean and variance of the albedo estimator over samples 0 .. n (f64 reference), and the
/// share below the horizon.
pub fn albedo_estimator(lobe: &Lobe, wi: DVec3, seed: u64, n: u64) -> (f64, f64, f64) {
    let (sum, sum2, below) = (0..n)
        .into_par_iter()
        .map(|i| {
            let u = rng::uniforms(seed, i);
            let s = lobe.sample(wi, [u[0], u[1]]);
            match s.invalid {
                None => {
                    let w = lobe.eval(wi, s.omega_r) * s.omega_r.z / s.pdf_r;
                    (w, w * w, 0u64)
                }
                Some(Invalid::OutsideDomain) => (0.0, 0.0, 1),
                Some(_) => (0.0, 0.0, 0),
            }
        })
        .reduce(|| (0.0, 0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
    let nf = n as f64;
    let mean = sum / nf;
    (mean, (sum2 / nf - mean * mean) * nf / (nf - 1.0), below as f64 / nf)
}

/// Time per sample and albedo-estimator variance of GGX spherical caps and bounded VNDF.
pub fn compare_methods(engine: &mut GpuEngine, set: &MethodSettings, log: &mut dyn FnMut(&str)) -> anyhow::Result<Vec<MethodPoint>> {
    engine.precision = Precision::F32Accurate;
    let mut out = Vec::new();
    for &alpha in &set.alphas {
        for &theta in &set.thetas_deg {
            let wi = reflect::spherical(theta.to_radians(), 0.0);
            let lobe0 = Sampler { kind: LobeKind::Ggx, method: Method::Vndf }.lobe(alpha);
            let albedo: f64 = expected::probabilities(&|w| lobe0.eval(wi, w) * w.z, GRID, alpha.min(1.0), &Quadrature::default())
                .probabilities
                .iter()
                .sum();
            for method in [Method::Vndf, Method::Bounded] {
                let lobe = Sampler { kind: LobeKind::Ggx, method }.lobe(alpha);
                let job = Job::Lobe { lobe, incident: wi, grid: GRID, scatter: Scatter::Reflect };
                engine.histogram(&job, SampleRange::whole(set.seed ^ 0x5eed, 1 << 16), &mut |_| {})?;
                let (_, wall, gpu) = timed_histogram(engine, &job, set.seed, set.gpu_samples, set.runs)?;
                let seconds = gpu.unwrap_or(wall);
                let (mean, variance, below) = albedo_estimator(&lobe, wi, set.seed, set.estimator_samples);
                let point = MethodPoint {
                    alpha,
                    incident_theta_deg: theta,
                    method: if method == Method::Vndf { "spherical caps (vndf)".into() } else { "bounded vndf".into() },
                    gpu_samples: set.gpu_samples,
                    seconds,
                    timing: if gpu.is_some() { "gpu timestamps" } else { "wall" },
                    ns_per_sample: seconds / set.gpu_samples as f64 * 1e9,
                    estimator_samples: set.estimator_samples,
                    below_horizon: below,
                    mean,
                    variance,
                    albedo_quadrature: albedo,
                    efficiency: 1.0 / (variance * seconds / set.gpu_samples as f64),
                };
                log(&format!(
                    "ggx {} alpha {alpha} theta {theta}: {:.2} ns/sample, below horizon {:.4}, mean w {:.5} (quadrature {:.5}), var {:.3e}",
                    method.name(),
                    point.ns_per_sample,
                    below,
                    mean,
                    albedo,
                    variance
                ));
                out.push(point);
            }
        }
    }
    Ok(out)
}

/// One quadrature rule for one lobe.
#[derive(Debug, Clone, Serialize)]
pub struct QuadraturePoint {
    pub sampler: String,
    pub alpha: f64,
    pub incident_theta_deg: f64,
    /// "adaptive" or "gl-N" (N × N Gauss–Legendre per bin).
    pub rule: String,
    pub cpu_seconds: f64,
    /// max over cells with expected count ≥ 5 at 10⁸ samples of |p − p_adaptive| / √(p_adaptive/10⁸).
    pub cpu_max_sigma_at_1e8: f64,
    pub gpu_seconds: Option<f64>,
    pub gpu_wall_seconds: Option<f64>,
    pub gpu_max_sigma_at_1e8: Option<f64>,
    /// max over the same cells of |p_gpu − p_cpu| / p_cpu (GPU f32 against CPU f64, same rule).
    pub gpu_vs_cpu_max_rel: Option<f64>,
    /// Σ |p_gpu − p_cpu| / Σ p_cpu over all bins.
    pub gpu_vs_cpu_l1_rel: Option<f64>,
}

/// max |p − q| / √(q/10⁸) over cells with 10⁸ q ≥ 5.
pub fn max_sigma(p: &[f64], reference: &[f64]) -> f64 {
    p.iter()
        .zip(reference)
        .filter(|&(_, &q)| q * REFERENCE_SAMPLES >= chi2::MIN_EXPECTED)
        .map(|(&a, &q)| (a - q).abs() / (q / REFERENCE_SAMPLES).sqrt())
        .fold(0.0, f64::max)
}

/// The quadrature comparison for one lobe: the adaptive f64 rule and fixed n × n rules.
pub fn compare_quadrature(engine: &GpuEngine, s: Sampler, alpha: f64, theta_deg: f64, rules: &[usize], runs: usize) -> anyhow::Result<Vec<QuadraturePoint>> {
    let lobe = s.lobe(alpha);
    let wi = reflect::spherical(theta_deg.to_radians(), 0.0);
    let mut times = Vec::new();
    let mut adaptive = None;
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        adaptive = Some(expected::lobe_probabilities(&lobe, wi, GRID, &Quadrature::default()));
        times.push(t.elapsed().as_secs_f64());
    }
    let adaptive = adaptive.expect("one run");
    let adaptive_seconds = median(times);
    // every rule, the default adaptive one included, is judged against a stricter setting
    let strict = expected::lobe_probabilities(&lobe, wi, GRID, &Quadrature::STRICT);
    let reference = &strict.probabilities;
    let base = |rule: String, cpu_seconds, cpu_sigma| QuadraturePoint {
        sampler: s.name(),
        alpha,
        incident_theta_deg: theta_deg,
        rule,
        cpu_seconds,
        cpu_max_sigma_at_1e8: cpu_sigma,
        gpu_seconds: None,
        gpu_wall_seconds: None,
        gpu_max_sigma_at_1e8: None,
        gpu_vs_cpu_max_rel: None,
        gpu_vs_cpu_l1_rel: None,
    };
    let mut out = vec![base("adaptive".into(), adaptive_seconds, max_sigma(&adaptive.probabilities, reference))];
    for &n in rules {
        let mut times = Vec::new();
        let mut cpu = Vec::new();
        for _ in 0..runs.max(1) {
            let t = Instant::now();
            cpu = quadrature::fixed_probabilities(&|w| lobe.pdf_r(wi, w), GRID, n);
            times.push(t.elapsed().as_secs_f64());
        }
        let mut point = base(format!("gl-{n}"), median(times), max_sigma(&cpu, reference));
        quadrature::gpu_probabilities(engine, &lobe, wi, GRID, n)?; // compile and warm up
        let gs: Vec<quadrature::GpuQuadrature> =
            (0..runs.max(1)).map(|_| quadrature::gpu_probabilities(engine, &lobe, wi, GRID, n)).collect::<Result<_, _>>()?;
        let g = &gs[0];
        let gpu: Vec<f64> = g.probabilities.iter().map(|&x| x as f64).collect();
        point.gpu_seconds = gs.iter().map(|g| g.gpu_seconds).collect::<Option<Vec<f64>>>().map(median);
        point.gpu_wall_seconds = Some(median(gs.iter().map(|g| g.wall_seconds).collect()));
        point.gpu_max_sigma_at_1e8 = Some(max_sigma(&gpu, reference));
        point.gpu_vs_cpu_max_rel = Some(
            gpu.iter()
                .zip(&cpu)
                .filter(|&(_, &c)| c * REFERENCE_SAMPLES >= chi2::MIN_EXPECTED)
                .map(|(&g, &c)| (g - c).abs() / c)
                .fold(0.0, f64::max),
        );
        point.gpu_vs_cpu_l1_rel = Some(gpu.iter().zip(&cpu).map(|(g, c)| (g - c).abs()).sum::<f64>() / cpu.iter().sum::<f64>());
        out.push(point);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poisson_mean_absolute_deviation() {
        // λ = 1: E|X − 1| = P(0)·1 + Σ_{k≥2} (k − 1) P(k) = 2/e; λ = 2.5 by direct summation
        assert!((poisson_mean_abs_dev(1.0) - 2.0 / std::f64::consts::E).abs() < 1e-15);
        let lambda: f64 = 2.5;
        let direct: f64 = (0..60)
            .map(|k| (k as f64 - lambda).abs() * (-lambda + k as f64 * lambda.ln() - ln_gamma(k as f64 + 1.0)).exp())
            .sum();
        assert!((poisson_mean_abs_dev(lambda) - direct).abs() < 1e-13, "{direct}");
        // large λ: the normal limit √(2λ/π)
        let l = 1e6;
        assert!((poisson_mean_abs_dev(l) / (2.0 * l / std::f64::consts::PI).sqrt() - 1.0).abs() < 1e-5);
        assert_eq!(poisson_mean_abs_dev(0.0), 0.0);
    }

    #[test]
    fn sample_counts_of_the_sweep() {
        let s = SweepSettings::default();
        let vndf = Sampler::parse("ggx-vndf").unwrap();
        assert_eq!(s.counts(Sampler::parse("ward-ndf").unwrap()), [1 << 16, 1 << 18, 1 << 20, 1 << 22, 1 << 24, 1 << 26]);
        assert_eq!(*s.counts(vndf).last().unwrap(), 1 << 28);
        assert!(Sampler::parse("ggx-fancy").is_none());
    }
}
