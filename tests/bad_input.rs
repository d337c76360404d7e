//! Bad input, tried as a new user would: broken scene files (each error must name the file,
//! line and column of the offending value and say what is allowed), command-line mistakes, no
//! GPU adapter, and a case that fails mid-way (no complete-looking `histogram.json` may be left).
//! The scene parser and the tutorial commands are fuzzed with proptest for panics.

use crate::common;
use lobes::reference::{effects::Effects, fresnel::Fresnel, masking::Masking};
use lobes::scene::{Scene, SceneError};
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Marks where a scene error must point: the marker is removed before parsing.
const AT: char = '⟦';

/// Parses `marked` (with one `AT` marker) and expects an error at the marker whose message
/// contains every string of `want`.
fn scene_error(marked: &str, want: &[&str]) {
    let at = marked.find(AT).unwrap_or_else(|| panic!("no marker in {marked:?}"));
    let text = marked.replace(AT, "");
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().unwrap().chars().count() + 1;
    let err = match Scene::parse("scene.toml", &text) {
        Ok(s) => panic!("accepted {} cases of:\n{text}", s.cases.len()),
        Err(e) => e,
    };
    assert_eq!((err.file.as_str(), err.line, err.column), ("scene.toml", line, column), "{err}\nin:\n{text}");
    for w in want {
        assert!(err.message.contains(w), "message {:?} lacks {w:?}\nin:\n{text}", err.message);
    }
    let shown = err.to_string();
    assert!(shown.starts_with(&format!("scene.toml:{line}:{column}: ")), "{shown}");
}

/// A valid lobe case with `extra` lines added.
fn ggx(extra: &str) -> String {
    format!("[[case]]\nname = \"c\"\nlobe = \"ggx\"\n{extra}")
}

fn discrete(extra: &str) -> String {
    format!("[[case]]\nname = \"d\"\nlobe = \"discrete\"\n{extra}")
}

#[test]
fn syntax_errors_and_unknown_keys() {
    scene_error("[[case]⟦\nname = \"a\"\n", &["expected `]`"]);
    scene_error("[[case]]\nname = \"a⟦\nlobe = \"ggx\"\n", &["string"]);
    scene_error(&ggx("alpha = 0.2\nalpha⟦\n"), &["expected `=`"]);
    scene_error(&ggx("alpha = 0.2\n⟦alpah = 0.3\n"), &["unknown field `alpah`", "expected one of", "`alpha`", "(did you mean 'alpha'?)"]);
    scene_error(&format!("⟦sample = 5\n{}", ggx("alpha = 0.2\n")), &["unknown field `sample`", "`defaults`", "`case`"]);
    scene_error(&format!("[defaults]\n⟦lobe = \"ggx\"\n{}", ggx("alpha = 0.2\n")), &["unknown field `lobe`", "`samples`", "`bins`", "`seed`"]);
    scene_error(&ggx("alpha = 0.2\n⟦alpha = 0.3\n"), &["duplicate key"]);
    scene_error(&format!("defaults = ⟦3\n{}", ggx("alpha = 0.2\n")), &["expected a [defaults] table"]);
    scene_error("⟦[case]\nname = \"c\"\nlobe = \"ggx\"\nalpha = 0.2\n", &["[[case]]", "not [case]"]);
    scene_error("⟦", &["no [[case]] tables"]);
    scene_error("⟦# only a comment\n[defaults]\nsamples = 10\n", &["no [[case]] tables"]);
}

