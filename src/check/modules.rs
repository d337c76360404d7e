//! A user's sampler as it is in its repository: the modules its file imports, found under the
//! shader roots and composed the way the renderer composes them, into WGSL that lobes' glue
//! (`gpu::glue`) calls.
//!
//! Three dialects, told apart by the files' own text ([`dialect`]):
//! - plain WGSL: the files, in order, as they are (their lines keep their numbers in the
//!   composition, `compose::Composed`);
//! - naga_oil (Bevy ≤ 0.19 and many wgpu projects): `#define_import_path`, `#import a::b::{c}`,
//!   `#import a::b as x`, `#ifdef`/`#if` shader defs. naga_oil's `Composer` composes the tree;
//! - WESL (Bevy 0.20): `import package::a::b;`, `super::`, `@if` features, by the `wesl` crate
//!   (0.4, feature "wesl"), with lobes' resolver over the shader roots ([`Roots`]).
//!
//! A composed tree becomes one WGSL text: the naga module of the tree and the glue, compacted to
//! what the glue's calls reach (so a module's bind groups, ray queries or other entry points need
//! not suit lobes' passes), written back by naga's WGSL writer. Errors in the user's modules are
//! the composer's, at the module's file:line:column; an import that no root holds names the
//! module, the roots searched and the closest module names.

use super::CheckError;
use super::compose::{Source, write_wgsl};
use super::composition::{Composition, Dialect, Origin, Renamed, UserCode, check_package, dialect};
use std::path::{Path, PathBuf};

impl UserCode {
    /// The functions named `name` (plain, or `module::path::name`) in `module`.
    pub fn functions_named(&self, module: &naga::Module, name: &str) -> Vec<naga::Handle<naga::Function>> {
        module
            .functions
            .iter()
            .filter(|(_, f)| {
                let Some(n) = f.name.as_deref() else { return false };
                n == name
                    || self.renamed.iter().any(|(written, original)| written == n && original == name)
                    || self.origins.iter().any(|(m, path, item)| m == n && (item == name || format!("{path}::{item}") == name))
            })
            .map(|(h, _)| h)
            .collect()
    }
}

impl UserCode {
    /// `expr` (a call expression of --sample, --pdf or --eval) with each qualified name
    /// `module::item` as the user wrote it (WESL's `ggx::pdf` or `package::sampling::ggx::pdf`,
    /// naga_oil's `ggx::pdf` or an `#import … as alias`'s `alias::pdf`) replaced by that item's
    /// name in the composed text. A module path matches an import's full path or its last
    /// segments. A name no imported module holds is an error naming the imported items.
    pub fn resolve_qualified(&self, flag: &str, expr: &str, root_text: &str) -> Result<String, CheckError> {
        if matches!(self.dialect, Dialect::Glsl | Dialect::Spirv) {
            let named = super::dialect::call_names(flag, expr, &self.origins)?;
            return super::dialect::out_params::rewrite(flag, &named, &self.parts[0].text);
        }
        if self.dialect == Dialect::Wgsl && !expr.contains("::") {
            return Ok(expr.to_string());
        }
        if self.dialect == Dialect::Wgsl {
            return Err(CheckError::Input(format!(
                "{flag} '{expr}': a qualified name (module::function) needs imports, and {} import nothing; name the function as it is declared",
                self.files.join(", ")
            )));
        }
        // naga_oil's `#import a::b as x`: x stands for a::b
        let aliases: Vec<(String, String)> = root_text
            .lines()
            .filter_map(|l| l.trim().strip_prefix("#import "))
            .filter_map(|l| l.split_once(" as ").map(|(m, a)| (a.trim().to_string(), m.trim().to_string())))
            .collect();
        let b = expr.as_bytes();
        let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
        let (mut out, mut i) = (String::new(), 0);
        while i < b.len() {
            if !ident(b[i]) || (i > 0 && ident(b[i - 1])) {
                out.push(expr[i..].chars().next().expect("in range"));
                i += expr[i..].chars().next().expect("in range").len_utf8();
                continue;
            }
            // a path: identifiers joined by ::
            let start = i;
            loop {
                while i < b.len() && ident(b[i]) {
                    i += 1;
                }
                if expr[i..].starts_with("::") && i + 2 < b.len() && ident(b[i + 2]) {
                    i += 2;
                } else {
                    break;
                }
            }
            let path = &expr[start..i];
            let Some((module, item)) = path.rsplit_once("::") else {
                let member = out.trim_end().ends_with('.');
                out.push_str(self.imported(path, root_text).filter(|_| !member).unwrap_or(path));
                continue;
            };
            let module = aliases.iter().find(|(a, _)| a == module).map_or(module, |(_, m)| m.as_str());
            let matches = |p: &str| p == module || p.ends_with(&format!("::{module}")) || format!("package::{module}") == p;
            match self.origins.iter().find(|(_, p, it)| it == item && matches(p)) {
                Some((name, _, _)) => out.push_str(name),
                None => {
                    let known: Vec<String> = self.origins.iter().map(|(_, p, it)| format!("{p}::{it}")).collect();
                    return Err(CheckError::Input(format!(
                        "{flag} '{expr}': no item `{item}` of a module `{module}` among what the sampler's file imports{} (imported: {}); name an item of a module the file imports, as its import names it",
                        crate::suggest::did_you_mean(path, known.iter().map(String::as_str)),
                        if known.is_empty() { "nothing".to_string() } else { known.join(", ") }
                    )));
                }
            }
        }
        Ok(out)
    }
}

