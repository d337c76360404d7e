//! `lobes check` of WESL as Bevy's main branch writes it (issue 34 §2), on trees written here:
//! `@if(…) { … } @elif(…) { … } @else { … }` blocks at module scope and in functions, composed
//! with the features `--define` gives (tests/fixtures/repository/wesl_if); another package's
//! modules found where `--package NAME=DIR` says, with `--rand` naming a function of that package
//! (tests/fixtures/repository/wesl_packages); errors of the `wesl` crate at the file, line and
//! column their span belongs to.
//! GPU tests: they need a wgpu adapter (lavapipe in CI) and fail without one.

use crate::common;
use common::{lobes, root, stderr, verdicts};

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Output;

const IF: &str = "tests/fixtures/repository/wesl_if";
const PACKAGES: &str = "tests/fixtures/repository/wesl_packages";





fn copy_tree(name: &str, from: &str, file: &str, edit: impl Fn(&str) -> String) -> PathBuf {
    common::edited_copy(&format!("check-wesl-{name}"), &root().join(from), file, edit)
}

/// The cosine sampler of the `@if` tree, with `extra` flags.
fn cosine_if(dir: &Path, extra: &[&str]) -> Output {
    let file = dir.join("shaders/sampling/cosine.wesl");
    let shaders = dir.join("shaders");
    let mut args = vec!["check", file.to_str().unwrap(), "--shader-root", shaders.to_str().unwrap()];
    args.extend(["--sample", "sample_cosine(rng)", "--pdf", "cosine_pdf(d)", "--rand", "rand_f", "--samples", "262144", "--json"]);
    args.extend(extra);
    lobes(&args)
}

