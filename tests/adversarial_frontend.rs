//! The adversarial cases of issue 35 that live in composition (the front end: shader roots,
//! imports, `--rand`, call expressions, flags), each its own test with the exit code it must
//! give and, for the ones that hung, the time it must finish in; and property-based tests of what
//! parses user text (call expressions, `--define`, `--stub`, `--rand`, module paths): no panic,
//! and every rejection is bad input naming the input.
//! Most cases are refused before any GPU work; the ones that pass run a small check (a wgpu
//! adapter: lavapipe in CI).

use lobes::check::{CheckError, Composition, Domain, Draw, Setting, Source, UserSampler};
use proptest::prelude::*;
use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");
const OIL: &str = "tests/fixtures/repository/naga_oil";
const WESL: &str = "tests/fixtures/repository/wesl";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("adversarial-frontend-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

fn lobes(args: &[&str]) -> Output {
    let out = Command::new(LOBES).current_dir(root()).args(args).output().expect("run lobes");
    println!("$ lobes {}\n{}{}", args.join(" "), text(&out.stdout), text(&out.stderr));
    out
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Exit 2, no panic, and stderr naming every string of `want`; the stderr.
fn bad_input(out: &Output, want: &[&str]) -> String {
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "want exit 2: {e}");
    assert!(!e.contains("panicked"), "{e}");
    for w in want {
        assert!(e.contains(w), "stderr lacks {w:?}: {e}");
    }
    e
}

/// The naga_oil fixture's check, in `dir` (a copy of the tree), with `extra` flags.
fn oil_check(dir: &Path, extra: &[&str]) -> Output {
    let file = dir.join("shaders/sampling/diffuse.wgsl");
    let roots = dir.join("shaders");
    let stub = format!("common::view={}", dir.join("stubs/view.wgsl").display());
    let mut args = vec!["check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--stub", &stub];
    args.extend(["--sample", "sample_diffuse(wi)", "--pdf", "diffuse_pdf(d)", "--rand", "rand", "--samples", "65536"]);
    args.extend(extra);
    lobes(&args)
}

/// Item 1: an old copy of `common::maths` (PI = 3, so the diffuse pdf integrates to 1.047) that
/// declares the same `#define_import_path` and sorts first: an error naming both files, not
/// whichever the scan met first.
#[test]
fn two_files_declaring_one_naga_oil_module_path_are_refused_naming_both() {
    let dir = scratch("oil-twice");
    common::copy_dir(&root().join(OIL), &dir);
    let stale = dir.join("shaders/archive/maths_2023.wgsl");
    write(&stale, "#define_import_path common::maths\n\nconst PI: f32 = 3.0;\nconst TAU: f32 = 6.0;\n");
    let out = oil_check(&dir, &[]);
    let maths = dir.join("shaders/common/maths.wgsl");
    bad_input(&out, &["common::maths", stale.to_str().unwrap(), maths.to_str().unwrap()]);
}

/// Item 1, WESL: `package::utils` as both `utils.wesl` and `utils.wgsl` of a root, or under two
/// roots: refused naming both files.
#[test]
fn a_wesl_module_reachable_two_ways_is_refused_naming_both() {
    let dir = scratch("wesl-twice");
    common::copy_dir(&root().join(WESL), &dir);
    let utils = dir.join("shaders/utils.wesl");
    let copy = dir.join("shaders/utils.wgsl");
    std::fs::copy(&utils, &copy).unwrap();
    let file = dir.join("shaders/sampling/ggx.wesl");
    let roots = dir.join("shaders");
    let stub = format!("package::bindings={}", dir.join("stubs/bindings.wesl").display());
    let args = |extra: &[&str]| {
        let mut a = vec!["check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--stub", &stub];
        a.extend(["--sample", "sample_ggx_vndf(wi, p0, rng)", "--sample-returns", "half-vector", "--pdf", "ggx_vndf_pdf(wi, d, p0)", "--params", "0.5"]);
        a.extend(extra);
        lobes(&a)
    };
    bad_input(&args(&[]), &["package::utils", utils.to_str().unwrap(), copy.to_str().unwrap()]);
    // the same under a second root
    std::fs::remove_file(&copy).unwrap();
    let other = dir.join("other");
    std::fs::copy(&utils, other.join("utils.wesl")).unwrap_or_else(|_| {
        std::fs::create_dir_all(&other).unwrap();
        std::fs::copy(&utils, other.join("utils.wesl")).unwrap()
    });
    let second = other.join("utils.wesl");
    bad_input(&args(&["--shader-root", other.to_str().unwrap()]), &["package::utils", utils.to_str().unwrap(), second.to_str().unwrap()]);
}

/// Item 12: `loops/a -> .` and `loops/b -> .` under the shader root: each folder is read once, and
/// the check of the naga_oil fixture is refused or passes in seconds, never walks 2^40 paths.
#[test]
fn a_symlink_loop_under_a_shader_root_is_walked_once() {
    let dir = scratch("symlink-loop");
    common::copy_dir(&root().join(OIL), &dir);
    let loops = dir.join("shaders/loops");
    std::fs::create_dir_all(&loops).unwrap();
    std::os::unix::fs::symlink(".", loops.join("a")).unwrap();
    std::os::unix::fs::symlink(".", loops.join("b")).unwrap();
    std::os::unix::fs::symlink("..", loops.join("up")).unwrap();
    let c = Composition::default()
        .shader_root(dir.join("shaders"))
        .stub("common::view", dir.join("stubs/view.wgsl"))
        .rand("rand");
    let start = Instant::now();
    let sampler = UserSampler::from_repository(&[dir.join("shaders/sampling/diffuse.wgsl")], "sample_diffuse(wi)", "diffuse_pdf(d)", None, Domain::Sphere, c);
    let took = start.elapsed();
    sampler.unwrap_or_else(|e| panic!("{e}"));
    assert!(took < Duration::from_secs(5), "took {took:?}");
}

/// Item 13: one function named twice by `--rand` (the same name, or its name and its qualified
/// path) was a panic (exit 101); now it is one function, and the check runs.
#[test]
fn one_rand_function_named_twice_is_one_function() {
    let dir = scratch("rand-twice");
    common::copy_dir(&root().join(OIL), &dir);
    for extra in [&["--rand", "rand"][..], &["--rand", "common::random::rand"][..]] {
        let out = oil_check(&dir, extra);
        assert_eq!(out.status.code(), Some(0), "{extra:?}: {}", text(&out.stderr));
    }
}

/// Item 13 in a scene: `rand = ["rand", "rand"]` through `lobes run` is not a panic.
#[test]
fn one_rand_function_named_twice_in_a_scene_is_one_function() {
    let dir = scratch("rand-twice-scene");
    common::copy_dir(&root().join(OIL), &dir);
    let scene = "[[case]]\nname = \"oil\"\nsamples = 65536\n\n[case.sampler]\nwgsl = [\"shaders/sampling/diffuse.wgsl\"]\nshader_root = [\"shaders\"]\n\
                 stub = { \"common::view\" = \"stubs/view.wgsl\" }\nsample = \"sample_diffuse(wi)\"\npdf = \"diffuse_pdf(d)\"\nrand = [\"rand\", \"rand\"]\n";
    let path = dir.join("scene.toml");
    write(&path, scene);
    let out_dir = dir.join("out");
    let out = lobes(&["run", path.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
}

/// A plain WGSL sampler (uniform sphere) that draws its two numbers from `name()`, through the
/// naga_oil composer (a `#define_import_path`) so that naga's WGSL writer writes it back.
fn named_rand(dir: &Path, name: &str) -> PathBuf {
    let file = dir.join("shaders/sampler.wgsl");
    write(
        &file,
        &format!(
            "#define_import_path sampling::unicode\n\n\
             var<private> state: u32 = 9u;\n\
             fn {name}() -> f32 {{ state = state * 747796405u + 2891336453u; return f32(state >> 8u) / 16777216.0; }}\n\
             fn s(wi: vec3<f32>) -> vec3<f32> {{\n\
             \x20   let z = 1.0 - 2.0 * {name}();\n\
             \x20   let phi = 6.283185307179586 * {name}();\n\
             \x20   let r = sqrt(max(0.0, 1.0 - z * z));\n\
             \x20   return vec3<f32>(r * cos(phi), r * sin(phi), z);\n\
             }}\n"
        ),
    );
    file
}

/// Item 15: `--rand würfel` (WGSL allows Unicode identifiers) and `--rand rand_` (naga's writer
/// drops the trailing underscore) are found in the composed module, and the check passes.
#[test]
fn rand_functions_renamed_by_the_wgsl_writer_are_found() {
    for name in ["würfel", "rand_", "r2"] {
        let dir = scratch(&format!("rand-name-{}", name.len()));
        let file = named_rand(&dir, name);
        let roots = dir.join("shaders");
        let out = lobes(&[
            "check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--sample", "s(wi)", "--pdf", "0.07957747154594767",
            "--rand", name, "--samples", "65536",
        ]);
        assert_eq!(out.status.code(), Some(0), "--rand {name}: {}", text(&out.stderr));
    }
}

/// Item 16: a naga_oil module that imports the sampler's own file is a cycle through the root,
/// named as one.
#[test]
fn a_naga_oil_cycle_through_the_root_is_named_as_a_cycle() {
    let dir = scratch("oil-cycle");
    let file = dir.join("shaders/sampling/diff_back.wgsl");
    write(&file, "#define_import_path sampling::diff_back\n#import sampling::helper::{h}\n\nfn p(d: vec3<f32>) -> f32 { return h(); }\nfn k() -> f32 { return 1.0; }\n");
    write(&dir.join("shaders/sampling/helper.wgsl"), "#define_import_path sampling::helper\n#import sampling::diff_back::{k}\n\nfn h() -> f32 { return k(); }\n");
    let roots = dir.join("shaders");
    let out = lobes(&["check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--sample", "vec3<f32>(0.0, 0.0, 1.0)", "--pdf", "p(d)"]);
    let e = bad_input(&out, &["cycle", "sampling::diff_back -> sampling::helper -> sampling::diff_back"]);
    assert!(!e.contains("no file under the shader roots"), "{e}");
}

/// Item 16: a WESL module that imports itself: a message naming the cycle.
#[test]
fn a_wesl_module_importing_itself_is_named_as_a_cycle() {
    let dir = scratch("wesl-cycle");
    let file = dir.join("shaders/sampling/s.wesl");
    write(&file, "import package::sampling::helper::helper;\n\nfn p(d: vec3<f32>) -> f32 { return helper(); }\n");
    write(&dir.join("shaders/sampling/helper.wesl"), "import package::sampling::helper::one;\n\nfn one() -> f32 { return 1.0; }\nfn helper() -> f32 { return one(); }\n");
    let roots = dir.join("shaders");
    let out = lobes(&["check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--sample", "vec3<f32>(0.0, 0.0, 1.0)", "--pdf", "p(d)"]);
    bad_input(&out, &["package::sampling::helper", "imports itself"]);
}

/// A plain uniform-sphere sampler with helper functions for the call-expression cases.
fn plain(dir: &Path) -> PathBuf {
    let file = dir.join("plain.wgsl");
    write(
        &file,
        "fn s(wi: vec3<f32>, u: vec4<f32>) -> vec3<f32> {\n\
         \x20   let z = 1.0 - 2.0 * u.x;\n\
         \x20   let r = sqrt(max(0.0, 1.0 - z * z));\n\
         \x20   return vec3<f32>(r * cos(6.2831853 * u.y), r * sin(6.2831853 * u.y), z);\n\
         }\n\
         fn p(d: vec3<f32>) -> f32 { return 0.07957747; }\n\
         fn v(d: vec3<f32>) -> vec3<f32> { return d; }\n",
    );
    file
}

/// Item 16: a `--pdf` / `--eval` expression of the wrong type, an empty one, and a call with the
/// wrong number of arguments: a message in the flag's terms, not naga's internals.
#[test]
fn density_expressions_of_the_wrong_type_or_empty_are_named_in_the_flags_terms() {
    let dir = scratch("density-types");
    let file = plain(&dir);
    let check = |pdf: &str, eval: Option<&str>| {
        let mut a = vec!["check", file.to_str().unwrap(), "--sample", "s(wi, u)", "--pdf", pdf];
        if let Some(e) = eval {
            a.extend(["--eval", e]);
        }
        lobes(&a)
    };
    for out in [bad_input(&check("v(d)", None), &["--pdf: 'v(d)' returns vec3<f32>; expected f32"]), bad_input(&check("p(d)", Some("v(d)")), &["--eval: 'v(d)' returns vec3<f32>; expected f32"])] {
        assert!(!out.contains("Handle") && !out.contains("Some(["), "{out}");
    }
    bad_input(&check("", None), &["--pdf: the expression is empty"]);
    bad_input(&check("  ", None), &["--pdf: the expression is empty"]);
    let e = bad_input(&check("p(d, d)", None), &["--pdf: 'p(d, d)'"]);
    assert!(!e.contains("Some(["), "{e}");
    bad_input(&lobes(&["check", file.to_str().unwrap(), "--sample", "", "--pdf", "p(d)"]), &["--sample: the expression is empty"]);
}

/// Item 16: `--define N=99999999999` is out of i32's range (said so); `X=false` vs `#ifdef X`
/// behaves as docs/samplers-in-repositories.md says (naga_oil's rule: `#ifdef` asks whether X is
/// defined at all).
#[test]
fn define_values_out_of_range_are_named() {
    let dir = scratch("define-range");
    common::copy_dir(&root().join(OIL), &dir);
    bad_input(&oil_check(&dir, &["--define", "N=99999999999"]), &["--define: N=99999999999: 99999999999 is out of the range of i32"]);
    bad_input(&oil_check(&dir, &["--define", "N=99999999999u"]), &["--define: N=99999999999u: 99999999999u is out of the range of u32"]);
    let docs = std::fs::read_to_string(root().join("docs/samplers-in-repositories.md")).unwrap();
    assert!(docs.contains("`--define X=false`") && docs.contains("`#ifdef X`"), "the docs say what X=false does to #ifdef X");
}

/// A composition's setting the front ends cannot use is refused before any reads a file, named
/// by its flag: a shader root that is not a folder, a define that is not a name, an order of
/// draws with no random function named (the library keys them by setting, Composition::validate).
#[test]
fn composition_settings_are_refused_naming_their_flag() {
    let dir = scratch("composition-settings");
    let file = plain(&dir);
    let check = |extra: &[&str]| {
        let mut args = vec!["check", file.to_str().unwrap(), "--sample", "s(wi, u)", "--pdf", "p(d)"];
        args.extend_from_slice(extra);
        lobes(&args)
    };
    let missing = dir.join("no_such_dir");
    bad_input(&check(&["--shader-root", missing.to_str().unwrap()]), &[&format!("--shader-root: {} is not a folder", missing.display())]);
    bad_input(&check(&["--define", "TWO WORDS"]), &["--define: 'TWO WORDS' is no shader def"]);
    bad_input(&check(&["--rand-order", "x,y"]), &["--rand-order: an order for the draws of the named random functions"]);
}

/// Conventions that do not fit the domain or the incidence are refused naming their flag, where
/// the library keys them by setting (Conventions::validate, check_incident): a plane's points have
/// no normal, a sampler declared for light from above gets no θ past 90°, a half vector is
/// neither a plane's point nor a light's.
#[test]
fn conventions_that_do_not_fit_are_refused_naming_their_flag() {
    let dir = scratch("conventions-settings");
    let file = plain(&dir);
    let check = |extra: &str| {
        let mut args = vec!["check", file.to_str().unwrap(), "--sample", "s(wi, u)", "--pdf", "p(d)"];
        args.extend(extra.split(' '));
        lobes(&args)
    };
    let plane = "--domain plane --bounds 0,0,1,1";
    let directions = "only for directions (a point of the plane has no normal)";
    bad_input(&check(&format!("{plane} --reflection-only")), &[&format!("--reflection-only: {directions}")]);
    bad_input(&check(&format!("{plane} --incident upper")), &[&format!("--incident: {directions}")]);
    bad_input(&check(&format!("{plane} --measure projected")), &[&format!("--measure: {directions}")]);
    bad_input(&check(&format!("{plane} --frame y-up")), &[&format!("--frame: {directions}")]);
    bad_input(&check(&format!("{plane} --sample-returns half-vector")), &["--sample-returns: a half vector reflects wi into a direction"]);
    bad_input(&check("--measure area --normal vec3(0.0,0.0,1.0) --sample-returns half-vector"), &["--sample-returns: a half vector is not a light's point"]);
    bad_input(&check("--incident upper --incident-theta 95"), &["--incident-theta: 95° is not above the surface, and the sampler is declared for upper incidence"]);
    bad_input(&check("--reflection-only --incident-theta 90"), &["--incident-theta: 90° is not above the surface, and the sampler is declared reflection-only"]);
}

/// Item 16: `--budget 1e-300` is refused with a short message (no 300 zeros).
#[test]
fn a_tiny_budget_gets_a_short_message() {
    let dir = scratch("budget");
    let file = plain(&dir);
    let out = lobes(&["check", file.to_str().unwrap(), "--sample", "s(wi, u)", "--pdf", "p(d)", "--budget", "1e-300"]);
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert!(e.len() < 600 && !e.contains("00000000"), "{e}");
}

/// Item 16: a `--stub` no import uses, and one module stubbed twice: exit 2 naming it.
#[test]
fn unused_or_repeated_stubs_are_refused_naming_them() {
    let dir = scratch("stubs");
    common::copy_dir(&root().join(OIL), &dir);
    let other = format!("common::lights={}", dir.join("stubs/view.wgsl").display());
    bad_input(&oil_check(&dir, &["--stub", &other]), &["--stub: common::lights: no import"]);
    let again = format!("common::view={}", dir.join("stubs/view.wgsl").display());
    bad_input(&oil_check(&dir, &["--stub", &again]), &["--stub: common::view is given twice"]);
    // WESL: a stub of a module nothing imports
    let wesl = scratch("stubs-wesl");
    common::copy_dir(&root().join(WESL), &wesl);
    let file = wesl.join("shaders/sampling/ggx.wesl");
    let roots = wesl.join("shaders");
    let stub = format!("package::bindings={}", wesl.join("stubs/bindings.wesl").display());
    let unused = format!("package::lights={}", wesl.join("stubs/bindings.wesl").display());
    let out = lobes(&[
        "check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--stub", &stub, "--stub", &unused,
        "--sample", "sample_ggx_vndf(wi, p0, rng)", "--sample-returns", "half-vector", "--pdf", "ggx_vndf_pdf(wi, d, p0)", "--params", "0.5",
    ]);
    bad_input(&out, &["--stub: package::lights: no import"]);
}

/// Whether `e` is bad input naming `what` (or a WGSL error at a file:line:column), a setting's
/// (a call expression's) and one with advice included.
fn names_input(e: &CheckError, what: &str) -> bool {
    match e {
        CheckError::Input(m) | CheckError::Setting { message: m, .. } => m.contains(what) || what.trim().is_empty(),
        CheckError::Advised(m) => m.to_string().contains(what) || what.trim().is_empty(),
        CheckError::Wgsl(m) => m.contains(':'),
        _ => false,
    }
}

const SPHERE: &str = "fn s(wi: vec3<f32>, u: vec4<f32>) -> vec3<f32> { let z = 1.0 - 2.0 * u.x; let r = sqrt(max(0.0, 1.0 - z * z)); return vec3<f32>(r * cos(6.28 * u.y), r * sin(6.28 * u.y), z); }\n\
                      fn p(d: vec3<f32>) -> f32 { return 0.0795; }\nfn rnd() -> f32 { return 0.5; }\n";

fn sphere() -> Vec<Source> {
    vec![Source { name: "sphere.wgsl".into(), text: SPHERE.into() }]
}

/// Text a user might type as an expression: lobes' names, operators, calls, qualified paths,
/// stray punctuation and Unicode.
fn expression() -> impl Strategy<Value = String> {
    let token = prop_oneof![
        Just("wi".to_string()), Just("d".to_string()), Just("u".to_string()), Just("p0".to_string()), Just("params".to_string()),
        Just("rng".to_string()), Just("s(wi, u)".to_string()), Just("p(d)".to_string()), Just("(".to_string()), Just(")".to_string()),
        Just(",".to_string()), Just("+".to_string()), Just("*".to_string()), Just("::".to_string()), Just("a::b::c".to_string()),
        Just("1.0".to_string()), Just("99999999999".to_string()), Just(".xyz".to_string()), Just("{".to_string()), Just(";".to_string()),
        Just("é".to_string()), Just("lobes_x".to_string()), Just(" ".to_string()), "[a-z_]{1,6}", "[ -~]{0,4}",
    ];
    prop::collection::vec(token, 0..8).prop_map(|t| t.concat())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    /// Call expressions: no panic; a rejection is bad input (Input, or a WGSL error at a place).
    #[test]
    fn call_expressions_never_panic(sample in expression(), pdf in expression()) {
        match UserSampler::from_sources(sphere(), &sample, &pdf, None, Domain::Sphere) {
            Ok(_) => {}
            Err(e) => prop_assert!(names_input(&e, ""), "{sample:?} / {pdf:?}: {e:?}"),
        }
    }

    /// A define, a stub, a random function and an order of draws as typed: no panic; a rejection
    /// is keyed by a setting of the composition, which the command line names by its flag.
    #[test]
    fn composition_settings_never_panic(define in "[ -~é]{0,12}", stub in "[ -~é]{0,12}", rand in "[ -~é]{0,8}", order in "[ -~]{0,12}") {
        let mut c = Composition::default().define(&define, None).stub(&stub, "stub.wgsl").stub(&stub, "again.wgsl").rand(&rand);
        c.rand_order = Draw::parse_list(&order).ok();
        let e = c.validate().unwrap_err();
        prop_assert!(matches!(e, CheckError::Setting { setting: Setting::Define | Setting::Stub, .. }), "{e:?}");
        let ordered_alone = Composition { rand_order: Some(vec![Draw::X]), ..Composition::default() }.validate().unwrap_err();
        prop_assert!(matches!(ordered_alone, CheckError::Setting { setting: Setting::RandOrder, .. }), "{ordered_alone:?}");
    }

    /// Module paths and `--rand` names through composition: no panic, bad input naming them.
    #[test]
    fn module_paths_and_rand_names_never_panic(path in "[a-z:_é ]{0,16}", rand in "[a-zé_0-9:]{1,12}") {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("adversarial-frontend-proptest-paths");
        let file = dir.join("sphere.wgsl");
        write(&file, &format!("#import {path}\n{SPHERE}"));
        let c = Composition::default().rand(&rand).shader_root(&dir);
        if let Err(e) = UserSampler::from_repository(&[file], "s(wi, u)", "p(d)", None, Domain::Sphere, c) {
            prop_assert!(names_input(&e, ""), "{path:?} / {rand:?}: {e:?}");
        }
        let file = dir.join("plain/sphere.wgsl");
        write(&file, SPHERE);
        let c = Composition::default().rand(&rand).rand(&rand);
        if let Err(e) = UserSampler::from_repository(&[file], "s(wi, u)", "p(d)", None, Domain::Sphere, c) {
            prop_assert!(names_input(&e, &rand), "{rand:?}: {e:?}");
        }
    }
}

/// Issue 34 §2: a call expression names what the sampler's file imports as the file names it
/// (`PI` of `#import common::maths::{PI, TAU}`), not only by a qualified path: the cosine pdf
/// written with it passes, and with `TAU` (half the density) fails.
#[test]
fn a_call_expression_names_an_imported_item_as_the_file_does() {
    let dir = scratch("imported-names");
    common::copy_dir(&root().join(OIL), &dir);
    let with_pdf = |pdf: &str| {
        let file = dir.join("shaders/sampling/diffuse.wgsl");
        let roots = dir.join("shaders");
        let stub = format!("common::view={}", dir.join("stubs/view.wgsl").display());
        lobes(&[
            "check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--stub", &stub, "--sample", "sample_diffuse(wi)",
            "--pdf", pdf, "--rand", "rand", "--samples", "262144",
        ])
    };
    let out = with_pdf("select(0.0, d.z / PI, d.z > 0.0)");
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let out = with_pdf("select(0.0, d.z / TAU, d.z > 0.0)");
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
}

/// Issue 34 §2: `--rand rand_f` where `rand_f` lives in a module whose path has underscores
/// (Bevy's `bevy_pbr::render_utils`, mangled `…_1rand_f` by the wesl crate): found, and the GGX
/// sampler passes.
#[test]
fn a_rand_function_of_a_module_with_underscores_in_its_path_is_found() {
    let dir = scratch("wesl-underscores");
    common::copy_dir(&root().join(WESL), &dir);
    let moved = dir.join("shaders/bevy_pbr/render_utils.wesl");
    std::fs::create_dir_all(moved.parent().unwrap()).unwrap();
    std::fs::rename(dir.join("shaders/utils.wesl"), &moved).unwrap();
    let file = dir.join("shaders/sampling/ggx.wesl");
    let source = std::fs::read_to_string(&file).unwrap();
    let edited = source.replace("import package::utils::rand_vec2f;", "import package::bevy_pbr::render_utils::rand_vec2f;");
    assert_ne!(edited, source);
    std::fs::write(&file, edited).unwrap();
    let roots = dir.join("shaders");
    let stub = format!("package::bindings={}", dir.join("stubs/bindings.wesl").display());
    let out = lobes(&[
        "check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--stub", &stub, "--sample", "sample_ggx_vndf(wi, p0, rng)",
        "--sample-returns", "half-vector", "--pdf", "ggx_vndf_pdf(wi, d, p0)", "--rand", "rand_f", "--params", "0.5", "--incident-theta", "40",
        "--samples", "262144",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("random draws x,y"), "{}", text(&out.stdout));
}

/// Issue 34 §2: a renderer's own preprocessor line (RedGPU's `#redgpu_include`) is named, with
/// what to do, not a WGSL parse error at `#`.
#[test]
fn a_custom_preprocessor_line_is_named_with_what_to_do() {
    let dir = scratch("custom-directive");
    let file = dir.join("ibl.wgsl");
    write(&file, &format!("#redgpu_include SYSTEM_UNIFORM\n{SPHERE}"));
    let out = lobes(&["check", file.to_str().unwrap(), "--sample", "s(wi, u)", "--pdf", "p(d)"]);
    bad_input(&out, &[&format!("{}:1: `#redgpu_include SYSTEM_UNIFORM`", file.display()), "pre-expanded", "--stub", "--define"]);
}

/// Issue 34 §2: an unresolved import among many modules lists the closest few, not all of them.
#[test]
fn an_unresolved_import_among_many_modules_lists_the_closest_few() {
    let dir = scratch("many-modules");
    for i in 0..40 {
        write(&dir.join(format!("shaders/pbr/m{i}.wgsl")), &format!("#define_import_path pbr::module_{i}\nfn f{i}() -> f32 {{ return 1.0; }}\n"));
    }
    write(&dir.join("shaders/pbr/lighting.wgsl"), "#define_import_path pbr::lighting\nfn light() -> f32 { return 1.0; }\n");
    let file = dir.join("shaders/sampler.wgsl");
    write(&file, &format!("#import pbr::lightning::light\n{SPHERE}fn lit(d: vec3<f32>) -> f32 {{ return light() * 0.0795; }}\n"));
    let roots = dir.join("shaders");
    let out = lobes(&["check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--sample", "s(wi, u)", "--pdf", "lit(d)"]);
    let e = bad_input(&out, &["closest: `pbr::lighting`", "41 modules found"]);
    let listed = e.matches("pbr::module_").count();
    assert!(listed <= 8, "{listed} module names listed: {e}");
}
