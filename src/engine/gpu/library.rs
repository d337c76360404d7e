//! The WGSL library (`shaders/lib`, `shaders/math`) composed by naga_oil.
//!
//! Each library file states its own import path (`#define_import_path lobes::ggx`) and what it
//! uses from other files (`#import lobes::reflect::{LobeSample, reflect_sample}`); apart from those
//! directives it is plain WGSL. [`wgsl`] has naga_oil (Bevy's shader composer) compose the wanted
//! modules: it resolves the imports, validates every file and reports an error at the file and
//! line it is in. The WGSL handed on is then the files themselves, in import order (each after
//! the files it imports), with the directive lines blanked: the same text, comments included, as
//! the files, which is what the passes (`shaders/passes`, which use the names of the job's
//! composed header), `lobes shader`, `lobes check` and renderers (`lobes::embed`) need.
//!
//! Why not naga_oil's composed module itself: it names every imported item with a module
//! decoration (`ggx_dX_naga_oil_mod_X…X`), and naga's WGSL writer, which could write the module
//! back with those cut, renames whatever ends in a digit (`add64` → `add64_`), so neither is the
//! API the files define. No two library files declare the same name
//! (`embed`'s `no_name_is_declared_by_two_modules`), so the plain text needs no namespaces.

use super::context::GpuError;
use naga_oil::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor};
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// The math module the library's `#import lobes::math` resolves to (see
/// [`super::precision::Precision`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Math {
    /// `shaders/math/f32.wgsl`: the WGSL builtins.
    Accurate,
    /// `shaders/math/f32_fast.wgsl`: the same names as cheap approximations.
    Fast,
}

/// The library's files: (path under the repository, source). The import path of each is the one
/// its `#define_import_path` names.
const FILES: [(&str, &str); 12] = [
    ("shaders/lib/rng.wgsl", include_str!("../../../shaders/lib/rng.wgsl")),
    ("shaders/lib/reflect.wgsl", include_str!("../../../shaders/lib/reflect.wgsl")),
    ("shaders/lib/microfacet.wgsl", include_str!("../../../shaders/lib/microfacet.wgsl")),
    ("shaders/lib/ward.wgsl", include_str!("../../../shaders/lib/ward.wgsl")),
    ("shaders/lib/ward_eval.wgsl", include_str!("../../../shaders/lib/ward_eval.wgsl")),
    ("shaders/lib/ggx.wgsl", include_str!("../../../shaders/lib/ggx.wgsl")),
    ("shaders/lib/ggx_eval.wgsl", include_str!("../../../shaders/lib/ggx_eval.wgsl")),
    ("shaders/lib/beckmann.wgsl", include_str!("../../../shaders/lib/beckmann.wgsl")),
    ("shaders/lib/beckmann_eval.wgsl", include_str!("../../../shaders/lib/beckmann_eval.wgsl")),
    ("shaders/lib/fresnel.wgsl", include_str!("../../../shaders/lib/fresnel.wgsl")),
    ("shaders/lib/masking.wgsl", include_str!("../../../shaders/lib/masking.wgsl")),
    ("shaders/lib/discrete.wgsl", include_str!("../../../shaders/lib/discrete.wgsl")),
];

const MATH_F32: (&str, &str) = ("shaders/math/f32.wgsl", include_str!("../../../shaders/math/f32.wgsl"));
const MATH_F32_FAST: (&str, &str) = ("shaders/math/f32_fast.wgsl", include_str!("../../../shaders/math/f32_fast.wgsl"));

/// The library's files with the math module of `math`.
fn files(math: Math) -> impl Iterator<Item = (&'static str, &'static str)> {
    let math = match math {
        Math::Accurate => MATH_F32,
        Math::Fast => MATH_F32_FAST,
    };
    FILES.into_iter().chain([math])
}

/// The file that defines import path `module` (`"lobes::ggx"`), or `None`.
pub fn source(module: &str) -> Option<&'static str> {
    files(Math::Accurate).find(|(_, src)| import_path(src) == Some(module)).map(|(_, src)| src)
}

/// The path a file's `#define_import_path` names.
fn import_path(source: &str) -> Option<&str> {
    source.lines().find_map(|l| l.trim().strip_prefix("#define_import_path")).map(str::trim)
}

/// A composer holding every library file, with `math` as `lobes::math` (naga_oil wants a
/// module's imports added before it).
fn composer(math: Math, extra: Option<(&str, &str)>) -> Result<Composer, GpuError> {
    let mut composer = Composer::default();
    let every: Vec<&str> = files(math).filter_map(|(_, s)| import_path(s)).collect();
    let extra = extra.map(|(p, s)| (p.to_string(), s.to_string()));
    let all = in_import_order(&every, math).into_iter().map(|(p, s)| (p.to_string(), s.to_string())).chain(extra);
    for (path, src) in all {
        let added = composer.add_composable_module(ComposableModuleDescriptor { source: &src, file_path: &path, ..Default::default() });
        if let Err(e) = added {
            return Err(GpuError::Shader { what: path, message: e.emit_to_string(&composer) });
        }
    }
    Ok(composer)
}

