//! lobes' WGSL samplers for your own shaders: a WESL package, naga_oil modules, or plain WGSL.
//!
//! The code that `lobes` tests (the counter-based RNG, every lobe's sampler, densities and BRDF,
//! the rough dielectric, Fresnel and masking terms, discrete CDF and alias sampling) comes in
//! three forms, all generated at build time from the same files of `shaders/` (`build.rs`), as
//! `&'static str` texts: nothing is parsed at run time.
//!
//! - **WESL** ([`Module::wesl_source`], [`wesl_files`], and with feature `wesl` the package
//!   [`WESL_PACKAGE`] for the `wesl` crate 0.4): one module per [`Module`], importable as
//!   `import lobes::ggx::ggx_sample_vndf;`. What Bevy 0.20 composes.
//! - **naga_oil modules** ([`Module::naga_oil_source`], [`naga_oil_modules`], and with feature
//!   `naga-oil` [`add_naga_oil_modules`]): `#define_import_path lobes::ggx`, for Bevy ≤ 0.19.
//! - **plain WGSL** ([`wgsl`]): the files a list of [`Module`]s needs, each once and in
//!   dependency order, as one string to prepend to your own shader source. Every name it defines
//!   carries the `lobes` prefix ([`prefixed`]: `lobes_ggx_sample_vndf`, `LOBES_PI`,
//!   `LobesLobeSample`), so your shader may have its own `PI`, `sample` or `stretch`:
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
//! // What wgpu does on `create_shader_module`: parse and validate with naga (feature `naga`).
//! embed::validate(&source).unwrap();
//! // Math, Reflect and Microfacet came along as dependencies of Ggx.
//! assert_eq!(embed::resolve(&[Module::Ggx, Module::Rng]),
//!            [Module::Math, Module::Rng, Module::Microfacet, Module::Reflect, Module::Ggx]);
//! ```
//!
//! The files of `shaders/` are naga_oil modules that lobes' own kernels compose (see
//! `crate::engine::gpu::library`); a [`Module`] is what a renderer imports as one (a lobe's
//! sampler, densities and BRDF: `ggx.wgsl` and `ggx_eval.wgsl` are both [`Module::Ggx`], import
//! path `lobes::ggx` in the naga_oil and WESL forms). The plain text is the files in import
//! order with their directive lines blanked and every module-scope name prefixed, by renaming
//! identifier tokens (`namespace.rs`); the naga_oil and WESL forms keep the short names (both
//! namespace by import path) and spell the files' type `Real` as `f32` (`text.rs`). Unit tests
//! parse the plain text and the composition lobes' kernels run with naga and find the same IR
//! up to the names, and compose the other two forms with naga_oil and the `wesl` crate; so
//! what you embed is the code the χ² tests judge, plus the pdf, BRDF and estimator-weight
//! functions of `shaders/lib/*_eval.wgsl` and the Fresnel and masking terms, which
//! `tests/embed.rs` checks against the f64 reference on the GPU.
//!
//! Everything [`wgsl`] defines is in [`Module::symbols`]. Only [`Module::Discrete`] declares
//! resource bindings; choose their group and binding numbers with [`wgsl_with`],
//! [`DiscreteBindings::apply`] (any form) or [`discrete_wgsl`], add more tables under names of
//! your own with [`discrete_table_wgsl`], and upload tables with `DiscreteBuffers` (feature
//! `wgpu`) or [`DiscreteTable`].
//!
//! Conventions (as everywhere in lobes): a local shading frame with the normal on +z, ωi (`wi`)
//! the given direction and ωr (`wr`) the sampled one, both unit vectors pointing away from the
//! surface; roughness `a = vec2(alpha_x, alpha_y)`; uniforms in [0, 1] (1 included); densities
//! per unit solid angle of ωr; BRDF values without Fresnel.

mod discrete;
mod namespace;
// the text rules; besides `with_bindings` and `declared` (a check's renaming of lobes' own names)
// they are build.rs's (and the unit tests')
#[allow(dead_code)]
mod text;

#[cfg(feature = "wgpu")]
pub use discrete::DiscreteBuffers;
pub use discrete::{BLOCK, DISCRETE_INFO_WGSL, DiscreteBindings, DiscreteInfo, DiscreteTable};
pub use namespace::prefixed;
pub(crate) use namespace::rename;
pub(crate) use text::declared;

/// The texts, names and dependencies `build.rs` generates from `shaders/`, indexed by
/// `Module as usize`.
mod generated {
    /// One naga_oil module / WESL file: a module's API (`lobes::ggx`) or its internal helpers
    /// (`lobes::ggx::internal`), in dependency order (each after the units it imports).
    pub(super) struct Unit {
        pub module: usize,
        pub internal: bool,
        pub import_path: &'static str,
        pub naga_oil: &'static str,
        pub wesl: &'static str,
        /// The units it imports from (indices into `UNITS`, each smaller than its own).
        pub imports: &'static [usize],
    }
    include!(concat!(env!("OUT_DIR"), "/embed_generated.rs"));

    /// The unit of `module`'s API, or of its internal helpers.
    pub(super) fn unit(module: usize, internal: bool) -> Option<&'static Unit> {
        UNITS.iter().find(|u| u.module == module && u.internal == internal)
    }
}

