//! No hang and no crash, as CI sees them through the binary (issue 24, items 4–6): a sampler of
//! one's own that never returns ends in `--timeout` (a failure of its case, with the pass it was
//! in) and the process still reports and exits; SIGINT and SIGTERM stop `lobes check`, and a
//! user's case in flight in `lobes run`, at once (exit 130, a report saying so); `--samples`
//! above 2⁴⁰ is bad input; a 120 KB expression (a sum of 20 000 terms) does not overflow the
//! stack; a sweep to 10⁸ cases is refused before it is expanded.
//! GPU tests (all but the sweep's and the samples' checks): they need a wgpu adapter (lavapipe
//! in CI) and fail without one. Each runs within seconds: short timeouts, small sample counts.

use crate::common;

use common::{finish, text};
use lobes::report::output::RunSummary;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("hangs-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A sphere sampler whose sample function loops "forever": on a real GPU it never returns; on
/// lavapipe, which ends a shader's loops after 65 535 iterations per invocation, each of its
/// invocations costs 65 535 iterations of transcendental work, minutes for the default samples.
const ENDLESS: &str = "fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {\n\
    var x = u.x;\n\
    loop {\n\
        x = fract(sin(x * 12.9898 + 78.233) * 43758.547) + exp(cos(x)) - sqrt(x + 4.0);\n\
        if x > 100.0 { break; }\n\
    }\n\
    return vec4<f32>(0.0, 0.0, 1.0, 1.0 + x * 1e-30);\n\
}\n\
fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 { return 0.25 / 3.14159265; }\n";

fn endless(dir: &Path) -> PathBuf {
    let path = dir.join("endless.wgsl");
    std::fs::write(&path, ENDLESS).unwrap();
    path
}

/// `lobes check` of `file` (functions s and p) with `extra` flags, spawned.
fn spawn_check(file: &Path, extra: &[&str]) -> Child {
    Command::new(LOBES)
        .arg("check")
        .arg(file)
        .args(["--sample", "s", "--pdf", "p"])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn signal(child: &Child, name: &str) {
    assert!(Command::new("kill").args([&format!("-{name}"), &child.id().to_string()]).status().unwrap().success());
}

/// A sampler that never returns fails its check when --timeout runs out: exit 1, the table names
/// the pass the GPU was in, and the process exits although the device is still busy.
#[test]
fn a_check_that_never_returns_fails_at_its_timeout() {
    let dir = scratch("timeout");
    let started = Instant::now();
    let (out, _) = finish(spawn_check(&endless(&dir), &["--timeout", "1", "--samples", "65536"]), Duration::from_secs(30));
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    let line = stdout.lines().find(|l| l.starts_with("timeout")).unwrap_or_else(|| panic!("no timeout row:\n{stdout}"));
    // the first pass of a check on the sphere: the probes that decide whether to fit its grid
    assert!(line.contains("FAIL") && line.contains("no result within 1 s") && line.contains("lobes_probe"), "{line}");
    assert!(stdout.contains("FAILED"), "{stdout}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(started.elapsed() < Duration::from_secs(20), "{:?}", started.elapsed());

    // --json: one object saying so
    let (out, _) = finish(spawn_check(&endless(&dir), &["--timeout", "1", "--samples", "65536", "--json"]), Duration::from_secs(30));
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!((v["status"].as_str(), v["passed"].as_bool(), v["timeout_seconds"].as_f64()), (Some("timed_out"), Some(false), Some(1.0)), "{v}");
}

/// A shader the driver compiles for longer than --timeout (issue 24: a hang outside any wait on
/// the device) fails the check at its timeout naming pipeline creation, and the process exits
/// while the thread that creates the pipeline is still held. No shader small enough for a test
/// keeps lavapipe compiling that long, so the test stands in a delay of 120 s before each
/// pipeline creation (`LOBES_TEST_CREATION_DELAY_MS`); SIGINT during it ends the check at once.
#[test]
fn a_shader_that_compiles_past_the_timeout_fails_at_its_timeout() {
    let dir = scratch("slow-compile");
    let file = root().join("examples/samplers/henyey_greenstein.wgsl");
    let spawn = |extra: &[&str]| {
        Command::new(LOBES)
            .arg("check")
            .arg(&file)
            .args(["--sample", "hg_sample", "--pdf", "hg_pdf", "--params", "0.3", "--samples", "65536"])
            .args(extra)
            .env("LOBES_TEST_CREATION_DELAY_MS", "120000")
            .current_dir(&dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (out, took) = finish(spawn(&["--timeout", "2"]), Duration::from_secs(30));
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    let line = stdout.lines().find(|l| l.starts_with("timeout")).unwrap_or_else(|| panic!("no timeout row:\n{stdout}"));
    assert!(line.contains("FAIL") && line.contains("no result within 2 s") && line.contains("pipeline creation of"), "{line}");
    assert!(took < Duration::from_secs(20), "the process exits with the creating thread held: {took:?}");
    let child = spawn(&["--timeout", "60"]);
    std::thread::sleep(Duration::from_millis(1500));
    signal(&child, "INT");
    let sent = Instant::now();
    let (out, _) = finish(child, Duration::from_secs(20));
    assert_eq!(out.status.code(), Some(130), "{}{}", text(&out.stdout), text(&out.stderr));
    assert!(sent.elapsed() < Duration::from_secs(5), "{:?} after the signal", sent.elapsed());
    assert!(text(&out.stdout).contains("pipeline creation of"), "{}", text(&out.stdout));
}

/// SIGINT or SIGTERM during a check (here one that would run for minutes): exit 130 at once, a
/// report that says it was interrupted, no verdict.
#[test]
fn a_signal_stops_a_check_at_once() {
    let dir = scratch("signal");
    for name in ["INT", "TERM"] {
        let child = spawn_check(&endless(&dir), &["--timeout", "60", "--samples", "65536"]);
        std::thread::sleep(Duration::from_millis(1500));
        signal(&child, name);
        let sent = Instant::now();
        let (out, _) = finish(child, Duration::from_secs(20));
        let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
        assert_eq!(out.status.code(), Some(130), "SIG{name}:\n{stdout}{stderr}");
        assert!(sent.elapsed() < Duration::from_secs(5), "SIG{name}: {:?} after the signal", sent.elapsed());
        assert!(stderr.contains("lobes: interrupted: stopping the check now"), "{stderr}");
        assert!(stdout.lines().any(|l| l.starts_with("interrupted") && l.contains("stopped (SIGINT/SIGTERM)")), "{stdout}");
        assert!(!stdout.contains("passed") && !stdout.contains("FAILED"), "no verdict: {stdout}");
    }
}

/// `--samples` above 2⁴⁰ is refused (as `lobes run` refuses it), before any GPU work.
#[test]
fn check_caps_its_samples_as_run_does() {
    let file = root().join("examples/samplers/henyey_greenstein.wgsl");
    for n in ["18446744073709551615", "1099511627777", "0"] {
        let out = Command::new(LOBES).arg("check").arg(&file).args(["--sample", "hg_sample", "--pdf", "hg_pdf", "--samples", n]).output().unwrap();
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{n}: {stderr}");
        assert!(stderr.contains("--samples") && stderr.contains("1..=1099511627776"), "{n}: {stderr}");
    }
}

/// A scene with a user's case that never returns (timeout = 1) before a lobe case: the user's
/// case fails with its reason, the lobe case says why it did not run (the device is still busy),
/// and the summary is written; exit 3 (a case could not run) as for a lost device.
#[test]
fn a_users_case_that_never_returns_fails_at_its_timeout_in_a_run() {
    let dir = scratch("run-timeout");
    endless(&dir);
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        "[[case]]\nname = \"endless\"\nsampler = { wgsl = [\"endless.wgsl\"], sample = \"s\", pdf = \"p\" }\nsamples = 65536\ntimeout = 1\n\n\
         [[case]]\nname = \"ggx\"\nlobe = \"ggx\"\nalpha = 0.3\nsamples = 10000\nbins = [8, 16]\n",
    )
    .unwrap();
    let out_dir = dir.join("out");
    let child = Command::new(LOBES).arg("run").arg(&scene).arg("--out").arg(&out_dir).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let (out, _) = finish(child, Duration::from_secs(30));
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(3), "{stdout}{stderr}");
    let summary: RunSummary = serde_json::from_slice(&std::fs::read(out_dir.join("summary.json")).expect("summary.json")).unwrap();
    let (endless, ggx) = (&summary.cases[0], &summary.cases[1]);
    assert!(!endless.passed && endless.error.is_none(), "{endless:?}");
    assert!(endless.failure.as_deref().is_some_and(|f| f.contains("no result within 1 s")), "{endless:?}");
    assert!(ggx.error.as_deref().is_some_and(|e| e.contains("not run") && e.contains("still running case 'endless'")), "{ggx:?}");
    assert_eq!((summary.failed, summary.errors), (1, 1));
    assert!(!out_dir.join("endless/histogram.json").exists());
}

/// SIGTERM (a CI job cancelled) while a user's case hangs in `lobes run`: the case stops at once,
/// the run is interrupted (130) and its summary written.
#[test]
fn sigterm_stops_a_hung_users_case_in_a_run() {
    let dir = scratch("run-signal");
    endless(&dir);
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, "[[case]]\nname = \"endless\"\nsampler = { wgsl = [\"endless.wgsl\"], sample = \"s\", pdf = \"p\" }\nsamples = 65536\n").unwrap();
    let out_dir = dir.join("out");
    let child = Command::new(LOBES).arg("run").arg(&scene).arg("--out").arg(&out_dir).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    signal(&child, "TERM");
    let sent = Instant::now();
    let (out, _) = finish(child, Duration::from_secs(20));
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(130), "{stdout}{stderr}");
    assert!(sent.elapsed() < Duration::from_secs(5), "{:?} after the signal", sent.elapsed());
    let summary: RunSummary = serde_json::from_slice(&std::fs::read(out_dir.join("summary.json")).expect("summary.json")).unwrap();
    assert_eq!(summary.not_run, ["endless"]);
    assert!(stdout.contains("interrupted: 1 of 1 cases not run"), "{stdout}");
}

/// A pdf returning a sum of 20 000 terms (about 120 KB of WGSL): `lobes scene` lists its case
/// and `lobes check` judges it; neither overflows its stack (an abort, exit 134, before).
#[test]
fn a_sum_of_20000_terms_does_not_overflow_the_stack() {
    let dir = scratch("deep");
    let terms: Vec<String> = (0..20_000).map(|i| format!("d.z * {}.0e-9", i % 10)).collect();
    let wgsl = format!(
        "fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
         \x20   let z = 1.0 - 2.0 * u.x; let r = sqrt(max(0.0, 1.0 - z * z)); let phi = 6.2831853 * u.y;\n\
         \x20   return vec4<f32>(r * cos(phi), r * sin(phi), z, 0.25 / 3.14159265);\n}}\n\
         fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n    return 0.25 / 3.14159265 + {};\n}}\n",
        terms.join(" + ")
    );
    assert!(wgsl.len() > 120_000, "{}", wgsl.len());
    std::fs::write(dir.join("deep.wgsl"), &wgsl).unwrap();
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, "[[case]]\nname = \"deep\"\nsampler = { wgsl = [\"deep.wgsl\"], sample = \"s\", pdf = \"p\" }\n").unwrap();
    let out = Command::new(LOBES).arg("scene").arg(&scene).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("deep"), "{}", text(&out.stdout));
    let (out, _) = finish(spawn_check(&dir.join("deep.wgsl"), &["--samples", "65536", "--bins", "8,16"]), Duration::from_secs(60));
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(matches!(out.status.code(), Some(0 | 1)), "{stdout}{stderr}");
    assert!(stdout.contains("chi2"), "a verdict: {stdout}");
}

