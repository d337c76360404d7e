//! Outputs for batch use: two runs of a scene write byte-identical `histogram.json` files (the
//! times are in `timing.json`); `histogram.json` is one compact line unless `--pretty`; and
//! `counts.npy` and `expected.npy` hold the counts and expected counts of `histogram.json`,
//! rows × cols, as NumPy arrays.
//! GPU test: it needs a wgpu adapter (lavapipe in CI) and fails without one.

use lobes::report::npy;
use lobes::report::output::HistogramFile;
use std::path::Path;
use std::process::Command;

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

/// Two lobe cases (a sweep over methods), a weighted case (its fixed-point sums) and a discrete case.
const SCENE: &str = r#"
[defaults]
samples = 30_000
bins = [8, 16]
seed = 5
[[case]]
name = "ggx"
lobe = "ggx"
method = ["ndf", "vndf"]
alpha = 0.4
incident_theta = 30.0
[[case]]
name = "masked"
lobe = "beckmann"
alpha = 0.5
masking = "g1"
[[case]]
name = "alias"
lobe = "discrete"
method = "alias"
weights = [1, 2, 3, 4, 0]
"#;

fn run(dir: &Path, args: &[&str]) {
    let out = Command::new(LOBES).current_dir(dir).args(args).output().expect("run lobes");
    assert!(out.status.success(), "lobes {}: {}", args.join(" "), String::from_utf8_lossy(&out.stderr));
}

#[test]
fn reruns_write_identical_histograms_and_npy_arrays_hold_its_counts() {
    if let Err(e) = lobes::engine::gpu::GpuEngine::open() {
        panic!("GPU tests need a wgpu adapter: {e}");
    }
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("batch-outputs");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.toml"), SCENE).unwrap();
    run(&dir, &["run", "scene.toml", "--out", "a"]);
    run(&dir, &["run", "scene.toml", "--out", "b"]);
    run(&dir, &["run", "scene.toml", "--out", "pretty", "--pretty"]);
    for case in ["ggx-ndf", "ggx-vndf", "masked", "alias"] {
        let file = |out: &str, name: &str| std::fs::read(dir.join(out).join(case).join(name)).unwrap();
        let (a, b) = (file("a", "histogram.json"), file("b", "histogram.json"));
        assert!(a == b, "{case}: two runs wrote different histogram.json files");
        // compact: one line; --pretty: indented, the same JSON value
        assert_eq!(a.iter().filter(|&&c| c == b'\n').count(), 1, "{case}: compact histogram.json is one line");
        let pretty = file("pretty", "histogram.json");
        assert!(pretty.iter().filter(|&&c| c == b'\n').count() > 50, "{case}: --pretty indents");
        let value = |bytes: &[u8]| serde_json::from_slice::<serde_json::Value>(bytes).unwrap();
        assert_eq!(value(&a), value(&pretty), "{case}");
        assert!(value(&a).get("timing").is_none(), "{case}: the times are in timing.json");
        let timing = value(&file("a", "timing.json"));
        assert!(timing["histogram"]["histogram_wall_seconds"].as_f64().unwrap() > 0.0, "{case}: {timing}");

        // counts.npy and expected.npy: rows × cols, u64 and f64, the values of histogram.json
        let h = HistogramFile::read(&dir.join("a").join(case).join("histogram.json")).unwrap();
        let (rows, cols) = (h.counts.len(), h.counts[0].len());
        assert_eq!((rows, cols), if case == "alias" { (1, 5) } else { (8, 16) });
        let (shape, counts) = npy::decode::<u64>(&file("a", "counts.npy")).unwrap();
        assert_eq!((shape, counts), (vec![rows, cols], h.counts.concat()), "{case}: counts.npy");
        let (shape, expected) = npy::decode::<f64>(&file("a", "expected.npy")).unwrap();
        assert_eq!((shape, expected), (vec![rows, cols], h.expected.concat()), "{case}: expected.npy");
        // independent of the writer: the total of the counts and the invalid samples is N
        let invalid: u64 = <[u64; lobes::reference::Invalid::COUNT]>::from(h.invalid.unwrap()).iter().sum();
        assert_eq!(h.counts.concat().iter().sum::<u64>() + invalid, 30_000, "{case}");
        assert_eq!(file("a", "counts.npy"), file("b", "counts.npy"), "{case}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
