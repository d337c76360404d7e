//! lobes' own samplers as users' samplers: a registry entry ([`SamplerSpec`]) wrapped in the
//! contract of `lobes check`, so that every built-in sampler can be judged by the same checks as
//! a renderer's (the χ² test against the GPU quadrature of its WGSL pdf, the Jacobian of its
//! map, pdf consistency, normalization, hard cases), independently of `lobes run`'s f64
//! reference.
//!
//! The sampler's WGSL is its library module in f32 (`shaders/lib`, with what it imports), and a
//! small wrapper maps the contract to the registry's call sites: `params[0].xy` is (αx, αy),
//! `u.xy` the sampler's two uniforms. A reflected direction at or below the horizon is reported
//! with pdf 0, an invalid sample ("zero pdf"), as `lobes run` counts it invalid ("below
//! horizon"): its expected count is the mass the pdf leaves out.

use super::compose::Source;
use super::{Domain, UserSampler};
use crate::engine::gpu::precision::Precision;
use crate::reference::sampler::SamplerSpec;

/// The names of the wrapper's functions.
pub const SAMPLE: &str = "builtin_sample";
pub const PDF: &str = "builtin_pdf";

impl UserSampler {
    /// The registry's sampler `spec` as a user's sampler on the sphere (see the module doc).
    pub fn builtin(spec: &SamplerSpec) -> Self {
        let library = crate::engine::gpu::library::wgsl(&[spec.wgsl.eval_module], Precision::F32Accurate).unwrap_or_else(|e| panic!("{e}"));
        let wrapper = format!(
            "// lobes check's contract for lobes' {name} sampler (src/check/builtin.rs)\n\
             fn {SAMPLE}(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n    \
                 let s = {sample}(params[0].xy, wi, u.xy);\n    \
                 return vec4<f32>(s.wr, select(0.0, s.pdf_r, s.wr.z > 0.0));\n\
             }}\n\n\
             fn {PDF}(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n    \
                 let a = params[0].xy;\n    \
                 let wr = d;\n    \
                 return select(0.0, {pdf}, wr.z > 0.0);\n\
             }}\n",
            name = spec.name(),
            sample = spec.wgsl.sample,
            pdf = spec.wgsl.pdf,
        );
        let sources = vec![
            Source { name: format!("lobes' {} (shaders/lib)", spec.wgsl.eval_module), text: library },
            Source { name: format!("the {} wrapper (src/check/builtin.rs)", spec.name()), text: wrapper },
        ];
        let s = Self { sources, sample: SAMPLE.into(), pdf: PDF.into(), eval: None, domain: Domain::Sphere, conventions: Default::default(), composition: Default::default() };
        s.validate().unwrap_or_else(|e| panic!("lobes' {} sampler does not meet the contract: {e}", spec.name()));
        s
    }
}