#[test]
fn names_lobes_and_methods() {
    scene_error("⟦[[case]]\nlobe = \"ggx\"\nalpha = 0.2\n", &["has no name"]);
    scene_error("⟦[[case]]\nname = \"a\"\nalpha = 0.2\n", &["has no lobe", "ward, beckmann, ggx or discrete"]);
    scene_error("[[case]]\nname = ⟦3\nlobe = \"ggx\"\nalpha = 0.2\n", &["name must be a string, got an integer"]);
    for bad in ["a/b", "", "..", ".", "a b", "é", &"x".repeat(101)] {
        scene_error(&format!("[[case]]\nname = ⟦\"{bad}\"\nlobe = \"ggx\"\nalpha = 0.2\n"), &["is not allowed", "letters, digits"]);
    }
    // issue 24 item 10: names of the files a run writes at the top of OUT (which a case folder
    // would collide with only after all the work was done) are refused at parse time
    for reserved in ["summary.json", "junit.xml", "index.html", "Index.HTML", ".lobes.lock", ".lobes-abc123.tmp"] {
        scene_error(&format!("[[case]]\nname = ⟦\"{reserved}\"\nlobe = \"ggx\"\nalpha = 0.2\n"), &[&format!("case name '{reserved}' is reserved"), "rename the case"]);
    }
    scene_error("[[case]]\nname = ⟦\"summary.json\"\nlobe = \"ggx\"\nalpha = 0.2\n", &["OUT/summary.json is a file the run writes itself"]);
    scene_error(&format!("{}\n[[case]]\nname = ⟦\"c\"\nlobe = \"ward\"\nalpha = 0.1\n", ggx("alpha = 0.2\n")), &["duplicate case name 'c'", "1:1"]);
    scene_error(&format!("{}\n[[case]]\nname = ⟦\"C\"\nlobe = \"ward\"\nalpha = 0.1\n", ggx("alpha = 0.2\n")), &["duplicate case name 'C'", "ignoring case"]);
    scene_error("[[case]]\nname = \"c\"\nlobe = ⟦\"phong\"\nalpha = 0.2\n", &["lobe 'phong' is unknown", "ward, beckmann, ggx or discrete"]);
    scene_error("[[case]]\nname = \"c\"\nlobe = ⟦\"GGX\"\nalpha = 0.2\n", &["lobe 'GGX' is unknown", "(did you mean 'ggx'?)"]);
    scene_error(&ggx("alpha = 0.2\nmethod = ⟦\"vndff\"\n"), &["method 'vndff' is unknown", "(did you mean 'vndf'?)"]);
    scene_error(&ggx("alpha = 0.2\n⟦incident_tehta = 30\n"), &["unknown field `incident_tehta`", "(did you mean 'incident_theta'?)"]);
    scene_error(&ggx("alpha = 0.2\nmasking = ⟦\"height_correlated\"\n"), &["(did you mean 'height-correlated'?)"]);
    scene_error(&ggx("alpha = 0.2\nmethod = ⟦\"importance\"\n"), &["method 'importance' is unknown", "ndf, vndf or bounded"]);
    scene_error(&ggx("alpha = 0.2\nmethod = ⟦\"cdf\"\n"), &["cdf and alias are for lobe = \"discrete\""]);
    scene_error(&ggx("alpha = 0.2\nmethod = ⟦1\n"), &["method must be a string"]);
    scene_error("[[case]]\nname = \"c\"\nlobe = \"ward\"\nmethod = ⟦\"vndf\"\nalpha = 0.2\n", &["ward has no 'vndf' sampler", "ward: ndf"]);
    scene_error("[[case]]\nname = \"c\"\nlobe = \"beckmann\"\nmethod = ⟦\"bounded\"\nalpha = 0.2\n", &["beckmann has no 'bounded'"]);
    scene_error(&discrete("weights = [1, 2]\nmethod = ⟦\"vndf\"\n"), &["not a discrete method; use cdf or alias"]);
}

#[test]
fn roughness_angles_and_non_finite_numbers() {
    for (v, shown) in [("0", "0"), ("0.0", "0"), ("-0.1", "-0.1"), ("nan", "NaN"), ("+inf", "inf"), ("-inf", "-inf"), ("-3", "-3")] {
        scene_error(&ggx(&format!("alpha = ⟦{v}\n")), &[&format!("alpha = {shown} is not allowed"), "finite number > 0"]);
    }
    scene_error(&ggx("alpha = ⟦\"0.2\"\n"), &["alpha must be a number, got a string"]);
    // an array sweeps (one case per value); an array inside it is not a number
    scene_error(&ggx("alpha = [0.1, ⟦[0.2]]\n"), &["alpha must be a number, got an array"]);
    scene_error(&ggx("alpha = 0.2\nincident_theta = [0, ⟦95]\n"), &["incident_theta", "0 ≤ θ < 90"]);
    scene_error(&ggx("alpha = ⟦[]\n"), &["alpha = [] sweeps over no values"]);
    scene_error(&ggx("alpha_x = 0.1\nalpha_y = ⟦0\n"), &["alpha_y = 0 is not allowed"]);
    scene_error(&ggx("alpha_x = ⟦nan\nalpha_y = 0.1\n"), &["alpha_x = NaN"]);
    scene_error(&ggx("alpha_x = ⟦0.1\n"), &["alpha_x needs alpha_y"]);
    scene_error(&ggx("alpha_y = ⟦0.1\n"), &["alpha_y needs alpha_x"]);
    scene_error(&ggx("alpha = 0.2\nalpha_x = ⟦0.1\nalpha_y = 0.1\n"), &["either alpha or both"]);
    scene_error("[[case]]\nname = \"c\"\nlobe = ⟦\"ggx\"\n", &["needs a roughness"]);
    for v in ["90", "90.0", "-1", "-0.001", "180", "nan", "inf"] {
        scene_error(&ggx(&format!("alpha = 0.2\nincident_theta = ⟦{v}\n")), &["incident_theta", "0 ≤ θ < 90"]);
    }
    for v in ["361", "-360.5", "nan", "-inf"] {
        scene_error(&ggx(&format!("alpha = 0.2\nincident_phi = ⟦{v}\n")), &["incident_phi", "−360 ≤ φ ≤ 360"]);
    }
    scene_error(&ggx("alpha = 0.2\nincident_theta = ⟦true\n"), &["must be a number, got a boolean"]);
    scene_error(&ggx("alpha = 0.2\nincident_theta = ⟦1979-05-27\n"), &["must be a number, got a date-time"]);
    // out-of-range literals are TOML errors at the literal
    scene_error(&ggx("alpha = ⟦1e999\n"), &[]);
    scene_error(&ggx("alpha = 0.2\nsamples = ⟦99999999999999999999\n"), &[]);
}

