//! Faults a CI job meets, injected into `lobes run` and `lobes merge` as child processes (issue
//! 24, items 7–14): two runs into one `--out`, signals sent to a child by its pid (a second
//! SIGINT, SIGKILL), a full disk (a file-size limit, RLIMIT_FSIZE through the shell's
//! `ulimit -f`, which makes every write past it fail with EFBIG as a full disk fails with
//! ENOSPC, on any Linux and without privileges), temporary files of a killed run, edited
//! shards, bad input into a folder of an earlier run, the umask, and `WGPU_BACKEND`.
//!
//! It also holds docs/errors.md to the code: every row of its tables names a test that exists,
//! the rows that name `fault_injection` are exactly the faults run here, and each of them
//! checks the row's exit code and the messages it quotes.
//!
//! Everything runs on the CPU engine (`--cpu`, no adapter needed) in well under a minute, but
//! `lobes check --out` (the same folder rules), which runs on lavapipe and fails without an
//! adapter.

use lobes::report::output::{RunStatus, RunSummary};
use lobes::run::shard::ShardFile;
use quick_junit::{Report, TestCaseStatus};
use std::collections::BTreeSet;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("fault-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A scene of the named GGX cases, `samples` each.
fn scene(dir: &Path, file: &str, names: &[&str], samples: u64) -> PathBuf {
    let mut text = format!("[defaults]\nsamples = {samples}\nbins = [8, 16]\n");
    for name in names {
        text += &format!("\n[[case]]\nname = \"{name}\"\nlobe = \"ggx\"\nmethod = \"vndf\"\nalpha = 0.3\nincident_theta = 40\n");
    }
    let path = dir.join(file);
    std::fs::write(&path, text).unwrap();
    path
}

fn lobes(dir: &Path, args: &[&str]) -> Output {
    Command::new(LOBES).current_dir(dir).args(args).output().expect("run lobes")
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// A `lobes` started in the background, once it has finished its first case (it holds the
/// output folder by then); its stderr is read on a thread.
struct Started {
    child: Child,
    stderr: std::thread::JoinHandle<String>,
}

fn started(dir: &Path, args: &[&str]) -> Started {
    let mut child = Command::new(LOBES).current_dir(dir).args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut first = String::new();
    stderr.read_line(&mut first).unwrap();
    assert!(first.starts_with("lobes: [1/"), "the first case's line: {first}");
    let stderr = std::thread::spawn(move || {
        let mut rest = first;
        let _ = std::io::Read::read_to_string(&mut stderr, &mut rest);
        rest
    });
    Started { child, stderr }
}

impl Started {
    fn id(&self) -> u32 {
        self.child.id()
    }

    fn finish(self) -> Output {
        let mut output = self.child.wait_with_output().unwrap();
        output.stderr = self.stderr.join().unwrap().into_bytes();
        output
    }
}

fn signal(child: &Started, name: &str) {
    assert!(Command::new("kill").args([&format!("-{name}"), &child.id().to_string()]).status().unwrap().success());
}

fn summary(out: &Path) -> RunSummary {
    serde_json::from_slice(&std::fs::read(out.join("summary.json")).expect("summary.json")).expect("a RunSummary")
}

fn junit(out: &Path) -> Report {
    Report::deserialize_from_str(&std::fs::read_to_string(out.join("junit.xml")).expect("junit.xml")).expect("junit.xml parses")
}

/// Every file under `dir`, relative, sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().into_owned();
        if e.file_type().unwrap().is_dir() {
            v.extend(files(&e.path()).into_iter().map(|n| format!("{name}/{n}")));
        } else {
            v.push(name);
        }
    }
    v.sort();
    v
}

fn temporary(dir: &Path) -> Vec<String> {
    files(dir).into_iter().filter(|f| f.rsplit('/').next().is_some_and(lobes::atomic::is_temporary)).collect()
}

// ---- docs/errors.md ---------------------------------------------------------------------

/// A row of a table in docs/errors.md: its cells, the exit code column and the "Checked by"
/// column (the last).
#[derive(Debug, Clone)]
struct Row {
    /// The first cell of its table's header.
    table: String,
    cells: Vec<String>,
    exit: Option<i32>,
    checked_by: String,
}

