//! The `--out` folder of `lobes run`, `lobes merge` and `lobes check`: one run owns it at a time.
//!
//! - A lock: [`OutFolder::claim`] takes an advisory lock (`flock(2)`, through std's
//!   `File::try_lock`) on `OUT/.lobes.lock`, held until the process ends, however it ends (the
//!   kernel drops it on SIGKILL too). A run, merge or check takes it exclusively; `lobes run --shard`
//!   shares it with other shard runs, which write files of their own names. A second owner
//!   exits with 2 naming the holder ([`FolderError`]), or waits for it with `--wait`.
//! - Its own files only: an owner removes, before it runs anything, every output of an earlier
//!   run in the folder ([`OutFolder::clean`]): the summary files, lobes' files in each case
//!   folder ([`CASE_FILES`]: nothing else is touched, an emptied folder is removed) and the
//!   temporary files a killed process left ([`crate::atomic::is_temporary`]). A case folder of
//!   an earlier run that this run does not write is reported as stale. A killed run therefore
//!   leaves complete folders of the cases that finished and nothing that looks like a result
//!   of the previous run.
//! - Reserved names: the files the run writes at the top of the folder ([`reserved`]) are not
//!   case names; the scene parser refuses them.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

pub use crate::folder_names::{JUNIT_XML, LOCK_FILE, SUMMARY_JSON, TOP_LEVEL_FILES, reserved};

/// The files of a case folder that `lobes run` and `lobes merge` write: only these are removed
/// when the folder is cleaned (a user's own files there, and shard files, are kept). The first
/// four mark a folder that a lobes case wrote.
pub const CASE_FILES: [&str; 11] = [
    "histogram.json",
    "timing.json",
    "counts.npy",
    "expected.npy",
    super::compare::MEASURED_PNG,
    super::compare::EXPECTED_PNG,
    super::compare::RESIDUAL_PNG,
    super::compare::RESIDUAL_COARSE_PNG,
    super::compare::MARGINALS_PNG,
    super::compare::BARS_PNG,
    "albedo.png",
];


/// A folder lobes cannot use: not a folder, cannot be created, or in use by another lobes.
/// Bad input: the CLI exits with its usage code, and writes nothing into the folder.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}", self.render("output folder", "`wait = true`"))]
pub struct FolderError {
    pub path: PathBuf,
    pub problem: FolderProblem,
}

/// What is wrong with an output folder (each with the system's words where it gave some).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FolderProblem {
    NotAFolder,
    CannotCreate(String),
    /// Its lock file cannot be opened or locked.
    CannotLock { lock: PathBuf, error: String },
    /// Another lobes holds it (the holder as its lock file names it).
    InUse { holder: String },
    /// A shard run could not remove the temporary files a killed run left.
    Temporary(String),
}

impl FolderError {
    fn new(path: &Path, problem: FolderProblem) -> Self {
        Self { path: path.to_path_buf(), problem }
    }

    /// Its message, naming the folder's setting `folder` and the setting that waits for a
    /// holder `wait` as the reader knows them (the CLI's `--out` and `--wait`).
    pub fn render(&self, folder: &str, wait: &str) -> String {
        let path = self.path.display();
        match &self.problem {
            FolderProblem::NotAFolder => format!("{folder} {path}: exists and is not a folder; give a folder (created if missing)"),
            FolderProblem::CannotCreate(e) => format!("{folder} {path}: cannot create the output folder: {e}"),
            FolderProblem::CannotLock { lock, error } => format!("{folder} {path}: cannot lock the output folder ({}): {error}", lock.display()),
            FolderProblem::InUse { holder } => format!(
                "{folder} {path} is in use by another lobes ({holder}); two runs into one folder would mix their results. \
                 Wait for it to finish, give another {folder}, or pass {wait} to wait for it"
            ),
            FolderProblem::Temporary(e) => format!("{folder} {path}: {e}"),
        }
    }
}