/// Declares [`Module`], one variant per module that build.rs finds in `shaders/` (the files'
/// `//! embed: NAME` lines), with the documentation it reads there.
macro_rules! modules {
    ($n:literal; $($(#[$doc:meta])* $variant:ident,)*) => {
        /// A WGSL module of lobes: what a renderer imports as one. The listed functions are the ones
        /// meant for callers, under the files' short names, which the naga_oil and WESL forms keep
        /// (`import lobes::ggx::ggx_sample_vndf;`); [`wgsl`] exports each as [`prefixed`]`("lobes",
        /// name)` (`rng_uniforms` → `lobes_rng_uniforms`, `PI` → `LOBES_PI`, `LobeSample` →
        /// `LobesLobeSample`). [`Module::symbols`] lists every name the module defines.
        ///
        /// A module's files say which module they are part of (`//! embed: ggx`) and mark its API
        /// with `///` comments; build.rs reads both, so a new module needs no Rust.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Module {
            $($(#[$doc])* $variant,)*
        }

        impl Module {
            /// Every module, in dependency order: by the longest chain of imports below it, then by name.
            pub const ALL: [Module; $n] = [$(Module::$variant),*];
        }
    };
}
include!(concat!(env!("OUT_DIR"), "/embed_modules.rs"));

impl Module {
    /// The module's name: its import path under `lobes` (`lobes::ggx`), its file in the WESL
    /// package and `--out-dir` (`ggx.wesl`), its name on `lobes wgsl`'s command line.
    ///
    /// ```
    /// assert_eq!(lobes::embed::Module::Ggx.name(), "ggx");
    /// ```
    pub fn name(self) -> &'static str {
        generated::NAMES[self as usize]
    }

    /// The import path of the module in the naga_oil and WESL forms (`"lobes::ggx"`).
    pub fn import_path(self) -> String {
        format!("lobes::{}", self.name())
    }

    /// The modules this one uses directly (each earlier in [`Module::ALL`]), from the `#import`
    /// lines of its files.
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert_eq!(Module::Beckmann.dependencies(), [Module::Math, Module::Microfacet, Module::Reflect]);
    /// assert_eq!(Module::Fresnel.dependencies(), [Module::Math]);
    /// assert!(Module::Rng.dependencies().is_empty());
    /// ```
    pub fn dependencies(self) -> Vec<Module> {
        generated::DEPENDENCIES[self as usize].iter().map(|&i| Module::ALL[i]).collect()
    }

    /// The files of `shaders/` the module is made of (`["shaders/lib/ggx.wgsl",
    /// "shaders/lib/ggx_eval.wgsl"]`).
    pub fn files(self) -> &'static [&'static str] {
        generated::FILES[self as usize]
    }

    /// The module alone (without its dependencies; [`wgsl`] adds those) as plain WGSL with
    /// every name prefixed, as [`wgsl`] writes it; [`Module::Discrete`] at its default bindings.
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert!(Module::Ggx.wgsl_source().contains("fn lobes_ggx_pdf_vndf("));
    /// assert!(!Module::Ggx.wgsl_source().contains("fn lobes_reflect_about("));
    /// ```
    pub fn wgsl_source(self) -> &'static str {
        generated::WGSL[self as usize]
    }

    /// The module's API as a naga_oil module (without its dependencies): `#define_import_path
    /// lobes::NAME`, `#import`s of the other modules (and of its own internal helpers, from
    /// `lobes::NAME::internal`: see [`Module::api`]), the files' short names, in f32.
    /// [`Module::Discrete`] comes with its bindings at group 0, bindings 3 and 4
    /// ([`DiscreteBindings::apply`] moves them).
    ///
    /// ```
    /// use lobes::embed::Module;
    /// let ggx = Module::Ggx.naga_oil_source();
    /// assert!(ggx.starts_with("#define_import_path lobes::ggx\n"));
    /// assert!(ggx.contains("fn ggx_sample_vndf(") && ggx.contains("fn ggx_pdf_vndf("));
    /// assert!(!ggx.contains("Real") && !ggx.contains("f32 >"));
    /// ```
    pub fn naga_oil_source(self) -> &'static str {
        generated::unit(self as usize, false).expect("every module has an API").naga_oil
    }

    /// The module's API as a WESL module (without its dependencies), `NAME.wesl` of the package
    /// `lobes` ([`wesl_files`]): `import super::reflect::{LobeSample, PI};` lines (relative, so the
    /// package works as an external package `lobes` and as a folder `lobes/` of your own
    /// package; its internal helpers come from `NAME/internal.wesl`, see [`Module::api`]), then
    /// the files' code under their short names, in f32.
    ///
    /// ```
    /// use lobes::embed::Module;
    /// let masking = Module::Masking.wesl_source();
    /// assert!(masking.contains("fn masking_separable(") && !masking.contains("fn masking_stirling_d("));
    /// assert!(masking.starts_with("import super::math::{math_exp, math_log};\nimport super::masking::internal::{HALF_LN_2PI, "));
    /// ```
    pub fn wesl_source(self) -> &'static str {
        generated::unit(self as usize, false).expect("every module has an API").wesl
    }

    /// The names the module offers a renderer: what `lobes::NAME` holds in the naga_oil and WESL
    /// forms (their `#import` / `import` of any other name fails), each listed in the module's
    /// documentation above and in docs/embedding.md. The module's other names
    /// ([`Module::short_names`]) are its internal helpers, which those forms put in the
    /// submodule `lobes::NAME::internal` (its API's code imports them from there; neither
    /// naga_oil nor WESL hides a name, so nothing stops an import from `internal`, but they are
    /// not API and may change in any release). The plain text holds both, prefixed.
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert!(Module::Ggx.api().contains(&"ggx_sample_vndf"));
    /// assert!(!Module::Ggx.api().contains(&"ggx_cap_sample"));          // a helper of ggx_sample_vndf
    /// assert!(Module::Ggx.short_names().contains(&"ggx_cap_sample"));
    /// assert!(!Module::Ggx.wesl_source().contains("fn ggx_cap_sample("));
    /// ```
    pub fn api(self) -> &'static [&'static str] {
        generated::API[self as usize]
    }

    /// The module named `name` (its [`Module::name`]).
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert_eq!(Module::from_name("dielectric"), Some(Module::Dielectric));
    /// assert_eq!(Module::from_name("GGX"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Module> {
        Module::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Every name the module defines at module scope (functions, constants, structs, type
    /// aliases, globals), prefixed as [`wgsl`] writes them: the names your shader must not reuse.
    ///
    /// ```
    /// use lobes::embed::Module;
    /// assert!(Module::Reflect.symbols().contains(&"LOBES_PI"));
    /// assert!(Module::Ggx.symbols().contains(&"lobes_ggx_eval"));
    /// assert!(!Module::Ggx.symbols().contains(&"LOBES_PI")); // that one is Reflect's
    /// ```
    pub fn symbols(self) -> &'static [&'static str] {
        generated::SYMBOLS[self as usize]
    }

    /// The module's documentation, in Markdown, as its variant above shows it: what it is, its
    /// files, each declaration of its API with what it does, and the modules it needs. Read from its
    /// files' comments at build time (`lobes wgsl --list` prints it).
    ///
    /// ```
    /// use lobes::embed::Module;
    /// let ggx = Module::Ggx.description();
    /// assert!(ggx.starts_with("GGX (Trowbridge–Reitz) microfacets."));
    /// assert!(ggx.contains("In `shaders/lib/ggx.wgsl`, `shaders/lib/ggx_eval.wgsl`."));
    /// assert!(ggx.contains("- `fn ggx_sample_vndf(a: vec2<f32>, wi: vec3<f32>, u: vec2<f32>) -> LobeSample`: "));
    /// assert!(!ggx.contains("ggx_cap_sample")); // a helper, not API
    /// ```
    pub fn description(self) -> &'static str {
        generated::DESCRIPTIONS[self as usize]
    }

    /// The names the module's files declare at module scope (the short, unprefixed ones).
    pub fn short_names(self) -> &'static [&'static str] {
        generated::SHORT_NAMES[self as usize]
    }
}

