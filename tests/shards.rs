//! Scale-out through the binary: `lobes run --shard I/N` and `lobes merge` give exactly the
//! counts (and verdicts) of the unsharded run; gaps, overlaps and mixed scenes are refused.
//! GPU tests: they need a wgpu adapter (lavapipe in CI) and fail without one.

use lobes::report::output::{HistogramFile, RunSummary, ShardSummary};
use lobes::run::shard::ShardFile;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

fn require_gpu() {
    if let Err(e) = lobes::engine::gpu::GpuEngine::open() {
        panic!("GPU tests need a wgpu adapter: {e}");
    }
}

/// A fresh, empty folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("shards-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn lobes(dir: &Path, args: &[&str]) -> Output {
    let out = Command::new(LOBES).current_dir(dir).args(args).output().expect("run lobes");
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    println!("$ lobes {}\n{}{}", args.join(" "), text(&out.stdout), text(&out.stderr));
    out
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn histogram(path: &Path) -> HistogramFile {
    HistogramFile::read(path).unwrap()
}

const SCENE: &str = r#"
[defaults]
samples = 1_000_000
bins = [16, 32]
seed = 11

[[case]]
name = "ggx-vndf"
lobe = "ggx"
method = "vndf"
alpha = 0.3
incident_theta = 40.0

[[case]]
name = "beckmann-ndf"
lobe = "beckmann"
alpha = 0.5
incident_theta = 70.0
samples = 999_999
fresnel = "dielectric"
eta = 1.5
masking = "height-correlated"

[[case]]
name = "alias"
lobe = "discrete"
method = "alias"
weights = [15, 5, 5, 25, 5, 10, 15, 5, 5, 10]
"#;

#[test]
fn three_shards_merge_to_exactly_the_unsharded_run() {
    require_gpu();
    let dir = scratch("identical");
    std::fs::write(dir.join("scene.toml"), SCENE).unwrap();
    let full = lobes(&dir, &["run", "scene.toml", "--out", "full", "--json"]);
    for i in 0..3 {
        // each shard into its own folder, as separate machines would write them
        let o = lobes(&dir, &["run", "scene.toml", "--shard", &format!("{i}/3"), "--out", &format!("part{i}"), "--json"]);
        assert!(o.status.success(), "shard {i}: {}", stderr(&o));
        let doc: ShardSummary = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(doc.backend, "gpu", "the shards must run on the GPU");
    }
    let ranges: Vec<(u64, u64)> = (0..3)
        .map(|i| {
            let s = ShardFile::read(&dir.join(format!("part{i}/beckmann-ndf/shard-{i}-of-3.json"))).unwrap();
            assert_eq!(s.format, "lobes-shard");
            assert_eq!(s.samples, 999_999);
            (s.first, s.end)
        })
        .collect();
    assert_eq!(ranges, [(0, 333_333), (333_333, 666_666), (666_666, 999_999)]);

    let merged = lobes(&dir, &["merge", "part0", "part1", "part2", "--out", "merged", "--json"]);
    assert_eq!(merged.status.code(), full.status.code(), "same verdicts, same exit code: {}", stderr(&merged));
    let (full_summary, merged_summary): (RunSummary, RunSummary) =
        (serde_json::from_slice(&full.stdout).unwrap(), serde_json::from_slice(&merged.stdout).unwrap());
    for (a, b) in full_summary.cases.iter().zip(&merged_summary.cases) {
        assert_eq!((&a.case, a.passed), (&b.case, b.passed), "the same verdict per case");
    }
    for case in ["ggx-vndf", "beckmann-ndf", "alias"] {
        let a = histogram(&dir.join("full").join(case).join("histogram.json"));
        let b = histogram(&dir.join("merged").join(case).join("histogram.json"));
        assert_eq!(a.backend, "gpu");
        let what = |key: &str| format!("{case}: '{key}' differs between the unsharded run and the merged shards");
        assert_eq!(a.counts, b.counts, "{}", what("counts"));
        assert_eq!(a.invalid, b.invalid, "{}", what("invalid"));
        assert_eq!((a.samples, a.seed), (b.samples, b.seed), "{}", what("samples, seed"));
        assert_eq!(a.expected, b.expected, "{}", what("expected"));
        assert_eq!(a.expected_invalid, b.expected_invalid, "{}", what("expected_invalid"));
        assert_eq!(a.chi2, b.chi2, "{}", what("chi2"));
        // and so is the family of tests, every level's figures (lobes::stats::family)
        if case != "alias" {
            assert!(a.chi2.family.len() > 4 && a.chi2.family_p_value.is_some(), "{case}: {:?}", a.chi2.family);
        }
        assert_eq!(a.per_sample_check, b.per_sample_check, "{}", what("per_sample_check"));
        assert_eq!(a.description, b.description, "{}", what("params, rows, cols"));
        assert_eq!((&a.adapter, &a.backend), (&b.adapter, &b.backend), "{}", what("adapter, backend"));
        let total: u64 = b.counts.iter().flatten().sum::<u64>() + <[u64; lobes::reference::Invalid::COUNT]>::from(b.invalid.expect("a lobe case counts invalid samples by reason")).iter().sum::<u64>();
        assert_eq!(total, a.samples);
        let pictures: &[&str] = if case == "alias" { &["bars.png"] } else { &["measured.png", "expected.png", "residual.png", "marginals.png"] };
        for png in pictures {
            assert!(dir.join("merged").join(case).join(png).is_file(), "{case}/{png}");
        }
        // the weighted case's fixed-point sums add up exactly too
        assert_eq!(a.weighted.is_none(), case != "beckmann-ndf", "{case}");
        if let (Some(a), Some(b)) = (&a.weighted, &b.weighted) {
            assert_eq!(a.sums, b.sums, "{case}: weighted 'sums' differs");
            assert_eq!(a.check, b.check, "{case}: weighted 'check' differs");
            assert_eq!(a.bin_albedo, b.bin_albedo, "{case}: weighted 'bin_albedo' differs");
            assert_eq!(a.bin_max_weight_error, b.bin_max_weight_error, "{case}: weighted 'bin_max_weight_error' differs");
            assert_eq!(a.effects, b.effects, "{case}: weighted 'effects' differs");
        }
    }
    assert!(dir.join("merged/beckmann-ndf/albedo.png").is_file());
    assert!(dir.join("merged/index.html").is_file() && dir.join("full/index.html").is_file());
    // the same table as `lobes run`
    let text = lobes(&dir, &["merge", "part0", "part1", "part2", "--out", "merged-again"]);
    let table = String::from_utf8_lossy(&text.stdout);
    for head in ["case", "samples", "chi2", "dof", "p-value", "verdict", "max angle err"] {
        assert!(table.contains(head), "{table}");
    }
}