/// How a run uses the folder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// `lobes run` and `lobes merge`: alone, and it removes what earlier runs left.
    Owner,
    /// `lobes run --shard`: with other shard runs (each writes its own `shard-I-of-N.json`).
    Shard,
}

/// An output folder, locked for this process.
#[derive(Debug)]
pub struct OutFolder {
    path: PathBuf,
    /// Holds the lock until dropped (or the process ends).
    _lock: File,
}

impl OutFolder {
    /// Creates `path` if missing and locks it; see `OutFolder::lock`.
    pub fn claim(path: &Path, access: Access, wait: bool) -> Result<OutFolder, FolderError> {
        if path.exists() && !path.is_dir() {
            return Err(not_a_folder(path));
        }
        std::fs::create_dir_all(path).map_err(|e| FolderError::new(path, FolderProblem::CannotCreate(e.to_string())))?;
        Self::lock(path, access, wait)
    }

    /// Locks `path` if it is already a folder (None if it does not exist): an earlier run's
    /// summary can then be replaced before anything else is known.
    pub fn claim_existing(path: &Path, access: Access, wait: bool) -> Result<Option<OutFolder>, FolderError> {
        match path.is_dir() {
            true => Self::lock(path, access, wait).map(Some),
            false if path.exists() => Err(not_a_folder(path)),
            false => Ok(None),
        }
    }

