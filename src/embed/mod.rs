//! lobes' WGSL samplers for your own wgpu shaders.
//!
//! The code that `lobes` tests (the counter-based RNG, every lobe's sampler, densities and BRDF,
//! discrete CDF and alias sampling) is plain WGSL. [`wgsl`] returns the files a list of
//! [`Module`]s needs, each once and in dependency order, as one string that you prepend to
//! (or concatenate with) your own shader source before `create_shader_module`:
//!
//! ```
//! use lobes::embed::{self, Module};
//!
//! let mine = "
//! @group(0) @binding(0) var<storage, read_write> out: array<vec4<f32>>;
//! @compute @workgroup_size(64)
//! fn main(@builtin(global_invocation_id) id: vec3<u32>) {
//!     let u = rng_uniforms(vec2<u32>(7u, 0u), vec2<u32>(id.x, 0u));   // Module::Rng
//!     let wi = vec3<f32>(0.6, 0.0, 0.8);
//!     let s = ggx_sample_vndf(vec2<f32>(0.3), wi, u.xy);               // Module::Ggx
//!     out[id.x] = vec4<f32>(s.wr, ggx_eval(vec2<f32>(0.3), wi, s.wr) * s.wr.z / s.pdf_r);
//! }";
//! let source = embed::wgsl(&[Module::Rng, Module::Ggx]) + mine;
//! // What wgpu does on `create_shader_module`: parse and validate with naga.
//! embed::validate(&source).unwrap();
//! // Reflect and Microfacet came along as dependencies of Ggx.
//! assert_eq!(embed::resolve(&[Module::Ggx, Module::Rng]),
//!            [Module::Rng, Module::Reflect, Module::Microfacet, Module::Ggx]);
//! ```
//!
//! The library files are naga_oil modules: each names its import path (`#define_import_path
//! lobes::ggx`) and what it imports from the others (`#import lobes::reflect::{LobeSample, PI}`),
//! and lobes composes them with naga_oil, Bevy's shader composer (chosen over a resolver of our
//! own: it resolves the imports, validates every file and reports errors at the file and line,
//! and it is what Bevy renderers already use; see `crate::engine::gpu::library`). What [`wgsl`]
//! returns is still plain WGSL, since a `String` is what every wgpu renderer can take: the files
//! in import order with their directive lines blanked. Their names do not collide with each
//! other and WGSL declarations at module scope may come in any order, so no namespaces are
//! needed. It is exactly the code the χ² tests judge (the test kernels are built from the same
//! composition), plus the pdf, BRDF and estimator-weight functions of `shaders/lib/*_eval.wgsl`,
//! which `tests/embed.rs` checks against the f64 reference on the GPU. A renderer that composes
//! with naga_oil itself can take the files as they are from [`Module::source`].
//!
//! The composed code defines, at module scope, the names listed on each [`Module`] (and a few
//! helpers: everything it defines is in [`Module::symbols`]); your shader must not define them
//! again (`PI` in particular comes from [`Module::Reflect`]). Only [`Module::Discrete`] declares
//! resource bindings; choose their group and binding numbers with [`wgsl_with`] or
//! [`discrete_wgsl`], and upload its tables with [`DiscreteBuffers`].
//!
//! Conventions (as everywhere in lobes): a local shading frame with the normal on +z, ωi (`wi`)
//! the given direction and ωr (`wr`) the sampled one, both unit vectors pointing away from the
//! surface; roughness `a = vec2(alpha_x, alpha_y)`; uniforms in [0, 1] (1 included); densities
//! per unit solid angle of ωr; BRDF values without Fresnel.

mod discrete;

pub use discrete::{BLOCK, DISCRETE_INFO_WGSL, DiscreteBindings, DiscreteBuffers, DiscreteInfo, DiscreteTable};

use crate::engine::gpu::GpuError;
use crate::engine::gpu::library;
use crate::engine::gpu::precision::Precision;


