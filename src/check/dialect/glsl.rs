//! A GLSL sampler through naga's GLSL front end (`glsl-in`: Vulkan GLSL 440, 450, 460).
//!
//! naga's front end has no `#include` and needs an entry point; lobes supplies both:
//! - `#include "x"` (and `<x>`) with `GL_GOOGLE_include_directive`'s meaning: `"x"` relative to
//!   the including file, then under each `--shader-root`; `<x>` under the roots only. The files
//!   are expanded into one text with a line map, so every error names the file and line it is
//!   at. An include that no root holds becomes an `#error` line, so that only one the
//!   preprocessor reaches (outside an inactive `#if`) is an error; a file that includes itself
//!   (through others) is not expanded again (include guards would skip it), and a file with
//!   `#pragma once` is expanded once;
//! - without a `void main()`, an empty compute one (dropped again with the other entry points:
//!   lobes calls the functions).
//!
//! `--define NAME[=VALUE]` is `#define NAME VALUE` (no value: 1, as `-DNAME` of glslang).
//! Several files given are one translation unit, in order. A `#version` other than 440, 450 or
//! 460 (an OpenGL renderer's 330 or 430) is read as 450.

use super::super::{CheckError, Message, Setting};
use super::super::compose::Source;
use super::super::composition::{Call, Composition, Dialect, UserCode};
use super::front_end::FrontEnd;
use super::gl_uniforms;
use super::translate::{Translation, fall_through, to_wgsl, translated};
use std::path::{Path, PathBuf};

/// The GLSL front end.
pub(in crate::check) struct Glsl;

impl FrontEnd for Glsl {
    fn sniff(&self, sources: &[Source]) -> bool {
        sources.iter().any(is_glsl)
    }
    fn compose(&self, sources: &[Source], c: &Composition) -> Result<UserCode, CheckError> {
        translated(Dialect::Glsl, sources, c, || translate(sources, c))
    }
    fn call(&self, code: &UserCode, call: Call, expr: &str, _root_text: &str) -> Result<String, CheckError> {
        super::translate::call(code, call, expr)
    }
}

/// The file extensions of GLSL: sources, includes and the stages glslang names by extension.
const EXTENSIONS: [&str; 16] = ["glsl", "vert", "frag", "comp", "geom", "tesc", "tese", "mesh", "task", "rgen", "rchit", "rmiss", "rahit", "rint", "rcall", "glslinc"];

/// Whether `s` is GLSL: its extension, or a `#version` line.
pub(super) fn is_glsl(s: &Source) -> bool {
    let ext = Path::new(&s.name).extension().and_then(|e| e.to_str()).unwrap_or("");
    EXTENSIONS.contains(&ext) || s.text.lines().any(|l| l.trim_start().strip_prefix('#').is_some_and(|r| r.trim_start().starts_with("version ")))
}

/// Where a line of the expanded text came from.
#[derive(Debug, Clone, Copy)]
struct At {
    /// Index into [`Expanded::files`].
    file: usize,
    /// 1-based line in that file.
    line: u32,
}

/// The files with their includes expanded, as one text.
#[derive(Debug, Default)]
struct Expanded {
    text: String,
    /// Per line of `text`, where it came from.
    lines: Vec<At>,
    files: Vec<String>,
    /// The texts of `files` (for the lines of messages).
    texts: Vec<String>,
    /// Lines of `text` that stand for an include no root holds, with the message.
    missing: Vec<(usize, Message)>,
    /// Files with `#pragma once` already expanded.
    once: Vec<PathBuf>,
    /// OpenGL's loose uniforms, where they are declared ([`gl_uniforms`]).
    uniforms: Vec<(gl_uniforms::Uniform, At)>,
}

impl Expanded {
    /// `file:line` of a line of a file.
    fn place(&self, at: At) -> String {
        format!("{}:{}", self.files[at.file], at.line)
    }

    fn push(&mut self, line: &str, at: At) {
        self.text.push_str(line);
        self.text.push('\n');
        self.lines.push(at);
    }

    /// `file:line:column: message`, the user's line and a caret, for a location in `text`.
    fn diagnostic(&self, loc: Option<naga::SourceLocation>, message: &str) -> String {
        self.advice(loc, Message::text(message)).to_string()
    }

