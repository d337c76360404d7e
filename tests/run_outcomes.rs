//! How `lobes run` ends, as CI sees it: the exit code of each outcome (docs/errors.md "Exit codes"),
//! `OUT/summary.json` and `OUT/junit.xml` on every run (interrupted and failed ones too), and a
//! stderr that holds only lobes' own lines. A failing case (exit 1) is in tests/user_scene.rs,
//! bad scenes (2) and no adapter (3) in tests/bad_input.rs.
//! The runs use the CPU engine (`--cpu`) except the stderr test, which needs a wgpu adapter.

use lobes::report::output::{RunStatus, RunSummary};
use quick_junit::{Report, TestCaseStatus};
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("run-outcomes-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `n` GGX cases of `samples` samples each, named c0, c1, …
fn scene(dir: &Path, n: usize, samples: u64) -> PathBuf {
    let mut text = format!("[defaults]\nsamples = {samples}\nbins = [8, 16]\n");
    for i in 0..n {
        text += &format!("\n[[case]]\nname = \"c{i}\"\nlobe = \"ggx\"\nmethod = \"vndf\"\nalpha = 0.3\nincident_theta = 40\n");
    }
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn read_summary(out: &Path) -> RunSummary {
    serde_json::from_slice(&std::fs::read(out.join("summary.json")).expect("summary.json")).expect("a RunSummary")
}

fn read_junit(out: &Path) -> Report {
    let xml = std::fs::read_to_string(out.join("junit.xml")).expect("junit.xml");
    Report::deserialize_from_str(&xml).unwrap_or_else(|e| panic!("junit.xml does not parse: {e}\n{xml}"))
}

/// SIGINT during a run: the case in flight finishes, the run stops, the finished cases are
/// printed and written (summary.json says interrupted and lists them, junit.xml skips the rest),
/// and the exit code is 130.
#[test]
fn sigint_stops_after_the_case_in_flight_and_reports_what_finished() {
    interrupt_mid_run("INT");
}

/// SIGTERM (what CI systems send to cancel a job) does the same as Ctrl-C.
#[test]
fn sigterm_stops_after_the_case_in_flight_and_reports_what_finished() {
    interrupt_mid_run("TERM");
}

fn interrupt_mid_run(signal: &str) {
    let dir = scratch(signal);
    let n = 8;
    let scene = scene(&dir, n, 4_000_000);
    let out = dir.join("out");
    let mut child = Command::new(LOBES)
        .args(["run", "--cpu", "--out"])
        .arg(&out)
        .arg(&scene)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // off a terminal, each finished case is one plain line on stderr: interrupt after the first
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut first = String::new();
    stderr.read_line(&mut first).unwrap();
    assert!(first.starts_with("lobes: [1/8] c0: pass"), "{first}");
    let kill = Command::new("kill").args([&format!("-{signal}"), &child.id().to_string()]).status().unwrap();
    assert!(kill.success());
    let mut rest = String::new();
    stderr.read_to_string(&mut rest).unwrap();
    let output = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(130), "{first}{rest}\n{stdout}");
    assert!(rest.contains("lobes: interrupted: stopping after the case in flight"), "{rest}");
    assert!(!rest.contains("error"), "an interrupt is not reported as an error: {rest}");

    let summary = read_summary(&out);
    assert_eq!(summary.status, RunStatus::Interrupted);
    let finished: Vec<&str> = summary.cases.iter().map(|c| c.case.as_str()).collect();
    assert!(!finished.is_empty() && !summary.not_run.is_empty(), "finished {finished:?}, not run {:?}", summary.not_run);
    let all: Vec<String> = (0..n).map(|i| format!("c{i}")).collect();
    let listed: Vec<&str> = finished.iter().copied().chain(summary.not_run.iter().map(String::as_str)).collect();
    assert_eq!(listed, all, "finished cases then the ones never started, in scene order");
    for c in &summary.cases {
        assert!(c.passed && c.error.is_none(), "{c:?}");
        assert!(out.join(&c.case).join("histogram.json").is_file(), "{} finished and is complete", c.case);
        assert!(stdout.lines().any(|l| l.starts_with(&format!("{} ", c.case)) && l.contains("pass")), "{stdout}");
    }
    for name in &summary.not_run {
        assert!(!out.join(name).exists(), "{name} never started");
        assert!(!stdout.lines().any(|l| l.starts_with(&format!("{name} "))), "{stdout}");
    }
    assert!(stdout.contains(&format!("interrupted: {} of {n} cases not run", summary.not_run.len())), "{stdout}");

    let junit = read_junit(&out);
    let suite = &junit.test_suites[0];
    assert_eq!(suite.test_cases.len(), n);
    let skipped = suite.test_cases.iter().filter(|t| matches!(t.status, TestCaseStatus::Skipped { .. })).count();
    let passed = suite.test_cases.iter().filter(|t| matches!(t.status, TestCaseStatus::Success { .. })).count();
    assert_eq!((passed, skipped), (summary.cases.len(), summary.not_run.len()));
    assert!(suite.properties.iter().any(|p| p.name.as_str() == "status" && p.value.as_str() == "interrupted"));
}

/// Outputs that cannot be written make the tool's failure (3), not a failed check (1): the
/// table is still printed and the cases' own outputs are complete.
#[test]
fn an_output_that_cannot_be_written_is_a_tool_failure() {
    let dir = scratch("unwritable");
    let scene = scene(&dir, 2, 20_000);
    let out = dir.join("out");
    // an earlier run's summary.json must not survive; a folder where junit.xml goes cannot be
    // replaced by the file, and summary.json, written last, is then not written
    std::fs::create_dir_all(out.join("junit.xml").join("blocker")).unwrap();
    std::fs::write(out.join("summary.json"), "{}").unwrap();
    let output = Command::new(LOBES).args(["run", "--cpu", "--out"]).arg(&out).arg(&scene).output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(3), "{stderr}");
    assert!(stderr.contains("lobes: error: cannot write") && stderr.contains("junit.xml"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let table = String::from_utf8_lossy(&output.stdout);
    assert!(table.lines().filter(|l| l.contains("pass")).count() == 2, "{table}");
    assert!(out.join("c1/histogram.json").is_file());
    assert!(!out.join("summary.json").exists(), "no summary.json where the run's outputs are not all written");
}

/// All cases pass: exit 0, and summary.json and junit.xml agree with the printed table. Every
/// line on stderr is lobes' own (`lobes: …`): Mesa's device-select layer, which prints
/// "XDG_RUNTIME_DIR is invalid" where that variable is unset, is switched off.
/// GPU test: it needs a wgpu adapter (lavapipe in CI).
#[test]
fn a_passing_run_on_the_gpu_has_only_lobes_lines_on_stderr() {
    let dir = scratch("stderr");
    let scene = scene(&dir, 2, 20_000);
    let out = dir.join("out");
    let output = Command::new(LOBES)
        .args(["run", "--out"])
        .arg(&out)
        .arg(&scene)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .env_remove("MESA_VK_DEVICE_SELECT")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("XDG_RUNTIME_DIR"), "{stderr}");
    assert!(stderr.lines().all(|l| l.starts_with("lobes: ")), "a line that is not lobes' own:\n{stderr}");
    assert_eq!(stderr.lines().count(), 2, "one progress line per case off a terminal:\n{stderr}");
    let summary = read_summary(&out);
    assert_eq!((summary.status, summary.failed, summary.errors, summary.cases.len()), (RunStatus::Complete, 0, 0, 2));
    assert_eq!(summary.lobes_version, env!("CARGO_PKG_VERSION"));
    assert_eq!(summary.backend, "gpu");
    let suite = &read_junit(&out).test_suites[0];
    assert_eq!((suite.tests, suite.failures, suite.errors), (2, 0, 0));
}

/// A rough dielectric's weighted case reports both albedos where CI reads them: the table (R
/// and T), summary.json's `transmitted`, and the verdict. With G = G1(ωi) the two references and
/// the expected share of wrong-side samples make the white furnace, 1 (an identity none of the
/// three quadratures is built from).
#[test]
fn a_glass_case_reports_its_reflected_and_transmitted_albedo() {
    let dir = scratch("glass");
    let scene = dir.join("glass.toml");
    let text = "[[case]]\nname = \"glass\"\nlobe = \"ggx\"\nmethod = \"vndf\"\nalpha = 0.3\nscatter = \"dielectric\"\neta = 1.5\n\
                incident_theta = 130\nmasking = \"g1\"\nsamples = 200000\nbins = [16, 32]\n";
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("out");
    let output = Command::new(LOBES).args(["run", "--cpu", "--out"]).arg(&out).arg(&scene).output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(0), "{stdout}{}", String::from_utf8_lossy(&output.stderr));
    assert!(stdout.lines().any(|l| l.starts_with("glass") && l.contains(" R 0.") && l.contains(" T 0.")), "{stdout}");
    let summary = read_summary(&out);
    let albedo = summary.cases[0].measured.as_ref().unwrap().albedo.unwrap();
    let t = albedo.transmitted.expect("a dielectric's transmitted albedo");
    let h: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("glass/histogram.json")).unwrap()).unwrap();
    let wrong_side: f64 = h["expected_invalid"].as_object().unwrap().values().map(|v| v.as_f64().unwrap()).sum::<f64>() / 200_000.0;
    let furnace = albedo.reference + t.reference + wrong_side;
    assert!((furnace - 1.0).abs() < 1e-3, "reflected {} + transmitted {} + wrong side {wrong_side} = {furnace}", albedo.reference, t.reference);
    assert!(albedo.passed && t.p_value > 1e-4, "{albedo:?}");
}

/// `lobes --help` and the help of the commands with verdicts list every exit code.
#[test]
fn help_lists_the_exit_codes() {
    for args in [&["--help"][..], &["run", "--help"], &["merge", "--help"], &["check", "--help"], &["stress", "--help"]] {
        let output = Command::new(LOBES).args(args).output().unwrap();
        assert_eq!(output.status.code(), Some(0));
        let help = String::from_utf8_lossy(&output.stdout);
        let section = help.split("Exit codes:").nth(1).unwrap_or_else(|| panic!("no exit codes in lobes {args:?}:\n{help}"));
        for (code, words) in [(0, "passed"), (1, "failed"), (2, "bad input"), (3, "could not do the work"), (130, "interrupted")] {
            assert!(section.lines().any(|l| l.trim_start().starts_with(&format!("{code} ")) && l.contains(words)), "{code}: {section}");
        }
    }
}
