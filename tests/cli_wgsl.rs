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
    assert_eq!(paths, ["lobes::math", "lobes::reflect", "lobes::ward", "lobes::ward_eval"]);
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
    assert!(err.contains("rng, reflect, microfacet, ward, ggx, beckmann, fresnel, masking, discrete"), "{err}");
    assert_eq!(lobes(&["wgsl"]).status.code(), Some(2), "at least one module");
}