/// The prefix of every exported name ([`prefixed`]).
const PREFIX: &str = "lobes";

/// `modules` with all their dependencies, each once, in dependency order (the order of
/// [`Module::ALL`]).
///
/// ```
/// use lobes::embed::{resolve, Module};
/// assert_eq!(resolve(&[Module::Ward]), [Module::Math, Module::Reflect, Module::Ward]);
/// assert_eq!(resolve(&[Module::Fresnel, Module::Masking]), [Module::Math, Module::Fresnel, Module::Masking]);
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
/// Include it once per shader: two such texts concatenated define their common modules twice,
/// which [`validate`] reports by file (ask for all modules in one call instead, or take one
/// text per module, [`Module::wgsl_source`], and include each once).
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
    for m in resolved {
        out.push_str(&module_wgsl(m, discrete));
    }
    out
}

#[cfg(feature = "glsl")]
/// The modules (and those they use) as GLSL 450 functions, constants and (the discrete module's)
/// buffer blocks, for `#include` in a `#version 450` shader (`lobes wgsl --glsl`): the texts of
/// [`wgsl_with`], every name prefixed `lobes_`, translated by naga's GLSL back end. naga's writer
/// needs an entry point: an empty compute one is added for it and taken out of the text again,
/// with its `#version` line (the including file has its own).
///
/// ```
/// use lobes::embed::{self, Module};
/// let glsl = embed::glsl(&[Module::Ggx], embed::DiscreteBindings::default()).unwrap();
/// assert!(glsl.contains("lobes_ggx_d(") && !glsl.lines().any(|l| l.starts_with("#version")) && !glsl.contains("void main()"));
/// ```
pub fn glsl(modules: &[Module], discrete: DiscreteBindings) -> Result<String, InvalidWgsl> {
    const MAIN: &str = "lobes_glsl_entry_point";
    let wgsl = format!("{}\n@compute @workgroup_size(1)\nfn {MAIN}() {{}}\n", wgsl_with(modules, discrete));
    let invalid = |message: String| InvalidWgsl { message };
    let module = naga::front::wgsl::parse_str(&wgsl).map_err(|e| invalid(format!("embedded lobes WGSL: {}", e.emit_to_string(&wgsl))))?;
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module)
        .map_err(|e| invalid(format!("embedded lobes WGSL: {e:?}")))?;
    let options = naga::back::glsl::Options { version: naga::back::glsl::Version::Desktop(450), ..Default::default() };
    let pipeline = naga::back::glsl::PipelineOptions { shader_stage: naga::ShaderStage::Compute, entry_point: MAIN.into(), multiview: None };
    let mut out = String::new();
    naga::back::glsl::Writer::new(&mut out, &module, &info, &options, &pipeline, naga::proc::BoundsCheckPolicies::default())
        .and_then(|mut w| w.write().map(|_| ()))
        .map_err(|e| invalid(format!("naga's GLSL writer: {e}")))?;
    // the entry point (written `void main()`), its workgroup size and the #version line go
    let main = out.find("void main()").ok_or_else(|| invalid("naga's GLSL writer wrote no entry point".into()))?;
    let body: String = out[..main]
        .lines()
        .filter(|l| !l.starts_with("#version") && !l.starts_with("layout(local_size_x") && !l.starts_with("#extension GL_ARB_compute_shader"))
        .map(|l| format!("{l}\n"))
        .collect();
    Ok(format!(
        "// lobes {} GLSL 450 (lobes wgsl --glsl): for #include in a #version 450 shader; every name lobes defines\n\
         // starts with lobes_, Lobes or LOBES_. Written from lobes' WGSL by naga's GLSL back end.\n{}",
        env!("CARGO_PKG_VERSION"),
        body.trim_start()
    ))
}

/// One module's plain prefixed text ([`Module::wgsl_source`]), [`Module::Discrete`] with its
/// buffers at `discrete`: the pieces of [`wgsl_with`], for a renderer that includes one text per
/// module (each once; they do not overlap).
///
/// ```
/// use lobes::embed::{module_wgsl, DiscreteBindings, Module};
/// let b = DiscreteBindings { group: 1, table: 0, alias: 1 };
/// assert!(module_wgsl(Module::Discrete, b).contains("@group(1) @binding(1) var<storage, read> lobes_discrete_u"));
/// assert_eq!(module_wgsl(Module::Ggx, b), Module::Ggx.wgsl_source());
/// ```
pub fn module_wgsl(m: Module, discrete: DiscreteBindings) -> std::borrow::Cow<'static, str> {
    match m {
        Module::Discrete => discrete.apply_wgsl(m.wgsl_source()).into(),
        _ => m.wgsl_source().into(),
    }
}

