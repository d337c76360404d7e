//! lobes' WGSL files (`shaders/lib`, `shaders/math`, `shaders/passes`) composed by naga_oil.
//!
//! Each file states its own import path (`#define_import_path lobes::ggx`) and what it uses
//! from other files (`#import lobes::reflect::{LobeSample, reflect_sample}`); apart from those
//! directives it is plain WGSL, and opens on its own in a WGSL editor that knows naga_oil.
//! [`compose`] has naga_oil (Bevy's shader composer) compose the wanted modules: it resolves the
//! imports and validates every file as a root of its own, reporting an error at the file and
//! line it is in. The WGSL handed on is then the files themselves, in import order (each after
//! the files it imports), with the directive lines blanked: the same text, comments included, as
//! the files, which is what the GPU engine's kernels ([`super::compose`]), `lobes shader`,
//! `lobes check` and renderers (`lobes::embed`) need.
//!
//! A composition may put files of its own in place of the built-in ones with the same import
//! path: the alternatives below (the fast math, counting in global memory, ...) and generated
//! files (a kernel's `lobes::job`, whose `#import`s [`imports_for`] finds from the names it uses).
//!
//! Why not naga_oil's composed module itself: it names every imported item with a module
//! decoration (`ggx_dX_naga_oil_mod_X…X`), and naga's WGSL writer, which could write the module
//! back with those cut, renames whatever ends in a digit (`add64` → `add64_`), so neither is the
//! API the files define. No two files declare the same name (`embed`'s
//! `no_name_is_declared_by_two_modules` for the library; naga rejects a composed kernel that
//! does), so the plain text needs no namespaces.
//!
//! One source per precision: the samplers and the binning are written once over the type
//! `Real`, which the math module of the kernel's [`Precision`] declares (`alias Real = f32;` in
//! `shaders/math/f32.wgsl` and `f32_fast.wgsl`, `alias Real = f64;` in `shaders/math/f64.wgsl`),
//! beside the functions of the same names in each (`math_exp`, `math_atan2`, …, and in
//! `lobes::erf` the Gaussian integrals): [`precision_files`]. The plain WGSL handed on keeps the
//! alias, so it is the files' own text. naga_oil 0.23 cannot hold an alias: a composable module
//! may not declare one (naga's WGSL writer, which writes a module's header for the modules that
//! import it, drops aliases, and naga_oil then rejects the name as one that "requires
//! substitution"), so it cannot be imported either. For naga_oil's check alone each file is
//! therefore read with `Real` spelled as the precision's type (`f32 ` or `f64 `, four columns
//! like `Real`, so positions stay the file's) and the `alias` line blanked (`for_naga_oil`).
//! Every file that uses `Real` says `#import lobes::math::Real`: that is the dependency which
//! brings the alias along in the plain WGSL (and to a renderer's naga_oil, `lobes::embed`), while
//! for lobes' own naga_oil check, which sees `Real` spelled out, the import is one it does not use.

use super::context::GpuError;
use super::precision::Precision;
use crate::wgsl_tokens::{Kind, replace, tokens};
use naga_oil::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor};
use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// One WGSL file of a composition: its path (in messages and in the composed text's file
/// markers) and its text, a naga_oil module that names its import path.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct File {
    pub path: Cow<'static, str>,
    pub source: Cow<'static, str>,
}

impl File {
    /// A file of `shaders/` compiled in (the [`shader!`] macro makes them).
    pub(crate) const fn builtin(path: &'static str, source: &'static str) -> Self {
        Self { path: Cow::Borrowed(path), source: Cow::Borrowed(source) }
    }

    /// A file made at run time (the job's `lobes::job`, a test's broken copy).
    pub fn generated(path: impl Into<String>, source: impl Into<String>) -> Self {
        Self { path: Cow::Owned(path.into()), source: Cow::Owned(source.into()) }
    }

    /// The path its `#define_import_path` names.
    pub fn import_path(&self) -> Option<&str> {
        import_path(&self.source)
    }
}

