//! A user's WGSL sampler, checked against the contract and composed with lobes' passes.
//!
//! The composition (`gpu::compose`) holds lobes' own files (the RNG and the passes, naga_oil
//! modules), the user's files in the order given, and a small generated file that calls the
//! user's functions under fixed names (`lobes_user_sample`, `lobes_user_pdf`,
//! `lobes_user_eval`). Every part's first line in the composed text is remembered, so that a
//! naga diagnostic anywhere maps back to `file:line:column` of the part it came from.

use super::CheckError;
use crate::wgsl_tokens::{Kind, replace, tokens};
use naga::{ScalarKind, TypeInner, VectorSize};

/// One WGSL source: its name as shown in messages (usually the path) and its text.
#[derive(Debug, Clone, PartialEq)]
pub struct Source {
    pub name: String,
    pub text: String,
}

/// What a user's function must look like: its role, and its signature in the contract.
#[derive(Debug, Clone, Copy)]
pub(super) struct Signature {
    pub role: &'static str,
    pub args: [Ty; 3],
    pub result: Ty,
    pub text: &'static str,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Ty {
    Vec3,
    Vec4,
    Params,
    F32,
}

impl Ty {
    fn wgsl(self) -> &'static str {
        match self {
            Ty::Vec3 => "vec3<f32>",
            Ty::Vec4 => "vec4<f32>",
            Ty::Params => "array<vec4<f32>, 4>",
            Ty::F32 => "f32",
        }
    }
    fn matches(self, module: &naga::Module, inner: &TypeInner) -> bool {
        let vec = |n| matches!(inner, TypeInner::Vector { size, scalar } if *size == n && scalar.kind == ScalarKind::Float && scalar.width == 4);
        match self {
            Ty::Vec3 => vec(VectorSize::Tri),
            Ty::Vec4 => vec(VectorSize::Quad),
            Ty::F32 => matches!(inner, TypeInner::Scalar(s) if s.kind == ScalarKind::Float && s.width == 4),
            Ty::Params => match inner {
                TypeInner::Array { base, size: naga::ArraySize::Constant(n), .. } => {
                    n.get() == 4 && Ty::Vec4.matches(module, &module.types[*base].inner)
                }
                _ => false,
            },
        }
    }
}

pub(super) const SAMPLE: Signature = Signature {
    role: "sample",
    args: [Ty::Vec3, Ty::Vec4, Ty::Params],
    result: Ty::Vec4,
    text: "fn NAME(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32>",
};
pub(super) const PDF: Signature = Signature {
    role: "pdf",
    args: [Ty::Vec3, Ty::Vec3, Ty::Params],
    result: Ty::F32,
    text: "fn NAME(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32",
};
pub(super) const EVAL: Signature = Signature { role: "eval", ..PDF };

/// Where one declaration of a composed tree was written. The wesl crate writes a tree anew from
/// its syntax (its source map is per declaration: a mangled name's module and item, and each
/// module's text), so a line of its output maps back to a declaration, not to a line.
#[derive(Debug, Clone, PartialEq)]
pub struct DeclOrigin {
    /// The declaration's lines in the composed part, 1-based, inclusive.
    pub lines: (u32, u32),
    /// The file it was read from, as messages name it, and its module path (`package::utils`).
    pub file: String,
    pub module: String,
    /// Its name in that file.
    pub name: String,
    /// Its text in the file, and the file's line and column (1-based) where that text starts.
    pub text: String,
    pub at: (u32, u32),
    /// (name in the composed text, name in the file) of the items renamed by the composition.
    pub renames: Vec<(String, String)>,
}

