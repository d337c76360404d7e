//! lobes' resolver of WESL modules for the `wesl` crate ([`Roots`]): `package::a::b` is
//! `a/b.wesl` (or `.wgsl`) under the shader roots, `NAME::a::b` under `--package NAME=DIR`, a
//! stub where one is given; what it refuses (a module reachable two ways, one that imports
//! itself) and why an import is not found (the closest modules under the roots).

use super::super::{CheckError, Message, Setting};
use super::super::compose::Source;
use super::super::composition::Composition;
use super::roots::{scan, show_roots};
use crate::wgsl_tokens::line_col;
use std::path::PathBuf;

/// lobes' WESL resolver: `package::a::b` is `a/b.wesl` (or `.wgsl`) under the shader roots, a
/// stub where one is given.
pub(super) struct Roots {
    pub roots: Vec<PathBuf>,
    /// `--package NAME=DIR`: where `NAME::…` paths are, instead of the roots.
    pub packages: Vec<(String, PathBuf)>,
    /// The `@if` features, for the conditional blocks `wesl` 0.4 cannot read ([`wesl_blocks`]).
    ///
    /// [`wesl_blocks`]: super::wesl_blocks
    pub features: std::collections::HashMap<String, bool>,
    pub stubs: Vec<(String, Source)>,
    /// Module paths (`package::a::b`) of the files under the roots, for "closest" names.
    pub known: Vec<String>,
    /// What resolving found (the wesl crate keeps the resolver; the tree's caller reads this).
    pub seen: std::rc::Rc<std::cell::RefCell<Resolved>>,
}

/// What lobes' resolver saw of a WESL tree: the stubs used, an input error of its own (a
/// module reachable two ways, one that imports itself), which the wesl crate's error would hide,
/// and why each import it could not find is not found (the wesl crate's error holds a
/// [`marker`] in its place, [`Resolved::advised`] puts it back).
#[derive(Default)]
pub(super) struct Resolved {
    stubs_used: Vec<String>,
    error: Option<Message>,
    not_found: Vec<Message>,
}

/// What the wesl crate's error holds in place of the `i`th message of [`Resolved::not_found`]
/// (a message that names settings cannot travel as its text).
fn marker(i: usize) -> String {
    format!("⟦lobes {i}⟧")
}

impl Resolved {
    /// The resolver's own error, else a `--stub` that no import reached.
    pub(super) fn refusal(&self, c: &Composition, root: &str) -> Result<(), CheckError> {
        if let Some(why) = &self.error {
            return Err(CheckError::Advised(why.clone()));
        }
        match c.stubs.iter().find(|(m, _)| !self.stubs_used.contains(m)) {
            Some((m, _)) => Err(CheckError::setting(
                Setting::Stub,
                format!("{m}: no import of {root} or of the modules it imports names that module, so the stub stands in for nothing; check the module path (as the import names it: package::a::b)"),
            )),
            None => Ok(()),
        }
    }