/// The rows of every table in docs/errors.md with an `Exit` column and a `Checked by` column.
fn doc_rows() -> Vec<Row> {
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/errors.md")).unwrap();
    let mut rows = Vec::new();
    let mut columns: Option<(usize, usize)> = None;
    let mut table = String::new();
    for line in doc.lines() {
        let Some(inner) = line.trim().strip_prefix('|').and_then(|l| l.strip_suffix('|')) else {
            columns = None;
            continue;
        };
        let cells: Vec<String> = split_cells(inner);
        if cells.iter().all(|c| c.chars().all(|ch| ch == '-' || ch == ':')) {
            continue;
        }
        match columns {
            None => {
                let find = |name: &str| cells.iter().position(|c| c == name);
                columns = find("Exit").zip(find("Checked by"));
                table = cells[0].clone();
                // a table without both columns (the exit codes) is not held here
                if columns.is_none() {
                    columns = Some((usize::MAX, usize::MAX));
                }
            }
            Some((usize::MAX, _)) => {}
            Some((exit, checked)) => {
                assert_eq!(cells.len(), checked + 1, "docs/errors.md: a row with the wrong number of cells: {line}");
                let exit = cells[exit].trim_matches('*').parse().ok();
                rows.push(Row { table: table.clone(), exit, checked_by: cells[checked].clone(), cells });
            }
        }
    }
    rows
}

/// The cells of a table row, where `|` inside backticks is text.
fn split_cells(inner: &str) -> Vec<String> {
    let (mut cells, mut cell, mut code) = (Vec::new(), String::new(), false);
    for ch in inner.chars() {
        match ch {
            '`' => {
                code = !code;
                cell.push(ch);
            }
            '|' if !code => cells.push(std::mem::take(&mut cell).trim().to_string()),
            _ => cell.push(ch),
        }
    }
    cells.push(cell.trim().to_string());
    cells
}

/// The rows of the table of bad input and what you get (its first header cell is `Input`).
fn input_rows() -> Vec<Row> {
    doc_rows().into_iter().filter(|r| r.table == "Input").collect()
}

/// The row of the `Input` table whose first cell is `key`, which must name this suite.
fn row(key: &str) -> Row {
    let rows: Vec<Row> = input_rows().into_iter().filter(|r| r.cells[0] == key).collect();
    assert_eq!(rows.len(), 1, "docs/errors.md needs exactly one row '{key}'");
    assert!(rows[0].checked_by.contains("fault_injection"), "row '{key}' should name fault_injection: {:?}", rows[0]);
    rows[0].clone()
}

/// The messages a row quotes: the `code` spans of its second column that are lobes' own lines
/// (they start with `lobes: `), cut at `…` into the parts that must appear as written.
fn quoted(row: &Row) -> Vec<String> {
    let cell = &row.cells[1];
    let spans = cell.split('`').skip(1).step_by(2).filter(|q| q.starts_with("lobes: "));
    spans.flat_map(|q| q.split('…')).map(str::trim).filter(|q| q.len() > 3).map(String::from).collect()
}

/// The faults this suite injects, by the first cell of their row in docs/errors.md.
const FAULTS: [&str; 14] = [
    "a second run into the same `--out` while one runs",
    "the same with `--wait`",
    "a second SIGINT (or SIGTERM) during `lobes run`",
    "SIGKILL during `lobes run`",
    "temporary files of a killed run (`.lobes-XXXXXX.tmp`)",
    "a full disk or a file-size limit while a case is written",
    "a scene with a typo, into the `--out` of an earlier run",
    "a run into the `--out` of another scene's run",
    "a shard of another lobes version (`\"lobes_version\": \"9.9.9\"`)",
    "a shard whose counts were edited keeping the total; one whose sum wraps past 2⁶⁴",
    "a shard whose `backend` was edited",
    "`WGPU_BACKEND=bogus`",
    "a `lobes check` into an `--out` in use by another lobes",
    "a `lobes check` with bad input into the `--out` of an earlier check",
];

