//! The feature sets the crate promises, by their dependency trees: `check` (the library
//! without the command line, what a renderer's `cargo test` uses with `lobes::check`) pulls in
//! none of the command line's crates, and no features at all (`lobes::embed` alone) only the
//! GPU crates. `.ci/run` compiles both (`cargo check --no-default-features [--features check]`).

use std::process::Command;

/// The crate names in `cargo tree -e normal` of lobes with `features`.
fn tree(features: &[&str]) -> Vec<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["tree", "--no-default-features", "--edges", "normal", "--prefix", "none", "--offline"])
        .args(features)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo tree runs");
    assert!(out.status.success(), "cargo tree failed: {}", String::from_utf8_lossy(&out.stderr));
    let mut names: Vec<String> = String::from_utf8_lossy(&out.stdout).lines().filter_map(|l| l.split_whitespace().next()).map(str::to_string).collect();
    names.sort();
    names.dedup();
    names
}

#[test]
fn the_library_needs_no_command_line_crates() {
    let tree = tree(&["--features", "check"]);
    assert!(tree.iter().any(|c| c == "wgpu") && tree.iter().any(|c| c == "statrs"), "the tree lists the library's dependencies:\n{tree:?}");
    for cli_only in ["clap", "indicatif", "quick-junit", "signal-hook"] {
        assert!(!tree.iter().any(|c| c == cli_only), "{cli_only} is in the library's tree:\n{tree:?}");
    }
}

#[test]
fn the_embed_alone_needs_only_the_gpu_crates() {
    let tree = tree(&[]);
    let direct = ["wgpu", "naga", "naga_oil", "bytemuck", "thiserror", "pollster"];
    for wanted in direct {
        assert!(tree.iter().any(|c| c == wanted), "{wanted} is missing:\n{tree:?}");
    }
    for beyond in ["clap", "image", "plotters", "serde_json", "statrs", "rayon", "glam", "toml", "schemars", "tempfile", "comfy-table", "ab_glyph"] {
        assert!(!tree.iter().any(|c| c == beyond), "{beyond} is in the embed's tree:\n{tree:?}");
    }
    // wgpu and naga_oil's own dependencies are the rest; 128 crates were in the library's tree
    // before the embed had a feature set of its own
    assert!(tree.len() < 90, "{} crates: {tree:?}", tree.len());
}
