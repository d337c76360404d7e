//! `lobes wgsl MODULE...`: the embeddable WGSL on stdout, as `lobes::embed` returns it; bad
//! module names are usage errors (exit 2) that list the modules.

use lobes::embed::{self, Module};
use std::process::{Command, Output};

fn lobes(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lobes")).args(args).output().expect("lobes runs")
}

#[test]
fn wgsl_prints_the_prefixed_embed_which_validates() {
    let out = lobes(&["wgsl", "rng", "ggx", "fresnel"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text, embed::wgsl(&[Module::Rng, Module::Ggx, Module::Fresnel]));
    assert!(text.contains("fn lobes_ggx_sample_vndf(") && text.contains("fn lobes_fresnel_schlick(") && text.contains("const LOBES_PI"));
    embed::validate(&(text + "const PI: f32 = 3.0;\nfn stretch() {}\n")).unwrap();
}

#[test]
fn wgsl_naga_oil_prints_composable_modules_with_their_directives() {
    let out = lobes(&["wgsl", "--naga-oil", "ward"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    // one module per file, each after those it imports, as naga_oil takes them
    let mut composer = naga_oil::compose::Composer::default();
    let mut paths = Vec::new();
    for part in text.split("// ==== naga_oil module ").skip(1) {
        let (path, source) = part.split_once(" ====\n").unwrap();
        assert!(source.starts_with(&format!("#define_import_path {path}")), "{source}");
        if let Err(e) = composer.add_composable_module(naga_oil::compose::ComposableModuleDescriptor { source, file_path: path, ..Default::default() }) {
            panic!("{path}: {}", e.emit_to_string(&composer));
        }
        paths.push(path);
    }
    assert_eq!(paths, ["lobes::math", "lobes::reflect", "lobes::ward"]);
    assert!(!text.contains("f32 >") && !text.contains("lobes::math::Real"), "{text}");
    let shader = "#import lobes::ward::ward_sample\n@compute @workgroup_size(1) fn main() { let s = ward_sample(vec2(0.2), vec3(0.0, 0.0, 1.0), vec2(0.5)); }\n";
    if let Err(e) = composer.make_naga_module(naga_oil::compose::NagaModuleDescriptor { source: shader, file_path: "mine.wgsl", ..Default::default() }) {
        panic!("{}", e.emit_to_string(&composer));
    }
}

#[test]
fn an_unknown_module_is_a_usage_error_that_lists_the_modules() {
    let out = lobes(&["wgsl", "ggx", "beckman"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown module 'beckman' (did you mean 'beckmann'?)"), "{err}");
    assert!(err.contains("beckmann, dielectric, discrete, disk_light, fresnel, ggx, light, masking, math, microfacet, rect_light, reflect, rng, sphere_light, triangle_area_light, triangle_light, ward"), "{err}");
    assert_eq!(lobes(&["wgsl"]).status.code(), Some(2), "at least one module");
}

/// `--list` prints every module with its files and its API, each name with its signature and a
/// line on it, and none of its internal helpers.
#[test]
fn list_prints_each_module_with_its_api() {
    let out = lobes(&["wgsl", "--list"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    for m in Module::ALL {
        let at = text.find(&format!("## {}\n", m.name())).unwrap_or_else(|| panic!("no {}:\n{text}", m.name()));
        let section = text[at + 3..].split("\n## ").next().unwrap();
        for f in m.files() {
            assert!(section.contains(&format!("`{f}`")), "{f}");
        }
        for name in m.api() {
            assert!(section.lines().any(|l| l.starts_with("- `") && l.contains(&format!(" {name}")) && l.contains("`: ")), "{}: {name}:\n{section}", m.name());
        }
    }
    assert!(text.contains("- `fn ggx_pdf_vndf(a: vec2<f32>, wi: vec3<f32>, wr: vec3<f32>) -> f32`: The density of ωr under ggx_sample_vndf."), "{text}");
    assert!(!text.contains("ggx_cap_sample"), "a helper is not API");
    assert!(!text.lines().any(|l| l.starts_with("- `") && l.contains("Real")), "signatures are in f32");
    assert_eq!(lobes(&["wgsl", "--list", "ggx"]).status.code(), Some(2), "--list takes no module");
}

/// A fresh folder under the target directory for one test's files.
fn out_dir(name: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn wgsl_dielectric_is_offered_and_validates() {
    let out = lobes(&["wgsl", "dielectric"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("fn lobes_dielectric_ggx_vndf(") && text.contains("fn lobes_dielectric_ggx_vndf_pdf("));
    embed::validate(&text).unwrap();
}

/// `--wesl --out-dir`: one file per module, the package the `wesl` crate (0.4) resolves as
/// a folder `lobes/` of the renderer's own package, and naga validates what it composes.
#[test]
fn wgsl_wesl_out_dir_writes_a_package_the_wesl_crate_compiles() {
    let root = out_dir("wesl_package");
    let dir = root.join("lobes");
    let out = lobes(&["wgsl", "--wesl", "--out-dir", dir.to_str().unwrap(), "ggx", "fresnel", "rng"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut names: Vec<String> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    // a module's API in NAME.wesl, its internal helpers (if any) in NAME/internal.wesl
    assert_eq!(names, ["fresnel", "fresnel.wesl", "ggx", "ggx.wesl", "math.wesl", "microfacet.wesl", "reflect.wesl", "rng.wesl"]);
    assert!(dir.join("ggx/internal.wesl").is_file() && dir.join("fresnel/internal.wesl").is_file());
    std::fs::write(
        root.join("main.wesl"),
        "import package::lobes::ggx::{ggx_sample_vndf, ggx_pdf_vndf};\nimport package::lobes::fresnel::fresnel_schlick;\n\
         import package::lobes::rng::rng_uniforms;\nconst PI: f32 = 3.0;\n@group(0) @binding(0) var<storage, read_write> o: array<f32>;\n\
         @compute @workgroup_size(1) fn main() {\n let u = rng_uniforms(vec2(1u, 2u), vec2(3u, 0u));\n\
         let s = ggx_sample_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), u.xy);\n\
         o[0] = fresnel_schlick(s.wr.z, 0.04) * PI / ggx_pdf_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), s.wr);\n}\n",
    )
    .unwrap();
    let compiled = wesl::Wesl::new(&root).compile(&"package::main".parse().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    embed::validate(&compiled.to_string()).unwrap_or_else(|e| panic!("{e}\n{compiled}"));
    // a helper is not in the module's API: importing it from there fails, naming it
    std::fs::write(root.join("helper.wesl"), "import package::lobes::ggx::ggx_cap_sample;\n@compute @workgroup_size(1) fn main() { let h = ggx_cap_sample(vec2(0.3), vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), 0.5, 0.5, vec2(0.5)); }\n").unwrap();
    let e = wesl::Wesl::new(&root).compile(&"package::helper".parse().unwrap()).map(|c| c.to_string()).unwrap_err().to_string();
    assert!(e.contains("ggx_cap_sample"), "{e}");
    let usage = lobes(&["wgsl", "--wesl", "ggx"]);
    assert_eq!(usage.status.code(), Some(2), "--wesl needs --out-dir");
}

/// Plain `--out-dir`: one file per module; the files do not overlap, so all of them together,
/// in any order, with a renderer's shader, validate; and the discrete module's bindings move.
#[test]
fn wgsl_out_dir_files_combine_and_bindings_move() {
    let dir = out_dir("plain_files");
    let out = lobes(&["wgsl", "--out-dir", dir.to_str().unwrap(), "ggx", "masking", "discrete", "--group", "1", "--binding", "0"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut files: Vec<String> = std::fs::read_dir(&dir).unwrap().map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap()).collect();
    files.sort();
    files.reverse();
    let all = files.concat();
    assert!(all.contains("@group(1) @binding(0) var<storage, read> lobes_discrete_f") && all.contains("@group(1) @binding(1) var<storage, read> lobes_discrete_u"));
    embed::validate(&(all + "@group(0) @binding(3) var<storage, read_write> mine: array<f32>;\n")).unwrap();
    let ggx = std::fs::read_to_string(dir.join("ggx.wgsl")).unwrap();
    assert!(ggx.lines().next().unwrap().contains("needs math.wgsl, microfacet.wgsl, reflect.wgsl"), "{ggx}");
    // two one-piece outputs concatenated are refused by name
    let a = String::from_utf8(lobes(&["wgsl", "ggx"]).stdout).unwrap();
    let b = String::from_utf8(lobes(&["wgsl", "fresnel"]).stdout).unwrap();
    let e = embed::validate(&(a + &b)).unwrap_err();
    assert!(e.message.contains("shaders/math/f32.wgsl is included twice"), "{e}");
    // bindings for modules without resources are a usage error
    let out = lobes(&["wgsl", "ggx", "--binding", "2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("discrete"), "{}", String::from_utf8_lossy(&out.stderr));
}

/// Every built-in light (the light registry) is a module of `lobes wgsl` in each form: plain
/// (prefixed, valid), naga_oil (composable with its import of `lobes::light`), GLSL (naga writes
/// it).
#[test]
fn wgsl_exports_every_light_of_the_registry() {
    use lobes::reference::light::registry::LIGHTS;
    for l in &LIGHTS {
        let name = l.module_name();
        let out = lobes(&["wgsl", name]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8(out.stdout).unwrap();
        let sample = l.sample.split('(').next().unwrap();
        assert!(text.contains(&format!("fn lobes_{sample}(")) && text.contains("struct LobesLightSample"), "{name}");
        embed::validate(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        let oil = String::from_utf8(lobes(&["wgsl", "--naga-oil", name]).stdout).unwrap();
        assert!(oil.contains("#define_import_path lobes::light\n") && oil.contains(&format!("#define_import_path lobes::{name}\n")), "{name}");
        let glsl = lobes(&["wgsl", "--glsl", name]);
        assert!(glsl.status.success() && String::from_utf8_lossy(&glsl.stdout).contains(&format!("lobes_{sample}(")), "{name}: {}", String::from_utf8_lossy(&glsl.stderr));
    }
}