impl UserCode {
    /// The composed name of `name` where the sampler's file imports it by that name (naga_oil's
    /// `#import a::b::{name}`, WESL's `import package::a::name;`): an expression names it as the
    /// file does. `None` where no import line names it, or two modules hold an item of that name.
    fn imported(&self, name: &str, root_text: &str) -> Option<&str> {
        let word = |l: &str| l.split(|c: char| !(c.is_alphanumeric() || c == '_')).any(|w| w == name);
        let imports = root_text.lines().map(str::trim_start).any(|l| (l.starts_with("#import ") || l.starts_with("import ")) && word(l));
        let mut held = self.origins.iter().filter(|(_, _, item)| item == name).map(|(composed, _, _)| composed.as_str());
        let first = held.next()?;
        (imports && held.all(|c| c == first)).then_some(first)
    }
}

/// The roots modules are looked up under: the given ones, else the first file's folder.
fn roots(sources: &[Source], c: &Composition) -> Vec<PathBuf> {
    if !c.shader_roots.is_empty() {
        return c.shader_roots.clone();
    }
    let first = Path::new(&sources[0].name);
    vec![first.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf()]
}

fn show_roots(roots: &[PathBuf]) -> String {
    roots.iter().map(|r| r.display().to_string()).collect::<Vec<_>>().join(", ")
}

/// Every file with one of `exts` under `dir` (hidden folders and `target` skipped), at most
/// 20 000. Each folder and file is taken once, by its device and inode: a symbolic link back up
/// the tree (`loops/a -> .`) is not walked again, and a file reached by two links is one file.
fn scan(dir: &Path, exts: &[&str], out: &mut Vec<PathBuf>) {
    scan_once(dir, exts, out, &mut std::collections::HashSet::new());
}

/// A file system object's identity: its device and inode.
fn identity(p: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(p).ok().map(|m| (m.dev(), m.ino()))
}

fn scan_once(dir: &Path, exts: &[&str], out: &mut Vec<PathBuf>, seen: &mut std::collections::HashSet<(u64, u64)>) {
    if !identity(dir).is_some_and(|id| seen.insert(id)) {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut entries: Vec<_> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if out.len() >= 20_000 {
            return;
        }
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if p.is_dir() {
            if !name.starts_with('.') && name != "target" {
                scan_once(&p, exts, out, seen);
            }
        } else if exts.iter().any(|e| p.extension().and_then(|x| x.to_str()) == Some(e)) && identity(&p).is_some_and(|id| seen.insert(id)) {
            out.push(p);
        }
    }
}

/// The stubs' files, read.
fn stubs(c: &Composition) -> Result<Vec<(String, Source)>, CheckError> {
    c.stubs.iter().map(|(m, f)| Source::read(f).map(|s| (m.clone(), s))).collect()
}

/// The 1-based line and column of byte `at` of `text`.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rfind('\n').map_or(before.len(), |n| before.len() - n - 1) + 1;
    (line, col)
}

/// What a composed tree was made from: the files given, the composition, and each file under
/// the roots and each stub by its path, size and modification time.
type TreeKey = (Vec<Source>, Composition, Vec<(PathBuf, u64, Option<std::time::SystemTime>)>);

/// The trees this process composed (a check composes its sampler's tree for validation, for
/// each --rand order probed and for the passes; a run composes each case's): naga_oil's
/// composer is superlinear in a tree's depth (each module's header holds its imports' imports),
/// so a tree is composed once per process, and again only when a file under its roots changed.
static TREES: std::sync::Mutex<Vec<(TreeKey, UserCode)>> = std::sync::Mutex::new(Vec::new());

/// The trees kept: a run's cases share a few.
const TREES_KEPT: usize = 8;

fn tree_key(sources: &[Source], c: &Composition) -> TreeKey {
    let mut files = Vec::new();
    for r in roots(sources, c) {
        scan(&r, &["wgsl", "wesl"], &mut files);
    }
    for (_, dir) in &c.packages {
        scan(dir, &["wgsl", "wesl"], &mut files);
    }
    files.extend(c.stubs.iter().map(|(_, f)| f.clone()));
    let stamp = files
        .into_iter()
        .map(|f| {
            let m = std::fs::metadata(&f).ok();
            let len = m.as_ref().map_or(0, std::fs::Metadata::len);
            let modified = m.and_then(|m| m.modified().ok());
            (f, len, modified)
        })
        .collect();
    (sources.to_vec(), c.clone(), stamp)
}

/// What this process is composing now, for a message about where the time went
/// ([`composing`]); `None` between compositions.
static COMPOSING: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// Sets [`COMPOSING`] to a stage of a composition until it is dropped, then back to the stage
/// it was in (the stage around it, or none).
struct Stage(Option<String>);

impl Stage {
    fn enter(what: String) -> Stage {
        Stage(COMPOSING.lock().unwrap_or_else(|p| p.into_inner()).replace(what))
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        *COMPOSING.lock().unwrap_or_else(|p| p.into_inner()) = self.0.take();
    }
}

/// What the composition in progress in this process is doing, as a phrase that follows "while
/// lobes was": "composing diffuse.wgsl and the 1000 naga_oil modules it imports (under
/// shaders) with naga_oil's Composer", "reading diffuse.wgsl and the modules it imports under
/// the shader roots (shaders), and composing them"; `None` when nothing is being composed
/// (plain WGSL is not). `lobes check` composes on a thread of its own and says with this where
/// the time went when `--timeout` runs out, or a signal comes, first: naga_oil's time grows
/// faster than N² in the depth N of a chain of imports (each module is parsed against a header
/// holding every module below it; 1000 modules take about 5 s), and nothing stops it midway.
/// The command line composes one sampler at a time; a library composing on several threads
/// sees the latest stage of any of them.
pub fn composing() -> Option<String> {
    COMPOSING.lock().unwrap_or_else(|p| p.into_inner()).clone()
}