#[test]
fn samples_bins_and_seeds_in_cases_and_in_defaults() {
    for v in ["0", "-5", "1099511627777"] {
        scene_error(&ggx(&format!("alpha = 0.2\nsamples = ⟦{v}\n")), &["is not allowed", "1 to 2^40"]);
    }
    scene_error(&ggx("alpha = 0.2\nsamples = ⟦1e7\n"), &["samples must be a whole number (an integer literal), got the floating-point number 10000000.0", "10_000_000"]);
    scene_error(&ggx("alpha = 0.2\nsamples = ⟦\"many\"\n"), &["samples must be a whole number, got a string"]);
    // a bad value in [defaults] is reported where [defaults] sets it, even if no case uses it
    scene_error(&format!("[defaults]\nsamples = ⟦0\n\n{}", ggx("alpha = 0.2\n")), &["samples = 0 is not allowed"]);
    scene_error(&format!("[defaults]\nsamples = ⟦0\n\n{}", ggx("alpha = 0.2\nsamples = 5\n")), &["samples = 0"]);
    scene_error(&format!("[defaults]\nbins = ⟦[63, 128]\n\n{}", discrete("weights = [1]\n")), &["63 rows is odd", "rows even"]);
    scene_error(&format!("[defaults]\nseed = ⟦-1\n\n{}", ggx("alpha = 0.2\n")), &["seed = -1 is not allowed", "≥ 0"]);
    scene_error(&ggx("alpha = 0.2\nseed = ⟦1.5\n"), &["seed must be a whole number"]);
    for (v, want) in [
        ("[0, 128]", "out of range"),
        ("[64, 0]", "out of range"),
        ("[-64, 128]", "out of range"),
        ("[63, 128]", "63 rows is odd"),
        ("[64]", "has 1 items, not 2"),
        ("[64, 128, 2]", "has 3 items, not 2"),
        ("[]", "has 0 items"),
        ("[8192, 4096]", "33554432 bins is more than 2^24"),
        ("[4294967296, 2]", "out of range"),
        ("[64.0, 128]", "must hold whole numbers, got a floating-point number"),
        ("\"64x128\"", "must be an array, got a string"),
        ("64", "must be an array, got an integer"),
    ] {
        scene_error(&ggx(&format!("alpha = 0.2\nbins = ⟦{v}\n")), &[want, "rows × cols ≤ 2^24"]);
    }
}

#[test]
fn discrete_weights_and_keys_that_do_not_apply() {
    scene_error("[[case]]\nname = \"d\"\nlobe = ⟦\"discrete\"\n", &["needs weights"]);
    scene_error(&discrete("weights = ⟦[]\n"), &["empty"]);
    scene_error(&discrete("weights = ⟦[0, 0.0]\n"), &["all weights are zero"]);
    scene_error(&discrete("weights = [1, ⟦-2, 3]\n"), &["weights[1] = -2 is not allowed", "finite numbers ≥ 0"]);
    scene_error(&discrete("weights = [1, 2, ⟦nan]\n"), &["weights[2] = NaN"]);
    scene_error(&discrete("weights = [⟦inf]\n"), &["weights[0] = inf"]);
    scene_error(&discrete("weights = [1, ⟦\"x\"]\n"), &["weights[1] must be a number, got a string"]);
    scene_error(&discrete("weights = [\n  1,\n  ⟦[2],\n]\n"), &["weights[1] must be a number, got an array"]);
    scene_error(&discrete("weights = ⟦[1e308, 1e308]\n"), &["sum to infinity"]);
    scene_error(&discrete("weights = ⟦5\n"), &["expected an array of weights"]);
    scene_error(&ggx("alpha = 0.2\nweights = ⟦[1, 2]\n"), &["weights only apply to lobe = \"discrete\""]);
    for (key, value) in [("alpha", "0.2"), ("alpha_x", "0.2"), ("incident_theta", "10"), ("incident_phi", "10"), ("bins", "[2, 2]")] {
        scene_error(&discrete(&format!("weights = [1]\n{key} = ⟦{value}\n")), &[&format!("{key} does not apply to lobe = \"discrete\"")]);
    }
}

