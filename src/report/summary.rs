//! A run's summary files in its output folder: `OUT/junit.xml` ([`super::junit`]) and then
//! `OUT/summary.json` ([`RunSummary`]), both written atomically by `lobes run` and `lobes merge`,
//! also when cases failed or the run was interrupted. `summary.json` comes last, so its presence
//! means that every output of the run was written; an earlier run's are removed first.

use super::atomic::write_atomic;
use super::output::RunSummary;
use std::path::Path;

/// The files of a run's summary in its output folder, in the order they are written.
pub const SUMMARY_FILES: [&str; 2] = ["junit.xml", "summary.json"];

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

/// Writes `OUT/junit.xml` ([`super::junit`]) and then `OUT/summary.json`, each atomically: a
/// `summary.json` means that all the run's outputs were written.
pub fn write(out: &Path, summary: &RunSummary) -> anyhow::Result<()> {
    let [junit, json] = SUMMARY_FILES;
    for (name, text) in [(junit, super::junit::to_xml(summary)?), (json, serde_json::to_string_pretty(summary)? + "\n")] {
        let path = out.join(name);
        write_atomic(&path, text.as_bytes()).map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    }
    Ok(())
}