/// A WGSL module of lobes, as embedded by [`wgsl`]. The listed functions are the ones meant for
/// callers; [`Module::symbols`] lists every name the module defines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Module {
    /// `shaders/lib/rng.wgsl`: counter-based uniforms, bit-identical to
    /// [`crate::reference::rng::uniforms`].
    ///
    /// - `rng_uniforms(seed: vec2<u32>, index: vec2<u32>) -> vec4<f32>`: four uniforms of sample
    ///   `index` (a 64-bit counter as (lo, hi)) of the stream keyed by `seed` (lo, hi); each a
    ///   multiple of 2⁻²⁴ in [0, 1).
    /// - `pcg4d(v: vec4<u32>) -> vec4<u32>` (Jarzynski & Olano 2020), `rng_to_unit`,
    ///   `add64(a: vec2<u32>, b: u32) -> vec2<u32>` (64-bit counter plus offset).
    Rng,
    /// `shaders/lib/reflect.wgsl`: the half vector → reflected direction change of variables.
    ///
    /// - `struct LobeSample { h: vec3<f32>, wr: vec3<f32>, pdf_r: f32 }`: what every sampler
    ///   returns: the half vector, ωr, and p(ωr). ωr may be below the horizon (`wr.z <= 0`):
    ///   such a sample carries no energy and must be discarded (or counted as zero).
    /// - `reflect_about(wi, h) -> vec3<f32>`, `reflect_sample(wi, h, pdf_h) -> LobeSample`
    ///   (p(ωr) = p(h) / (4 |ωr·h|)), `from_tan_theta`, `neg_ln`, `const PI: f32`.
    Reflect,
    /// `shaders/lib/microfacet.wgsl`: `stretch(a, w) -> vec3<f32>` = normalize(αx wx, αy wy, wz);
    /// `shaders/lib/microfacet_eval.wgsl`: the BRDF and densities of every microfacet lobe from
    /// its D and G terms (`microfacet_eval`, `microfacet_pdf_ndf`, `microfacet_pdf_vndf`).
    Microfacet,
    /// `shaders/lib/ward.wgsl` and `shaders/lib/ward_eval.wgsl`: Ward's lobe, Walter 2005's pdf.
    ///
    /// - `ward_sample(a, wi, u: vec2<f32>) -> LobeSample`;
    /// - `ward_pdf(a, wi, wr) -> f32` (the density of `ward_sample`), `ward_eval(a, wi, wr) -> f32`
    ///   (Ward's BRDF, ρs = 1), `ward_pdf_h(a, h)`, `ward_sample_h(a, u)`.
    Ward,
    /// `shaders/lib/ggx.wgsl` and `shaders/lib/ggx_eval.wgsl`: GGX (Trowbridge–Reitz).
    ///
    /// - samplers `ggx_sample_ndf`, `ggx_sample_vndf` (spherical caps, Dupuy & Benyoub 2023),
    ///   `ggx_sample_bounded` (Eto & Tokuyoshi 2023), all `(a, wi, u: vec2<f32>) -> LobeSample`;
    /// - their densities `ggx_pdf_ndf`, `ggx_pdf_vndf`, `ggx_pdf_bounded`, all
    ///   `(a, wi, wr) -> f32`;
    /// - `ggx_eval(a, wi, wr)`: D G2 / (4 cos θi cos θr) with height-correlated Smith G2;
    ///   `ggx_d(a, h)`, `ggx_g1(a, w)`, `ggx_lambda(a, w)`, `ggx_g2(a, wi, wr)`.
    Ggx,
    /// `shaders/lib/beckmann.wgsl` and `shaders/lib/beckmann_eval.wgsl`: Beckmann.
    ///
    /// - samplers `beckmann_sample_ndf`, `beckmann_sample_vndf` (Heitz & d'Eon 2014),
    ///   `(a, wi, u: vec2<f32>) -> LobeSample`;
    /// - densities `beckmann_pdf_ndf`, `beckmann_pdf_vndf`, `(a, wi, wr) -> f32`;
    /// - `beckmann_eval(a, wi, wr)`, `beckmann_d`, `beckmann_g1`, `beckmann_lambda`,
    ///   `beckmann_g2`.
    Beckmann,
    /// `shaders/lib/discrete.wgsl`: discrete 1D distributions. Declares two storage buffers,
    /// `discrete_f: array<f32>` and `discrete_u: array<u32>` (see [`DiscreteBindings`] for their
    /// numbers and [`DiscreteTable`] for their contents).
    ///
    /// - `discrete_sample_cdf(u: f32, n: u32, last_positive: u32) -> u32`: the first index whose
    ///   CDF ≥ u (binary search), for up to [`BLOCK`] items;
    /// - `discrete_sample_cdf_blocks(u: vec2<f32>, n: u32, last_positive: u32) -> u32`: the same
    ///   for longer tables, in two levels (u.x picks a block of [`BLOCK`] items, u.y the item);
    /// - `discrete_sample_alias(u: vec2<f32>, n: u32) -> u32`: Walker's alias table, column
    ///   ⌊u.x·n⌋, kept when u.y < its threshold.
    Discrete,
}

