//! `lobes check` on samplers as they are in a renderer's repository (issue 23 §1–2): a WESL
//! package and a naga_oil module tree (tests/fixtures/repository), checked with no adapter file
//! through their own signatures, RNGs and imports; their broken variants fail by the check that
//! should catch them; bad imports and errors in imported modules are reported at the user's
//! file:line:column.
//! GPU tests: they need a wgpu adapter (lavapipe in CI) and fail without one.

use serde_json::Value;
use crate::common;
use common::{lobes, root, stderr};

use std::path::{Path, PathBuf};
use std::process::Output;

const WESL: &str = "tests/fixtures/repository/wesl";
const OIL: &str = "tests/fixtures/repository/naga_oil";




/// The report's verdict per check.
fn verdicts(out: &Output) -> Vec<(String, bool, String)> {
    let v: Value = serde_json::from_slice(&out.stdout).expect("a JSON report on stdout");
    v["checks"]
        .as_array()
        .expect("checks")
        .iter()
        .map(|c| (c["name"].as_str().unwrap_or("?").to_string(), c["passed"].as_bool().unwrap(), c["summary"].as_str().unwrap_or("").to_string()))
        .collect()
}

fn report_field(out: &Output, key: &str) -> String {
    let v: Value = serde_json::from_slice(&out.stdout).expect("a JSON report on stdout");
    v[key].as_str().unwrap_or("").to_string()
}

