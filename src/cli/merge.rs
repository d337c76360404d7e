//! `lobes merge DIR... --out DIR`: adds up the shards of a scene (`lobes run SCENE --shard
//! I/N`, [`crate::run::shard`]) and judges the sums as `lobes run` judges a case
//! ([`crate::run::merge`], [`crate::run::judge`]), with the same outputs and table.

use super::{FileArgs, OutputArgs, emit, emit_json, parse_level, prepare_out};
use crate::report::output::{self, CaseSummary, RunSummary, SUMMARY_VERSION};
use crate::run::judge;
use crate::run::merge::{merge, read_shards};
use crate::stats::chi2::sidak;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `lobes merge`.
#[derive(Debug, Clone, Args)]
pub struct MergeArgs {
    /// Folders (or shard files) to read shards from: each folder's `*/shard-*-of-*.json` and
    /// `shard-*-of-*.json`, as written by `lobes run --shard I/N --out DIR`.
    #[arg(required = true, value_name = "DIR")]
    pub dirs: Vec<PathBuf>,
    /// Output folder: one subfolder per case with histogram.json and PNG heat maps, as `lobes run`.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Family-wise significance level, Šidák-corrected over the scene's cases.
    #[arg(long, default_value_t = 0.01, value_parser = parse_level, allow_hyphen_values = true)]
    pub significance: f64,
    #[command(flatten)]
    pub files: FileArgs,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// `lobes merge DIR... --out DIR`.
pub fn run(args: &MergeArgs) -> anyhow::Result<()> {
    let shards = read_shards(&args.dirs)?;
    let merged = merge(&shards)?;
    let (adapter, backend) = (&merged.adapter, &merged.backend);
    if merged.mixed_adapters() {
        eprintln!(
            "warning: the shards come from more than one adapter ({adapter}); their counts add exactly, \
             but the sum is not bit-identical to a run on any one of them"
        );
    }
    let n = merged.scene.cases.len();
    let level = sidak(args.significance, n);
    prepare_out(&args.out)?;
    let mut rows = Vec::new();
    let mut summary = Vec::new();
    let mut failed = 0;
    for (case, sampled, parts) in merged.iter() {
        let result = judge(case, sampled.clone(), level)?;
        output::write_case(&args.out, &result, adapter, backend, args.files.style())?;
        failed += usize::from(!result.passed());
        rows.push(output::table_row(&result));
        summary.push(CaseSummary { shards: Some(parts), ..CaseSummary::of(&result, &args.out) });
    }
    if args.output.json {
        emit_json(&RunSummary {
            format_version: SUMMARY_VERSION,
            adapter: adapter.clone(),
            backend: backend.clone(),
            significance: args.significance,
            per_case_significance: level,
            shard_files: Some(shards.len()),
            failed,
            errors: 0,
            cases: summary,
        })?;
    } else {
        let mut text = format!(
            "adapter: {adapter}\nmerged {} shard files of scene {} ({})\nsignificance {} (Šidák over {n} cases: {level:.3e} each)\n\n",
            shards.len(),
            merged.scene_name,
            merged.scene_fnv1a64,
            args.significance,
        );
        text += &output::format_table(&rows);
        if shards.iter().any(|s| s.file.timing.gpu_seconds.is_none()) {
            text += "\n* wall time (no GPU timestamps for some shards)\n";
        }
        text += &format!("\noutputs in {}\n", args.out.display());
        emit(&text)?;
    }
    anyhow::ensure!(failed == 0, "{failed} of {n} cases failed the χ² test or the albedo checks");
    Ok(())
}