/// Module-scope blocks choose the bindings and `hemisphere_z`; a block in `sample_cosine`
/// declares the `x` and `y` used after it (blocks have no scope of their own, as wesl-rs 0.5
/// flattens them). The default (`@else`) and `PRECISE_Z` are Malley's z and pass; `FAST_Z`
/// takes the `@elif` block's wrong z and fails.
#[test]
fn if_blocks_compose_the_path_the_features_choose() {
    let dir = root().join(IF);
    for flags in [&[][..], &["--define", "PRECISE_Z", "--define", "FAST_Z", "--define", "MIRROR_X", "--define", "BINDLESS"][..]] {
        let out = cosine_if(&dir, flags);
        assert_eq!(out.status.code(), Some(0), "{flags:?}: {}", stderr(&out));
        assert!(verdicts(&out).iter().all(|(_, passed)| *passed), "{flags:?}");
    }
    let out = cosine_if(&dir, &["--define", "FAST_Z"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let failed: Vec<String> = verdicts(&out).into_iter().filter(|(_, p)| !p).map(|(n, _)| n).collect();
    assert!(failed.contains(&"chi2".to_string()), "{failed:?}");
    // an @if feature is true or false
    let out = cosine_if(&dir, &["--define", "FAST_Z=2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--define: FAST_Z=2: WESL's @if features are true or false"), "{}", stderr(&out));
}

/// A malformed condition in an imported module: exit 2 at its file, line and column, saying
/// what a condition may hold.
#[test]
fn a_malformed_if_is_exit_2_at_its_file_line_and_column() {
    let dir = copy_tree("bad-if", IF, "shaders/rng.wesl", |t| {
        t.replace("// A float in [0, 1) from the top 24 bits.\n", "// A float in [0, 1) from the top 24 bits.\n@if(FAST_Z == 1) {\nconst SCALE: f32 = 1.0;\n}\n")
    });
    let out = cosine_if(&dir, &[]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    let rng = dir.join("shaders/rng.wesl");
    let line = std::fs::read_to_string(&rng).unwrap().lines().position(|l| l.starts_with("@if(FAST_Z == 1)")).unwrap() + 1;
    assert_eq!(line, 10);
    assert!(e.contains(&format!("{}:10:1: @if(FAST_Z == 1): `=` is not allowed here; a translate-time expression is a feature name, true, false, !, &&, || and parentheses", rng.display())), "{e}");
    // an @else with no @if before it, in the sampler's own file
    let dir = copy_tree("orphan-else", IF, "shaders/sampling/cosine.wesl", |t| t.replace("fn cosine_pdf(", "@else {\n}\nfn cosine_pdf("));
    let out = cosine_if(&dir, &[]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let file = dir.join("shaders/sampling/cosine.wesl");
    let line = std::fs::read_to_string(&file).unwrap().lines().position(|l| l.starts_with("@else {")).unwrap() + 1;
    assert!(stderr(&out).contains(&format!("{}:{line}:1: @else without an @if before it", file.display())), "{}", stderr(&out));
}

/// A parse error in an imported module is at that module's file, line and column, never headed
/// with the sampler's file and a byte range of another file.
#[test]
fn a_wesl_error_in_an_imported_file_is_at_that_files_line_and_column() {
    let dir = copy_tree("imported-error", IF, "shaders/rng.wesl", |t| t.replace("    let word = ((", "    let word = let (("));
    let out = cosine_if(&dir, &[]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    let rng = dir.join("shaders/rng.wesl");
    // line 5: the parser reads `let` after `=` as a name and stops at the `(` after it, column 20
    assert!(e.starts_with(&format!("lobes: error: {}:5:20: unexpected token `(`", rng.display())), "{e}");
    assert!(e.contains("let word = let (("), "the line itself: {e}");
    assert!(e.contains("in module package::rng"), "{e}");
    assert!(!e.contains("cosine.wesl") && !e.contains("chars "), "{e}");
}

/// The app and the library both hold modules `consts` and `random`: without `--package` lobes looks for
/// `mathlib::consts` and `mathlib::random` under the app's root and takes the app's own (its consts
/// lack INV_PI, so the tree does not compose and the message names that file); with it the
/// library's is composed, and `--rand rand_f` replaces the library's RNG (its draws are u.x and
/// u.y, so the Jacobian check applies).
#[test]
fn another_package_is_found_where_package_says() {
    let file = format!("{PACKAGES}/app/shaders/sampling/cosine.wesl");
    let shaders = format!("{PACKAGES}/app/shaders");
    let lib = format!("mathlib={PACKAGES}/mathlib/src");
    let args = |extra: &[&'static str]| -> Vec<String> {
        let mut a: Vec<String> = ["check", &file, "--shader-root", &shaders, "--sample", "sample_cosine(rng)", "--pdf", "cosine_pdf(d)", "--rand", "rand_f", "--samples", "262144", "--json"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let run = |a: Vec<String>| lobes(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let out = run(args(&[]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(e.contains("module `mathlib::consts` has no declaration `INV_PI`") && e.contains(&format!("{shaders}/consts.wesl")), "the fallback's wrong file: {e}");
    let mut with = args(&[]);
    with.extend(["--package".to_string(), lib.clone()]);
    let out = run(with);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v = verdicts(&out);
    assert!(v.iter().all(|(_, p)| *p), "{v:?}");
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(report["sampler"].as_str().unwrap_or("").contains("random draws x,y"), "{report}");
}

/// A `--package` folder that does not hold the module: exit 2 naming the folder, the closest
/// few modules found (not all of them) and the flag to fix.
#[test]
fn a_module_missing_from_its_package_names_the_closest_few() {
    let file = format!("{PACKAGES}/app/shaders/sampling/cosine.wesl");
    let wrong = format!("mathlib={PACKAGES}/mathlib");
    let out = lobes(&["check", &file, "--shader-root", &format!("{PACKAGES}/app/shaders"), "--package", &wrong, "--sample", "sample_cosine(rng)", "--pdf", "cosine_pdf(d)"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    // the crate resolves the two imports in either order: the first one missing is named
    let m = if e.contains("module not found: `mathlib::consts`") { "consts" } else { "random" };
    assert!(e.contains(&format!("no file {m}.wesl or .wgsl in {PACKAGES}/mathlib (--package mathlib)")), "{e}");
    assert!(e.contains(&format!("closest: `mathlib::src::{m}`, `package::{m}`")), "{e}");
    assert!(e.contains("of the 5 modules found"), "{e}");
    assert!(e.contains("Check the folder of --package mathlib=DIR"), "{e}");
    // a folder that is not there, and a name that is not a package's
    let out = lobes(&["check", &file, "--package", "mathlib=no/such/dir", "--sample", "sample_cosine(rng)", "--pdf", "cosine_pdf(d)"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--package: mathlib=no/such/dir: not a folder"), "{}", stderr(&out));
    let out = lobes(&["check", &file, "--package", "package=x", "--sample", "sample_cosine(rng)", "--pdf", "cosine_pdf(d)"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--package 'package': a package name is an identifier other than package and super"), "{}", stderr(&out));
}

/// The scene key `package` is `--package`: a `lobes run` scene whose user case names the
/// library's folder composes the library's modules (the roots' fallback alone takes the app's
/// `consts`, which lacks INV_PI, and the case would be an input error) and passes.
#[test]
fn a_scene_case_finds_another_package_where_its_package_key_says() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("check-wesl-scene-package");
    std::fs::create_dir_all(&dir).unwrap();
    let packages = root().join(PACKAGES);
    let scene = dir.join("package.toml");
    std::fs::write(
        &scene,
        format!(
            "[[case]]\nname = \"cosine-from-mathlib\"\nsampler = {{ wgsl = [\"{0}/app/shaders/sampling/cosine.wesl\"], shader_root = [\"{0}/app/shaders\"], package = {{ mathlib = \"{0}/mathlib/src\" }}, sample = \"sample_cosine(rng)\", pdf = \"cosine_pdf(d)\", rand = [\"rand_f\"] }}\nsamples = 262144\n",
            packages.display()
        ),
    )
    .unwrap();
    let out = lobes(&["run", scene.to_str().unwrap(), "--out", dir.join("out").to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["cases"][0]["passed"], Value::Bool(true), "{summary}");
}
