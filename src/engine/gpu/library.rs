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
//!
//! One source per precision: the samplers and the binning are written once over the type
//! `Real`, which the math module of the kernel's [`Precision`] declares (`alias Real = f32;` in
//! `shaders/math/f32.wgsl` and `f32_fast.wgsl`, `alias Real = f64;` in `shaders/math/f64.wgsl`),
//! beside the functions of the same names in each (`math_exp`, `math_atan2`, …, and in
//! `lobes::erf` the Gaussian integrals). The plain WGSL handed on keeps the alias, so it is
//! the files' own text. naga_oil 0.23 cannot hold an alias: a composable module may not declare
//! one (naga's WGSL writer, which writes a module's header for the modules that import it, drops
//! aliases, and naga_oil then rejects the name as one that "requires substitution"), so it cannot
//! be imported either. For naga_oil's check alone each file is therefore read with `Real`
//! spelled as the precision's type (`f32 ` or `f64 `, four columns like `Real`, so positions
//! stay the file's) and the `alias` line blanked ([`naga_oil_source`]). Every file that uses `Real`
//! says `#import lobes::math::Real`: that is the dependency which brings the alias along in the
//! plain WGSL (and to a renderer's naga_oil, `lobes::embed`), while for lobes' own naga_oil check,
//! which sees `Real` spelled out, the import is one it does not use.

use super::context::GpuError;
use super::precision::Precision;
use naga_oil::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor};
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

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
const MATH_F64: (&str, &str) = ("shaders/math/f64.wgsl", include_str!("../../../shaders/math/f64.wgsl"));
const ERF_F32: (&str, &str) = ("shaders/math/erf_f32.wgsl", include_str!("../../../shaders/math/erf_f32.wgsl"));
const ERF_F64: (&str, &str) = ("shaders/math/erf_f64.wgsl", include_str!("../../../shaders/math/erf_f64.wgsl"));

/// The library's files with the `lobes::math` and `lobes::erf` of `precision`.
fn files(precision: Precision) -> impl Iterator<Item = (&'static str, &'static str)> {
    let (math, erf) = match precision {
        Precision::F32Accurate => (MATH_F32, ERF_F32),
        Precision::F32Fast => (MATH_F32_FAST, ERF_F32),
        Precision::F64 => (MATH_F64, ERF_F64),
    };
    FILES.into_iter().chain([math, erf])
}

/// The file that defines import path `module` (`"lobes::ggx"`), or `None`; the f32 one of the
/// math modules.
pub fn source(module: &str) -> Option<&'static str> {
    files(Precision::F32Accurate).find(|(_, src)| import_path(src) == Some(module)).map(|(_, src)| src)
}

/// The file of import path `module` as naga_oil reads it (see the module doc), in f32: the
/// form for a renderer's naga_oil (`lobes::embed`).
pub fn naga_oil_source(module: &str) -> Option<String> {
    source(module).map(|s| for_naga_oil(s, Precision::F32Accurate))
}

/// A library file as naga_oil reads it (see the module doc): its `alias Real` line blanked and
/// the word `Real` spelled `f32 ` or `f64 ` outside the directives.
fn for_naga_oil(source: &str, precision: Precision) -> String {
    let scalar = format!("{:<4}", precision.scalar());
    let word = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let line = |l: &str| -> String {
        if l.trim_start().starts_with("alias Real") {
            return String::new();
        }
        if l.trim_start().starts_with('#') {
            return l.to_string();
        }
        let mut out = String::with_capacity(l.len());
        let mut rest = l;
        while let Some(at) = rest.find("Real") {
            let (before, after) = (&rest[..at], &rest[at + 4..]);
            let whole = !before.ends_with(word) && !after.starts_with(word);
            out.push_str(before);
            out.push_str(if whole { &scalar } else { "Real" });
            rest = after;
        }
        out + rest
    };
    source.lines().map(line).collect::<Vec<_>>().join("\n")
}

/// The path a file's `#define_import_path` names.
fn import_path(source: &str) -> Option<&str> {
    source.lines().find_map(|l| l.trim().strip_prefix("#define_import_path")).map(str::trim)
}

