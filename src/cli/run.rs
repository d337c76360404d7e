//! `lobes run`: every case of a scene, sampled and histogrammed on the GPU, judged against
//! the f64 reference, with per-case outputs and a table.

use super::{OutputArgs, emit, emit_json, usage};
use crate::report::output;
use crate::run::{Backend, device_lost, run_case};
use crate::scene::{DEFAULT_SCENE, Scene};
use crate::stats::chi2::sidak;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Args)]
pub struct RunArgs {
    /// Scene file (TOML); without it, the embedded scenes/all-lobes.toml (every lobe and method).
    pub scene: Option<PathBuf>,
    /// Output folder: one subfolder per case with histogram.json and PNG heat maps.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Family-wise significance level, Šidák-corrected over the scene's cases.
    #[arg(long, default_value_t = 0.01, value_parser = parse_level, allow_hyphen_values = true)]
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

/// A significance level strictly between 0 and 1 (`--significance` of run and merge).
pub(super) fn parse_level(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x < 1.0 => Ok(x),
        _ => Err(format!("'{s}' is not a significance level; give a number strictly between 0 and 1")),
    }
}

/// Reads and validates a scene (the embedded default when `path` is None). A file that cannot
/// be read, is not UTF-8 or is not a valid scene is a [`super::UsageError`] naming the file (and
/// the line and column).
pub fn load_scene(path: Option<&PathBuf>) -> anyhow::Result<Scene> {
    let scene = match path {
        Some(p) => {
            let bytes = std::fs::read(p).map_err(|e| {
                usage(format!(
                    "cannot read scene file {}: {e}; give the path of a TOML scene such as scenes/tutorial.toml",
                    p.display()
                ))
            })?;
            Scene::from_bytes(&p.display().to_string(), &bytes)
        }
        None => Scene::parse("<embedded scenes/all-lobes.toml>", DEFAULT_SCENE),
    };
    scene.map_err(|e| usage(e.to_string()))
}

/// Creates the `--out` folder; a path that is not a folder or cannot be created is bad input.
fn prepare_out(out: &Path) -> anyhow::Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(usage(format!("--out {}: exists and is not a folder; give a folder (created if missing)", out.display())));
    }
    std::fs::create_dir_all(out).map_err(|e| usage(format!("--out {}: cannot create the output folder: {e}", out.display())))
}

/// Checks, before anything runs, that every case fits the GPU adapter (histograms larger than a
/// storage binding are split into tiles; a discrete table must fit one binding), and says
/// which cases are split.
fn check_fits(backend: &Backend, scene: &Scene) -> anyhow::Result<()> {
    let Backend::Gpu(engine) = backend else { return Ok(()) };
    for (i, case) in scene.cases.iter().enumerate() {
        let tiling = engine
            .tiling(&case.job)
            .map_err(|e| usage(format!("{}: case '{}': {e}", scene.case_location(i), case.name)))?;
        if tiling.tiles > 1 {
            eprintln!(
                "note: case '{}': {} bins exceed one storage binding of this adapter; counting them in {} passes of {} bins",
                case.name,
                case.job.bins(),
                tiling.tiles,
                tiling.tile_bins
            );
        }
    }
    Ok(())
}

