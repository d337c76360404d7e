//! Composes the WGSL module of a job from the files in `shaders/`, holding only the code the
//! job needs, and validates it with naga before any pipeline is made.
//!
//! A module is: the job's constants (a generated header), the library modules it needs
//! (`shaders/lib`, `shaders/math`: the RNG, the math of its precision, reflection, its sampler's
//! module and, for weighted modules, the density, Fresnel and masking modules), composed by
//! naga_oil from the files' own `#import`s ([`super::library`], which says why naga_oil), then the
//! passes (`shaders/passes`, binning) and the generated call sites that pick the sampler. The
//! passes are still joined as text after the library: they use the header's names, which are
//! not a module of their own yet.

use super::context::GpuError;
use super::layout;
use super::library;
use super::precision::{self, Precision};
use crate::engine::job::{DiscreteMethod, Job};
use crate::reference::sampler::{self, SamplerSpec};

/// The WGSL of the passes, which use the names the composed header defines (the library files,
/// `shaders/lib` and `shaders/math`, are composed by [`super::library`]).
pub mod sources {
    pub const HISTOGRAM: &str = include_str!("../../../shaders/lib/histogram.wgsl");
    pub const KERNEL: &str = include_str!("../../../shaders/passes/kernel.wgsl");
    pub const COUNTING_WORKGROUP: &str = include_str!("../../../shaders/passes/counting_workgroup.wgsl");
    pub const COUNTING_GLOBAL: &str = include_str!("../../../shaders/passes/counting_global.wgsl");
    pub const LOBE_KERNEL: &str = include_str!("../../../shaders/passes/lobe_kernel.wgsl");
    pub const WEIGHTED: &str = include_str!("../../../shaders/passes/weighted.wgsl");
    pub const LOBE_DRAW: &str = include_str!("../../../shaders/passes/lobe_draw.wgsl");
    pub const EFFECT: &str = include_str!("../../../shaders/passes/effect.wgsl");
    pub const EFFECT_FRESNEL: &str = include_str!("../../../shaders/passes/effect_fresnel.wgsl");
    pub const EFFECT_MASKING: &str = include_str!("../../../shaders/passes/effect_masking.wgsl");
}

pub use super::layout::{SAMPLES_PER_THREAD, WG_SIZE};

/// The library module of a sampler, or with `eval` that of its density and weight (which
/// imports the sampler's): `eval` false for the counting kernels, which only draw.
pub(crate) fn sampler_module(spec: &SamplerSpec, eval: bool) -> &'static str {
    if eval { spec.wgsl.eval_module } else { spec.wgsl.module }
}

/// The plain WGSL of the library `modules` with the math of `precision` (see [`library::wgsl`]).
///
/// Panics if the library does not compose: its files are built in, and the tests compose every
/// module.
pub(crate) fn library(modules: &[&str], precision: Precision) -> String {
    library::wgsl(modules, precision).unwrap_or_else(|e| panic!("{e}"))
}

/// A generated call site `fn NAME(ARGS) -> RET` returning `expr` of the sampler's
/// [`Wgsl`](crate::reference::sampler::Wgsl): directly for one sampler, for several by a
/// run-time switch on the sampler id `effect.modes.x` (the uber-kernel, `shaders/passes/weighted.wgsl`).
pub(crate) fn call_site(name: &str, args: &str, ret: &str, samplers: &[&SamplerSpec], expr: impl Fn(&sampler::Wgsl) -> String) -> String {
    if let [only] = samplers {
        return format!("fn {name}({args}) -> {ret} {{\n    return {};\n}}\n", expr(&only.wgsl));
    }
    let mut body = format!("fn {name}({args}) -> {ret} {{\n    var r: {ret};\n    switch effect.modes.x {{\n");
    for (i, s) in samplers.iter().enumerate() {
        let label = if i + 1 == samplers.len() { "default".to_string() } else { format!("case {}u", s.id()) };
        body += &format!("        {label}: {{ r = {}; }}\n", expr(&s.wgsl));
    }
    body + "    }\n    return r;\n}\n"
}

