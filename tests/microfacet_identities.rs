//! The microfacet identities (Heitz 2014, "Understanding the Masking-Shadowing Function"; the
//! checks of Falcor's MicrofacetTests), for GGX and Beckmann, isotropic and anisotropic, by
//! quadrature over the sphere of normals h: in f64 of the reference (`src/reference`) on the
//! CPU, and in f32 of the library WGSL (`shaders/lib`) on the GPU, both with lobes check's
//! adaptive Gauss–Legendre rules (`lobes::check::quadrature`):
//!
//! 1. normalisation, ∫ D(h) cos θh dh = 1 (Heitz 2014, eq. 4);
//! 2. projected area, ∫ max(0, ω·h) D(h) dh = (1 + Λ(ω)) cos θ for ω above the horizon
//!    (eqs. 13 and 43: G1 = cos θ / ∫ max(0, ω·h) D(h) dh), against Λ's closed form (eqs. 72, 86);
//! 3. Λ's symmetry: the projected area at ω and at ω rotated by π about the normal agree (D is
//!    symmetric under h → (−hx, −hy, hz)); for isotropic D, at any rotation;
//! 4. the visible normals' density D_ω(h) = G1(ω) max(0, ω·h) D(h) / cos θ (eq. 38) integrates
//!    to 1.
//!
//! Each is shown able to fail: a D off by π (without its 1/π), a Λ off by 10 % and a D skewed
//! by (1 + hx/2) (which keeps the normalisation) break the identity they should.

use glam::DVec3;
use lobes::check::Source;
use lobes::check::quadrature::{SphereIntegral, WgslIntegrand, sphere_integral_f64};
use lobes::engine::gpu::Gpu;
use lobes::engine::gpu::library;
use lobes::engine::gpu::precision::Precision;
use lobes::reference::beckmann::Beckmann;
use lobes::reference::ggx::Ggx;
use lobes::reference::microfacet::{Microfacet, pdf_ndf, pdf_vndf};
use lobes::reference::reflect::spherical;
use std::f64::consts::PI;

/// (αx, αy): isotropic from near-specular to beyond 1, and anisotropic pairs.
const ALPHAS: [(f64, f64); 9] = [(0.001, 0.001), (0.01, 0.01), (0.1, 0.1), (0.5, 0.5), (1.0, 1.0), (2.0, 2.0), (0.01, 0.5), (0.5, 0.1), (2.0, 0.3)];
/// θ of ω in degrees, to grazing.
const THETAS: [f64; 5] = [0.0, 45.0, 80.0, 89.0, 89.9];
/// φ of ω in radians (off the anisotropy's axes).
const PHI: f64 = 0.7;

/// Relative error of `got` against `want`.
fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs()
}

/// The four identities' relative errors for one distribution and one ω.
struct Errors {
    normalisation: f64,
    projected_area: f64,
    symmetry: f64,
    vndf: f64,
}

/// A distribution with its identities evaluated by the f64 quadrature of the sphere.
fn f64_errors<M: Microfacet + Sync>(m: &M, w: DVec3, isotropic: bool) -> Errors {
    let integral = |f: &(dyn Fn(DVec3) -> f64 + Send + Sync)| {
        let i: SphereIntegral = sphere_integral_f64(f);
        assert_eq!(i.bad_parts, 0);
        i.value
    };
    let area = |w: DVec3| integral(&|h: DVec3| if h.z > 0.0 { w.dot(h).max(0.0) * m.d(h) } else { 0.0 });
    let at = area(w);
    let rotated = |by: f64| area(DVec3::new(w.x * by.cos() - w.y * by.sin(), w.x * by.sin() + w.y * by.cos(), w.z));
    let mut symmetry = rel(rotated(PI), at);
    if isotropic {
        symmetry = symmetry.max(rel(rotated(1.9), at));
    }
    Errors {
        normalisation: rel(integral(&|h| pdf_ndf(m, h)), 1.0),
        projected_area: rel(at, (1.0 + m.lambda(w)) * w.z),
        symmetry,
        vndf: rel(integral(&|h| pdf_vndf(m, w, h)), 1.0),
    }
}

