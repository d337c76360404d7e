//! The tutorial subcommands through the built `lobes` binary: the JSON numbers against closed
//! forms computed here, and bad input rejected with exit code 2 and a message naming the flag.

use serde_json::Value;
use std::f64::consts::PI;
use std::process::{Command, Output};

const TUTORIAL_WEIGHTS: &str = "15,5,5,25,5,10,15,5,5,10";

fn lobes(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lobes")).args(args).output().expect("run the lobes binary")
}

/// Runs `lobes args`, expects success and exactly one JSON object on stdout.
fn json(args: &[&str]) -> Value {
    let out = lobes(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "lobes {args:?} failed ({:?}): {stderr}", out.status);
    let stdout = String::from_utf8(out.stdout).expect("utf-8 stdout");
    let values: Vec<Value> = serde_json::Deserializer::from_str(&stdout)
        .into_iter::<Value>()
        .collect::<Result<_, _>>()
        .unwrap_or_else(|e| panic!("lobes {args:?}: stdout is not JSON ({e}): {stdout}"));
    assert_eq!(values.len(), 1, "lobes {args:?}: expected one JSON value, got: {stdout}");
    assert!(values[0].is_object(), "lobes {args:?}: not an object: {stdout}");
    values.into_iter().next().unwrap()
}

/// Runs `lobes args`, expects exit code 2, nothing on stdout, and `lobes: error:` plus `flag` on stderr.
fn bad(args: &[&str], flag: &str) {
    let out = lobes(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "lobes {args:?}: want exit 2, stderr: {stderr}");
    assert!(out.stdout.is_empty(), "lobes {args:?}: printed on stdout: {}", String::from_utf8_lossy(&out.stdout));
    assert!(stderr.starts_with("lobes: error: "), "lobes {args:?}: stderr: {stderr}");
    assert!(stderr.contains(flag), "lobes {args:?}: stderr does not name {flag}: {stderr}");
    assert!(!stderr.contains("panicked"), "lobes {args:?} panicked: {stderr}");
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn f_list(v: &Value) -> Vec<f64> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}")).iter().map(f).collect()
}