/// The built-in [`File`] at `$path` under `shaders/`, its text compiled in.
macro_rules! shader {
    ($path:literal) => {
        $crate::engine::gpu::library::File::builtin(concat!("shaders/", $path), include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders/", $path)))
    };
}
pub(crate) use shader;

include!(concat!(env!("OUT_DIR"), "/library_files.rs"));

/// The alternatives (below): files of [`LIBRARY`] that replace a default of the same import path
/// only where a composition asks for them.
fn is_alternative(f: &File) -> bool {
    ALTERNATIVES.iter().any(|a| a.path == f.path)
}

static ALTERNATIVES: [File; 8] = [MATH_F32_FAST, MATH_F64, ERF_F64, COUNTING_GLOBAL, COUNTING_SLABS, DISCRETE_DRAW, NO_FRESNEL, NO_MASKING];

/// The built-in files, one per import path: the library (`shaders/lib`, `shaders/math`) and the
/// passes of `lobes run` (`shaders/passes`). Where a module has alternatives (above), this is its
/// default. `lobes check` hands its own passes and domains (`shaders/check`) to each composition
/// (`check::shaders`).
fn files<'a>() -> impl Iterator<Item = &'a File> {
    LIBRARY.iter().filter(|f| !is_alternative(f))
}

/// `lobes::math` as cheap approximations (instead of `shaders/math/f32.wgsl`, the builtins).
pub const MATH_F32_FAST: File = shader!("math/f32_fast.wgsl");
/// `lobes::math` and `lobes::erf` in f64 (`lobes tradeoff`'s f64 kernels).
pub const MATH_F64: File = shader!("math/f64.wgsl");
pub const ERF_F64: File = shader!("math/erf_f64.wgsl");
/// `lobes::counting` in global memory (instead of packed workgroup counters), for histograms
/// too large for the adapter's workgroup storage.
pub const COUNTING_GLOBAL: File = shader!("passes/counting_global.wgsl");
/// `lobes::counting` in per-invocation slabs of a storage buffer, on CPU adapters
/// (src/engine/gpu/counting.rs).
pub const COUNTING_SLABS: File = shader!("passes/counting_slabs.wgsl");
/// `lobes::draw` of a discrete job (instead of a lobe's).
pub const DISCRETE_DRAW: File = shader!("passes/discrete_draw.wgsl");
/// `lobes::effect_fresnel` and `lobes::effect_masking` of a weighted case without the effect: 1.
pub const NO_FRESNEL: File = shader!("passes/no_fresnel.wgsl");
pub const NO_MASKING: File = shader!("passes/no_masking.wgsl");

/// The files that replace the defaults (`shaders/math/f32.wgsl`, `erf_f32.wgsl`) for the math of
/// `precision` (see [`Precision`]).
pub fn precision_files(precision: Precision) -> Vec<File> {
    match precision {
        Precision::F32Accurate => Vec::new(),
        Precision::F32Fast => vec![MATH_F32_FAST],
        Precision::F64 => vec![MATH_F64, ERF_F64],
    }
}

/// The file that provides import path `module`: the first of `chosen` that names it, else the
/// built-in one.
fn lookup<'a>(module: &str, chosen: &'a [File]) -> Option<&'a File> {
    chosen.iter().chain(files()).find(|f| f.import_path() == Some(module))
}

/// The built-in file that defines import path `module` (`"lobes::ggx"`), or `None`.
pub fn source(module: &str) -> Option<&'static str> {
    files().find(|f| f.import_path() == Some(module)).map(|f| match f.source {
        Cow::Borrowed(s) => s,
        Cow::Owned(_) => unreachable!("built-in files are static"),
    })
}

/// The path a file's `#define_import_path` names.
fn import_path(source: &str) -> Option<&str> {
    source.lines().find_map(|l| l.trim().strip_prefix("#define_import_path")).map(str::trim)
}

/// The plain WGSL of the library `modules` (import paths such as `"lobes::ggx"`) and all they
/// import, in the math of `precision` (see [`compose`]).
pub fn wgsl(modules: &[&str], precision: Precision) -> Result<String, GpuError> {
    compose(modules, &precision_files(precision))
}

/// The built-in file of import path `module` as naga_oil reads it (see the module doc), in f32:
/// the form for a renderer's naga_oil (`lobes::embed`).
pub fn naga_oil_source(module: &str) -> Option<String> {
    source(module).map(|s| for_naga_oil(s, "f32"))
}

