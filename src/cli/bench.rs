//! `lobes bench`: samples per second (sampling + histogram, data on the device) per lobe,
//! method and backend. Medians of several runs.

use super::{OutputArgs, emit, emit_json};
use crate::engine::cpu;
use crate::engine::gpu::GpuEngine;
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

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    if let Some(scene) = &args.effects {
        return run_effects(args, scene);
    }
    let runs = args.runs.max(1);
    let jobs = chosen(bench_jobs(args.alpha), &args.samplers)?;
    let mut engine = GpuEngine::open()?;
    let adapter = engine.gpu.adapter_name();
    let mut results = Vec::new();
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
        return emit_json(&serde_json::json!({"adapter": adapter, "runs": runs, "results": results}));
    }
    let mut text = format!("adapter: {adapter}\nmedian of {runs} runs, 64 x 128 bins, alpha {}, 45 deg incidence\n\n", args.alpha);
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
