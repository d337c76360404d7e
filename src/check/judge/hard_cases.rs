//! `hard_cases`: u at 0, 2⁻²⁴, ½, 1 − 2⁻²⁴, 1 (each component) at grazing and below-surface
//! incidence: every sample valid or rejected with pdf 0 ([`crate::check::hard`] classifies).

use super::Run;
use crate::check::hard::{self, HardRow};
use crate::check::report::{Check, Figures};
use crate::check::{CheckError, incident};

pub(crate) fn check(run: &Run) -> Result<Check, CheckError> {
    let (s, settings) = (&*run.sampler, run.settings);
    let us = hard::uniforms(&s.conventions.hard_u_values());
    let thetas: Vec<f64> = if s.domain.directions() { s.conventions.hard_thetas() } else { vec![settings.incident_theta] };
    let items: Vec<([f32; 4], [f32; 3])> = thetas.iter().flat_map(|&t| us.iter().map(move |u| (*u, incident(t, settings.incident_phi)))).collect();
    let probes = run.passes.probe(&run.params, &items)?;
    let bounds = s.domain.bounds();
    let table: Vec<HardRow> = thetas.iter().zip(probes.chunks(us.len())).map(|(&t, p)| hard::row(t, p, &us, bounds)).collect();
    let summary = match failing(&table) {
        None => {
            let ones = if s.conventions.u_open { "" } else { ", 1" };
            format!("{} inputs at u ∈ {{0, 2⁻²⁴, ½, 1 − 2⁻²⁴{ones}}}⁴ × {} incident angles: every sample valid or rejected with pdf 0", items.len(), thetas.len())
        }
        Some(f) => format!("NaN, ∞, a negative pdf or a bad point at {f}"),
    };
    Ok(Check { passed: table.iter().all(|r| r.passed), summary, figures: Figures::HardCases(table) })
}

/// The failing incident angles and the first failure: "θi 89°, 90°; the first at θi 89°, u = …".
fn failing(table: &[HardRow]) -> Option<String> {
    let rows: Vec<&HardRow> = table.iter().filter(|r| !r.passed).collect();
    let first = rows.first()?;
    let angles: Vec<String> = rows.iter().map(|r| format!("{}°", r.incident_theta)).collect();
    Some(format!(
        "θi {}; the first at θi {}°, u = {:?}: {}",
        angles.join(", "),
        first.incident_theta,
        first.first_failure.unwrap_or_default(),
        first.first_failure_got.as_deref().unwrap_or("")
    ))
}