/// The plain, unprefixed `shaders/lib/discrete.wgsl` (directive lines blanked, no marker line).
fn discrete_short() -> &'static str {
    let s = generated::SHORT_WGSL[Module::Discrete as usize];
    s.split_once('\n').map_or(s, |(_, rest)| rest)
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
/// (each with its own buffers at its own bindings); the name `discrete` gives the names of
/// [`wgsl_with`].
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
    namespace::rename(&bindings.apply(discrete_short()), |t| {
        defined.contains(&t).then(|| prefixed(&prefix, t.strip_prefix("discrete_").or_else(|| t.strip_prefix("DISCRETE_")).unwrap_or(t)))
    })
}

impl DiscreteBindings {
    /// `source` (a text of [`Module::Discrete`] in any form: [`Module::naga_oil_source`],
    /// [`Module::wesl_source`], or the unprefixed file) with the two storage buffers
    /// `discrete_f` and `discrete_u` at these numbers.
    ///
    /// ```
    /// use lobes::embed::{DiscreteBindings, Module};
    /// let b = DiscreteBindings { group: 2, table: 0, alias: 5 };
    /// let wesl = b.apply(Module::Discrete.wesl_source());
    /// assert!(wesl.contains("@group(2) @binding(0) var<storage, read> discrete_f: array<f32>;"));
    /// assert!(wesl.contains("@group(2) @binding(5) var<storage, read> discrete_u: array<u32>;"));
    /// ```
    ///
    /// # Panics
    ///
    /// If `source` declares neither buffer (it is not a text of [`Module::Discrete`]).
    pub fn apply(self, source: &str) -> String {
        text::with_bindings(source, "discrete_f", "discrete_u", self.group, [self.table, self.alias]).expect("a text of Module::Discrete, which declares discrete_f and discrete_u")
    }

    /// The same for the prefixed text ([`Module::wgsl_source`]: `lobes_discrete_f`, `lobes_discrete_u`).
    fn apply_wgsl(self, source: &str) -> String {
        text::with_bindings(source, "lobes_discrete_f", "lobes_discrete_u", self.group, [self.table, self.alias]).expect("Module::Discrete's plain text declares its buffers")
    }
}

/// One of lobes' naga_oil modules, for a renderer that composes its shaders with naga_oil
/// (Bevy ≤ 0.19): a module's API (`lobes::ggx`) or its internal helpers
/// (`lobes::ggx::internal`, which the API's code imports; see [`Module::api`]). Add each with
/// [`add_naga_oil_modules`] (feature `naga-oil`) or your own
/// `Composer::add_composable_module`, then `#import lobes::ggx::ggx_sample_vndf` in your shader.
/// naga_oil keeps modules apart by import path, so these carry the files' short names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NagaOilModule {
    /// The module.
    pub module: Module,
    /// Whether this is the module's internal helpers (`lobes::NAME::internal`) rather than its API.
    pub internal: bool,
    /// The path its `#define_import_path` names (`"lobes::ggx"`, `"lobes::ggx::internal"`).
    pub import_path: String,
    /// The text: WGSL with naga_oil's `#define_import_path` and `#import` directives
    /// ([`Module::naga_oil_source`] for the API).
    pub source: &'static str,
}

impl NagaOilModule {
    /// Its file in `lobes wgsl --naga-oil --out-dir` and in the WESL package: `ggx.EXT`, or
    /// `ggx/internal.EXT` for the helpers.
    ///
    /// ```
    /// use lobes::embed::{naga_oil_modules, Module};
    /// let files: Vec<String> = naga_oil_modules(&[Module::Fresnel]).iter().map(|m| m.file_name("wesl")).collect();
    /// assert_eq!(files, ["fresnel/internal.wesl", "fresnel.wesl"]);
    /// ```
    pub fn file_name(&self, ext: &str) -> String {
        format!("{}{}.{ext}", self.module.name(), if self.internal { "/internal" } else { "" })
    }
}

#[cfg(feature = "naga-oil")]
impl NagaOilModule {
    /// The descriptor for `naga_oil::compose::Composer::add_composable_module` (naga_oil 0.23),
    /// with the import path as the file path that naga_oil's messages name. (For naga_oil 0.22,
    /// Bevy 0.19's, build its own descriptor from `source` and `import_path`.)
    pub fn descriptor(&self) -> naga_oil::compose::ComposableModuleDescriptor<'_> {
        naga_oil::compose::ComposableModuleDescriptor { source: self.source, file_path: &self.import_path, ..Default::default() }
    }
}

/// The units of `modules`' APIs and all they import, in dependency order.
fn units(modules: &[Module]) -> Vec<&'static generated::Unit> {
    let mut wanted = vec![false; generated::UNITS.len()];
    let mut stack: Vec<usize> = modules.iter().map(|&m| generated::UNITS.iter().position(|u| u.module == m as usize && !u.internal).unwrap()).collect();
    while let Some(i) = stack.pop() {
        if !std::mem::replace(&mut wanted[i], true) {
            stack.extend(generated::UNITS[i].imports);
        }
    }
    generated::UNITS.iter().zip(wanted).filter(|(_, w)| *w).map(|(u, _)| u).collect()
}

/// `modules` and what they import as naga_oil modules (see [`NagaOilModule`]), each after
/// the modules it imports (the order naga_oil's `add_composable_module` needs).
///
/// ```
/// use lobes::embed::{naga_oil_modules, Module};
/// let paths: Vec<String> = naga_oil_modules(&[Module::Fresnel]).into_iter().map(|m| m.import_path).collect();
/// assert_eq!(paths, ["lobes::fresnel::internal", "lobes::fresnel"]); // in f32, Fresnel needs nothing of lobes::math
/// ```
pub fn naga_oil_modules(modules: &[Module]) -> Vec<NagaOilModule> {
    units(modules)
        .into_iter()
        .map(|u| NagaOilModule { module: Module::ALL[u.module], internal: u.internal, import_path: u.import_path.to_string(), source: u.naga_oil })
        .collect()
}

