//! Generates the texts of `lobes::embed` from `shaders/` at build time, so that a renderer that
//! embeds lobes' WGSL gets `&'static str` constants and parses nothing at run time, and so that
//! each fact stays in one place: the files of `shaders/lib` and `shaders/math` are the only
//! source of every form (plain prefixed WGSL, naga_oil modules, the WESL package), and of each
//! module's names and dependencies. The text rules are `src/embed/text.rs` and
//! `src/embed/namespace.rs` (over the lexer `src/wgsl_tokens.rs`), compiled into this script as
//! they are into the crate;
//! `src/embed/mod.rs`'s unit tests parse the results with naga and compare them with the
//! composition lobes' own kernels run.

use std::fmt::Write;

#[path = "src/embed/namespace.rs"]
#[allow(dead_code)]
mod namespace;
#[path = "src/embed/text.rs"]
#[allow(dead_code)]
mod text;
#[path = "src/wgsl_tokens.rs"]
#[allow(dead_code)]
mod wgsl_tokens;

/// The folders whose files are lobes' WGSL library; `shaders/passes` holds the engine's passes.
const LIBRARY: [&str; 3] = ["lib", "math", "passes"];

struct File {
    path: String,
    source: String,
}

/// One module of `lobes::embed`: what a renderer imports as one (a lobe's sampler, densities and
/// BRDF). Its files say so with the line `//! embed: NAME`; the one whose import path is
/// `lobes::NAME` holds the module's documentation in its other `//!` lines, and every file marks
/// the declarations a renderer may use (its API) with `///` comments.
struct Module {
    name: String,
    files: Vec<File>,
}

/// Every `.wgsl` file under `shaders/DIR` for DIR in [`LIBRARY`], by path.
fn library_files() -> Vec<File> {
    let mut paths: Vec<String> = Vec::new();
    for dir in LIBRARY {
        println!("cargo:rerun-if-changed=shaders/{dir}");
        for entry in std::fs::read_dir(format!("shaders/{dir}")).unwrap_or_else(|e| panic!("shaders/{dir}: {e}")) {
            let name = entry.unwrap().file_name().into_string().unwrap();
            if name.ends_with(".wgsl") {
                paths.push(format!("shaders/{dir}/{name}"));
            }
        }
    }
    paths.sort();
    paths
        .into_iter()
        .map(|path| {
            println!("cargo:rerun-if-changed={path}");
            let source = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
            File { path, source }
        })
        .collect()
}

/// The module a file belongs to, from its `//! embed: NAME` line.
fn embed_tag(source: &str) -> Option<&str> {
    source.lines().find_map(|l| l.strip_prefix("//! embed:")).map(str::trim)
}

/// `items` ordered so that each comes after those `needs` names (ties by their order in
/// `items`); panics on a circle.
fn after_needs<T>(mut items: Vec<T>, needs: impl Fn(&T, &T) -> bool, what: impl Fn(&T) -> String) -> Vec<T> {
    let mut out: Vec<T> = Vec::new();
    while !items.is_empty() {
        let ready = (0..items.len())
            .find(|&i| !items.iter().enumerate().any(|(j, other)| j != i && needs(&items[i], other)))
            .unwrap_or_else(|| panic!("a circle of imports among {}", items.iter().map(&what).collect::<Vec<_>>().join(", ")));
        out.push(items.remove(ready));
    }
    out
}

/// The embedded modules, each after the modules it imports (by depth, then name), each module's
/// files after the files they import (ties by path).
fn embedded_modules(files: Vec<File>) -> Vec<Module> {
    let mut modules: Vec<Module> = Vec::new();
    for f in files {
        let Some(name) = embed_tag(&f.source).map(str::to_string) else { continue };
        match modules.iter_mut().find(|m| m.name == name) {
            Some(m) => m.files.push(f),
            None => modules.push(Module { name, files: vec![f] }),
        }
    }
    let imports = |f: &File, g: &File| text::imports(&f.source).iter().any(|(p, _)| Some(*p) == text::import_path(&g.source));
    for m in &mut modules {
        m.files = after_needs(std::mem::take(&mut m.files), imports, |f| f.path.clone());
    }
    let needs = |m: &Module, other: &Module| m.files.iter().any(|f| other.files.iter().any(|g| imports(f, g)));
    let ordered = after_needs(modules, needs, |m| m.name.clone());
    // by depth (the longest chain of imports below), then name: the foundations first
    let mut depth: Vec<(usize, Module)> = Vec::new();
    for m in ordered {
        let d = depth.iter().filter(|(_, o)| needs(&m, o)).map(|(d, _)| d + 1).max().unwrap_or(0);
        depth.push((d, m));
    }
    depth.sort_by(|(d, a), (e, b)| (d, &a.name).cmp(&(e, &b.name)));
    depth.into_iter().map(|(_, m)| m).collect()
}

