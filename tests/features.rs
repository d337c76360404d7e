//! The feature sets the crate promises, by their dependency trees: `check` (the library
//! without the command line, what a renderer's `cargo test` uses with `lobes::check`) pulls in
//! none of the command line's crates; no features at all (`lobes::embed` alone) none of the GPU
//! crates; each of the embed's features (naga, glsl, naga-oil, wgpu, wesl) only its own. `.ci/run`
//! compiles the embed alone (`cargo check --release --no-default-features`).

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

/// The counts docs/embedding.md quotes for each feature set, which these bounds hold (a tree
/// may shrink as dependencies drop crates; growing past a bound needs the docs changed).
#[test]
fn the_embed_alone_needs_no_gpu_crates() {
    let tree = tree(&[]);
    for wanted in ["lobes", "bytemuck", "thiserror"] {
        assert!(tree.iter().any(|c| c == wanted), "{wanted} is missing:\n{tree:?}");
    }
    for beyond in ["wgpu", "naga", "naga_oil", "regex", "pollster", "wesl", "clap", "image", "statrs", "glam"] {
        assert!(!tree.iter().any(|c| c == beyond), "{beyond} is in the embed's tree:\n{tree:?}");
    }
    // 9 on 2026-12-01: lobes, bytemuck and thiserror with their derive macros' syn stack
    assert!(tree.len() <= 9, "{} crates: {tree:?}", tree.len());
}

#[test]
fn each_embed_feature_adds_only_its_own_crates() {
    // (features, crates it must hold, crates it must not hold, the most crates: docs/embedding.md)
    let sets: [(&str, &[&str], &[&str], usize); 5] = [
        ("naga", &["naga"], &["wgpu", "naga_oil", "regex", "wesl"], 30),
        ("glsl", &["naga", "pp-rs", "petgraph"], &["wgpu", "naga_oil", "regex", "wesl"], 35),
        ("naga-oil", &["naga_oil", "naga"], &["wgpu", "wesl"], 42),
        ("wgpu", &["wgpu"], &["naga_oil", "regex", "wesl", "pollster"], 55),
        ("wesl", &["wesl"], &["wgpu", "naga", "naga_oil"], 46),
    ];
    for (features, with, without, most) in sets {
        let tree = tree(&["--features", features]);
        for c in with {
            assert!(tree.iter().any(|t| t == c), "--features {features} lacks {c}:\n{tree:?}");
        }
        for c in without {
            assert!(!tree.iter().any(|t| t == c), "--features {features} pulls {c}:\n{tree:?}");
        }
        assert!(tree.len() <= most, "--features {features}: {} crates, docs/embedding.md says {most}: {tree:?}", tree.len());
    }
    // glsl (pp-rs, petgraph, fixedbitset, unicode-xid) is in check: 124 + 4, 173 + 3
    assert!(tree(&["--features", "check"]).len() <= 128);
    assert!(tree(&["--features", "cli"]).len() <= 176);
}
