//! lobes' light samplers as users' samplers: a light registry entry ([`LightSpec`]) wrapped in
//! the contract of `lobes check`, so that each built-in light is judged by the same checks as a
//! renderer's light sampler (χ² against the GPU quadrature of its WGSL pdf on a cap fitted to
//! a small light, the Jacobian of its map, pdf consistency, normalization, hard cases).
//!
//! The sampler's WGSL is its library module (`shaders/lib`, with `lobes::light`), and a small
//! wrapper maps the contract to the registry's call sites: `params` is the light's geometry in
//! the layout [`LightSpec::layout`] names, `u.xy` the sampler's two uniforms; the incident
//! direction is not used (the shading point is the origin).

use super::compose::Source;
use super::{Domain, UserSampler};
use crate::engine::gpu::precision::Precision;
use crate::reference::light::registry::LightSpec;

/// The names of the wrapper's functions.
pub const SAMPLE: &str = "light_sample";
pub const PDF: &str = "light_pdf";

/// The wrapper of `spec` with the sample and pdf call sites given (a test's broken variant
/// changes them).
pub fn wrapper(spec: &LightSpec, sample: &str, pdf: &str) -> String {
    format!(
        "// lobes check's contract for lobes' {name} light (src/check/light.rs)\n\
         fn {SAMPLE}(wi: vec3<f32>, u4: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n    \
             let u = u4.xy;\n    \
             let s = {sample};\n    \
             return vec4<f32>(s.d, s.pdf);\n\
         }}\n\n\
         fn {PDF}(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n    \
             return {pdf};\n\
         }}\n",
        name = spec.name,
    )
}

impl UserSampler {
    /// The registry's light `spec` as a user's sampler on the sphere (see the module doc).
    pub fn light(spec: &LightSpec) -> Self {
        Self::light_with(spec, &wrapper(spec, spec.sample, spec.pdf))
    }

    /// The light's WGSL with another wrapper (a test's broken variant).
    pub fn light_with(spec: &LightSpec, wrapper: &str) -> Self {
        let library = crate::engine::gpu::library::wgsl(&[spec.module], Precision::F32Accurate).unwrap_or_else(|e| panic!("{e}"));
        let sources = vec![
            Source { name: format!("lobes' {} (shaders/lib)", spec.module), text: library },
            Source { name: format!("the {} light wrapper (src/check/light.rs)", spec.name), text: wrapper.to_string() },
        ];
        let s = Self { sources, sample: SAMPLE.into(), pdf: PDF.into(), eval: None, domain: Domain::Sphere, conventions: Default::default(), composition: Default::default() };
        s.validate().unwrap_or_else(|e| panic!("lobes' {} light does not meet the contract: {e}", spec.name));
        s
    }
}