/// Adds `modules` and what they import to a naga_oil composer, each after those it imports,
/// skipping any the composer already holds: calling it twice, or for overlapping module
/// lists, adds each module once (naga_oil would otherwise replace a module that is added again
/// and drop the modules that import it).
///
/// ```
/// use naga_oil::compose::{Composer, NagaModuleDescriptor};
/// use lobes::embed::{add_naga_oil_modules, Module};
/// let mut composer = Composer::default();
/// add_naga_oil_modules(&mut composer, &[Module::Ggx]).unwrap();
/// add_naga_oil_modules(&mut composer, &[Module::Fresnel, Module::Ggx]).unwrap(); // no duplicates
/// let shader = "#import lobes::ggx::{ggx_sample_vndf, ggx_pdf_vndf}
/// #import lobes::fresnel::fresnel_schlick
/// const PI: f32 = 3.0; // the renderer's own
/// @compute @workgroup_size(1) fn main() {
///     let s = ggx_sample_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), vec2(0.5 / PI));
///     let w = fresnel_schlick(s.wr.z, 0.04) / ggx_pdf_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), s.wr);
/// }";
/// composer.make_naga_module(NagaModuleDescriptor { source: shader, file_path: "mine.wgsl", ..Default::default() }).unwrap();
/// ```
#[cfg(feature = "naga-oil")]
#[allow(clippy::result_large_err)] // naga_oil's own error, as its Composer returns it
pub fn add_naga_oil_modules(composer: &mut naga_oil::compose::Composer, modules: &[Module]) -> Result<(), naga_oil::compose::ComposerError> {
    for m in naga_oil_modules(modules) {
        if !composer.contains_module(&m.import_path) {
            composer.add_composable_module(m.descriptor())?;
        }
    }
    Ok(())
}

/// `modules` and what they import as the files of the WESL package `lobes`: (`"ggx.wesl"`,
/// [`Module::wesl_source`]) and, for a module with internal helpers, (`"ggx/internal.wesl"`,
/// their text), each once. Write them into a folder `lobes/` beside your shaders, or hand them
/// to your WESL resolver as the package `lobes`; then `import lobes::ggx::ggx_sample_vndf;`.
///
/// ```
/// use lobes::embed::{wesl_files, Module};
/// let files: Vec<String> = wesl_files(&[Module::Ggx]).into_iter().map(|(name, _)| name).collect();
/// assert_eq!(files, ["math.wesl", "microfacet.wesl", "reflect.wesl", "ggx/internal.wesl", "ggx.wesl"]);
/// ```
pub fn wesl_files(modules: &[Module]) -> Vec<(String, &'static str)> {
    units(modules)
        .into_iter()
        .map(|u| (format!("{}{}.wesl", Module::ALL[u.module].name(), if u.internal { "/internal" } else { "" }), u.wesl))
        .collect()
}

#[cfg(feature = "wesl")]
mod wesl_package {
    use super::generated::UNITS;
    use wesl::{CodegenModule, CodegenPkg};
    include!(concat!(env!("OUT_DIR"), "/embed_wesl_package.rs"));
    static ROOT: CodegenModule = CodegenModule { name: "lobes", source: "", submodules: &MODULES };
    pub static WESL_PACKAGE: CodegenPkg = CodegenPkg { crate_name: "lobes", root: &ROOT, dependencies: &[] };
}

/// Every [`Module`] as the WESL package `lobes` for the `wesl` crate 0.4 (feature `wesl`), for
/// a build script or a run-time compiler: `Wesl::new("shaders").add_package(&WESL_PACKAGE)`,
/// then `import lobes::ggx::ggx_sample_vndf;` in your WESL. (The `wesl` crate's package type
/// is its own per version; with another version, e.g. Bevy 0.20's wesl 0.6, take
/// [`wesl_files`] or `lobes wgsl --wesl --out-dir`.)
///
/// ```
/// // in build.rs, beside `shaders/main.wesl` that says `import lobes::ggx::ggx_sample_vndf;`
/// let mut compiler = wesl::Wesl::new("shaders");
/// compiler.add_package(&lobes::embed::WESL_PACKAGE);
/// // compiler.build_artifact(&"package::main".parse().unwrap(), "main");
/// ```
#[cfg(feature = "wesl")]
pub use wesl_package::WESL_PACKAGE;

/// docs/embedding.md, whose Rust blocks rustdoc compiles and runs as doctests of this item
/// (`cargo test --doc`, with the features the page uses; tests/docs_commands.rs checks that the
/// page is included here).
#[cfg(all(doctest, feature = "naga-oil", feature = "wgpu", feature = "wesl"))]
#[doc = include_str!("../../docs/embedding.md")]
pub struct EmbeddingPage;

/// A source given to [`validate`] that holds one of lobes' files twice (two texts of [`wgsl`]
/// concatenated), or that naga rejects.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct InvalidWgsl {
    /// naga's message with the source location, or which file is included twice.
    pub message: String,
}

/// Parses and validates WGSL with naga, as wgpu does on `create_shader_module` (feature
/// `naga`); the error carries naga's message with the source location. A source that includes
/// one of lobes' files twice (two outputs of [`wgsl`] or `lobes wgsl` concatenated) is
/// refused first, by file, rather than with naga's "redefinition of …".
///
/// ```
/// use lobes::embed::{self, Module};
/// assert!(embed::validate("fn f() -> f32 { return ggx_d(vec2(0.1), vec3(0.0, 0.0, 1.0)); }").is_err());
/// let twice = embed::wgsl(&[Module::Ggx]) + &embed::wgsl(&[Module::Fresnel]);
/// let e = embed::validate(&twice).unwrap_err();
/// assert!(e.message.contains("shaders/math/f32.wgsl is included twice"), "{e}");
/// ```
#[cfg(feature = "naga")]
pub fn validate(source: &str) -> Result<(), InvalidWgsl> {
    let mut seen: Vec<&str> = Vec::new();
    for marker in source.lines().filter_map(|l| l.strip_prefix("// ---- shaders/")).filter_map(|l| l.strip_suffix(" ----")) {
        if seen.contains(&marker) {
            return Err(InvalidWgsl {
                message: format!(
                    "shaders/{marker} is included twice (two texts of lobes::embed::wgsl or `lobes wgsl` concatenated?): \
                     take all modules from one call, or one text per module (Module::wgsl_source, `lobes wgsl --out-dir`) and include each once"
                ),
            });
        }
        seen.push(marker);
    }
    let module = naga::front::wgsl::parse_str(source).map_err(|e| InvalidWgsl { message: format!("embedded lobes WGSL: {}", e.emit_to_string(source)) })?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module)
        .map_err(|e| InvalidWgsl { message: format!("embedded lobes WGSL: {e:?}") })?;
    Ok(())
}