/// A distribution made wrong on purpose: D times `d_factor` and (1 + `skew` hx), Λ times
/// `lambda_factor` (and G1 = 1 / (1 + Λ) with it).
struct Broken<M> {
    m: M,
    d_factor: f64,
    skew: f64,
    lambda_factor: f64,
}

impl<M: Microfacet> Microfacet for Broken<M> {
    fn d(&self, h: DVec3) -> f64 {
        self.d_factor * (1.0 + self.skew * h.x) * self.m.d(h)
    }
    fn lambda(&self, w: DVec3) -> f64 {
        self.lambda_factor * self.m.lambda(w)
    }
    fn sample_ndf(&self, u: [f64; 2]) -> DVec3 {
        self.m.sample_ndf(u)
    }
    fn sample_vndf(&self, wi: DVec3, u: [f64; 2]) -> DVec3 {
        self.m.sample_vndf(wi, u)
    }
}

fn broken<M>(m: M) -> Broken<M> {
    Broken { m, d_factor: 1.0, skew: 0.0, lambda_factor: 1.0 }
}

/// The f64 limits, for α from 0.001 to 2 and θ to 89.9°. Largest errors measured over the grid
/// (`cargo test --release --test integration microfacet_identities:: -- --nocapture`): normalisation 1.7e-10
/// (GGX; 2e-11 Beckmann); projected area, symmetry and visible normals 7.2e-7 (Beckmann; 4.4e-7
/// GGX). Those three integrate max(0, ω·h), whose kink along the great circle ω·h = 0 crosses the
/// quadrature's parts: Gauss–Legendre converges slowly there, and a kink that clips a part's
/// corner between the nodes escapes the error estimate, hence ~10⁻⁷ rather than the ~10⁻¹⁰ of
/// the smooth normalisation. Each limit leaves a factor ~6 or more.
const F64_NORMALISATION_LIMIT: f64 = 1e-9;
const F64_KINKED_LIMIT: f64 = 5e-6;

fn worst(name: &str, errors: impl Iterator<Item = Errors>) -> [f64; 4] {
    let mut w = [0.0f64; 4];
    for e in errors {
        for (k, v) in [e.normalisation, e.projected_area, e.symmetry, e.vndf].into_iter().enumerate() {
            w[k] = w[k].max(v);
        }
    }
    eprintln!("{name}: worst relative errors: normalisation {:.1e}, projected area {:.1e}, symmetry {:.1e}, visible normals {:.1e}", w[0], w[1], w[2], w[3]);
    w
}

fn grid() -> impl Iterator<Item = ((f64, f64), f64)> {
    ALPHAS.into_iter().flat_map(|a| THETAS.into_iter().map(move |t| (a, t)))
}

#[test]
fn identities_hold_in_f64_for_ggx_and_beckmann() {
    let ggx = worst("GGX f64", grid().map(|((ax, ay), t)| f64_errors(&Ggx { ax, ay }, spherical(t.to_radians(), PHI), ax == ay)));
    let beckmann = worst("Beckmann f64", grid().map(|((ax, ay), t)| f64_errors(&Beckmann { ax, ay }, spherical(t.to_radians(), PHI), ax == ay)));
    for (name, w) in [("GGX", ggx), ("Beckmann", beckmann)] {
        assert!(w[0] < F64_NORMALISATION_LIMIT, "{name}: normalisation off by {:e}", w[0]);
        assert!(w[1..].iter().all(|&e| e < F64_KINKED_LIMIT), "{name}: {w:?} against {F64_KINKED_LIMIT:e}");
    }
}

