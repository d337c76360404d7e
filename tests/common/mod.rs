//! Helpers of the tests that drive the `lobes` binary as CI does, and copies of fixture trees.
//! (A module of the test binary, tests/main.rs; the files that use it say `use crate::common;`.)
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Child, Output};
use std::time::{Duration, Instant};

pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// The repository, where the tests run `lobes`.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `lobes ARGS` run from the repository, its output printed for a failing test's log.
pub fn lobes(args: &[&str]) -> Output {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lobes")).current_dir(root()).args(args).output().expect("run lobes");
    println!("$ lobes {}\n{}{}", args.join(" "), text(&out.stdout), text(&out.stderr));
    out
}

pub fn stderr(out: &Output) -> String {
    text(&out.stderr)
}

/// (check, passed) of a `--json` report on stdout.
pub fn verdicts(out: &Output) -> Vec<(String, bool)> {
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("a JSON report on stdout");
    v["checks"].as_array().expect("checks").iter().map(|c| (c["name"].as_str().unwrap_or("?").to_string(), c["passed"].as_bool().unwrap())).collect()
}

/// Waits for `child` at most `limit`; kills it (and fails) past that. The output and the time
/// it took.
pub fn finish(mut child: Child, limit: Duration) -> (Output, Duration) {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!("still running after {limit:?}:\n{}{}", text(&out.stdout), text(&out.stderr));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    (child.wait_with_output().unwrap(), start.elapsed())
}

/// Copies the folder `from` (its files and subfolders) into `to`.
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let t = to.join(p.file_name().unwrap());
        if p.is_dir() { copy_dir(&p, &t) } else { std::fs::copy(&p, &t).unwrap(); }
    }
}

/// A copy of the fixture tree `from` in a fresh scratch folder `name`, with `edit` applied to its
/// `file` (which the edit must change).
pub fn edited_copy(name: &str, from: &Path, file: &str, edit: impl Fn(&str) -> String) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    copy_dir(from, &dir);
    let f = dir.join(file);
    let text = std::fs::read_to_string(&f).unwrap();
    let edited = edit(&text);
    assert_ne!(edited, text, "the edit changed {file}");
    std::fs::write(&f, edited).unwrap();
    dir
}

/// `valid` with `edits` (position fraction, what to do, token index) applied: insert a token of
/// `tokens`, delete up to 8 characters, replace the word there with a token, or duplicate the
/// line. The fuzzing of scene files in tests/bad_input.rs and tests/adversarial_parsers.rs.
pub fn mutate(valid: &str, tokens: &[&str], edits: &[(f64, u8, usize)]) -> String {
    let mut s = valid.to_string();
    for &(pos, op, tok) in edits {
        let mut at = ((s.len() as f64) * pos) as usize;
        while !s.is_char_boundary(at) {
            at -= 1;
        }
        let token = tokens[tok % tokens.len()];
        match op % 4 {
            0 => s.insert_str(at, token),
            1 => {
                // delete up to 8 characters
                let end = s[at..].char_indices().nth(8).map_or(s.len(), |(i, _)| at + i);
                s.replace_range(at..end, "");
            }
            2 => {
                // replace the word at `at` with the token
                let end = s[at..].find(|c: char| !c.is_alphanumeric() && c != '_' && c != '.').map_or(s.len(), |i| at + i);
                s.replace_range(at..end, token);
            }
            _ => {
                // duplicate a line
                let start = s[..at].rfind('\n').map_or(0, |i| i + 1);
                let end = s[at..].find('\n').map_or(s.len(), |i| at + i);
                let line = s[start..end].to_string();
                s.insert_str(start, &(line + "\n"));
            }
        }
    }
    s
}