/// A 6.6 KB scene that sweeps to 10⁸ cases is refused before it is expanded (an allocation of
/// 3.4 GB aborted, before), naming the keys that multiply; 10⁵ cases still expand.
#[test]
fn a_sweep_beyond_the_case_limit_is_refused_before_it_expands() {
    let dir = scratch("sweep");
    let values = |n: usize, step: f64, start: f64| (0..n).map(|i| format!("{}", start + step * i as f64)).collect::<Vec<_>>().join(", ");
    let huge = format!(
        "[[case]]\nname = \"g\"\nlobe = \"ggx\"\nalpha = [{}]\nincident_theta = [{}]\nincident_phi = [{}]\nseed = [{}]\n",
        values(100, 0.009, 0.01),
        values(100, 0.8, 0.1),
        values(100, 3.0, 0.5),
        values(100, 1.0, 1.0)
    );
    assert!(huge.len() < 7_000, "{}", huge.len());
    let scene = dir.join("huge.toml");
    std::fs::write(&scene, &huge).unwrap();
    let started = Instant::now();
    let out = Command::new(LOBES).arg("scene").arg(&scene).output().unwrap();
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("huge.toml:1:1:") && stderr.contains("sweeps to 100000000 cases"), "{stderr}");
    assert!(stderr.contains("alpha (100 values) × incident_theta (100 values) × incident_phi (100 values) × seed (100 values)"), "{stderr}");
    assert!(stderr.contains("at most 100000 cases"), "{stderr}");
    assert!(started.elapsed() < Duration::from_secs(5), "{:?}", started.elapsed());

    // the limit counts the whole scene: two tables of 60 000
    let two = (0..2).map(|t| format!("[[case]]\nname = \"t{t}\"\nlobe = \"ggx\"\nalpha = [{}]\nseed = [{}]\n", values(60, 0.01, 0.1), values(1000, 1.0, 1.0))).collect::<String>();
    std::fs::write(&scene, two).unwrap();
    let out = Command::new(LOBES).arg("scene").arg(&scene).output().unwrap();
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("case 't1' sweeps to 60000 cases") && stderr.contains("after the 60000 cases of the tables above"), "{stderr}");
}