    /// `e` with the messages of the imports not found back where the wesl crate's text holds
    /// their markers: advice naming settings ([`CheckError::Advised`]).
    pub(super) fn advised(&self, e: CheckError) -> CheckError {
        let text = match &e {
            CheckError::Wgsl(t) | CheckError::Input(t) if t.contains("⟦lobes ") => t.clone(),
            _ => return e,
        };
        let mut message = Message::text("");
        let mut rest = text.as_str();
        while let Some(at) = rest.find("⟦lobes ") {
            let (before, after) = rest.split_at(at);
            let Some((index, tail)) = after["⟦lobes ".len()..].split_once('⟧') else { break };
            let Some(m) = index.parse::<usize>().ok().and_then(|i| self.not_found.get(i)) else { break };
            message = message.then(before).append(m.clone());
            rest = tail;
        }
        CheckError::Advised(message.then(rest))
    }
}

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
    pub(super) fn file(&self, path: &wesl::ModulePath) -> Option<PathBuf> {
        self.files(path).into_iter().next()
    }
    fn stub(&self, path: &wesl::ModulePath) -> Option<&(String, Source)> {
        let shown = path.to_string();
        self.stubs.iter().find(|(m, _)| *m == shown || format!("package::{m}") == shown)
    }
    /// Why no file holds `path`: where lobes looked, the closest modules it found, and the
    /// settings that say where the module is; kept in [`Resolved`], its [`marker`] returned.
    fn not_found(&self, path: &wesl::ModulePath) -> String {
        let shown = path.to_string();
        let rel = path.components.join("/");
        let package = |name: &str| Message::text("").setting(Setting::Package).then(format!(" {name}"));
        let (looked, hint) = match &path.origin {
            wesl::syntax::PathOrigin::Package(name) => match self.packages.iter().find(|(n, _)| n == name) {
                Some((_, dir)) => (
                    Message::text(format!("no file {rel}.wesl or .wgsl in {} (", dir.display())).append(package(name)).then(")"),
                    Message::text("Check the folder of ").append(package(name)).then(format!("=DIR (it holds {name}'s modules: {name}::a::b is DIR/a/b.wesl), ")),
                ),
                None => (
                    Message::text(format!("no package {name} given (")).setting(Setting::Package).then(format!("), and no file {rel}.wesl or .wgsl under the shader roots ({}), where lobes looks for it without its name", show_roots(&self.roots))),
                    Message::text(format!("Say where {name} is with ")).append(package(name)).then("=DIR, "),
                ),
            },
            _ => (
                Message::text(format!("no file {rel}.wesl or .wgsl under the shader roots ({})", show_roots(&self.roots))),
                Message::text("Add its folder with ").setting(Setting::ShaderRoot).then(", "),
            ),
        };
        let close = closest_modules(&shown, &self.known);
        let close = match close.is_empty() {
            true => format!("none of the {} modules found is close", self.known.len()),
            false => format!("closest: {} of the {} modules found", close.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", "), self.known.len()),
        };
        let why = Message::text("unresolved import: ").append(looked).then(format!(" ({close}). ")).append(hint).then("or stand in for it with ").setting(Setting::Stub).then(format!(" {shown}=FILE"));
        let mut seen = self.seen.borrow_mut();
        seen.not_found.push(why);
        marker(seen.not_found.len() - 1)
    }
    /// `text` (the file `name`) with its `@if` blocks resolved; a malformed condition is an
    /// error at its file, line and column.
    fn conditional_blocks(&self, path: &wesl::ModulePath, name: &str, text: &str) -> Result<String, wesl::ResolveError> {
        super::wesl_blocks::resolve(text, &self.features).map_err(|e| {
            let (line, col) = line_col(text, e.at);
            self.refuse(path, Message::text(format!("{name}:{line}:{col}: {}", e.message)))
        })
    }
    /// An error of the resolver's own, kept for the tree's caller (and a short one for wesl).
    fn refuse(&self, path: &wesl::ModulePath, why: Message) -> wesl::ResolveError {
        self.seen.borrow_mut().error.get_or_insert(why);
        wesl::ResolveError::ModuleNotFound(path.clone(), "see above".into())
    }
}

/// The first `import` statement of a WESL text that names its own module `path`
/// (`package::a::b`, or through `super::`): its line and text.
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
            let why = format!("the module {shown} is reachable two ways: {}; which one the renderer composes is not for lobes to guess. Remove or rename the stale copy, or give the right one with ", names.join(" and "));
            return Err(self.refuse(path, Message::text(why).setting(Setting::Stub).then(format!(" {shown}=FILE"))));
        }
        let text = std::fs::read_to_string(f).map_err(|e| wesl::ResolveError::ModuleNotFound(path.clone(), format!("{}: {e}", f.display())))?;
        if let Some((line, stmt)) = self_import(&text, path) {
            return Err(self.refuse(path, Message::text(format!(
                "{}:{line}: the module {shown} imports itself (`{stmt}`); a module names its own declarations without an import: remove the line",
                f.display()
            ))));
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

/// The few modules of `known` closest to `wanted`: those that share its last segment first
/// (`bevy_render::maths` and `package::maths`), then by the edit distance of the last segment
/// and of the whole path.
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
pub(super) fn wesl_known(roots: &[PathBuf], packages: &[(String, PathBuf)]) -> Vec<String> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_marker_is_its_message_naming_settings() {
        let r = Resolved { not_found: vec![Message::text("stand in with ").setting(Setting::Stub)], ..Default::default() };
        let CheckError::Advised(m) = r.advised(CheckError::Wgsl(format!("a.wesl:1:2: module not found: `x` ({})", marker(0)))) else { panic!() };
        assert_eq!(m.render(&|s| format!("--{}", s.key())), "a.wesl:1:2: module not found: `x` (stand in with --stub)");
        assert!(matches!(r.advised(CheckError::Wgsl("a.wesl:1:2: x".into())), CheckError::Wgsl(_)), "no marker: left as it is");
    }
}
