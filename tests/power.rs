//! How many samples a sampler's test needs (issue 25): `lobes check --power`'s count per test of
//! the χ² family and per check, `--budget` and `--profile`, and `lobes tradeoff`'s detection
//! table, on lavapipe at small scale (the panel's turned GGX sampler,
//! src/experiments/tradeoff/turn.wgsl at ε = 0.005, the detection table's ε-turn).

use lobes::check::budget::{self, PILOT_SAMPLES};
use lobes::check::power::{PowerSweep, TestKind};
use lobes::check::{Domain, Report, Settings, UserSampler, check};
use lobes::engine::gpu::Gpu;
use lobes::experiments::tradeoff::detection::{self, DetectionSettings, FAMILY};
use std::path::PathBuf;
use std::process::Command;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("lobes check needs a GPU adapter: {e}"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `lobes check` of GGX's visible normals (α 0.3, θi 30°), turned by the panel's 0.005 sin φ
/// or not, with `extra` flags: exit code, stdout, stderr.
fn lobes_check(turn: bool, extra: &[&str]) -> (Option<i32>, String, String) {
    let mut files = vec![root().join("examples/samplers/ggx_vndf.wgsl")];
    let (sample, pdf) = if turn { ("turn_sample", "turn_pdf") } else { ("ggx_sample", "ggx_pdf") };
    if turn {
        files.push(root().join("src/experiments/tradeoff/turn.wgsl"));
    }
    let out = Command::new(env!("CARGO_BIN_EXE_lobes"))
        .arg("check")
        .args(files)
        // the turn's ε = 0.005 is params[0].z
        .args(["--sample", sample, "--pdf", pdf, "--params", if turn { "0.3,0.3,0.005" } else { "0.3,0.3" }])
        .args(extra)
        .output()
        .unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

fn turned(extra: &[&str]) -> (Option<i32>, String, String) {
    lobes_check(true, extra)
}

/// `--power` names the count from which each test of the family and each check catches the
/// turn: a coarse grid or the φ marginal by 2²² (docs/statistics.md: the family from 2²²), the
/// fine grid not (it needs 2²⁵), the Jacobian's systematic test at the first count (a smooth
/// 0.5 % error of the map, whatever the sample count), the other checks never. The turn is then
/// caught at the count `--power` says with another seed, by the test it named.
#[test]
fn power_names_the_count_each_test_catches_from_and_the_check_agrees() {
    let (code, stdout, stderr) = turned(&["--samples", "4194304", "--power", "--json"]);
    assert_eq!(code, Some(1), "{stdout}{stderr}");
    let sweep: PowerSweep = serde_json::from_str(&stdout).unwrap();
    let names: Vec<&str> = sweep.tests.iter().map(|t| t.test.as_str()).collect();
    assert_eq!(names[..8], ["64 × 128", "32 × 64", "16 × 32", "8 × 16", "4 × 8", "2 × 4", "cos θ", "φ"], "{names:?}");
    assert!(sweep.tests[..8].iter().all(|t| t.kind == TestKind::Chi2Family));
    let from = |name: &str| sweep.tests.iter().find(|t| t.test == name).unwrap_or_else(|| panic!("no row {name}")).caught.as_ref().map(|c| c.samples);
    assert_eq!(from("64 × 128"), None, "the fine grid alone needs about 2^25: {stdout}");
    for check in ["pdf_consistency", "pdf_values", "normalization"] {
        assert_eq!(from(check), None, "{check} should not see a 0.5 % turn");
    }
    assert_eq!(from("jacobian"), Some(sweep.points[0].samples), "the Jacobian's systematic test sees the turn at any count: {stdout}");
    // the coarse test that catches it first, and the chi2 check with it
    let first = sweep.tests[1..8].iter().filter_map(|t| t.caught.as_ref().map(|c| (c.samples, t))).min_by_key(|(n, _)| *n);
    let (n, test) = first.unwrap_or_else(|| panic!("no coarse test caught the turn by 2^22: {stdout}"));
    assert_eq!(from("chi2"), Some(n), "the chi2 check fails from the count its first test rejects from");
    let caught = test.caught.as_ref().unwrap();
    assert!(caught.gpu_seconds.is_none_or(|s| s > 0.0) && caught.seconds > 0.0);
    // the same count, another seed: the check fails, by that test or another of the family
    let seed2 = check(&gpu(), &sampler(), &Settings { samples: n, seed: 2, params: vec![0.3, 0.3, 0.005], ..Settings::default() }).unwrap();
    assert_eq!(seed2.failed(), ["jacobian", "chi2"], "at {n} samples, seed 2");
    // the terminal table: a row per test
    let (code, text, _) = turned(&["--samples", "4194304", "--power"]);
    assert_eq!(code, Some(1));
    assert!(text.lines().any(|l| l.starts_with("64 × 128") && l.contains(" - ")), "{text}");
    assert!(text.lines().any(|l| l.starts_with(&test.test) && l.contains(&n.to_string())), "{text}");
}

fn sampler() -> UserSampler {
    let files = [root().join("examples/samplers/ggx_vndf.wgsl"), root().join("src/experiments/tradeoff/turn.wgsl")];
    UserSampler::from_files(&files, "turn_sample", "turn_pdf", None, Domain::Sphere).unwrap()
}

fn correct() -> UserSampler {
    UserSampler::from_files(&[root().join("examples/samplers/ggx_vndf.wgsl")], "ggx_sample", "ggx_pdf", None, Domain::Sphere).unwrap()
}

/// `--budget` picks the largest count that its pilots' model t(N) = t₀ + N · s fits in the
/// budget, runs the check at that count and says what it picked and why. Whether the check then
/// takes the budget is a measurement of this machine, not asserted here (tests run in parallel:
/// a pilot slowed by another test picks a smaller count); docs/statistics.md has measured ones.
#[test]
fn budget_picks_the_largest_count_that_fits() {
    let budget = 4.0;
    let (code, stdout, stderr) = lobes_check(false, &["--budget", "4", "--json"]);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    let report: Report = serde_json::from_str(&stdout).unwrap();
    let line = stderr.lines().find(|l| l.starts_with("lobes: budget 4.0 s: ")).unwrap_or_else(|| panic!("{stderr}"));
    assert!(line.contains(&format!("{} samples picked", report.samples)) && line.contains("pilot checks"), "{line}");
    assert!(report.samples >= PILOT_SAMPLES && report.samples.is_multiple_of(PILOT_SAMPLES), "{line}");
    // the library's pick: its count is the model's largest, and the model is the pilots' line
    let settings = Settings { params: vec![0.3, 0.3], ..Settings::default() };
    let pick = budget::pick(&gpu(), &correct(), &settings, budget, None).unwrap();
    let t = |n: u64| pick.fixed_seconds + pick.seconds_per_sample * n as f64;
    assert!(pick.samples >= PILOT_SAMPLES && pick.samples.is_multiple_of(PILOT_SAMPLES), "{pick:?}");
    assert!(t(pick.samples) <= budget && (t(pick.samples + PILOT_SAMPLES) > budget || pick.samples == lobes::engine::job::MAX_SAMPLES), "{pick:?}");
    assert!((pick.predicted_seconds - t(pick.samples)).abs() < 1e-9, "{pick:?}");
    let (base, last) = (&pick.pilots[1], pick.pilots.last().unwrap());
    assert!(pick.pilots[0].samples == PILOT_SAMPLES && base.samples == PILOT_SAMPLES && last.samples > base.samples, "{pick:?}");
    // the line's slope where the samples' share was measured (half the fixed part); else the
    // last pilot's time over its samples where that is more (a sample costs no more than it)
    let slope = ((last.seconds - base.seconds) / (last.samples - base.samples) as f64).max(0.0);
    let measured = last.seconds - base.seconds >= 0.5 * base.seconds || last.samples >= lobes::engine::job::MAX_SAMPLES / 4;
    let want = if measured { slope } else { slope.max(last.seconds / last.samples as f64) };
    assert!((pick.seconds_per_sample - want).abs() <= 1e-12 * want.max(1e-12), "{pick:?}");
}

/// `--profile` and `--budget` conflict with `--samples` and with each other (exit 2), and a
/// budget below the check's fixed part is refused (exit 2), naming what it took.
#[test]
fn budget_and_profile_bad_input_exits_2() {
    for (args, says) in [
        (vec!["--profile", "ci", "--samples", "65536"], "--samples"),
        (vec!["--budget", "5", "--samples", "65536"], "--samples"),
        (vec!["--budget", "5", "--profile", "thorough"], "--profile"),
        (vec!["--budget", "0"], "not a time budget"),
        (vec!["--profile", "fast"], "ci"),
    ] {
        let (code, _, stderr) = turned(&args);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
    let (code, _, stderr) = turned(&["--budget", "0.001"]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("lobes: error: --budget: 0.001 s is too small: a check of 65536 samples of this sampler took "), "{stderr}");
}

/// The detection table at small scale: turns of 3 % and 6 % (3 seeds, 2¹⁶ … 2²¹). A bigger
/// defect needs no more samples than a smaller one, the family no more than the fine grid
/// alone, and the φ marginal (the turn's own axis) sees it while cos θ's marginal (which an
/// azimuthal turn leaves exactly as it is) does not.
#[test]
fn detection_table_orders_by_defect_size_and_test() {
    let set = DetectionSettings { epsilons: vec![0.03, 0.06], seeds: 3, log2_min: 16, log2_max: 21, ..Default::default() };
    let d = detection::detection(&gpu(), &set, &mut |s| eprintln!("{s}")).unwrap();
    let at = |e: f64, t: &str| d.samples(e, t);
    eprintln!("{}", lobes::report::tradeoff::tables::detection_table(&d));
    for e in [0.03, 0.06] {
        let (family, fine) = (at(e, FAMILY).expect("the family catches it"), at(e, "64 × 128").expect("the fine grid catches it"));
        assert!(family <= fine, "ε {e}: the family from {family}, the fine grid from {fine}");
        assert!(at(e, "φ").is_some(), "ε {e}: φ's marginal should see a turn in φ");
        assert_eq!(at(e, "cos θ"), None, "ε {e}: a turn about the normal leaves cos θ as it is");
    }
    for t in [FAMILY, "64 × 128", "φ"] {
        assert!(at(0.06, t).unwrap() <= at(0.03, t).unwrap(), "{t}: ε 0.06 from {:?}, ε 0.03 from {:?}", at(0.06, t), at(0.03, t));
    }
    // the seconds: a whole check's time at the count, more for more samples
    let row = |e: f64| d.epsilons.iter().find(|x| x.epsilon == e).unwrap().detected.iter().find(|x| x.test == "64 × 128").unwrap().seconds.unwrap();
    assert!(row(0.03) >= row(0.06) && row(0.06) > 0.0);
}