#[test]
fn valid_scenes_still_parse() {
    let s = Scene::parse(
        "ok.toml",
        "[defaults]\nsamples = 1_000\nbins = [2, 1]\nseed = 0\n\n[[case]]\nname = \"a-1_b.c\"\nlobe = \"ggx\"\nmethod = \"bounded\"\nalpha_x = 1\nalpha_y = 0.5\nincident_theta = 89.99\nincident_phi = -360\n\n[[case]]\nname = \"d\"\nlobe = \"discrete\"\nmethod = \"alias\"\nweights = [0, 2.5, 1]\nsamples = 1099511627776\n",
    )
    .unwrap();
    assert_eq!(s.cases.len(), 2);
    assert_eq!((s.cases[0].samples, s.cases[0].seed, s.cases[1].samples), (1000, 0, 1 << 40));
    assert_eq!(s.case_location(1), "ok.toml:15:1");
    // a UTF-8 byte-order mark and CRLF line ends are fine
    let crlf = "\u{feff}[[case]]\r\nname = \"c\"\r\nlobe = \"ward\"\r\nalpha = 0.2\r\n";
    assert_eq!(Scene::parse("crlf.toml", crlf).unwrap().cases.len(), 1);
    let err = Scene::parse("crlf.toml", &crlf.replace("0.2", "0")).unwrap_err();
    assert_eq!((err.line, err.column), (4, 9));
}

#[test]
fn text_that_is_not_utf8_is_located() {
    let err = Scene::from_bytes("x.toml", b"[[case]]\nname = \"a\xffb\"\n").unwrap_err();
    assert_eq!((err.line, err.column), (2, 10), "{err}");
    assert!(err.message.contains("not UTF-8"), "{err}");
}

// ---------------------------------------------------------------------------------------------
// Fuzzing the scene parser: it returns Ok or a located error, never panics.

const VALID: &str = "[defaults]\nsamples = 10_000\nbins = [8, 16]\nseed = 7\n\n[[case]]\nname = \"ggx-vndf\"\nlobe = \"ggx\"\nmethod = \"vndf\"\nalpha_x = 0.2\nalpha_y = 0.4\nincident_theta = 45.0\nincident_phi = 30.0\n\n[[case]]\nname = \"disc\"\nlobe = \"discrete\"\nmethod = \"alias\"\nweights = [15, 5, 0, 25.5]\n";

/// Tokens that stress a TOML reader and the validation.
const TOKENS: &[&str] = &[
    "nan", "-inf", "+inf", "0", "-0", "-1", "1e400", "99999999999999999999", "0x10", "1_0", "1__0", "\"", "'", "\"\"\"",
    "[", "]", "[[", "]]", "{", "}", "=", ",", ".", "\n", "\r\n", "#", "\\", "\\u{0}", "\u{0}", "é", "θ", "𝔸", "\u{feff}",
    "[[case]]", "[defaults]", "[case]", "name = \"x\"", "lobe = \"ward\"", "method = \"bounded\"", "alpha = 0",
    "bins = [0, 0]", "bins = [4096, 4096]", "samples = 1099511627777", "weights = []", "true", "1979-05-27T07:32:00Z",
    "inf", "90", "-360", "a.b", "\t", " ",
];

fn check_outcome(text: &str, result: Result<Scene, SceneError>) {
    match result {
        Err(e) => {
            let lines = text.split('\n').count();
            assert!(e.line >= 1 && e.line <= lines.max(1), "line {} of {lines}: {e}", e.line);
            assert!(e.column >= 1, "{e}");
            assert!(!e.message.is_empty());
        }
        Ok(scene) => {
            assert!(!scene.cases.is_empty());
            for c in &scene.cases {
                assert!(c.samples >= 1 && c.samples <= lobes::scene::MAX_SAMPLES);
                assert!(c.job.bins() >= 1 && c.job.bins() as u64 <= lobes::scene::MAX_BINS);
                if let lobes::engine::job::Job::Lobe { lobe, grid, .. } = &c.job {
                    assert!(lobe.alpha_x.is_finite() && lobe.alpha_x > 0.0 && lobe.alpha_y.is_finite() && lobe.alpha_y > 0.0);
                    assert!(grid.rows % 2 == 0);
                    assert!((0.0..90.0).contains(&c.incident_deg.0) && c.incident_deg.1.abs() <= 360.0);
                }
            }
        }
    }
}