#[cfg(all(test, feature = "check"))]
mod tests {
    use super::*;
    use crate::engine::gpu::library;

    /// Names declared at module scope of a WGSL source, by naga's parse (empty if it does not
    /// parse), and the `alias` declarations, which naga resolves away.
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

    /// The unprefixed plain text of `modules` (no dependencies added), in the order given.
    fn short(modules: &[Module]) -> String {
        modules.iter().map(|&m| generated::SHORT_WGSL[m as usize]).collect()
    }

    #[test]
    fn the_generated_table_is_the_enum() {
        for (i, m) in Module::ALL.into_iter().enumerate() {
            assert_eq!(m as usize, i);
            // the variant's name in snake case: SphereLight is sphere_light
            let snake: String = format!("{m:?}").chars().enumerate().flat_map(|(k, c)| (k > 0 && c.is_uppercase()).then_some('_').into_iter().chain(c.to_lowercase())).collect();
            assert_eq!(snake, m.name());
        }
    }

    #[test]
    fn every_module_composes_and_validates_alone_and_together() {
        for m in Module::ALL {
            validate(&wgsl(&[m])).unwrap_or_else(|e| panic!("{m:?}: {e}"));
        }
        validate(&wgsl(&Module::ALL)).unwrap();
    }

    /// The embedded files are the ones lobes' engine composes: each module's text is, file by
    /// file, the engine's plain piece of the same import path.
    #[test]
    fn the_embedded_files_are_the_engines() {
        for m in Module::ALL {
            let mut expected = String::new();
            for file in m.files() {
                let path = text::import_path(&std::fs::read_to_string(file).unwrap()).unwrap().to_string();
                let pieces = library::pieces(&[&path], &[]).unwrap();
                let (_, plain) = pieces.iter().find(|(p, _)| p == file).unwrap_or_else(|| panic!("{file} is not the engine's {path}"));
                expected += &format!("// ---- {file} ----\n{plain}\n");
            }
            assert_eq!(generated::SHORT_WGSL[m as usize], expected, "{m:?}");
        }
    }

    #[test]
    fn declared_names_are_what_naga_finds() {
        for m in Module::ALL {
            let deps: Vec<Module> = resolve(&[m]).into_iter().filter(|&d| d != m).collect();
            let before = names(&short(&deps));
            let found: Vec<String> = names(&short(&resolve(&[m]))).into_iter().filter(|n| !before.contains(n)).collect();
            assert_eq!(m.short_names(), found, "{m:?}");
        }
    }

