//! A user's WGSL sampler, checked against the contract and composed with lobes' passes.
//!
//! The composition (`gpu::compose`) holds lobes' own files (the RNG and the passes, naga_oil
//! modules), the user's files in the order given, and a small generated file that calls the
//! user's functions under fixed names (`lobes_user_sample`, `lobes_user_pdf`,
//! `lobes_user_eval`). Every part's first line in the composed text is remembered, so that a
//! naga diagnostic anywhere maps back to `file:line:column` of the part it came from.

use super::CheckError;
use naga::{ScalarKind, TypeInner, VectorSize};

/// One WGSL source: its name as shown in messages (usually the path) and its text.
#[derive(Debug, Clone, PartialEq)]
pub struct Source {
    pub name: String,
    pub text: String,
}

impl Source {
    /// Reads a WGSL file, naming it by its path.
    pub fn read(path: &std::path::Path) -> Result<Self, CheckError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| CheckError::Input(format!("{}: cannot read the WGSL file: {e}", path.display())))?;
        Ok(Self { name: path.display().to_string(), text })
    }
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

/// Composed text with the first line of each part, for mapping diagnostics back.
#[derive(Debug, Clone, Default)]
pub struct Composed {
    pub text: String,
    /// (first line, 1-based, of the part in `text`; the part's name).
    parts: Vec<(u32, String)>,
}

impl Composed {
    pub fn push(&mut self, name: &str, text: &str) {
        let line = self.text.lines().count() as u32 + 1;
        self.parts.push((line, name.to_string()));
        self.text.push_str(text);
        if !text.ends_with('\n') {
            self.text.push('\n');
        }
    }

    /// `file:line:column` of a composed line and column.
    pub fn locate(&self, line: u32, column: u32) -> String {
        match self.parts.iter().rev().find(|(first, _)| *first <= line) {
            Some((first, name)) => format!("{name}:{}:{column}", line - first + 1),
            None => format!("<composed>:{line}:{column}"),
        }
    }

    /// The source line at a composed line number.
    fn line(&self, line: u32) -> &str {
        self.text.lines().nth(line as usize - 1).unwrap_or("")
    }

    /// A diagnostic at `span`: "file:line:col: error: message", the offending line and a caret.
    fn diagnostic(&self, span: Option<naga::SourceLocation>, message: &str, labels: &[String]) -> String {
        let mut out = match span {
            Some(loc) => {
                let at = self.locate(loc.line_number, loc.line_position);
                let src = self.line(loc.line_number);
                let caret = " ".repeat(loc.line_position.saturating_sub(1) as usize) + &"^".repeat((loc.length as usize).clamp(1, 60));
                format!("{at}: {message}\n    {src}\n    {caret}")
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
pub(super) fn check_user(sources: &[Source], functions: &[(&str, Signature)]) -> Result<naga::Module, CheckError> {
    if sources.is_empty() {
        return Err(CheckError::Input("no WGSL file given: name at least one file that defines the sampler".into()));
    }
    let mut composed = Composed::default();
    for s in sources {
        composed.push(&s.name, &s.text);
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
