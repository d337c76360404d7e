//! `lobes tradeoff`'s building blocks on the GPU (lavapipe in CI): the precision variants, the
//! f64 kernels, the L1-against-N behaviour and the GPU quadrature. A machine with no adapter
//! fails these tests with the fix in the message.

use lobes::gpu::GpuEngine;
use lobes::reference::{LobeKind, Method};
use lobes::stats::compare;
use lobes::stats::expected::Quadrature;
use lobes::tradeoff::{self, Precision, Sampler, quadrature};

fn engine() -> GpuEngine {
    GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"))
}

const GGX_VNDF: Sampler = Sampler { kind: LobeKind::Ggx, method: Method::Vndf };

fn angle(e: &mut GpuEngine, s: Sampler, prec: Precision, n: u32) -> tradeoff::AngleError {
    let job = tradeoff::sweep_job(s, 0.3, 45.0);
    e.rewrite = prec.rewrite();
    let a = tradeoff::angle_error(e, &job, 1, n, prec).expect("angle check");
    e.rewrite = None;
    a
}

/// The f64 kernels reproduce the f64 reference to far below f32 resolution: every sample's
/// angle < 1e-9 rad (f32 kernels: ~1e-7), with no validity disagreement.
#[test]
fn f64_kernels_match_the_f64_reference() {
    let mut e = engine();
    assert!(e.gpu.has_f64(), "this test needs SHADER_F64 (lavapipe has it); adapter {}", e.gpu.adapter_name());
    for s in Sampler::ALL {
        if tradeoff::unavailable(&e, s, Precision::F64).is_some() {
            continue;
        }
        let a = angle(&mut e, s, Precision::F64, 1 << 16);
        eprintln!("{} f64: {a:?}", s.name());
        assert_eq!(a.validity_mismatches, 0, "{}", s.name());
        assert!(a.compared > 30_000, "{}: {a:?}", s.name());
        assert!(a.max_angle_rad < 1e-9, "{}: {a:?}", s.name());
    }
}
