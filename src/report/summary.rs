//! A run's summary files in its output folder: `OUT/junit.xml` ([`super::junit`]),
//! `OUT/index.html` ([`super::html`]) and then `OUT/summary.json` ([`RunSummary`]), each written
//! atomically by `lobes run` and `lobes merge`, also when cases failed or the run was
//! interrupted. `summary.json` comes last, so its presence means that every output of the run was
//! written; an earlier run's are removed first.

use super::atomic::write_atomic;
use super::output::RunSummary;
use std::path::Path;

/// The files of a run's summary in its output folder, in the order they are written.
pub const SUMMARY_FILES: [&str; 3] = ["junit.xml", super::html::INDEX_HTML, "summary.json"];

/// Removes the summary files an earlier run left in `out`, so that a run that ends without
/// writing its own (killed, or stopped by a second Ctrl-C) leaves none that look complete.
pub fn remove(out: &Path) -> anyhow::Result<()> {
    for path in SUMMARY_FILES.map(|name| out.join(name)) {
        if path.is_file() {
            std::fs::remove_file(&path).map_err(|e| anyhow::anyhow!("cannot remove the earlier {}: {e}", path.display()))?;
        }
    }
    Ok(())
}

/// Writes `OUT/junit.xml` ([`super::junit`]), `OUT/index.html` (with the run's `heading` lines)
/// and then `OUT/summary.json`, each atomically: a `summary.json` means that all the run's
/// outputs were written.
pub fn write(out: &Path, summary: &RunSummary, heading: &[String]) -> anyhow::Result<()> {
    let [junit, html, json] = SUMMARY_FILES;
    let mut heading = heading.to_vec();
    if !summary.not_run.is_empty() {
        heading.push(format!("interrupted: {} cases not run ({})", summary.not_run.len(), summary.not_run.join(", ")));
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