/// A composer holding the library `modules` and those they import, with the math modules of
/// `precision` (naga_oil wants a module's imports added before it), and `extra`.
fn composer(modules: &[&str], precision: Precision, extra: Option<(&str, &str)>) -> Result<Composer, GpuError> {
    let mut composer = Composer::default().with_capabilities(naga::valid::Capabilities::FLOAT64);
    let mut wanted = modules.to_vec();
    wanted.extend(extra.map(|(_, src)| imports_of(src)).unwrap_or_default());
    let extra = extra.map(|(p, s)| (p.to_string(), s.to_string()));
    let all = in_import_order(&wanted, precision).into_iter().map(|(p, s)| (p.to_string(), s.to_string())).chain(extra);
    for (path, src) in all {
        let src = for_naga_oil(&src, precision);
        let added = composer.add_composable_module(ComposableModuleDescriptor { source: &src, file_path: &path, ..Default::default() });
        if let Err(e) = added {
            return Err(GpuError::Shader { what: path, message: e.emit_to_string(&composer) });
        }
    }
    Ok(composer)
}

/// The plain WGSL of the library `modules` (import paths such as `"lobes::ggx"`) and all they
/// import, each file once and after those it imports, with the math modules of `precision`.
/// Cached: a run composes the same few sets again and again.
pub fn wgsl(modules: &[&str], precision: Precision) -> Result<String, GpuError> {
    type Cache = Mutex<HashMap<(Vec<String>, Precision), String>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let key = (modules.iter().map(|m| m.to_string()).collect::<Vec<_>>(), precision);
    let cache = CACHE.get_or_init(Default::default);
    if let Some(hit) = cache.lock().unwrap().get(&key) {
        return Ok(hit.clone());
    }
    compose(modules, precision, None)?;
    let out: String = in_import_order(modules, precision).into_iter().map(|(path, src)| format!("// ---- {path} ----\n{}\n", plain(src))).collect();
    cache.lock().unwrap().insert(key, out.clone());
    Ok(out)
}

/// `modules` and every module they import, each after those it imports, as (file path, source).
fn in_import_order(modules: &[&str], precision: Precision) -> Vec<(&'static str, &'static str)> {
    fn visit(module: &str, precision: Precision, out: &mut Vec<(&'static str, &'static str)>) {
        let file = files(precision).find(|(_, src)| import_path(src) == Some(module));
        let Some(file) = file else { return };
        if out.contains(&file) {
            return;
        }
        for target in imports_of(file.1) {
            visit(target, precision, out);
        }
        out.push(file);
    }
    let mut out = Vec::new();
    for m in modules {
        visit(m, precision, &mut out);
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
        let target = files(Precision::F32Accurate)
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
fn compose(modules: &[&str], precision: Precision, extra: Option<(&str, &str)>) -> Result<(), GpuError> {
    let mut composer = composer(modules, precision, extra)?;
    let mut order = in_import_order(modules, precision);
    order.extend(extra.filter(|(_, src)| import_path(src).is_some_and(|p| modules.contains(&p))));
    for (path, src) in order {
        let src = for_naga_oil(src, precision);
        composer
            .make_naga_module(NagaModuleDescriptor { source: &src, file_path: path, ..Default::default() })
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
        for (path, src) in files(Precision::F32Accurate).chain([MATH_F32_FAST, MATH_F64, ERF_F64]) {
            let p = import_path(src).unwrap_or_else(|| panic!("{path} has no #define_import_path"));
            seen.push(p);
        }
        // each once, but lobes::math (f32, f32-fast, f64) and lobes::erf (f32, f64)
        for p in &seen {
            let per_precision = [("lobes::math", 3), ("lobes::erf", 2)];
            let expected = per_precision.iter().find(|(m, _)| m == p).map_or(1, |(_, n)| *n);
            assert_eq!(seen.iter().filter(|q| q == &p).count(), expected, "{p}");
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
        let e = compose(&["lobes::broken"], Precision::F32Accurate, Some(("shaders/lib/broken.wgsl", broken))).unwrap_err();
        let message = e.to_string();
        assert!(message.contains("shaders/lib/broken.wgsl:3:"), "{message}");
    }
}
