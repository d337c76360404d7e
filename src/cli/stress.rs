//! `lobes stress`: the stability suite by hand, a table of case, kernel, worst errors and
//! verdict, then the light samplers' table (`experiments::light_stress`); exits non-zero if any
//! row fails.

use super::{OutputArgs, emit, emit_json};
use crate::engine::gpu::GpuEngine;
use crate::experiments::{light_stress, stress};
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
    let lights = light_stress::run_all_lights(engine.as_ref().map(|e| &e.gpu))?;
    let failed = rows.iter().filter(|r| !r.passed).count() + lights.iter().filter(|r| !r.passed).count();
    if args.output.json {
        emit_json(&serde_json::json!({"rows": rows, "lights": lights, "failed": failed,
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
        t += "\n";
        t += &light_table(lights.iter().filter(|r| !args.failures || !r.passed));
        t += &format!("\n{} rows, {failed} failed\n", rows.len() + lights.len());
        emit(&t)?;
    }
    if failed > 0 {
        return Err(super::ChecksFailed(format!("{failed} stress rows failed")).into());
    }
    Ok(())
}

/// The light samplers' rows: case, kernel, samples, valid, bad values, unit error, interior
/// samples whose pdf function disagrees with the reported pdf, verdict.
fn light_table<'a>(rows: impl Iterator<Item = &'a light_stress::LightRow>) -> String {
    table::render(
        &["light case", "kernel", "n", "valid", "bad", "unit err", "pdf ≠ pdf(d)", "verdict"],
        rows.map(|r| {
            vec![
                r.case.clone(),
                r.kernel.clone(),
                r.samples.to_string(),
                r.valid.to_string(),
                r.bad_values.to_string(),
                format!("{:.2e}", r.worst_unit_error),
                format!("{}/{}", r.inconsistent, r.interior),
                if r.passed { "pass" } else { "FAIL" }.to_string(),
            ]
        }),
    )
}