/// A file as naga_oil reads it (see the module doc): its `alias Real` line blanked and the word
/// `Real` spelled `scalar` (`f32` or `f64`, padded to four columns) in the code outside the
/// directives (comments are left as written).
fn for_naga_oil(source: &str, scalar: &str) -> String {
    let scalar = format!("{scalar:<4}");
    let line = |l: &str| -> String {
        if l.trim_start().starts_with("alias Real") {
            return String::new();
        }
        if l.trim_start().starts_with('#') {
            return l.to_string();
        }
        replace(l, tokens(l), |t| t.is_name("Real").then(|| scalar.clone()))
    };
    source.lines().map(line).collect::<Vec<_>>().join("\n")
}

/// The type `alias Real = T;` names in one of `order` (the math module), or f32.
fn real_scalar(order: &[&File]) -> String {
    let alias = order.iter().flat_map(|f| f.source.lines()).find_map(|l| l.trim().strip_prefix("alias Real ="));
    alias.map_or("f32".to_string(), |t| t.trim().trim_end_matches(';').trim().to_string())
}

/// The plain WGSL of the modules `roots` and all they import, each file once and after those it
/// imports, the files of `chosen` taking the place of the built-in ones of their import paths.
/// The joined text is validated by naga; only when that fails is every file built by naga_oil as
/// a root of its own, to report the error at its file and line. That per-file build (which also
/// refuses a name used without its `#import`) took as long as the rest of a process's start-up
/// (BENCHMARKS.md, "Where start-up goes"); the unit tests still run it ([`validate_files`]) on
/// every kernel they compose, and they compose every kind. Cached: a run composes the same few
/// sets again and again.
pub fn compose(roots: &[&str], chosen: &[File]) -> Result<String, GpuError> {
    type Cache = Mutex<HashMap<(Vec<String>, Vec<File>), String>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let key = (roots.iter().map(|m| m.to_string()).collect::<Vec<_>>(), chosen.to_vec());
    let cache = CACHE.get_or_init(Default::default);
    if let Some(hit) = cache.lock().unwrap().get(&key) {
        return Ok(hit.clone());
    }
    let order = in_import_order(roots, chosen)?;
    let out: String = order.iter().map(|f| format!("// ---- {} ----\n{}\n", f.path, plain(&f.source))).collect();
    if let Err(joined) = validate_module("the composed module", &out) {
        validate(&order)?;
        return Err(joined);
    }
    cache.lock().unwrap().insert(key, out.clone());
    Ok(out)
}

/// The files of [`compose`] as (path, plain WGSL) without validating them, for a caller that
/// joins them itself (`lobes check`, which maps naga's diagnostics back to each part).
pub fn pieces(roots: &[&str], chosen: &[File]) -> Result<Vec<(String, String)>, GpuError> {
    Ok(in_import_order(roots, chosen)?.iter().map(|f| (f.path.to_string(), plain(&f.source))).collect())
}

/// Validates `roots` and all they import as [`compose`] does, each file a naga_oil root of its
/// own: the first error, at its file and line.
pub fn validate_files(roots: &[&str], chosen: &[File]) -> Result<(), GpuError> {
    validate(&in_import_order(roots, chosen)?)
}

/// `roots` and every module they import, each after those it imports; an import that no file
/// provides is an error.
fn in_import_order<'a>(roots: &[&str], chosen: &'a [File]) -> Result<Vec<&'a File>, GpuError> {
    fn visit<'a>(module: &str, chosen: &'a [File], path: &mut Vec<String>, out: &mut Vec<&'a File>) -> Result<(), GpuError> {
        let file = lookup(module, chosen).ok_or_else(|| GpuError::Shader {
            what: path.last().cloned().unwrap_or_else(|| "composition".into()),
            message: format!("no file defines the import path {module}"),
        })?;
        if out.contains(&file) {
            return Ok(());
        }
        if path.contains(&module.to_string()) {
            return Err(GpuError::Shader { what: file.path.to_string(), message: format!("imports form a cycle: {} -> {module}", path.join(" -> ")) });
        }
        path.push(module.to_string());
        for target in imports_of(&file.source, chosen) {
            visit(&target, chosen, path, out)?;
        }
        path.pop();
        out.push(file);
        Ok(())
    }
    let mut out = Vec::new();
    for m in roots {
        visit(m, chosen, &mut Vec::new(), &mut out)?;
    }
    Ok(out)
}

