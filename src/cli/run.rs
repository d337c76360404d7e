//! `lobes run`: every case of a scene, sampled and histogrammed on the GPU, judged against
//! the f64 reference, with per-case outputs and a table.

use super::{OutputArgs, emit, emit_json, usage};
use crate::report::output;
use crate::run::{Backend, run_case};
use crate::scene::{DEFAULT_SCENE, Scene};
use crate::stats::chi2::sidak;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use std::path::PathBuf;

#[derive(Debug, Clone, Args)]
pub struct RunArgs {
    /// Scene file (TOML); without it, the embedded scenes/all-lobes.toml (every lobe and method).
    pub scene: Option<PathBuf>,
    /// Output folder: one subfolder per case with histogram.json and PNG heat maps.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Family-wise significance level, Šidák-corrected over the scene's cases.
    #[arg(long, default_value_t = 0.01, value_parser = parse_level)]
    pub significance: f64,
    /// Use the CPU reference engine even if a GPU adapter exists.
    #[arg(long)]
    pub cpu: bool,
    /// Run only shard I of N (0 ≤ I < N) of every case: its contiguous range of sample indices,
    /// written as raw counts to `OUT/<case>/shard-I-of-N.json` for `lobes merge`.
    #[arg(long, value_name = "I/N", value_parser = super::merge::parse_shard)]
    pub shard: Option<super::merge::Shard>,
    #[command(flatten)]
    pub output: OutputArgs,
}

fn parse_level(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x < 1.0 => Ok(x),
        _ => Err(format!("'{s}' is not a significance level; give a number strictly between 0 and 1")),
    }
}

/// Reads and validates a scene (the embedded default when `path` is None).
pub fn load_scene(path: Option<&PathBuf>) -> anyhow::Result<Scene> {
    let (name, text) = match path {
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| usage(format!("cannot read scene file {}: {e}", p.display())))?;
            (p.display().to_string(), text)
        }
        None => ("<embedded scenes/all-lobes.toml>".to_string(), DEFAULT_SCENE.to_string()),
    };
    Scene::parse(&name, &text).map_err(|e| usage(e.to_string()))
}

fn progress_bar(samples: u64, name: &str) -> ProgressBar {
    let bar = ProgressBar::new(samples);
    bar.set_style(ProgressStyle::with_template("{msg:24} [{bar:40}] {percent:>3}% {per_sec} eta {eta}").unwrap().progress_chars("=> "));
    bar.set_message(name.to_string());
    bar
}

pub fn run(args: &RunArgs) -> anyhow::Result<()> {
    if let Some(shard) = args.shard {
        return super::merge::run_shard(args, shard);
    }
    let scene = load_scene(args.scene.as_ref())?;
    let mut backend = if args.cpu { Backend::Cpu } else { Backend::open_or_cpu() };
    let adapter = backend.adapter();
    let level = sidak(args.significance, scene.cases.len());
    std::fs::create_dir_all(&args.out).map_err(|e| anyhow::anyhow!("cannot create output folder {}: {e}", args.out.display()))?;
    let mut rows = Vec::new();
    let mut summary = Vec::new();
    let mut failed = 0;
    for case in &scene.cases {
        let bar = progress_bar(case.samples, &case.name);
        let result = run_case(&mut backend, case, level, &mut |done| bar.set_position(done))?;
        bar.finish_and_clear();
        output::write_case(&args.out, &result, &adapter, backend.name())?;
        failed += usize::from(!result.chi2.passed);
        rows.push(output::table_row(&result));
        summary.push(json!({
            "case": case.name, "samples": case.samples, "gpu_seconds": result.gpu_seconds,
            "wall_seconds": result.histogram_seconds, "chi2": result.chi2.statistic, "dof": result.chi2.dof,
            "p_value": result.chi2.p_value, "passed": result.chi2.passed,
            "max_angle_rad": result.angle.as_ref().map(|a| a.max_angle_rad),
            "output": args.out.join(&case.name),
        }));
    }
    if args.output.json {
        emit_json(&json!({"adapter": adapter, "backend": backend.name(), "significance": args.significance,
                          "per_case_significance": level, "failed": failed, "cases": summary}))?;
    } else {
        let mut text = format!("adapter: {adapter}\nsignificance {} (Šidák over {} cases: {level:.3e} each)\n\n", args.significance, scene.cases.len());
        text += &output::format_table(&rows);
        if backend.name() == "cpu" {
            text += "\n* wall time of the CPU engine (no GPU adapter)\n";
        }
        text += &format!("\noutputs in {}\n", args.out.display());
        emit(&text)?;
    }
    anyhow::ensure!(failed == 0, "{failed} of {} cases failed the χ² test", scene.cases.len());
    Ok(())
}