/// Bevy Solari's shape: `sample_ggx_vndf(wi, roughness, rng) -> vec3` returning a half vector,
/// `ggx_vndf_pdf(wi, wo, roughness)`, the RNG behind `ptr<function, u32>`.
fn wesl_args<'a>(file: &'a str, extra: &[&'a str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "check",
        file,
        "--shader-root",
        "tests/fixtures/repository/wesl/shaders",
        "--stub",
        "package::bindings=tests/fixtures/repository/wesl/stubs/bindings.wesl",
        "--sample",
        "sample_ggx_vndf(wi, p0, rng)",
        "--sample-returns",
        "half-vector",
        "--pdf",
        "ggx_vndf_pdf(wi, d, p0)",
        "--rand",
        "rand_f",
        "--params",
        "0.5",
        "--incident-theta",
        "40",
        "--samples",
        "1048576",
        "--json",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn run(args: &[String]) -> Output {
    lobes(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn a_wesl_package_is_checked_as_it_is_and_passes() {
    let out = run(&wesl_args("tests/fixtures/repository/wesl/shaders/sampling/ggx.wesl", &[]));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v = verdicts(&out);
    for (name, passed, summary) in &v {
        assert!(passed, "{name}: {summary}");
    }
    // the RNG's two draws are u.x and u.y, so the Jacobian check applies (it does not without --rand)
    let jac = v.iter().find(|c| c.0 == "jacobian").expect("a jacobian check");
    assert!(!jac.2.starts_with("not applicable"), "{}", jac.2);
    assert!(report_field(&out, "sampler").contains("random draws x,y"), "{}", report_field(&out, "sampler"));
    // the pdf is named once, as written: "∫ggx_vndf_pdf(wi, d, p0) over the domain", never "…(d)(d)"
    let norm = v.iter().find(|c| c.0 == "normalization").expect("a normalization check");
    assert!(norm.2.starts_with("∫ggx_vndf_pdf(wi, d, p0) over the domain"), "{}", norm.2);
    for (name, _, summary) in &v {
        assert!(!summary.contains(")(d)"), "{name}: {summary}");
    }
}

#[test]
fn a_broken_wesl_sampler_fails_chi2() {
    let out = run(&wesl_args("tests/fixtures/repository/wesl/shaders/sampling/ggx_broken.wesl", &[]));
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let v = verdicts(&out);
    let chi2 = v.iter().find(|c| c.0 == "chi2").unwrap();
    assert!(!chi2.1, "{}", chi2.2);
}

fn oil_args(extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "check",
        "tests/fixtures/repository/naga_oil/shaders/sampling/diffuse.wgsl",
        "--shader-root",
        "tests/fixtures/repository/naga_oil/shaders",
        "--stub",
        "common::view=tests/fixtures/repository/naga_oil/stubs/view.wgsl",
        "--sample",
        "sample_diffuse(wi)",
        "--pdf",
        "diffuse_pdf(d)",
        "--eval",
        "diffuse_eval(d)",
        "--rand",
        "rand",
        "--samples",
        "1048576",
        "--seed",
        "2",
        "--json",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

#[test]
fn a_naga_oil_tree_is_checked_as_it_is_and_passes_with_and_without_a_shader_def() {
    for defs in [&[][..], &["--define", "UNIFORM_HEMISPHERE"][..]] {
        let out = run(&oil_args(defs));
        assert_eq!(out.status.code(), Some(0), "{defs:?}: {}", stderr(&out));
        for (name, passed, summary) in verdicts(&out) {
            assert!(passed, "{defs:?} {name}: {summary}");
        }
    }
}

#[test]
fn a_shader_def_that_breaks_the_naga_oil_sampler_fails_chi2() {
    let out = run(&oil_args(&["--define", "COSINE_SQUARED"]));
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let v = verdicts(&out);
    assert!(!v.iter().find(|c| c.0 == "chi2").unwrap().1);
}

/// Qualified names in call expressions (issue 23 §5): naga_oil's `maths::PI` (the last segment
/// of `#import common::maths::{PI, TAU}`) resolves to the composed name, and the cosine pdf
/// written with it passes while the same with `maths::TAU` (half the density) fails χ²; a name
/// no imported module holds, and a qualified name in plain WGSL, are refused naming what is
/// there (they were WGSL parse errors in the generated glue).
#[test]
fn qualified_names_in_call_expressions_resolve_or_are_refused() {
    let with_pdf = |pdf: &str| -> Vec<String> { oil_args(&[]).into_iter().map(|a| if a == "diffuse_pdf(d)" { pdf.into() } else { a }).collect() };
    let out = run(&with_pdf("select(0.0, d.z / maths::PI, d.z > 0.0)"));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    for (name, passed, summary) in verdicts(&out) {
        assert!(passed, "{name}: {summary}");
    }
    let half = run(&with_pdf("select(0.0, d.z / maths::TAU, d.z > 0.0)"));
    assert_eq!(half.status.code(), Some(1), "{}", stderr(&half));
    assert!(!verdicts(&half).iter().find(|c| c.0 == "chi2").unwrap().1);
    let unknown = run(&with_pdf("d.z / maths::PIE"));
    assert_eq!(unknown.status.code(), Some(2));
    let e = stderr(&unknown);
    assert!(e.contains("--pdf: 'd.z / maths::PIE': no item `PIE` of a module `maths`") && e.contains("common::maths::PI"), "{e}");
    let f = plain("qualified.wgsl", "fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> { return vec4<f32>(0.0, 0.0, 1.0, 1.0); }\n");
    let out = lobes(&["check", f.to_str().unwrap(), "--sample", "s", "--pdf", "d.z / maths::PI"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("a qualified name (module::function) needs imports"), "{}", stderr(&out));
}

/// A copy of a fixture tree in a fresh folder, with `edit` applied to one file.
fn copy_tree(name: &str, from: &str, file: &str, edit: impl Fn(&str) -> String) -> PathBuf {
    common::edited_copy(&format!("check-repository-{name}"), &root().join(from), file, edit)
}

#[test]
fn an_unresolved_naga_oil_import_names_the_module_the_roots_and_the_closest_name() {
    let dir = copy_tree("oil-unresolved", OIL, "shaders/sampling/diffuse.wgsl", |t| t.replace("#import common::maths::{PI, TAU}", "#import common::mathematics::{PI, TAU}"));
    let file = dir.join("shaders/sampling/diffuse.wgsl");
    let roots = dir.join("shaders");
    let out = lobes(&["check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--sample", "sample_diffuse(wi)", "--pdf", "diffuse_pdf(d)", "--rand", "rand"]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    // the import's own line and column, in the user's file
    assert!(e.contains(&format!("{}:3:9", file.display())), "{e}");
    assert!(e.contains("unresolved import `common::mathematics`"), "{e}");
    assert!(e.contains(roots.to_str().unwrap()), "{e}");
    assert!(e.contains("closest: `common::maths`"), "{e}");
}

#[test]
fn an_unresolved_wesl_import_names_the_module_the_roots_and_the_closest_name() {
    let dir = copy_tree("wesl-unresolved", WESL, "shaders/sampling/ggx.wesl", |t| t.replace("import package::utils::rand_vec2f;", "import package::util::rand_vec2f;"));
    let file = dir.join("shaders/sampling/ggx.wesl");
    let roots = dir.join("shaders");
    let out = lobes(&["check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--sample", "sample_ggx_vndf(wi, p0, rng)", "--pdf", "ggx_vndf_pdf(wi, d, p0)"]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(e.contains("package::util"), "{e}");
    assert!(e.contains("unresolved import"), "{e}");
    assert!(e.contains(roots.to_str().unwrap()), "{e}");
    assert!(e.contains("closest: `package::utils`"), "{e}");
}

#[test]
fn an_error_in_an_imported_naga_oil_module_is_at_its_file_line_and_column() {
    // line 4 of common/maths.wgsl: `const PI: f32 = 3.14…;` made a bool
    let dir = copy_tree("oil-error", OIL, "shaders/common/maths.wgsl", |t| t.replace("const PI: f32 = 3.141592653589793;", "const PI: f32 = true;"));
    let file = dir.join("shaders/sampling/diffuse.wgsl");
    let roots = dir.join("shaders");
    let stub = root().join(OIL).join("stubs/view.wgsl");
    let stub = format!("common::view={}", stub.display());
    let out = lobes(&["check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--stub", &stub, "--sample", "sample_diffuse(wi)", "--pdf", "diffuse_pdf(d)", "--rand", "rand"]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    let maths = dir.join("shaders/common/maths.wgsl");
    assert!(e.contains(&format!("{}:3:", maths.display())), "{e}");
    assert!(e.contains("common::maths"), "{e}");
}

#[test]
fn an_error_in_an_imported_wesl_module_names_its_file_and_module() {
    let dir = copy_tree("wesl-error", WESL, "shaders/utils.wesl", |t| t.replace("return vec2<f32>(rand_f(state), rand_f(state));", "return vec2<f32>(rand_f(state), rand_f(state))"));
    let file = dir.join("shaders/sampling/ggx.wesl");
    let roots = dir.join("shaders");
    let out = lobes(&["check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--sample", "sample_ggx_vndf(wi, p0, rng)", "--pdf", "ggx_vndf_pdf(wi, d, p0)"]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(e.contains("utils.wesl"), "{e}");
    assert!(e.contains("package::utils"), "{e}");
}

/// A type error only naga finds (the wesl crate composes without validating, and writes the tree
/// anew): reported at the user's file, line and column, not at the composed text's.
#[test]
fn a_type_error_in_a_wesl_file_is_at_its_file_line_and_column() {
    let file = "tests/fixtures/repository/wesl/shaders/sampling/ggx_type_error.wesl";
    let out = run(&wesl_args(file, &[]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    // line 35: `    let z2: u32 = w.z * w.z;`
    let line = std::fs::read_to_string(root().join(file)).unwrap().lines().position(|l| l.contains("let z2: u32")).unwrap() + 1;
    assert_eq!(line, 35);
    // the `z2` of `let z2: u32`, column 9, found through its line (z2 occurs three times in ggx_g1)
    assert!(e.contains(&format!("{file}:35:9: the type of `z2` is expected to be `u32`")), "{e}");
    assert!(e.contains("in `ggx_g1` of module package::sampling::ggx_type_error"), "{e}");
    // the composed position only in the note
    assert!(!e.starts_with("lobes: error: <"), "{e}");
}

/// The same in an imported module: its file, its line and column, the item as the module names it
/// (not its mangled name).
#[test]
fn a_type_error_in_an_imported_wesl_module_is_at_its_file_line_and_column() {
    // utils.wesl's rand_f: a u32 times an f32
    let dir = copy_tree("wesl-type-error", WESL, "shaders/utils.wesl", |t| {
        t.replace("return f32(pcg_next(state) >> 8u) * (1.0 / 16777216.0);", "return (pcg_next(state) >> 8u) * (1.0 / 16777216.0);")
    });
    let file = dir.join("shaders/sampling/ggx.wesl");
    let roots = dir.join("shaders");
    let stub = root().join(WESL).join("stubs/bindings.wesl");
    let stub = format!("package::bindings={}", stub.display());
    let out = lobes(&[
        "check", file.to_str().unwrap(), "--shader-root", roots.to_str().unwrap(), "--stub", &stub,
        "--sample", "sample_ggx_vndf(wi, p0, rng)", "--pdf", "ggx_vndf_pdf(wi, d, p0)", "--rand", "rand_f",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    let utils = dir.join("shaders/utils.wesl");
    // naga calls the function invalid, at its declaration: `fn rand_f(` on line 11 of utils.wesl
    let line = std::fs::read_to_string(&utils).unwrap().lines().position(|l| l.starts_with("fn rand_f(")).unwrap() + 1;
    assert!(e.contains(&format!("{}:{line}:1: Function", utils.display())), "{e}");
    assert!(e.contains("`rand_f` of module package::utils"), "{e}");
}

/// A plain WGSL sampler with a global rand(), as GLSL ports write it.
fn plain(name: &str, text: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("check-repository-plain");
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join(name);
    std::fs::write(&f, text).unwrap();
    f
}

const RAND: &str = "var<private> state: u32 = 7u;\n\
    fn rand() -> f32 { state = state * 747796405u + 2891336453u; return f32(state >> 8u) / 16777216.0; }\n";

#[test]
fn more_than_four_draws_is_an_error_naming_the_count() {
    let text = format!(
        "{RAND}fn s(wi: vec3<f32>) -> vec3<f32> {{\n  var t = 0.0;\n  for (var i = 0; i < 5; i++) {{ t += rand(); }}\n  let z = 2.0 * fract(t) - 1.0;\n  let r = sqrt(max(0.0, 1.0 - z * z));\n  return vec3<f32>(r, 0.0, z);\n}}\n"
    );
    let f = plain("five_draws.wgsl", &text);
    let out = lobes(&["check", f.to_str().unwrap(), "--sample", "s(wi)", "--pdf", "0.25 / 3.14159265", "--rand", "rand", "--samples", "65536"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("drew 5 random numbers"), "{}", stderr(&out));
}

/// A mixture that draws the lobe choice first (uniform sphere with probability 0.3, else a
/// cosine lobe): lobes' probe finds the event draw and gives it u.z, and the check passes.
#[test]
fn the_draw_that_chooses_an_event_is_found_and_the_mixture_passes() {
    let text = format!(
        "{RAND}const PI: f32 = 3.141592653589793;\n\
         fn mix_sample(wi: vec3<f32>) -> vec3<f32> {{\n\
           let e = rand();\n\
           let a = rand();\n\
           let b = rand();\n\
           let phi = 2.0 * PI * b;\n\
           if (e < 0.3) {{\n\
             let z = 1.0 - 2.0 * a;\n\
             let r = sqrt(max(0.0, 1.0 - z * z));\n\
             return vec3<f32>(r * cos(phi), r * sin(phi), z);\n\
           }}\n\
           let z = sqrt(a);\n\
           let r = sqrt(max(0.0, 1.0 - z * z));\n\
           return vec3<f32>(r * cos(phi), r * sin(phi), z);\n\
         }}\n\
         fn mix_pdf(d: vec3<f32>) -> f32 {{ return 0.3 / (4.0 * PI) + 0.7 * max(0.0, d.z) / PI; }}\n"
    );
    let f = plain("mixture.wgsl", &text);
    let out = lobes(&["check", f.to_str().unwrap(), "--sample", "mix_sample(wi)", "--pdf", "mix_pdf(d)", "--rand", "rand", "--samples", "1048576", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let s = report_field(&out, "sampler");
    assert!(s.contains("random draws event,x,y (found by lobes' probe)"), "{s}");
    for (name, passed, summary) in verdicts(&out) {
        assert!(passed, "{name}: {summary}");
    }
    // given as the user says it, the same
    let out = lobes(&["check", f.to_str().unwrap(), "--sample", "mix_sample(wi)", "--pdf", "mix_pdf(d)", "--rand", "rand", "--rand-order", "event,x,y", "--samples", "262144", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(report_field(&out, "sampler").contains("random draws event,x,y (in the order given)"));
}

#[test]
fn a_sample_expression_of_the_wrong_type_is_refused_at_the_glue() {
    let f = plain("wrong_type.wgsl", "fn s(wi: vec3<f32>) -> f32 { return 1.0; }\nfn p(d: vec3<f32>) -> f32 { return 1.0; }\n");
    let out = lobes(&["check", f.to_str().unwrap(), "--sample", "s(wi)", "--pdf", "p(d)"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--sample: 's(wi)' returns f32"), "{}", stderr(&out));
}

/// The same keys in a scene: the WESL package and the naga_oil tree as cases of `lobes run`,
/// paths relative to the scene file.
#[test]
fn a_scene_takes_the_same_keys() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("check-repository-scene");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let fixtures = root().join("tests/fixtures/repository");
    let scene = format!(
        "[defaults]\nsamples = 1_000_000\n\n\
         [[case]]\nname = \"wesl-ggx\"\nparams = [0.5]\nincident_theta = 40\n\n\
         [case.sampler]\nwgsl = [\"{f}/wesl/shaders/sampling/ggx.wesl\"]\nshader_root = [\"{f}/wesl/shaders\"]\n\
         stub = {{ \"package::bindings\" = \"{f}/wesl/stubs/bindings.wesl\" }}\n\
         sample = \"sample_ggx_vndf(wi, p0, rng)\"\nsample_returns = \"half-vector\"\npdf = \"ggx_vndf_pdf(wi, d, p0)\"\nrand = [\"rand_f\"]\n\n\
         [[case]]\nname = \"oil-uniform\"\n\n\
         [case.sampler]\nwgsl = [\"{f}/naga_oil/shaders/sampling/diffuse.wgsl\"]\nshader_root = [\"{f}/naga_oil/shaders\"]\n\
         stub = {{ \"common::view\" = \"{f}/naga_oil/stubs/view.wgsl\" }}\ndefine = {{ UNIFORM_HEMISPHERE = true }}\n\
         sample = \"sample_diffuse(wi)\"\npdf = \"diffuse_pdf(d)\"\neval = \"diffuse_eval(d)\"\nrand = [\"rand\"]\n",
        f = fixtures.display()
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out_dir = dir.join("out");
    let out = lobes(&["run", path.to_str().unwrap(), "--out", out_dir.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // a key of the wrong kind is refused at its line
    std::fs::write(&path, std::fs::read_to_string(&path).unwrap().replace("rand = [\"rand\"]", "rand = \"rand\"")).unwrap();
    let out = lobes(&["run", path.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("sampler.rand must be an array of strings"), "{}", stderr(&out));
}

/// Issue 34 §2: a renderer's resource (a storage buffer, a texture) that the pdf reads is bad
/// input named at its declaration, exit 2 before any GPU work (it was exit 3, "the GPU device was
/// lost": wgpu's "expects a BindGroup to be set at index 2"); declared and never reached, it is
/// no obstacle.
#[test]
fn a_binding_the_sampler_reaches_is_named() {
    let file = "tests/fixtures/bindings/lut_sampler.wgsl";
    for (pdf, name, kind, line) in [("lut_scaled_pdf", "lut", "a storage buffer", 6), ("texture_scaled_pdf", "lut_texture", "a texture", 7)] {
        let out = lobes(&["check", file, "--sample", "uniform_sample", "--pdf", pdf, "--samples", "65536"]);
        assert_eq!(out.status.code(), Some(2), "{pdf}: {}", stderr(&out));
        let e = stderr(&out);
        assert!(e.contains(&format!("{file}:{line}:")) && e.contains(&format!("`{name}` (@group(2) @binding({}), {kind})", line - 6)), "{pdf}: {e}");
        assert!(e.contains("--stub"), "{pdf}: says how to proceed: {e}");
    }
    let out = lobes(&["check", file, "--sample", "uniform_sample", "--pdf", "uniform_pdf", "--samples", "65536"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}
