//! An environment map as renderers sample it: a lat-long `.hdr` texture and the CDF tables built
//! from it on the CPU (`.npy`, examples/envmap/make.py), bound where the sampler's file
//! declares them (`--texture NAME=FILE`, `--buffer NAME=FILE`; issue 33 item 3). The correct
//! sampler passes at two seeds; without the map's sin θ, searching the next row's conditional CDF,
//! or at texel corners it fails by the check that should catch it. A binding left without its
//! file, a file of the wrong kind or type, and a file that is not what its flag reads are exit 2.
//! GPU tests: they need a wgpu adapter (lavapipe in CI) and fail without one.

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");
const DIR: &str = "examples/envmap";
/// ∫ luminance · sin θ_centre over the unit square, as make.py prints it.
const INTEGRAL: &str = "111.694735";

fn lobes(args: &[&str]) -> Output {
    let out = Command::new(LOBES).current_dir(env!("CARGO_MANIFEST_DIR")).args(args).output().expect("run lobes");
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    // the report's table (or the error), not the JSON's arrays
    eprintln!("$ lobes {}\n{}", args.join(" "), text(&out.stderr));
    out
}

/// The binding flags of the map's texture and tables, with `extra` instead where it names one.
fn bindings(extra: &[(&str, String)]) -> Vec<String> {
    let mut out = Vec::new();
    for (flag, name, file) in [("--texture", "env_radiance", "sky.hdr"), ("--buffer", "env_marginal", "marginal.npy"), ("--buffer", "env_conditional", "conditional.npy")] {
        match extra.iter().find(|(n, _)| *n == name) {
            Some((_, replaced)) if replaced.is_empty() => {}
            Some((_, replaced)) => out.extend([flag.to_string(), format!("{name}={replaced}")]),
            None => out.extend([flag.to_string(), format!("{name}={DIR}/{file}")]),
        }
    }
    out
}

/// `lobes check` of the map's `sample` against env_pdf, 2¹⁸ samples, a JSON report.
fn check(sample: &str, seed: &str, extra: &[(&str, String)]) -> Output {
    let file = format!("{DIR}/envmap.wgsl");
    let mut args: Vec<String> = ["check", &file, "--sample", sample, "--pdf", "env_pdf", "--params", INTEGRAL, "--samples", "262144", "--seed", seed, "--json"].map(String::from).to_vec();
    args.extend(bindings(extra));
    lobes(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

fn failed(out: &Output) -> Vec<String> {
    let v: Value = serde_json::from_slice(&out.stdout).expect("a JSON report on stdout");
    v["checks"].as_array().expect("checks").iter().filter(|c| c["passed"] == false).map(|c| c["name"].as_str().unwrap_or("?").to_string()).collect()
}

#[test]
fn the_environment_map_with_its_own_texture_and_tables_passes() {
    assert!(Path::new(env!("CARGO_MANIFEST_DIR")).join(DIR).join("sky.hdr").is_file());
    for seed in ["1", "2"] {
        let out = check("env_sample", seed, &[]);
        assert_eq!(out.status.code(), Some(0), "seed {seed}: {:?}", failed(&out));
    }
}

#[test]
fn a_broken_environment_map_sampler_fails() {
    for (sample, by) in [("env_sample_no_sin", &["pdf_consistency"][..]), ("env_sample_wrong_row", &["jacobian", "chi2"][..]), ("env_sample_corners", &["pdf_consistency", "chi2"][..])] {
        let out = check(sample, "1", &[]);
        assert_eq!(out.status.code(), Some(1), "{sample}");
        let f = failed(&out);
        assert!(by.iter().all(|c| f.contains(&c.to_string())), "{sample}: failed {f:?}, expected {by:?}");
    }
}

#[test]
fn bindings_without_the_right_file_are_exit_2() {
    let npy_of_u32 = std::env::temp_dir().join(format!("lobes-envmap-u32-{}.npy", std::process::id()));
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    let header = "{'descr': '<u4', 'fortran_order': False, 'shape': (2,), }          \n";
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.bytes());
    bytes.extend([0u8; 8]);
    std::fs::write(&npy_of_u32, bytes).unwrap();
    let cases: [(&str, String, &str); 4] = [
        ("env_marginal", String::new(), "`env_marginal` (@group(0) @binding(1), a storage buffer) is a resource of the renderer that the sampler reads, and nothing is bound to it: bind its contents (--texture env_marginal=FILE.hdr"),
        ("env_marginal", npy_of_u32.display().to_string(), "--buffer env_marginal: the file holds u32 and `env_marginal` is an array<f32>"),
        ("env_conditional", format!("{DIR}/sky.hdr"), "not a .npy file"),
        ("env_radiance", format!("{DIR}/missing.hdr"), "--texture env_radiance=examples/envmap/missing.hdr: cannot read the file"),
    ];
    for (name, file, message) in cases {
        let out = check("env_sample", "1", &[(name, file.clone())]);
        assert_eq!(out.status.code(), Some(2), "{name}={file}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(message), "{name}={file}: {stderr}");
    }
    let _ = std::fs::remove_file(&npy_of_u32);
    // a texture bound to a table
    let file = format!("{DIR}/envmap.wgsl");
    let out = lobes(&["check", &file, "--sample", "env_sample", "--pdf", "env_pdf", "--params", INTEGRAL, "--texture", "env_marginal=examples/envmap/sky.hdr", "--texture", "env_radiance=examples/envmap/sky.hdr", "--buffer", "env_conditional=examples/envmap/conditional.npy"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--texture env_marginal: `env_marginal` is not declared as a texture_2d<f32>"));
    // one name twice
    let out = lobes(&["check", &file, "--sample", "env_sample", "--pdf", "env_pdf", "--buffer", "env_marginal=a.npy", "--buffer", "env_marginal=b.npy"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("env_marginal is bound twice"));
}

/// The same map as a case of a scene: `texture` and `buffer` are the flags' keys, paths relative
/// to the scene file.
#[test]
fn a_scene_binds_the_maps_texture_and_tables() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("check-envmap-scene");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let maps = Path::new(env!("CARGO_MANIFEST_DIR")).join(DIR);
    let case = |name: &str, sample: &str| {
        format!(
            "[[case]]\nname = \"{name}\"\nsampler = {{ wgsl = [{wgsl:?}], sample = \"{sample}\", pdf = \"env_pdf\", texture = {{ env_radiance = {hdr:?} }}, buffer = {{ env_marginal = {m:?}, env_conditional = {c:?} }} }}\nparams = [{INTEGRAL}]\nsamples = 262144\n\n",
            wgsl = maps.join("envmap.wgsl"),
            hdr = maps.join("sky.hdr"),
            m = maps.join("marginal.npy"),
            c = maps.join("conditional.npy"),
        )
    };
    let scene = dir.join("envmap.toml");
    std::fs::write(&scene, format!("{}{}", case("env", "env_sample"), case("env-corners", "env_sample_corners"))).unwrap();
    let out_dir = dir.join("out");
    let out = lobes(&["run", scene.to_str().unwrap(), "--out", out_dir.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(1), "one case passes, the other fails");
    let summary: Value = serde_json::from_slice(&out.stdout).expect("a JSON summary");
    let passed = |name: &str| summary["cases"].as_array().unwrap().iter().find(|c| c["case"] == name).unwrap_or_else(|| panic!("{name} in {summary}"))["passed"].clone();
    assert_eq!(passed("env"), Value::Bool(true));
    assert_eq!(passed("env-corners"), Value::Bool(false));
}