fn vec3(v: &Value) -> [f64; 3] {
    f_list(v).try_into().unwrap_or_else(|l: Vec<f64>| panic!("not a 3-vector: {l:?}"))
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

fn assert_vec_close(got: [f64; 3], want: [f64; 3], tol: f64) {
    for (g, w) in got.iter().zip(want) {
        assert!(close(*g, w, tol), "got {got:?}, want {want:?}");
    }
}

#[test]
fn clap_definition_is_consistent() {
    use clap::CommandFactory;
    lobes::cli::Cli::command().debug_assert();
}

#[test]
fn exit_codes_separate_bad_input_from_failures() {
    use lobes::cli::{ChecksFailed, EXIT_CHECKS_FAILED, EXIT_TOOL_FAILURE, EXIT_USAGE, exit_code, usage};
    assert_eq!(exit_code(&usage("--x: bad")), EXIT_USAGE);
    assert_eq!(exit_code(&usage("--x: bad").context("while running")), EXIT_USAGE);
    assert_eq!(exit_code(&anyhow::anyhow!("disk full")), EXIT_TOOL_FAILURE);
    assert_eq!(exit_code(&ChecksFailed("1 of 2 cases failed".into()).into()), EXIT_CHECKS_FAILED);
    assert_eq!((EXIT_CHECKS_FAILED, EXIT_USAGE, EXIT_TOOL_FAILURE), (1, 2, 3));
}

#[test]
fn discrete_tutorial_part_1() {
    let v = json(&["discrete", "--weights", TUTORIAL_WEIGHTS, "--u", "0.5,0.25,0.9,0.65", "--json"]);
    let weights = [15.0, 5.0, 5.0, 25.0, 5.0, 10.0, 15.0, 5.0, 5.0, 10.0];
    // pmf = w / 100 and CDF = prefix / 100, each correctly rounded, so equal to the literals.
    assert_eq!(f_list(&v["pmf"]), [0.15, 0.05, 0.05, 0.25, 0.05, 0.1, 0.15, 0.05, 0.05, 0.1]);
    assert_eq!(f_list(&v["cdf"]), [0.15, 0.2, 0.25, 0.5, 0.55, 0.65, 0.8, 0.85, 0.9, 1.0]);
    assert_eq!(v["method"], "cdf");
    let samples = v["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 4);
    // Integer prefix sums: the first index whose prefix (in percent) reaches 100·u.
    let prefix: Vec<u32> = weights
        .iter()
        .scan(0u32, |s, &w| {
            *s += w as u32;
            Some(*s)
        })
        .collect();
    let want = [(0.5, 50u32, 3usize, 25.0), (0.25, 25, 2, 5.0), (0.9, 90, 8, 5.0), (0.65, 65, 5, 10.0)];
    for (s, &(u, percent, index, value)) in samples.iter().zip(&want) {
        assert_eq!(f(&s["u"]), u);
        assert_eq!(prefix.iter().position(|&p| p >= percent), Some(index));
        assert_eq!(s["index"].as_u64(), Some(index as u64), "{s}");
        assert_eq!(f(&s["value"]), value);
        assert_eq!(f(&s["probability"]), weights[index] / 100.0);
        assert_eq!(f(&s["cdf"]), f64::from(prefix[index]) / 100.0);
    }
}

#[test]
fn discrete_alias_reproduces_the_pmf() {
    // Equally spaced u: column ⌊10u⌋ and coin frac(10u) both sweep evenly, so the frequency of
    // each index is its pmf within one u per column and index (≤ 10/2000).
    let n = 2000;
    let us: Vec<String> = (0..n).map(|k| format!("{}", (k as f64 + 0.5) / n as f64)).collect();
    let u_arg = us.join(",");
    let v = json(&["discrete", "--weights", TUTORIAL_WEIGHTS, "--u", &u_arg, "--method", "alias", "--json"]);
    assert_eq!(v["method"], "alias");
    let pmf = f_list(&v["pmf"]);
    let samples = v["samples"].as_array().unwrap();
    assert_eq!(samples.len(), n);
    let mut counts = [0usize; 10];
    for s in samples {
        let i = s["index"].as_u64().unwrap() as usize;
        counts[i] += 1;
        assert_eq!(f(&s["probability"]), pmf[i]);
        assert_eq!(f(&s["value"]), f_list(&v["weights"])[i]);
    }
    for (i, (&c, &p)) in counts.iter().zip(&pmf).enumerate() {
        let freq = c as f64 / n as f64;
        assert!(close(freq, p, 0.005), "index {i}: frequency {freq}, pmf {p}");
    }
    // u at the ends of [0, 1] are accepted and land on a positive weight
    let v = json(&["discrete", "--weights", "0,3,0,1,0", "--u", "0,1", "--method", "alias", "--json"]);
    for s in v["samples"].as_array().unwrap() {
        assert!(f(&s["value"]) > 0.0, "{s}");
    }
}

#[test]
fn pdf_convert_tutorial_part_2() {
    let v = json(&["pdf-convert", "--pdf-h", "0.5", "--theta-h", "15", "--theta-i", "45", "--json"]);
    let cos30 = (PI / 6.0).cos();
    assert!(close(f(&v["jacobian"]), 1.0 / (4.0 * cos30), 1e-14), "{v}");
    assert!(close(f(&v["pdf_r"]), 0.5 / (4.0 * cos30), 1e-14), "{v}");
    assert!(close(f(&v["pdf_r"]), 0.144, 5e-4));
    let (s45, s15) = ((PI / 4.0).sin(), (PI / 12.0).sin());
    assert_vec_close(vec3(&v["omega_i"]), [s45, 0.0, s45], 1e-15);
    assert_vec_close(vec3(&v["h"]), [s15, 0.0, (PI / 12.0).cos()], 1e-15);
    // in plane, θr = 2θh − θi = −15°: mirrored to the other side of the normal
    assert_vec_close(vec3(&v["omega_r"]), [-s15, 0.0, (PI / 12.0).cos()], 1e-15);
    assert_eq!(v["valid"], true);
    assert_eq!(v["invalid_reason"], Value::Null);
}

#[test]
fn sample_tutorial_part_3_ward() {
    let v = json(&["sample", "--lobe", "ward", "--alpha", "0.2", "--u", "0.4,0.2", "--json"]);
    let alpha: f64 = 0.2;
    let tan_t = alpha * (-(0.4f64).ln()).sqrt();
    let theta = tan_t.atan();
    assert!(close(f(&v["theta_h_deg"]), theta.to_degrees(), 1e-9), "{v}");
    assert!(close(f(&v["theta_h_deg"]), 10.84, 0.005));
    assert!(close(f(&v["phi_h_deg"]), 72.0, 1e-9), "{v}");
    let phi = 0.4 * PI;
    let h = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
    assert_vec_close(vec3(&v["h"]), h, 1e-12);
    // default ωi = +z: ωr = 2 hz h − z
    assert_vec_close(vec3(&v["omega_i"]), [0.0, 0.0, 1.0], 0.0);
    assert_vec_close(vec3(&v["omega_r"]), [2.0 * h[2] * h[0], 2.0 * h[2] * h[1], 2.0 * h[2] * h[2] - 1.0], 1e-12);
    // Walter 2005: p(h) = exp(−tan²θ/α²) / (π α² cos³θ); p(ωr) = p(h) / (4 ωr·h), ωr·h = hz
    let pdf_h = (-tan_t * tan_t / (alpha * alpha)).exp() / (PI * alpha * alpha * theta.cos().powi(3));
    assert!(close(f(&v["pdf_h"]), pdf_h, 1e-12 * pdf_h), "{v}");
    assert!(close(f(&v["pdf_r"]), pdf_h / (4.0 * theta.cos()), 1e-12 * pdf_h), "{v}");
    assert_eq!(v["valid"], true);
    assert_eq!(v["invalid_reason"], Value::Null);
    assert_eq!((v["lobe"].as_str(), v["method"].as_str()), (Some("ward"), Some("ndf")));
}

#[test]
fn sample_every_supported_pair_and_phi_range() {
    let pairs = [
        ("ward", "ndf"),
        ("beckmann", "ndf"),
        ("beckmann", "vndf"),
        ("ggx", "ndf"),
        ("ggx", "vndf"),
        ("ggx", "bounded"),
    ];
    for (lobe, method) in pairs {
        for u in ["0,0", "0.3,0.7", "0.5,1", "1,0.999999", "0.999,0.5"] {
            let v = json(&[
                "sample",
                "--lobe",
                lobe,
                "--method",
                method,
                "--alpha-x",
                "0.3",
                "--alpha-y",
                "0.1",
                "--u",
                u,
                "--incident-theta",
                "40",
                "--incident-phi",
                "-30",
                "--json",
            ]);
            assert_eq!((v["alpha_x"].as_f64(), v["alpha_y"].as_f64()), (Some(0.3), Some(0.1)));
            if let Some(phi) = v["phi_h_deg"].as_f64() {
                assert!((0.0..360.0).contains(&phi), "{lobe}/{method} u={u}: φh = {phi}");
            }
            let valid = v["valid"].as_bool().unwrap();
            assert_eq!(valid, v["invalid_reason"].is_null(), "{v}");
            if valid {
                let wr = vec3(&v["omega_r"]);
                assert!(wr[2] > 0.0 && f(&v["pdf_r"]) > 0.0, "{v}");
            }
        }
    }
    // GGX NDF at u1 = 1 puts h on the horizon; the sample is reported invalid, not an error
    let v = json(&["sample", "--lobe", "ggx", "--alpha", "0.3", "--u", "1,0.25", "--json"]);
    assert_eq!(v["valid"], false);
    assert!(v["invalid_reason"].is_string(), "{v}");
}

#[test]
fn tables_without_json() {
    let cases: [(&[&str], &str); 3] = [
        (&["discrete", "--weights", TUTORIAL_WEIGHTS, "--u", "0.5,0.25,0.9,0.65"], "0.900000"),
        (&["pdf-convert", "--pdf-h", "0.5", "--theta-h", "15", "--theta-i", "45"], "0.144338"),
        (&["sample", "--lobe", "ward", "--alpha", "0.2", "--u", "0.4,0.2"], "72.000000"),
    ];
    for (args, needle) in cases {
        let out = lobes(args);
        assert!(out.status.success(), "{args:?}");
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(text.contains(needle), "{args:?}: {text}");
        assert!(serde_json::from_str::<Value>(&text).is_err(), "{args:?} printed JSON without --json");
    }
}

#[test]
fn discrete_bad_input_exits_2_naming_the_flag() {
    let u = ["--u", "0.5"];
    for weights in ["1,,2", "a", "1,", "-1,2", "0,0", "nan,1", "1,inf", "", "1e308,1e308"] {
        bad(&[&["discrete", "--weights", weights][..], &u].concat(), "--weights");
    }
    for u in ["1.5", "-0.1", "nan", "", "0.5,,0.2", "x"] {
        bad(&["discrete", "--weights", "1,2", "--u", u], "--u");
    }
    bad(&["discrete", "--weights", "1,2", "--u", "0.5", "--method", "inverse"], "--method");
    bad(&["discrete", "--u", "0.5"], "--weights");
}

#[test]
fn pdf_convert_bad_input_exits_2_naming_the_flag() {
    bad(&["pdf-convert", "--pdf-h", "-1", "--theta-h", "15", "--theta-i", "45"], "--pdf-h");
    bad(&["pdf-convert", "--pdf-h", "inf", "--theta-h", "15", "--theta-i", "45"], "--pdf-h");
    bad(&["pdf-convert", "--pdf-h", "0.5", "--theta-h", "95", "--theta-i", "45"], "--theta-h");
    bad(&["pdf-convert", "--pdf-h", "0.5", "--theta-h", "15", "--theta-i", "nan"], "--theta-i");
    bad(&["pdf-convert", "--pdf-h", "0.5", "--theta-h", "15"], "--theta-i");
}

#[test]
fn sample_bad_input_exits_2_naming_the_flag() {
    let base = ["sample", "--lobe", "ggx"];
    let run = |extra: &[&str], flag: &str| bad(&[&base[..], extra].concat(), flag);
    for alpha in ["0", "-0.1", "inf", "nan", "x"] {
        run(&["--alpha", alpha, "--u", "0.1,0.2"], "--alpha");
    }
    run(&["--alpha-x", "0", "--alpha-y", "0.1", "--u", "0.1,0.2"], "--alpha-x");
    run(&["--alpha", "0.2", "--alpha-x", "0.1", "--alpha-y", "0.1", "--u", "0.1,0.2"], "--alpha");
    run(&["--alpha-x", "0.1", "--u", "0.1,0.2"], "--alpha-y");
    run(&["--alpha-y", "0.1", "--u", "0.1,0.2"], "--alpha-x");
    run(&["--u", "0.1,0.2"], "--alpha");
    for u in ["0.1", "0.1,0.2,0.3", "0.1,1.5", "nan,0.2", "0.1,,0.2", ""] {
        run(&["--alpha", "0.2", "--u", u], "--u");
    }
    for theta in ["181", "-1", "nan"] {
        run(&["--alpha", "0.2", "--u", "0.1,0.2", "--incident-theta", theta], "--incident-theta");
    }
    run(&["--alpha", "0.2", "--u", "0.1,0.2", "--incident-phi", "inf"], "--incident-phi");
    bad(&["sample", "--lobe", "ward", "--method", "vndf", "--alpha", "0.2", "--u", "0.1,0.2"], "--method");
    bad(&["sample", "--lobe", "ward", "--method", "bounded", "--alpha", "0.2", "--u", "0.1,0.2"], "--method");
    bad(&["sample", "--lobe", "beckmann", "--method", "bounded", "--alpha", "0.2", "--u", "0.1,0.2"], "--method");
    bad(&["sample", "--lobe", "phong", "--alpha", "0.2", "--u", "0.1,0.2"], "--lobe");
}

#[test]
fn missing_or_unknown_subcommand_exits_2() {
    assert_eq!(lobes(&[]).status.code(), Some(2));
    assert_eq!(lobes(&["frobnicate"]).status.code(), Some(2));
    assert_eq!(lobes(&["--help"]).status.code(), Some(0));
}