impl Module {
    /// Every module, in dependency order.
    pub const ALL: [Module; 7] =
        [Module::Rng, Module::Reflect, Module::Microfacet, Module::Ward, Module::Ggx, Module::Beckmann, Module::Discrete];

    /// The file name of the module's main source (`"ggx"` for `shaders/lib/ggx.wgsl`).
    ///
    /// ```
    /// assert_eq!(lobes::embed::Module::Ggx.name(), "ggx");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Module::Rng => "rng",
            Module::Reflect => "reflect",
            Module::Microfacet => "microfacet",
            Module::Ward => "ward",
            Module::Ggx => "ggx",
            Module::Beckmann => "beckmann",
            Module::Discrete => "discrete",
        }
    }

    /// The modules this one uses directly (each earlier in [`Module::ALL`]), from the `#import`
    /// lines of its files.
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert_eq!(Module::Beckmann.dependencies(), [Module::Reflect, Module::Microfacet]);
    /// assert!(Module::Rng.dependencies().is_empty());
    /// ```
    pub fn dependencies(self) -> Vec<Module> {
        let imported: Vec<String> = self.parts().iter().flat_map(|p| library::imports(p)).collect();
        Module::ALL.into_iter().filter(|&m| m != self && m.parts().iter().any(|p| imported.iter().any(|i| i == p))).collect()
    }

    /// The import paths of the module's files (`#define_import_path` in `shaders/lib`).
    fn parts(self) -> &'static [&'static str] {
        match self {
            Module::Rng => &["lobes::rng"],
            Module::Reflect => &["lobes::math", "lobes::reflect"],
            Module::Microfacet => &["lobes::microfacet", "lobes::microfacet_eval"],
            Module::Ward => &["lobes::ward", "lobes::ward_eval"],
            Module::Ggx => &["lobes::ggx", "lobes::ggx_eval"],
            Module::Beckmann => &["lobes::erf", "lobes::beckmann", "lobes::beckmann_eval"],
            Module::Discrete => &["lobes::discrete"],
        }
    }

    /// The module's files as naga_oil reads them (without its dependencies; [`wgsl`] adds
    /// those): naga_oil modules, WGSL with `#define_import_path` and `#import` directives, for a
    /// renderer that composes its shaders with naga_oil. They are the files of `shaders/` with
    /// the type `Real` spelled `f32` (naga_oil cannot hold the files' `alias Real = f32;`: see
    /// `engine::gpu::library`). [`Module::Discrete`] comes with its bindings at group 0, bindings
    /// 3 and 4.
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert!(Module::Ggx.source().contains("fn ggx_sample_vndf("));
    /// assert!(Module::Ggx.source().contains("fn ggx_pdf_vndf("));
    /// assert!(Module::Ggx.source().contains("#define_import_path lobes::ggx_eval"));
    /// ```
    pub fn source(self) -> String {
        self.parts().iter().map(|p| library::naga_oil_source(p).expect("a library module")).collect::<Vec<_>>().join("\n")
    }

    /// Every name the module declares at module scope (functions, constants, structs, globals),
    /// found by parsing [`Module::source`] with its dependencies with naga: the names your shader
    /// must not reuse.
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert!(Module::Reflect.symbols().contains(&"PI".to_string()));
    /// assert!(Module::Ggx.symbols().contains(&"ggx_eval".to_string()));
    /// assert!(!Module::Ggx.symbols().contains(&"PI".to_string())); // that one is Reflect's
    /// ```
    pub fn symbols(self) -> Vec<String> {
        let deps: Vec<Module> = resolve(&[self]).into_iter().filter(|&m| m != self).collect();
        let all = names(&wgsl(&resolve(&[self])));
        let before = names(&wgsl(&deps));
        all.into_iter().filter(|n| !before.contains(n)).collect()
    }
}

/// Names declared at module scope of a WGSL source (parsed by naga; empty if it does not parse).
fn names(source: &str) -> Vec<String> {
    let Ok(m) = naga::front::wgsl::parse_str(source) else { return Vec::new() };
    let mut out: Vec<String> = Vec::new();
    out.extend(m.functions.iter().filter_map(|(_, f)| f.name.clone()));
    out.extend(m.constants.iter().filter_map(|(_, c)| c.name.clone()));
    out.extend(m.global_variables.iter().filter_map(|(_, g)| g.name.clone()));
    out.extend(m.types.iter().filter_map(|(_, t)| match t.inner {
        naga::TypeInner::Struct { .. } => t.name.clone(),
        _ => None,
    }));
    out.sort();
    out.dedup();
    out
}

