//! naga_oil (Bevy ≤ 0.19 and many wgpu projects): `#define_import_path`, `#import a::b::{c}`,
//! `#import a::b as x`, `#ifdef`/`#if` shader defs. lobes finds the modules under the shader
//! roots ([`oil_modules`]) and orders them ([`oil_order`]); naga_oil's `Composer` composes the
//! tree, and naga's WGSL writer writes it back as one text.

use super::super::{CheckError, Message, Setting};
use super::super::compose::{Source, global_names, write_wgsl};
use super::super::composition::{Call, Composition, Dialect, Origin, Renamed, UserCode};
use super::front_end::FrontEnd;
use super::roots::{roots, scan, show_roots, stubs};
use super::stage::Stage;
use crate::wgsl_tokens::line_col;
use std::path::PathBuf;

/// The naga_oil front end.
pub(in crate::check) struct NagaOil;

impl FrontEnd for NagaOil {
    /// A naga_oil directive at the start of a line of any file.
    fn sniff(&self, sources: &[Source]) -> bool {
        let directive = |l: &str| {
            let l = l.trim_start();
            ["#import", "#define_import_path", "#ifdef", "#ifndef", "#if ", "#else", "#endif"].iter().any(|d| l.starts_with(d))
        };
        sources.iter().any(|s| s.text.lines().any(directive))
    }

    fn compose(&self, sources: &[Source], c: &Composition) -> Result<UserCode, CheckError> {
        foreign_directives(sources)?;
        let (text, origins, renamed) = naga_oil_tree(sources, c)?;
        Ok(UserCode { renamed, ..UserCode::tree(Dialect::NagaOil, sources, "naga_oil", text, origins) })
    }

    /// Qualified names ([`super::qualified`]), an `#import a::b as x`'s `x` standing for `a::b`.
    fn call(&self, code: &UserCode, call: Call, expr: &str, root_text: &str) -> Result<String, CheckError> {
        let aliases: Vec<(String, String)> = root_text
            .lines()
            .filter_map(|l| l.trim().strip_prefix("#import "))
            .filter_map(|l| l.split_once(" as ").map(|(m, a)| (a.trim().to_string(), m.trim().to_string())))
            .collect();
        super::qualified::resolve(code, call, expr, root_text, &aliases)
    }
}

/// The directives lobes composes: naga_oil's (WGSL and WESL have none at the start of a line).
const DIRECTIVES: [&str; 9] = ["#import", "#define_import_path", "#ifdef", "#ifndef", "#if", "#else", "#endif", "#elif", "#define"];

/// A line of the user's files that starts with a preprocessor directive lobes does not know
/// (a renderer's own, RedGPU's `#redgpu_include`): an error saying what it is and how to
/// proceed, rather than WGSL's parse error at `#`.
pub(super) fn foreign_directives(sources: &[Source]) -> Result<(), CheckError> {
    for s in sources {
        for (n, line) in s.text.lines().enumerate() {
            let l = line.trim_start();
            let Some(word) = l.strip_prefix('#').map(|r| r.split(|c: char| !(c.is_alphanumeric() || c == '_')).next().unwrap_or("")) else { continue };
            if word.is_empty() || DIRECTIVES.iter().any(|d| d[1..] == *word) {
                continue;
            }
            let m = Message::text(format!(
                "{}:{}: `{}` is a preprocessor line of the renderer's own (not WGSL, nor naga_oil's #import/#ifdef family), which lobes cannot expand; give lobes the file as the renderer's preprocessor writes it (a pre-expanded file), or, where the line pulls in a module, write it as a naga_oil `#import` and stand in for that module with ",
                s.name,
                n + 1,
                l.trim_end()
            ));
            return Err(CheckError::Advised(m.setting(Setting::Stub).then(" MODULE=FILE; a switch the line tests is a ").setting(Setting::Define)));
        }
    }
    Ok(())
}