impl DeclOrigin {
    /// The file's line and column of `snippet` (text of the composed declaration, on the
    /// composed `line`) where it, or else that line, occurs exactly once in the declaration as
    /// written (its renamed items named as the file names them).
    fn find(&self, snippet: &str, line: &str) -> Option<(u32, u32)> {
        let written = |t: &str| self.renames.iter().fold(t.to_string(), |t, (composed, item)| replace_word(&t, composed, item));
        let once = |t: &str| {
            let mut hits = self.text.match_indices(t);
            let (at, _) = hits.next()?;
            hits.next().is_none().then_some(at)
        };
        let snippet = written(snippet);
        let snippet = snippet.trim();
        if snippet.is_empty() {
            return None;
        }
        // the offending text itself, or (it occurs more than once) its whole line, then the
        // text within that line
        let at = once(snippet).or_else(|| {
            let line = written(line);
            let line = line.trim();
            let start = once(line).filter(|_| !line.is_empty())?;
            Some(start + line.find(snippet)?)
        })?;
        let before = &self.text[..at];
        let lines = before.matches('\n').count() as u32;
        let column = match before.rfind('\n') {
            Some(nl) => before[nl + 1..].chars().count() as u32 + 1,
            None => before.chars().count() as u32 + self.at.1,
        };
        Some((self.at.0 + lines, column))
    }
}

/// `text` with every name `from` replaced by `to`.
pub(super) fn replace_word(text: &str, from: &str, to: &str) -> String {
    replace(text, tokens(text), |t| t.is_name(from).then(|| to.to_string()))
}

/// Composed text with the first line of each part, for mapping diagnostics back.
#[derive(Debug, Clone, Default)]
pub struct Composed {
    pub text: String,
    /// (first line, 1-based, of the part in `text`; the part's name; where its declarations
    /// came from, for a tree that the wesl crate wrote).
    parts: Vec<(u32, String, Vec<DeclOrigin>)>,
    /// The user's resources bound for lobes' passes ([`super::resources`]).
    pub bound: Vec<super::resources::Bound>,
}

impl Composed {
    pub fn push(&mut self, name: &str, text: &str) {
        self.push_mapped(name, text, Vec::new());
    }

    /// [`Self::push`] of a part whose declarations map back to their files ([`DeclOrigin`]).
    pub fn push_mapped(&mut self, name: &str, text: &str, decls: Vec<DeclOrigin>) {
        let line = self.text.lines().count() as u32 + 1;
        self.parts.push((line, name.to_string(), decls));
        self.text.push_str(text);
        if !text.ends_with('\n') {
            self.text.push('\n');
        }
    }

    /// `file:line:column` of a composed line and column.
    pub fn locate(&self, line: u32, column: u32) -> String {
        match self.parts.iter().rev().find(|(first, _, _)| *first <= line) {
            Some((first, name, _)) => format!("{name}:{}:{column}", line - first + 1),
            None => format!("<composed>:{line}:{column}"),
        }
    }

    /// The declaration of a mapped part ([`Self::push_mapped`]) that holds a composed line.
    fn declaration(&self, line: u32) -> Option<&DeclOrigin> {
        let (first, _, decls) = self.parts.iter().rev().find(|(first, _, _)| *first <= line)?;
        let line = line - first + 1;
        decls.iter().find(|d| (d.lines.0..=d.lines.1).contains(&line))
    }

    /// The source line at a composed line number.
    fn line(&self, line: u32) -> &str {
        self.text.lines().nth(line as usize - 1).unwrap_or("")
    }

    /// A diagnostic at `span`: "file:line:col: error: message", the offending line and a caret.
    /// `message` at the user's file and line of `span` of the composed text.
    pub fn diagnostic_at(&self, span: naga::Span, message: &str) -> String {
        self.diagnostic(Some(span.location(&self.text)), message, &[])
    }

    fn diagnostic(&self, span: Option<naga::SourceLocation>, message: &str, labels: &[String]) -> String {
        let caret = |column: u32, length: u32| " ".repeat(column.saturating_sub(1) as usize) + &"^".repeat((length as usize).clamp(1, 60));
        let mut out = match span {
            Some(loc) => {
                let at = self.locate(loc.line_number, loc.line_position);
                let src = self.line(loc.line_number);
                let snippet = self.text.get(loc.offset as usize..(loc.offset + loc.length) as usize).unwrap_or("");
                match self.declaration(loc.line_number) {
                    // the user's own line and column, where the offending text is found in the declaration
                    Some(d) => match d.find(snippet, src) {
                        Some((line, column)) => {
                            let user_line = d.text.lines().nth((line - d.at.0) as usize).unwrap_or("");
                            let user_line = if line == d.at.0 { format!("{}{user_line}", " ".repeat(d.at.1 as usize - 1)) } else { user_line.to_string() };
                            let length = snippet.lines().next().map_or(1, |l| l.chars().count() as u32);
                            format!(
                                "{}:{line}:{column}: {message}\n    {user_line}\n    {}\n    note: in `{}` of module {} (wesl composed it as {at})",
                                d.file,
                                caret(column, length),
                                d.name,
                                d.module
                            )
                        }
                        // else the declaration's line, and the composed line
                        None => format!(
                            "{}:{}: in the declaration `{}` of module {}: {message}\n    note: wesl composed that declaration anew; at {at} of its text:\n    {src}\n    {}",
                            d.file,
                            d.at.0,
                            d.name,
                            d.module,
                            caret(loc.line_position, loc.length)
                        ),
                    },
                    None => format!("{at}: {message}\n    {src}\n    {}", caret(loc.line_position, loc.length)),
                }
            }
            None => format!("error: {message}"),
        };
        for label in labels.iter().filter(|l| !l.is_empty()) {
            out.push_str(&format!("\n    note: {label}"));
        }
        out
    }