/// `modules` with all their dependencies, each once, in dependency order (the order of
/// [`Module::ALL`]).
///
/// ```
/// use lobes::embed::{resolve, Module};
/// assert_eq!(resolve(&[Module::Ward]), [Module::Reflect, Module::Ward]);
/// assert_eq!(resolve(&[Module::Discrete, Module::Discrete]), [Module::Discrete]);
/// ```
pub fn resolve(modules: &[Module]) -> Vec<Module> {
    let mut wanted = [false; Module::ALL.len()];
    fn mark(m: Module, wanted: &mut [bool; Module::ALL.len()]) {
        if !wanted[m as usize] {
            wanted[m as usize] = true;
            for d in m.dependencies() {
                mark(d, wanted);
            }
        }
    }
    for &m in modules {
        mark(m, &mut wanted);
    }
    Module::ALL.into_iter().filter(|&m| wanted[m as usize]).collect()
}

/// The WGSL of `modules` and their dependencies, each once, in dependency order, with
/// [`Module::Discrete`]'s buffers at their default numbers ([`DiscreteBindings::default`]:
/// group 0, bindings 3 and 4). Append your own code; see the [module documentation](self).
///
/// ```
/// use lobes::embed::{self, Module};
/// let src = embed::wgsl(&[Module::Beckmann]);
/// assert!(src.find("fn reflect_about(").unwrap() < src.find("fn beckmann_sample_vndf(").unwrap());
/// embed::validate(&src).unwrap();
/// ```
pub fn wgsl(modules: &[Module]) -> String {
    wgsl_with(modules, DiscreteBindings::default())
}

/// As [`wgsl`], with [`Module::Discrete`]'s two storage buffers at the given group and binding
/// numbers (see [`discrete_wgsl`]).
///
/// ```
/// use lobes::embed::{self, DiscreteBindings, Module};
/// let b = DiscreteBindings { group: 1, table: 0, alias: 1 };
/// let src = embed::wgsl_with(&[Module::Rng, Module::Discrete], b);
/// assert!(src.contains("@group(1) @binding(0) var<storage, read> discrete_f: array<f32>;"));
/// assert!(src.contains("@group(1) @binding(1) var<storage, read> discrete_u: array<u32>;"));
/// embed::validate(&src).unwrap();
/// ```
pub fn wgsl_with(modules: &[Module], discrete: DiscreteBindings) -> String {
    let resolved = resolve(modules);
    let names: Vec<&str> = resolved.iter().map(|m| m.name()).collect();
    let mut out = format!(
        "// lobes {} (lobes::embed): {}\n// Conventions: normal +z; wi given, wr sampled, both unit and pointing away; a = (alpha_x, alpha_y).\n",
        env!("CARGO_PKG_VERSION"),
        names.join(", ")
    );
    // the library composes every module but Discrete, whose bindings are the caller's
    let paths: Vec<&str> = resolved.iter().filter(|&&m| m != Module::Discrete).flat_map(|m| m.parts().iter().copied()).collect();
    if !paths.is_empty() {
        out.push_str(&library::wgsl(&paths, Precision::F32Accurate).unwrap_or_else(|e| panic!("{e}")));
    }
    if resolved.contains(&Module::Discrete) {
        out.push_str("// ---- shaders/lib/discrete.wgsl ----\n");
        out.push_str(&discrete_wgsl(discrete));
    }
    out
}

