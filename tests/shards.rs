//! Scale-out through the binary: `lobes run --shard I/N` and `lobes merge` give exactly the
//! counts (and verdicts) of the unsharded run; gaps, overlaps and mixed scenes are refused.
//! GPU tests: they need a wgpu adapter (lavapipe in CI) and fail without one.

use serde_json::Value;
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

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))).unwrap()
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
        let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(doc["backend"], "gpu", "the shards must run on the GPU");
    }
    let ranges: Vec<(u64, u64)> = (0..3)
        .map(|i| {
            let s = json(&dir.join(format!("part{i}/beckmann-ndf/shard-{i}-of-3.json")));
            assert_eq!(s["format"], "lobes-shard");
            assert_eq!(s["samples"], 999_999);
            (s["first"].as_u64().unwrap(), s["end"].as_u64().unwrap())
        })
        .collect();
    assert_eq!(ranges, [(0, 333_333), (333_333, 666_666), (666_666, 999_999)]);

    let merged = lobes(&dir, &["merge", "part0", "part1", "part2", "--out", "merged", "--json"]);
    assert_eq!(merged.status.code(), full.status.code(), "same verdicts, same exit code: {}", stderr(&merged));
    for case in ["ggx-vndf", "beckmann-ndf", "alias"] {
        let a = json(&dir.join("full").join(case).join("histogram.json"));
        let b = json(&dir.join("merged").join(case).join("histogram.json"));
        assert_eq!(a["backend"], "gpu");
        for key in ["counts", "invalid", "samples", "seed", "expected", "expected_invalid", "chi2", "per_sample_check", "params", "adapter", "backend", "rows", "cols"] {
            assert_eq!(a[key], b[key], "{case}: '{key}' differs between the unsharded run and the merged shards");
        }
        let total: u64 = b["counts"].as_array().unwrap().iter().flat_map(|r| r.as_array().unwrap()).map(|c| c.as_u64().unwrap()).sum::<u64>()
            + b["invalid"].as_object().unwrap().values().map(|c| c.as_u64().unwrap()).sum::<u64>();
        assert_eq!(total, a["samples"].as_u64().unwrap());
        for png in ["measured.png", "expected.png", "residual.png"] {
            assert!(dir.join("merged").join(case).join(png).is_file(), "{case}/{png}");
        }
        // the weighted case's fixed-point sums add up exactly too
        assert_eq!(a["weighted"].is_null(), case != "beckmann-ndf", "{case}");
        for key in ["sums", "check", "bin_albedo", "bin_max_weight_error", "effects"] {
            assert_eq!(a["weighted"][key], b["weighted"][key], "{case}: weighted '{key}' differs");
        }
    }
    assert!(dir.join("merged/beckmann-ndf/albedo.png").is_file());
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

    let overlap = lobes(&dir, &["merge", "p0", "p1", "p2", "half", "--out", "m"]);
    assert_eq!(overlap.status.code(), Some(2));
    let e = stderr(&overlap);
    assert!(e.contains("overlap") && e.contains("shard-1-of-2.json") && e.contains("15000..30000"), "{e}");

    let mixed = lobes(&dir, &["merge", "p0", "other", "p2", "--out", "m"]);
    assert_eq!(mixed.status.code(), Some(2));
    assert!(stderr(&mixed).contains("different scenes"), "{}", stderr(&mixed));

    let empty = lobes(&dir, &["merge", "nowhere", "--out", "m"]);
    assert_eq!(empty.status.code(), Some(2));

    let bad = lobes(&dir, &["run", "scene.toml", "--shard", "3/3", "--out", "x"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("--shard"), "{}", stderr(&bad));
    assert!(!dir.join("m").exists(), "nothing is written when the shards are refused");

    // the same shard passed twice through two paths is read once
    let twice = lobes(&dir, &["merge", "p0", "p1", "p2", "p1/alias/shard-1-of-3.json", "--out", "ok"]);
    assert!(twice.status.code() != Some(2), "{}", stderr(&twice));
}