/// The module's documentation: the `//!` lines of its head file, `lobes::NAME`, but the tag.
fn module_doc(m: &Module) -> String {
    let head = m.files.iter().find(|f| text::import_path(&f.source) == Some(&format!("lobes::{}", m.name)));
    let head = head.unwrap_or_else(|| panic!("embed module {}: no file has the import path lobes::{0}", m.name));
    let doc: Vec<&str> = head.source.lines().filter_map(|l| l.strip_prefix("//!")).map(str::trim).filter(|l| !l.starts_with("embed:")).collect();
    assert!(!doc.is_empty(), "{}: lobes::{} has no //! documentation", head.path, m.name);
    doc.join("\n")
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/embed/text.rs");
    println!("cargo:rerun-if-changed=src/embed/namespace.rs");
    let library = library_files();
    write_library_list(&library);
    let modules = embedded_modules(library);
    let files: Vec<&[File]> = modules.iter().map(|m| m.files.as_slice()).collect();
    let api_declarations: Vec<Vec<Declaration>> = modules.iter().map(files_api).collect();
    let api: Vec<Vec<String>> = api_declarations.iter().map(|ds| ds.iter().filter_map(|d| d.name.clone()).collect()).collect();
    let owner = |import_path: &str| -> usize {
        files
            .iter()
            .position(|fs| fs.iter().any(|f| text::import_path(&f.source) == Some(import_path)))
            .unwrap_or_else(|| panic!("no embedded module holds the import path {import_path}"))
    };
    let n = modules.len();
    // the modules each imports from (by any name, `Real` included: the plain text needs its alias)
    let mut deps: Vec<Vec<usize>> = Vec::new();
    // the names it imports, by module, without `Real` (the naga_oil and WESL forms spell it f32)
    let mut items: Vec<Vec<(usize, Vec<String>)>> = Vec::new();
    for (m, fs) in files.iter().enumerate() {
        let mut d: Vec<usize> = Vec::new();
        let mut by_module: Vec<(usize, Vec<String>)> = Vec::new();
        for f in fs.iter() {
            for (path, names) in text::imports(&f.source) {
                let o = owner(path);
                if o == m {
                    continue;
                }
                assert!(o < m, "{} imports {path}, which comes later", f.path);
                if !d.contains(&o) {
                    d.push(o);
                }
                let names: Vec<String> = names.into_iter().filter(|&i| i != "Real").map(str::to_string).collect();
                if names.is_empty() {
                    continue;
                }
                match by_module.iter_mut().find(|(k, _)| *k == o) {
                    Some((_, v)) => v.extend(names.into_iter().filter(|x| !v.contains(x)).collect::<Vec<_>>()),
                    None => by_module.push((o, names)),
                }
            }
        }
        d.sort();
        by_module.sort_by_key(|(k, _)| *k);
        deps.push(d);
        items.push(by_module);
    }
    let closure = |m: usize| -> Vec<usize> {
        let mut wanted = vec![false; n];
        let mut stack = vec![m];
        while let Some(k) = stack.pop() {
            if !std::mem::replace(&mut wanted[k], true) {
                stack.extend(&deps[k]);
            }
        }
        (0..n).filter(|&k| wanted[k]).collect()
    };
    let short_names: Vec<Vec<String>> = files
        .iter()
        .map(|fs| {
            let mut names: Vec<String> = fs.iter().flat_map(|f| text::declared(&f.source)).map(str::to_string).collect();
            names.sort();
            names.dedup();
            names
        })
        .collect();
    let version = std::env::var("CARGO_PKG_VERSION").unwrap();
    let mut out = String::from("// Generated by build.rs from shaders/lib and shaders/math: do not edit.\n");
    let list = |v: Vec<String>| format!("&[{}]", v.join(", "));
    let strs = |v: &[String]| list(v.iter().map(|s| format!("{s:?}")).collect());
    let array = |name: &str, ty: &str, v: Vec<String>| format!("pub(super) const {name}: [{ty}; {n}] = [\n    {},\n];\n", v.join(",\n    "));
    out += &array("NAMES", "&str", modules.iter().map(|m| format!("{:?}", m.name)).collect());
    out += &array("DEPENDENCIES", "&[usize]", deps.iter().map(|d| list(d.iter().map(usize::to_string).collect())).collect());
    out += &array("FILES", "&[&str]", files.iter().map(|fs| strs(&fs.iter().map(|f| f.path.clone()).collect::<Vec<_>>())).collect());
    out += &array("SHORT_NAMES", "&[&str]", short_names.iter().map(|v| strs(v)).collect());
    out += &array("API", "&[&str]", api.iter().map(|v| strs(v)).collect());
    out += &array("SYMBOLS", "&[&str]", short_names.iter().map(|v| strs(&v.iter().map(|s| namespace::prefixed("lobes", s)).collect::<Vec<_>>())).collect());
    // plain WGSL: each file with its directive lines blanked, after a marker line (as the
    // engine's composition writes them), under its short names and with every name prefixed
    let short: Vec<String> = files.iter().map(|fs| fs.iter().map(|f| format!("// ---- {} ----\n{}\n", f.path, text::plain(&f.source))).collect()).collect();
    let prefixed: Vec<String> = (0..n)
        .map(|m| {
            let defined: Vec<&String> = closure(m).into_iter().flat_map(|k| &short_names[k]).collect();
            namespace::rename(&short[m], |t| defined.iter().any(|d| *d == t).then(|| namespace::prefixed("lobes", t)))
        })
        .collect();
    out += &array("SHORT_WGSL", "&str", short.iter().map(|s| format!("{s:?}")).collect());
    out += &array("WGSL", "&str", prefixed.iter().map(|s| format!("{s:?}")).collect());
    // naga_oil and WESL, in f32: per module the unit `lobes::NAME`, its API, and where it has
    // internal helpers the unit `lobes::NAME::internal` before it; each imports what its code uses
    // where each module's files import a name from another module: name -> that module
    let imported: Vec<Vec<(String, usize)>> = items.iter().map(|by| by.iter().flat_map(|(k, names)| names.iter().map(|n| (n.clone(), *k))).collect()).collect();
    struct Unit {
        module: usize,
        internal: bool,
        code: String,
        names: Vec<String>,
    }
    let mut units: Vec<Unit> = Vec::new();
    for (m, fs) in files.iter().enumerate() {
        let (mut public, mut internal) = (Unit { module: m, internal: false, code: String::new(), names: Vec::new() }, Unit { module: m, internal: true, code: String::new(), names: Vec::new() });
        for f in fs.iter() {
            let (mut p, mut q, mut opening) = (String::new(), String::new(), String::new());
            for d in declarations(&text::in_f32(&f.source)) {
                match d.name {
                    None => opening = d.text,
                    Some(n) if api[m].contains(&n) => {
                        p += &d.text;
                        public.names.push(n);
                    }
                    Some(n) => {
                        q += &d.text;
                        internal.names.push(n);
                    }
                }
            }
            // the file's opening comments go with its API, or with its helpers if it has no API
            let marker = format!("// ---- {} ----\n", f.path);
            if p.is_empty() {
                q = opening + &q;
            } else {
                public.code += &(marker.clone() + &opening + &p);
            }
            if !q.is_empty() {
                internal.code += &(marker + &q);
            }
        }
        if !internal.code.is_empty() {
            units.push(internal);
        }
        units.push(public);
    }
    let unit_of = |m: usize, name: &str| -> usize {
        let internal = !api[m].iter().any(|a| a == name);
        units.iter().position(|u| u.module == m && u.internal == internal).unwrap()
    };
    // per unit: the units it imports from, with the names
    let mut unit_imports: Vec<Vec<(usize, Vec<String>)>> = Vec::new();
    for u in &units {
        let used = identifiers(&u.code);
        let mut by_unit: Vec<(usize, Vec<String>)> = Vec::new();
        let mut add = |k: usize, n: &str| match by_unit.iter_mut().find(|(j, _)| *j == k) {
            Some((_, v)) => v.push(n.to_string()),
            None => by_unit.push((k, vec![n.to_string()])),
        };
        for (n, k) in &imported[u.module] {
            if used.contains(n) {
                add(unit_of(*k, n), n);
            }
        }
        for other in units.iter().filter(|o| o.module == u.module && o.internal != u.internal) {
            for n in other.names.iter().filter(|n| used.contains(*n)) {
                assert!(!u.internal, "{}: the internal helpers use {n}, which is its API: mark their declarations `///` too, or take the `///` off {n}", modules[u.module].name);
                add(unit_of(u.module, n), n);
            }
        }
        by_unit.sort_by_key(|(k, _)| *k);
        for (_, v) in &mut by_unit {
            v.sort();
            v.dedup();
        }
        unit_imports.push(by_unit);
    }
    let path = |u: &Unit| format!("{}{}", modules[u.module].name, if u.internal { "::internal" } else { "" });
    let header = |u: &Unit, form: &str| {
        let fs: Vec<&str> = files[u.module].iter().map(|f| f.path.as_str()).collect();
        let what = if u.internal {
            format!("{form}: the internal helpers of lobes::{}, not its API; they may change in any release", modules[u.module].name)
        } else {
            format!("{form}, lobes {version}")
        };
        format!("// lobes::{} ({what}), from {}; see docs/embedding.md.\n", path(u), fs.join(", "))
    };
    let mut table = String::from("pub(super) const UNITS: &[Unit] = &[\n");
    for (i, u) in units.iter().enumerate() {
        let mut naga_oil = format!("#define_import_path lobes::{}\n", path(u));
        // a unit's WESL file is lobes/NAME.wesl or lobes/NAME/internal.wesl: the package's root is
        // one or two levels up
        let up = if u.internal { "super::super" } else { "super" };
        let mut wesl = String::new();
        for (k, names) in &unit_imports[i] {
            assert!(*k < i, "unit {} imports a later one", path(u));
            writeln!(naga_oil, "#import lobes::{}::{{{}}}", path(&units[*k]), names.join(", ")).unwrap();
            writeln!(wesl, "import {up}::{}::{{{}}};", path(&units[*k]), names.join(", ")).unwrap();
        }
        naga_oil += &(header(u, "naga_oil module") + &u.code);
        wesl += &(header(u, "WESL module") + &u.code);
        let imports: Vec<String> = unit_imports[i].iter().map(|(k, _)| k.to_string()).collect();
        writeln!(
            table,
            "    Unit {{ module: {}, internal: {}, import_path: {:?}, naga_oil: {naga_oil:?}, wesl: {wesl:?}, imports: &[{}] }},",
            u.module,
            u.internal,
            format!("lobes::{}", path(u)),
            imports.join(", ")
        )
        .unwrap();
    }
    out += &(table + "];\n");
    // the WESL package for the `wesl` crate (feature wesl): module NAME with its submodule internal
    let mut package = String::from("// Generated by build.rs: lobes::embed::WESL_PACKAGE's modules.\n");
    let mut refs = Vec::new();
    for (m, name) in modules.iter().map(|m| &m.name).enumerate() {
        let public = units.iter().position(|u| u.module == m && !u.internal).unwrap();
        let submodules = match units.iter().position(|u| u.module == m && u.internal) {
            Some(i) => {
                writeln!(package, "static INTERNAL_{m}: CodegenModule = CodegenModule {{ name: \"internal\", source: UNITS[{i}].wesl, submodules: &[] }};").unwrap();
                format!("&[&INTERNAL_{m}]")
            }
            None => "&[]".into(),
        };
        writeln!(package, "static MODULE_{m}: CodegenModule = CodegenModule {{ name: {name:?}, source: UNITS[{public}].wesl, submodules: {submodules} }};").unwrap();
        refs.push(format!("&MODULE_{m}"));
    }
    writeln!(package, "static MODULES: [&CodegenModule; {n}] = [{}];", refs.join(", ")).unwrap();
    let needs = |m: usize| deps[m].iter().map(|&d| modules[d].name.as_str()).collect::<Vec<_>>();
    let docs: Vec<String> = modules.iter().enumerate().map(|(m, module)| variant_doc(module, &api_declarations[m], &needs(m))).collect();
    out += &array("DESCRIPTIONS", "&str", docs.iter().map(|d| format!("{d:?}")).collect());
    let mut variants = format!("modules! {{ {n};\n");
    for (module, doc) in modules.iter().zip(&docs) {
        writeln!(variants, "    #[doc = {doc:?}]\n    {},", camel(&module.name)).unwrap();
    }
    variants += "}\n";
    let dir = std::env::var("OUT_DIR").unwrap();
    std::fs::write(format!("{dir}/embed_generated.rs"), out).unwrap();
    std::fs::write(format!("{dir}/embed_wesl_package.rs"), package).unwrap();
    std::fs::write(format!("{dir}/embed_modules.rs"), variants).unwrap();
}