/// Runs one case and writes its outputs. A `histogram.json` left by an earlier run is removed
/// first, so a case that fails here leaves no complete-looking `histogram.json` behind.
fn run_and_write(
    backend: &mut Backend,
    case: &crate::scene::Case,
    level: f64,
    out: &Path,
    bar: &ProgressBar,
) -> anyhow::Result<crate::run::CaseResult> {
    let stale = out.join(&case.name).join("histogram.json");
    match std::fs::remove_file(&stale) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => anyhow::bail!("cannot remove the earlier {}: {e}", stale.display()),
    }
    let result = run_case(backend, case, level, &mut |done| bar.set_position(done))?;
    let adapter = backend.adapter();
    output::write_case(out, &result, &adapter, backend.name())
        .map_err(|e| anyhow::anyhow!("writing the outputs into {}: {e:#}", out.join(&case.name).display()))?;
    Ok(result)
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
    prepare_out(&args.out)?;
    let mut backend = if args.cpu { Backend::Cpu } else { Backend::open_or_cpu() };
    check_fits(&backend, &scene)?;
    let adapter = backend.adapter();
    let n = scene.cases.len();
    let level = sidak(args.significance, n);
    let mut rows = Vec::new();
    let mut summary = Vec::new();
    let (mut failed, mut errors) = (0, 0);
    let (mut cpu_rows, mut wall_rows) = (false, false);
    // A case that cannot run (device lost, a write that fails) is reported and skipped; the
    // others still run. After a lost device the remaining cases run on the CPU engine.
    for (i, case) in scene.cases.iter().enumerate() {
        let bar = progress_bar(case.samples, &case.name);
        let outcome = run_and_write(&mut backend, case, level, &args.out, &bar);
        bar.finish_and_clear();
        let result = match outcome {
            Ok(result) => result,
            Err(e) => {
                errors += 1;
                eprintln!("error: case '{}' ({}): {e:#}; no histogram.json was written for it", case.name, scene.case_location(i));
                if device_lost(&e) && matches!(backend, Backend::Gpu(_)) && i + 1 < n {
                    eprintln!("warning: the GPU device is unusable; the remaining cases run on the CPU reference engine (f64, all cores)");
                    backend = Backend::Cpu;
                }
                let dash = || "-".to_string();
                rows.push([case.name.clone(), case.samples.to_string(), dash(), dash(), dash(), dash(), "ERROR".into(), dash(), dash()]);
                summary.push(json!({"case": case.name, "samples": case.samples, "passed": false, "error": format!("{e:#}"), "output": null}));
                continue;
            }
        };
        failed += usize::from(!result.passed());
        if result.gpu_seconds.is_none() {
            if backend.name() == "cpu" { cpu_rows = true } else { wall_rows = true }
        }
        rows.push(output::table_row(&result));
        summary.push(json!({
            "case": case.name, "samples": case.samples, "backend": backend.name(), "gpu_seconds": result.gpu_seconds,
            "wall_seconds": result.histogram_seconds, "chi2": result.chi2.statistic, "dof": result.chi2.dof,
            "p_value": result.chi2.p_value, "passed": result.passed(),
            "albedo": result.weighted.as_ref().map(|w| json!({"albedo": w.check.albedo, "reference": w.check.reference,
                "relative_error": w.check.relative_error, "p_value": w.check.p_value, "max_weight_error": w.check.max_weight_error,
                "passed": w.check.passed})),
            "max_angle_rad": result.angle.as_ref().map(|a| a.max_angle_rad),
            "output": args.out.join(&case.name),
        }));
    }
    if args.output.json {
        emit_json(&json!({"adapter": adapter, "backend": backend.name(), "significance": args.significance,
                          "per_case_significance": level, "failed": failed, "errors": errors, "cases": summary}))?;
    } else {
        let mut text = format!("adapter: {adapter}\nsignificance {} (Šidák over {n} cases: {level:.3e} each)\n\n", args.significance);
        text += &output::format_table(&rows);
        if cpu_rows {
            text += "\n* wall time of the CPU engine (no GPU adapter)\n";
        }
        if wall_rows {
            text += "\n* wall time: the adapter has no timestamp queries\n";
        }
        text += &format!("\noutputs in {}\n", args.out.display());
        emit(&text)?;
    }
    match (errors, failed) {
        (0, 0) => Ok(()),
        (0, f) => anyhow::bail!("{f} of {n} cases failed the χ² test or the albedo checks"),
        (e, 0) => anyhow::bail!("{e} of {n} cases could not run (see the errors above)"),
        (e, f) => anyhow::bail!("{e} of {n} cases could not run and {f} failed the χ² test or the albedo checks"),
    }
}