/// Edits of the valid scene: (position fraction, what to do, token index).
fn mutate(edits: &[(f64, u8, usize)]) -> String {
    common::mutate(VALID, TOKENS, edits)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn fuzz_mutated_valid_scene(edits in prop::collection::vec((0.0..1.0f64, any::<u8>(), any::<usize>()), 1..6)) {
        let text = mutate(&edits);
        check_outcome(&text, Scene::parse("fuzz.toml", &text));
    }

    #[test]
    fn fuzz_random_text(text in "(\\PC|\n|\\[\\[case\\]\\]\n|name = \"[a-z.]{0,3}\"\n|lobe = \"(ward|ggx|discrete|x)\"\n|[a-z_]{1,14} = [-+0-9.e_naif]{0,8}\n|weights = \\[[-0-9., ]{0,12}\\]\n|bins = \\[[-0-9, ]{0,10}\\]\n){0,40}") {
        check_outcome(&text, Scene::parse("fuzz.toml", &text));
    }

    #[test]
    fn fuzz_random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        let text = String::from_utf8_lossy(&bytes).into_owned();
        check_outcome(&text, Scene::from_bytes("fuzz.toml", &bytes));
    }
}

#[test]
fn the_mutator_keeps_the_valid_scene_valid_without_edits() {
    check_outcome(VALID, Scene::parse("v.toml", VALID));
    assert_eq!(Scene::parse("v.toml", &mutate(&[])).unwrap().cases.len(), 2);
}

// ---------------------------------------------------------------------------------------------
// The command line: tutorial subcommands (fuzzed through clap and the report functions) and
// `lobes run` through the binary.

const ARG_WORDS: &[&str] = &[
    "discrete", "pdf-convert", "sample", "--weights", "--u", "--method", "--json", "--lobe", "--alpha", "--alpha-x",
    "--alpha-y", "--incident-theta", "--incident-phi", "--pdf-h", "--theta-h", "--theta-i", "cdf", "alias", "ndf",
    "vndf", "bounded", "ward", "beckmann", "ggx", "0", "1", "0.5", "-0", "-1", "90", "180", "360", "1e-320", "1e308",
    "nan", "inf", "0,1", "1,0", "0.5,0.25,0.9", "1,,2", ",", "", " ", "0x1", "1e-300,1", "15,5,5,25", "--", "-h",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, failure_persistence: None, ..ProptestConfig::default() })]

    /// Any argument list either fails to parse with clap's exit code 2 (0 for help), fails
    /// validation with a usage error (exit 2), or yields a report; none panics.
    #[test]
    fn fuzz_tutorial_arguments(words in prop::collection::vec(any::<prop::sample::Index>(), 0..9)) {
        use clap::Parser;
        use lobes::cli::{Cli, Command, EXIT_USAGE, exit_code, tutorial};
        let args: Vec<&str> = std::iter::once("lobes").chain(words.iter().map(|i| ARG_WORDS[i.index(ARG_WORDS.len())])).collect();
        match Cli::try_parse_from(&args) {
            Err(e) => prop_assert!(e.exit_code() == 2 || e.exit_code() == 0, "{args:?}: {e}"),
            Ok(cli) => {
                let outcome = match &cli.command {
                    Command::Discrete(a) => tutorial::discrete_report(a).map(|r| serde_json::to_string(&r).unwrap()),
                    Command::PdfConvert(a) => Ok(serde_json::to_string(&tutorial::pdf_convert_report(a)).unwrap()),
                    Command::Sample(a) => tutorial::sample_report(a).map(|r| serde_json::to_string(&r).unwrap()),
                    _ => Ok(String::new()),
                };
                if let Err(e) = outcome {
                    prop_assert_eq!(exit_code(&e), EXIT_USAGE, "{:?}: {:#}", args, e);
                }
            }
        }
    }
}