/// `sphere_light` → `SphereLight`: the module's variant of `embed::Module`.
fn camel(name: &str) -> String {
    name.split('_').map(|w| w[..1].to_uppercase() + &w[1..]).collect()
}

/// The module's API declarations, file by file.
fn files_api(m: &Module) -> Vec<Declaration> {
    m.files.iter().flat_map(|f| declarations(&text::in_f32(&f.source))).filter(|d| !d.doc.is_empty()).collect()
}

/// The rustdoc of `embed::Module`'s variant: the module's `//!` text, its files, its API with
/// each declaration's `///` text, and the modules it needs.
fn variant_doc(m: &Module, api: &[Declaration], needs: &[&str]) -> String {
    let files: Vec<String> = m.files.iter().map(|f| format!("`{}`", f.path)).collect();
    let mut doc = format!("{}\n\nIn {}.\n\n", module_doc(m), files.join(", "));
    for d in api {
        writeln!(doc, "- `{}`: {}", d.signature, d.doc.join(" ")).unwrap();
    }
    let needs: Vec<String> = needs.iter().map(|v| format!("`{v}`")).collect();
    doc += &if needs.is_empty() { "\nNeeds no other module.".to_string() } else { format!("\nNeeds {}.", needs.join(", ")) };
    doc
}