    /// A renderer's naga_oil composes lobes' modules and a shader that imports from them and has
    /// names of its own that lobes' files also use.
    #[test]
    fn naga_oil_modules_compose_with_a_renderer_shader() {
        use naga_oil::compose::{Composer, NagaModuleDescriptor};
        let mut composer = Composer::default();
        if let Err(e) = add_naga_oil_modules(&mut composer, &Module::ALL) {
            panic!("{}", e.emit_to_string(&composer));
        }
        add_naga_oil_modules(&mut composer, &[Module::Ggx, Module::Fresnel]).unwrap();
        let shader = "#import lobes::beckmann::beckmann_sample_vndf\n#import lobes::ggx::{ggx_eval, ggx_g1, ggx_pdf_vndf}\n\
                      #import lobes::fresnel::fresnel_schlick\n#import lobes::masking::masking_height_correlated\n\
                      #import lobes::rng::rng_uniforms\n#import lobes::discrete::discrete_sample_alias\n\
                      #import lobes::dielectric::{dielectric_ggx_vndf, dielectric_ggx_vndf_pdf}\n\
                      const PI: f32 = 3.0;\nfn stretch(x: f32) -> f32 { return x; }\nfn pcg4d(x: u32) -> u32 { return x; }\n\
                      @compute @workgroup_size(1) fn main() {\n\
                      let u = rng_uniforms(vec2(1u, 2u), vec2(3u, 0u));\n\
                      let s = beckmann_sample_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), u.xy);\n\
                      let f = ggx_eval(vec2(0.3), vec3(0.0, 0.0, 1.0), s.wr) * fresnel_schlick(s.wr.z, 0.04 * PI) / ggx_pdf_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), s.wr);\n\
                      let g = masking_height_correlated(ggx_g1(vec2(0.3), s.wr), 0.5) + stretch(f);\n\
                      let t = dielectric_ggx_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), u.xyz, 1.5);\n\
                      let p = dielectric_ggx_vndf_pdf(vec2(0.3), vec3(0.0, 0.0, 1.0), t.wr, 1.5);\n\
                      let k = discrete_sample_alias(u.zw, pcg4d(4u));\n}\n";
        match composer.make_naga_module(NagaModuleDescriptor { source: shader, file_path: "renderer.wgsl", ..Default::default() }) {
            Ok(module) => {
                let caps = naga::valid::Capabilities::default();
                naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps).validate(&module).unwrap();
            }
            Err(e) => panic!("{}", e.emit_to_string(&composer)),
        }
    }

    #[test]
    fn naga_oil_and_wesl_texts_are_clean() {
        for u in generated::UNITS {
            let m = Module::ALL[u.module];
            for text in [u.naga_oil, u.wesl] {
                let code: String = text.lines().map(|l| l.split("//").next().unwrap()).collect::<Vec<_>>().join("\n");
                assert!(!code.contains("Real") && !code.contains("f32 >") && !code.contains("f32 )"), "{m:?}:\n{text}");
                assert!(!text.contains("lobes::math::Real") && !code.contains("alias "), "{m:?}");
            }
            // each unit imports only from the modules the plain form depends on, or its own helpers
            let up = if u.internal { "import super::super::" } else { "import super::" };
            for line in u.wesl.lines().filter(|l| l.starts_with("import ")) {
                let from = line.strip_prefix(up).and_then(|r| r.split("::").next()).and_then(Module::from_name);
                assert!(from.is_some_and(|d| m.dependencies().contains(&d) || (d == m && !u.internal)), "{}: {line}", u.import_path);
            }
        }
        for wanted in [Module::Fresnel, Module::Masking] {
            let paths: Vec<Module> = naga_oil_modules(&[wanted]).into_iter().map(|m| m.module).collect();
            assert!(!paths.contains(&Module::Reflect), "{wanted:?} brings {paths:?}");
        }
    }

    /// In the naga_oil and WESL forms `lobes::NAME` declares exactly the module's API, its
    /// helpers are in `lobes::NAME::internal`, and together they are every name of its files.
    #[test]
    fn each_module_declares_its_api_and_its_helpers_apart() {
        for m in Module::ALL {
            let declared = |internal: bool| -> Vec<&str> {
                let mut v = generated::unit(m as usize, internal).map_or(Vec::new(), |u| text::declared(u.wesl));
                v.sort();
                v
            };
            let mut api = m.api().to_vec();
            api.sort();
            assert_eq!(declared(false), api, "{m:?}");
            let mut all: Vec<&str> = declared(false).into_iter().chain(declared(true)).collect();
            all.sort();
            let expected: Vec<&str> = m.short_names().iter().copied().filter(|&n| n != "Real").collect();
            assert_eq!(all, expected, "{m:?}");
            let naga_oil = generated::unit(m as usize, false).unwrap().naga_oil;
            assert_eq!(text::declared(naga_oil).len(), api.len(), "{m:?}");
        }
        assert!(Module::ALL.iter().filter(|m| generated::unit(**m as usize, true).is_some()).count() >= 6);
    }

    /// A renderer that imports a helper from naga_oil's `lobes::ggx` gets an error naming it;
    /// the API's names compose (the renderer tests above use them), and the helpers are
    /// where the documentation says, in `lobes::ggx::internal`.
    #[test]
    fn importing_a_helper_from_a_naga_oil_module_fails_clearly() {
        use naga_oil::compose::{Composer, NagaModuleDescriptor};
        let body = "@compute @workgroup_size(1) fn main() { let h = ggx_cap_sample(vec2(0.3), vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), 0.5, 0.5, vec2(0.5)); }\n";
        let mut composer = Composer::default();
        add_naga_oil_modules(&mut composer, &[Module::Ggx]).unwrap();
        let compose = |composer: &mut Composer, import: &str| {
            let source = format!("{import}\n{body}");
            composer.make_naga_module(NagaModuleDescriptor { source: &source, file_path: "mine.wgsl", ..Default::default() }).map_err(|e| e.emit_to_string(composer))
        };
        let e = compose(&mut composer, "#import lobes::ggx::ggx_cap_sample").unwrap_err();
        println!("naga_oil: {e}");
        assert!(e.contains("ggx_cap_sample"), "{e}");
        compose(&mut composer, "#import lobes::ggx::internal::ggx_cap_sample").unwrap_or_else(|e| panic!("{e}"));
        compose(&mut composer, "#import lobes::ggx::ggx_sample_vndf").unwrap_err();
    }

    /// The same in WESL: `import lobes::ggx::ggx_cap_sample;` fails naming the item, and
    /// `lobes::ggx::internal` holds it.
    #[cfg(feature = "wesl")]
    #[test]
    fn importing_a_helper_from_a_wesl_module_fails_clearly() {
        let body = "@compute @workgroup_size(1) fn main() { let h = ggx_cap_sample(vec2(0.3), vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), 0.5, 0.5, vec2(0.5)); }\n";
        let wesl = |import: &str| -> Result<String, String> {
            use wesl::syntax::PathOrigin;
            let mut local = wesl::VirtualResolver::new();
            let root = wesl::ModulePath::new(PathOrigin::Absolute, vec!["main".into()]);
            local.add_module(root.clone(), format!("{import}\n{body}").into());
            let mut packages = wesl::PkgResolver::new();
            packages.add_package(&WESL_PACKAGE);
            let mut router = wesl::Router::new();
            router.mount_resolver(wesl::ModulePath::new(PathOrigin::Absolute, vec![]), local);
            router.mount_fallback_resolver(packages);
            wesl::Wesl::new("").set_custom_resolver(router).compile(&root).map(|c| c.to_string()).map_err(|e| e.to_string())
        };
        let e = wesl("import lobes::ggx::ggx_cap_sample;").unwrap_err();
        println!("wesl: {e}");
        assert!(e.contains("ggx_cap_sample"), "{e}");
        let compiled = wesl("import lobes::ggx::internal::ggx_cap_sample;").unwrap_or_else(|e| panic!("{e}"));
        validate(&compiled).unwrap();
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
    fn assert_same_ir_up_to_names(plain: &str, renamed: &str, names: &[&str], to: impl Fn(&str) -> String) {
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

    /// What [`wgsl`] exports is the code lobes' kernels compose, with only the names changed:
    /// the same functions, constants, globals and types in the same order, and the same
    /// expressions and statements in each function.
    #[test]
    fn exported_wgsl_is_the_composed_code_up_to_names() {
        let library: Vec<Module> = Module::ALL.into_iter().filter(|&m| m != Module::Discrete).collect();
        let names: Vec<&str> = library.iter().flat_map(|m| m.short_names().iter().copied()).collect();
        let exported = wgsl(&library);
        assert_same_ir_up_to_names(&short(&library), &exported, &names, |n| prefixed(PREFIX, n));
        assert!(exported.contains("fn lobes_ggx_sample_vndf(") && exported.contains("const LOBES_PI") && exported.contains("struct LobesLobeSample"));
        // a discrete table under a name of its own
        let names = Module::Discrete.short_names();
        let lights = discrete_table_wgsl("lights", DiscreteBindings::default());
        let table = |n: &str| prefixed("lobes_lights", n.strip_prefix("discrete_").or_else(|| n.strip_prefix("DISCRETE_")).unwrap_or(n));
        assert_same_ir_up_to_names(discrete_short(), &lights, names, table);
        assert!(lights.contains("fn lobes_lights_sample_alias(") && lights.contains("LOBES_LIGHTS_BLOCK"), "{lights}");
    }

    /// A renderer's shader that defines, for itself, every short name of lobes' files (and
    /// `sample`) validates together with everything [`wgsl`] exports.
    #[test]
    fn a_renderer_with_lobes_short_names_of_its_own_composes_with_the_export() {
        let mut mine = String::from("struct LobeSample { x: f32 }\nconst PI: f32 = 3.0;\nfn stretch(x: f32) -> f32 { return x * PI; }\n\
                                     fn sample(s: LobeSample) -> f32 { return stretch(s.x); }\nfn pcg4d(x: u32) -> u32 { return x; }\n\
                                     fn rng_uniforms() -> f32 { return f32(pcg4d(1u)); }\nalias Real = f32;\n");
        let special = ["LobeSample", "PI", "stretch", "pcg4d", "rng_uniforms", "Real"];
        let all: Vec<&str> = Module::ALL.iter().flat_map(|m| m.short_names().iter().copied()).filter(|n| !special.contains(n)).collect();
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

    /// One text per module ([`Module::wgsl_source`]), each once, in any order, is the same
    /// shader as [`wgsl`]'s.
    #[test]
    fn one_text_per_module_combines() {
        let mut parts: Vec<&str> = resolve(&[Module::Dielectric, Module::Rng]).iter().map(|m| m.wgsl_source()).collect();
        parts.reverse();
        validate(&parts.concat()).unwrap();
        let twice = wgsl(&[Module::Ward]) + &wgsl(&[Module::Ggx]);
        assert!(validate(&twice).unwrap_err().message.contains("shaders/math/f32.wgsl is included twice"));
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
        let mut seen: Vec<(&str, Module)> = Vec::new();
        for m in Module::ALL {
            for &s in m.symbols() {
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
            (Module::Math, &["Real", "math_exp", "neg_ln"]),
            (Module::Reflect, &["LobeSample", "reflect_about", "reflect_sample", "reflection_half_vector", "PI"]),
            (Module::Ward, &["ward_sample", "ward_pdf", "ward_eval"]),
            (
                Module::Ggx,
                &["ggx_sample_ndf", "ggx_sample_vndf", "ggx_sample_bounded", "ggx_pdf_ndf", "ggx_pdf_vndf", "ggx_pdf_bounded", "ggx_eval", "ggx_g2", "ggx_lambda"],
            ),
            (Module::Beckmann, &["beckmann_sample_ndf", "beckmann_sample_vndf", "beckmann_pdf_ndf", "beckmann_pdf_vndf", "beckmann_eval", "beckmann_g2"]),
            (Module::Fresnel, &["fresnel_schlick", "fresnel_dielectric", "fresnel_conductor"]),
            (Module::Masking, &["masking_separable", "masking_height_correlated", "masking_height_correlated_transmitted", "masking_ln_beta"]),
            (
                Module::Dielectric,
                &["dielectric_ggx_ndf", "dielectric_ggx_vndf", "dielectric_beckmann_ndf", "dielectric_beckmann_vndf", "dielectric_ggx_vndf_pdf", "dielectric_ggx_eval", "dielectric_ggx_vndf_weight"],
            ),
            (Module::Discrete, &["discrete_sample_cdf", "discrete_sample_cdf_blocks", "discrete_sample_alias", "discrete_f", "discrete_u"]),
        ];
        for (m, names) in wanted {
            let s = m.short_names();
            for n in names {
                assert!(s.contains(n), "{m:?} lacks {n}: {s:?}");
            }
        }
    }

    #[test]
    fn default_discrete_bindings_leave_the_file_unchanged() {
        assert_eq!(DiscreteBindings::default().apply(discrete_short()), discrete_short());
        assert_eq!(module_wgsl(Module::Discrete, DiscreteBindings::default()), Module::Discrete.wgsl_source());
    }

    /// The WESL package compiles, with the `wesl` crate's own resolver and mangler, a renderer's
    /// shader that imports from it and has lobes' short names of its own; naga validates the result.
    #[cfg(feature = "wesl")]
    #[test]
    fn the_wesl_package_compiles_a_renderer_shader() {
        use wesl::syntax::PathOrigin;
        let shader = "import lobes::ggx::{ggx_sample_vndf, ggx_pdf_vndf, ggx_eval};\nimport lobes::rng::rng_uniforms;\n\
                      import lobes::dielectric::dielectric_beckmann_vndf;\nimport lobes::discrete::discrete_sample_alias;\n\
                      const PI: f32 = 3.0;\nfn stretch(x: f32) -> f32 { return x; }\n\
                      @group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\
                      @compute @workgroup_size(1) fn main() {\n\
                      let u = rng_uniforms(vec2(1u, 2u), vec2(3u, 0u));\n\
                      let wi = vec3(0.0, 0.0, 1.0);\n\
                      let s = ggx_sample_vndf(vec2(0.3), wi, u.xy);\n\
                      let t = dielectric_beckmann_vndf(vec2(0.3), wi, u.xyz, 1.5);\n\
                      out[0] = stretch(ggx_eval(vec2(0.3), wi, s.wr) / ggx_pdf_vndf(vec2(0.3), wi, s.wr)) * PI + t.pdf_r + f32(discrete_sample_alias(u.zw, 4u));\n}\n";
        let mut local = wesl::VirtualResolver::new();
        let root = wesl::ModulePath::new(PathOrigin::Absolute, vec!["main".into()]);
        local.add_module(root.clone(), shader.into());
        let mut packages = wesl::PkgResolver::new();
        packages.add_package(&WESL_PACKAGE);
        let mut router = wesl::Router::new();
        router.mount_resolver(wesl::ModulePath::new(PathOrigin::Absolute, vec![]), local);
        router.mount_fallback_resolver(packages);
        let compiled = wesl::Wesl::new("").set_custom_resolver(router).compile(&root).unwrap_or_else(|e| panic!("{e}"));
        validate(&compiled.to_string()).unwrap_or_else(|e| panic!("{e}\n{compiled}"));
    }
}