/// The built-in modules that module `module` imports (`#import` lines of its file), each once,
/// in the file's order.
pub fn imports(module: &str) -> Vec<String> {
    source(module).map(|s| imports_of(s, &[])).unwrap_or_default()
}

/// The modules a file's `#import` lines name, each once, in the file's order (`#import
/// lobes::ggx::ggx_d` names an item of `lobes::ggx`).
fn imports_of(source: &str, chosen: &[File]) -> Vec<String> {
    let (_, imports, _) = naga_oil::compose::get_preprocessor_data(source);
    let known: Vec<&str> = chosen.iter().chain(files()).filter_map(File::import_path).collect();
    let mut out: Vec<String> = Vec::new();
    for import in imports {
        let target = known.iter().filter(|p| import.import == **p || import.import.starts_with(&format!("{p}::"))).max_by_key(|p| p.len());
        // an import no file provides is kept as written, for the error that names it
        let target = target.map_or_else(|| import.import.clone(), |p| p.to_string());
        if !out.contains(&target) {
            out.push(target);
        }
    }
    out
}

/// A file as plain WGSL: its `#define_import_path` and `#import` lines blanked (so that line
/// numbers stay those of the file).
pub fn plain(source: &str) -> String {
    source.lines().map(|l| if l.trim_start().starts_with('#') { "" } else { l }).collect::<Vec<_>>().join("\n")
}

/// Composes each file of `order` (each after the files it imports) with naga_oil as the root of
/// a module of its own (a root builds only the imported items it uses): the check that every
/// import resolves and every file is valid WGSL, errors at the file's line.
fn validate(order: &[&File]) -> Result<(), GpuError> {
    // a user's file (`lobes check`) may nest deeper than an ordinary stack holds
    super::stack::with_big_stack(|| compose_each(order))
}

/// [`validate`]'s work, on its thread.
fn compose_each(order: &[&File]) -> Result<(), GpuError> {
    let caps = naga::valid::Capabilities::default() | naga::valid::Capabilities::FLOAT64;
    let mut composer = Composer::default().with_capabilities(caps);
    // `what`: the file the error is in (it may be one that the file being built imports)
    let error = |e: naga_oil::compose::ComposerError, c: &Composer| GpuError::Shader { what: e.source.path(c).clone(), message: e.emit_to_string(c) };
    let scalar = real_scalar(order);
    let sources: Vec<String> = order.iter().map(|f| for_naga_oil(&f.source, &scalar)).collect();
    for (f, source) in order.iter().zip(&sources) {
        let added = composer.add_composable_module(ComposableModuleDescriptor { source, file_path: &f.path, ..Default::default() });
        if let Err(e) = added {
            return Err(error(e, &composer));
        }
    }
    for (f, source) in order.iter().zip(&sources) {
        if let Err(e) = composer.make_naga_module(NagaModuleDescriptor { source, file_path: &f.path, ..Default::default() }) {
            return Err(error(e, &composer));
        }
    }
    Ok(())
}

/// Parses and validates a composed module with naga, so that a broken composition is a clear
/// error rather than a wgpu panic.
pub fn validate_module(what: &str, source: &str) -> Result<naga::Module, GpuError> {
    super::stack::with_big_stack(|| parse_and_validate(what, source))
}

/// [`validate_module`]'s work, on its thread.
fn parse_and_validate(what: &str, source: &str) -> Result<naga::Module, GpuError> {
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|e| GpuError::Shader { what: what.into(), message: e.emit_to_string(source) })?;
    // FLOAT64 for lobes::experiments::tradeoff's f64 kernels; wgpu still refuses f64 on a device without SHADER_F64.
    let caps = naga::valid::Capabilities::default() | naga::valid::Capabilities::FLOAT64;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps)
        .validate(&module)
        .map_err(|e| GpuError::Shader { what: what.into(), message: format!("{e:?}") })?;
    Ok(module)
}

// The text rules of lobes::embed and build.rs (`declared`): one file, compiled into each (a
// `use crate::embed::text` would make the engine and the embed import each other).
#[path = "../../embed/text.rs"]
#[allow(dead_code, clippy::duplicate_mod)]
mod text;
use text::declared;