/// `shaders/lib/discrete.wgsl` with its two storage buffers at `bindings`: the f32 table
/// (`discrete_f`) at `@group(bindings.group) @binding(bindings.table)` and the u32 aliases
/// (`discrete_u`) at `@binding(bindings.alias)`. The sampling functions are unchanged.
///
/// ```
/// use lobes::embed::{discrete_wgsl, DiscreteBindings};
/// let src = discrete_wgsl(DiscreteBindings { group: 2, table: 7, alias: 8 });
/// assert!(src.contains("@group(2) @binding(7) var<storage, read> discrete_f"));
/// assert!(src.contains("@group(2) @binding(8) var<storage, read> discrete_u"));
/// assert!(!src.contains("@group(0)"));
/// ```
pub fn discrete_wgsl(bindings: DiscreteBindings) -> String {
    let mut found = [false; 2];
    let file = library::plain(library::source("lobes::discrete").expect("shaders/lib/discrete.wgsl"));
    let mut out = String::with_capacity(file.len() + 16);
    for line in file.lines() {
        let var = line.find("var<storage");
        let which = [("discrete_f", bindings.table, 0), ("discrete_u", bindings.alias, 1)]
            .into_iter()
            .find(|(name, _, _)| var.is_some() && line.contains(&format!("> {name}:")));
        match (var, which) {
            (Some(at), Some((_, binding, k))) => {
                found[k] = true;
                out.push_str(&format!("@group({}) @binding({binding}) {}", bindings.group, &line[at..]));
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    assert!(found == [true, true], "shaders/lib/discrete.wgsl no longer declares discrete_f and discrete_u");
    out
}

/// Parses and validates WGSL with naga, as wgpu does on `create_shader_module`; the error
/// carries naga's message with the source location.
///
/// ```
/// assert!(lobes::embed::validate("fn f() -> f32 { return ggx_d(vec2(0.1), vec3(0.0, 0.0, 1.0)); }").is_err());
/// ```
pub fn validate(source: &str) -> Result<(), GpuError> {
    crate::engine::gpu::compose::validate("embedded lobes WGSL", source).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_module_composes_and_validates_alone_and_together() {
        for m in Module::ALL {
            validate(&wgsl(&[m])).unwrap_or_else(|e| panic!("{m:?}: {e}"));
        }
        validate(&wgsl(&Module::ALL)).unwrap();
    }

    /// A renderer's naga_oil composes the modules' files and a shader that imports from them.
    #[test]
    fn sources_compose_with_naga_oil() {
        use naga_oil::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor};
        let mut composer = Composer::default();
        for p in Module::ALL.iter().filter(|&&m| m != Module::Discrete).flat_map(|m| m.parts()) {
            let source = library::naga_oil_source(p).unwrap();
            if let Err(e) = composer.add_composable_module(ComposableModuleDescriptor { source: &source, file_path: p, ..Default::default() }) {
                panic!("{p}: {}", e.emit_to_string(&composer));
            }
        }
        let shader = "#import lobes::beckmann::beckmann_sample_vndf\n#import lobes::ggx_eval::ggx_eval\n\
                      @compute @workgroup_size(1) fn main() {\n\
                      let s = beckmann_sample_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), vec2(0.5));\n\
                      let f = ggx_eval(vec2(0.3), vec3(0.0, 0.0, 1.0), s.wr);\n}\n";
        if let Err(e) = composer.make_naga_module(NagaModuleDescriptor { source: shader, file_path: "renderer.wgsl", ..Default::default() }) {
            panic!("{}", e.emit_to_string(&composer));
        }
    }

    #[test]
    fn dependencies_come_earlier() {
        for m in Module::ALL {
            for d in m.dependencies() {
                assert!(d < m, "{m:?} depends on {d:?}");
            }
        }
    }

    #[test]
    fn no_name_is_declared_by_two_modules() {
        let mut seen: Vec<(String, Module)> = Vec::new();
        for m in Module::ALL {
            for s in m.symbols() {
                assert!(!seen.iter().any(|(n, _)| *n == s), "{s} declared twice");
                seen.push((s, m));
            }
        }
        assert!(seen.len() > 40);
    }

    #[test]
    fn documented_functions_exist() {
        let wanted = [
            (Module::Rng, &["rng_uniforms", "pcg4d", "add64"][..]),
            (Module::Reflect, &["LobeSample", "reflect_about", "reflect_sample", "PI"]),
            (Module::Ward, &["ward_sample", "ward_pdf", "ward_eval"]),
            (
                Module::Ggx,
                &["ggx_sample_ndf", "ggx_sample_vndf", "ggx_sample_bounded", "ggx_pdf_ndf", "ggx_pdf_vndf", "ggx_pdf_bounded", "ggx_eval", "ggx_g2", "ggx_lambda"],
            ),
            (Module::Beckmann, &["beckmann_sample_ndf", "beckmann_sample_vndf", "beckmann_pdf_ndf", "beckmann_pdf_vndf", "beckmann_eval", "beckmann_g2"]),
            (Module::Discrete, &["discrete_sample_cdf", "discrete_sample_cdf_blocks", "discrete_sample_alias", "discrete_f", "discrete_u"]),
        ];
        for (m, names) in wanted {
            let s = m.symbols();
            for n in names {
                assert!(s.iter().any(|x| x == n), "{m:?} lacks {n}: {s:?}");
            }
        }
    }

    #[test]
    fn default_discrete_bindings_leave_the_file_unchanged() {
        let file = library::plain(library::source("lobes::discrete").unwrap());
        assert_eq!(discrete_wgsl(DiscreteBindings::default()).trim_end(), file.trim_end());
    }
}
