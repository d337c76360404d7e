//! lobes' lines on stderr. `eprintln!` panics when stderr is gone (a pipe whose reader has
//! exited: `lobes check … 2>&1 | head -2`, common in CI logs), turning any verdict into exit
//! 101; here a line that cannot be written is dropped, and the process ends with its verdict's
//! exit code. (stdout's text goes through `cli::emit`, which treats a closed pipe alike.)

use std::io::Write;

/// Writes `line` and a newline to stderr, as `eprintln!` does; a write that fails is ignored
/// (see the module).
pub fn say(line: impl std::fmt::Display) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}
