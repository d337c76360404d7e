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
use super::gpu::Passes;
use super::{CheckError, Domain, UserSampler};
use crate::engine::gpu::Gpu;
use crate::engine::gpu::params::Params;
use crate::engine::gpu::precision::Precision;
use crate::reference::light::registry::{LightParams, LightSpec};

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

/// One draw of a light's WGSL: the direction and the pdf the sampler reported, and the pdf
/// function at that direction.
#[derive(Debug, Clone, Copy)]
pub struct LightDraw {
    pub d: glam::DVec3,
    pub pdf: f64,
    pub pdf_at_d: f64,
}

/// `lobes check`'s passes over a light's WGSL (its library module, f32), composed once for any
/// number of draws.
pub struct LightPasses<'g> {
    passes: Passes<'g>,
}

impl<'g> LightPasses<'g> {
    pub fn new(gpu: &'g Gpu, spec: &LightSpec) -> Result<Self, CheckError> {
        Ok(Self { passes: Passes::new(gpu, &UserSampler::light(spec))? })
    }

    /// The draws with geometry `params` at each u: the sample map (`lobes_map`), then the pdf at
    /// the drawn directions (`lobes_conditioning`).
    pub fn draws(&self, params: &LightParams, us: &[[f64; 2]]) -> Result<Vec<LightDraw>, CheckError> {
        let p = Params { user: Params::user_numbers(params), ..bytemuck::Zeroable::zeroed() };
        let drawn = self.passes.map(&p, &us.iter().map(|u| [u[0] as f32, u[1] as f32, 0.0, 0.0]).collect::<Vec<_>>())?;
        let at = self.passes.conditioning(&p, &drawn.iter().map(|s| [s[0], s[1], s[2]]).collect::<Vec<_>>())?;
        let d = |s: &[f32; 4]| glam::DVec3::new(s[0] as f64, s[1] as f64, s[2] as f64);
        Ok(drawn.iter().zip(&at).map(|(s, a)| LightDraw { d: d(s), pdf: s[3] as f64, pdf_at_d: a[0] as f64 }).collect())
    }
}