    /// Locks the folder `path`: exclusively for an [`Access::Owner`], shared for an
    /// [`Access::Shard`]. Where another lobes holds it, an error naming that process, or with
    /// `wait` a line saying so and a wait until it is free. A shard run that finds the folder
    /// free removes the temporary files a killed run left before sharing it.
    fn lock(path: &Path, access: Access, wait: bool) -> Result<OutFolder, FolderError> {
        let file_path = path.join(LOCK_FILE);
        let cannot = |e: std::io::Error| FolderError::new(path, FolderProblem::CannotLock { lock: file_path.clone(), error: e.to_string() });
        let mut file = OpenOptions::new().read(true).write(true).create(true).truncate(false).open(&file_path).map_err(cannot)?;
        let exclusive = match file.try_lock() {
            Ok(()) => true,
            // other shard runs hold it shared: share it too
            Err(std::fs::TryLockError::WouldBlock) if access == Access::Shard && file.try_lock_shared().is_ok() => false,
            Err(std::fs::TryLockError::WouldBlock) => {
                let holder = holder(&mut file);
                if !wait {
                    return Err(FolderError::new(path, FolderProblem::InUse { holder }));
                }
                crate::console::say(format_args!("lobes: waiting for the output folder {}, in use by another lobes ({holder})", path.display()));
                match access {
                    Access::Owner => file.lock().map_err(cannot)?,
                    Access::Shard => file.lock_shared().map_err(cannot)?,
                }
                access == Access::Owner
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(cannot(e)),
        };
        let folder = OutFolder { path: path.to_path_buf(), _lock: file };
        if exclusive {
            folder.write_holder();
            if access == Access::Shard {
                folder.remove_temporary().map_err(|e| FolderError::new(path, FolderProblem::Temporary(e.to_string())))?;
                folder._lock.lock_shared().map_err(cannot)?;
            }
        }
        Ok(folder)
    }

    /// Who holds the lock, for the next process that finds it taken: pid, command line, start.
    fn write_holder(&self) {
        let args: Vec<String> = std::iter::once("lobes".to_string()).chain(std::env::args().skip(1)).collect();
        let since = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
        let text = format!("pid {}: {}, since {since} (Unix time)\n", std::process::id(), args.join(" "));
        let mut f = &self._lock;
        // best effort: the lock itself is what excludes; this only names the holder
        let _ = f.set_len(0).and_then(|()| f.rewind()).and_then(|()| f.write_all(text.as_bytes()));
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Removes what earlier runs left (the summary files, lobes' files in every case folder,
    /// temporary files), so that a run that ends early leaves nothing that looks like a result
    /// of an earlier one. Returns the case folders of an earlier run that are not among
    /// `cases` (this run's), sorted: stale results, now removed.
    pub fn clean(&self, cases: &[&str]) -> anyhow::Result<Vec<String>> {
        self.remove_temporary()?;
        // (a folder of that name is left: writing the file will fail and say so)
        for path in [JUNIT_XML, super::html::INDEX_HTML, SUMMARY_JSON].map(|name| self.path.join(name)).into_iter().filter(|p| p.is_file()) {
            remove_file(&path)?;
        }
        let ours: std::collections::HashSet<String> = cases.iter().map(|c| c.to_lowercase()).collect();
        let mut stale = Vec::new();
        for dir in self.subfolders()? {
            let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            // a folder of this run's case, or one that a lobes case wrote (its JSON or arrays:
            // a folder of a user's pictures that happen to share a name is left alone)
            let ours_here = ours.contains(&name.to_lowercase());
            if !ours_here && !CASE_FILES[..4].iter().any(|f| dir.join(f).is_file()) {
                continue;
            }
            let mut had = false;
            // files only: a folder of such a name is not lobes' (writing there fails and says so)
            for path in CASE_FILES.map(|name| dir.join(name)).into_iter().filter(|p| p.is_file()) {
                had |= remove_file(&path)?;
            }
            // an emptied folder goes; one with a user's files (or shard files) stays
            if had && std::fs::read_dir(&dir).is_ok_and(|mut d| d.next().is_none()) {
                std::fs::remove_dir(&dir).map_err(|e| anyhow::anyhow!("cannot remove the emptied folder {}: {e}", dir.display()))?;
            }
            if had && !ours_here {
                stale.push(name);
            }
        }
        stale.sort();
        Ok(stale)
    }

    /// Removes what an earlier `lobes check` left at the top of the folder: the files `names`
    /// (its report, pictures and composed WGSL) and the temporary files of killed processes
    /// (at the top and in subfolders, as [`OutFolder::clean`] does). A user's other files stay.
    pub fn clean_files(&self, names: &[&str]) -> anyhow::Result<()> {
        self.remove_temporary()?;
        // files only: a folder of such a name is not lobes' (writing there fails and says so)
        for path in names.iter().map(|name| self.path.join(name)).filter(|p| p.is_file()) {
            remove_file(&path)?;
        }
        Ok(())
    }

    /// Removes the temporary files of killed runs, at the top and in the case folders.
    fn remove_temporary(&self) -> anyhow::Result<()> {
        for dir in std::iter::once(self.path.clone()).chain(self.subfolders()?) {
            for entry in read_dir(&dir)? {
                if entry.file_name().to_str().is_some_and(crate::atomic::is_temporary) && entry.file_type().is_ok_and(|t| t.is_file()) {
                    remove_file(&entry.path())?;
                }
            }
        }
        Ok(())
    }

    fn subfolders(&self) -> anyhow::Result<Vec<PathBuf>> {
        let mut dirs: Vec<PathBuf> = read_dir(&self.path)?.into_iter().filter(|e| e.file_type().is_ok_and(|t| t.is_dir())).map(|e| e.path()).collect();
        dirs.sort();
        Ok(dirs)
    }
}

fn not_a_folder(path: &Path) -> FolderError {
    FolderError::new(path, FolderProblem::NotAFolder)
}

/// The holder named in the lock file, or a note that it names none.
fn holder(file: &mut File) -> String {
    let mut text = String::new();
    let _ = file.rewind().and_then(|()| file.read_to_string(&mut text));
    let text = text.trim();
    if text.is_empty() { "it has not yet written its pid".into() } else { text.to_string() }
}

fn read_dir(dir: &Path) -> anyhow::Result<Vec<std::fs::DirEntry>> {
    let entries = std::fs::read_dir(dir).map_err(|e| anyhow::anyhow!("cannot read the folder {}: {e}", dir.display()))?;
    Ok(entries.filter_map(Result::ok).collect())
}

/// Removes a file; whether it was there.
fn remove_file(path: &Path) -> anyhow::Result<bool> {
    match std::fs::remove_file(path) {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(false),
        Err(e) => anyhow::bail!("cannot remove the earlier {}: {e}", path.display()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_owner_is_refused_and_names_the_first() {
        let dir = tempfile::tempdir().unwrap();
        let first = OutFolder::claim(dir.path(), Access::Owner, false).unwrap();
        let err = OutFolder::claim(dir.path(), Access::Owner, false).unwrap_err();
        let FolderProblem::InUse { holder } = &err.problem else { panic!("{err}") };
        assert!(holder.contains(&format!("pid {}", std::process::id())), "{err}");
        let shown = err.render("--out", "--wait");
        assert!(shown.starts_with(&format!("--out {} is in use by another lobes", dir.path().display())) && shown.ends_with("pass --wait to wait for it"), "{shown}");
        assert!(OutFolder::claim(dir.path(), Access::Shard, false).is_err(), "a shard run waits for an owner too");
        drop(first);
        let shard = OutFolder::claim(dir.path(), Access::Shard, false).unwrap();
        let other_shard = OutFolder::claim(dir.path(), Access::Shard, false).expect("shard runs share the folder");
        assert!(OutFolder::claim(dir.path(), Access::Owner, false).is_err(), "an owner waits for the shard runs");
        drop((shard, other_shard));
        OutFolder::claim(dir.path(), Access::Owner, false).unwrap();
    }

    #[test]
    fn cleaning_removes_lobes_files_only_and_names_stale_cases() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path();
        for (file, text) in [
            ("summary.json", "{}"),
            (".lobes-AbC123.tmp", "half"),
            ("notes.txt", "mine"),
            ("a/histogram.json", "{}"),
            ("a/measured.png", ""),
            ("a/.lobes-x1y2z3.tmp", ""),
            ("old/histogram.json", "{}"),
            ("old/counts.npy", ""),
            ("kept/histogram.json", "{}"),
            ("kept/my-notes.md", "mine"),
            ("parts/shard-0-of-2.json", "{}"),
            ("empty-of-lobes/readme", "mine"),
            ("pictures/measured.png", "a user's picture, in a folder no case wrote"),
        ] {
            let path = out.join(file);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, text).unwrap();
        }
        let folder = OutFolder::claim(out, Access::Owner, false).unwrap();
        assert_eq!(folder.clean(&["A", "b"]).unwrap(), ["kept", "old"], "a is this run's (ignoring case)");
        let mut left: Vec<String> = walk(out);
        left.sort();
        assert_eq!(left, [".lobes.lock", "empty-of-lobes/readme", "kept/my-notes.md", "notes.txt", "parts/shard-0-of-2.json", "pictures/measured.png"]);
    }

    fn walk(dir: &Path) -> Vec<String> {
        let mut v = Vec::new();
        for e in std::fs::read_dir(dir).unwrap() {
            let e = e.unwrap();
            let name = e.file_name().to_string_lossy().into_owned();
            if e.file_type().unwrap().is_dir() {
                v.extend(walk(&e.path()).into_iter().map(|n| format!("{name}/{n}")));
            } else {
                v.push(name);
            }
        }
        v
    }

    #[test]
    fn reserved_names() {
        for name in ["summary.json", "junit.xml", "index.html", "INDEX.HTML", ".lobes.lock", ".lobes-abc.tmp"] {
            assert!(reserved(name).is_some(), "{name}");
        }
        for name in ["summary", "junit.xml.d", "ggx", ".lobes-", "x.tmp"] {
            assert!(reserved(name).is_none(), "{name}");
        }
    }
}
