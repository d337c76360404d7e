//! `lobes bench`: samples per second (sampling + histogram, data on the device) per lobe,
//! method and backend. Medians of several runs.

use super::{OutputArgs, emit, emit_json};
use crate::engine::cpu;
use crate::engine::gpu::{Counting, GpuEngine, Strategy};
use crate::engine::job::{Job, SampleRange, Scatter};
use crate::reference::{Lobe, SAMPLERS, reflect};
use crate::report::table;
use crate::stats::histogram::SphereGrid;
use crate::stats::median::median;
use clap::Args;
use serde::Serialize;
use std::time::Instant;

#[derive(Debug, Clone, Args)]
pub struct BenchArgs {
    /// Samples per GPU run (default 2^24).
    #[arg(long, default_value_t = 1 << 24)]
    pub samples: u64,
    /// Samples per CPU-reference run (default 2^20; the f64 reference is much slower).
    #[arg(long, default_value_t = 1 << 20)]
    pub cpu_samples: u64,
    /// Runs per measurement; the median is reported.
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Roughness of every lobe.
    #[arg(long, default_value_t = 0.3)]
    pub alpha: f64,
    /// Skip the CPU reference backend.
    #[arg(long)]
    pub gpu_only: bool,
    /// Only this sampler, as LOBE-METHOD (e.g. beckmann-vndf); repeat for several. Default: all.
    #[arg(long = "sampler", value_name = "LOBE-METHOD")]
    pub samplers: Vec<String>,
    /// Instead of the lobe table: what generality costs. For each weighted case of this scene
    /// (e.g. scenes/effects.toml), the weighted pass with the case's specialised module against
    /// the uber-kernel with every lobe and effect switched at run time, alternating in one run.
    #[arg(long, value_name = "SCENE")]
    pub effects: Option<std::path::PathBuf>,
    /// Instead of the lobe table: the two ways of counting on this adapter. For each sampler,
    /// the counting pass with workgroup atomics and with per-invocation slabs (lobes counts in
    /// slabs on CPU adapters, in atomics on GPUs), alternating in one run, their medians and
    /// ratio; the counts of the two must be equal bit for bit (else an error).
    #[arg(long, conflicts_with = "effects")]
    pub counting: bool,
    /// Instead of the lobe table: where start-up goes. Opening the adapter and device, composing
    /// and validating the first sampler's module, its first histogram of 1024 samples (pipelines
    /// made and the driver's compilation at first use) and the same again (a dispatch alone).
    #[arg(long, conflicts_with_all = ["effects", "counting"])]
    pub startup: bool,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// One measurement.
#[derive(Debug, Clone, Serialize)]
pub struct BenchResult {
    pub lobe: String,
    pub method: String,
    pub alpha: f64,
    pub backend: String,
    pub samples: u64,
    /// Median over the runs: GPU time from timestamp queries where available, else wall time.
    pub seconds: f64,
    pub samples_per_second: f64,
    pub timing: String,
}

/// The lobes and methods benchmarked, at 45° incidence on a 64 × 128 grid.
pub fn bench_jobs(alpha: f64) -> Vec<Job> {
    SAMPLERS
        .into_iter()
        .map(|(kind, method)| Job::Lobe {
            lobe: Lobe { kind, method, alpha_x: alpha, alpha_y: alpha, alpha_angle: 0.0 },
            incident: reflect::spherical(45f64.to_radians(), 0.0),
            grid: SphereGrid { rows: 64, cols: 128 },
            scatter: Scatter::Reflect,
        })
        .collect()
}

/// The jobs named by `--sampler` (all without it); an unknown name is a usage error listing the names.
fn chosen(jobs: Vec<Job>, names: &[String]) -> anyhow::Result<Vec<Job>> {
    let name = |job: &Job| match job {
        Job::Lobe { lobe, .. } => format!("{}-{}", lobe.kind.name(), lobe.method.name()),
        _ => unreachable!("bench jobs are lobes"),
    };
    let all: Vec<String> = jobs.iter().map(name).collect();
    if let Some(bad) = names.iter().find(|n| !all.contains(n)) {
        return Err(super::usage(format!("--sampler {bad}: no such sampler; use one of {}", all.join(", "))));
    }
    Ok(jobs.into_iter().filter(|j| names.is_empty() || names.contains(&name(j))).collect())
}

fn result(job: &Job, backend: &str, samples: u64, seconds: f64, timing: &str, alpha: f64) -> BenchResult {
    let Job::Lobe { lobe, .. } = job else { unreachable!("bench jobs are lobes") };
    BenchResult {
        lobe: lobe.kind.name().into(),
        method: lobe.method.name().into(),
        alpha,
        backend: backend.into(),
        samples,
        seconds,
        samples_per_second: samples as f64 / seconds,
        timing: timing.into(),
    }
}

/// The specialised module against the uber-kernel on one case.
#[derive(Debug, Clone, Serialize)]
pub struct EffectsResult {
    pub case: String,
    pub samples: u64,
    pub specialised_seconds: f64,
    pub uber_seconds: f64,
    /// uber / specialised: how many times longer generality takes.
    pub ratio: f64,
}

fn run_effects(args: &BenchArgs, scene: &std::path::PathBuf) -> anyhow::Result<()> {
    use crate::engine::gpu::effects::Specialisation::{Specialised, Uber};
    let scene = super::run::load_scene(Some(scene))?;
    let runs = args.runs.max(1);
    let mut engine = GpuEngine::open()?;
    let adapter = engine.gpu.adapter_name();
    let mut results = Vec::new();
    // the uber-kernel draws reflections only (Ward and bounded VNDF have no rough dielectric)
    let reflecting = |c: &&crate::scene::Case| matches!(c.job, Job::Lobe { scatter: Scatter::Reflect, .. });
    for case in scene.cases.iter().filter(|c| c.effects.is_some()).filter(reflecting) {
        let effects = case.effects.as_ref().expect("filtered");
        let mut time = |how, seed: u64, n: u64| -> anyhow::Result<f64> {
            let r = engine.weighted(&case.job, effects, SampleRange::whole(seed, n), how)?;
            Ok(r.gpu_seconds.unwrap_or(r.wall_seconds))
        };
        time(Specialised, 0, 1 << 16)?; // compile and warm up both
        time(Uber, 0, 1 << 16)?;
        let (mut spec, mut uber) = (Vec::new(), Vec::new());
        for r in 0..runs as u64 {
            spec.push(time(Specialised, r, args.samples)?);
            uber.push(time(Uber, r, args.samples)?);
        }
        let ratios: Vec<f64> = uber.iter().zip(&spec).map(|(u, s)| u / s).collect();
        results.push(EffectsResult {
            case: case.name.clone(),
            samples: args.samples,
            specialised_seconds: median(spec),
            uber_seconds: median(uber),
            ratio: median(ratios),
        });
    }
    anyhow::ensure!(!results.is_empty(), "{}: the scene has no weighted cases (set weighted = true, fresnel or masking)", scene.file);
    if args.output.json {
        return emit_json(&serde_json::json!({"adapter": adapter, "runs": runs, "effects": results}));
    }
    let mut text = format!("adapter: {adapter}
weighted pass, median of {runs} runs; ratio = uber-kernel time / specialised time (median of per-run ratios)

");
    text += &table::render(
        &["case", "samples", "specialised s", "uber s", "ratio"],
        results.iter().map(|r| {
            vec![
                r.case.clone(),
                r.samples.to_string(),
                format!("{:.4}", r.specialised_seconds),
                format!("{:.4}", r.uber_seconds),
                format!("{:.2}", r.ratio),
            ]
        }),
    );
    let geo = (results.iter().map(|r| r.ratio.ln()).sum::<f64>() / results.len() as f64).exp();
    text += &format!("
geometric mean of the ratios: {geo:.2}
");
    emit(&text)
}

/// Workgroup atomics against per-invocation slabs on one sampler.
#[derive(Debug, Clone, Serialize)]
pub struct CountingResult {
    pub lobe: String,
    pub method: String,
    pub samples: u64,
    /// What each strategy came to on this adapter ([`Counting::name`]).
    pub atomics: String,
    pub slabs: String,
    /// Medians over the runs, GPU timestamps where available, else wall time.
    pub atomics_seconds: f64,
    pub slabs_seconds: f64,
    pub atomics_samples_per_second: f64,
    pub slabs_samples_per_second: f64,
    /// atomics / slabs, the median of the per-run ratios: above 1, slabs are faster.
    pub ratio: f64,
    pub timing: String,
}

fn run_counting(args: &BenchArgs) -> anyhow::Result<()> {
    let runs = args.runs.max(1);
    let jobs = chosen(bench_jobs(args.alpha), &args.samplers)?;
    let mut engine = GpuEngine::open()?;
    let adapter = engine.gpu.adapter_name();
    let device_type = format!("{:?}", engine.gpu.info.device_type);
    let mut results = Vec::new();
    for job in &jobs {
        let mut time = |strategy, seed: u64, n: u64| -> anyhow::Result<(f64, bool, Counting, crate::engine::job::Counts)> {
            engine.force_counting = Some(strategy);
            let g = engine.histogram(job, SampleRange::whole(seed, n), &mut |_| {})?;
            Ok((g.gpu_seconds.unwrap_or(g.wall_seconds), g.gpu_seconds.is_some(), g.counting, g.counts))
        };
        time(Strategy::Atomics, 0, 1 << 16)?; // compile and warm up both
        time(Strategy::Slabs, 0, 1 << 16)?;
        let (mut atomics, mut slabs, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
        let (mut names, mut timed) = ((String::new(), String::new()), true);
        for r in 0..runs as u64 {
            let (a, ta, ca, counts_a) = time(Strategy::Atomics, r, args.samples)?;
            let (s, ts, cs, counts_s) = time(Strategy::Slabs, r, args.samples)?;
            anyhow::ensure!(counts_a == counts_s, "{}: seed {r}: counting with {} and with {} gave different counts", crate::engine::gpu::compose::describe(job), ca.name(), cs.name());
            atomics.push(a);
            slabs.push(s);
            ratios.push(a / s);
            names = (ca.name().to_string(), cs.name().to_string());
            timed &= ta && ts;
        }
        let Job::Lobe { lobe, .. } = job else { unreachable!("bench jobs are lobes") };
        let (a, s) = (median(atomics), median(slabs));
        results.push(CountingResult {
            lobe: lobe.kind.name().into(),
            method: lobe.method.name().into(),
            samples: args.samples,
            atomics: names.0,
            slabs: names.1,
            atomics_seconds: a,
            slabs_seconds: s,
            atomics_samples_per_second: args.samples as f64 / a,
            slabs_samples_per_second: args.samples as f64 / s,
            ratio: median(ratios),
            timing: if timed { "gpu timestamps" } else { "wall" }.into(),
        });
    }
    engine.force_counting = None;
    let default = engine.counting(64 * 128).name();
    if args.output.json {
        return emit_json(&serde_json::json!({"adapter": adapter, "device_type": device_type, "default_counting": default, "runs": runs, "counting": results}));
    }
    let mut text = format!(
        "adapter: {adapter} (device type {device_type}; counts in {default} by default)\n\
         counting pass, median of {runs} runs, 64 x 128 bins, alpha {}, 45 deg incidence; ratio = atomics time / slabs time (median of per-run ratios); counts equal bit for bit\n\n",
        args.alpha
    );
    text += &table::render(
        &["lobe", "method", "samples", "atomics", "atomics samples/s", "slabs", "slabs samples/s", "ratio"],
        results.iter().map(|r| {
            vec![
                r.lobe.clone(),
                r.method.clone(),
                r.samples.to_string(),
                r.atomics.clone(),
                format!("{:.3e}", r.atomics_samples_per_second),
                r.slabs.clone(),
                format!("{:.3e}", r.slabs_samples_per_second),
                format!("{:.2}", r.ratio),
            ]
        }),
    );
    emit(&text)
}

/// Where start-up goes, in seconds of wall time.
#[derive(Debug, Clone, Serialize)]
pub struct StartupResult {
    /// Instance, adapter, device (and the pipeline cache file read, where there is one).
    pub open_seconds: f64,
    /// The first sampler's module composed and validated by naga.
    pub compose_seconds: f64,
    /// Its first histogram of 1024 samples: the module and pipelines made, the driver's
    /// compilation at first use, one dispatch and the readback.
    pub first_histogram_seconds: f64,
    /// The same again: one dispatch and the readback.
    pub second_histogram_seconds: f64,
    /// Whether a pipeline cache was in use ([`crate::engine::gpu::pipeline_cache`]).
    pub pipeline_cache: bool,
}

fn run_startup(args: &BenchArgs) -> anyhow::Result<()> {
    let job = chosen(bench_jobs(args.alpha), &args.samplers)?.into_iter().next().expect("a sampler");
    let t = Instant::now();
    let mut engine = GpuEngine::open()?;
    let open_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    crate::engine::gpu::compose::validate("startup", &engine.source(&job, None))?;
    let compose_seconds = t.elapsed().as_secs_f64();
    let mut histogram = || -> anyhow::Result<f64> {
        let t = Instant::now();
        engine.histogram(&job, SampleRange::whole(0, 1024), &mut |_| {})?;
        Ok(t.elapsed().as_secs_f64())
    };
    let first_histogram_seconds = histogram()?;
    let second_histogram_seconds = histogram()?;
    let r = StartupResult { open_seconds, compose_seconds, first_histogram_seconds, second_histogram_seconds, pipeline_cache: engine.gpu.pipeline_cache.is_some() };
    let adapter = engine.gpu.adapter_name();
    drop(engine); // saves the pipeline cache, as a run does
    if args.output.json {
        return emit_json(&serde_json::json!({"adapter": adapter, "startup": r}));
    }
    let mut text = format!("adapter: {adapter}; pipeline cache {}\n\n", if r.pipeline_cache { "on" } else { "off" });
    text += &table::render(
        &["stage", "seconds"],
        [
            ("open the adapter and device", r.open_seconds),
            ("compose and validate the module", r.compose_seconds),
            ("first histogram, 1024 samples (pipelines, compilation)", r.first_histogram_seconds),
            ("second histogram, 1024 samples", r.second_histogram_seconds),
        ]
        .into_iter()
        .map(|(s, v)| vec![s.to_string(), format!("{v:.4}")]),
    );
    emit(&text)
}

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    if let Some(scene) = &args.effects {
        return run_effects(args, scene);
    }
    if args.counting {
        return run_counting(args);
    }
    if args.startup {
        return run_startup(args);
    }
    let runs = args.runs.max(1);
    let jobs = chosen(bench_jobs(args.alpha), &args.samplers)?;
    let mut engine = GpuEngine::open()?;
    let adapter = engine.gpu.adapter_name();
    let mut results = Vec::new();
    let mut counting = "";
    for job in jobs {
        engine.histogram(&job, SampleRange::whole(0, 1 << 16), &mut |_| {})?; // compile and warm up
        let mut times = Vec::new();
        let mut timing = "wall";
        for r in 0..runs {
            let g = engine.histogram(&job, SampleRange::whole(r as u64, args.samples), &mut |_| {})?;
            timing = if g.gpu_seconds.is_some() { "gpu timestamps" } else { "wall" };
            times.push(g.gpu_seconds.unwrap_or(g.wall_seconds));
        }
        results.push(result(&job, "gpu", args.samples, median(times), timing, args.alpha));
        counting = engine.counting(job.bins() as u32).name();
        if !args.gpu_only {
            let times = (0..runs)
                .map(|r| {
                    let t = Instant::now();
                    cpu::histogram(&job, SampleRange::whole(r as u64, args.cpu_samples));
                    t.elapsed().as_secs_f64()
                })
                .collect();
            let threads = format!("cpu-f64-{}-threads", rayon::current_num_threads());
            results.push(result(&job, &threads, args.cpu_samples, median(times), "wall", args.alpha));
        }
    }
    if args.output.json {
        return emit_json(&serde_json::json!({"adapter": adapter, "counting": counting, "runs": runs, "results": results}));
    }
    let mut text = format!("adapter: {adapter}; counting in {counting}\nmedian of {runs} runs, 64 x 128 bins, alpha {}, 45 deg incidence\n\n", args.alpha);
    text += &table::render(
        &["lobe", "method", "backend", "samples", "seconds", "samples/s"],
        results.iter().map(|r| {
            vec![
                r.lobe.clone(),
                r.method.clone(),
                r.backend.clone(),
                r.samples.to_string(),
                format!("{:.4}", r.seconds),
                format!("{:.3e}", r.samples_per_second),
            ]
        }),
    );
    emit(&text)
}