#[test]
fn broken_distributions_fail_the_f64_identities() {
    let w80 = spherical(80f64.to_radians(), PHI);
    for (ax, ay) in [(0.1, 0.1), (0.5, 0.1)] {
        // D without its 1/π: the normalisation is π
        let e = f64_errors(&Broken { d_factor: PI, ..broken(Ggx { ax, ay }) }, w80, ax == ay);
        assert!((e.normalisation - (PI - 1.0)).abs() < 1e-6, "{}", e.normalisation);
        // Λ 10 % too large: the projected area misses (1 + Λ) cos θ, and D_ω misses 1
        let e = f64_errors(&Broken { lambda_factor: 1.1, ..broken(Beckmann { ax, ay }) }, spherical(89f64.to_radians(), PHI), ax == ay);
        assert!(e.normalisation < F64_NORMALISATION_LIMIT);
        assert!(e.projected_area > 1e-3 && e.vndf > 1e-3, "{} {}", e.projected_area, e.vndf);
        // D skewed toward +x: still normalised, no longer symmetric
        let e = f64_errors(&Broken { skew: 0.5, ..broken(Ggx { ax, ay }) }, w80, ax == ay);
        assert!(e.normalisation < F64_NORMALISATION_LIMIT, "{}", e.normalisation);
        assert!(e.symmetry > 1e-2, "{}", e.symmetry);
    }
}

/// The library's D and G1/cos θ of a distribution under the names the integrands call.
fn distribution_wgsl(kind: &str, d: &str, g1_over_cos: &str) -> Vec<Source> {
    let module = format!("lobes::{kind}");
    let library = library::wgsl(&[&module], Precision::F32Accurate).unwrap();
    let text = format!(
        "fn mf_d(a: vec2<f32>, h: vec3<f32>) -> f32 {{ {d} }}\n\
         fn mf_g1_over_cos(a: vec2<f32>, w: vec3<f32>) -> f32 {{ {g1_over_cos} }}\n\
         fn normalisation(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n    \
             return select(0.0, mf_d(params[0].xy, d) * d.z, d.z > 0.0);\n}}\n\
         fn projected_area(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n    \
             return select(0.0, max(0.0, dot(wi, d)) * mf_d(params[0].xy, d), d.z > 0.0);\n}}\n\
         fn vndf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n    \
             let a = params[0].xy;\n    \
             return select(0.0, mf_g1_over_cos(a, wi) * max(0.0, dot(wi, d)) * mf_d(a, d), d.z > 0.0);\n}}\n"
    );
    vec![Source { name: format!("shaders/lib ({module})"), text: library }, Source { name: "the identities' integrands".into(), text }]
}

const GGX_D: &str = "return ggx_d(a, h);";
const GGX_G1_OVER_COS: &str = "return ggx_g1(a, w) / w.z;";
const BECKMANN_D: &str = "return beckmann_d(a, h);";
const BECKMANN_G1_OVER_COS: &str = "return beckmann_g1_over_cos(a, w);";

/// The GPU's α grid: from 0.01 (the f32 quadrature's narrowest lobe here) to 2.
const GPU_ALPHAS: [(f64, f64); 7] = [(0.01, 0.01), (0.1, 0.1), (0.5, 0.5), (1.0, 1.0), (2.0, 2.0), (0.01, 0.5), (0.5, 0.1)];
const GPU_THETAS: [f64; 5] = [0.0, 45.0, 80.0, 89.0, 89.9];

