//! lobes' WGSL samplers for your own wgpu shaders.
//!
//! The code that `lobes` tests (the counter-based RNG, every lobe's sampler, densities and BRDF,
//! Fresnel and masking terms, discrete CDF and alias sampling) is plain WGSL. [`wgsl`] returns
//! the files a list of [`Module`]s needs, each once and in dependency order, as one string that
//! you prepend to (or concatenate with) your own shader source before `create_shader_module`.
//! Every name it defines carries the `lobes` prefix ([`prefixed`]: `lobes_ggx_sample_vndf`,
//! `LOBES_PI`, `LobesLobeSample`), so your shader may have its own `PI`, `sample` or `stretch`:
//!
//! ```
//! use lobes::embed::{self, Module};
//!
//! let mine = "
//! const PI: f32 = 3.14159265;            // the renderer's own names stay free
//! fn stretch(x: f32) -> f32 { return 2.0 * x; }
//! @group(0) @binding(0) var<storage, read_write> out: array<vec4<f32>>;
//! @compute @workgroup_size(64)
//! fn main(@builtin(global_invocation_id) id: vec3<u32>) {
//!     let u = lobes_rng_uniforms(vec2<u32>(7u, 0u), vec2<u32>(id.x, 0u));   // Module::Rng
//!     let wi = vec3<f32>(0.6, 0.0, 0.8);
//!     let s = lobes_ggx_sample_vndf(vec2<f32>(0.3), wi, u.xy);               // Module::Ggx
//!     out[id.x] = vec4<f32>(s.wr, lobes_ggx_eval(vec2<f32>(0.3), wi, s.wr) * s.wr.z / s.pdf_r);
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
//! and lobes composes them with naga_oil, Bevy's shader composer (see
//! `crate::engine::gpu::library`). What [`wgsl`] returns is plain WGSL, since a `String` is what
//! every wgpu renderer can take: the files in import order with their directive lines blanked,
//! and every module-scope name prefixed. The prefix is added on export, by renaming identifier
//! tokens of that text (see `namespace.rs`), not written into the files: the files stay the
//! short-named naga_oil modules that lobes' kernels and tests compose, and a unit test parses
//! the plain and the prefixed text with naga and finds the same IR up to the names. So what
//! you embed is exactly the code the χ² tests judge (the test kernels are built from the same
//! composition), plus the pdf, BRDF and estimator-weight functions of
//! `shaders/lib/*_eval.wgsl` and the Fresnel and masking terms, which `tests/embed.rs` checks
//! against the f64 reference on the GPU.
//!
//! A renderer that composes with naga_oil (or Bevy) takes the files as naga_oil modules instead,
//! from [`naga_oil_modules`], and imports what it uses (`#import lobes::ggx::ggx_sample_vndf`):
//! naga_oil namespaces by import path, so those keep their short names.
//!
//! Everything [`wgsl`] defines is in [`Module::symbols`]. Only [`Module::Discrete`] declares
//! resource bindings; choose their group and binding numbers with [`wgsl_with`] or
//! [`discrete_wgsl`], add more tables under names of your own with [`discrete_table_wgsl`], and
//! upload tables with [`DiscreteBuffers`].
//!
//! Conventions (as everywhere in lobes): a local shading frame with the normal on +z, ωi (`wi`)
//! the given direction and ωr (`wr`) the sampled one, both unit vectors pointing away from the
//! surface; roughness `a = vec2(alpha_x, alpha_y)`; uniforms in [0, 1] (1 included); densities
//! per unit solid angle of ωr; BRDF values without Fresnel.

mod discrete;
mod namespace;

pub use discrete::{BLOCK, DISCRETE_INFO_WGSL, DiscreteBindings, DiscreteBuffers, DiscreteInfo, DiscreteTable};
pub use namespace::prefixed;

use crate::engine::gpu::GpuError;
use crate::engine::gpu::library;
use crate::engine::gpu::precision::Precision;


