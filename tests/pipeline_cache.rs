//! The pipeline cache kept between processes (src/engine/gpu/pipeline_cache.rs), through the
//! `lobes` binary with its own XDG_CACHE_HOME: written where the adapter has PIPELINE_CACHE, a
//! corrupt file is ignored (the run passes) and replaced, and LOBES_PIPELINE_CACHE=off writes
//! nothing.

use lobes::engine::gpu::pipeline_cache::{DISABLE_VAR, decode};
use std::path::Path;
use std::process::Command;

const LOBES: &str = env!("CARGO_BIN_EXE_lobes");

/// `lobes run` of one small case with the cache under `home`; the run must pass.
fn run(home: &Path, out: &Path, off: bool) {
    let mut cmd = Command::new(LOBES);
    cmd.args(["run", "--case", "ggx-vndf", "--samples", "100000", "--out"]).arg(out).env("XDG_CACHE_HOME", home).env_remove(DISABLE_VAR);
    if off {
        cmd.env(DISABLE_VAR, "off");
    }
    let o = cmd.output().expect("lobes runs");
    assert!(o.status.success(), "lobes run: {}\n{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
}

fn cache_files(home: &Path) -> Vec<std::path::PathBuf> {
    match std::fs::read_dir(home.join("lobes")) {
        Ok(d) => d.map(|e| e.unwrap().path()).collect(),
        Err(_) => Vec::new(),
    }
}

#[test]
fn the_cache_is_written_checked_and_can_be_turned_off() {
    let gpu = lobes::engine::gpu::Gpu::new().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
    let supported = gpu.features.contains(wgpu::Features::PIPELINE_CACHE);
    drop(gpu);
    let dir = tempfile::tempdir().unwrap();
    let (home, out) = (dir.path().join("cache"), dir.path().join("out"));

    run(&home, &out, true);
    assert!(cache_files(&home).is_empty(), "{DISABLE_VAR}=off wrote {:?}", cache_files(&home));

    run(&home, &out, false);
    let files = cache_files(&home);
    if !supported {
        assert!(files.is_empty(), "no PIPELINE_CACHE, yet {files:?}");
        return;
    }
    assert_eq!(files.len(), 1, "{files:?}");
    let first = std::fs::read(&files[0]).unwrap();
    assert!(decode(&first).is_some_and(|d| !d.is_empty()), "{} is not a valid cache file", files[0].display());

    // Another program's bytes, then a valid file with one data byte altered: ignored, replaced.
    for bad in [b"not a pipeline cache".to_vec(), { let mut b = first.clone(); *b.last_mut().unwrap() ^= 0x5a; b }] {
        std::fs::write(&files[0], &bad).unwrap();
        run(&home, &out, false);
        let now = std::fs::read(&files[0]).unwrap();
        assert!(decode(&now).is_some(), "the corrupt cache was not replaced");
    }
}