/// The identities' errors on the GPU for the integrands of `sources`, with Λ's f64 closed form.
fn gpu_errors(gpu: &Gpu, sources: &[Source], lambda: impl Fn((f64, f64), DVec3) -> f64, alphas: &[(f64, f64)], thetas: &[f64]) -> Vec<Errors> {
    let integrand = |name: &str| WgslIntegrand::new(gpu, sources.to_vec(), name).unwrap_or_else(|e| panic!("{name}: {e}"));
    let (normalisation, area, vndf) = (integrand("normalisation"), integrand("projected_area"), integrand("vndf"));
    let value = |f: &WgslIntegrand, a: (f64, f64), w: DVec3| {
        let i = f.integrate(&[a.0, a.1], w).unwrap();
        assert_eq!(i.bad_parts, 0, "α {a:?} ω {w}");
        i.value
    };
    let mut out = Vec::new();
    for &a in alphas {
        let norm = rel(value(&normalisation, a, DVec3::Z), 1.0);
        for &t in thetas {
            let w = spherical(t.to_radians(), PHI);
            let at = value(&area, a, w);
            out.push(Errors {
                normalisation: norm,
                projected_area: rel(at, (1.0 + lambda(a, w)) * w.z),
                symmetry: rel(value(&area, a, DVec3::new(-w.x, -w.y, w.z)), at),
                vndf: rel(value(&vndf, a, w), 1.0),
            });
        }
    }
    out
}

/// The f32 limit on the GPU, for α from 0.01 to 2 and θ to 89.9°. Largest errors measured on
/// lavapipe: normalisation 3.8e-7, projected area 7.6e-7, symmetry 5.2e-7,
/// visible normals 6.8e-7 (Beckmann; GGX within 5.2e-7): the f32 rounding of the parts' sums
/// (the quadrature's tolerance is 2e-6 of a part). The limit leaves a factor ~13 for other GPUs'
/// f32 exp and division.
const GPU_LIMIT: f64 = 1e-5;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("the GPU identities need an adapter: {e}"))
}

#[test]
fn identities_hold_in_f32_on_the_gpu() {
    let gpu = gpu();
    let ggx = distribution_wgsl("ggx", GGX_D, GGX_G1_OVER_COS);
    let beckmann = distribution_wgsl("beckmann", BECKMANN_D, BECKMANN_G1_OVER_COS);
    let started = std::time::Instant::now();
    let g = worst("GGX f32 GPU", gpu_errors(&gpu, &ggx, |(ax, ay), w| Ggx { ax, ay }.lambda(w), &GPU_ALPHAS, &GPU_THETAS).into_iter());
    let b = worst("Beckmann f32 GPU", gpu_errors(&gpu, &beckmann, |(ax, ay), w| Beckmann { ax, ay }.lambda(w), &GPU_ALPHAS, &GPU_THETAS).into_iter());
    eprintln!("GPU identities in {:.1} s", started.elapsed().as_secs_f64());
    for (name, w) in [("GGX", g), ("Beckmann", b)] {
        assert!(w.iter().all(|&e| e < GPU_LIMIT), "{name}: {w:?} against {GPU_LIMIT:e}");
    }
}

#[test]
fn broken_wgsl_fails_the_identities_on_the_gpu() {
    let gpu = gpu();
    let ggx_lambda = |(ax, ay): (f64, f64), w: DVec3| Ggx { ax, ay }.lambda(w);
    let one = |sources: Vec<Source>| gpu_errors(&gpu, &sources, ggx_lambda, &[(0.5, 0.1)], &[80.0]).remove(0);
    // D without its 1/π
    let e = one(distribution_wgsl("ggx", "return 3.14159265 * ggx_d(a, h);", GGX_G1_OVER_COS));
    assert!(e.normalisation > 1.0, "{}", e.normalisation);
    // G1 from a Λ 10 % too large: G1 = 1 / (1 + 1.1 (1/G1 − 1))
    let e = one(distribution_wgsl("ggx", GGX_D, "let g = ggx_g1(a, w); return 1.0 / ((1.0 + 1.1 * (1.0 / g - 1.0)) * w.z);"));
    assert!(e.normalisation < GPU_LIMIT && e.vndf > 1e-3, "{} {}", e.normalisation, e.vndf);
    // D skewed toward +x: still normalised, no longer symmetric
    let e = one(distribution_wgsl("ggx", "return (1.0 + 0.5 * h.x) * ggx_d(a, h);", GGX_G1_OVER_COS));
    assert!(e.normalisation < GPU_LIMIT && e.symmetry > 1e-2, "{} {}", e.normalisation, e.symmetry);
}