/// `sampler_sample(a, wi, u) -> LobeSample`, what `shaders/passes/lobe_kernel.wgsl` draws with.
pub(crate) fn sampler_call_site(samplers: &[&SamplerSpec]) -> String {
    call_site("sampler_sample", "a: vec2<Real>, wi: vec3<Real>, u: vec2<Real>", "LobeSample", samplers, |w| format!("{}(a, wi, u)", w.sample))
}

/// `lobe_alpha()` and `lobe_wi()`, a lobe job's α and ωi in the kernel's precision
/// (`shaders/passes/lobe_kernel.wgsl`): f32 from the uniform block, f64 as constants of the
/// job's values (the block carries f32 only, and f32(0.3) is not 0.3).
fn lobe_parameters(job: &Job, precision: Precision) -> String {
    let Job::Lobe { lobe, incident, .. } = job else { return String::new() };
    let (alpha, wi) = match precision {
        Precision::F64 => {
            let [ax, ay, x, y, z] = [lobe.alpha_x, lobe.alpha_y, incident.x, incident.y, incident.z].map(precision::lit);
            (format!("vec2<f64>({ax}, {ay})"), format!("vec3<f64>({x}, {y}, {z})"))
        }
        Precision::F32Accurate | Precision::F32Fast => ("params.alpha".to_string(), "params.wi.xyz".to_string()),
    };
    format!("fn lobe_alpha() -> vec2<Real> {{\n    return {alpha};\n}}\n\nfn lobe_wi() -> vec3<Real> {{\n    return {wi};\n}}\n")
}

/// The composed WGSL of `job`, counting all its bins.
pub fn compose(job: &Job, workgroup_words: u32) -> String {
    compose_tile(job, workgroup_words, job.bins() as u32)
}

/// The composed WGSL of `job` counting `tile_bins` bins from `params.tile_first` on (a
/// histogram too large for one storage buffer is counted tile by tile, one pass each), in
/// workgroup memory when `ceil(tile_bins / 2)` words fit in `workgroup_words`, else in global
/// memory.
pub fn compose_tile(job: &Job, workgroup_words: u32, tile_bins: u32) -> String {
    compose_precision(job, workgroup_words, tile_bins, Precision::F32Accurate)
}

/// As [`compose_tile`], in the arithmetic of `precision` (`lobes tradeoff`; see
/// [`super::precision`]).
pub fn compose_precision(job: &Job, workgroup_words: u32, tile_bins: u32, precision: Precision) -> String {
    compose_with(job, workgroup_words, tile_bins, precision, &[])
}

/// As [`compose_precision`], with the library modules `extra` too (a weighted module's density,
/// Fresnel and masking).
pub(crate) fn compose_with(job: &Job, workgroup_words: u32, tile_bins: u32, precision: Precision, extra: &[&str]) -> String {
    let mut modules = extra.to_vec();
    modules.push(match job {
        Job::Lobe { lobe, .. } => sampler_module(sampler::find(lobe.kind, lobe.method), false),
        Job::Discrete { .. } => "lobes::discrete",
    });
    let mut src = header(job, workgroup_words, tile_bins, precision, &modules);
    match job {
        Job::Lobe { lobe, .. } => {
            let spec = sampler::find(lobe.kind, lobe.method);
            src.push_str(&sampler_call_site(&[spec]));
            push_all(&mut src, &[sources::LOBE_KERNEL, sources::LOBE_DRAW]);
        }
        Job::Discrete { method, .. } => {
            let call = match method {
                DiscreteMethod::Cdf if job.bins() > crate::reference::discrete::BLOCK => {
                    "discrete_sample_cdf_blocks(u.xy, params.n_items, params.last_positive)"
                }
                DiscreteMethod::Cdf => "discrete_sample_cdf(u.x, params.n_items, params.last_positive)",
                DiscreteMethod::Alias => "discrete_sample_alias(u.xy, params.n_items)",
            };
            src.push_str(&format!(
                "\nfn draw(index: vec2<u32>) -> u32 {{\n    let u = rng_uniforms(params.seed, index);\n    return {call};\n}}\n"
            ));
        }
    }
    src
}

