//! The standing guard of issue 35, property tests of what parses user text: `--params` (the
//! number-list parser and the settings that judge the numbers) and scene files with users'
//! samplers (`lobes scene`, `lobes run --scene`). Whatever the text, no panic, and every
//! rejection is a clear error: an `Err` naming the item's index, or the scene's line and column
//! and the key; exit 2 through the command line. What is accepted is what a check accepts. (Call
//! expressions, `--define`, `--stub`, `--rand` and module paths: tests/adversarial_frontend.rs;
//! lobes' own scene keys, random text and bytes: tests/bad_input.rs.) No GPU: the command lines
//! here are refused before any GPU work, and each property runs a modest number of cases.

use crate::common;

use common::text;
use lobes::check::{CheckError, MAX_PARAMS, Setting, Settings};
use lobes::cli::parse_number_list;
use lobes::scene::{Scene, SceneError};
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/samplers")
}

// ---- --params --------------------------------------------------------------------------------

/// One item of a `--params` list as a user might type it: numbers of every size (NaN, ∞, beyond
/// f32, subnormal), spellings Rust reads or not (`.5`, `5.`, `+1`, `1e`, `0x10`, `1_0`), blanks
/// and stray text.
fn item() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|x| x.to_string()),
        (-1e3..1e3f64).prop_map(|x| format!("{x}")),
        (-330i32..330).prop_map(|e| format!("1e{e}")),
        prop::sample::select(vec![
            "", " ", "nan", "NaN", "-inf", "+inf", "infinity", "1e39", "-3.4028235e38", "3.4028236e38", "0x10", "1_0", "+1", ".5", "5.", "1e", "e5", "--",
            "é", "1 2", "\u{0}", "٣",
        ])
        .prop_map(String::from),
        "[ -~]{0,4}",
    ]
}

/// A list of items joined by commas, each with blanks around it.
fn list() -> impl Strategy<Value = String> {
    prop::collection::vec((item(), "[ \t]{0,2}", "[ \t]{0,2}"), 0..20)
        .prop_map(|items| items.iter().map(|(i, before, after)| format!("{before}{i}{after}")).collect::<Vec<_>>().join(","))
}

/// What `--params TEXT` must give, by the rules as the docs state them: Ok(the numbers), or the
/// text an error must hold (the first bad item's index; too many numbers).
fn oracle(s: &str) -> Result<Vec<f64>, String> {
    if s.trim().is_empty() {
        return Ok(Vec::new());
    }
    let mut numbers = Vec::new();
    for (i, item) in s.split(',').enumerate() {
        let t = item.trim();
        match t.parse::<f64>() {
            Ok(x) if !t.is_empty() => numbers.push(x),
            _ => return Err(format!("item at index {i} (counting from 0)")),
        }
    }
    if numbers.len() > MAX_PARAMS {
        return Err(format!("{} numbers given, at most {MAX_PARAMS}", numbers.len()));
    }
    match numbers.iter().position(|x| !(*x as f32).is_finite()) {
        Some(i) => Err(format!("the item at index {i} (counting from 0) is ")),
        None => Ok(numbers),
    }
}

/// `--params TEXT` as `lobes check` reads it: the list's syntax, then the settings' judgement.
fn read_params(s: &str) -> Result<Vec<f64>, String> {
    let list = parse_number_list(s)?.0;
    match (Settings { params: list.clone(), ..Settings::default() }).validate() {
        Ok(()) => Ok(list),
        Err(CheckError::Setting { setting: Setting::Params, message }) => Err(message),
        Err(e) => panic!("{s:?}: not an error of params: {e:?}"),
    }
}

/// `lobes check` of the uniform sphere with `--params TEXT`.
fn check_with_params(s: &str) -> Output {
    let file = fixtures().join("uniform_sphere.wgsl");
    Command::new(LOBES).arg("check").arg(file).args(["--sample", "s", "--pdf", "p", "--samples", "65536", "--params", s]).output().unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    /// Any text: the numbers the rules give, or an error naming the first bad item's index
    /// (or the count); never a panic.
    #[test]
    fn params_are_read_by_the_rules_or_refused_naming_the_item(s in list()) {
        match (read_params(&s), oracle(&s)) {
            (Ok(got), Ok(want)) => prop_assert_eq!(got.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), want.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), "{:?}", s),
            (Err(got), Err(want)) => prop_assert!(got.contains(&want), "{s:?}: {got:?} should say {want:?}"),
            (got, want) => prop_assert!(false, "{s:?}: got {got:?}, want {want:?}"),
        }
    }

    /// Up to 16 numbers written as Rust writes them come back bit for bit; they are accepted
    /// exactly when each is a finite f32.
    #[test]
    fn written_numbers_are_read_back_exactly(xs in prop::collection::vec(any::<f64>().prop_filter("finite", |x| x.is_finite()), 0..=MAX_PARAMS)) {
        let s = xs.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(", ");
        let list = parse_number_list(&s).unwrap().0;
        prop_assert_eq!(list.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), xs.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
        prop_assert_eq!(read_params(&s).is_ok(), xs.iter().all(|x| (*x as f32).is_finite()), "{}", s);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, failure_persistence: None, ..ProptestConfig::default() })]

    /// Through the command line, a refused `--params` is exit 2 before any GPU work, with the
    /// flag and the rules' reason in the message.
    #[test]
    fn refused_params_exit_2_naming_the_flag(s in list().prop_filter("refused, and no NUL (no process argument holds one)", |s| oracle(s).is_err() && !s.contains('\0'))) {
        let out = check_with_params(&s);
        let stderr = text(&out.stderr);
        prop_assert_eq!(out.status.code(), Some(2), "{:?}: {}", s, stderr);
        prop_assert!(stderr.starts_with("lobes: ") && stderr.contains("--params"), "{s:?}: {stderr}");
        let want = oracle(&s).unwrap_err();
        prop_assert!(stderr.contains(&want), "{s:?}: {stderr} should say {want:?}");
    }
}