/// The user's files composed as their dialect composes them (a tree composed before in this
/// process, from the same files, is taken from [`TREES`]).
pub(super) fn compose_user(sources: &[Source], c: &Composition) -> Result<UserCode, CheckError> {
    if sources.is_empty() || (dialect(sources) == Dialect::Wgsl && c.defines.is_empty()) {
        return compose_anew(sources, c);
    }
    let _stage = Stage::enter(format!("reading {} and the modules it imports under the shader roots ({}), and composing them", sources[0].name, show_roots(&roots(sources, c))));
    let key = tree_key(sources, c);
    let kept = TREES.lock().unwrap_or_else(|p| p.into_inner()).iter().find(|(k, _)| *k == key).map(|(_, code)| code.clone());
    if let Some(code) = kept {
        return Ok(code);
    }
    // on a large stack: naga_oil recurses once per module along a chain of imports
    let code = crate::engine::gpu::stack::with_big_stack(|| compose_anew(sources, c))?;
    let mut trees = TREES.lock().unwrap_or_else(|p| p.into_inner());
    if trees.len() >= TREES_KEPT {
        trees.remove(0);
    }
    trees.push((key, code.clone()));
    Ok(code)
}

fn compose_anew(sources: &[Source], c: &Composition) -> Result<UserCode, CheckError> {
    if sources.is_empty() {
        return Err(CheckError::Input("no WGSL file given: name at least one file that defines the sampler".into()));
    }
    let files = sources.iter().map(|s| s.name.clone()).collect();
    let mut d = dialect(sources);
    if !matches!(d, Dialect::Glsl | Dialect::Spirv) {
        // GLSL's own directives (#version, #include, #extension) are its front end's
        foreign_directives(sources)?;
    }
    if d == Dialect::Wgsl && !c.defines.is_empty() {
        // shader defs of plain files are naga_oil's (#ifdef); with none in the files they are unused
        d = Dialect::NagaOil;
    }
    match d {
        Dialect::Wgsl => {
            if let Some((m, _)) = c.stubs.first() {
                return Err(CheckError::Input(format!("--stub {m}: the files import nothing (no #import or import statement), so there is no module to stand in for")));
            }
            Ok(UserCode { dialect: d, parts: sources.to_vec(), origins: Vec::new(), files, decls: Vec::new(), renamed: Vec::new(), uniforms: Vec::new() })
        }
        Dialect::NagaOil => naga_oil_tree(sources, c).map(|(text, origins, renamed)| UserCode {
            dialect: d,
            parts: vec![Source { name: format!("<{} with its modules, composed by naga_oil>", sources[0].name), text }],
            origins,
            files,
            decls: Vec::new(),
            renamed,
            uniforms: Vec::new(),
        }),
        Dialect::Wesl => wesl_tree(sources, c).map(|(text, origins, decls)| UserCode {
            dialect: d,
            parts: vec![Source { name: format!("<{} with its modules, composed by wesl>", sources[0].name), text }],
            origins,
            files,
            decls,
            renamed: Vec::new(),
            uniforms: Vec::new(),
        }),
        Dialect::Glsl | Dialect::Spirv => super::dialect::compose(d, sources, c),
    }
}

/// The directives lobes composes: naga_oil's (WGSL and WESL have none at the start of a line).
const DIRECTIVES: [&str; 9] = ["#import", "#define_import_path", "#ifdef", "#ifndef", "#if", "#else", "#endif", "#elif", "#define"];