    /// Parses and validates the composed text with naga; errors point at the original files.
    /// (On a thread with a large stack: a user's expression may nest deeper than an ordinary
    /// stack holds, [`crate::engine::gpu::stack`].)
    pub fn validate(&self) -> Result<naga::Module, CheckError> {
        Ok(self.validate_with(naga::valid::Capabilities::default())?.0)
    }

    /// [`Self::validate`] with the given capabilities, and naga's information on the module
    /// (the types of its expressions).
    pub fn validate_with(&self, caps: naga::valid::Capabilities) -> Result<(naga::Module, naga::valid::ModuleInfo), CheckError> {
        crate::engine::gpu::stack::with_big_stack(|| self.parse_and_validate(caps))
    }

    fn parse_and_validate(&self, caps: naga::valid::Capabilities) -> Result<(naga::Module, naga::valid::ModuleInfo), CheckError> {
        let module = naga::front::wgsl::parse_str(&self.text).map_err(|e| {
            let labels: Vec<String> = e.labels().map(|(_, l)| l.to_string()).collect();
            CheckError::Wgsl(self.diagnostic(e.location(&self.text), e.message(), &labels))
        })?;
        let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps).validate(&module).map_err(|e| {
            let labels: Vec<String> = e.spans().map(|(_, l)| l.clone()).collect();
            let mut message = e.as_inner().to_string();
            let mut source: Option<&dyn std::error::Error> = std::error::Error::source(e.as_inner());
            while let Some(s) = source {
                message.push_str(&format!(": {s}"));
                source = s.source();
            }
            CheckError::Wgsl(self.diagnostic(e.location(&self.text), &message, &labels))
        })?;
        Ok((module, info))
    }
}

/// The user's files alone, validated, with each named function checked against its signature.
/// (Any capability is allowed here: what the passes cannot run is the final composition's to
/// refuse, once a composed tree is cut to what the sampler reaches.)
///
/// `decls`: where the declarations of a tree the wesl crate composed (one part) came from.
pub(super) fn check_user(sources: &[Source], decls: &[DeclOrigin], functions: &[(&str, Signature)]) -> Result<naga::Module, CheckError> {
    if sources.is_empty() {
        return Err(CheckError::Input("no WGSL file given: name at least one file that defines the sampler".into()));
    }
    let mut composed = Composed::default();
    for s in sources {
        composed.push_mapped(&s.name, &s.text, if sources.len() == 1 { decls.to_vec() } else { Vec::new() });
    }
    let module = composed.validate_with(naga::valid::Capabilities::all())?.0;
    let files = sources.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ");
    for &(name, sig) in functions {
        let expected = sig.text.replace("NAME", name);
        let Some((handle, f)) = module.functions.iter().find(|(_, f)| f.name.as_deref() == Some(name)) else {
            let known: Vec<&str> = module.functions.iter().filter_map(|(_, f)| f.name.as_deref()).collect();
            return Err(CheckError::Input(format!(
                "no {} function `{name}` in {files}; expected `{expected}` (functions there: {})",
                sig.role,
                if known.is_empty() { "none".to_string() } else { known.join(", ") }
            )));
        };
        let args_ok = f.arguments.len() == sig.args.len()
            && f.arguments.iter().zip(sig.args).all(|(a, t)| t.matches(&module, &module.types[a.ty].inner));
        let result_ok = f.result.as_ref().is_some_and(|r| sig.result.matches(&module, &module.types[r.ty].inner));
        if !(args_ok && result_ok) {
            let loc = module.functions.get_span(handle).location(&composed.text);
            let got: Vec<String> = f.arguments.iter().map(|a| describe(&module, a.ty)).collect();
            let ret = f.result.as_ref().map(|r| format!(" -> {}", describe(&module, r.ty))).unwrap_or_default();
            return Err(CheckError::Input(format!(
                "{}: the {} function `{name}` has the wrong signature: `fn {name}({}){ret}`; expected `{expected}`",
                composed.locate(loc.line_number, loc.line_position),
                sig.role,
                got.join(", "),
            )));
        }
    }
    Ok(module)
}