// ---- scene files with users' samplers ------------------------------------------------------

/// A scene of users' samplers that parses: a sphere case with params, a timeout and a
/// convention, a plane case swept over params, a budget case. Its files are the fixtures'.
const VALID: &str = "[defaults]\nsamples = 65536\nseed = 3\n\n\
[[case]]\nname = \"sphere\"\nsampler = { wgsl = [\"uniform_sphere.wgsl\"], sample = \"s\", pdf = \"p\", eval = \"p\", incident = \"upper\" }\nparams = [0.3, 0.5]\nincident_theta = 30\ntimeout = 20\n\n\
[[case]]\nname = \"plane\"\nsampler = { wgsl = [\"uniform_sphere.wgsl\"], sample = \"s(wi, u, params)\", pdf = \"p(wi, d, params)\", u_open = true }\ndomain = \"plane\"\nbounds = [-1, -1, 1, 1]\nparams = [[0.1], [0.2, 0.3]]\nbins = [16, 16]\n\n\
[[case]]\nname = \"budgeted\"\nsampler = { wgsl = [\"uniform_sphere.wgsl\"], sample = \"s\", pdf = \"p_twice\", reflection_only = true, frame = \"y-up\" }\nbudget = \"ci\"\nincident_phi = 45\n";

/// Tokens that stress a user's case: its keys and their values at and past their limits, and
/// TOML's punctuation.
const TOKENS: &[&str] = &[
    "params = [1e39]", "params = [nan]", "params = []", "params = [[]]", "params = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16]",
    "params = [\"x\"]", "params = 0.5", "params = [[0.1], 2]", "sampler", "wgsl = []", "wgsl = [\"missing.wgsl\"]", "wgsl = [\"../samplers\"]",
    "sample = \"s(wi, u)\"", "pdf = \"\"", "eval = \"p(d\"", "rand = [\"rnd\", \"rnd\"]", "rand = [\"würfel\"]", "rand_order = \"event,x\"",
    "define = { A = 99999999999 }", "define = { A = false }", "stub = { \"a::b\" = \"x.wgsl\" }", "shader_root = [\"..\"]", "shader_root = \"/\"",
    "domain = \"plane\"", "domain = \"torus\"", "bounds = [1, 1, 0, 0]", "bounds = [0, 0, inf, 1]", "timeout = 0", "timeout = 1e-320", "timeout = 1e7",
    "budget = \"ci\"", "budget = 1e-300", "budget = -1", "incident = \"upper\"", "incident_theta = 120", "incident_theta = 180", "incident_phi = nan",
    "sample_returns = \"half-vector\"", "frame = \"y-up\"", "measure = \"projected\"", "reflection_only = 1", "u_open = true", "samples = 0",
    "bins = [1, 1]", "bins = [4096, 4097]", "seed = -1", "lobe = \"ggx\"", "alpha = 0.3", "nan", "inf", "1e400", "-0", "\"", "[", "]", "{", "}",
    "=", ",", ".", "\n", "#", "é", "\u{0}", "[[case]]", "[defaults]", "name = \"sphere\"", "true",
];

/// `VALID` with `edits` applied ([`common::mutate`]).
fn mutate(edits: &[(f64, u8, usize)]) -> String {
    common::mutate(VALID, TOKENS, edits)
}

/// A scene's outcome: a rejection at a line and column of the text with a message; an accepted
/// scene's users' cases hold settings that a check accepts (params within f32, a timeout > 0).
fn judge(text: &str, file: &str, result: Result<Scene, SceneError>) -> Result<(), TestCaseError> {
    match result {
        Err(e) => {
            let lines = text.split('\n').count();
            prop_assert!(e.line >= 1 && e.line <= lines.max(1) && e.column >= 1, "line {} of {lines}: {e}", e.line);
            prop_assert!(!e.message.trim().is_empty() && e.to_string().starts_with(&format!("{file}:{}:{}: ", e.line, e.column)), "{e}");
        }
        Ok(scene) => {
            for c in &scene.user_cases {
                prop_assert!(c.settings.validate().is_ok(), "case {}: {:?} in\n{text}", c.name, c.settings.validate());
                prop_assert!(c.sampler.validate().is_ok(), "case {}", c.name);
            }
        }
    }
    Ok(())
}

