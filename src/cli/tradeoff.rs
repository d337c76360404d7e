//! `lobes tradeoff`: samples × precision, spherical caps against bounded VNDF, and the expected
//! histogram's quadrature, each against its cost (see [`crate::experiments::tradeoff`]).

use super::{OutputArgs, emit, emit_json, usage};
use crate::engine::gpu::GpuEngine;
use crate::report::tradeoff::{self as report, Report};
use crate::experiments::tradeoff::detection::{self, DetectionSettings};
use crate::experiments::tradeoff::{self, MethodSettings, Precision, Sampler, SweepSettings};
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Clone, Args)]
pub struct TradeoffArgs {
    /// Output folder for tradeoff.md, tradeoff.png and tradeoff.json (created if missing);
    /// without it the markdown is printed.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Samplers to sweep, comma-separated: ward-ndf, beckmann-ndf, beckmann-vndf, ggx-ndf,
    /// ggx-vndf, ggx-bounded.
    #[arg(long, value_name = "LIST", default_value = "ward-ndf,beckmann-ndf,beckmann-vndf,ggx-ndf,ggx-vndf,ggx-bounded")]
    pub samplers: String,
    /// Kernel precisions, comma-separated: f32-fast, f32-accurate, f64.
    #[arg(long, value_name = "LIST", default_value = "f32-fast,f32-accurate,f64")]
    pub precisions: String,
    /// Roughness α of the sweep (isotropic), a finite number > 0.
    #[arg(long, default_value_t = 0.3, value_parser = super::parse_alpha, allow_hyphen_values = true)]
    pub alpha: f64,
    /// Incidence θi of the sweep in degrees, [0, 90).
    #[arg(long, value_name = "DEG", default_value_t = 45.0, value_parser = parse_theta, allow_hyphen_values = true)]
    pub incident_theta: f64,
    /// Smallest sample count, as log2 (10 ..= 34).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(10..=34))]
    pub min_log2: u32,
    /// Largest sample count for every sampler, as log2 (10 ..= 34).
    #[arg(long, default_value_t = 26, value_parser = clap::value_parser!(u32).range(10..=34))]
    pub max_log2: u32,
    /// Step between sample counts, as log2 (1 ..= 8).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub step_log2: u32,
    /// One sampler swept further, to --long-max-log2 (or `none`).
    #[arg(long, value_name = "SAMPLER", default_value = "ggx-vndf")]
    pub long: String,
    /// Largest sample count of the --long sampler, as log2 (10 ..= 34).
    #[arg(long, default_value_t = 28, value_parser = clap::value_parser!(u32).range(10..=34))]
    pub long_max_log2: u32,
    /// Which parts to run, comma-separated: sweep, methods, quadrature, detection (the
    /// detection table: minutes on lavapipe, so not by default).
    #[arg(long, value_name = "LIST", default_value = "sweep,methods,quadrature")]
    pub parts: String,
    /// The detection table's turn sizes ε in radians, comma-separated, each in (0, 0.5].
    #[arg(long, value_name = "LIST", default_value = "0.005,0.01,0.02")]
    pub detection_epsilons: String,
    /// The detection table's seeds per sample count (its power is the share of them that
    /// reject), 1 ..= 1000.
    #[arg(long, value_name = "N", default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub detection_seeds: u64,
    /// The detection table's counts, as log2: from --detection-min-log2 doubling up to
    /// --detection-max-log2 (10 ..= 34).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(10..=34))]
    pub detection_min_log2: u32,
    #[arg(long, default_value_t = 27, value_parser = clap::value_parser!(u32).range(10..=34))]
    pub detection_max_log2: u32,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Samples per sampler and precision compared one by one with the f64 reference (1 ..= 2^22).
    #[arg(long, default_value_t = 1 << 18, value_parser = clap::value_parser!(u32).range(1..=1 << 22))]
    pub angle_samples: u32,
    /// Longest predicted time of one sweep point, in seconds (the previous point's time per
    /// sample × N); longer points are skipped and listed as such.
    #[arg(long, value_name = "S", default_value_t = 20.0, value_parser = parse_seconds)]
    pub max_seconds: f64,
    /// Timed runs per measurement; medians are reported (1 ..= 99).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=99))]
    pub runs: u32,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// The parts `--parts` names.
const PARTS: [&str; 4] = ["sweep", "methods", "quadrature", "detection"];

fn parse_seconds(s: &str) -> Result<f64, String> {
    let x = super::parse_number(s)?;
    if x.is_finite() && x > 0.0 { Ok(x) } else { Err(format!("{x} is not a time limit; give a number of seconds > 0")) }
}

fn parse_theta(s: &str) -> Result<f64, String> {
    let x = super::parse_number(s)?;
    if (0.0..90.0).contains(&x) { Ok(x) } else { Err(format!("{x} is outside [0, 90); give θi in degrees, 0 ≤ θ < 90")) }
}

fn list<T>(flag: &str, s: &str, parse: impl Fn(&str) -> Option<T>, allowed: &str) -> anyhow::Result<Vec<T>> {
    let items: Vec<&str> = s.split(',').map(str::trim).filter(|x| !x.is_empty()).collect();
    if items.is_empty() {
        return Err(usage(format!("{flag}: the list is empty; give one or more of {allowed}")));
    }
    items
        .into_iter()
        .map(|x| parse(x).ok_or_else(|| usage(format!("{flag}: '{x}' is unknown; use {allowed}"))))
        .collect()
}

pub fn run(args: &TradeoffArgs) -> anyhow::Result<()> {
    let all = Sampler::ALL.map(|s| s.name()).join(", ");
    let samplers = list("--samplers", &args.samplers, Sampler::parse, &all)?;
    let precisions = list("--precisions", &args.precisions, Precision::parse, "f32-fast, f32-accurate, f64")?;
    let parts = list("--parts", &args.parts, |s| PARTS.contains(&s).then(|| s.to_string()), &PARTS.join(", "))?;
    let epsilons = list("--detection-epsilons", &args.detection_epsilons, |s| s.parse::<f64>().ok().filter(|e| *e > 0.0 && *e <= 0.5), "numbers in (0, 0.5], e.g. 0.005,0.01")?;
    if args.detection_min_log2 > args.detection_max_log2 {
        return Err(usage(format!(
            "--detection-min-log2 {} is above --detection-max-log2 {}; give min ≤ max",
            args.detection_min_log2, args.detection_max_log2
        )));
    }
    let long = match args.long.trim() {
        "none" => None,
        s => Some(Sampler::parse(s).ok_or_else(|| usage(format!("--long: '{s}' is unknown; use none or {all}")))?),
    };
    if args.min_log2 > args.max_log2 {
        return Err(usage(format!("--min-log2 {} is above --max-log2 {}; give min ≤ max", args.min_log2, args.max_log2)));
    }
    if let Some(out) = &args.out {
        super::prepare_out(out)?;
    }
    let mut engine = GpuEngine::open()?;
    let adapter = engine.gpu.adapter_name();
    crate::console::say(format_args!("adapter: {adapter}"));
    let mut log = |s: &str| crate::console::say(s);
    let sweep_settings = SweepSettings {
        samplers,
        precisions,
        alpha: args.alpha,
        incident_theta_deg: args.incident_theta,
        log2_min: args.min_log2,
        log2_max: args.max_log2,
        log2_step: args.step_log2,
        long,
        long_log2_max: args.long_max_log2,
        seed: args.seed,
        angle_samples: args.angle_samples,
        runs: args.runs as usize,
        max_point_seconds: args.max_seconds,
    };
    let has = |p: &str| parts.iter().any(|x| x == p);
    let sweep = if has("sweep") { tradeoff::sweep(&mut engine, &sweep_settings, &mut log)? } else { Default::default() };
    let methods = if has("methods") {
        tradeoff::compare_methods(&mut engine, &MethodSettings { seed: args.seed + 1, runs: args.runs as usize, ..Default::default() }, &mut log)?
    } else {
        Vec::new()
    };
    let mut quadrature = Vec::new();
    if has("quadrature") {
        let ggx_vndf = Sampler::parse("ggx-vndf").expect("a sampler");
        for alpha in [args.alpha, 0.05] {
            log(&format!("quadrature: ggx-vndf alpha {alpha}"));
            quadrature.extend(tradeoff::compare_quadrature(&engine, ggx_vndf, alpha, args.incident_theta, &[1, 2, 4, 8], args.runs as usize)?);
        }
    }
    let detection = if has("detection") {
        let set = DetectionSettings {
            epsilons,
            seeds: args.detection_seeds,
            log2_min: args.detection_min_log2,
            log2_max: args.detection_max_log2,
            ..Default::default()
        };
        Some(detection::detection(&engine.gpu, &set, &mut log).map_err(|e| if e.is_input() { usage(e.to_string()) } else { e.into() })?)
    } else {
        None
    };
    let command = std::iter::once("lobes".to_string()).chain(std::env::args().skip(1)).collect::<Vec<_>>().join(" ");
    let r = Report {
        adapter,
        command,
        grid: [tradeoff::GRID.rows, tradeoff::GRID.cols],
        seed: args.seed,
        angle_samples: args.angle_samples,
        runs: args.runs,
        sweep,
        methods,
        quadrature,
        detection,
    };
    if let Some(out) = &args.out {
        report::write(out, &r)?;
        crate::console::say(format_args!("wrote {0}/tradeoff.md, {0}/tradeoff.png, {0}/tradeoff.json", out.display()));
    }
    if args.output.json {
        emit_json(&r)
    } else {
        emit(&report::markdown(&r))
    }
}
