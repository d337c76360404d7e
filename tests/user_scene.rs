//! A user's WGSL sampler as a case of `lobes run`: the shipped scene of example samplers passes,
//! a broken sampler fails the run with exit 1 naming the checks it failed, and bad scenes are
//! refused with exit 2 at the scene's line before any case runs.
//! GPU tests: they need a wgpu adapter (lavapipe in CI) and fail without one.

use lobes::report::output::{HistogramFile, RunSummary};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("user-scene-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The scene `text` written to `dir/name`, beside a copy of the repository's file `from`
/// named `to`.
fn scene_beside(dir: &Path, (from, to): (&str, &str), name: &str, text: &str) -> PathBuf {
    std::fs::copy(root().join(from), dir.join(to)).unwrap();
    let scene = dir.join(name);
    std::fs::write(&scene, text).unwrap();
    scene
}

fn lobes(args: &[&str]) -> Output {
    let out = Command::new(LOBES).current_dir(root()).args(args).output().expect("run lobes");
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    println!("$ lobes {}\n{}{}", args.join(" "), text(&out.stdout), text(&out.stderr));
    out
}

fn summary(out: &Output) -> RunSummary {
    serde_json::from_slice(&out.stdout).expect("one JSON summary on stdout")
}

/// The shipped scene: GGX visible normals swept over θi, Henyey–Greenstein swept over g, a
/// piecewise-constant 2-D distribution on the plane; every case passes every check.
#[test]
fn the_example_scene_of_user_samplers_passes() {
    let dir = scratch("example");
    let out = lobes(&["run", "scenes/user-samplers.toml", "--out", dir.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let s = summary(&out);
    let names: Vec<&str> = s.cases.iter().map(|c| c.case.as_str()).collect();
    assert_eq!(
        names,
        ["ggx-vndf-theta0", "ggx-vndf-theta45", "ggx-vndf-theta80", "henyey-greenstein-params0.7", "henyey-greenstein-params-0.3", "piecewise-2d"]
    );
    // Šidák over the six cases: 1 − (1 − 0.01)^(1/6)
    assert!((s.per_case_significance - 1.673_653_852e-3).abs() < 1e-9, "{}", s.per_case_significance);
    for c in &s.cases {
        assert!(c.passed, "{c:?}");
        assert_eq!(c.failed_checks.as_deref(), Some(&[][..]));
    }
    // Every case has its folder: heat maps and a histogram.json judged at the per-case level.
    for c in &s.cases {
        let folder = dir.join(&c.case);
        for png in ["measured.png", "expected.png", "residual.png"] {
            assert!(folder.join(png).is_file(), "{}/{png}", folder.display());
        }
        let h = HistogramFile::read(&folder.join("histogram.json")).unwrap();
        assert_eq!((h.description.lobe.as_str(), h.samples, h.seed), ("user", 1_000_000, 7));
        assert_eq!(h.chi2.significance, s.per_case_significance);
        let record = h.user_sampler.expect("a user sampler's checks");
        assert!(record.passed && record.checks.iter().any(|c| c.name() == "jacobian"));
    }
    // Independent values on the plane (piecewise_2d.wgsl's table): its second row of cells,
    // y in [0.25, 0.5), has weight 0, and its first row holds 1+2+3+4+4+3+2+1 = 20 of Σw = 60.
    let h = HistogramFile::read(&dir.join("piecewise-2d/histogram.json")).unwrap();
    assert_eq!((h.description.rows, h.description.cols), (64, 64));
    assert_eq!(h.counts[16..32].iter().flatten().sum::<u64>(), 0);
    let first = h.counts[..16].iter().flatten().sum::<u64>() as f64 / 1e6;
    let p = 20.0 / 60.0;
    assert!((first - p).abs() < 4.0 * (p * (1.0 - p) / 1e6).sqrt(), "{first}");
    // On the sphere the incident direction is recorded: θi = 45° in the x-z plane.
    let h = HistogramFile::read(&dir.join("ggx-vndf-theta45/histogram.json")).unwrap();
    let wi = h.incident.unwrap();
    assert!((wi[0] - 0.5f64.sqrt()).abs() < 1e-12 && wi[1].abs() < 1e-12 && (wi[2] - 0.5f64.sqrt()).abs() < 1e-12, "{wi:?}");
}

/// A scene with a lobe case and a user's sampler without its reflection Jacobian: the lobe
/// passes, the broken sampler fails (the Jacobian and χ² checks), the run exits 1.
#[test]
fn a_broken_user_sampler_fails_the_run() {
    let dir = scratch("broken");
    let scene = dir.join("broken.toml");
    let samplers = root().join("examples/samplers");
    std::fs::write(
        &scene,
        format!(
            r#"
[defaults]
samples = 200_000
bins = [16, 32]

[[case]]
name = "ggx-lobe"
lobe = "ggx"
method = "vndf"
alpha = 0.3
incident_theta = 30

[[case]]
name = "no-jacobian"
sampler = {{ wgsl = ["{0}/ggx_vndf.wgsl", "{0}/broken_no_jacobian.wgsl"], sample = "broken_sample_no_jacobian", pdf = "broken_pdf_no_jacobian" }}
params = [0.3, 0.3]
incident_theta = 30
"#,
            samplers.display()
        ),
    )
    .unwrap();
    let out_dir = dir.join("out");
    let out = lobes(&["run", scene.to_str().unwrap(), "--out", out_dir.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let s = summary(&out);
    assert_eq!((s.failed, s.errors), (1, 0));
    assert!(s.cases[0].passed && s.cases[0].case == "ggx-lobe");
    let broken = &s.cases[1];
    assert!(!broken.passed);
    let failed = broken.failed_checks.clone().unwrap();
    assert!(failed.iter().any(|c| c == "jacobian") && failed.iter().any(|c| c == "chi2"), "{failed:?}");
    assert!(out_dir.join("no-jacobian/histogram.json").is_file());
    // summary.json is the --json summary; junit.xml reports the failure with its reason
    let written: RunSummary = serde_json::from_slice(&std::fs::read(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(written, s);
    let reason = broken.failure.clone().unwrap();
    assert!(reason.contains("jacobian: ") && reason.contains("chi2: "), "{reason}");
    let junit = quick_junit::Report::deserialize_from_str(&std::fs::read_to_string(out_dir.join("junit.xml")).unwrap()).unwrap();
    let suite = &junit.test_suites[0];
    assert_eq!((suite.tests, suite.failures, suite.errors), (2, 1, 0));
    match &suite.test_cases[1].status {
        quick_junit::TestCaseStatus::NonSuccess { kind: quick_junit::NonSuccessKind::Failure, message, .. } => {
            assert_eq!(message.as_ref().map(|m| m.as_str()), Some(reason.as_str()))
        }
        other => panic!("no-jacobian is not a failure in junit.xml: {other:?}"),
    }
    // The table names the failed checks.
    let out = lobes(&["run", scene.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("FAIL (jacobian"), "{table}");
}

/// Issue 24 item 1 as a scene case: a sampler that rejects every sample (ggx_vndf.wgsl with its
/// guard inverted, its pdf 0 everywhere) passed with χ² = 0 on 0 dof; it fails, saying no sample
/// was valid, and the run exits 1.
#[test]
fn a_user_sampler_that_rejects_every_sample_fails_the_run() {
    let dir = scratch("rejects-all");
    let text = std::fs::read_to_string(root().join("examples/samplers/ggx_vndf.wgsl")).unwrap().replace("wi.z <= 0.0", "wi.z > 0.0");
    std::fs::write(dir.join("inverted.wgsl"), text).unwrap();
    let scene = dir.join("s.toml");
    std::fs::write(
        &scene,
        "[[case]]\nname = \"inverted\"\nsampler = { wgsl = [\"inverted.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\" }\nparams = [0.3, 0.3]\nsamples = 262144\n",
    )
    .unwrap();
    let out = lobes(&["run", scene.to_str().unwrap(), "--out", dir.join("out").to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let case = &summary(&out).cases[0];
    assert!(!case.passed && case.failed_checks.as_ref().unwrap().iter().any(|c| c == "chi2"), "{case:?}");
    let reason = case.failure.clone().unwrap();
    assert!(reason.contains("no sample was valid"), "{reason}");
}

/// A case with `budget = 4`: pilot checks pick its count (issue 25 item 5, as `lobes check
/// --budget`); the case runs at that count, which fits the budget by the fitted model, and
/// histogram.json says how it was picked.
#[test]
fn a_budget_picks_the_cases_sample_count() {
    let dir = scratch("budget");
    let scene = scene_beside(&dir, ("examples/samplers/ggx_vndf.wgsl", "ggx.wgsl"), "s.toml", "[[case]]\nname = \"timed\"\nsampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\" }\nparams = [0.3, 0.3]\nbudget = 4\n");
    let out_dir = dir.join("out");
    let out = lobes(&["run", scene.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("‡ the count the case's budget picked"), "{table}");
    let h = HistogramFile::read(&out_dir.join("timed/histogram.json")).unwrap();
    let pick = h.user_sampler.as_ref().unwrap().budget.clone().expect("user_sampler.budget");
    assert_eq!(h.samples, pick.samples, "the case ran at the picked count");
    assert!(table.lines().any(|l| l.starts_with("timed") && l.contains(&format!("{}‡", pick.samples))), "{table}");
    assert!(pick.samples >= 1 << 16 && pick.samples.is_multiple_of(1 << 16), "{pick:?}");
    assert!(pick.budget_seconds == 4.0 && pick.profile.is_none());
    assert!(pick.predicted_seconds <= 4.0 && pick.fixed_seconds + pick.seconds_per_sample * pick.samples as f64 <= 4.0 + 1e-9, "{pick:?}");
    // the next count up would not fit: the pick is the largest
    let next = pick.samples + (1 << 16);
    assert!(pick.fixed_seconds + pick.seconds_per_sample * next as f64 > 4.0 || pick.samples == lobes::engine::job::MAX_SAMPLES, "{pick:?}");
    // `lobes run --samples N` sets every case's count: the budget is not used
    let out = lobes(&["run", scene.to_str().unwrap(), "--out", out_dir.to_str().unwrap(), "--samples", "131072", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let h = HistogramFile::read(&out_dir.join("timed/histogram.json")).unwrap();
    assert_eq!(h.samples, 131072);
    assert!(h.user_sampler.unwrap().budget.is_none());
}

/// lobes' built-in lights as cases (`sampler = { light = "NAME" }`, scenes/lights.toml): every
/// case passes; a misspelt light is exit 2 naming the lights, and a light with WGSL keys too is
/// exit 2 naming the key.
#[test]
fn built_in_light_cases_pass_and_bad_ones_are_refused() {
    let dir = scratch("lights");
    let out = lobes(&["run", "scenes/lights.toml", "--samples", "200000", "--out", dir.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let s = summary(&out);
    let names: Vec<&str> = s.cases.iter().map(|c| c.case.as_str()).collect();
    assert_eq!(names, ["sphere-tiny", "rect-horizon", "triangle-overhead", "disk"]);
    assert!(s.cases.iter().all(|c| c.passed), "{:?}", s.cases);
    let cases: [(&str, &[&str]); 3] = [
        ("sampler = { light = \"spere\" }\nparams = [0, 0, 1, 0.1]\n", &["bad.toml:6:", "unknown light 'spere' (did you mean 'sphere'?)", "sphere, disk, triangle, triangle-area, rect"]),
        ("sampler = { light = \"disk\", pdf = \"p\" }\n", &["bad.toml:6:", "sampler.pdf does not apply to a built-in light", "params[0] = (centre x, y, z, radius)"]),
        ("sampler = { light = 3 }\n", &["bad.toml:6:", "sampler.light must be a string", "sphere, disk"]),
    ];
    for (lines, want) in cases {
        let scene = bad_scene(&dir, lines);
        let out = lobes(&["run", scene.to_str().unwrap(), "--out", dir.join("out").to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{lines}: {stderr}");
        for w in want {
            assert!(stderr.contains(w), "{lines}: want {w:?} in: {stderr}");
        }
    }
}

/// Writes a scene whose case uses ggx_vndf.wgsl through a path relative to the scene file.
fn bad_scene(dir: &Path, case_lines: &str) -> PathBuf {
    scene_beside(dir, ("examples/samplers/ggx_vndf.wgsl", "ggx.wgsl"), "bad.toml", &format!("[defaults]\nsamples = 1000\n\n[[case]]\nname = \"mine\"\n{case_lines}"))
}

/// Bad user-sampler cases: exit 2, the message at the scene's file:line, and no case runs.
#[test]
fn bad_user_sampler_cases_are_refused_at_the_scene_line() {
    let dir = scratch("bad");
    let good = "sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\" }\n";
    let conventions = |c: &str| format!("sampler = {{ wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\", {c} }}\n");
    let plane = "domain = \"plane\"\nbounds = [0, 0, 1, 1]\n";
    let cases: [(&str, &[&str]); 25] = [
        // so do the conventions, keyed in the sampler table, and the incidence they allow
        (&format!("{}{plane}", conventions("measure = \"projected\"")), &["bad.toml:6:", "sampler.measure: only for directions (a point of the plane has no normal)"]),
        (&format!("{}{plane}", conventions("frame = \"y-up\"")), &["bad.toml:6:", "sampler.frame: only for directions"]),
        (&format!("{}{plane}", conventions("sample_returns = \"half-vector\"")), &["bad.toml:6:", "sampler.sample_returns: a half vector reflects wi into a direction"]),
        (&format!("{}incident_theta = [30, 95]\n", conventions("reflection_only = true")), &["bad.toml:7:", "incident_theta: 95° is not above the surface, and the sampler is declared reflection-only"]),
        // a resource's or package's error names its scene key, not lobes check's flag
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\", package = { super = \"lib\" } }\n", &["bad.toml:6:", "sampler.package 'super': a package name is an identifier"]),
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\", filter = { s = \"bilinear\" } }\n", &["bad.toml:6:", "sampler.filter 's=bilinear': the filter 'bilinear' is unknown"]),
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\", texture = { s = \"a.hdr\" }, filter = { s = \"linear\" } }\n", &["bad.toml:6:", "sampler.filter 's=linear': s is bound twice"]),
        // so does a composition's setting the front ends cannot use
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\", shader_root = [\"no_such_dir\"] }\n", &["bad.toml:6:", "sampler.shader_root: ", "no_such_dir is not a folder"]),
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\", define = { \"TWO WORDS\" = true } }\n", &["bad.toml:6:", "sampler.define: 'TWO WORDS' is no shader def"]),
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_pdf\", rand_order = \"x,y\" }\n", &["bad.toml:6:", "sampler.rand_order: an order for the draws of the named random functions"]),
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"vec3<f32>(ggx_pdf(wi, d, params))\" }\n", &["bad.toml:6:", "sampler.pdf: 'vec3<f32>(ggx_pdf(wi, d, params))' returns vec3<f32>; expected f32"]),
        ("sampler = \"ggx.wgsl\"\n", &["bad.toml:6:", "expected a sampler table { wgsl = [\"file.wgsl\"]"]),
        ("sampler = { wgsl = [\"missing.wgsl\"], sample = \"s\", pdf = \"p\" }\n", &["bad.toml:6:", "missing.wgsl", "cannot read"]),
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"nope\" }\n", &["bad.toml:6:", "no pdf function `nope`", "expected `fn nope(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32`"]),
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\", pdf = \"ggx_d\" }\n", &["bad.toml:6:", "ggx.wgsl:", "wrong signature"]),
        ("sampler = { wgsl = [\"ggx.wgsl\"], sample = \"ggx_sample\" }\n", &["bad.toml:6:", "no pdf"]),
        (&format!("{good}domain = \"plane\"\n"), &["bad.toml:7:", "needs bounds"]),
        (&format!("{good}bounds = [0, 0, 1, 1]\n"), &["bad.toml:7:", "only applies to domain = \"plane\""]),
        (&format!("{good}alpha = 0.3\n"), &["bad.toml:7:", "alpha does not apply to a user sampler"]),
        (&format!("{good}params = [[0.3, 0.3], [0.1, \"x\"]]\n"), &["bad.toml:7:", "params must be a number"]),
        ("lobe = \"ggx\"\nalpha = 0.3\nparams = [0.3]\n", &["bad.toml:8:", "params only applies to a user sampler"]),
        (&format!("{good}samples = 4096\nbudget = 5\n"), &["bad.toml:7:", "samples and budget both set the case's sample count"]),
        (&format!("{good}budget = \"nightly\"\n"), &["bad.toml:7:", "budget = \"nightly\" is not a budget", "\"ci\" (20 s)"]),
        (&format!("{good}budget = 0\n"), &["bad.toml:7:", "budget = 0 is not a budget", "a number > 0"]),
        ("lobe = \"ggx\"\nalpha = 0.3\nbudget = 5\n", &["bad.toml:8:", "budget only applies to a user sampler"]),
    ];
    for (lines, want) in cases {
        let scene = bad_scene(&dir, lines);
        let out_dir = dir.join("out");
        let out = lobes(&["run", scene.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{lines}: {stderr}");
        for w in want {
            assert!(stderr.contains(w), "{lines}: want {w:?} in: {stderr}");
        }
        assert!(!out_dir.join("mine").exists(), "{lines}: a case ran");
        assert!(!["--sampler", "--texture", "--package", "--shader-root", "--define", "--rand", "--sample", "--pdf", "--eval", "--measure", "--frame", "--incident", "--reflection-only", "--domain", "--bounds"].iter().any(|f| stderr.contains(f)), "{lines}: a scene's error names a flag: {stderr}");
    }
    // A user's sampler needs the GPU, and runs whole: --cpu and --shard refuse it.
    let scene = bad_scene(&dir, good);
    for flags in [&["--cpu"][..], &["--shard", "0/2"]] {
        let mut args = vec!["run", scene.to_str().unwrap(), "--out", dir.to_str().unwrap()];
        args.extend_from_slice(flags);
        let out = lobes(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {stderr}");
        assert!(stderr.contains("bad.toml:4:1: case 'mine'"), "{flags:?}: {stderr}");
    }
}

/// The advice in a check's error names settings as the scene writes them: a case whose sampler
/// reads a texture that nothing binds says `sampler.texture NAME=FILE.hdr` (and `sampler.stub`),
/// where `lobes check` says `--texture NAME=FILE.hdr`.
#[test]
fn advice_names_the_scene_keys() {
    let dir = scratch("advice");
    let scene = scene_beside(&dir, ("examples/envmap/envmap.wgsl", "envmap.wgsl"), "s.toml", "[defaults]\nsamples = 65536\n\n[[case]]\nname = \"env\"\nsampler = { wgsl = [\"envmap.wgsl\"], sample = \"env_sample\", pdf = \"env_pdf\" }\nparams = [1]\n");
    let out = lobes(&["run", scene.to_str().unwrap(), "--out", dir.join("out").to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("nothing is bound to it") && stderr.contains("(sampler.texture env_radiance=FILE.hdr for a texture_2d<f32>") && stderr.contains("(sampler.stub MODULE=FILE"), "{stderr}");
    assert!(!stderr.contains("--texture") && !stderr.contains("--stub"), "{stderr}");
    let check = lobes(&["check", "examples/envmap/envmap.wgsl", "--sample", "env_sample", "--pdf", "env_pdf", "--params", "1"]);
    assert_eq!(check.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&check.stderr).contains("help: bind its contents (--texture env_radiance=FILE.hdr"));
}

/// `lobes shader` shows the modules of users' cases too (nothing in a scene is left out): two
/// modules per sampler (lobes check's passes, and the histogram's counting kernel drawing it),
/// shared by the cases of its sweep, each holding the user's own functions, valid WGSL.
#[test]
fn lobes_shader_shows_users_samplers() {
    let out = lobes(&["shader", "scenes/user-samplers.toml", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let modules = v["modules"].as_array().unwrap();
    assert_eq!(modules.len(), 6, "ggx (3 angles), Henyey–Greenstein (2 params), piecewise 2-D: passes and histogram each");
    assert_eq!(modules[0]["cases"].as_array().unwrap().len(), 3);
    let functions = ["fn ggx_sample(", "fn ggx_sample(", "fn hg_sample(", "fn hg_sample(", "fn env_sample(", "fn env_sample("];
    for (k, (m, function)) in modules.iter().zip(functions).enumerate() {
        let entry = if k % 2 == 0 { "fn lobes_probe(" } else { "fn lobes_sample_histogram(" };
        assert!(m["source"].as_str().unwrap().contains(entry), "module {k}: {entry}");
        let source = m["source"].as_str().unwrap();
        assert!(source.contains(function), "{function}");
        let module = naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all()).validate(&module).unwrap();
    }
}