/// `LIBRARY`, the engine's list of every file of its library (`src/engine/gpu/library.rs`).
fn write_library_list(files: &[File]) {
    let mut out = format!("/// Every file of `shaders/lib`, `shaders/math` and `shaders/passes` (build.rs lists them).\nstatic LIBRARY: [File; {}] = [\n", files.len());
    for f in files {
        writeln!(out, "    shader!({:?}),", f.path.strip_prefix("shaders/").unwrap()).unwrap();
    }
    out += "];\n";
    std::fs::write(format!("{}/library_files.rs", std::env::var("OUT_DIR").unwrap()), out).unwrap();
}

/// One module-scope declaration of a file, with the comment lines right above it.
struct Declaration {
    /// The name it declares; `None` for the file's opening lines.
    name: Option<String>,
    text: String,
    /// Its `///` lines: the declaration is API, documented so.
    doc: Vec<String>,
    /// Its declaring text: a function's signature, a struct with its fields, a constant or
    /// global with its type, on one line.
    signature: String,
}

/// A file's code cut before each module-scope declaration, the file's opening lines first.
fn declarations(code: &str) -> Vec<Declaration> {
    let lines: Vec<&str> = code.lines().collect();
    let mut starts: Vec<(usize, usize, String)> = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        if let Some(name) = text::declared(line).first() {
            let mut s = i;
            while s > 0 && lines[s - 1].starts_with("//") && starts.last().is_none_or(|(p, _, _)| *p < s - 1) {
                s -= 1;
            }
            starts.push((s, i, name.to_string()));
        }
    }
    let text = |a: usize, b: usize| lines[a..b].iter().map(|l| format!("{l}\n")).collect::<String>();
    let first = starts.first().map_or(lines.len(), |(s, _, _)| *s);
    let mut out = vec![Declaration { name: None, text: text(0, first), doc: Vec::new(), signature: String::new() }];
    for (j, (s, at, name)) in starts.iter().enumerate() {
        let end = starts.get(j + 1).map_or(lines.len(), |(e, _, _)| *e);
        let doc = lines[*s..*at].iter().filter_map(|l| l.strip_prefix("///")).map(|l| l.trim().to_string()).collect();
        out.push(Declaration { name: Some(name.clone()), text: text(*s, end), doc, signature: signature(&lines[*at..end]) });
    }
    out
}

/// A declaration's text up to its body or value (a struct's up to its closing brace), on one
/// line, without comments.
fn signature(lines: &[&str]) -> String {
    let code: Vec<&str> = lines.iter().map(|l| l.split("//").next().unwrap().trim()).collect();
    let joined = code.join(" ");
    let cut = if joined.starts_with("struct") { joined.find('}').map(|i| i + 1) } else { joined.find(['{', '=', ';']) };
    joined[..cut.unwrap_or(joined.len())].split_whitespace().collect::<Vec<_>>().join(" ").replace(", }", " }")
}

/// The identifier tokens of WGSL code outside comments (`namespace::rename`'s reading).
fn identifiers(code: &str) -> Vec<String> {
    let found = std::cell::RefCell::new(Vec::new());
    namespace::rename(code, |t| {
        found.borrow_mut().push(t.to_string());
        None
    });
    let mut v = found.into_inner();
    v.sort();
    v.dedup();
    v
}
