//! The text rules by which `build.rs` turns `shaders/` into the embedded texts of
//! [`super`] (each module's plain, naga_oil and WESL form), and by which [`super`] moves a
//! resource's bindings at run time. Plain string work, no WGSL parser: the build script includes
//! this file (`#[path]`), and a renderer that embeds plain WGSL should not compile naga for it.
//! The unit tests of [`super`] parse what these rules produce with naga.

/// The names a file declares at module scope (`fn`, `const`, `override`, `struct`, `alias`,
/// `var`): the lines that start, after their attributes, with one of those keywords at column 0,
/// as every file of `shaders/` writes its module-scope declarations (checked against naga's
/// parse by `super::tests::declared_names_are_what_naga_finds`).
pub fn declared(source: &str) -> Vec<&str> {
    fn ident(s: &str) -> Option<&str> {
        let s = s.trim_start();
        let end = s.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(s.len());
        (end > 0).then(|| &s[..end])
    }
    fn skip_attributes(mut s: &str) -> &str {
        while let Some(after) = s.strip_prefix('@') {
            let end = after.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(after.len());
            s = &after[end..];
            if let Some(args) = s.strip_prefix('(') {
                s = args.find(')').map_or("", |i| &args[i + 1..]);
            }
            s = s.trim_start();
        }
        s
    }
    let mut out = Vec::new();
    for line in source.lines().filter(|l| !l.starts_with(char::is_whitespace)) {
        let rest = skip_attributes(line);
        for keyword in ["fn ", "const ", "override ", "struct ", "alias "] {
            out.extend(rest.strip_prefix(keyword).and_then(ident));
        }
        if let Some(var) = rest.strip_prefix("var") {
            out.extend(ident(var.find('>').map_or(var, |i| &var[i + 1..])));
        }
    }
    out
}

/// The path a file's `#define_import_path` names.
pub fn import_path(source: &str) -> Option<&str> {
    source.lines().find_map(|l| l.trim().strip_prefix("#define_import_path")).map(str::trim)
}

/// A file's `#import` lines as (path, items): `#import lobes::reflect::{LobeSample, PI}` is
/// (`lobes::reflect`, [`LobeSample`, `PI`]), `#import lobes::microfacet::stretch` is
/// (`lobes::microfacet`, [`stretch`]), the form every file of `shaders/` writes.
pub fn imports(source: &str) -> Vec<(&str, Vec<&str>)> {
    let mut out = Vec::new();
    for line in source.lines() {
        let Some(import) = line.trim().strip_prefix("#import ") else { continue };
        let import = import.trim();
        if let Some((path, items)) = import.split_once("::{") {
            let items = items.trim_end_matches('}').split(',').map(str::trim).filter(|s| !s.is_empty()).collect();
            out.push((path, items));
        } else if let Some((path, item)) = import.rsplit_once("::") {
            out.push((path, vec![item]));
        }
    }
    out
}

/// A file as plain WGSL: its `#define_import_path` and `#import` lines blanked (so that line
/// numbers stay those of the file).
pub fn plain(source: &str) -> String {
    source.lines().map(|l| if l.trim_start().starts_with('#') { "" } else { l }).collect::<Vec<_>>().join("\n")
}

/// A file's code for a module system that cannot hold the files' `alias Real` (naga_oil, whose
/// header writer drops aliases; the WESL package, which is lobes' f32 API): the directive lines
/// and the `alias Real` line dropped, and the word `Real` spelled `f32` in the code (comments,
/// after `//`, are left as written).
pub fn in_f32(source: &str) -> String {
    let word = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut out = String::with_capacity(source.len());
    for l in source.lines() {
        let t = l.trim_start();
        if t.starts_with('#') || t.starts_with("alias Real") {
            continue;
        }
        let (code, comment) = l.find("//").map_or((l, ""), |i| l.split_at(i));
        let mut rest = code;
        while let Some(at) = rest.find("Real") {
            let (before, after) = (&rest[..at], &rest[at + 4..]);
            let whole = !before.ends_with(word) && !after.starts_with(word);
            out.push_str(before);
            out.push_str(if whole { "f32" } else { "Real" });
            rest = after;
        }
        out.push_str(rest);
        out.push_str(comment);
        out.push('\n');
    }
    out
}

/// `source` with the storage buffers `table` and `alias` (names as written in it) declared at
/// `@group(group) @binding(..)`: each line that declares one (`var<storage, …> NAME:`) gets
/// the new attributes in place of its own. `None` if either declaration is missing.
pub fn with_bindings(source: &str, table: &str, alias: &str, group: u32, bindings: [u32; 2]) -> Option<String> {
    let mut found = [false; 2];
    let mut out = String::with_capacity(source.len() + 16);
    for line in source.split_inclusive('\n') {
        let var = line.find("var<storage");
        let which = [(table, 0), (alias, 1)].into_iter().find(|(name, _)| var.is_some() && line.contains(&format!("> {name}:")));
        match (var, which) {
            (Some(at), Some((_, k))) => {
                found[k] = true;
                out.push_str(&format!("@group({group}) @binding({}) {}", bindings[k], &line[at..]));
            }
            _ => out.push_str(line),
        }
    }
    (found == [true, true]).then_some(out)
}