fn lobes_cmd() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lobes"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lobes-bad-input-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Expects exit code 2, nothing on stdout, an `error:` naming every string of `want`, no panic.
fn usage_error(out: &Output, want: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "want exit 2; stderr: {stderr}");
    assert!(out.stdout.is_empty(), "stdout: {}", String::from_utf8_lossy(&out.stdout));
    assert!(stderr.contains("lobes: error:"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for w in want {
        assert!(stderr.contains(w), "stderr lacks {w:?}: {stderr}");
    }
    stderr
}

/// A small, fast scene: two lobes and a distribution, 20 000 samples each on 8 × 16 bins.
const SMALL: &str = "[defaults]\nsamples = 20_000\nbins = [8, 16]\n\n[[case]]\nname = \"first\"\nlobe = \"ward\"\nalpha = 0.3\n\n[[case]]\nname = \"broken\"\nlobe = \"beckmann\"\nmethod = \"vndf\"\nalpha = 0.5\nincident_theta = 30\n\n[[case]]\nname = \"last\"\nlobe = \"discrete\"\nweights = [1, 2, 3]\n";

#[test]
fn run_rejects_bad_scenes_and_paths_with_exit_2() {
    let dir = scratch("run-args");
    let out = dir.join("out");
    let run = |args: &[&dyn AsRef<std::ffi::OsStr>]| lobes_cmd().arg("run").args(args.iter().map(|a| a.as_ref())).output().unwrap();

    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[[case]]\nname = \"c\"\nlobe = \"ggx\"\nalpha = -0.5\n").unwrap();
    let stderr = usage_error(&run(&[&bad, &"--out", &out]), &[&format!("{}:4:9: alpha = -0.5 is not allowed", bad.display())]);
    assert!(!out.exists(), "a bad scene creates no output folder: {stderr}");

    usage_error(&run(&[&dir.join("missing.toml"), &"--out", &out]), &["cannot read scene file", "missing.toml", "No such file"]);
    usage_error(&run(&[&dir, &"--out", &out]), &["cannot read scene file"]);
    let latin1 = dir.join("latin1.toml");
    std::fs::write(&latin1, b"# caf\xe9\n[[case]]\n").unwrap();
    usage_error(&run(&[&latin1, &"--out", &out]), &["latin1.toml:1:6", "not UTF-8"]);

    let good = dir.join("good.toml");
    std::fs::write(&good, SMALL).unwrap();
    let file = dir.join("a-file");
    std::fs::write(&file, "x").unwrap();
    usage_error(&run(&[&good, &"--out", &file]), &["--out", "is not a folder"]);
    usage_error(&run(&[&good, &"--out", &file.join("sub")]), &["--out", "cannot create the output folder"]);
    for level in ["0", "1", "nan", "-0.1", "x", ""] {
        usage_error(&run(&[&good, &"--out", &out, &"--significance", &level]), &["--significance"]);
    }
    usage_error(&run(&[&good, &"--out", &out, &"--frobnicate"]), &["--frobnicate"]);
    usage_error(&run(&[&good, &good, &"--out", &out]), &["unexpected argument"]);
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Environment that hides every Vulkan driver from the loader.
fn without_gpu(cmd: &mut Command) -> &mut Command {
    cmd.env("VK_DRIVER_FILES", "/nonexistent.json").env("VK_ICD_FILENAMES", "/nonexistent.json").env_remove("WGPU_BACKEND")
}

/// Without an adapter `run` fails (3) naming the driver to install, and runs no case on the CPU
/// behind the user's back; `--cpu` runs them on the CPU engine; `bench` fails as `run` does.
#[test]
fn without_an_adapter_run_and_bench_fail_and_run_cpu_uses_the_cpu() {
    let dir = scratch("no-gpu");
    let scene = dir.join("small.toml");
    std::fs::write(&scene, SMALL).unwrap();
    let out = without_gpu(&mut lobes_cmd()).args(["run", "--json", "--out"]).arg(dir.join("out")).arg(&scene).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(stderr.starts_with("lobes: error: no GPU adapter found") && stderr.contains("mesa-vulkan-drivers"), "{stderr}");
    assert!(out.stdout.is_empty() && !dir.join("out/first").exists(), "no case ran");

    let out = without_gpu(&mut lobes_cmd()).args(["run", "--cpu", "--json", "--out"]).arg(dir.join("out")).arg(&scene).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object on stdout");
    assert_eq!(v["backend"], "cpu");
    for case in ["first", "broken", "last"] {
        let h: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("out").join(case).join("histogram.json")).unwrap()).unwrap();
        assert_eq!(h["backend"], "cpu");
    }

    let out = without_gpu(&mut lobes_cmd()).args(["bench", "--runs", "1", "--samples", "1000"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(stderr.starts_with("lobes: error: no GPU adapter found") && stderr.contains("mesa-vulkan-drivers"), "{stderr}");
    assert!(out.stdout.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// WGPU_ADAPTER_NAME picks an adapter by part of its name, case ignored; a name that matches none
/// fails (3) listing the adapters there are, rather than silently taking another one.
#[test]
fn wgpu_adapter_name_selects_or_fails_listing_the_adapters() {
    let bench = ["bench", "--gpu-only", "--runs", "1", "--samples", "1000"];
    let out = lobes_cmd().env("WGPU_ADAPTER_NAME", "no-such-gpu").args(bench).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(stderr.contains("WGPU_ADAPTER_NAME='no-such-gpu' matches no adapter") && stderr.contains("llvmpipe"), "{stderr}");
    assert!(out.stdout.is_empty());

    let out = lobes_cmd().env("WGPU_ADAPTER_NAME", "LLVMPIPE").args(bench).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
}

/// `lobes bench --sampler LOBE-METHOD` measures only the named samplers; an unknown name is a
/// usage error (2) that lists the names.
#[test]
fn bench_sampler_selects_and_rejects_unknown_names() {
    let out = lobes_cmd().args(["bench", "--gpu-only", "--runs", "1", "--samples", "1000", "--json", "--sampler", "beckmann-vndf"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows: Vec<(&str, &str)> = v["results"].as_array().unwrap().iter().map(|r| (r["lobe"].as_str().unwrap(), r["method"].as_str().unwrap())).collect();
    assert_eq!(rows, [("beckmann", "vndf")]);
    let out = lobes_cmd().args(["bench", "--sampler", "ggx-vdnf"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--sampler ggx-vdnf: no such sampler") && stderr.contains("ggx-vndf"), "{stderr}");
}

fn tree(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

/// A case whose outputs cannot be written fails alone: it leaves no `histogram.json` (not even
/// the one an earlier run left), no temporary files, and the other cases complete; exit 3 (the
/// tool could not do the work), and summary.json and junit.xml name the case as an error.
#[test]
fn a_case_that_fails_mid_way_leaves_no_histogram_json() {
    let dir = scratch("mid-way");
    let scene = dir.join("small.toml");
    std::fs::write(&scene, SMALL).unwrap();
    let out = dir.join("out");
    // an earlier, complete run
    let first = lobes_cmd().args(["run", "--cpu", "--out"]).arg(&out).arg(&scene).output().unwrap();
    assert!(first.status.success(), "{}", String::from_utf8_lossy(&first.stderr));
    let broken = out.join("broken");
    assert!(broken.join("histogram.json").exists());
    // residual.png, written after measured.png and expected.png and before histogram.json,
    // becomes a folder that a file cannot replace
    std::fs::remove_file(broken.join("residual.png")).unwrap();
    std::fs::create_dir_all(broken.join("residual.png").join("blocker")).unwrap();
    let again = lobes_cmd().args(["run", "--cpu", "--out"]).arg(&out).arg(&scene).output().unwrap();
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert_eq!(again.status.code(), Some(3), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains("lobes: error: case 'broken'") && stderr.contains("small.toml:10:1"), "{stderr}");
    assert!(stderr.contains("writing the outputs into") && stderr.contains("no histogram.json was written"), "{stderr}");
    assert!(stderr.contains("1 of 3 cases could not run"), "{stderr}");
    assert!(!broken.join("histogram.json").exists(), "the failed case left a histogram.json");
    // the earlier run's files were removed before the first case (the run owns its --out), so
    // what is left is what this run wrote before residual.png failed
    assert_eq!(tree(&broken), ["expected.png", "measured.png", "residual.png"], "no temporary files, nothing of the earlier run");
    let table = String::from_utf8_lossy(&again.stdout);
    assert!(table.lines().any(|l| l.starts_with("broken") && l.contains("ERROR")), "{table}");
    let arrays = ["counts.npy", "expected.npy"];
    let (json, timing) = ("histogram.json", "timing.json");
    assert_eq!(tree(&out.join("first")), [arrays[0], arrays[1], "expected.png", json, "marginals.png", "measured.png", "residual.png", timing]);
    // a discrete case: a bar chart of its items
    assert_eq!(tree(&out.join("last")), ["bars.png", arrays[0], arrays[1], json, timing]);
    let summary: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!((summary["errors"].as_u64(), summary["failed"].as_u64(), summary["status"].as_str()), (Some(1), Some(0), Some("complete")));
    assert!(summary["cases"][1]["error"].as_str().unwrap().contains("residual.png"), "{summary}");
    let junit = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    assert!(junit.contains(r#"<testcase name="broken" classname="lobes">"#) && junit.contains("<error message=\"writing the outputs into"), "{junit}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn effects() {
    scene_error(&ggx("alpha = 0.2\nfresnel = ⟦\"fresnell\"\n"), &["fresnel 'fresnell' is unknown", "schlick", "conductor", "dielectric"]);
    scene_error(&ggx("alpha = 0.2\nfresnel = ⟦\"schlick\"\n"), &["needs f0", "0 ≤ f0 ≤ 1"]);
    scene_error(&ggx("alpha = 0.2\nfresnel = \"schlick\"\nf0 = ⟦1.5\n"), &["f0 = 1.5 is not allowed", "0 ≤ f0 ≤ 1"]);
    scene_error(&ggx("alpha = 0.2\nfresnel = ⟦\"conductor\"\neta = 0.2\n"), &["needs k"]);
    scene_error(&ggx("alpha = 0.2\nfresnel = \"conductor\"\neta = ⟦-1\nk = 3\n"), &["eta = -1 is not allowed", "> 0"]);
    scene_error(&ggx("alpha = 0.2\nfresnel = \"dielectric\"\neta = 1.5\nk = ⟦2\n"), &["k does not apply to fresnel = \"dielectric\""]);
    scene_error(&ggx("alpha = 0.2\nf0 = ⟦0.04\n"), &["f0 does not apply to fresnel = \"none\""]);
    scene_error(&ggx("alpha = 0.2\nmasking = ⟦\"smith\"\n"), &["masking 'smith' is unknown", "height-correlated"]);
    scene_error("[[case]]\nname = \"w\"\nlobe = \"ward\"\nalpha = 0.2\nmasking = ⟦\"g1\"\n", &["lobe = \"ward\" has no Smith masking"]);
    scene_error(&ggx("alpha = 0.2\nweighted = false\nfresnel = ⟦\"schlick\"\nf0 = 0.1\n"), &["set weighted = true or remove them"]);
    scene_error(&ggx("alpha = 0.2\nweighted = ⟦1\n"), &["weighted must be true or false"]);
    scene_error(&discrete("weights = [1, 2]\nmasking = ⟦\"g1\"\n"), &["masking does not apply to lobe = \"discrete\""]);
    scene_error(&ggx("alpha = 0.2\nweighted = true\nsamples = ⟦8_000_000_000\n"), &["too many for a weighted case", "2^32"]);
}

/// `scatter = "dielectric"` (rough glass) and its `eta`: where each applies, with what values.
#[test]
fn dielectric_scatter_keys() {
    let glass = |extra: &str| ggx(&format!("alpha = 0.3\nmethod = \"vndf\"\n{extra}"));
    let ok = Scene::parse("s.toml", &glass("scatter = \"dielectric\"\neta = 1.5\nincident_theta = 140\n")).unwrap();
    assert!(matches!(ok.cases[0].job, lobes::engine::job::Job::Lobe { scatter: lobes::engine::job::Scatter::Dielectric { eta: 1.5 }, .. }));
    scene_error(&glass("scatter = ⟦\"glass\"\neta = 1.5\n"), &["scatter 'glass' is unknown", "reflect or dielectric"]);
    scene_error(&glass("scatter = ⟦\"dielectric\"\n"), &["needs eta", "≠ 1"]);
    scene_error(&glass("scatter = \"dielectric\"\neta = ⟦1.0\n"), &["eta", "> 0 and ≠ 1"]);
    scene_error(&glass("scatter = \"dielectric\"\neta = ⟦-1.5\n"), &["eta", "> 0 and ≠ 1"]);
    scene_error(&glass("eta = ⟦1.5\n"), &["eta applies to scatter = \"dielectric\"", "fresnel"]);
    scene_error(&glass("scatter = \"reflect\"\neta = ⟦1.5\n"), &["eta applies to scatter = \"dielectric\""]);
    scene_error(&glass("incident_theta = ⟦140\n"), &["0 ≤ θ < 90"]);
    scene_error(&glass("scatter = \"dielectric\"\neta = 1.5\nincident_theta = ⟦180\n"), &["0 ≤ θ < 180"]);
    scene_error(&glass("scatter = \"dielectric\"\neta = 1.5\nfresnel = ⟦\"schlick\"\n"), &["fresnel does not apply to scatter = \"dielectric\""]);
    scene_error(&glass("scatter = \"dielectric\"\neta = 1.5\nf0 = ⟦0.04\n"), &["f0 does not apply to scatter = \"dielectric\""]);
    scene_error(&glass("scatter = \"dielectric\"\neta = 1.5\nweighted = false\nmasking = ⟦\"g1\"\n"), &["weighted = false"]);
    // the weighted pass: any masking, or weighted = true alone; the Fresnel term is the dielectric's
    for (extra, masking) in [
        ("masking = \"g1\"\n", Masking::G1),
        ("masking = \"separable\"\n", Masking::Separable),
        ("masking = \"height-correlated\"\n", Masking::HeightCorrelated),
        ("weighted = true\n", Masking::None),
    ] {
        let s = Scene::parse("s.toml", &glass(&format!("scatter = \"dielectric\"\neta = 1.5\n{extra}"))).unwrap();
        assert_eq!(s.cases[0].effects, Some(Effects { fresnel: Fresnel::None, masking }), "{extra}");
    }
    scene_error(&ggx("alpha = 0.3\nmethod = ⟦\"bounded\"\nscatter = \"dielectric\"\neta = 1.5\n"), &["ggx bounded has no dielectric sampler", "ndf or vndf"]);
    scene_error("[[case]]\nname = \"w\"\nlobe = ⟦\"ward\"\nalpha = 0.2\nscatter = \"dielectric\"\neta = 1.5\n", &["ward has no dielectric sampler"]);
    scene_error(&discrete("weights = [1, 2]\nscatter = ⟦\"dielectric\"\n"), &["scatter does not apply to lobe = \"discrete\""]);
}