/// The scene's name as `Scene::parse` takes it: beside the fixtures its files name.
fn scene_file() -> String {
    fixtures().join("fuzz.toml").display().to_string()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    /// Mutated scenes of users' samplers: no panic; a rejection at its line and column.
    #[test]
    fn users_scenes_are_parsed_or_refused_at_a_place(edits in prop::collection::vec((0.0..1.0f64, any::<u8>(), any::<usize>()), 1..5)) {
        let text = mutate(&edits);
        let file = scene_file();
        judge(&text, &file, Scene::parse(&file, &text))?;
    }

    /// `params = [...]` of any TOML numbers: accepted exactly when there are at most 16, each a
    /// finite f32, as `--params` is; else refused at the params line, naming the key (or, for a
    /// literal past f64, as the TOML reader's overflow).
    #[test]
    fn params_in_a_scene_follow_the_command_lines_rules(items in prop::collection::vec(prop_oneof![
        any::<f64>().prop_map(|x| if x.is_nan() { "nan".to_string() } else { format!("{x:?}") }),
        (-330i32..330).prop_map(|e| format!("1e{e}")),
        any::<i64>().prop_map(|i| i.to_string()),
        prop::sample::select(vec!["nan", "-inf", "+inf", "1e39", "-0.0", "\"1\"", "true"]).prop_map(String::from),
    ], 0..20)) {
        let line = format!("params = [{}]", items.join(", "));
        let text = VALID.replace("params = [0.3, 0.5]", &line);
        let at = text.lines().position(|l| l == line).unwrap() + 1;
        let values: Option<Vec<f64>> = items.iter().map(|i| i.parse::<f64>().ok()).collect();
        let fits = values.as_ref().is_some_and(|v| v.len() <= MAX_PARAMS && v.iter().all(|x| (*x as f32).is_finite()));
        match Scene::parse(&scene_file(), &text) {
            Ok(scene) => {
                prop_assert!(fits, "{line} accepted");
                let case = scene.user_cases.iter().find(|c| c.name == "sphere").unwrap();
                prop_assert_eq!(case.settings.params.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), values.unwrap().iter().map(|x| x.to_bits()).collect::<Vec<_>>());
            }
            Err(e) => {
                prop_assert!(!fits, "{line}: {e}");
                // the TOML reader's own refusal of a number past f64 names no key, but is there
                prop_assert!(e.line == at && (e.message.contains("params") || e.message.contains("overflowed")), "{line}: {e}");
            }
        }
    }

    /// `timeout = SECONDS` of any size: accepted exactly when a check accepts the timeout it
    /// makes (1e-320 would be 0 s), else refused at its line naming the key.
    #[test]
    fn a_scenes_timeout_is_accepted_only_where_a_check_accepts_it(seconds in prop_oneof![
        (-330i32..8).prop_map(|e| format!("1e{e}")),
        any::<f64>().prop_map(|x| if x.is_nan() { "nan".to_string() } else { format!("{x:?}") }),
        any::<i32>().prop_map(|i| i.to_string()),
    ]) {
        let line = format!("timeout = {seconds}");
        let text = VALID.replace("timeout = 20", &line);
        let at = text.lines().position(|l| l == line).unwrap() + 1;
        match Scene::parse(&scene_file(), &text) {
            Ok(scene) => {
                let case = scene.user_cases.iter().find(|c| c.name == "sphere").unwrap();
                prop_assert!(case.settings.validate().is_ok(), "{line}: {:?}", case.settings.validate());
            }
            Err(e) => prop_assert!(e.line == at && (e.message.contains("timeout") || e.message.contains("overflowed")), "{line}: {e}"),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, failure_persistence: None, ..ProptestConfig::default() })]

    /// Through `lobes scene FILE`: exit 0 listing the cases, or 2 with `FILE:LINE:COLUMN:`;
    /// never a panic.
    #[test]
    fn lobes_scene_lists_or_refuses_with_exit_2(edits in prop::collection::vec((0.0..1.0f64, any::<u8>(), any::<usize>()), 1..4)) {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("adversarial-parsers-scene");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(fixtures().join("uniform_sphere.wgsl"), dir.join("uniform_sphere.wgsl")).unwrap();
        let scene = dir.join("fuzz.toml");
        std::fs::write(&scene, mutate(&edits)).unwrap();
        let out = Command::new(LOBES).arg("scene").arg(&scene).output().unwrap();
        let stderr = text(&out.stderr);
        match out.status.code() {
            Some(0) => prop_assert!(!text(&out.stdout).is_empty()),
            Some(2) => prop_assert!(stderr.contains(&format!("{}:", scene.display())) && stderr.starts_with("lobes: "), "{stderr}"),
            code => prop_assert!(false, "exit {code:?}: {stderr}"),
        }
    }
}

/// The mutator without edits keeps the scene valid, and its three cases (one a sweep of two).
#[test]
fn the_valid_users_scene_parses() {
    let scene = Scene::parse(&scene_file(), VALID).unwrap_or_else(|e| panic!("{e}"));
    let names: Vec<&str> = scene.user_cases.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names.len(), 4, "{names:?}");
    assert_eq!(mutate(&[]), VALID);
}