/// Checks `outputs` against the row `key`: each has its exit code (128 + the signal for a
/// process a signal ended, as a shell reports it), and together they print every message the
/// row quotes.
fn holds(key: &str, outputs: &[&Output]) {
    use std::os::unix::process::ExitStatusExt;
    let row = row(key);
    let all: String = outputs.iter().map(|o| text(o)).collect();
    for o in outputs {
        let code = o.status.code().or(o.status.signal().map(|s| 128 + s));
        assert_eq!(code, row.exit, "'{key}': exit code\n{}", text(o));
    }
    for q in quoted(&row) {
        assert!(all.contains(&q), "'{key}': the output lacks {q:?} (docs/errors.md)\n{all}");
    }
}

#[test]
fn the_rows_of_docs_errors_name_tests_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let rows = doc_rows();
    assert!(rows.len() > 30, "docs/errors.md's tables were not found ({} rows)", rows.len());
    for r in &rows {
        assert!(r.exit.is_some(), "row '{}': the Exit column is not a code", r.cells[0]);
        // each comma-separated item starts with a test's name (tests/NAME.rs, or unit tests in
        // src/NAME.rs or src/NAME/), or says that only the code path checks it
        let named: Vec<&str> = r.checked_by.split(',').map(|i| i.trim().split([' ', '(']).next().unwrap_or("")).collect();
        let exists = |n: &&str| {
            let n = n.trim_matches('`');
            root.join("tests").join(format!("{n}.rs")).is_file() || root.join("src").join(format!("{n}.rs")).is_file() || root.join("src").join(n).is_dir()
        };
        assert!(
            named.iter().any(exists) || r.checked_by.starts_with("code path only"),
            "docs/errors.md row '{}' names no test that exists: '{}'",
            r.cells[0],
            r.checked_by
        );
    }
    let inputs = input_rows();
    let here: BTreeSet<&str> = inputs.iter().filter(|r| r.checked_by.contains("fault_injection")).map(|r| r.cells[0].as_str()).collect();
    assert_eq!(here, FAULTS.into_iter().collect::<BTreeSet<_>>(), "the Input rows naming fault_injection are the faults of this suite");
    assert!(doc_rows().iter().any(|r| r.table.starts_with("How `lobes run`")), "the table of what each exit leaves");
}

// ---- the faults ---------------------------------------------------------------------------

/// Item 7: a second run into a folder in use exits 2 naming the holder and touches nothing; with
/// `--wait` it waits, then owns the folder: the first run's cases are removed as stale, and
/// summary.json and every histogram.json are the second run's.
#[test]
fn two_runs_into_one_folder() {
    let dir = scratch("two-runs");
    scene(&dir, "long.toml", &["a0", "a1", "a2"], 1_500_000);
    scene(&dir, "short.toml", &["b0"], 20_000);
    let first = started(&dir, &["run", "--cpu", "long.toml", "--out", "out"]);
    let refused = lobes(&dir, &["run", "--cpu", "short.toml", "--out", "out"]);
    holds("a second run into the same `--out` while one runs", &[&refused]);
    assert!(text(&refused).contains(&format!("pid {}", first.id())), "names the holder: {}", text(&refused));
    assert!(!dir.join("out/b0").exists(), "the refused run wrote nothing");

    let waiting = Command::new(LOBES).current_dir(&dir).args(["run", "--cpu", "short.toml", "--out", "out", "--wait"]).output();
    let first = first.finish();
    assert_eq!(first.status.code(), Some(0), "{}", text(&first));
    let waited = waiting.unwrap();
    holds("the same with `--wait`", &[&waited]);
    let s = summary(&dir.join("out"));
    assert_eq!(s.cases.iter().map(|c| c.case.as_str()).collect::<Vec<_>>(), ["b0"]);
    assert_eq!(s.stale, ["a0", "a1", "a2"]);
    let histograms: Vec<String> = files(&dir.join("out")).into_iter().filter(|f| f.ends_with("histogram.json")).collect();
    assert_eq!(histograms, ["b0/histogram.json"], "no histogram.json of the first run survives");
}