/// The constants, the RNG, the math of `precision`, binning and counting kernels every job's
/// module starts with, the library `modules` it draws with and, for a lobe job, its α and ωi.
pub(crate) fn header(job: &Job, workgroup_words: u32, tile_bins: u32, precision: Precision, modules: &[&str]) -> String {
    let bins = job.bins() as u32;
    let (rows, cols) = match job {
        Job::Lobe { grid, .. } => (grid.rows, grid.cols),
        Job::Discrete { .. } => (1, bins),
    };
    let wg_words = tile_bins.div_ceil(2);
    let in_workgroup = wg_words <= workgroup_words;
    let mut src = format!(
        "// Composed by lobes for {}\n\
         const ROWS: u32 = {rows}u;\nconst COLS: u32 = {cols}u;\nconst BINS: u32 = {bins}u;\n\
         const TILE_BINS: u32 = {tile_bins}u;\nconst CELLS: u32 = TILE_BINS + N_REASONS;\nconst WG_WORDS: u32 = {wg_words}u;\n{}\n",
        describe(job),
        layout::consts_wgsl()
    );
    let counting = if in_workgroup { sources::COUNTING_WORKGROUP } else { sources::COUNTING_GLOBAL };
    let mut library_modules = vec!["lobes::rng", "lobes::math", "lobes::reflect"];
    library_modules.extend(modules);
    src.push_str(&library(&library_modules, precision));
    push_all(&mut src, &[sources::HISTOGRAM, sources::KERNEL, counting]);
    src.push_str(&lobe_parameters(job, precision));
    src
}

pub(crate) fn push_all(src: &mut String, parts: &[&str]) {
    for part in parts {
        src.push_str(part);
        src.push('\n');
    }
}

/// "ggx vndf", "discrete cdf (10 items)".
pub fn describe(job: &Job) -> String {
    match job {
        Job::Lobe { lobe, .. } => format!("{} {}", lobe.kind.name(), lobe.method.name()),
        Job::Discrete { dist, method } => format!("discrete {method:?} ({} items)", dist.len()).to_lowercase(),
    }
}

/// Parses and validates a composed module with naga, so that a broken composition is a clear
/// error rather than a wgpu panic.
pub fn validate(what: &str, source: &str) -> Result<naga::Module, GpuError> {
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|e| GpuError::Shader { what: what.into(), message: e.emit_to_string(source) })?;
    // FLOAT64 for lobes::experiments::tradeoff's f64 kernels; wgpu still refuses f64 on a device without SHADER_F64.
    let caps = naga::valid::Capabilities::default() | naga::valid::Capabilities::FLOAT64;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps)
        .validate(&module)
        .map_err(|e| GpuError::Shader { what: what.into(), message: format!("{e:?}") })?;
    Ok(module)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::sampler::REGISTRY;
    use crate::reference::{Lobe, reflect};
    use crate::stats::histogram::SphereGrid;

    /// Every sampler's counting module composes and validates in each precision (without a
    /// device: naga's check), and declares `Real` as that precision's type once.
    #[test]
    fn every_sampler_composes_in_every_precision() {
        for spec in &REGISTRY {
            let lobe = Lobe { kind: spec.kind, method: spec.method, alpha_x: 0.3, alpha_y: 0.2 };
            let job = Job::Lobe { lobe, incident: reflect::spherical(0.7, 0.1), grid: SphereGrid { rows: 8, cols: 16 } };
            for precision in Precision::ALL.into_iter().filter(|&p| spec.wgsl.f64 || p != Precision::F64) {
                let src = compose_precision(&job, 4096, job.bins() as u32, precision);
                assert_eq!(src.matches("alias Real").count(), 1, "{} {}", spec.name(), precision.name());
                assert!(src.contains(&format!("alias Real = {};", precision.scalar())));
                validate(&format!("{} {}", spec.name(), precision.name()), &src).unwrap_or_else(|e| panic!("{e}"));
            }
        }
    }
}
