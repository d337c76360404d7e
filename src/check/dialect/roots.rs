//! Where the modules of a tree are found: the shader roots, their files (a scan of the file
//! system) and the stubs that stand in for modules.

use super::super::CheckError;
use super::super::compose::Source;
use super::super::composition::Composition;
use std::path::{Path, PathBuf};

/// The roots modules are looked up under: the given ones, else the first file's folder.
pub(in crate::check) fn roots(sources: &[Source], c: &Composition) -> Vec<PathBuf> {
    if !c.shader_roots.is_empty() {
        return c.shader_roots.clone();
    }
    let first = Path::new(&sources[0].name);
    vec![first.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf()]
}

/// The roots as messages name them: `shaders, vendor/shaders`.
pub(in crate::check) fn show_roots(roots: &[PathBuf]) -> String {
    roots.iter().map(|r| r.display().to_string()).collect::<Vec<_>>().join(", ")
}

/// Every file with one of `exts` under `dir` (hidden folders and `target` skipped), at most
/// 20 000. Each folder and file is taken once, by its device and inode: a symbolic link back up
/// the tree (`loops/a -> .`) is not walked again, and a file reached by two links is one file.
pub(in crate::check) fn scan(dir: &Path, exts: &[&str], out: &mut Vec<PathBuf>) {
    scan_once(dir, exts, out, &mut std::collections::HashSet::new());
}

/// A file system object's identity: its device and inode.
fn identity(p: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(p).ok().map(|m| (m.dev(), m.ino()))
}

fn scan_once(dir: &Path, exts: &[&str], out: &mut Vec<PathBuf>, seen: &mut std::collections::HashSet<(u64, u64)>) {
    if !identity(dir).is_some_and(|id| seen.insert(id)) {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut entries: Vec<_> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if out.len() >= 20_000 {
            return;
        }
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if p.is_dir() {
            if !name.starts_with('.') && name != "target" {
                scan_once(&p, exts, out, seen);
            }
        } else if exts.iter().any(|e| p.extension().and_then(|x| x.to_str()) == Some(e)) && identity(&p).is_some_and(|id| seen.insert(id)) {
            out.push(p);
        }
    }
}

/// The stubs' files, read.
pub(super) fn stubs(c: &Composition) -> Result<Vec<(String, Source)>, CheckError> {
    c.stubs.iter().map(|(m, f)| Source::read(f).map(|s| (m.clone(), s))).collect()
}