/// The `#import` lines a generated file needs: for each module in the import closure of `from`,
/// the names it declares that `code` uses.
pub fn imports_for(code: &str, from: &[&str], chosen: &[File]) -> Result<String, GpuError> {
    let used: Vec<&str> = tokens(code).filter(|t| t.kind == Kind::Ident).map(|t| t.text).collect();
    let mut out = String::new();
    for file in in_import_order(from, chosen)? {
        let names: Vec<&str> = declared(&file.source).into_iter().filter(|n| used.contains(n)).collect();
        if let (Some(module), false) = (file.import_path(), names.is_empty()) {
            out += &format!("#import {module}::{{{}}}\n", names.join(", "));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_file_names_its_import_path_once() {
        let mut seen = Vec::new();
        for f in files() {
            let p = f.import_path().unwrap_or_else(|| panic!("{} has no #define_import_path", f.path));
            assert!(!seen.contains(&p), "{p} twice");
            seen.push(p);
        }
        // each alternative takes the place of a built-in file
        for alt in &ALTERNATIVES {
            assert!(seen.contains(&alt.import_path().unwrap()), "{}", alt.path);
        }
    }

    #[test]
    fn composed_names_are_plain() {
        let src = wgsl(&["lobes::ggx_eval", "lobes::beckmann_eval", "lobes::ward_eval"], Precision::F32Fast).unwrap();
        assert!(src.contains("fn ggx_sample_vndf("));
        assert!(src.contains("fn math_atan2("));
        assert!(!src.contains("#import") && !src.contains("#define_import_path"));
        // each file after those it imports, each once
        let at = |s: &str| src.find(s).unwrap();
        assert!(at("---- shaders/lib/reflect.wgsl") < at("---- shaders/lib/ggx.wgsl"));
        assert!(at("---- shaders/lib/ggx.wgsl") < at("---- shaders/lib/ggx_eval.wgsl"));
        assert_eq!(src.matches("---- shaders/lib/reflect.wgsl").count(), 1);
        assert!(src.contains("---- shaders/math/f32_fast.wgsl"));
        super::super::compose::validate("library", &src).unwrap();
    }

    #[test]
    fn a_broken_file_is_reported_at_its_own_line() {
        // line 3 of the file calls a function no module defines
        let broken = "#define_import_path lobes::broken\n#import lobes::reflect::PI\nfn f() -> f32 { return no_such_fn(PI); }\n";
        let e = compose(&["lobes::broken"], &[File::generated("shaders/lib/broken.wgsl", broken)]).unwrap_err();
        let message = e.to_string();
        assert!(message.contains("shaders/lib/broken.wgsl:3:"), "{message}");
    }

    #[test]
    fn an_import_no_file_provides_or_a_cycle_is_an_error() {
        let lost = File::generated("a.wgsl", "#define_import_path lobes::a\n#import lobes::nowhere::f\nfn g() { f(); }\n");
        let message = compose(&["lobes::a"], &[lost]).unwrap_err().to_string();
        assert!(message.contains("lobes::nowhere"), "{message}");
        let a = File::generated("a.wgsl", "#define_import_path lobes::a\n#import lobes::b::g\nfn f() { g(); }\n");
        let b = File::generated("b.wgsl", "#define_import_path lobes::b\n#import lobes::a::f\nfn g() { f(); }\n");
        let message = compose(&["lobes::a"], &[a, b]).unwrap_err().to_string();
        assert!(message.contains("cycle"), "{message}");
    }

    #[test]
    fn a_generated_file_imports_the_names_it_uses() {
        let imports = imports_for("fn f(a: vec2<f32>, wi: vec3<f32>, u: vec2<f32>) -> LobeSample { return ggx_sample_vndf(a, wi, u); }", &["lobes::ggx"], &[]).unwrap();
        assert!(imports.contains("#import lobes::reflect::{LobeSample}"), "{imports}");
        assert!(imports.contains("#import lobes::ggx::{ggx_sample_vndf}"), "{imports}");
        assert_eq!(imports.lines().count(), 2, "{imports}");
        let decl = declared("@group(0) @binding(1) var<storage, read_write> counts: array<u32>;\nconst A: u32 = 1u;\nfn main() {\n    var local = 0u;\n}\n");
        assert_eq!(decl, ["counts", "A", "main"]);
    }
}
