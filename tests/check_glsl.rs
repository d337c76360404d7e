//! `lobes check` of GLSL and SPIR-V samplers (issue 34 §1), in the shapes GLSL path tracers
//! write them (tests/fixtures/repository/glsl): `#include` of a file in another folder (relative to the
//! including file) and of one under `--shader-root`, a `float rand()` that steps a global
//! `uint seed`, call expressions over the GLSL functions' own names. The correct sampler passes,
//! the one whose pdf keeps a sin θ fails the checks that catch it; an error in an included file is
//! reported at that file and line; SPIR-V compiled from the same GLSL is checked by its debug
//! names; `lobes wgsl --glsl` writes GLSL that naga's GLSL front end and glslang compile.
//! GPU tests: they need a wgpu adapter (lavapipe in CI) and fail without one. glslangValidator
//! (Debian's `glslang-tools`, installed by .ci/install) is required, not optional.

use crate::common;
use common::{lobes, root, stderr, verdicts};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GLSL: &str = "tests/fixtures/repository/glsl";





fn failed(out: &Output) -> Vec<String> {
    verdicts(out).into_iter().filter(|(_, p)| !p).map(|(n, _)| n).collect()
}

/// The GGX reflection sampler's command: α = 0.5 at θi 40°, the GLSL functions called by their
/// names, the renderer's `rand()` replaced by lobes' uniforms.
fn ggx_args<'a>(file: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "check",
        file,
        "--sample",
        "SampleGgxReflection(wi, p0)",
        "--pdf",
        "GgxReflectionPdf(wi, d, p0)",
        "--rand",
        "rand",
        "--params",
        "0.5",
        "--incident-theta",
        "40",
        "--samples",
        "262144",
        "--json",
    ];
    a.extend_from_slice(extra);
    a
}

const SHADER_ROOT: [&str; 2] = ["--shader-root", "tests/fixtures/repository/glsl/common"];

#[test]
fn a_glsl_sampler_with_includes_and_a_global_seed_passes() {
    let out = lobes(&ggx_args("tests/fixtures/repository/glsl/shaders/ggx.glsl", &SHADER_ROOT));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v = verdicts(&out);
    assert!(v.len() == 6 && v.iter().all(|(_, p)| *p), "{v:?}");
}

#[test]
fn a_glsl_pdf_missing_the_sin_theta_jacobian_fails() {
    let out = lobes(&ggx_args("tests/fixtures/repository/glsl/shaders/broken_sin_theta.glsl", &SHADER_ROOT));
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let f = failed(&out);
    // the sampler reports the same wrong pdf: consistency holds, the map's density does not
    assert!(f.contains(&"jacobian".to_string()) && f.contains(&"normalization".to_string()) && !f.contains(&"pdf_consistency".to_string()), "{f:?}");
}