/// `--define` values as naga_oil's shader defs: no value or `true`/`false` a bool, else an
/// integer (`7`, `-1`; `7u` unsigned).
fn shader_defs(c: &Composition) -> Result<std::collections::HashMap<String, naga_oil::compose::ShaderDefValue>, CheckError> {
    use naga_oil::compose::ShaderDefValue as V;
    let digits = |d: &str| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit());
    c.defines
        .iter()
        .map(|(n, v)| {
            let value = match v.as_deref() {
                None | Some("true") => V::Bool(true),
                Some("false") => V::Bool(false),
                Some(s) => match (s.strip_suffix('u').map(str::parse::<u32>), s.parse::<i32>()) {
                    (Some(Ok(u)), _) => V::UInt(u),
                    (_, Ok(i)) => V::Int(i),
                    // an integer, but not one naga_oil's i32 or u32 holds
                    (Some(Err(_)), _) if s.strip_suffix('u').is_some_and(digits) => {
                        return Err(CheckError::setting(Setting::Define, format!("{n}={s}: {s} is out of the range of u32 (0 to {}u)", u32::MAX)));
                    }
                    (None, Err(_)) if digits(s.strip_prefix('-').unwrap_or(s)) => {
                        return Err(CheckError::setting(Setting::Define, format!("{n}={s}: {s} is out of the range of i32 ({} to {})", i32::MIN, i32::MAX)));
                    }
                    _ => return Err(CheckError::setting(Setting::Define, format!("{n}={s}: the value must be true, false or an integer (7, -1, 7u)"))),
                },
            };
            Ok((n.clone(), value))
        })
        .collect()
}

/// A naga_oil module: its import path, file and text.
struct OilModule {
    path: String,
    source: Source,
    /// The file's `#import`s (module paths; an imported item's module is its prefix).
    imports: Vec<String>,
    /// Whether it stands in for a module (`--stub`).
    stub: bool,
    /// Other files under the roots that declare the same `#define_import_path`.
    also: Vec<String>,
}

fn oil_module(source: Source, as_name: Option<&str>) -> Option<OilModule> {
    let (name, imports, _) = naga_oil::compose::get_preprocessor_data(&source.text);
    let path = as_name.map(String::from).or(name)?;
    Some(OilModule { path, imports: imports.into_iter().map(|i| i.import).collect(), source, stub: as_name.is_some(), also: Vec::new() })
}

/// The modules a naga_oil tree may import: stubs first, then the files given after the
/// sampler's, then every .wgsl under the roots (a path already given by a stub or a file stays
/// theirs; one declared by two files under the roots keeps both names, refused if imported).
fn oil_modules(sources: &[Source], c: &Composition, roots: &[PathBuf]) -> Result<Vec<OilModule>, CheckError> {
    let mut modules: Vec<OilModule> = Vec::new();
    for (m, s) in stubs(c)? {
        modules.push(oil_module(s, Some(&m)).expect("a stub has a name"));
    }
    for s in &sources[1..] {
        match oil_module(s.clone(), None) {
            Some(m) => modules.push(m),
            None => {
                let m = Message::text(format!("{}: no #define_import_path: with naga_oil imports, give the sampler's file first and its modules by ", s.name));
                return Err(CheckError::Advised(m.setting(Setting::ShaderRoot).then(" (or as files with their #define_import_path)")));
            }
        }
    }
    let given = modules.len();
    let mut found = Vec::new();
    for r in roots {
        scan(r, &["wgsl"], &mut found);
    }
    let skip: Vec<PathBuf> = sources.iter().filter_map(|s| std::fs::canonicalize(&s.name).ok()).collect();
    let mut index: std::collections::HashMap<String, usize> = modules.iter().enumerate().map(|(i, m)| (m.path.clone(), i)).collect();
    for f in found {
        if std::fs::canonicalize(&f).is_ok_and(|f| skip.contains(&f)) {
            continue;
        }
        let Ok(text) = std::fs::read_to_string(&f) else { continue };
        let Some(m) = oil_module(Source { name: f.display().to_string(), text }, None) else { continue };
        match index.get(&m.path) {
            Some(&i) if i >= given => modules[i].also.push(m.source.name),
            Some(_) => {}
            None => {
                index.insert(m.path.clone(), modules.len());
                modules.push(m);
            }
        }
    }
    Ok(modules)
}