/// Item 11: a second SIGINT stops at once and still writes summary.json and junit.xml (the
/// case in flight and the rest not run).
#[test]
fn a_second_signal_writes_the_summary() {
    let dir = scratch("second-signal");
    let names: Vec<String> = (0..6).map(|i| format!("c{i}")).collect();
    // cases of about 3 s on CPU (30·10⁶ samples; 0.3 s for 3·10⁶ at CI), both signals half a
    // second into the second: a first signal that landed between two cases (writing the first
    // case's outputs) would stop the run there, leaving nothing in flight for the second to stop
    scene(&dir, "s.toml", &names.iter().map(String::as_str).collect::<Vec<_>>(), 30_000_000);
    let child = started(&dir, &["run", "--cpu", "s.toml", "--out", "out"]);
    std::thread::sleep(std::time::Duration::from_millis(500));
    signal(&child, "INT");
    std::thread::sleep(std::time::Duration::from_millis(100));
    signal(&child, "INT");
    let output = child.finish();
    holds("a second SIGINT (or SIGTERM) during `lobes run`", &[&output]);
    let s = summary(&dir.join("out"));
    assert_eq!(s.status, RunStatus::Interrupted);
    let listed: Vec<&str> = s.cases.iter().map(|c| c.case.as_str()).chain(s.not_run.iter().map(String::as_str)).collect();
    assert_eq!(listed, names, "every case, finished or not run");
    assert!(s.not_run.len() >= 4, "stopped at once, in the second case: {s:?}");
    let suite = &junit(&dir.join("out")).test_suites[0];
    assert_eq!(suite.test_cases.len(), 6);
    assert!(suite.test_cases.iter().filter(|t| matches!(t.status, TestCaseStatus::Skipped { .. })).count() == s.not_run.len());
}

/// Items 11 and 12: a run killed by SIGKILL leaves the cases it finished and nothing of the
/// earlier run looking current (no summary.json, no later case's histogram.json); the next run
/// removes the temporary files a killed write leaves.
#[test]
fn sigkill_and_its_temporary_files() {
    let dir = scratch("sigkill");
    let names = ["c0", "c1", "c2", "c3"];
    scene(&dir, "s.toml", &names, 20_000);
    assert_eq!(lobes(&dir, &["run", "--cpu", "s.toml", "--out", "out"]).status.code(), Some(0));
    let child = started(&dir, &["run", "--cpu", "s.toml", "--out", "out", "--samples", "3000000"]);
    signal(&child, "KILL");
    let killed = child.finish();
    holds("SIGKILL during `lobes run`", &[&killed]);
    let out = dir.join("out");
    assert!(!out.join("summary.json").exists() && !out.join("junit.xml").exists(), "{:?}", files(&out));
    let h: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("c0/histogram.json")).unwrap()).unwrap();
    assert_eq!(h["samples"], 3_000_000, "c0 finished in the killed run");
    for late in ["c2", "c3"] {
        assert!(!out.join(late).exists(), "{late}: the earlier run's files were removed before the first case");
    }
    // what a kill during a write leaves, at the top and in a case folder
    for planted in [".lobes-Ab12Cd.tmp", "c1/.lobes-Zz99Yy.tmp"] {
        std::fs::create_dir_all(out.join(planted).parent().unwrap()).unwrap();
        std::fs::write(out.join(planted), vec![0u8; 4096]).unwrap();
    }
    let rerun = lobes(&dir, &["run", "--cpu", "s.toml", "--out", "out"]);
    holds("temporary files of a killed run (`.lobes-XXXXXX.tmp`)", &[&rerun]);
    assert_eq!(temporary(&out), Vec::<String>::new());
    // a shard run, which shares its folder with other shard runs, removes them too when alone
    std::fs::write(dir.join("parts-tmp"), "").unwrap();
    std::fs::create_dir_all(dir.join("parts/c0")).unwrap();
    std::fs::write(dir.join("parts/c0/.lobes-Qq11Ww.tmp"), "x").unwrap();
    assert_eq!(lobes(&dir, &["run", "--cpu", "s.toml", "--shard", "0/2", "--out", "parts"]).status.code(), Some(0));
    assert_eq!(temporary(&dir.join("parts")), Vec::<String>::new());
}