#[test]
fn merge_refuses_gaps_overlaps_and_mixed_scenes() {
    require_gpu();
    let dir = scratch("refused");
    let small = SCENE.replace("1_000_000", "30_000").replace("999_999", "29_999");
    std::fs::write(dir.join("scene.toml"), &small).unwrap();
    std::fs::write(dir.join("other.toml"), small.replace("seed = 11", "seed = 12")).unwrap();
    for i in 0..3 {
        assert!(lobes(&dir, &["run", "scene.toml", "--shard", &format!("{i}/3"), "--out", &format!("p{i}")]).status.success());
    }
    assert!(lobes(&dir, &["run", "scene.toml", "--shard", "1/2", "--out", "half"]).status.success());
    assert!(lobes(&dir, &["run", "other.toml", "--shard", "1/3", "--out", "other"]).status.success());

    let missing = lobes(&dir, &["merge", "p0", "p2", "--out", "m"]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(stderr(&missing).contains("samples 10000..20000 are missing"), "{}", stderr(&missing));
    // the command line names the command that writes the missing shard
    assert!(stderr(&missing).contains("`lobes run SCENE --shard I/N`"), "{}", stderr(&missing));

    let overlap = lobes(&dir, &["merge", "p0", "p1", "p2", "half", "--out", "m"]);
    assert_eq!(overlap.status.code(), Some(2));
    let e = stderr(&overlap);
    assert!(e.contains("overlap") && e.contains("shard-1-of-2.json") && e.contains("15000..30000"), "{e}");

    let mixed = lobes(&dir, &["merge", "p0", "other", "p2", "--out", "m"]);
    assert_eq!(mixed.status.code(), Some(2));
    assert!(stderr(&mixed).contains("different scenes"), "{}", stderr(&mixed));

    let empty = lobes(&dir, &["merge", "nowhere", "--out", "m"]);
    assert_eq!(empty.status.code(), Some(2));
    std::fs::create_dir_all(dir.join("no-shards")).unwrap();
    let none = lobes(&dir, &["merge", "no-shards", "--out", "m"]);
    assert_eq!(none.status.code(), Some(2));
    assert!(stderr(&none).contains("no-shards: no shard files") && stderr(&none).contains("--shard I/N --out no-shards`"), "{}", stderr(&none));

    let bad = lobes(&dir, &["run", "scene.toml", "--shard", "3/3", "--out", "x"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("--shard"), "{}", stderr(&bad));
    assert!(!dir.join("m").exists(), "nothing is written when the shards are refused");

    // the same shard passed twice through two paths is read once
    let twice = lobes(&dir, &["merge", "p0", "p1", "p2", "p1/alias/shard-1-of-3.json", "--out", "ok"]);
    assert!(twice.status.code() != Some(2), "{}", stderr(&twice));
}

/// `lobes merge` judges a case as `lobes run` does: a weighted case whose χ² test passes but
/// whose albedo check fails is a failed case (exit 1, `passed: false`). The shards run on the
/// CPU engine; one shard's weighted sums are doubled, which doubles half the albedo estimate
/// and leaves the counts alone.
#[test]
fn a_merged_case_that_fails_the_albedo_check_fails() {
    let dir = scratch("albedo-fails");
    let scene = "[[case]]\nname = \"w\"\nlobe = \"ggx\"\nalpha = 0.3\nincident_theta = 20.0\nsamples = 20_000\nbins = [8, 16]\nfresnel = \"schlick\"\nf0 = 0.5\nmasking = \"separable\"\n";
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    for i in 0..2 {
        assert!(lobes(&dir, &["run", "scene.toml", "--cpu", "--shard", &format!("{i}/2"), "--out", "parts"]).status.success());
    }
    let honest = lobes(&dir, &["merge", "parts", "--out", "honest", "--json"]);
    assert_eq!(honest.status.code(), Some(0), "{}", stderr(&honest));

    let path = dir.join("parts/w/shard-1-of-2.json");
    let mut shard = ShardFile::read(&path).unwrap();
    let sums = shard.weighted.as_mut().unwrap();
    sums.bins.iter_mut().for_each(|b| *b *= 2);
    // an edit on purpose: sealed with the checksum of the edited sums (an unsealed edit is
    // refused, tests/fault_injection.rs)
    std::fs::write(&path, serde_json::to_string(&shard.sealed()).unwrap()).unwrap();

    let merged = lobes(&dir, &["merge", "parts", "--out", "merged", "--json"]);
    assert_eq!(merged.status.code(), Some(1), "{}", stderr(&merged));
    assert!(stderr(&merged).contains("1 of 1 cases failed the χ² test or the albedo checks"), "{}", stderr(&merged));
    let summary: RunSummary = serde_json::from_slice(&merged.stdout).unwrap();
    assert_eq!(summary.failed, 1);
    let case = &summary.cases[0];
    assert!(!case.passed, "the summary reports the failed albedo check");
    let measured = case.measured.as_ref().unwrap();
    assert!(!measured.albedo.unwrap().passed);
    assert!(measured.p_value >= summary.per_case_significance, "the χ² test alone passes: p = {}", measured.p_value);
    let h = histogram(&dir.join("merged/w/histogram.json"));
    assert!(h.chi2.passed && !h.weighted.unwrap().check.passed);
    let table = lobes(&dir, &["merge", "parts", "--out", "merged"]);
    assert!(String::from_utf8_lossy(&table.stdout).lines().any(|l| l.starts_with("w ") && l.contains("FAIL")));
}

/// Issue 24 item 14: honest shards from the GPU and from the CPU engine merge, with a warning
/// that names both backends and a file of each (it said "more than one adapter" and named one).
#[test]
fn shards_of_two_backends_are_named_in_the_warning() {
    require_gpu();
    let dir = scratch("two-backends");
    let scene = "[[case]]\nname = \"g\"\nlobe = \"ggx\"\nalpha = 0.3\nincident_theta = 30.0\nsamples = 40_000\nbins = [8, 16]\n";
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    assert!(lobes(&dir, &["run", "scene.toml", "--shard", "0/2", "--out", "gpu"]).status.success());
    assert!(lobes(&dir, &["run", "scene.toml", "--cpu", "--shard", "1/2", "--out", "cpu"]).status.success());
    let merged = lobes(&dir, &["merge", "gpu", "cpu", "--out", "m"]);
    assert!(merged.status.code() != Some(2), "{}", stderr(&merged));
    let e = stderr(&merged);
    assert!(e.contains("lobes: warning: the shards come from more than one backend: 'cpu' in 1 file (such as cpu/g/shard-1-of-2.json), 'gpu' in 1 file (such as gpu/g/shard-0-of-2.json)"), "{e}");
    assert!(e.contains("more than one adapter: 'cpu (f64 reference"), "{e}");
}
