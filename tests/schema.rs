//! The JSON Schemas in `docs/schema/` are those generated from the output structs, and every
//! JSON file lobes writes validates against its schema: `histogram.json` of a run and of a
//! merge, its `timing.json`, shard files, and the `--json` summaries of `lobes run`, `lobes run --shard` and
//! `lobes merge`. The files read back through the same structs that wrote them.
//! GPU test: it needs a wgpu adapter (lavapipe in CI) and fails without one.
//!
//! After a change to an output struct, regenerate the schemas with
//! `LOBES_WRITE_SCHEMA=1 cargo test --release --test integration schema::`.

use lobes::report::output::{CaseSummary, HistogramFile, JsonStyle, RunSummary, SUMMARY_VERSION, ShardSummary, TimingFile};
use lobes::report::schema::{schemas, to_text};
use lobes::run::shard::ShardFile;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

fn docs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/schema")
}

#[test]
fn published_schemas_are_up_to_date() {
    let write = std::env::var_os("LOBES_WRITE_SCHEMA").is_some();
    for (name, schema) in schemas() {
        let path = docs().join(name);
        let text = to_text(&schema);
        if write {
            std::fs::create_dir_all(docs()).unwrap();
            std::fs::write(&path, &text).unwrap();
        }
        let stored = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            stored == text,
            "{} is not the schema generated from the structs; regenerate it with \
             `LOBES_WRITE_SCHEMA=1 cargo test --release --test integration schema::`",
            path.display()
        );
    }
}

/// Validates `instance` against the published schema `name`; the errors name the JSON paths.
fn validate(name: &str, instance: &Value, what: &str) {
    let schema: Value = serde_json::from_str(&std::fs::read_to_string(docs().join(name)).unwrap()).unwrap();
    let validator = jsonschema::validator_for(&schema).unwrap_or_else(|e| panic!("{name} is not a valid schema: {e}"));
    let errors: Vec<String> = validator.iter_errors(instance).map(|e| format!("{}: {e}", e.instance_path())).collect();
    assert!(errors.is_empty(), "{what} does not validate against {name}:\n{}", errors.join("\n"));
}

fn file(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))).unwrap()
}

