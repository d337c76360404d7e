//! The example renderer crate (examples/renderer), which uses lobes as a dev-dependency the way
//! a renderer would, passes its own `cargo test`: its diffuse sampler passes `lobes::check` and a
//! pdf off by a factor of two is caught. It is a crate of its own (its own `[workspace]`), so it is
//! run here with cargo, in lobes' target directory. Its dependencies are built anew all the same:
//! lobes with the `check` feature alone, and the rest without the features lobes' own
//! dev-dependencies and command line add. So it runs as a renderer's plain `cargo test` does (the
//! dev profile), without debug info: on 2 cores that built in 3.5 min of CPU against 9.0 with
//! `--release`, and its tests ran 28 s against 14 s.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Where lobes' own build goes: `CARGO_TARGET_DIR` if set (relative to the package root, as
/// cargo reads it when run there), else `target/` of the package.
fn target_dir(root: &Path) -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) => root.join(dir),
        None => root.join("target"),
    }
}

#[test]
fn renderer_example_passes_its_own_tests() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest = root.join("examples/renderer/Cargo.toml");
    assert!(manifest.is_file(), "{} is missing: this test runs in lobes' repository, not a packaged crate", manifest.display());
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let output = Command::new(&cargo)
        .args(["test", "--manifest-path"])
        .arg(&manifest)
        .env("CARGO_TARGET_DIR", target_dir(root))
        .env("CARGO_PROFILE_DEV_DEBUG", "0")
        // built once from nothing: incremental compilation's bookkeeping would buy nothing
        .env("CARGO_INCREMENTAL", "0")
        .current_dir(root)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", Path::new(&cargo).display()));
    let text = format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "`cargo test --manifest-path {}` failed ({}):\n{text}", manifest.display(), output.status);
    // the renderer's tests ran, each by name (not a build that found no tests)
    for test in [
        "diffuse_lobe_passes",
        "diffuse_lobe_passes_against_an_f64_reference_pdf",
        "incident_direction_from_below_tests_nothing",
        "a_pdf_off_by_a_factor_of_two_is_caught",
        "a_reported_pdf_that_differs_from_the_pdf_function_is_caught",
        "an_error_of_a_fraction_of_a_percent_is_caught_by_chi2_with_many_samples",
    ] {
        assert!(text.contains(&format!("test {test} ... ok")), "`{test}` did not run and pass:\n{text}");
    }
}