/// An include found neither beside the including file nor under a root: exit 2 at its line,
/// naming the paths searched and the flag that adds a folder.
#[test]
fn an_include_that_no_root_holds_is_named_at_its_line() {
    let out = lobes(&ggx_args("tests/fixtures/repository/glsl/shaders/ggx.glsl", &[]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    let line = std::fs::read_to_string(root().join(GLSL).join("shaders/ggx.glsl")).unwrap().lines().position(|l| l.contains("#include \"constants.glsl\"")).unwrap() + 1;
    assert!(e.contains(&format!("shaders/ggx.glsl:{line}:")) && e.contains("#include \"constants.glsl\": no such file") && e.contains("--shader-root"), "{e}");
}

/// A copy of the fixture tree in a fresh folder, with `edit` applied to one file.
fn copy_tree(name: &str, file: &str, edit: impl Fn(&str) -> String) -> PathBuf {
    common::edited_copy(&format!("check-glsl-{name}"), &root().join(GLSL), file, edit)
}

/// A type error in a file the sampler includes (from another folder) is reported at that
/// file's own line, after the includes: not at a line of the expanded text.
#[test]
fn an_error_in_an_included_file_is_at_that_file_and_line() {
    let dir = copy_tree("included-error", "common/random.glsl", |t| t.replace("return float(w >> 8u) / 16777216.0;", "return float(w >> 8u) / SCALE;"));
    let random = dir.join("common/random.glsl");
    let line = std::fs::read_to_string(&random).unwrap().lines().position(|l| l.contains("/ SCALE;")).unwrap() + 1;
    let sampler = dir.join("shaders/ggx.glsl");
    let root_dir = dir.join("common");
    let out = lobes(&ggx_args(sampler.to_str().unwrap(), &["--shader-root", root_dir.to_str().unwrap()]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(e.contains(&format!("common/random.glsl:{line}:")), "not at random.glsl:{line}: {e}");
    assert!(e.contains("return float(w >> 8u) / SCALE;") && e.contains("SCALE"), "the line as the file has it: {e}");
}

/// glslangValidator, which these tests need (Debian's `glslang-tools`, .ci/install).
fn glslang() -> &'static str {
    let ok = Command::new("glslangValidator").arg("--version").output().is_ok_and(|o| o.status.success());
    assert!(ok, "glslangValidator is not installed: these tests need Debian's package glslang-tools (apt-get install glslang-tools; .ci/install installs it)");
    "glslangValidator"
}

/// The sampler with a compute entry point that calls it, for a compiler that needs one.
fn with_main(file: &str, out: &Path) -> PathBuf {
    let text = std::fs::read_to_string(root().join(file)).unwrap();
    let comp = out.with_extension("comp");
    std::fs::write(&comp, format!("{text}\nlayout(local_size_x = 1) in;\nlayout(std430, binding = 0) buffer Out {{ vec4 o; }};\nvoid main() {{ o = SampleGgxReflection(vec3(0.0, 0.0, 1.0), 0.5) + vec4(GgxReflectionPdf(vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), 0.5)); }}\n")).unwrap();
    comp
}

/// SPIR-V as glslang compiles a GLSL renderer's shader (every parameter passed as a pointer,
/// functions named `SampleGgxReflection(vf3;f1;`), checked by the functions' debug names: the
/// correct sampler passes, the one without the sin θ Jacobian fails as its GLSL does.
#[test]
fn spirv_from_glslang_is_checked_by_the_functions_debug_names() {
    let tool = glslang();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("check-glsl-spirv");
    std::fs::create_dir_all(&dir).unwrap();
    for (file, code, fails) in [("tests/fixtures/repository/glsl/shaders/ggx.glsl", 0, false), ("tests/fixtures/repository/glsl/shaders/broken_sin_theta.glsl", 1, true)] {
        let spv = dir.join(format!("{}.spv", Path::new(file).file_stem().unwrap().to_str().unwrap()));
        let comp = with_main(file, &spv);
        let compiled = Command::new(tool).args(["-V", "-Itests/fixtures/repository/glsl/shaders", "-Itests/fixtures/repository/glsl/common", comp.to_str().unwrap(), "-o", spv.to_str().unwrap()]).current_dir(root()).output().unwrap();
        assert!(compiled.status.success(), "{}", String::from_utf8_lossy(&compiled.stdout));
        let out = lobes(&ggx_args(spv.to_str().unwrap(), &[]));
        assert_eq!(out.status.code(), Some(code), "{}", stderr(&out));
        let f = failed(&out);
        assert_eq!(f.contains(&"jacobian".to_string()), fails, "{f:?}");
    }
}

/// SPIR-V written by naga's own SPIR-V back end from the GLSL (no external tool): the same
/// verdict.
#[test]
fn spirv_from_naga_passes() {
    let read = |f: &str| std::fs::read_to_string(root().join(GLSL).join(f)).unwrap();
    let sampler: String = read("shaders/ggx.glsl").lines().filter(|l| !l.starts_with("#include")).map(|l| format!("{l}\n")).collect();
    let sampler = sampler.replacen("#extension GL_GOOGLE_include_directive : require\n", &format!("{}{}", read("common/random.glsl"), read("common/constants.glsl")), 1);
    let text = format!("{sampler}\nvoid main() {{}}\n");
    let module = naga::front::glsl::Frontend::default().parse(&naga::front::glsl::Options::from(naga::ShaderStage::Compute), &text).unwrap_or_else(|e| panic!("{e:?}"));
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default()).validate(&module).unwrap();
    let options = naga::back::spv::Options { flags: naga::back::spv::WriterFlags::DEBUG, ..Default::default() };
    let words = naga::back::spv::write_vec(&module, &info, &options, None).unwrap();
    let spv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("check-glsl-naga.spv");
    std::fs::write(&spv, words.iter().flat_map(|w| w.to_le_bytes()).collect::<Vec<u8>>()).unwrap();
    let out = lobes(&ggx_args(spv.to_str().unwrap(), &[]));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(verdicts(&out).iter().all(|(_, p)| *p));
}

/// `lobes wgsl --glsl`: GLSL 450 that naga's GLSL front end and glslang both compile, holding
/// lobes' functions under their names.
#[test]
fn lobes_wgsl_glsl_compiles_in_naga_and_in_glslang() {
    let tool = glslang();
    let out = lobes(&["wgsl", "ggx", "beckmann", "ward", "dielectric", "discrete", "--glsl"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let glsl = String::from_utf8(out.stdout).unwrap();
    let shader = format!("#version 450\n{glsl}\nlayout(local_size_x = 1) in;\nvoid main() {{}}\n");
    let module = naga::front::glsl::Frontend::default().parse(&naga::front::glsl::Options::from(naga::ShaderStage::Compute), &shader).unwrap_or_else(|e| panic!("{e:?}\n{shader}"));
    for f in ["lobes_ggx_d", "lobes_beckmann_d", "lobes_ward_sample"] {
        assert!(module.functions.iter().any(|(_, x)| x.name.as_deref() == Some(f)), "{f}");
    }
    let file = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lobes-wgsl-glsl.comp");
    std::fs::write(&file, &shader).unwrap();
    let compiled = Command::new(tool).args(["-V", file.to_str().unwrap(), "-o"]).arg(file.with_extension("spv")).output().unwrap();
    assert!(compiled.status.success(), "glslang: {}", String::from_utf8_lossy(&compiled.stdout));
}

// --- out and inout parameters (issue 34 §1): tests/fixtures/repository/glsl/pathtracer, a GLSL
// path tracer's sampling file with its helpers in ../include: Heitz's (2018) GGX VNDF sampler,
// the reflected direction's pdf returned through `out float pdf`, the renderer's global-seed
// rand(), and a BSDF state passed `inout`.

const PATHTRACER: &str = "tests/fixtures/repository/glsl/pathtracer/shaders/sampling.glsl";

/// The VNDF sampler's command at α = 0.5, θi 40°, with `sample` as --sample.
fn vndf_args<'a>(file: &'a str, sample: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec!["check", file, "--sample", sample, "--pdf", "GgxVndfPdf(wi, d, p0)", "--params", "0.5", "--incident-theta", "40", "--samples", "262144", "--json"];
    a.extend_from_slice(extra);
    a
}

/// The three ways a GLSL path tracer hands back its pdf: an `out float` with the uniforms given
/// (`vec4(SampleGgx(wi, p0, u.xy, pdf), pdf)`: `pdf` is a variable lobes declares), the same
/// with the renderer's `rand()`, and an `inout` state struct set up by a statement before the
/// call. Each passes every check.
#[test]
fn a_glsl_sampler_returning_its_pdf_through_out_and_inout_parameters_passes() {
    let ways: [(&str, &[&str]); 3] = [
        ("vec4(SampleGgx(wi, p0, u.xy, pdf), pdf)", &[]),
        ("vec4(SampleGgxRand(wi, p0, pdf), pdf)", &["--rand", "rand"]),
        ("s.roughness = p0; SampleBsdf(s, wi); vec4(s.L, s.pdf)", &["--rand", "rand"]),
    ];
    for (sample, extra) in ways {
        let out = lobes(&vndf_args(PATHTRACER, sample, extra));
        assert_eq!(out.status.code(), Some(0), "{sample}: {}", stderr(&out));
        let v = verdicts(&out);
        assert!(v.len() == 6 && v.iter().all(|(_, p)| *p), "{sample}: {v:?}");
    }
}

/// The out pdf is the one judged: SampleGgx's `pdf` written without Smith's G1(V) (the density
/// of h over 4 V·h of the other GGX sampler) while the pdf function keeps it fails
/// pdf_consistency; the sampler itself is unchanged, so the Jacobian of its map holds.
#[test]
fn a_wrong_pdf_through_an_out_parameter_fails_pdf_consistency() {
    let dir = copy_tree("out-pdf", "pathtracer/shaders/sampling.glsl", |t| t.replacen("pdf = SmithG1(V, a, a) * GgxD(H, a, a) / (4.0 * V.z);", "pdf = GgxD(H, a, a) * H.z / (4.0 * dot(V, H));", 1));
    let file = dir.join("pathtracer/shaders/sampling.glsl");
    let out = lobes(&vndf_args(file.to_str().unwrap(), "vec4(SampleGgx(wi, p0, u.xy, pdf), pdf)", &[]));
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let f = failed(&out);
    assert!(f.contains(&"pdf_consistency".to_string()) && !f.contains(&"normalization".to_string()), "{f:?}");
}

/// The VNDF with Heitz's blend s = (1 + Vh.z) / 2 taken as 1/2 (the lower half of the disk
/// squeezed as for normal incidence): the directions no longer follow the pdf, which fails the
/// Jacobian and χ², by the out parameter and by the inout state alike.
#[test]
fn a_vndf_sampler_with_a_wrong_disk_blend_fails() {
    let dir = copy_tree("vndf-blend", "pathtracer/shaders/sampling.glsl", |t| t.replacen("float s = 0.5 * (1.0 + Vh.z);", "float s = 0.5;", 1));
    let file = dir.join("pathtracer/shaders/sampling.glsl");
    for (sample, extra) in [("vec4(SampleGgx(wi, p0, u.xy, pdf), pdf)", &[][..]), ("s.roughness = p0; SampleBsdf(s, wi); vec4(s.L, s.pdf)", &["--rand", "rand"][..])] {
        let out = lobes(&vndf_args(file.to_str().unwrap(), sample, extra));
        assert_eq!(out.status.code(), Some(1), "{sample}: {}", stderr(&out));
        let f = failed(&out);
        assert!(f.contains(&"jacobian".to_string()) && f.contains(&"chi2".to_string()), "{sample}: {f:?}");
    }
}

/// SPIR-V compiled by glslang from the path tracer's file: every parameter is a pointer there,
/// the out one included; a call naming a variable (`pdf`) calls the module's function itself
/// with pointers, and the verdicts are those of the GLSL: the correct file passes, the one
/// with the wrong out pdf fails pdf_consistency.
#[test]
fn spirv_with_out_parameters_is_checked_by_naming_a_variable() {
    let tool = glslang();
    let good = root().join(GLSL);
    let bad = copy_tree("out-pdf-spirv", "pathtracer/shaders/sampling.glsl", |t| t.replacen("pdf = SmithG1(V, a, a) * GgxD(H, a, a) / (4.0 * V.z);", "pdf = GgxD(H, a, a) * H.z / (4.0 * dot(V, H));", 1));
    for (tree, code) in [(good, 0), (bad, 1)] {
        let shaders = tree.join("pathtracer/shaders");
        let main = "\nlayout(local_size_x = 1) in;\nlayout(std430, binding = 0) buffer Out { vec4 o; };\nvoid main() { float pdf; BsdfState s; s.roughness = 0.5; SampleBsdf(s, vec3(0.0, 0.0, 1.0)); o = vec4(SampleGgx(vec3(0.0, 0.0, 1.0), 0.5, vec2(0.5), pdf), pdf + GgxVndfPdf(vec3(0.0, 0.0, 1.0), s.L, 0.5)); }\n";
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("check-glsl-out-spirv-{code}"));
        std::fs::create_dir_all(&dir).unwrap();
        // the includes (../include/…) found under the shaders' folder, as glslang's -I gives
        let comp = dir.join("sampling.comp");
        std::fs::write(&comp, std::fs::read_to_string(shaders.join("sampling.glsl")).unwrap() + main).unwrap();
        let spv = dir.join("sampling.spv");
        let compiled = Command::new(tool).arg("-V").arg(format!("-I{}", shaders.display())).args([comp.to_str().unwrap(), "-o", spv.to_str().unwrap()]).output().unwrap();
        assert!(compiled.status.success(), "{}", String::from_utf8_lossy(&compiled.stdout));
        let out = lobes(&vndf_args(spv.to_str().unwrap(), "vec4(SampleGgx(wi, p0, u.xy, pdf), pdf)", &[]));
        assert_eq!(out.status.code(), Some(code), "{}", stderr(&out));
        assert_eq!(failed(&out).contains(&"pdf_consistency".to_string()), code == 1, "{:?}", failed(&out));
    }
}

/// A `switch` whose cases end in `return` (naga's GLSL front end marks them as falling through,
/// which its WGSL writer refused as an internal error, exit 3) is checked; a case that does fall
/// through into the next with statements of its own is exit 2 at the `switch`'s line, saying
/// what to write instead.
#[test]
fn switch_cases_ending_in_return_pass_and_a_real_fall_through_is_named() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("check-glsl-switch");
    std::fs::create_dir_all(&dir).unwrap();
    let cosine = "vec3 cosdir(vec2 u) { float r = sqrt(u.x); float phi = 6.2831853 * u.y; return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x))); }\nfloat cospdf(vec3 L) { return L.z > 0.0 ? L.z / 3.14159265 : 0.0; }\n";
    let returns = format!("#version 450\n{cosine}vec3 s(vec2 u, int k) {{\n    switch (k) {{\n        case 0: return cosdir(u);\n        default: return vec3(0.0, 0.0, 1.0);\n    }}\n}}\n");
    let falls = format!("#version 450\n{cosine}vec3 s(vec2 u, int k) {{\n    vec3 d = vec3(0.0);\n    switch (k) {{\n        case 0: d = cosdir(u);\n        case 1: d.z += 0.0; break;\n        default: d = vec3(0.0, 0.0, 1.0);\n    }}\n    return d;\n}}\n");
    for (name, text, code) in [("returns.glsl", returns, 0), ("falls.glsl", falls, 2)] {
        let file = dir.join(name);
        std::fs::write(&file, &text).unwrap();
        let out = lobes(&["check", file.to_str().unwrap(), "--sample", "s(u.xy, 0)", "--pdf", "cospdf(d)", "--samples", "65536", "--json"]);
        assert_eq!(out.status.code(), Some(code), "{name}: {}", stderr(&out));
        if code == 0 {
            assert!(verdicts(&out).iter().all(|(_, p)| *p), "{:?}", verdicts(&out));
            continue;
        }
        let line = text.lines().position(|l| l.contains("switch (k)")).unwrap() + 1;
        let e = stderr(&out);
        assert!(e.contains(&format!("falls.glsl:{line}:5:")) && e.contains("in `s`, a `switch` case falls through into the next one") && e.contains("with `break` or `return`"), "{e}");
    }
}

/// One name passed to out parameters of two types is exit 2 naming both types.
#[test]
fn one_variable_at_out_parameters_of_two_types_is_refused() {
    let out = lobes(&vndf_args(PATHTRACER, "vec4(SampleGgx(wi, p0, u.xy, x), x); SampleBsdf(x, wi); vec4(x.L, 1.0)", &[]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(e.contains("the variable `x` is passed to an out/inout parameter of type f32 and to one of type BsdfState"), "{e}");
}

/// An OpenGL renderer's loose uniforms (the fixture's include/uniforms.glsl, outside Vulkan):
/// the sampler above passes with them declared (the three ways of the test before). One that
/// the sampler reads is 0 here, since no glUniform sets it: exit 2 at its declaration, before
/// any GPU work, unless the call expression sets it; an OpenGL sampler2D, which naga cannot
/// take, is left out, and a function that uses it is exit 2 naming the declaration.
#[test]
fn opengl_uniforms_are_named_where_the_sampler_reads_them() {
    let reads = copy_tree("uniform-read", "pathtracer/shaders/sampling.glsl", |t| t.replacen("float r1 = rand();", "float r1 = rand() * float(numOfLights);", 1));
    let file = reads.join("pathtracer/shaders/sampling.glsl");
    let out = lobes(&vndf_args(file.to_str().unwrap(), "vec4(SampleGgxRand(wi, p0, pdf), pdf)", &["--rand", "rand"]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(e.contains("include/uniforms.glsl:6: the sampler reads the OpenGL uniform `numOfLights`") && e.contains("--sample 'numOfLights = 1; …'"), "{e}");
    let texture = copy_tree("uniform-sampler", "pathtracer/shaders/sampling.glsl", |t| format!("{t}\nvec3 Sky(vec2 uv) {{ return texture(envMapTex, uv).rgb; }}\n"));
    let file = texture.join("pathtracer/shaders/sampling.glsl");
    let out = lobes(&vndf_args(file.to_str().unwrap(), "vec4(SampleGgx(wi, p0, u.xy, pdf), pdf)", &[]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    let line = std::fs::read_to_string(&file).unwrap().lines().position(|l| l.starts_with("vec3 Sky")).unwrap() + 1;
    assert!(e.contains(&format!("sampling.glsl:{line}:")) && e.contains("`envMapTex` is an OpenGL uniform sampler or image (") && e.contains("include/uniforms.glsl:8)"), "{e}");
    assert!(e.contains("behind an #ifdef that --define leaves off)"), "the advice names the flag: {e}");
}
