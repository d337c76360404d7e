//! `lobes stress`: the stability suite by hand, a table of case, kernel, worst errors and
//! verdict; exits non-zero if any row fails.

use super::{OutputArgs, emit, emit_json};
use crate::engine::gpu::GpuEngine;
use crate::experiments::stress;
use crate::report::table;
use clap::Args;

#[derive(Debug, Clone, Args)]
pub struct StressArgs {
    /// Only the CPU f64 reference (no GPU needed).
    #[arg(long)]
    pub cpu: bool,
    /// Print only the rows that fail.
    #[arg(long)]
    pub failures: bool,
    /// List every sample (u, CPU and GPU directions, events, pdfs, validity) of the cases whose
    /// name contains this text, instead of the table.
    #[arg(long, value_name = "TEXT")]
    pub case: Option<String>,
    #[command(flatten)]
    pub output: OutputArgs,
}

pub fn run(args: &StressArgs) -> anyhow::Result<()> {
    let mut engine = if args.cpu { None } else { Some(GpuEngine::open()?) };
    if let (Some(text), Some(e)) = (&args.case, engine.as_mut()) {
        for case in stress::cases().iter().filter(|c| c.name.contains(text.as_str())) {
            emit(&stress::details(case, e)?)?;
        }
        return Ok(());
    }
    let rows = stress::run_all(engine.as_mut())?;
    let failed = rows.iter().filter(|r| !r.passed).count();
    if args.output.json {
        emit_json(&serde_json::json!({"rows": rows, "failed": failed,
            "direction_bound_rad": stress::DIRECTION_BOUND, "unit_bound_f32": stress::UNIT_BOUND_F32}))?;
    } else {
        let shown = rows.iter().filter(|r| !args.failures || !r.passed);
        let mut t = table::render(
            &["case", "kernel", "n", "valid", "unit err", "bad", "mism", "angle rad", "pdf err/bound", "verdict"],
            shown.map(|r| {
                vec![
                    r.case.clone(),
                    r.kernel.to_string(),
                    r.samples.to_string(),
                    r.valid.to_string(),
                    format!("{:.2e}", r.worst_unit_error),
                    r.bad_values.to_string(),
                    r.validity_mismatches.to_string(),
                    format!("{:.2e}", r.worst_angle_rad),
                    format!("{:.2e}", r.worst_pdf_error),
                    if r.passed { "pass" } else { "FAIL" }.to_string(),
                ]
            }),
        );
        t += &format!("\n{} rows, {failed} failed\n", rows.len());
        emit(&t)?;
    }
    if failed > 0 {
        return Err(super::ChecksFailed(format!("{failed} stress rows failed")).into());
    }
    Ok(())
}