/// A full disk, simulated by a file-size limit (RLIMIT_FSIZE, `ulimit -f` in KiB under bash;
/// SIGXFSZ ignored so that a write past it fails with EFBIG instead of killing lobes): the
/// case that cannot be written is an error (exit 3), no temporary file is left, and the
/// summary, smaller than the limit, says so.
#[test]
fn a_full_disk_while_a_case_is_written() {
    let dir = scratch("full-disk");
    let text_of = "[[case]]\nname = \"big\"\nlobe = \"ggx\"\nalpha = 0.5\nsamples = 20000\nbins = [64, 256]\n\n[[case]]\nname = \"small\"\nlobe = \"ggx\"\nalpha = 0.5\nsamples = 20000\nbins = [8, 16]\n";
    std::fs::write(dir.join("s.toml"), text_of).unwrap();
    // counts.npy of 64 × 256 bins is 128 KiB; summary.json, junit.xml and index.html are smaller
    let limit_kib = 96;
    let output = Command::new("bash")
        .current_dir(&dir)
        .args(["-c", &format!("ulimit -f {limit_kib} && trap '' XFSZ && exec \"$0\" run --cpu s.toml --out out"), LOBES])
        .output()
        .unwrap();
    holds("a full disk or a file-size limit while a case is written", &[&output]);
    let out = dir.join("out");
    assert_eq!(temporary(&out), Vec::<String>::new(), "a failed write leaves no temporary file");
    assert!(!out.join("big/histogram.json").exists());
    assert!(out.join("small/histogram.json").is_file());
    let s = summary(&out);
    assert_eq!((s.errors, s.failed), (1, 0));
    assert!(s.cases[0].error.as_deref().is_some_and(|e| e.contains("File too large")), "{:?}", s.cases[0]);
}

/// The "also noticed" of issue 24: bad input into the folder of an earlier, passing run
/// replaces its summary with one that says why nothing ran (a CI job that publishes junit.xml
/// after `|| true` then reports the failure, not the earlier pass); into no folder, nothing is
/// created.
#[test]
fn bad_input_into_the_folder_of_an_earlier_run() {
    let dir = scratch("typo");
    scene(&dir, "s.toml", &["c0"], 20_000);
    assert_eq!(lobes(&dir, &["run", "--cpu", "s.toml", "--out", "out"]).status.code(), Some(0));
    std::fs::write(dir.join("typo.toml"), "[[case]]\nname = \"c0\"\nlobe = \"ggx\"\nalpah = 0.3\n").unwrap();
    let typo = lobes(&dir, &["run", "--cpu", "typo.toml", "--out", "out"]);
    holds("a scene with a typo, into the `--out` of an earlier run", &[&typo]);
    let s = summary(&dir.join("out"));
    assert_eq!(s.status, RunStatus::Error);
    assert!(s.error.as_deref().is_some_and(|e| e.starts_with("typo.toml:4:1: unknown field `alpah`")), "{s:?}");
    assert_eq!(s.stale, ["c0"]);
    let suite = &junit(&dir.join("out")).test_suites[0];
    assert_eq!((suite.tests, suite.errors), (1, 1), "one test that could not run, not an empty passing suite");
    assert!(!dir.join("out/c0").exists(), "the earlier run's results are gone with its summary");
    let nowhere = lobes(&dir, &["run", "--cpu", "typo.toml", "--out", "never"]);
    assert_eq!(nowhere.status.code(), Some(2));
    assert!(!dir.join("never").exists(), "bad input creates no folder");
    // the same for a merge with bad shards
    let merge = lobes(&dir, &["merge", "nowhere", "--out", "out"]);
    assert_eq!(merge.status.code(), Some(2));
    assert!(summary(&dir.join("out")).error.as_deref().is_some_and(|e| e.contains("nowhere")));
}

/// Item 11: a run owns its --out: the folders of another scene's cases are removed (a user's
/// own files there are kept) and listed as stale.
#[test]
fn a_run_into_the_folder_of_another_scene() {
    let dir = scratch("stale");
    scene(&dir, "a.toml", &["a0", "a1"], 20_000);
    scene(&dir, "b.toml", &["b0"], 20_000);
    assert_eq!(lobes(&dir, &["run", "--cpu", "a.toml", "--out", "out"]).status.code(), Some(0));
    std::fs::write(dir.join("out/a1/notes.md"), "mine").unwrap();
    let b = lobes(&dir, &["run", "--cpu", "b.toml", "--out", "out"]);
    holds("a run into the `--out` of another scene's run", &[&b]);
    let left = files(&dir.join("out"));
    assert!(left.iter().all(|f| !f.starts_with("a0")), "{left:?}");
    assert_eq!(left.iter().filter(|f| f.starts_with("a1/")).collect::<Vec<_>>(), ["a1/notes.md"]);
    assert_eq!(summary(&dir.join("out")).stale, ["a0", "a1"]);
}