    /// [`Expanded::diagnostic`] of a message that may name settings.
    fn advice(&self, loc: Option<naga::SourceLocation>, message: Message) -> Message {
        let Some((loc, at)) = loc.and_then(|l| Some((l, self.lines.get(l.line_number.saturating_sub(1) as usize)?))) else {
            return Message::text(format!("{}: error: ", self.files.join(", "))).append(message);
        };
        let src = self.texts[at.file].lines().nth(at.line as usize - 1).unwrap_or("");
        let caret = " ".repeat(loc.line_position.saturating_sub(1) as usize) + &"^".repeat((loc.length as usize).clamp(1, 60));
        Message::text(format!("{}:{}:{}: error: ", self.files[at.file], at.line, loc.line_position)).append(message).then(format!("\n    {src}\n    {caret}"))
    }
}

/// The user's GLSL files, their includes expanded and `--define`s given, translated to WGSL.
pub(super) fn translate(sources: &[Source], c: &Composition) -> Result<Translation, CheckError> {
    let roots = c.shader_roots.clone();
    let mut x = Expanded::default();
    for (i, s) in sources.iter().enumerate() {
        expand(&mut x, s, &roots, &mut Vec::new(), i == 0)?;
    }
    let stage = match Path::new(&sources[0].name).extension().and_then(|e| e.to_str()) {
        Some("vert") => naga::ShaderStage::Vertex,
        Some("frag") => naga::ShaderStage::Fragment,
        _ => naga::ShaderStage::Compute,
    };
    let mut options = naga::front::glsl::Options::from(stage);
    for (name, value) in &c.defines {
        options.defines.insert(name.clone(), value.clone().unwrap_or_else(|| "1".into()));
    }
    let module = match parse(&x, &options) {
        Err(errors) if errors.iter().all(is_missing_entry_point) => {
            // lobes calls the functions: an empty entry point for naga, dropped after parsing
            let files = x.files.len();
            x.files.push("<lobes' empty entry point>".into());
            x.texts.push("void main() {}".into());
            x.push("void main() {}", At { file: files, line: 1 });
            parse(&x, &options)
        }
        other => other,
    };
    let mut module = module.map_err(|errors| {
        let mut messages: Vec<Message> = errors.iter().map(|e| message(&x, e)).collect();
        messages.dedup();
        let all = messages.into_iter().take(8).reduce(|all, m| all.then("\n").append(m)).unwrap_or_else(|| Message::text("naga's GLSL reader failed and said nothing"));
        if all.names_settings() { CheckError::Advised(all) } else { CheckError::Wgsl(all.to_string()) }
    })?;
    if let Some((span, f)) = fall_through(&mut module) {
        let m = format!("in `{f}`, a `switch` case falls through into the next one, which WGSL (what lobes runs) cannot express; end each case that has statements with `break` or `return` (repeat the next case's statements in it if it meant to fall through)");
        return Err(CheckError::Wgsl(x.diagnostic(Some(span.location(&x.text)), &m)));
    }
    let shown = sources.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ");
    to_wgsl(module, &shown, |e| {
        let mut message = e.as_inner().to_string();
        let mut source: Option<&dyn std::error::Error> = std::error::Error::source(e.as_inner());
        while let Some(s) = source {
            message.push_str(&format!(": {s}"));
            source = s.source();
        }
        x.diagnostic(e.location(&x.text), &format!("naga translated the GLSL into a module it does not accept: {message}"))
    })
    .map(|t| Translation { uniforms: x.uniforms.iter().filter(|(u, _)| !u.opaque).map(|(u, at)| (u.name.clone(), x.place(*at))).collect(), ..t })
}

fn parse(x: &Expanded, options: &naga::front::glsl::Options) -> Result<naga::Module, Vec<naga::front::glsl::Error>> {
    let text = x.text.clone();
    crate::engine::gpu::stack::with_big_stack(|| naga::front::glsl::Frontend::default().parse(options, &text).map_err(|e| e.errors))
}

