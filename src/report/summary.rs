//! A run's summary files in its output folder: `OUT/junit.xml` ([`super::junit`]),
//! `OUT/index.html` ([`super::html`]) and then `OUT/summary.json` ([`RunSummary`]), each written
//! atomically by `lobes run` and `lobes merge`, also when cases failed or the run was
//! interrupted. `summary.json` comes last, so its presence means that every output of the run was
//! written; an earlier run's are removed first ([`super::folder::OutFolder::clean`]).

use super::atomic::write_atomic;
use super::output::RunSummary;
use std::path::Path;

/// The files of a run's summary in its output folder, in the order they are written.
pub const SUMMARY_FILES: [&str; 3] = [super::folder::JUNIT_XML, super::html::INDEX_HTML, super::folder::SUMMARY_JSON];

/// Writes `OUT/junit.xml` ([`super::junit`]), `OUT/index.html` (with the run's `heading` lines)
/// and then `OUT/summary.json`, each atomically: a `summary.json` means that all the run's
/// outputs were written.
pub fn write(out: &Path, summary: &RunSummary, heading: &[String]) -> anyhow::Result<()> {
    let [junit, html, json] = SUMMARY_FILES;
    let mut heading = heading.to_vec();
    if !summary.not_run.is_empty() {
        heading.push(format!("interrupted: {} cases not run ({})", summary.not_run.len(), summary.not_run.join(", ")));
    }
    if let Some(error) = &summary.error {
        heading.push(format!("no case ran: {error}"));
    }
    if !summary.stale.is_empty() {
        heading.push(format!("removed the outputs of {} cases of an earlier run that this run does not have ({})", summary.stale.len(), summary.stale.join(", ")));
    }
    let files = [
        (junit, super::junit::to_xml(summary)?),
        (html, super::html::page(out, &heading, &summary.cases)),
        (json, serde_json::to_string_pretty(summary)? + "\n"),
    ];
    for (name, text) in files {
        let path = out.join(name);
        write_atomic(&path, text.as_bytes())?;
    }
    Ok(())
}