/// A type as WGSL writes it, for the common ones; else naga's debug form.
fn describe(module: &naga::Module, ty: naga::Handle<naga::Type>) -> String {
    let inner = &module.types[ty].inner;
    for t in [Ty::Vec3, Ty::Vec4, Ty::Params, Ty::F32] {
        if t.matches(module, inner) {
            return t.wgsl().to_string();
        }
    }
    describe_inner(inner)
}

/// A scalar or vector type as WGSL writes it; else naga's debug form.
pub(super) fn describe_inner(inner: &TypeInner) -> String {
    let scalar = |s: &naga::Scalar| match s.kind {
        ScalarKind::Float => format!("f{}", s.width * 8),
        ScalarKind::Sint => format!("i{}", s.width * 8),
        ScalarKind::Uint => format!("u{}", s.width * 8),
        ScalarKind::Bool => "bool".to_string(),
        k => format!("{k:?}").to_lowercase(),
    };
    match inner {
        TypeInner::Scalar(s) => scalar(s),
        TypeInner::Vector { size, scalar: s } => format!("vec{}<{}>", *size as u8, scalar(s)),
        other => format!("{other:?}"),
    }
}

/// The names the user's module defines at module scope (functions, constants, globals, types).
pub(super) fn global_names(module: &naga::Module) -> Vec<String> {
    let f = module.functions.iter().filter_map(|(_, f)| f.name.clone());
    let c = module.constants.iter().filter_map(|(_, c)| c.name.clone());
    let g = module.global_variables.iter().filter_map(|(_, g)| g.name.clone());
    let o = module.overrides.iter().filter_map(|(_, o)| o.name.clone());
    let t = module.types.iter().filter_map(|(_, t)| t.name.clone());
    f.chain(c).chain(g).chain(o).chain(t).collect()
}

/// A validated module written back as WGSL, with the names as the module holds them: naga's
/// writer appends `_` to a name that ends in a digit (`v0` → `v0_`), which is undone here. What
/// the writer cannot write (ray queries, and what calls them) is left out first.
pub(super) fn write_wgsl(module: &naga::Module, caps: naga::valid::Capabilities) -> Result<String, CheckError> {
    let module = &*writable(module);
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps)
        .validate(module)
        .map_err(|e| CheckError::Internal(format!("the composed module does not validate: {}", e.as_inner())))?;
    let text = naga::back::wgsl::write_string(module, &info, naga::back::wgsl::WriterFlags::empty())
        .map_err(|e| CheckError::Internal(format!("naga's WGSL writer failed: {e}")))?;
    Ok(undo_digit_suffix(&text))
}

/// `module` without what naga's WGSL writer cannot write (ray queries and their callers,
/// `call_graph::drop_ray_queries`); itself where it has none.
pub(super) fn writable(module: &naga::Module) -> std::borrow::Cow<'_, naga::Module> {
    if !super::call_graph::needs_cut(module) {
        return std::borrow::Cow::Borrowed(module);
    }
    let mut m = module.clone();
    super::call_graph::drop_ray_queries(&mut m);
    std::borrow::Cow::Owned(m)
}