fn is_missing_entry_point(e: &naga::front::glsl::Error) -> bool {
    matches!(&e.kind, naga::front::glsl::ErrorKind::SemanticError(m) if m == "Missing entry point")
}

/// One error of naga's GLSL front end at the user's file and line (an `#error` lobes wrote for
/// a missing include: that include's message).
fn message(x: &Expanded, e: &naga::front::glsl::Error) -> Message {
    let loc = e.location(&x.text);
    match loc.and_then(|l| x.missing.iter().find(|(line, _)| *line + 1 == l.line_number as usize)) {
        // the include line as the user wrote it, from its start
        Some((line, m)) => x.advice(Some(naga::SourceLocation { line_number: *line as u32 + 1, line_position: 1, offset: 0, length: 0 }), m.clone()),
        None => x.advice(loc, left_out(x, e).unwrap_or_else(|| Message::text(e.kind.to_string()))),
    }
}

/// The message for a use of an opaque loose uniform that lobes left out ([`gl_uniforms`]).
fn left_out(x: &Expanded, e: &naga::front::glsl::Error) -> Option<Message> {
    let naga::front::glsl::ErrorKind::UnknownVariable(name) = &e.kind else { return None };
    let (_, at) = x.uniforms.iter().find(|(u, _)| u.opaque && &u.name == name)?;
    let what = format!(
        "`{name}` is an OpenGL uniform sampler or image ({}), which naga's GLSL reader cannot take, so lobes left it out; the function here uses it: give lobes the files that define the sampler without this one (or this function behind an #ifdef that ",
        x.place(*at)
    );
    Some(Message::text(what).setting(Setting::Define).then(" leaves off)"))
}

/// `#include "x"` or `#include <x>` on this line: (x, whether quoted).
fn include(line: &str) -> Option<(&str, bool)> {
    let rest = line.trim_start().strip_prefix('#')?.trim_start().strip_prefix("include")?.trim();
    let quoted = rest.strip_prefix('"').and_then(|r| r.split_once('"')).map(|(p, _)| (p, true));
    quoted.or_else(|| rest.strip_prefix('<').and_then(|r| r.split_once('>')).map(|(p, _)| (p, false)))
}

/// Whether the line is the directive `#NAME…`.
fn directive(line: &str, name: &str) -> bool {
    line.trim_start().strip_prefix('#').is_some_and(|r| r.trim_start().starts_with(name))
}

