//! WESL (Bevy 0.20): `import package::a::b;`, `super::`, `@if` features, composed by the `wesl`
//! crate (0.4, feature "wesl") with lobes' resolver over the shader roots
//! ([`super::wesl_resolver`]) and lobes' reading of conditional blocks ([`super::wesl_blocks`]).
//! The crate writes the tree anew from its syntax, so each declaration's origin is kept
//! (`compose::DeclOrigin`) for messages at the user's file and line.

use super::super::{CheckError, Message, Setting};
use super::super::compose::{DeclOrigin, Source};
use super::super::composition::{Call, Composition, Dialect, Origin, UserCode};
use super::front_end::FrontEnd;
use super::naga_oil::foreign_directives;
#[cfg(feature = "wesl")]
#[cfg(feature = "wesl")]
use super::{
    roots::{roots, show_roots, stubs},
    stage::Stage,
    wesl_resolver::{Resolved, Roots, wesl_known},
};
#[cfg(feature = "wesl")]
use crate::wgsl_tokens::{Token, line_col, tokens};
#[cfg(feature = "wesl")]
use std::path::PathBuf;

/// The WESL front end.
pub(in crate::check) struct Wesl;

impl FrontEnd for Wesl {
    /// A `.wesl` file, or a WESL `import …;` statement in any file.
    fn sniff(&self, sources: &[Source]) -> bool {
        let wesl_import = |l: &str| {
            let l = l.trim_start();
            l.starts_with("import ") && (l.contains("::") || l.trim_end().ends_with(';'))
        };
        sources.iter().any(|s| s.name.ends_with(".wesl") || s.text.lines().any(wesl_import))
    }

    fn compose(&self, sources: &[Source], c: &Composition) -> Result<UserCode, CheckError> {
        foreign_directives(sources)?;
        let (text, origins, decls) = wesl_tree(sources, c)?;
        Ok(UserCode { decls, ..UserCode::tree(Dialect::Wesl, sources, "wesl", text, origins) })
    }

    /// Qualified names ([`super::qualified`]): WESL has no import aliases lobes reads.
    fn call(&self, code: &UserCode, call: Call, expr: &str, root_text: &str) -> Result<String, CheckError> {
        super::qualified::resolve(code, call, expr, root_text, &[])
    }
}

/// A composed WESL tree: its text, the origins of its mangled names, and of its declarations.
type WeslTree = (String, Vec<Origin>, Vec<DeclOrigin>);

#[cfg(not(feature = "wesl"))]
fn wesl_tree(sources: &[Source], _c: &Composition) -> Result<WeslTree, CheckError> {
    Err(CheckError::Input(format!("{}: WESL imports need lobes built with the feature \"wesl\" (the CLI has it)", sources[0].name)))
}

/// The sampler's file as a WESL module: the roots (each a folder, as each `--package` DIR) and
/// its path under the first root that holds it.
#[cfg(feature = "wesl")]
fn wesl_root(sources: &[Source], c: &Composition) -> Result<(Vec<PathBuf>, wesl::ModulePath), CheckError> {
    if let Some(s) = sources.get(1) {
        let m = Message::text(format!("{}: with WESL imports give only the sampler's file; the modules it imports are found under ", s.name));
        return Err(CheckError::Advised(m.setting(Setting::ShaderRoot)));
    }
    // each a folder, each package named once (Composition::validate)
    let roots = roots(sources, c);
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
    let result = result.map_err(|e| seen.borrow().advised(wesl_error(&e, &sources[0], &files)))?;
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
        decls.push(DeclOrigin { lines, file, module, name: item, text: original, at, renames: renames.clone() });
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

/// `--define` values as WESL's `@if` features: true or false (one not given is false).
#[cfg(feature = "wesl")]
fn feature_flags(c: &Composition) -> Result<std::collections::HashMap<String, bool>, CheckError> {
    let mut flags = std::collections::HashMap::new();
    for (n, v) in &c.defines {
        let on = match v.as_deref() {
            None | Some("true") => true,
            Some("false") => false,
            Some(other) => return Err(CheckError::setting(Setting::Define, format!("{n}={other}: WESL's @if features are true or false"))),
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

/// The keywords that start a module-scope declaration.
#[cfg(feature = "wesl")]
const DECLARES: [&str; 6] = ["fn", "const", "var", "override", "struct", "alias"];

/// Where the declaration of `name` starts in a WGSL/WESL text (the line whose first token, at
/// the margin, is `fn`, `const`, `var`, `override`, `struct` or `alias`, `name` after it), and
/// its text up to the next line that starts a declaration or an attribute at the margin.
#[cfg(feature = "wesl")]
fn declaration_text(source: &str, name: &str) -> Option<(usize, String)> {
    let found: Vec<Token> = tokens(source).collect();
    let margin = |t: &Token| t.column == 1;
    let declares = |t: &Token| margin(t) && DECLARES.iter().any(|k| t.is_name(k));
    let line_start = |t: &Token| t.start - (t.column - 1);
    let at = (0..found.len()).find(|&i| {
        // `var<private> NAME`: the name after the template's `>`
        let after = if found.get(i + 1).is_some_and(|t| t.is("<")) { found[i..].iter().position(|t| t.is(">")).map_or(i, |j| i + j) } else { i };
        declares(&found[i]) && found.get(after + 1).is_some_and(|t| t.is_name(name))
    })?;
    let start = line_start(&found[at]);
    let end = found[at + 1..].iter().find(|t| declares(t) || (margin(t) && t.is("@"))).map_or(source.len(), line_start);
    Some((start, source[start..end].to_string()))
}

#[cfg(all(test, feature = "wesl"))]
mod tests {
    use super::*;

    #[test]
    fn declarations_are_found_by_name() {
        let text = "const PI: f32 = 3.14;\n// a comment\nfn g1(w: vec3<f32>) -> f32 {\n  let z2 = w.z;\n  return z2;\n}\nfn other() {}\n";
        let (start, decl) = declaration_text(text, "g1").unwrap();
        assert_eq!(&text[start..start + 6], "fn g1(");
        assert_eq!(decl, "fn g1(w: vec3<f32>) -> f32 {\n  let z2 = w.z;\n  return z2;\n}\n");
        assert!(declaration_text(text, "g").is_none());
        assert_eq!(declaration_text(text, "PI").unwrap().0, 0);
        // a commented-out declaration is none; a `var<…>` is found by its name
        let text = "// fn h() {}\nvar<private> seed: u32;\n@compute @workgroup_size(1)\nfn main() {}\n";
        assert!(declaration_text(text, "h").is_none());
        assert_eq!(declaration_text(text, "seed").unwrap().1, "var<private> seed: u32;\n");
    }

    /// The fixture's WESL tree: every declaration of the root and of the modules it imports maps
    /// back to its file and line.
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
}
