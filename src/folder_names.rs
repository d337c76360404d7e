//! The names of the files a run writes at the top of its output folder, which no case may take
//! (the scene parser refuses them; the report writes them), and lobes' temporary files.

/// The report's index page.
pub const INDEX_HTML: &str = "index.html";
/// The lock file at the top of the folder (kept after the run: removing it would race).
pub const LOCK_FILE: &str = ".lobes.lock";
/// The run's summary for CI (JUnit XML).
pub const JUNIT_XML: &str = "junit.xml";
/// The run's summary, written last.
pub const SUMMARY_JSON: &str = "summary.json";

/// The files a run writes at the top of its folder, which no case may be named.
pub const TOP_LEVEL_FILES: [&str; 4] = [JUNIT_XML, INDEX_HTML, SUMMARY_JSON, LOCK_FILE];

/// Why a case name is reserved, if it is: it names a file the run writes at the top of the
/// output folder (ignoring case: some file systems do), or a temporary file.
///
/// ```
/// assert!(lobes::folder_names::reserved("Summary.JSON").is_some());
/// assert!(lobes::folder_names::reserved("ggx-vndf").is_none());
/// ```
pub fn reserved(name: &str) -> Option<String> {
    let lower = name.to_lowercase();
    if let Some(file) = TOP_LEVEL_FILES.iter().find(|f| **f == lower) {
        return Some(format!("OUT/{file} is a file the run writes itself"));
    }
    crate::atomic::is_temporary(&lower).then(|| "names like .lobes-*.tmp are lobes' temporary files, removed by the next run".to_string())
}
