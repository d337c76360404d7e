//! `lobes merge DIR... --out DIR`: adds up the shards of a scene (`lobes run SCENE --shard
//! I/N`, [`crate::run::shard`]) and judges the sums as `lobes run` judges a case
//! ([`crate::run::merge`], [`crate::run::judge`]), with the same outputs and table.

use super::{ChecksFailed, FileArgs, OutputArgs, emit, emit_json, parse_level};
use crate::report::folder::Access;
use crate::scene::Entry;
use crate::report::outcome::Outcome;
use crate::report::output::{self, CaseSummary, RunSummary};
use crate::run::{Expected, judge};
use crate::run::merge::{merge, read_shards};
use crate::run::shard::ShardError;
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

/// `e` with the command that writes what it says is missing.
fn with_advice(e: ShardError) -> ShardError {
    let advice = match &e {
        ShardError::NoneIn { dir } => format!("write them with `lobes run SCENE --shard I/N --out {}`", dir.display()),
        ShardError::Missing { .. } => "run the missing `lobes run SCENE --shard I/N` and pass its output folder to `lobes merge` too".into(),
        ShardError::Bad(_) => return e,
    };
    ShardError::Bad(format!("{e}; {advice}"))
}

/// `lobes merge DIR... --out DIR`.
pub fn run(args: &MergeArgs) -> anyhow::Result<()> {
    // as `lobes run`: an existing --out is locked first, and bad shards replace its summary
    let existing = args.files.claim_existing(&args.out)?;
    let (shards, merged) = match read_shards(&args.dirs).and_then(|shards| merge(&shards).map(|m| (shards, m))) {
        Ok(found) => found,
        Err(e) => {
            let e = anyhow::Error::from(with_advice(e));
            if let Some(folder) = &existing {
                super::run::record_error(folder, args.significance, &e);
            }
            return Err(e);
        }
    };
    let (adapter, backend) = (&merged.adapter, &merged.backend);
    for mixture in &merged.mixtures {
        crate::console::say(format_args!("lobes: warning: {mixture}; their counts add exactly, but the sum is not bit-identical to a run on any one of them"));
    }
    let n = merged.scene.cases.len();
    let level = sidak(args.significance, n);
    let folder = match existing {
        Some(folder) => folder,
        None => args.files.claim(&args.out, Access::Owner)?,
    };
    let stale = folder.clean(&merged.scene.cases.iter().map(|c| c.name.as_str()).collect::<Vec<_>>())?;
    let mut rows = Vec::new();
    let mut summary = RunSummary { shard_files: Some(shards.len()), stale, ..RunSummary::new(adapter.clone(), backend.clone(), args.significance, level) };
    // as `lobes run`: a case whose outputs cannot be written is an error, the others still run
    for (case, sampled, parts) in merged.iter() {
        let judged = judge(case, sampled.clone(), Expected::of(case), level).and_then(|result| {
            output::write_case(&args.out, Outcome::Lobe(&result), adapter, backend, args.files.style())
                .map_err(|e| anyhow::anyhow!("writing the outputs into {}: {e:#}", args.out.join(&case.name).display()))
                .map(|()| result)
        });
        match judged {
            Ok(result) => {
                rows.push(output::table_row(Outcome::Lobe(&result)));
                summary.push(CaseSummary { shards: Some(parts), ..CaseSummary::of(Outcome::Lobe(&result), &args.out) });
            }
            Err(e) => {
                crate::console::say(format_args!("lobes: error: case '{}': {e:#}; no histogram.json was written for it", case.name));
                rows.push(output::dash_row(&Entry::Lobe(case), "ERROR"));
                summary.push(CaseSummary { shards: Some(parts), ..CaseSummary::error(&Entry::Lobe(case), format!("{e:#}")) });
            }
        }
    }
    let heading = [
        format!("adapter: {adapter}"),
        format!("merged {} shard files of scene {} ({})", shards.len(), merged.scene_name, merged.scene_fnv1a64),
        format!("significance {} (Šidák over {n} cases: {level:.3e} each)", args.significance),
    ];
    let written = crate::report::summary::write(&args.out, &summary, &heading);
    let (failed, errors) = (summary.failed, summary.errors);
    if args.output.json {
        emit_json(&summary)?;
    } else {
        let mut text = format!("{}\n\n", heading.join("\n"));
        text += &output::format_table(&rows);
        if shards.iter().any(|s| s.file.timing.gpu_seconds.is_none()) {
            text += "\n* wall time (no GPU timestamps for some shards)\n";
        }
        text += &format!("\noutputs in {} (index.html, summary.json, junit.xml)\n", args.out.display());
        emit(&text)?;
    }
    written?;
    if errors > 0 {
        anyhow::bail!("{errors} of {n} cases could not be written (see the errors above)");
    }
    if failed > 0 {
        return Err(ChecksFailed(format!("{failed} of {n} cases failed the χ² test or the albedo checks")).into());
    }
    Ok(())
}