/// `name0_` → `name0` for every name that ends in a digit and one underscore, unless the text
/// holds `name0` too (the writer's namer gave a clash of `name` the name `name0`: a GLSL
/// parameter `u` beside its copy `u_1`, written `u_1` and `u_1_`).
fn undo_digit_suffix(text: &str) -> String {
    let names: std::collections::HashSet<&str> = tokens(text).filter(|t| t.kind == Kind::Ident).map(|t| t.text).collect();
    let unsuffixed = |name: &str| {
        let plain = name.strip_suffix('_')?;
        (plain.ends_with(|c: char| c.is_ascii_digit()) && plain.len() >= 2 && !names.contains(plain)).then(|| plain.to_string())
    };
    replace(text, tokens(text), |t| unsuffixed(t.text).filter(|_| t.kind == Kind::Ident))
}

/// Replaces the body of each function in `functions` (handles of `module`, parsed from `text`)
/// with `body(function)`, keeping the text's line count (the body's newlines stay), so that
/// every later line keeps its number.
pub(super) fn replace_bodies(text: &str, module: &naga::Module, functions: &[(naga::Handle<naga::Function>, String)]) -> Result<String, CheckError> {
    let mut spans: Vec<(usize, usize, &str)> = Vec::new();
    for (h, body) in functions {
        let span = module.functions.get_span(*h).to_range().ok_or_else(|| CheckError::Internal("a function without a span".into()))?;
        let (open, end) = body_of(&text[span.clone()])?;
        spans.push((span.start + open, span.start + end, body.as_str()));
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

/// The byte range of the body of the function declared by `decl`: from the first `{` after its
/// argument list's `)` to its last `}`.
fn body_of(decl: &str) -> Result<(usize, usize), CheckError> {
    let internal = |what: &str| CheckError::Internal(what.into());
    let mut after = tokens(decl).skip_while(|t| !t.is("("));
    let mut depth = 0;
    after.find(|t| {
        depth += i32::from(t.is("(")) - i32::from(t.is(")"));
        depth == 0
    });
    if depth != 0 {
        return Err(internal(if tokens(decl).any(|t| t.is("(")) { "unbalanced parentheses" } else { "a function without arguments" }));
    }
    let open = after.find(|t| t.is("{")).ok_or_else(|| internal("a function without a body"))?;
    let end = tokens(decl).filter(|t| t.is("}")).last().ok_or_else(|| internal("a function without a body"))?;
    Ok((open.start, end.end()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Locals named as naga's writer names its own values (`_e4`, `_e5`: what a module written
    /// by naga once, as naga_oil's headers are, holds) beside the values the writer names anew:
    /// written, the suffix undone, and read back, no name is defined twice in a function (Bevy
    /// 0.19.1's Solari BRDF gave "redefinition of `_e41`").
    #[test]
    fn locals_named_like_the_writers_values_stay_distinct() {
        let text = "fn f(x: f32) -> f32 {\n    let _e4 = x * 2.0;\n    let _e5 = sin(x) + cos(_e4);\n    let _e6 = _e5 * _e5 + x;\n    return _e6 * x + sin(_e6 * 3.0) * cos(_e5);\n}\n";
        let module = naga::front::wgsl::parse_str(text).unwrap();
        let written = write_wgsl(&module, naga::valid::Capabilities::all()).unwrap();
        if let Err(e) = naga::front::wgsl::parse_str(&written) {
            panic!("{}\n{written}", e.emit_to_string(&written));
        }
    }

    #[test]
    fn digit_suffixes_are_undone() {
        assert_eq!(undo_digit_suffix("fn f0_(a: f32) -> f32 { let x_1 = a; return v2_ + b_; }"), "fn f0(a: f32) -> f32 { let x_1 = a; return v2 + b_; }");
        // a name the namer gave a clash stays: `u_1_` (the user's u_1) beside `u_1` (its u)
        assert_eq!(undo_digit_suffix("fn g(u: f32, u_1: f32) { var u_1_ = u_1; }"), "fn g(u: f32, u_1: f32) { var u_1_ = u_1; }");
        // numbers are no names: 1e3 and 2u stay as they are
        assert_eq!(undo_digit_suffix("let a2_ = 1e3 + 2u;"), "let a2 = 1e3 + 2u;");
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
        // a parenthesis or a brace in a comment is no part of the declaration's shape
        assert_eq!(body_of("fn f(a: f32 /* ) { */) -> f32 { return a; } // }").unwrap(), (30, 43));
    }
}