/// Appends `s` to `x` with its includes expanded. `stack`: the files being expanded (a file
/// that includes itself through others is not expanded again); `first`: the translation unit's
/// first file, whose `#version` stays.
fn expand(x: &mut Expanded, s: &Source, roots: &[PathBuf], stack: &mut Vec<PathBuf>, first: bool) -> Result<(), CheckError> {
    const DEPTH: usize = 64;
    let path = std::fs::canonicalize(&s.name).unwrap_or_else(|_| PathBuf::from(&s.name));
    if s.text.lines().any(|l| directive(l, "pragma") && l.split_whitespace().any(|w| w == "once")) {
        if x.once.contains(&path) {
            return Ok(());
        }
        x.once.push(path.clone());
    }
    if stack.len() >= DEPTH {
        return Err(CheckError::Input(format!("{}: includes nest deeper than {DEPTH} files: {}", s.name, stack.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(" -> "))));
    }
    stack.push(path);
    let file = x.files.len();
    x.files.push(s.name.clone());
    x.texts.push(s.text.clone());
    let mut versioned = false;
    for (i, line) in s.text.lines().enumerate() {
        let at = At { file, line: i as u32 + 1 };
        if directive(line, "version") {
            // one #version, first in the unit: the first file's (as 450 where naga reads no other)
            let kept = first && !versioned && ["440", "450", "460"].iter().any(|v| line.split_whitespace().any(|w| w == *v || w == format!("version{v}")));
            x.push(if kept { line } else if first && !versioned { "#version 450" } else { "" }, at);
            versioned = true;
            continue;
        }
        if let Some((text, uniforms)) = gl_uniforms::rewrite(line) {
            x.push(&text, at);
            x.uniforms.extend(uniforms.into_iter().map(|u| (u, at)));
            continue;
        }
        let Some((name, quoted)) = include(line) else {
            x.push(if directive(line, "pragma") { "" } else { line }, at);
            continue;
        };
        let here = Path::new(&s.name).parent().unwrap_or(Path::new("."));
        let candidates: Vec<PathBuf> = quoted.then(|| here.join(name)).into_iter().chain(roots.iter().map(|r| r.join(name))).collect();
        let Some(found) = candidates.iter().find(|p| p.is_file()) else {
            let searched: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
            let what = format!("#include \"{name}\": no such file ({} searched); give the folder that holds it with ", searched.join(", "));
            x.missing.push((x.lines.len(), Message::text(what).setting(Setting::ShaderRoot)));
            x.push("#error lobes: include not found", at);
            continue;
        };
        let canonical = std::fs::canonicalize(found).unwrap_or_else(|_| found.clone());
        if stack.contains(&canonical) {
            x.push("", at);
            continue;
        }
        let text = std::fs::read_to_string(found).map_err(|e| CheckError::Input(format!("{}:{}: #include \"{name}\": cannot read {}: {e}", s.name, i + 1, found.display())))?;
        // the include line itself stays a (blank) line of the including file
        x.push("", at);
        expand(x, &Source { name: found.display().to_string(), text }, roots, stack, false)?;
    }
    stack.pop();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn include_lines() {
        assert_eq!(include("#include \"common/rng.glsl\" // the RNG"), Some(("common/rng.glsl", true)));
        assert_eq!(include("  #  include <lights.glsl>"), Some(("lights.glsl", false)));
        assert_eq!(include("#included"), None);
        assert_eq!(include("// #include \"x\""), None);
    }

    #[test]
    fn glsl_is_told_by_extension_or_version() {
        let s = |name: &str, text: &str| Source { name: name.into(), text: text.into() };
        assert!(is_glsl(&s("a.frag", "void main() {}")));
        assert!(is_glsl(&s("a.txt", "#version 450\nvoid main() {}")));
        assert!(!is_glsl(&s("a.wgsl", "fn f() {}")));
    }
}

#[cfg(test)]
mod translation_tests {
    use super::*;

    /// The fixture's sampler, its includes expanded, translates to WGSL that naga reads back,
    /// with the GLSL functions under their own names.
    #[test]
    fn the_fixture_translates_to_wgsl_that_parses() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/repository/glsl");
        let sources = vec![Source::read(&dir.join("shaders/ggx.glsl")).unwrap()];
        let c = Composition::default().shader_root(dir.join("common"));
        let t = translate(&sources, &c).unwrap();
        if let Err(e) = naga::front::wgsl::parse_str(&t.text) {
            panic!("{}\n{}", e.emit_to_string(&t.text), t.text);
        }
        for f in ["fn rand(", "fn GgxD(", "fn GgxReflectionPdf(", "fn SampleGgxH(", "fn SampleGgxReflection("] {
            assert!(t.text.contains(f), "{f}\n{}", t.text);
        }
    }
}

#[cfg(test)]
mod name_tests {
    use super::*;

    /// A GLSL function named as a WGSL built-in and an overloaded one: written under other
    /// names, which call expressions reach by the GLSL names (an overload is refused).
    #[test]
    fn names_wgsl_cannot_spell_are_mapped() {
        let text = "#version 450\nfloat saturate(float x) { return clamp(x, 0.0, 1.0); }\nfloat sqr(float x) { return x * x; }\nvec3 sqr(vec3 x) { return x * x; }\n";
        let t = translate(&[Source { name: "n.glsl".into(), text: text.into() }], &Composition::default()).unwrap();
        naga::front::wgsl::parse_str(&t.text).unwrap();
        let call = super::super::translate::call_names(Call::Pdf, "saturate(p0) * d.z", &t.origins).unwrap();
        assert!(call.starts_with("saturate_(") && t.text.contains("fn saturate_("), "{call}\n{}", t.text);
        let e = super::super::translate::call_names(Call::Pdf, "sqr(p0)", &t.origins).unwrap_err().to_string();
        assert!(e.contains("`sqr` is overloaded"), "{e}");
    }
}