/// The modules the root needs (indices of `modules`), each after those it imports; an import
/// that no module declares, that two files declare, or that comes back to the root or to a
/// module on the way, is an error naming it.
fn oil_order(root: &OilModule, root_path: Option<&str>, modules: &[OilModule], roots: &[PathBuf]) -> Result<Vec<usize>, CheckError> {
    let index: std::collections::HashMap<&str, usize> = modules.iter().enumerate().map(|(i, m)| (m.path.as_str(), i)).collect();
    let mut order = Vec::new();
    let mut done = vec![false; modules.len()];
    let mut stack: Vec<String> = root_path.map(String::from).into_iter().collect();
    // depth first, without recursion (a chain of thousands of modules): (module, next import)
    let mut todo: Vec<(Option<usize>, usize)> = vec![(None, 0)];
    while let Some((at, next)) = todo.pop() {
        let from = at.map_or(root, |i| &modules[i]);
        let Some(import) = from.imports.get(next) else {
            if let Some(i) = at {
                done[i] = true;
                order.push(i);
                stack.pop();
            }
            continue;
        };
        todo.push((at, next + 1));
        let parent = import.rsplit_once("::").map(|(p, _)| p);
        if root_path.is_some_and(|r| r == import || Some(r) == parent) {
            return Err(CheckError::Input(format!(
                "{}: imports form a cycle through the sampler's file: {} -> {} (the sampler's file, {})",
                from.source.name,
                stack.join(" -> "),
                root_path.expect("a root path"),
                root.source.name
            )));
        }
        let Some(&i) = index.get(import.as_str()).or_else(|| parent.and_then(|p| index.get(p))) else {
            return Err(unresolved(from, import, parent, modules, roots));
        };
        if done[i] {
            continue;
        }
        if stack.contains(&modules[i].path) {
            return Err(CheckError::Input(format!("{}: imports form a cycle: {} -> {}", modules[i].source.name, stack.join(" -> "), modules[i].path)));
        }
        if !modules[i].also.is_empty() {
            let m = Message::text(format!(
                "{}: `{}` is declared (#define_import_path {}) by more than one file under the shader roots: {} and {}; which one the renderer composes is not for lobes to guess. Remove or rename the stale copy, or give the right one with ",
                from.source.name,
                modules[i].path,
                modules[i].path,
                modules[i].source.name,
                modules[i].also.join(" and "),
            ));
            return Err(CheckError::Advised(m.setting(Setting::Stub).then(format!(" {}=FILE", modules[i].path))));
        }
        stack.push(modules[i].path.clone());
        todo.push((Some(i), 0));
    }
    Ok(order)
}

/// The error of an import no module declares: at the import, with the roots and the closest
/// module names.
fn unresolved(from: &OilModule, import: &str, parent: Option<&str>, modules: &[OilModule], roots: &[PathBuf]) -> CheckError {
    let at = from.source.text.find(import).map(|b| line_col(&from.source.text, b));
    let at = at.map_or(from.source.name.clone(), |(l, c)| format!("{}:{l}:{c}", from.source.name));
    let names: Vec<&str> = modules.iter().map(|m| m.path.as_str()).collect();
    let close = crate::suggest::closest(import, names.iter().copied()).or_else(|| parent.and_then(|p| crate::suggest::closest(p, names.iter().copied())));
    let m = Message::text(format!(
        "{at}: error: unresolved import `{import}`: no file under the shader roots ({}) has `#define_import_path {import}`{}; {}. Add its folder with ",
        show_roots(roots),
        close.map_or(String::new(), |c| format!(" (closest: `{c}`)")),
        some_names("modules found", &names, import),
    ));
    CheckError::Advised(m.setting(Setting::ShaderRoot).then(", or stand in for it with ").setting(Setting::Stub).then(format!(" {import}=FILE")))
}

/// "modules found: a, b, c" for a few names; past 12 the 8 closest to `near` and how many more.
fn some_names(what: &str, names: &[&str], near: &str) -> String {
    if names.is_empty() {
        return format!("{what}: none");
    }
    if names.len() <= 12 {
        return format!("{what}: {}", names.join(", "));
    }
    let mut by: Vec<(f64, &str)> = names.iter().map(|n| (strsim::normalized_levenshtein(n, near), *n)).collect();
    by.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(b.1)));
    let shown: Vec<&str> = by.iter().take(8).map(|(_, n)| *n).collect();
    format!("{} {what}, the closest: {} (and {} more)", names.len(), shown.join(", "), names.len() - shown.len())
}