fn lobes(dir: &Path, args: &[&str]) -> Value {
    let out = Command::new(LOBES).current_dir(dir).args(args).output().expect("run lobes");
    assert!(out.status.success(), "lobes {}: {}", args.join(" "), String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

/// A lobe case, a weighted lobe case and a discrete case: every optional section appears.
const SCENE: &str = r#"
[defaults]
samples = 40_000
bins = [8, 16]
seed = 3

[[case]]
name = "ggx"
lobe = "ggx"
method = "vndf"
alpha = 0.4
incident_theta = 30.0

[[case]]
name = "weighted"
lobe = "beckmann"
alpha = 0.5
incident_theta = 60.0
fresnel = "schlick"
f0 = 0.04
masking = "height-correlated"

[[case]]
name = "alias"
lobe = "discrete"
method = "alias"
weights = [1, 2, 3, 4]
"#;

#[test]
fn every_file_lobes_writes_validates_against_its_schema() {
    if let Err(e) = lobes::engine::gpu::GpuEngine::open() {
        panic!("GPU tests need a wgpu adapter: {e}");
    }
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("schema-outputs");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.toml"), SCENE).unwrap();
    let cases = ["ggx", "weighted", "alias"];

    let run = lobes(&dir, &["run", "scene.toml", "--out", "full", "--json"]);
    validate("run-summary.schema.json", &run, "the summary of lobes run");
    // OUT/summary.json is the same summary
    assert_eq!(file(&dir.join("full/summary.json")), run, "summary.json and --json agree");
    let summary: RunSummary = serde_json::from_value(run).unwrap();
    assert_eq!(summary.format_version, SUMMARY_VERSION);
    assert_eq!(summary.cases.iter().map(|c| c.case.as_str()).collect::<Vec<_>>(), cases);

    for i in 0..2 {
        let shard = lobes(&dir, &["run", "scene.toml", "--shard", &format!("{i}/2"), "--out", "parts", "--json"]);
        validate("shard-summary.schema.json", &shard, "the summary of lobes run --shard");
        let shard: ShardSummary = serde_json::from_value(shard).unwrap();
        for c in &shard.cases {
            let path = dir.join(&c.file);
            validate("shard.schema.json", &file(&path), &path.display().to_string());
            let back = ShardFile::read(&path).unwrap();
            assert_eq!((back.first, back.end), (c.first, c.end));
        }
    }
    let merge = lobes(&dir, &["merge", "parts", "--out", "merged", "--json"]);
    validate("run-summary.schema.json", &merge, "the summary of lobes merge");
    assert_eq!(file(&dir.join("merged/summary.json")), merge, "summary.json and --json agree");
    let merged: RunSummary = serde_json::from_value(merge).unwrap();
    assert_eq!(merged.shard_files, Some(6));

    for out in ["full", "merged"] {
        for case in cases {
            let path = dir.join(out).join(case).join("histogram.json");
            validate("histogram.schema.json", &file(&path), &path.display().to_string());
            let h = HistogramFile::read(&path).unwrap();
            // what the struct reads is all the file holds: written again, it is the same text
            assert!(JsonStyle::Compact.to_bytes(&h).unwrap() == std::fs::read(&path).unwrap(), "{}", path.display());
            let timing = path.with_file_name("timing.json");
            validate("timing.schema.json", &file(&timing), &timing.display().to_string());
            let t: TimingFile = serde_json::from_value(file(&timing)).unwrap();
            assert_eq!((t.histogram.is_some(), t.weighted.is_some(), t.quadrature_seconds.is_some()), (true, case == "weighted", case != "alias"));
            assert_eq!(h.weighted.is_some(), case == "weighted");
            assert_eq!(h.per_sample_check.is_some(), case != "alias", "{}", path.display());
        }
    }

    // a scene of users' WGSL samplers (sphere and plane; with and without an eval), with fewer samples
    let user_scene = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/user-samplers.toml"))
        .unwrap()
        .replace("samples = 1_000_000", "samples = 50_000")
        .replace("../examples", &Path::new(env!("CARGO_MANIFEST_DIR")).join("examples").display().to_string());
    std::fs::write(dir.join("user.toml"), user_scene).unwrap();
    let run = lobes(&dir, &["run", "user.toml", "--out", "user", "--json"]);
    validate("run-summary.schema.json", &run, "the summary of lobes run on users' samplers");
    for case in ["ggx-vndf-theta45", "piecewise-2d"] {
        let path = dir.join("user").join(case).join("histogram.json");
        validate("histogram.schema.json", &file(&path), &path.display().to_string());
        let h = HistogramFile::read(&path).unwrap();
        assert!(JsonStyle::Compact.to_bytes(&h).unwrap() == std::fs::read(&path).unwrap(), "{}", path.display());
        assert!(h.user_sampler.is_some() && h.invalid.is_some_and(|i| i.refracted_near_side == 0) && h.expected_invalid.is_none());
        let timing = path.with_file_name("timing.json");
        validate("timing.schema.json", &file(&timing), &timing.display().to_string());
        assert!(serde_json::from_value::<TimingFile>(file(&timing)).unwrap().checks_wall_seconds.is_some());
    }

    // the schemas are not vacuous: a damaged file does not validate
    let schema: Value = serde_json::from_str(&std::fs::read_to_string(docs().join("histogram.schema.json")).unwrap()).unwrap();
    let validator = jsonschema::validator_for(&schema).unwrap();
    let mut damaged = file(&dir.join("full/ggx/histogram.json"));
    damaged["counts"][0][0] = (-1).into();
    assert!(!validator.is_valid(&damaged));
    damaged.as_object_mut().unwrap().remove("chi2");
    assert!(validator.iter_errors(&damaged).any(|e| e.to_string().contains("\"chi2\" is a required property")));

    // a case that could not run: the error row of a summary
    let mut with_error = summary.clone();
    let scene = lobes::scene::Scene::parse("scene.toml", SCENE).unwrap();
    with_error.cases.push(CaseSummary::error(&lobes::scene::Entry::Lobe(&scene.cases[0]), "the GPU device was lost".into()));
    with_error.errors = 1;
    let v = serde_json::to_value(&with_error).unwrap();
    validate("run-summary.schema.json", &v, "a summary with an error row");
    assert_eq!(serde_json::from_value::<RunSummary>(v).unwrap(), with_error);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs lobes in `dir`, expecting the exit status `code`; its stdout as JSON.
fn lobes_exit(dir: &Path, args: &[&str], code: i32) -> Value {
    let out = Command::new(LOBES).current_dir(dir).args(args).output().expect("run lobes");
    assert_eq!(out.status.code(), Some(code), "lobes {}: {}", args.join(" "), String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

/// A uniform sampler of the sphere whose reported pdf is NaN above z = 0.9 and negative below
/// z = −0.9, with a pdf function negative there too: every figure that can go wrong does.
const BROKEN: &str = "fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(0.0, 1.0 - z * z));
    let d = vec3<f32>(r * cos(6.2831853 * u.y), r * sin(6.2831853 * u.y), z);
    var pdf = 0.0795775;
    if (z > 0.9) { pdf = sqrt(-z); }
    if (z < -0.9) { pdf = -1.0; }
    return vec4<f32>(d, pdf);
}
fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    if (d.z < -0.9) { return -1.0; }
    if (d.z > 0.95) { return sqrt(-d.z); }
    return 0.0795775;
}
fn e(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    return 0.5 * p(wi, d, params);
}
";

/// `lobes check --json`, its `report.json` and `lobes check --power --json` validate against
/// their schemas, for a passing sampler on the sphere, a failing one whose figures hold NaN
/// sources, and a warp on the plane; the report reads back through `lobes::check::Report`.
#[test]
fn check_reports_validate_against_their_schema() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("schema-check");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("broken.wgsl"), BROKEN).unwrap();
    let samplers = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/samplers");
    let hg = samplers.join("henyey_greenstein.wgsl");
    let plane = samplers.join("piecewise_2d.wgsl");
    let hg_args = [hg.to_str().unwrap(), "--sample", "hg_sample", "--pdf", "hg_pdf", "--eval", "hg_eval", "--params", "0.6"];
    let runs: [(Vec<&str>, i32); 3] = [
        ([&hg_args[..], &["--samples", "65536", "--bins", "16,32", "--out", "hg", "--json"]].concat(), 0),
        (vec!["broken.wgsl", "--sample", "s", "--pdf", "p", "--eval", "e", "--samples", "65536", "--bins", "16,32", "--out", "broken", "--json"], 1),
        (
            vec![plane.to_str().unwrap(), "--sample", "env_sample", "--pdf", "env_pdf", "--domain", "plane", "--bounds", "0,0,1,1", "--samples", "65536"]
                .into_iter()
                .chain(["--bins", "16,16", "--out", "plane", "--json"])
                .collect(),
            0,
        ),
    ];
    for (args, code) in runs {
        let mut full = vec!["check"];
        full.extend(&args);
        let printed = lobes_exit(&dir, &full, code);
        validate("check-report.schema.json", &printed, &format!("lobes {}", full.join(" ")));
        let out = dir.join(args[args.len() - 2]);
        let written = file(&out.join("report.json"));
        validate("check-report.schema.json", &written, &out.join("report.json").display().to_string());
        let report: lobes::check::Report = serde_json::from_value(written).unwrap();
        assert_eq!(report.format_version, lobes::check::report::REPORT_VERSION);
        assert_eq!(report.passed, code == 0);
        let from_stdout: lobes::check::Report = serde_json::from_value(printed).unwrap();
        assert!(report == from_stdout, "report.json holds what --json prints");
        for png in ["measured.png", "expected.png", "residual.png"] {
            let img = image::open(out.join(png)).unwrap_or_else(|e| panic!("{}: {e}", out.join(png).display()));
            assert!(img.width() > 300 && img.height() > 200, "{png}: {}×{}", img.width(), img.height());
        }
    }

    // the schema holds the contract: each check names its figures, and a check's figures must
    // be those of its name
    let schema: Value = serde_json::from_str(&std::fs::read_to_string(docs().join("check-report.schema.json")).unwrap()).unwrap();
    let validator = jsonschema::validator_for(&schema).unwrap();
    let mut damaged = file(&dir.join("hg/report.json"));
    assert_eq!(damaged["checks"][4]["name"], "chi2");
    damaged["checks"][4]["name"] = "normalization".into();
    assert!(!validator.is_valid(&damaged), "chi2's figures under the name normalization");
    let mut damaged = file(&dir.join("hg/report.json"));
    damaged.as_object_mut().unwrap().remove("format_version");
    assert!(!validator.is_valid(&damaged));

    let mut power = vec!["check"];
    power.extend(&hg_args);
    power.extend(["--samples", "131072", "--bins", "16,32", "--power", "--out", "power", "--json"]);
    let sweep = lobes_exit(&dir, &power, 0);
    validate("check-power.schema.json", &sweep, "lobes check --power --json");
    validate("check-power.schema.json", &file(&dir.join("power/power.json")), "power.json");
    let sweep: lobes::check::power::PowerSweep = serde_json::from_value(sweep).unwrap();
    assert_eq!(sweep.points.iter().map(|p| p.samples).collect::<Vec<_>>(), [65536, 131072]);
    assert!(sweep.passed && sweep.caught.is_none());
    let _ = std::fs::remove_dir_all(&dir);
}