/// The plain WGSL of the library `modules` (import paths such as `"lobes::ggx"`) and all they
/// import, each file once and after those it imports, with `math` as `lobes::math`. Cached: a run
/// composes the same few sets again and again.
pub fn wgsl(modules: &[&str], math: Math) -> Result<String, GpuError> {
    type Cache = Mutex<HashMap<(Vec<String>, Math), String>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let key = (modules.iter().map(|m| m.to_string()).collect::<Vec<_>>(), math);
    let cache = CACHE.get_or_init(Default::default);
    if let Some(hit) = cache.lock().unwrap().get(&key) {
        return Ok(hit.clone());
    }
    compose(modules, math, None)?;
    let out: String = in_import_order(modules, math).into_iter().map(|(path, src)| format!("// ---- {path} ----\n{}\n", plain(src))).collect();
    cache.lock().unwrap().insert(key, out.clone());
    Ok(out)
}

/// `modules` and every module they import, each after those it imports, as (file path, source).
fn in_import_order(modules: &[&str], math: Math) -> Vec<(&'static str, &'static str)> {
    fn visit(module: &str, math: Math, out: &mut Vec<(&'static str, &'static str)>) {
        let file = files(math).find(|(_, src)| import_path(src) == Some(module));
        let Some(file) = file else { return };
        if out.contains(&file) {
            return;
        }
        for target in imports_of(file.1) {
            visit(target, math, out);
        }
        out.push(file);
    }
    let mut out = Vec::new();
    for m in modules {
        visit(m, math, &mut out);
    }
    out
}

/// The library modules that library module `module` imports (`#import` lines of its file),
/// each once, in the file's order.
pub fn imports(module: &str) -> Vec<&'static str> {
    source(module).map(imports_of).unwrap_or_default()
}

fn imports_of(source: &str) -> Vec<&'static str> {
    let (_, imports, _) = naga_oil::compose::get_preprocessor_data(source);
    let mut out: Vec<&'static str> = Vec::new();
    for import in imports {
        // `#import lobes::ggx::ggx_d` names an item of `lobes::ggx`
        let target = files(Math::Accurate)
            .filter_map(|(_, s)| import_path(s))
            .find(|p| import.import == *p || import.import.starts_with(&format!("{p}::")));
        if let Some(target) = target
            && !out.contains(&target)
        {
            out.push(target);
        }
    }
    out
}

/// A library file as plain WGSL: its `#define_import_path` and `#import` lines blanked (so that
/// line numbers stay those of the file).
pub fn plain(source: &str) -> String {
    source.lines().map(|l| if l.trim_start().starts_with('#') { "" } else { l }).collect::<Vec<_>>().join("\n")
}

/// Composes each of `modules` and the modules they import with naga_oil, each file as the root
/// of a module of its own (a root builds only the imported items it uses): the check that every
/// import resolves and every file is valid WGSL, errors at the file's line. `extra`: one more
/// file, as if it were in the library.
fn compose(modules: &[&str], math: Math, extra: Option<(&str, &str)>) -> Result<(), GpuError> {
    let mut composer = composer(math, extra)?;
    let mut order = in_import_order(modules, math);
    order.extend(extra.filter(|(_, src)| import_path(src).is_some_and(|p| modules.contains(&p))));
    for (path, src) in order {
        composer
            .make_naga_module(NagaModuleDescriptor { source: src, file_path: path, ..Default::default() })
            .map_err(|e| GpuError::Shader { what: path.into(), message: e.emit_to_string(&composer) })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_file_names_its_import_path_once() {
        let mut seen = Vec::new();
        for (path, src) in files(Math::Accurate) {
            let p = import_path(src).unwrap_or_else(|| panic!("{path} has no #define_import_path"));
            assert!(!seen.contains(&p), "{p} twice");
            seen.push(p);
        }
        assert_eq!(import_path(MATH_F32_FAST.1), Some("lobes::math"));
    }

    #[test]
    fn composed_names_are_plain() {
        let src = wgsl(&["lobes::ggx_eval", "lobes::beckmann_eval", "lobes::ward_eval"], Math::Fast).unwrap();
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
        let e = compose(&["lobes::broken"], Math::Accurate, Some(("shaders/lib/broken.wgsl", broken))).unwrap_err();
        let message = e.to_string();
        assert!(message.contains("shaders/lib/broken.wgsl:3:"), "{message}");
    }
}