/// The tree of `sources[0]` composed by naga_oil, as WGSL text (the root's names as written, the
/// imported ones decorated), each decorated name's origin, and the names naga's writer changed.
fn naga_oil_tree(sources: &[Source], c: &Composition) -> Result<(String, Vec<Origin>, Renamed), CheckError> {
    use naga_oil::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderLanguage, ShaderType};
    let roots = roots(sources, c);
    let defs = shader_defs(c)?;
    let modules = oil_modules(sources, c, &roots)?;
    let root = oil_module(sources[0].clone(), Some("")).expect("named");
    let root_path = naga_oil::compose::get_preprocessor_data(&sources[0].text).0;
    let order = oil_order(&root, root_path.as_deref(), &modules, &roots)?;
    if let Some(m) = modules.iter().enumerate().find(|(i, m)| m.stub && !order.contains(i)).map(|(_, m)| m) {
        let message = format!("{}: no import of {} or of the modules it imports names that module, so the stub stands in for nothing; check the module path (as the #import names it)", m.path, sources[0].name);
        return Err(CheckError::setting(Setting::Stub, message));
    }
    let _stage = Stage::enter(format!(
        "composing {} and the {} naga_oil modules it imports (under {}) with naga_oil's Composer",
        sources[0].name,
        order.len(),
        show_roots(&roots)
    ));
    let mut composer = Composer::default().with_capabilities(naga::valid::Capabilities::all());
    let oil_error = |e: naga_oil::compose::ComposerError, composer: &Composer, module: &str| {
        let text = e.emit_to_string(composer);
        // codespan's "┌─ file:line:col" first, as compilers write it
        let at = text.lines().find_map(|l| l.trim_start().strip_prefix("┌─ ")).map(str::trim).unwrap_or("");
        // naga_oil parses a module when a root needs it: the file says which module erred
        let module = modules
            .iter()
            .find(|m| at.rsplitn(3, ':').nth(2) == Some(m.source.name.as_str()))
            .map_or(module.to_string(), |m| m.path.clone());
        CheckError::Wgsl(format!("{at}: error in module {module}: {}\n{text}", e.inner))
    };
    for &i in &order {
        let m = &modules[i];
        let added = composer
            .add_composable_module(ComposableModuleDescriptor {
                source: &m.source.text,
                file_path: &m.source.name,
                language: ShaderLanguage::Wgsl,
                as_name: m.stub.then(|| m.path.clone()),
                shader_defs: defs.clone(),
                ..Default::default()
            })
            .map(|_| ());
        added.map_err(|e| oil_error(e, &composer, &m.path))?;
    }
    let module = composer
        .make_naga_module(NagaModuleDescriptor { source: &sources[0].text, file_path: &sources[0].name, shader_type: ShaderType::Wgsl, shader_defs: defs, additional_imports: &[] })
        .map_err(|e| oil_error(e, &composer, &format!("{} (the sampler's file)", root_name(&sources[0]))))?;
    let suffixes: Vec<(String, String)> = order.iter().map(|&i| (modules[i].path.clone(), Composer::decorated_name(Some(&modules[i].path), ""))).collect();
    let mut origins = Vec::new();
    for name in global_names(&module) {
        if let Some((path, suffix)) = suffixes.iter().find(|(_, s)| name.ends_with(s.as_str())) {
            origins.push((name.clone(), path.clone(), name[..name.len() - suffix.len()].to_string()));
        }
    }
    let (text, renamed) = write_wgsl_renamed(&module, naga::valid::Capabilities::all())?;
    for o in &mut origins {
        if let Some((written, _)) = renamed.iter().find(|(_, original)| *original == o.0) {
            o.0 = written.clone();
        }
    }
    Ok((text, origins, renamed))
}

/// The sampler file's own import path, or its file name.
fn root_name(s: &Source) -> String {
    naga_oil::compose::get_preprocessor_data(&s.text).0.unwrap_or_else(|| s.name.clone())
}

/// [`write_wgsl`], and the functions whose names the writer changed (its namer keeps ASCII
/// letters, digits and single underscores: `würfel` → `wrfel`, `rand_` → `rand`): the written
/// text parsed again holds the functions in the module's order (the writer writes them in arena
/// order, callees first, and the parser keeps that order), so each is paired with its handle's.
fn write_wgsl_renamed(module: &naga::Module, caps: naga::valid::Capabilities) -> Result<(String, Renamed), CheckError> {
    let module = &*super::super::compose::writable(module);
    let text = write_wgsl(module, caps)?;
    let written = naga::front::wgsl::parse_str(&text).map_err(|e| CheckError::Internal(format!("the written WGSL does not parse: {}", e.message())))?;
    if written.functions.len() != module.functions.len() {
        return Err(CheckError::Internal(format!("naga's WGSL writer wrote {} functions of {}", written.functions.len(), module.functions.len())));
    }
    let renamed = written
        .functions
        .iter()
        .zip(module.functions.iter())
        .filter_map(|((_, w), (_, f))| Some((w.name.clone()?, f.name.clone()?)))
        .filter(|(w, f)| w != f)
        .collect();
    Ok((text, renamed))
}
