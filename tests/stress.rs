//! The stability suite (`lobes stress`) as tests: every sampler at the inputs where naive
//! formulas break, on the GPU (f32) and the CPU (f64), plus the discrete hard cases.

use lobes::gpu::GpuEngine;
use lobes::job::{DiscreteMethod, Job};
use lobes::reference::discrete::Distribution;
use lobes::stats::compare;
use lobes::stats::expected::Quadrature;

fn engine() -> GpuEngine {
    GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"))
}

#[test]
fn every_sampler_is_stable_at_the_hard_inputs() {
    let mut e = engine();
    let rows = lobes::stress::run_all(Some(&mut e)).unwrap();
    assert_eq!(rows.len(), 2 * lobes::stress::cases().len());
    let failed: Vec<_> = rows.iter().filter(|r| !r.passed).map(|r| format!("{} [{}]", r.case, r.kernel)).collect();
    assert!(failed.is_empty(), "unstable: {failed:?}");
    // the suite exercises invalid samples too (u at 0 and 1, grazing and below-horizon light)
    assert!(rows.iter().any(|r| r.valid < r.samples));
}

fn gpu_counts(e: &mut GpuEngine, weights: &[f64], method: DiscreteMethod, n: u64) -> (Distribution, Vec<u64>) {
    let dist = Distribution::new(weights).unwrap();
    let job = Job::Discrete { dist: dist.clone(), method };
    let r = e.histogram(&job, 17, 0, n, &mut |_| {}).unwrap();
    assert_eq!(r.counts.total(), n);
    assert_eq!(r.counts.invalid, [0; 4]);
    (dist, r.counts.bins)
}

#[test]
fn discrete_hard_cases() {
    let mut e = engine();
    for method in [DiscreteMethod::Cdf, DiscreteMethod::Alias] {
        // one nonzero weight takes every sample
        let (_, c) = gpu_counts(&mut e, &[0.0, 0.0, 3.0, 0.0, 0.0], method, 1_000_000);
        assert_eq!(c, vec![0, 0, 1_000_000, 0, 0], "{method:?}");
        // zeros at both ends and in between are never selected
        let w = [0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 3.0, 0.0];
        let (_, c) = gpu_counts(&mut e, &w, method, 1_000_000);
        for (k, &x) in w.iter().enumerate() {
            assert_eq!(x == 0.0, c[k] == 0, "{method:?} index {k}");
        }
        // weights spanning 1e-30 to 1e30: the huge one takes (almost) all
        let (_, c) = gpu_counts(&mut e, &[1e-30, 1.0, 1e30, 0.0], method, 1_000_000);
        assert_eq!(c[2], 1_000_000, "{method:?}: {c:?}");
    }
}

/// 2^24 + 1 entries: beyond one 24-bit uniform and an f32 CDF. The two-level CDF and the alias
/// table both reproduce the distribution (χ² over the pooled cells).
#[test]
fn tables_beyond_f32_resolution() {
    let mut e = engine();
    let n = (1 << 24) + 1;
    // a ramp, so that neighbouring entries differ and every entry matters
    let mut w: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
    w[n - 1] = 1000.0; // the entry past 2^24 must be reached, often
    w[n - 2] = 0.0; // and a zero next to it never
    for method in [DiscreteMethod::Cdf, DiscreteMethod::Alias] {
        let samples = 1 << 25;
        let (dist, c) = gpu_counts(&mut e, &w, method, samples);
        let job = Job::Discrete { dist, method };
        let exp = compare::expected_counts(&job, samples, &Quadrature::default());
        let counts = lobes::job::Counts { bins: c, invalid: [0; 4] };
        let t = compare::chi2_test(&counts, &exp, 0.001);
        assert!(t.passed, "{method:?}: χ² {} / {} p {}", t.statistic, t.dof, t.p_value);
        // the last entry, beyond 2^24, is reached
        let (got, want) = (counts.bins[n - 1] as f64, exp.bins[n - 1]);
        assert!((got - want).abs() < 5.0 * want.sqrt(), "{method:?}: last entry {got}, expected {want}");
        assert_eq!(counts.bins[n - 2], 0);
    }
}