/// A WGSL module of lobes, as embedded by [`wgsl`]. The listed functions are the ones meant for
/// callers, under the files' short names; [`wgsl`] exports each as [`prefixed`]`("lobes", name)`
/// (`rng_uniforms` → `lobes_rng_uniforms`, `PI` → `LOBES_PI`, `LobeSample` →
/// `LobesLobeSample`), the names naga_oil imports ([`naga_oil_modules`]) are the short ones.
/// [`Module::symbols`] lists every name the module exports.
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
    /// `shaders/lib/fresnel.wgsl`: Fresnel reflectance at cos θ = ωi·h (CPU twin:
    /// [`crate::reference::fresnel`]), each in [0, 1].
    ///
    /// - `fresnel_schlick(c: f32, f0: f32) -> f32` (Schlick 1994, eq. 24);
    /// - `fresnel_dielectric(c: f32, eta: f32) -> f32` (relative index η = nt / ni; 1 past the
    ///   critical angle), `fresnel_dielectric_transmittance(c, eta)` (1 − F without its
    ///   cancellation near the critical angle), `fresnel_cos_transmitted(c, eta)` (Snell's
    ///   cos θt, −1 past the critical angle);
    /// - `fresnel_conductor(c: f32, eta: f32, k: f32) -> f32` (complex index η + ik).
    Fresnel,
    /// `shaders/lib/masking.wgsl`: Smith masking-shadowing G2 from the two masking terms G1(ωi),
    /// G1(ωr) (CPU twin: [`crate::reference::masking`]).
    ///
    /// - `masking_separable(gi: f32, gr: f32) -> f32`: G1(ωi) G1(ωr) (Heitz 2014, eq. 98);
    /// - `masking_height_correlated(gi: f32, gr: f32) -> f32`: 1 / (1 + Λ(ωi) + Λ(ωr))
    ///   (Heitz 2014, eq. 99);
    /// - `masking_height_correlated_transmitted(gi: f32, go: f32) -> f32`: the same across a
    ///   rough dielectric's surface, B(1 + Λ(ωi), 1 + Λ(ωo)), from `masking_ln_beta(x, y)`
    ///   (ln of Euler's Beta function for x, y ≥ 1, without cancellation in f32).
    Masking,
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
    pub const ALL: [Module; 9] = [
        Module::Rng,
        Module::Reflect,
        Module::Microfacet,
        Module::Ward,
        Module::Ggx,
        Module::Beckmann,
        Module::Fresnel,
        Module::Masking,
        Module::Discrete,
    ];

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
            Module::Fresnel => "fresnel",
            Module::Masking => "masking",
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
        let imported: Vec<String> = self.import_paths().iter().flat_map(|p| library::imports(p)).collect();
        Module::ALL.into_iter().filter(|&m| m != self && m.import_paths().iter().any(|p| imported.iter().any(|i| i == p))).collect()
    }

    /// The import paths of the module's files (`#define_import_path` in `shaders/lib`), the
    /// paths of its [`naga_oil_modules`].
    ///
    /// ```
    /// assert_eq!(lobes::embed::Module::Ggx.import_paths(), ["lobes::ggx", "lobes::ggx_eval"]);
    /// ```
    pub fn import_paths(self) -> &'static [&'static str] {
        match self {
            Module::Rng => &["lobes::rng"],
            Module::Reflect => &["lobes::math", "lobes::reflect"],
            Module::Microfacet => &["lobes::microfacet", "lobes::microfacet_eval"],
            Module::Ward => &["lobes::ward", "lobes::ward_eval"],
            Module::Ggx => &["lobes::ggx", "lobes::ggx_eval"],
            Module::Beckmann => &["lobes::erf", "lobes::beckmann", "lobes::beckmann_eval"],
            Module::Fresnel => &["lobes::fresnel"],
            Module::Masking => &["lobes::masking"],
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
        self.import_paths().iter().map(|p| library::naga_oil_source(p).expect("a library module")).collect::<Vec<_>>().join("\n")
    }

    /// The module named `name` (its [`Module::name`]).
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert_eq!(Module::from_name("ggx"), Some(Module::Ggx));
    /// assert_eq!(Module::from_name("GGX"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Module> {
        Module::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Every name the module exports at module scope (functions, constants, structs, type
    /// aliases, globals), prefixed as [`wgsl`] writes them: the names your shader must not reuse.
    /// The list is found by parsing the module's files with naga; it is the one list [`wgsl`]
    /// renames by.
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert!(Module::Reflect.symbols().contains(&"LOBES_PI".to_string()));
    /// assert!(Module::Ggx.symbols().contains(&"lobes_ggx_eval".to_string()));
    /// assert!(!Module::Ggx.symbols().contains(&"LOBES_PI".to_string())); // that one is Reflect's
    /// ```
    pub fn symbols(self) -> Vec<String> {
        self.short_names().iter().map(|n| prefixed(PREFIX, n)).collect()
    }

    /// The names the module's files declare at module scope (the short, unprefixed ones).
    fn short_names(self) -> Vec<String> {
        let deps: Vec<Module> = resolve(&[self]).into_iter().filter(|&m| m != self).collect();
        let before = names(&short_wgsl(&deps));
        names(&short_wgsl(&[self])).into_iter().filter(|n| !before.contains(n)).collect()
    }
}

/// The prefix of every exported name ([`prefixed`]).
const PREFIX: &str = "lobes";

/// Names declared at module scope of a WGSL source: parsed by naga (empty if it does not parse),
/// and the `alias` declarations, which naga resolves away.
fn names(source: &str) -> Vec<String> {
    let Ok(m) = naga::front::wgsl::parse_str(source) else { return Vec::new() };
    let mut out: Vec<String> = Vec::new();
    out.extend(m.functions.iter().filter_map(|(_, f)| f.name.clone()));
    out.extend(m.constants.iter().filter_map(|(_, c)| c.name.clone()));
    out.extend(m.overrides.iter().filter_map(|(_, c)| c.name.clone()));
    out.extend(m.global_variables.iter().filter_map(|(_, g)| g.name.clone()));
    out.extend(m.types.iter().filter_map(|(_, t)| match t.inner {
        naga::TypeInner::Struct { .. } => t.name.clone(),
        _ => None,
    }));
    let alias = |l: &str| l.strip_prefix("alias ").and_then(|r| r.split(|c: char| !(c.is_alphanumeric() || c == '_')).next()).map(str::to_string);
    out.extend(source.lines().filter_map(|l| alias(l.trim_start())));
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
/// assert!(src.find("fn lobes_reflect_about(").unwrap() < src.find("fn lobes_beckmann_sample_vndf(").unwrap());
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
/// assert!(src.contains("@group(1) @binding(0) var<storage, read> lobes_discrete_f: array<f32>;"));
/// assert!(src.contains("@group(1) @binding(1) var<storage, read> lobes_discrete_u: array<u32>;"));
/// embed::validate(&src).unwrap();
/// ```
pub fn wgsl_with(modules: &[Module], discrete: DiscreteBindings) -> String {
    let resolved = resolve(modules);
    let listed: Vec<&str> = resolved.iter().map(|m| m.name()).collect();
    let mut out = format!(
        "// lobes {} (lobes::embed): {}; every name lobes defines starts with lobes_, Lobes or LOBES_.\n\
         // Conventions: normal +z; wi given, wr sampled, both unit and pointing away; a = (alpha_x, alpha_y).\n",
        env!("CARGO_PKG_VERSION"),
        listed.join(", ")
    );
    // the library composes every module but Discrete, whose bindings and names are the caller's
    let library: Vec<Module> = resolved.iter().copied().filter(|&m| m != Module::Discrete).collect();
    let short = short_wgsl(&library);
    let defined: Vec<String> = library.iter().flat_map(|m| m.short_names()).collect();
    out.push_str(&namespace::rename(&short, |t| defined.iter().any(|d| d == t).then(|| prefixed(PREFIX, t))));
    if resolved.contains(&Module::Discrete) {
        out.push_str("// ---- shaders/lib/discrete.wgsl ----\n");
        out.push_str(&discrete_wgsl(discrete));
    }
    out
}

/// The files of `modules` and their dependencies as plain WGSL under their own short names
/// (what lobes' kernels compose), [`Module::Discrete`] at its default bindings.
fn short_wgsl(modules: &[Module]) -> String {
    let resolved = resolve(modules);
    let paths: Vec<&str> = resolved.iter().filter(|&&m| m != Module::Discrete).flat_map(|m| m.import_paths().iter().copied()).collect();
    let mut out = String::new();
    if !paths.is_empty() {
        out.push_str(&library::wgsl(&paths, Precision::F32Accurate).unwrap_or_else(|e| panic!("{e}")));
    }
    if resolved.contains(&Module::Discrete) {
        out.push_str(&discrete_file(DiscreteBindings::default()));
    }
    out
}

/// `shaders/lib/discrete.wgsl` with its two storage buffers at `bindings`: the table named
/// `discrete` of [`discrete_table_wgsl`], the one [`wgsl_with`] includes.
///
/// ```
/// use lobes::embed::{discrete_wgsl, DiscreteBindings};
/// let src = discrete_wgsl(DiscreteBindings { group: 2, table: 7, alias: 8 });
/// assert!(src.contains("@group(2) @binding(7) var<storage, read> lobes_discrete_f"));
/// assert!(src.contains("@group(2) @binding(8) var<storage, read> lobes_discrete_u"));
/// assert!(src.contains("fn lobes_discrete_sample_alias("));
/// assert!(!src.contains("@group(0)"));
/// ```
pub fn discrete_wgsl(bindings: DiscreteBindings) -> String {
    discrete_table_wgsl("discrete", bindings)
}

/// `shaders/lib/discrete.wgsl` as a table of its own, named `name`, with its two storage
/// buffers at `bindings`: every name the file defines is exported under the prefix
/// `lobes_{name}` with the file's `discrete_` dropped (`discrete_sample_alias` →
/// `lobes_{name}_sample_alias`, `discrete_f` → `lobes_{name}_f`, `DISCRETE_BLOCK` →
/// `LOBES_{NAME}_BLOCK`). Append one per table to sample several distributions in one shader
/// (each with its own [`DiscreteBuffers`] at its own bindings); the name `discrete` gives the
/// names of [`wgsl_with`].
///
/// # Panics
///
/// If `name` is not a lower-case WGSL identifier (`[a-z][a-z0-9_]*`).
///
/// ```
/// use lobes::embed::{self, discrete_table_wgsl, DiscreteBindings, Module};
/// let lights = discrete_table_wgsl("lights", DiscreteBindings { group: 1, table: 0, alias: 1 });
/// let texels = discrete_table_wgsl("texels", DiscreteBindings { group: 1, table: 2, alias: 3 });
/// assert!(lights.contains("@group(1) @binding(0) var<storage, read> lobes_lights_f: array<f32>;"));
/// assert!(texels.contains("fn lobes_texels_sample_cdf_blocks("));
/// embed::validate(&(embed::wgsl(&[Module::Rng]) + &lights + &texels)).unwrap();
/// ```
pub fn discrete_table_wgsl(name: &str, bindings: DiscreteBindings) -> String {
    let valid = name.starts_with(|c: char| c.is_ascii_lowercase()) && name.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
    assert!(valid, "discrete table name {name:?}: expected a lower-case WGSL identifier ([a-z][a-z0-9_]*)");
    let prefix = format!("{PREFIX}_{name}");
    let defined = Module::Discrete.short_names();
    namespace::rename(&discrete_file(bindings), |t| {
        defined.iter().any(|d| d == t).then(|| prefixed(&prefix, t.strip_prefix("discrete_").or_else(|| t.strip_prefix("DISCRETE_")).unwrap_or(t)))
    })
}

/// The plain `shaders/lib/discrete.wgsl` (short names) with its two storage buffers at
/// `bindings`: `discrete_f` at `@group(bindings.group) @binding(bindings.table)` and
/// `discrete_u` at `@binding(bindings.alias)`.
fn discrete_file(bindings: DiscreteBindings) -> String {
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

/// One of lobes' files as a naga_oil module, for a renderer that composes its shaders with
/// naga_oil (or Bevy, whose shader imports are naga_oil's): add each with
/// `Composer::add_composable_module(m.descriptor())`, then `#import lobes::ggx::ggx_sample_vndf`
/// (or any name of [`Module::source`]) in your shader. naga_oil keeps modules apart by import
/// path, so these carry the files' short names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NagaOilModule {
    /// The path its `#define_import_path` names (`"lobes::ggx"`).
    pub import_path: &'static str,
    /// The module's text: WGSL with naga_oil's `#define_import_path` and `#import` directives.
    pub source: String,
}

impl NagaOilModule {
    /// The descriptor for `naga_oil::compose::Composer::add_composable_module` (naga_oil 0.23),
    /// with the import path as the file path that naga_oil's messages name.
    pub fn descriptor(&self) -> naga_oil::compose::ComposableModuleDescriptor<'_> {
        naga_oil::compose::ComposableModuleDescriptor { source: &self.source, file_path: self.import_path, ..Default::default() }
    }
}

/// Every file of every [`Module`] as a naga_oil module (see [`NagaOilModule`]), each after the
/// modules it imports (the order naga_oil's `add_composable_module` needs). They are
/// [`Module::source`]'s: spelled in f32 (naga_oil cannot import the files' `alias Real`), and
/// [`Module::Discrete`] with its buffers at group 0, bindings 3 and 4.
///
/// ```
/// use naga_oil::compose::{Composer, NagaModuleDescriptor};
/// let mut composer = Composer::default();
/// for m in lobes::embed::naga_oil_modules() {
///     composer.add_composable_module(m.descriptor()).unwrap();
/// }
/// let shader = "#import lobes::ggx::ggx_sample_vndf
/// const PI: f32 = 3.0; // the renderer's own
/// @compute @workgroup_size(1) fn main() {
///     let s = ggx_sample_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), vec2(0.5 / PI));
/// }";
/// composer.make_naga_module(NagaModuleDescriptor { source: shader, file_path: "mine.wgsl", ..Default::default() }).unwrap();
/// ```
pub fn naga_oil_modules() -> Vec<NagaOilModule> {
    Module::ALL
        .iter()
        .flat_map(|m| m.import_paths())
        .map(|&p| NagaOilModule { import_path: p, source: library::naga_oil_source(p).expect("a library module") })
        .collect()
}

/// Parses and validates WGSL with naga, as wgpu does on `create_shader_module`; the error
/// carries naga's message with the source location.
///
/// ```
/// assert!(lobes::embed::validate("fn f() -> f32 { return ggx_d(vec2(0.1), vec3(0.0, 0.0, 1.0)); }").is_err());
/// ```
pub fn validate(source: &str) -> Result<(), GpuError> {
    library::validate_module("embedded lobes WGSL", source).map(|_| ())
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

    /// A renderer's naga_oil composes the modules of [`naga_oil_modules`] and a shader that
    /// imports from them and has names of its own that lobes' files also use.
    #[test]
    fn naga_oil_modules_compose_with_a_renderer_shader() {
        use naga_oil::compose::{Composer, NagaModuleDescriptor};
        let mut composer = Composer::default();
        let modules = naga_oil_modules();
        for m in &modules {
            if let Err(e) = composer.add_composable_module(m.descriptor()) {
                panic!("{}: {}", m.import_path, e.emit_to_string(&composer));
            }
        }
        let paths: Vec<&str> = modules.iter().map(|m| m.import_path).collect();
        for wanted in ["lobes::rng", "lobes::ggx", "lobes::fresnel", "lobes::masking", "lobes::discrete"] {
            assert!(paths.contains(&wanted), "{paths:?}");
        }
        let shader = "#import lobes::beckmann::beckmann_sample_vndf\n#import lobes::ggx_eval::ggx_eval\n#import lobes::ggx::ggx_g1\n\
                      #import lobes::fresnel::fresnel_schlick\n#import lobes::masking::masking_height_correlated\n\
                      #import lobes::rng::rng_uniforms\n#import lobes::discrete::discrete_sample_alias\n\
                      const PI: f32 = 3.0;\nfn stretch(x: f32) -> f32 { return x; }\nfn pcg4d(x: u32) -> u32 { return x; }\n\
                      @compute @workgroup_size(1) fn main() {\n\
                      let u = rng_uniforms(vec2(1u, 2u), vec2(3u, 0u));\n\
                      let s = beckmann_sample_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), u.xy);\n\
                      let f = ggx_eval(vec2(0.3), vec3(0.0, 0.0, 1.0), s.wr) * fresnel_schlick(s.wr.z, 0.04 * PI);\n\
                      let g = masking_height_correlated(ggx_g1(vec2(0.3), s.wr), 0.5) + stretch(f);\n\
                      let k = discrete_sample_alias(u.zw, pcg4d(4u));\n}\n";
        match composer.make_naga_module(NagaModuleDescriptor { source: shader, file_path: "renderer.wgsl", ..Default::default() }) {
            Ok(module) => {
                let caps = naga::valid::Capabilities::default();
                naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps).validate(&module).unwrap();
            }
            Err(e) => panic!("{}", e.emit_to_string(&composer)),
        }
    }

    /// naga's IR of a source as text, without the source positions (which the rename moves).
    fn ir(source: &str) -> String {
        let module = naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
        let text = format!("{module:#?}");
        let mut out = String::with_capacity(text.len());
        let mut rest = text.as_str();
        while let Some(at) = rest.find("Span {") {
            out.push_str(&rest[..at]);
            let end = rest[at..].find('}').unwrap();
            rest = &rest[at + end + 1..];
        }
        out + rest
    }

    /// The IR of `plain` with every name `n` in it (functions, constants, globals, structs,
    /// and any local of the same name) read as `to(n)`, equals the IR of `renamed`.
    fn assert_same_ir_up_to_names(plain: &str, renamed: &str, names: &[String], to: impl Fn(&str) -> String) {
        let mut expected = ir(plain);
        for n in names {
            expected = expected.replace(&format!("\"{n}\""), &format!("\"{}\"", to(n)));
        }
        let got = ir(renamed);
        assert!(expected.len() > 10_000, "{} bytes of IR", expected.len());
        if expected != got {
            let line = expected.lines().zip(got.lines()).position(|(a, b)| a != b).unwrap_or(0);
            let window = |t: &str| t.lines().skip(line.saturating_sub(5)).take(10).collect::<Vec<_>>().join("\n");
            panic!("IR differs at line {line}:\nexpected\n{}\ngot\n{}", window(&expected), window(&got));
        }
    }

    /// What [`wgsl`] exports is the composed code lobes' kernels run, with only the names changed:
    /// the same functions, constants, globals and types in the same order, and the same
    /// expressions and statements in each function.
    #[test]
    fn exported_wgsl_is_the_composed_code_up_to_names() {
        let library: Vec<Module> = Module::ALL.into_iter().filter(|&m| m != Module::Discrete).collect();
        let names: Vec<String> = library.iter().flat_map(|m| m.short_names()).collect();
        let exported = wgsl(&library);
        assert_same_ir_up_to_names(&short_wgsl(&library), &exported, &names, |n| prefixed(PREFIX, n));
        assert!(exported.contains("fn lobes_ggx_sample_vndf(") && exported.contains("const LOBES_PI") && exported.contains("struct LobesLobeSample"));
        // a discrete table under a name of its own
        let names = Module::Discrete.short_names();
        let lights = discrete_table_wgsl("lights", DiscreteBindings::default());
        let table = |n: &str| prefixed("lobes_lights", n.strip_prefix("discrete_").or_else(|| n.strip_prefix("DISCRETE_")).unwrap_or(n));
        assert_same_ir_up_to_names(&discrete_file(DiscreteBindings::default()), &lights, &names, table);
        assert!(lights.contains("fn lobes_lights_sample_alias(") && lights.contains("LOBES_LIGHTS_BLOCK"), "{lights}");
    }

    /// A renderer's shader that defines, for itself, every short name of lobes' files (and
    /// `sample`) validates together with everything [`wgsl`] exports.
    #[test]
    fn a_renderer_with_lobes_short_names_of_its_own_composes_with_the_export() {
        let mut mine = String::from("struct LobeSample { x: f32 }\nconst PI: f32 = 3.0;\nfn stretch(x: f32) -> f32 { return x * PI; }\n\
                                     fn sample(s: LobeSample) -> f32 { return stretch(s.x); }\nfn pcg4d(x: u32) -> u32 { return x; }\n\
                                     fn rng_uniforms() -> f32 { return f32(pcg4d(1u)); }\n");
        let special = ["LobeSample", "PI", "stretch", "pcg4d", "rng_uniforms"];
        let all: Vec<String> = Module::ALL.iter().flat_map(|m| m.short_names()).filter(|n| !special.contains(&n.as_str())).collect();
        assert!(all.len() > 50, "{all:?}");
        for (i, n) in all.iter().enumerate() {
            mine += &format!("const {n}: u32 = {i}u;\n");
        }
        mine += "@compute @workgroup_size(1) fn main() {\n\
                 let u = lobes_rng_uniforms(vec2(1u, 2u), vec2(3u, 0u));\n\
                 let s = lobes_ggx_sample_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), u.xy);\n\
                 let f = sample(LobeSample(s.pdf_r * LOBES_PI)) + f32(ggx_sample_vndf);\n\
                 let k = lobes_discrete_sample_alias(u.zw, 4u);\n}\n";
        let source = wgsl(&Module::ALL) + &mine;
        validate(&source).unwrap_or_else(|e| panic!("{e}"));
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
            (Module::Fresnel, &["fresnel_schlick", "fresnel_dielectric", "fresnel_conductor"]),
            (Module::Masking, &["masking_separable", "masking_height_correlated", "masking_height_correlated_transmitted", "masking_ln_beta"]),
            (Module::Discrete, &["discrete_sample_cdf", "discrete_sample_cdf_blocks", "discrete_sample_alias", "discrete_f", "discrete_u"]),
        ];
        for (m, names) in wanted {
            let s = m.short_names();
            for n in names {
                assert!(s.iter().any(|x| x == n), "{m:?} lacks {n}: {s:?}");
            }
        }
    }

    #[test]
    fn default_discrete_bindings_leave_the_file_unchanged() {
        let file = library::plain(library::source("lobes::discrete").unwrap());
        assert_eq!(discrete_file(DiscreteBindings::default()).trim_end(), file.trim_end());
    }
}