/// Items 8, 9 and 14: edited shards are refused with exit 2, each with what is wrong.
#[test]
fn edited_shards() {
    let dir = scratch("shards");
    scene(&dir, "s.toml", &["c0"], 20_000);
    for i in 0..2 {
        assert_eq!(lobes(&dir, &["run", "--cpu", "s.toml", "--shard", &format!("{i}/2"), "--out", "parts"]).status.code(), Some(0));
    }
    assert_eq!(lobes(&dir, &["merge", "parts", "--out", "m"]).status.code(), Some(0), "the honest shards merge");
    let path = dir.join("parts/c0/shard-1-of-2.json");
    let honest = std::fs::read_to_string(&path).unwrap();
    let edit = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut v: serde_json::Value = serde_json::from_str(&honest).unwrap();
        f(&mut v);
        std::fs::write(&path, v.to_string()).unwrap();
        lobes(&dir, &["merge", "parts", "--out", "m"])
    };
    let newer = edit(&|v| v["lobes_version"] = "9.9.9".into());
    holds("a shard of another lobes version (`\"lobes_version\": \"9.9.9\"`)", &[&newer]);

    let file = ShardFile::parse(&path, &honest).unwrap();
    let (a, b) = (file.counts.iter().position(|&c| c > 0).unwrap(), file.counts.iter().rposition(|&c| c > 0).unwrap());
    assert!(a < b);
    let moved = edit(&|v| {
        let c = v["counts"].as_array_mut().unwrap();
        let (x, y) = (c[a].as_u64().unwrap(), c[b].as_u64().unwrap());
        c[a] = (x - 1).into();
        c[b] = (y + 1).into();
    });
    let moved_output = moved;
    let counted: u64 = file.counts.iter().sum();
    let wraps = edit(&|v| {
        // (2^64 − 1) + (counted + 1) wraps to counted: the total of the range is kept
        let c = v["counts"].as_array_mut().unwrap();
        c.iter_mut().for_each(|x| *x = 0.into());
        c[a] = u64::MAX.into();
        c[b] = (counted + 1).into();
    });
    holds("a shard whose counts were edited keeping the total; one whose sum wraps past 2⁶⁴", &[&moved_output, &wraps]);

    let gpu = edit(&|v| v["backend"] = "gpu".into());
    holds("a shard whose `backend` was edited", &[&gpu]);
    // each refusal replaced the earlier merge's summary with its error
    assert_eq!(summary(&dir.join("m")).status, RunStatus::Error);
    std::fs::write(&path, honest).unwrap();
}

/// Item 14: a WGPU_BACKEND that names no backend says so (exit 2), not "install Mesa's driver".
#[test]
fn an_unknown_wgpu_backend() {
    let dir = scratch("backend");
    scene(&dir, "s.toml", &["c0"], 1000);
    let output = Command::new(LOBES).current_dir(&dir).args(["run", "s.toml", "--out", "out"]).env("WGPU_BACKEND", "bogus").output().unwrap();
    holds("`WGPU_BACKEND=bogus`", &[&output]);
    assert!(!text(&output).contains("Mesa"), "{}", text(&output));
}

/// Item 13: outputs take the process umask (0666 and 0777 less it), not a fixed 0600.
#[test]
fn outputs_follow_the_umask() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("umask");
    scene(&dir, "s.toml", &["c0"], 20_000);
    for (umask, file_mode, dir_mode) in [("022", 0o644, 0o755), ("027", 0o640, 0o750)] {
        let out = format!("out{umask}");
        let status = Command::new("bash").current_dir(&dir).args(["-c", &format!("umask {umask} && exec \"$0\" run --cpu s.toml --out {out}"), LOBES]).output().unwrap().status;
        assert_eq!(status.code(), Some(0));
        for f in files(&dir.join(&out)) {
            let mode = std::fs::metadata(dir.join(&out).join(&f)).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode, file_mode, "{out}/{f}: {mode:o} under umask {umask}");
        }
        let mode = std::fs::metadata(dir.join(&out).join("c0")).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, dir_mode, "the case folder under umask {umask}");
    }
}