/// A line of the user's files that starts with a preprocessor directive lobes does not know
/// (a renderer's own, RedGPU's `#redgpu_include`): an error saying what it is and how to
/// proceed, rather than WGSL's parse error at `#`.
fn foreign_directives(sources: &[Source]) -> Result<(), CheckError> {
    for s in sources {
        for (n, line) in s.text.lines().enumerate() {
            let l = line.trim_start();
            let Some(word) = l.strip_prefix('#').map(|r| r.split(|c: char| !(c.is_alphanumeric() || c == '_')).next().unwrap_or("")) else { continue };
            if word.is_empty() || DIRECTIVES.iter().any(|d| d[1..] == *word) {
                continue;
            }
            return Err(CheckError::Input(format!(
                "{}:{}: `{}` is a preprocessor line of the renderer's own (not WGSL, nor naga_oil's #import/#ifdef family), which lobes cannot expand; give lobes the file as the renderer's preprocessor writes it (a pre-expanded file), or, where the line pulls in a module, write it as a naga_oil `#import` and stand in for that module with --stub MODULE=FILE; a switch the line tests is a --define",
                s.name,
                n + 1,
                l.trim_end()
            )));
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
                        return Err(CheckError::Input(format!("--define {n}={s}: {s} is out of the range of u32 (0 to {}u)", u32::MAX)));
                    }
                    (None, Err(_)) if digits(s.strip_prefix('-').unwrap_or(s)) => {
                        return Err(CheckError::Input(format!("--define {n}={s}: {s} is out of the range of i32 ({} to {})", i32::MIN, i32::MAX)));
                    }
                    _ => return Err(CheckError::Input(format!("--define {n}={s}: the value must be true, false or an integer (7, -1, 7u)"))),
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
                return Err(CheckError::Input(format!(
                    "{}: no #define_import_path: with naga_oil imports, give the sampler's file first and its modules by --shader-root (or as files with their #define_import_path)",
                    s.name
                )));
            }
        }
    }
    let given = modules.len();
    let mut found = Vec::new();
    for r in roots {
        if !r.is_dir() {
            return Err(CheckError::Input(format!("--shader-root {}: not a folder", r.display())));
        }
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
            return Err(CheckError::Input(format!(
                "{}: `{}` is declared (#define_import_path {}) by more than one file under the shader roots: {} and {}; which one the renderer composes is not for lobes to guess. Remove or rename the stale copy, or give the right one with --stub {}=FILE",
                from.source.name,
                modules[i].path,
                modules[i].path,
                modules[i].source.name,
                modules[i].also.join(" and "),
                modules[i].path
            )));
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
    CheckError::Input(format!(
        "{at}: error: unresolved import `{import}`: no file under the shader roots ({}) has `#define_import_path {import}`{}; {}. Add its folder with --shader-root, or stand in for it with --stub {import}=FILE",
        show_roots(roots),
        close.map_or(String::new(), |c| format!(" (closest: `{c}`)")),
        some_names("modules found", &names, import),
    ))
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
        return Err(CheckError::Input(format!(
            "--stub {}: no import of {} or of the modules it imports names that module, so the stub stands in for nothing; check the module path (as the #import names it)",
            m.path, sources[0].name
        )));
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
    for name in super::compose::global_names(&module) {
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

/// `text` without terminal colour codes (`ESC [ … m`), which wesl's diagnostics hold.
#[cfg(feature = "wesl")]
fn strip_ansi(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        if c == '\u{1b}' {
            for c in chars.by_ref() {
                if c.is_ascii_alphabetic() {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// The sampler file's own import path, or its file name.
fn root_name(s: &Source) -> String {
    naga_oil::compose::get_preprocessor_data(&s.text).0.unwrap_or_else(|| s.name.clone())
}

/// [`write_wgsl`], and the functions whose names the writer changed (its namer keeps ASCII
/// letters, digits and single underscores: `würfel` → `wrfel`, `rand_` → `rand`): the written
/// text parsed again holds the functions in the module's order (the writer writes them in arena
/// order, callees first, and the parser keeps that order), so each is paired with its handle's.
pub(super) fn write_wgsl_renamed(module: &naga::Module, caps: naga::valid::Capabilities) -> Result<(String, Renamed), CheckError> {
    let module = &*super::compose::writable(module);
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

/// A composed WESL tree: its text, the origins of its mangled names, and of its declarations.
type WeslTree = (String, Vec<Origin>, Vec<super::compose::DeclOrigin>);

#[cfg(not(feature = "wesl"))]
fn wesl_tree(sources: &[Source], _c: &Composition) -> Result<WeslTree, CheckError> {
    Err(CheckError::Input(format!("{}: WESL imports need lobes built with the feature \"wesl\" (the CLI has it)", sources[0].name)))
}

/// lobes' WESL resolver: `package::a::b` is `a/b.wesl` (or `.wgsl`) under the shader roots, a
/// stub where one is given.
#[cfg(feature = "wesl")]
struct Roots {
    roots: Vec<PathBuf>,
    /// `--package NAME=DIR`: where `NAME::…` paths are, instead of the roots.
    packages: Vec<(String, PathBuf)>,
    /// The `@if` features, for the conditional blocks `wesl` 0.4 cannot read ([`wesl_blocks`]).
    ///
    /// [`wesl_blocks`]: super::dialect::wesl_blocks
    features: std::collections::HashMap<String, bool>,
    stubs: Vec<(String, Source)>,
    /// Module paths (`package::a::b`) of the files under the roots, for "closest" names.
    known: Vec<String>,
    /// What resolving found (the wesl crate keeps the resolver; the tree's caller reads this).
    seen: std::rc::Rc<std::cell::RefCell<Resolved>>,
}

/// What lobes' resolver saw of a WESL tree: the stubs used, and an input error of its own (a
/// module reachable two ways, one that imports itself), which the wesl crate's error would hide.
#[cfg(feature = "wesl")]
#[derive(Default)]
struct Resolved {
    stubs_used: Vec<String>,
    error: Option<String>,
}

#[cfg(feature = "wesl")]
impl Resolved {
    /// The resolver's own error, else a `--stub` that no import reached.
    fn refusal(&self, c: &Composition, root: &str) -> Result<(), CheckError> {
        if let Some(why) = &self.error {
            return Err(CheckError::Input(why.clone()));
        }
        match c.stubs.iter().find(|(m, _)| !self.stubs_used.contains(m)) {
            Some((m, _)) => Err(CheckError::Input(format!(
                "--stub {m}: no import of {root} or of the modules it imports names that module, so the stub stands in for nothing; check the module path (as the import names it: package::a::b)"
            ))),
            None => Ok(()),
        }
    }
}

#[cfg(feature = "wesl")]
impl Roots {
    /// The files that `path` names: `a/b.wesl` and `a/b.wgsl` under every root; a path of a
    /// package given by `--package NAME=DIR` (`NAME::a::b`) under DIR alone.
    fn files(&self, path: &wesl::ModulePath) -> Vec<PathBuf> {
        let mut out = Vec::new();
        let package = match &path.origin {
            wesl::syntax::PathOrigin::Package(name) => self.packages.iter().find(|(n, _)| n == name).map(|(_, d)| std::slice::from_ref(d)),
            _ => None,
        };
        for r in package.unwrap_or(&self.roots) {
            let mut p = r.clone();
            p.extend(&path.components);
            out.extend(["wesl", "wgsl"].iter().map(|e| p.with_extension(e)).filter(|f| f.is_file()));
        }
        // one file under two roots (a root inside another) is one file
        let mut ids = Vec::new();
        out.retain(|f| match std::fs::canonicalize(f) {
            Ok(c) if ids.contains(&c) => false,
            Ok(c) => {
                ids.push(c);
                true
            }
            Err(_) => true,
        });
        out
    }
    fn file(&self, path: &wesl::ModulePath) -> Option<PathBuf> {
        self.files(path).into_iter().next()
    }
    fn stub(&self, path: &wesl::ModulePath) -> Option<&(String, Source)> {
        let shown = path.to_string();
        self.stubs.iter().find(|(m, _)| *m == shown || format!("package::{m}") == shown)
    }
    /// Why no file holds `path`: where lobes looked, the closest modules it found, and the flags
    /// that say where the module is.
    fn not_found(&self, path: &wesl::ModulePath) -> String {
        let shown = path.to_string();
        let rel = path.components.join("/");
        let (looked, hint) = match &path.origin {
            wesl::syntax::PathOrigin::Package(name) => match self.packages.iter().find(|(n, _)| n == name) {
                Some((_, dir)) => (format!("no file {rel}.wesl or .wgsl in {} (--package {name})", dir.display()), format!("Check the folder of --package {name}=DIR (it holds {name}'s modules: {name}::a::b is DIR/a/b.wesl), ")),
                None => (
                    format!("no package {name} given (--package), and no file {rel}.wesl or .wgsl under the shader roots ({}), where lobes looks for it without its name", show_roots(&self.roots)),
                    format!("Say where {name} is with --package {name}=DIR, "),
                ),
            },
            _ => (format!("no file {rel}.wesl or .wgsl under the shader roots ({})", show_roots(&self.roots)), String::new()),
        };
        let close = closest_modules(&shown, &self.known);
        let close = match close.is_empty() {
            true => format!("none of the {} modules found is close", self.known.len()),
            false => format!("closest: {} of the {} modules found", close.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", "), self.known.len()),
        };
        let hint = if hint.is_empty() { "Add its folder with --shader-root, ".to_string() } else { hint };
        format!("unresolved import: {looked} ({close}). {hint}or stand in for it with --stub {shown}=FILE")
    }
    /// `text` (the file `name`) with its `@if` blocks resolved; a malformed condition is an
    /// error at its file, line and column.
    fn conditional_blocks(&self, path: &wesl::ModulePath, name: &str, text: &str) -> Result<String, wesl::ResolveError> {
        super::dialect::wesl_blocks::resolve(text, &self.features).map_err(|e| {
            let (line, col) = line_col(text, e.at);
            self.refuse(path, format!("{name}:{line}:{col}: {}", e.message))
        })
    }
    /// An error of the resolver's own, kept for the tree's caller (and a short one for wesl).
    fn refuse(&self, path: &wesl::ModulePath, why: String) -> wesl::ResolveError {
        self.seen.borrow_mut().error.get_or_insert(why);
        wesl::ResolveError::ModuleNotFound(path.clone(), "see above".into())
    }
}

/// The first `import` statement of a WESL text that names its own module `path`
/// (`package::a::b`, or through `super::`): its line and text.
#[cfg(feature = "wesl")]
fn self_import(text: &str, path: &wesl::ModulePath) -> Option<(usize, String)> {
    let own = path.to_string();
    let parent = path.components[..path.components.len().saturating_sub(1)].join("::");
    text.lines().enumerate().find_map(|(n, line)| {
        let stmt = line.trim().strip_prefix("import ")?.trim_end().trim_end_matches(';').trim();
        // the module the statement imports from: before `::{`, else all but the last segment
        let module = match stmt.split_once("::{") {
            Some((m, _)) => m,
            None => stmt.rsplit_once("::")?.0,
        };
        let module = match module.strip_prefix("super::") {
            Some(rest) if !parent.is_empty() => format!("package::{parent}::{rest}"),
            Some(rest) => format!("package::{rest}"),
            None => module.to_string(),
        };
        (module == own).then(|| (n + 1, line.trim().to_string()))
    })
}

#[cfg(feature = "wesl")]
impl wesl::Resolver for Roots {
    fn resolve_source<'a>(&'a self, path: &wesl::ModulePath) -> Result<std::borrow::Cow<'a, str>, wesl::ResolveError> {
        if let Some((m, s)) = self.stub(path) {
            self.seen.borrow_mut().stubs_used.push(m.clone());
            return self.conditional_blocks(path, &s.name, &s.text).map(Into::into);
        }
        let shown = path.to_string();
        let files = self.files(path);
        let Some(f) = files.first() else {
            return Err(wesl::ResolveError::ModuleNotFound(path.clone(), self.not_found(path)));
        };
        if files.len() > 1 {
            let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
            return Err(self.refuse(path, format!(
                "the module {shown} is reachable two ways: {}; which one the renderer composes is not for lobes to guess. Remove or rename the stale copy, or give the right one with --stub {shown}=FILE",
                names.join(" and ")
            )));
        }
        let text = std::fs::read_to_string(f).map_err(|e| wesl::ResolveError::ModuleNotFound(path.clone(), format!("{}: {e}", f.display())))?;
        if let Some((line, stmt)) = self_import(&text, path) {
            return Err(self.refuse(path, format!(
                "{}:{line}: the module {shown} imports itself (`{stmt}`); a module names its own declarations without an import: remove the line",
                f.display()
            )));
        }
        self.conditional_blocks(path, &f.display().to_string(), &text).map(Into::into)
    }
    fn display_name(&self, path: &wesl::ModulePath) -> Option<String> {
        match self.stub(path) {
            Some((_, s)) => Some(s.name.clone()),
            None => self.file(path).map(|f| f.display().to_string()),
        }
    }
}

/// The sampler's file as a WESL module: the roots (each a folder, as each `--package` DIR) and
/// its path under the first root that holds it.
#[cfg(feature = "wesl")]
fn wesl_root(sources: &[Source], c: &Composition) -> Result<(Vec<PathBuf>, wesl::ModulePath), CheckError> {
    if let Some(s) = sources.get(1) {
        return Err(CheckError::Input(format!(
            "{}: with WESL imports give only the sampler's file; the modules it imports are found under --shader-root",
            s.name
        )));
    }
    let roots = roots(sources, c);
    for r in &roots {
        if !r.is_dir() {
            return Err(CheckError::Input(format!("--shader-root {}: not a folder", r.display())));
        }
    }
    for (name, dir) in &c.packages {
        check_package(name, &[]).map_err(CheckError::Input)?;
        if !dir.is_dir() {
            return Err(CheckError::Input(format!("--package {name}={}: not a folder; give the folder that holds {name}'s modules ({name}::a::b is DIR/a/b.wesl)", dir.display())));
        }
    }
    let file = std::fs::canonicalize(&sources[0].name).map_err(|e| CheckError::Input(format!("{}: {e}", sources[0].name)))?;
    let rel = roots
        .iter()
        .find_map(|r| file.strip_prefix(std::fs::canonicalize(r).ok()?).ok().map(|rel| rel.with_extension("")))
        .ok_or_else(|| CheckError::Input(format!("{}: not under any shader root ({}); WESL's `package::` paths start at a root", sources[0].name, show_roots(&roots))))?;
    let components: Vec<String> = rel.iter().map(|c| c.to_string_lossy().into_owned()).collect();
    Ok((roots, wesl::ModulePath { origin: wesl::syntax::PathOrigin::Absolute, components }))
}

/// The tree of `sources[0]` composed by the wesl crate: WGSL text (the root's names as written,
/// imported ones mangled), each mangled name's origin, and each declaration's.
#[cfg(feature = "wesl")]
fn wesl_tree(sources: &[Source], c: &Composition) -> Result<WeslTree, CheckError> {
    let (roots, root_path) = wesl_root(sources, c)?;
    let known = wesl_known(&roots, &c.packages);
    let seen = std::rc::Rc::new(std::cell::RefCell::new(Resolved::default()));
    let flags = feature_flags(c)?;
    let resolver = |stubs| Roots { roots: roots.clone(), packages: c.packages.clone(), features: flags.clone(), stubs, known: known.clone(), seen: seen.clone() };
    let options = wesl::CompileOptions {
        imports: true,
        condcomp: true,
        strip: true,
        lazy: true,
        keep_root: true,
        mangle_root: false,
        validate: false,
        features: wesl_features(&flags),
        ..Default::default()
    };
    let mut compiler = wesl::Wesl::new_barebones().set_custom_resolver(resolver(stubs(c)?));
    compiler.set_options(options).set_mangler(wesl::ManglerKind::Escape).use_sourcemap(true);
    let _stage = Stage::enter(format!("composing {} and the WESL modules it imports (under {}) with the wesl crate", sources[0].name, show_roots(&roots)));
    let result = compiler.compile(&root_path);
    seen.borrow().refusal(c, &sources[0].name)?;
    let files = resolver(Vec::new());
    let result = result.map_err(|e| wesl_error(&e, &sources[0], &files))?;
    wesl_origins(&result, &root_path.to_string(), &files, &sources[0])
}

/// A `wesl` error at the file, line and column its span belongs to: the crate's diagnostic
/// carries the span's module, its source and its display name (this resolver's file name), and
/// its Display heads it with the root's name and a byte range.
#[cfg(feature = "wesl")]
fn wesl_error(e: &wesl::Error, root: &Source, files: &Roots) -> CheckError {
    let whole = || CheckError::Wgsl(format!("{}: {}", root.name, strip_ansi(&e.to_string())));
    let wesl::Error::Error(d) = e else { return whole() };
    let Some(span) = d.detail.span else { return whole() };
    let module = d.detail.module_path.as_ref();
    let file = d.detail.display_name.clone().or_else(|| module.and_then(|m| wesl::Resolver::display_name(files, m))).unwrap_or_else(|| root.name.clone());
    let source = d.detail.source.clone().or_else(|| std::fs::read_to_string(&file).ok());
    let Some(source) = source.filter(|s| span.range().end <= s.len()) else { return whole() };
    let (line, col) = line_col(&source, span.range().start);
    // the inner error's text, without wgsl_parse's "chars A..B: " (a byte range of that file)
    let inner = strip_ansi(&d.error.to_string());
    let inner = match inner.strip_prefix("chars ") {
        Some(rest) => rest.split_once(": ").map_or(inner.clone(), |(_, m)| m.to_string()),
        None => inner.clone(),
    };
    let text = source.lines().nth(line - 1).unwrap_or("");
    let within = match (&d.detail.declaration, module) {
        (Some(decl), Some(m)) => format!("in `{decl}` of module {m}"),
        (None, Some(m)) => format!("in module {m}"),
        _ => String::new(),
    };
    CheckError::Wgsl(format!("{file}:{line}:{col}: {inner}\n   | {text}\n   = note: {within}"))
}

/// The origins of a composed WESL tree's mangled names and of its declarations.
#[cfg(feature = "wesl")]
fn wesl_origins(result: &wesl::CompileResult, root_path_shown: &str, resolver_files: &Roots, root: &Source) -> Result<WeslTree, CheckError> {
    use wesl::SourceMap;
    let mut origins = Vec::new();
    use wesl::syntax::GlobalDeclaration as G;
    let ident = |decl: &G| match decl {
        G::Declaration(d) => Some(d.ident.name().to_string()),
        G::TypeAlias(d) => Some(d.ident.name().to_string()),
        G::Struct(d) => Some(d.ident.name().to_string()),
        G::Function(d) => Some(d.ident.name().to_string()),
        _ => None,
    };
    for decl in &result.syntax.global_declarations {
        if let Some(name) = ident(decl.node())
            && let Some((path, item)) = result.sourcemap.as_ref().and_then(|m| m.get_decl(&name))
        {
            origins.push((name.clone(), path.to_string(), item.to_string()));
        }
    }
    let text = result.to_string();
    let renames: Vec<(String, String)> = origins.iter().map(|(m, _, item)| (m.clone(), item.clone())).collect();
    // each declaration as the crate writes it, found in order in the text; its span is in its
    // own module's text (the root's, or the source map's of the module its mangled name names)
    let mut decls = Vec::new();
    let mut from = 0;
    for decl in &result.syntax.global_declarations {
        let Some(name) = ident(decl.node()) else { continue };
        let written = decl.to_string();
        let Some(at) = text[from..].find(&written).map(|i| from + i) else { continue };
        from = at + written.len();
        let first = text[..at].matches('\n').count() as u32 + 1;
        let lines = (first, first + written.trim_end().matches('\n').count() as u32);
        let Some((file, module, item, source)) = declared_in(result.sourcemap.as_ref(), &name, root_path_shown, resolver_files, root) else { continue };
        // the declaration's text in its file: its span there, or (a span that does not hold its
        // name) from the line that declares it to the next declaration
        let span = decl.span();
        let (start, original) = match source.get(span.start..span.end).filter(|t| t.contains(item.as_str())) {
            Some(t) => (span.start, t.to_string()),
            None => match declaration_text(&source, &item) {
                Some(found) => found,
                None => continue,
            },
        };
        let before = &source[..start];
        let at = (before.matches('\n').count() as u32 + 1, before.rsplit('\n').next().unwrap_or("").chars().count() as u32 + 1);
        decls.push(super::compose::DeclOrigin { lines, file, module, name: item, text: original, at, renames: renames.clone() });
    }
    Ok((text, origins, decls))
}

/// Where the declaration `name` of a composed WESL tree comes from: (its file, module path,
/// name there, the file's text); the root's own declarations are the sampler's file's.
#[cfg(feature = "wesl")]
fn declared_in(map: Option<&wesl::BasicSourceMap>, name: &str, root_path: &str, roots: &Roots, root: &Source) -> Option<(String, String, String, String)> {
    use wesl::SourceMap;
    match map.and_then(|m| m.get_decl(name)) {
        Some((path, item)) if path.to_string() != root_path => {
            let m = map.expect("a source map holds the declaration");
            let file = m.get_display_name(path).map(str::to_string).or_else(|| roots.file(path).map(|f| f.display().to_string()))?;
            let source = match m.get_source(path) {
                Some(s) => s.to_string(),
                None => std::fs::read_to_string(&file).ok()?,
            };
            Some((file, path.to_string(), item.to_string(), source))
        }
        _ => Some((root.name.clone(), root_path.to_string(), name.to_string(), root.text.clone())),
    }
}

/// The few modules of `known` closest to `wanted`: those that share its last segment first
/// (`bevy_render::maths` and `package::maths`), then by the edit distance of the last segment
/// and of the whole path.
#[cfg(feature = "wesl")]
fn closest_modules<'a>(wanted: &str, known: &'a [String]) -> Vec<&'a str> {
    let last = |p: &str| p.rsplit("::").next().unwrap_or("").to_string();
    let want = last(wanted);
    let score = |k: &str| (strsim::normalized_levenshtein(&want, &last(k)), strsim::normalized_levenshtein(wanted, k));
    let mut by: Vec<((f64, f64), &str)> = known.iter().map(|k| (score(k), k.as_str())).filter(|(s, _)| s.0 >= 0.5 || s.1 >= 0.5).collect();
    by.sort_by(|a, b| b.0.0.total_cmp(&a.0.0).then(b.0.1.total_cmp(&a.0.1)).then(a.1.cmp(b.1)));
    by.into_iter().take(5).map(|(_, k)| k).collect()
}

/// The module paths of the WESL and WGSL files under the roots (`package::a::b`) and under each
/// `--package` folder (`NAME::a::b`).
#[cfg(feature = "wesl")]
fn wesl_known(roots: &[PathBuf], packages: &[(String, PathBuf)]) -> Vec<String> {
    let named = roots.iter().map(|r| ("package", r)).chain(packages.iter().map(|(n, d)| (n.as_str(), d)));
    let mut known = Vec::new();
    for (name, r) in named {
        let mut files = Vec::new();
        scan(r, &["wesl", "wgsl"], &mut files);
        for f in files {
            if let Ok(rel) = f.strip_prefix(r) {
                let comps: Vec<String> = rel.with_extension("").iter().map(|c| c.to_string_lossy().into_owned()).collect();
                known.push(format!("{name}::{}", comps.join("::")));
            }
        }
    }
    known
}

/// `--define` values as WESL's `@if` features: true or false (one not given is false).
#[cfg(feature = "wesl")]
fn feature_flags(c: &Composition) -> Result<std::collections::HashMap<String, bool>, CheckError> {
    let mut flags = std::collections::HashMap::new();
    for (n, v) in &c.defines {
        let on = match v.as_deref() {
            None | Some("true") => true,
            Some("false") => false,
            Some(other) => return Err(CheckError::Input(format!("--define {n}={other}: WESL's @if features are true or false"))),
        };
        flags.insert(n.clone(), on);
    }
    Ok(flags)
}

/// [`feature_flags`] as the `wesl` crate's features.
#[cfg(feature = "wesl")]
fn wesl_features(flags: &std::collections::HashMap<String, bool>) -> wesl::Features {
    let mut features = wesl::Features::default();
    features.flags.extend(flags.iter().map(|(n, on)| (n.clone(), (*on).into())));
    features
}

/// Where the declaration of `name` starts in a WGSL/WESL text (a line `fn NAME(`, `const NAME`,
/// `struct NAME`, …, attributes before it included), and its text up to the next line that
/// starts a declaration at the margin.
#[cfg(feature = "wesl")]
fn declaration_text(source: &str, name: &str) -> Option<(usize, String)> {
    let keywords = ["fn", "const", "var", "override", "struct", "alias"];
    let starts = |line: &str| keywords.iter().any(|k| line.strip_prefix(k).is_some_and(|r| r.starts_with([' ', '<'])));
    let declares = |line: &str| {
        starts(line) && line.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).nth(1) == Some(name)
    };
    let mut offset = 0;
    let mut found = None;
    for line in source.split_inclusive('\n') {
        match found {
            None if declares(line) => found = Some(offset),
            Some(start) if starts(line) || line.starts_with('@') => return Some((start, source[start..offset].to_string())),
            _ => {}
        }
        offset += line.len();
    }
    found.map(|start| (start, source[start..].to_string()))
}

/// Replaces the body of each function in `functions` (handles of `module`, parsed from `text`)
/// with `body(function)`, keeping the text's line count (the body's newlines stay), so that
/// every later line keeps its number.
pub(super) fn replace_bodies(text: &str, module: &naga::Module, functions: &[(naga::Handle<naga::Function>, String)]) -> Result<String, CheckError> {
    let mut spans: Vec<(usize, usize, &str)> = Vec::new();
    for (h, body) in functions {
        let span = module.functions.get_span(*h).to_range().ok_or_else(|| CheckError::Internal("a function without a span".into()))?;
        let decl = &text[span.clone()];
        // the body: the first `{` after the argument list's `)`
        let open_args = decl.find('(').ok_or_else(|| CheckError::Internal("a function without arguments".into()))?;
        let close_args = super::dialect::out_params::closing(decl, open_args);
        let close_args = close_args.ok_or_else(|| CheckError::Internal("unbalanced parentheses".into()))?;
        let open = close_args + decl[close_args..].find('{').ok_or_else(|| CheckError::Internal("a function without a body".into()))?;
        let end = decl.rfind('}').ok_or_else(|| CheckError::Internal("a function without a body".into()))?;
        spans.push((span.start + open, span.start + end + 1, body.as_str()));
    }
    spans.sort();
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for (start, end, body) in spans {
        out.push_str(&text[at..start]);
        out.push_str(body);
        out.push_str(&"\n".repeat(text[start..end].matches('\n').count()));
        at = end;
    }
    out.push_str(&text[at..]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::composition::Draw;

    #[test]
    fn draw_orders() {
        assert_eq!(Draw::components(&[]), [0, 1, 2, 3]);
        assert_eq!(Draw::components(&[Draw::Event, Draw::X, Draw::Y]), [2, 0, 1, 3]);
        assert_eq!(Draw::components(&[Draw::X, Draw::Event, Draw::Event, Draw::Y]), [0, 2, 3, 1]);
        assert_eq!(Draw::list(&[2, 0, 1, 3], 3), "event,x,y");
        assert!(Draw::parse_list("x,x").is_err());
        assert!(Draw::parse_list("z").unwrap_err().contains("'z' is not a draw"));
    }

    #[test]
    fn bodies_are_replaced_keeping_lines() {
        let text = "fn a() -> f32 {\n  return 1.0;\n}\nfn r(s: ptr<function, u32>) -> f32 {\n  *s = *s + 1u;\n  return f32(*s);\n}\nfn b() -> f32 { return r_(); }\n";
        let text = text.replace("r_()", "2.0");
        let module = naga::front::wgsl::parse_str(&text).unwrap();
        let (h, _) = module.functions.iter().find(|(_, f)| f.name.as_deref() == Some("r")).unwrap();
        let out = replace_bodies(&text, &module, &[(h, "{ return 0.5; }".into())]).unwrap();
        assert_eq!(out.lines().count(), text.lines().count());
        assert!(out.contains("fn r(s: ptr<function, u32>) -> f32 { return 0.5; }"), "{out}");
        assert_eq!(out.lines().nth(7), Some("fn b() -> f32 { return 2.0; }"));
        naga::front::wgsl::parse_str(&out).unwrap();
    }

    #[cfg(feature = "wesl")]
    #[test]
    fn declarations_are_found_by_name() {
        let text = "const PI: f32 = 3.14;\n// a comment\nfn g1(w: vec3<f32>) -> f32 {\n  let z2 = w.z;\n  return z2;\n}\nfn other() {}\n";
        let (start, decl) = declaration_text(text, "g1").unwrap();
        assert_eq!(&text[start..start + 6], "fn g1(");
        assert_eq!(decl, "fn g1(w: vec3<f32>) -> f32 {\n  let z2 = w.z;\n  return z2;\n}\n");
        assert!(declaration_text(text, "g").is_none());
        assert_eq!(declaration_text(text, "PI").unwrap().0, 0);
    }

    /// The fixture's WESL tree: every declaration of the root and of the modules it imports maps
    /// back to its file and line.
    #[cfg(feature = "wesl")]
    #[test]
    fn wesl_declarations_map_back_to_their_files() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/repository/wesl");
        let file = dir.join("shaders/sampling/ggx.wesl");
        let sources = vec![Source::read(&file).unwrap()];
        let c = Composition::default().shader_root(dir.join("shaders")).stub("package::bindings", dir.join("stubs/bindings.wesl"));
        let (text, _, decls) = wesl_tree(&sources, &c).unwrap();
        let g1 = decls.iter().find(|d| d.name == "ggx_g1").unwrap_or_else(|| panic!("{decls:#?}\n{text}"));
        assert_eq!((g1.file.as_str(), g1.at.0), (sources[0].name.as_str(), 33), "{g1:#?}");
        assert!(text.lines().nth(g1.lines.0 as usize - 1).unwrap().contains("fn ggx_g1("), "{g1:#?}\n{text}");
        let rand = decls.iter().find(|d| d.name == "rand_f").unwrap_or_else(|| panic!("{decls:#?}"));
        assert!(rand.file.ends_with("utils.wesl") && rand.module == "package::utils" && rand.at.0 == 11, "{rand:#?}");
    }

    #[test]
    fn dialects() {
        let s = |name: &str, text: &str| vec![Source { name: name.into(), text: text.into() }];
        assert_eq!(dialect(&s("a.wgsl", "fn f() {}")), Dialect::Wgsl);
        assert_eq!(dialect(&s("a.wgsl", "#import a::b::{c}\nfn f() {}")), Dialect::NagaOil);
        assert_eq!(dialect(&s("a.wgsl", "import package::maths::pi;\nfn f() {}")), Dialect::Wesl);
        assert_eq!(dialect(&s("a.wesl", "fn f() {}")), Dialect::Wesl);
    }
}
