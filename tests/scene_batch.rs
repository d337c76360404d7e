//! Scenes for batch use, through the binary: `lobes scene --template` prints a scene that
//! parses; `lobes run -` reads a scene from standard input; `--case` (repeatable, patterns),
//! `--samples` and `--seed` pick cases and replace the scene's values; sweeps expand into named
//! cases that `lobes scene` lists; bad patterns and values are bad input (exit 2).
//! Runs on the CPU engine (`--cpu`): no GPU adapter needed.

use lobes::report::output::{HistogramFile, RunSummary};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs lobes in `dir` with `stdin` on its standard input.
fn lobes(dir: &Path, args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(LOBES).current_dir(dir).args(args).stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    child.stdin.take().unwrap().write_all(stdin.as_bytes()).unwrap();
    child.wait_with_output().unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

const SWEEP: &str = "[defaults]\nsamples = 5000\nbins = [8, 16]\n\n\
                     [[case]]\nname = \"g\"\nlobe = \"ggx\"\nmethod = [\"ndf\", \"vndf\"]\nalpha = [0.2, 0.5]\nincident_theta = [0, 60]\n\n\
                     [[case]]\nname = \"w\"\nlobe = \"ward\"\nalpha_x = [0.1, 0.3]\nalpha_y = 0.2\n";

#[test]
fn the_template_is_a_scene_that_runs_from_stdin_with_overrides() {
    let dir = scratch("scene-template");
    let template = lobes(&dir, &["scene", "--template"], "");
    assert!(template.status.success(), "{}", text(&template.stderr));
    let template = text(&template.stdout);
    assert!(template.contains("samples = 10000000") && template.contains("bins = [64, 128]"), "{template}");
    let scene = lobes::scene::Scene::parse("template.toml", &template).unwrap();
    assert_eq!(scene.len(), 2);

    let out = lobes(&dir, &["run", "-", "--cpu", "--case", "disc*", "--samples", "20000", "--seed", "7", "--out", "out", "--json"], &template);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let summary: RunSummary = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary.cases.iter().map(|c| (c.case.as_str(), c.samples)).collect::<Vec<_>>(), [("discrete", 20_000)]);
    let h = HistogramFile::read(&dir.join("out/discrete/histogram.json")).unwrap();
    assert_eq!((h.samples, h.seed), (20_000, 7));
    assert_eq!(h.counts.concat().iter().sum::<u64>(), 20_000);
    assert!(!dir.join("out/ggx").exists(), "--case ran only the discrete case");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweeps_expand_into_named_cases_that_case_patterns_pick() {
    let dir = scratch("scene-sweeps");
    std::fs::write(dir.join("sweep.toml"), SWEEP).unwrap();
    let listed = lobes(&dir, &["scene", "sweep.toml"], "");
    assert!(listed.status.success(), "{}", text(&listed.stderr));
    let names: Vec<String> = text(&listed.stdout).lines().map(String::from).collect();
    assert_eq!(names.len(), 2 * 2 * 2 + 2);
    assert_eq!(names[..2], ["g-ndf-alpha0.2-theta0", "g-ndf-alpha0.2-theta60"]);
    assert_eq!(names[8..], ["w-ax0.1", "w-ax0.3"]);

    let out = lobes(&dir, &["run", "sweep.toml", "--cpu", "--case", "g-vndf-*-theta60", "--case", "W-AX0.3", "--out", "out", "--json"], "");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let summary: RunSummary = serde_json::from_slice(&out.stdout).unwrap();
    let ran: Vec<&str> = summary.cases.iter().map(|c| c.case.as_str()).collect();
    assert_eq!(ran, ["g-vndf-alpha0.2-theta60", "g-vndf-alpha0.5-theta60", "w-ax0.3"]);
    let h = HistogramFile::read(&dir.join("out/g-vndf-alpha0.5-theta60/histogram.json")).unwrap();
    assert_eq!((h.samples, h.seed, h.counts.len(), h.counts[0].len()), (5000, 1, 8, 16));
    assert_eq!(h.description.method, "vndf");
    // ωi at θ = 60°, φ = 0: (sin 60°, 0, cos 60°)
    let wi = h.incident.unwrap();
    assert!((wi[0] - 0.75f64.sqrt()).abs() < 1e-12 && wi[1].abs() < 1e-12 && (wi[2] - 0.5).abs() < 1e-12, "{wi:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_patterns_and_values_are_bad_input() {
    let dir = scratch("scene-bad");
    std::fs::write(dir.join("sweep.toml"), SWEEP).unwrap();
    let bad = [
        (&["run", "sweep.toml", "--cpu", "--case", "g-vnfd-*"][..], "--case \"g-vnfd-*\" matches no case of sweep.toml"),
        (&["run", "sweep.toml", "--cpu", "--case", "w-ax0.33"][..], "(did you mean 'w-ax0.3'?)"),
        (&["run", "sweep.toml", "--cpu", "--case", "[g"][..], "--case \"[g\" is not a valid pattern"),
        (&["run", "sweep.toml", "--cpu", "--shard", "2/2"][..], "is not in 0..2; give I/N with 0 ≤ I < N, e.g. 0/4"),
        (&["run", "sweep.toml", "--cpu", "--samples", "0"][..], "--samples"),
        (&["run", "sweep.toml", "--cpu", "--seed", "-1"][..], "--seed"),
        (&["run", "sweep.toml", "--shard", "0/2", "--case", "w-*"][..], "cannot be used with"),
        (&["scene", "-"][..], "<stdin>:1:1: the scene has no [[case]] tables"),
    ];
    for (args, want) in bad {
        let out = lobes(&dir, args, "");
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "lobes {}: {stderr}", args.join(" "));
        assert!(stderr.contains(want), "lobes {}: {stderr:?} lacks {want:?}", args.join(" "));
    }
    // a weighted case holds at most 2^32 samples, also when --samples sets them
    let weighted = "[[case]]\nname = \"f\"\nlobe = \"ggx\"\nalpha = 0.3\nfresnel = \"schlick\"\nf0 = 0.04\n";
    let out = lobes(&dir, &["run", "-", "--cpu", "--samples", "5000000000"], weighted);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("samples = 5000000000 (the command line's, for every case) is too many for a weighted case"), "{}", text(&out.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}