/// `lobes check` of the GGX example into `out`, with `extra` flags.
fn check_args(extra: &[&str]) -> Vec<String> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/samplers/ggx_vndf.wgsl");
    let mut a: Vec<String> = ["check", file.to_str().unwrap(), "--sample", "ggx_sample", "--pdf", "ggx_pdf", "--params", "0.5,0.5", "--samples", "65536", "--out", "out"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

/// Issue 24: `lobes check --out` owns its folder as `lobes run` does (the same lock, the same
/// cleaning, src/report/folder.rs): a check into a folder another lobes holds exits 2 naming it
/// and touches nothing, or waits for it with `--wait`; bad input into the folder of an earlier
/// check removes that check's report.json, pictures and composed.wgsl (no report.json is left to
/// read as this check's pass) and the temporary files of a killed one, keeping a user's files;
/// a check's files take the umask. Runs on a GPU adapter (lavapipe).
#[test]
fn a_check_owns_its_out_folder() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("check-out");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let earlier = ["report.json", "measured.png", "composed.wgsl", ".lobes-Ab12Cd.tmp", "notes.txt"];
    for f in earlier {
        std::fs::write(out.join(f), "an earlier check's").unwrap();
    }
    let args = check_args(&[]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();

    // another lobes holds the folder (this test, by the same lock): refused, nothing touched
    let lock = std::fs::OpenOptions::new().read(true).write(true).create(true).truncate(false).open(out.join(".lobes.lock")).unwrap();
    lock.try_lock().unwrap();
    std::fs::write(out.join(".lobes.lock"), format!("pid {}: the test, since 0 (Unix time)\n", std::process::id())).unwrap();
    let refused = lobes(&dir, &args);
    holds("a `lobes check` into an `--out` in use by another lobes", &[&refused]);
    assert!(text(&refused).contains(&format!("pid {}", std::process::id())), "names the holder: {}", text(&refused));
    for f in earlier {
        assert!(out.join(f).is_file(), "the refused check removed {f}");
    }
    // with --wait it waits for the lock, then runs
    let mut waiting = Command::new(LOBES).current_dir(&dir).args(&args).arg("--wait").stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    assert!(waiting.try_wait().unwrap().is_none(), "a check with --wait ran while the folder was held");
    drop(lock);
    let waited = waiting.wait_with_output().unwrap();
    assert_eq!(waited.status.code(), Some(0), "{}", String::from_utf8_lossy(&waited.stderr));
    assert!(String::from_utf8_lossy(&waited.stderr).contains("lobes: waiting for the output folder out, in use by another lobes"));
    assert!(temporary(&out).is_empty(), "the killed check's temporary file is removed: {:?}", files(&out));
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["passed"], true);

    // bad input into the folder of that passing check: its outputs go, a user's stay
    std::fs::write(out.join(".lobes-Ef34Gh.tmp"), "half").unwrap();
    let typo: Vec<String> = check_args(&[]).into_iter().map(|a| if a.ends_with("ggx_vndf.wgsl") { "nope.wgsl".into() } else { a }).collect();
    let bad = lobes(&dir, &typo.iter().map(String::as_str).collect::<Vec<_>>());
    holds("a `lobes check` with bad input into the `--out` of an earlier check", &[&bad]);
    assert_eq!(files(&out), [".lobes.lock", "notes.txt"], "only the lock and the user's file are left");

    // the check's files under umask 027: 0640
    let status = Command::new("bash").current_dir(&dir).args(["-c", "umask 027 && exec \"$0\" \"$@\"", LOBES]).args(&args).output().unwrap();
    assert_eq!(status.status.code(), Some(0), "{}", text(&status));
    for f in files(&out).into_iter().filter(|f| f != "notes.txt" && f != ".lobes.lock") {
        let mode = std::fs::metadata(out.join(&f)).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640, "{f}: {mode:o} under umask 027");
    }
}
