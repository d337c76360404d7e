//! The library without the command line: a renderer that uses lobes from its `cargo test`
//! (`default-features = false`) pulls in none of the command line's crates.

use std::process::Command;

#[test]
fn the_library_needs_no_command_line_crates() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["tree", "--no-default-features", "--edges", "normal", "--prefix", "none", "--offline"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo tree runs");
    let tree = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "cargo tree failed: {}", String::from_utf8_lossy(&out.stderr));
    assert!(tree.lines().any(|l| l.starts_with("wgpu ")), "the tree lists the library's dependencies:\n{tree}");
    for cli_only in ["clap ", "indicatif ", "quick-junit ", "signal-hook "] {
        assert!(!tree.lines().any(|l| l.starts_with(cli_only)), "{cli_only}is in the library's tree:\n{tree}");
    }
}
