//! The one way lobes writes a file: into a temporary file in the target folder, synced to disk,
//! then renamed over the target (`tempfile`'s `NamedTempFile::persist`), and the folder synced.
//! A reader sees the old file or the complete new one, never a part; a failed write leaves no
//! temporary file behind (it is removed when dropped). A process killed mid-write (SIGKILL, a
//! power cut) can leave one, named `.lobes-XXXXXX.tmp` ([`is_temporary`]): the next run into
//! the folder removes them ([`crate::report::folder`]). Files are created with mode 0666 less the
//! process umask, as `open(2)` and every Unix tool create them (tempfile's own default is 0600,
//! which a CI uploader running as another user cannot read).

use std::io::{self, Write};
use std::path::Path;

/// The name of a temporary file starts with this…
pub const TEMPORARY_PREFIX: &str = ".lobes-";
/// …and ends with this.
pub const TEMPORARY_SUFFIX: &str = ".tmp";

/// Whether `name` is that of a temporary file of [`write_atomic`] (left by a killed process if
/// it is still there when no lobes writes the folder).
///
/// ```
/// assert!(lobes::atomic::is_temporary(".lobes-a1B2c3.tmp"));
/// assert!(!lobes::atomic::is_temporary("histogram.json"));
/// ```
pub fn is_temporary(name: &str) -> bool {
    name.len() > TEMPORARY_PREFIX.len() + TEMPORARY_SUFFIX.len() && name.starts_with(TEMPORARY_PREFIX) && name.ends_with(TEMPORARY_SUFFIX)
}

/// Writes `bytes` to `path` atomically.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("a.txt");
/// lobes::atomic::write_atomic(&path, b"hello").unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello");
/// ```
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |out| out.write_all(bytes))
}

/// Writes `path` atomically with `write`, which gets the temporary file (buffered). An error
/// names the path: `cannot write PATH: REASON`.
pub fn write_atomic_with(path: &Path, write: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    replace(path, write).map_err(|e| io::Error::new(e.kind(), format!("cannot write {}: {e}", path.display())))
}

fn replace(path: &Path, write: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(TEMPORARY_PREFIX).suffix(TEMPORARY_SUFFIX);
    // open(2) with 0666 applies the umask (tempfile would create 0600)
    #[cfg(unix)]
    builder.permissions(<std::fs::Permissions as std::os::unix::fs::PermissionsExt>::from_mode(0o666));
    let mut tmp = builder.tempfile_in(folder)?;
    {
        let mut out = io::BufWriter::new(tmp.as_file_mut());
        write(&mut out)?;
        out.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    sync_folder(folder)
}

/// Makes the rename durable (POSIX: the folder's entry is synced separately from the file).
#[cfg(unix)]
fn sync_folder(folder: &Path) -> io::Result<()> {
    std::fs::File::open(folder)?.sync_all()
}

#[cfg(not(unix))]
fn sync_folder(_: &Path) -> io::Result<()> {
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn replaces_the_file_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.json");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second, longer").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second, longer");
        assert_eq!(names(dir.path()), ["x.json"]);
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.json");
        write_atomic(&path, b"old").unwrap();
        let err = write_atomic_with(&path, |out| {
            out.write_all(b"half")?;
            Err(io::Error::other("the encoder failed"))
        })
        .unwrap_err();
        // the writer's own error, named by the path
        assert_eq!(err.to_string(), format!("cannot write {}: the encoder failed", path.display()));
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        // a target that is a folder cannot be replaced by a file
        std::fs::create_dir(dir.path().join("blocked")).unwrap();
        assert!(write_atomic(&dir.path().join("blocked"), b"x").is_err());
        assert_eq!(names(dir.path()), ["blocked", "x.json"]);
        assert!(write_atomic(&dir.path().join("no/such/folder/x"), b"x").is_err());
    }

    /// The file gets 0666 less the umask (0644 under the usual 022), not tempfile's 0600. The
    /// umask is the process's, so this reads it without changing it: a file created by
    /// `File::create` (0666 less the umask) has the mode to expect (tests/fault_injection.rs sets
    /// the umask of a `lobes run` to 022 and 027).
    #[cfg(unix)]
    #[test]
    fn files_are_created_with_the_umask() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain");
        std::fs::File::create(&plain).unwrap();
        let want = std::fs::metadata(&plain).unwrap().permissions().mode() & 0o777;
        let path = dir.path().join("x.json");
        write_atomic(&path, b"x").unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().permissions().mode() & 0o777, want);
    }

    #[test]
    fn an_error_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let blocked = dir.path().join("no-such-folder").join("a.txt");
        let message = write_atomic(&blocked, b"x").unwrap_err().to_string();
        assert!(message.starts_with(&format!("cannot write {}: ", blocked.display())), "{message}");
    }
}
