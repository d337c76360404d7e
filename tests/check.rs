//! `lobes check` on shipped example samplers: correct ones pass, broken ones are rejected by the
//! check that should catch them.

use lobes::check::{Domain, Settings, UserSampler, check};
use lobes::engine::gpu::Gpu;
use std::path::PathBuf;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("lobes check needs a GPU adapter: {e}"))
}

fn files(names: &[&str]) -> Vec<PathBuf> {
    names.iter().map(|n| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/samplers").join(n)).collect()
}

#[test]
fn henyey_greenstein_passes() {
    let gpu = gpu();
    let s = UserSampler::from_files(&files(&["henyey_greenstein.wgsl"]), "hg_sample", "hg_pdf", Some("hg_eval"), Domain::Sphere).unwrap();
    for g in [0.7, -0.3, 0.0] {
        let r = check(&gpu, &s, &Settings { params: vec![g], ..Settings::default() }).unwrap();
        for c in &r.checks {
            eprintln!("g {g}: {} {} {}", c.name, c.passed, c.summary);
        }
        r.assert_passed();
    }
}
