//! How a user's sampler is composed and called: the settings beyond the contract's three
//! functions ([`Composition`], [`Draw`], [`SampleReturns`]), the dialect of its files
//! ([`Dialect`]; `dialect::sniff` tells it), and the composed code that lobes' glue calls
//! (`UserCode`). The vocabulary that `modules` (which composes), `dialect` (the front ends) and
//! `gpu` (the glue) share.

use super::compose::Source;
use super::{CheckError, Setting};
use super::resources::{Filter, Resource, ResourceError, ResourceKind};
use std::path::PathBuf;

/// How lobes finds and calls a sampler beyond the contract's three functions (issue 23 §1–2).
///
/// ```
/// use lobes::check::{Composition, Draw, SampleReturns};
/// let c = Composition::default()
///     .shader_root("shaders")
///     .define("MULTISCATTER", None)
///     .stub("renderer::bindings", "tests/stub_bindings.wgsl")
///     .rand("rand_f")
///     .rand_order(&[Draw::Event, Draw::X, Draw::Y]);
/// assert_eq!(c.shader_roots.len(), 1);
/// assert_eq!(c.sample_returns, SampleReturns::Direction);
/// assert_eq!(lobes::check::Draw::parse_list("event,x,y").unwrap(), vec![Draw::Event, Draw::X, Draw::Y]);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Composition {
    /// Where modules are found (`--shader-root`, repeatable); none: the first file's folder.
    pub shader_roots: Vec<PathBuf>,
    /// Shader defs (`--define NAME[=VALUE]`): naga_oil's `#ifdef`/`#if`, WESL's `@if` features.
    pub defines: Vec<(String, Option<String>)>,
    /// Stand-ins for modules the test does not need (`--stub MODULE=FILE`): bind groups, scene
    /// bindings, ray queries.
    pub stubs: Vec<(String, PathBuf)>,
    /// Where another WESL package's modules are (`--package NAME=DIR`): `NAME::a::b` is
    /// `DIR/a/b.wesl` (or `.wgsl`). A package not named here is looked for under the shader roots
    /// without its name (`NAME::a::b` as `a/b.wesl`).
    pub packages: Vec<(String, PathBuf)>,
    /// The user's random functions (`--rand NAME`): their bodies are replaced by lobes' queue of
    /// u.x, u.y, u.z, u.w in call order.
    pub rand: Vec<String>,
    /// Which draw takes which uniform (`--rand-order`); `None`: found by lobes' probe.
    pub rand_order: Option<Vec<Draw>>,
    /// What the sample expression returns (`--sample-returns`).
    pub sample_returns: SampleReturns,
    /// The light's unit normal at the sampled point `p` (`--normal`, with `--measure area`): a
    /// WGSL expression over `p`, `params` and `p0` … `p15`.
    pub normal: Option<String>,
    /// The renderer's textures and tables, by the name the sampler's files declare them with
    /// (`--texture NAME=FILE`, `--buffer NAME=FILE`; [`super::resources`]).
    pub resources: Vec<(String, Resource)>,
}

impl Composition {
    pub fn shader_root(mut self, dir: impl Into<PathBuf>) -> Self {
        self.shader_roots.push(dir.into());
        self
    }
    pub fn define(mut self, name: &str, value: Option<&str>) -> Self {
        self.defines.push((name.into(), value.map(Into::into)));
        self
    }
    pub fn stub(mut self, module: &str, file: impl Into<PathBuf>) -> Self {
        self.stubs.push((module.into(), file.into()));
        self
    }
    /// A `.hdr` image bound as the sampler's `name: texture_2d<f32>` (`--texture NAME=FILE`).
    pub fn texture(mut self, name: &str, file: impl Into<PathBuf>) -> Self {
        self.resources.push((name.into(), Resource::Texture(file.into())));
        self
    }
    /// A `.npy` table bound as the sampler's `var<storage, read> name: array<…>` (`--buffer
    /// NAME=FILE`).
    pub fn buffer(mut self, name: &str, file: impl Into<PathBuf>) -> Self {
        self.resources.push((name.into(), Resource::Buffer(file.into())));
        self
    }
    /// A sampler bound as the sampler's `name: sampler` (`--sampler NAME=linear|nearest`).
    pub fn sampler(mut self, name: &str, filter: Filter) -> Self {
        self.resources.push((name.into(), Resource::Sampler(filter)));
        self
    }
    /// Resource items, each NAME=FILE (a texture, a buffer) or NAME=linear|nearest (a sampler);
    /// each NAME bound once.
    pub fn parse_resources(items: &[(ResourceKind, String)]) -> Result<Vec<(String, Resource)>, ResourceError> {
        let mut out: Vec<(String, Resource)> = Vec::new();
        for (kind, item) in items {
            let (name, resource) = parse_resource(*kind, item).map_err(|message| ResourceError { kind: *kind, message })?;
            if out.iter().any(|(n, _)| n == name) {
                return Err(ResourceError { kind: *kind, message: format!("'{item}': {name} is bound twice") });
            }
            out.push((name.to_string(), resource));
        }
        Ok(out)
    }
    /// Another WESL package's folder: `NAME::a::b` is `dir/a/b.wesl` (`--package NAME=DIR`).
    pub fn package(mut self, name: &str, dir: impl Into<PathBuf>) -> Self {
        self.packages.push((name.into(), dir.into()));
        self
    }
    pub fn rand(mut self, name: &str) -> Self {
        self.rand.push(name.into());
        self
    }
    pub fn rand_order(mut self, order: &[Draw]) -> Self {
        self.rand_order = Some(order.to_vec());
        self
    }
    pub fn sample_returns(mut self, r: SampleReturns) -> Self {
        self.sample_returns = r;
        self
    }
    /// The light's normal at `p` of a sampler that samples a light's area (`--normal`).
    pub fn normal(mut self, expr: &str) -> Self {
        self.normal = Some(expr.into());
        self
    }
    /// What the front ends assume of the settings, checked once before any of them reads a
    /// file: shader defs are names, a module has one stand-in, an order of the draws orders
    /// named random functions, the shader roots and the packages' folders are folders, a package
    /// is named once. The error is keyed by the [`Setting`]: the command line names its flag, a
    /// scene its key.
    ///
    /// ```
    /// use lobes::check::{CheckError, Composition, Setting};
    /// let e = Composition::default().define("TWO WORDS", None).validate().unwrap_err();
    /// assert!(matches!(e, CheckError::Setting { setting: Setting::Define, .. }));
    /// ```
    pub fn validate(&self) -> Result<(), CheckError> {
        let bad = |setting, message: String| Err(CheckError::setting(setting, message));
        if let Some((n, _)) = self.defines.iter().find(|(n, _)| !is_name(n)) {
            return bad(Setting::Define, format!("'{n}' is no shader def: a def is a name (letters, digits, _) with a value or none, as UNIFORM_HEMISPHERE or SAMPLES=4"));
        }
        if let Some((m, _)) = self.stubs.iter().enumerate().find(|(i, (m, _))| self.stubs[..*i].iter().any(|(n, _)| n == m)).map(|(_, s)| s) {
            return bad(Setting::Stub, format!("{m} is given twice; one module has one stand-in"));
        }
        if self.rand_order.is_some() && self.rand.is_empty() {
            return bad(Setting::RandOrder, "an order for the draws of the named random functions, and no random function is named".into());
        }
        if let Some(r) = self.shader_roots.iter().find(|r| !r.is_dir()) {
            return bad(Setting::ShaderRoot, format!("{} is not a folder", r.display()));
        }
        for (i, (name, dir)) in self.packages.iter().enumerate() {
            check_package(name, &self.packages[..i]).map_err(|message| CheckError::setting(Setting::Package, message))?;
            if !dir.is_dir() {
                return bad(Setting::Package, format!("{name}={}: not a folder; give the folder that holds {name}'s modules ({name}::a::b is DIR/a/b.wesl)", dir.display()));
            }
        }
        Ok(())
    }

    /// Package items, each NAME=DIR (`--package`, a scene's `package`): NAME a WESL package name,
    /// each at most once. The error quotes the item; its caller names the flag or key.
    pub fn parse_packages(items: &[String]) -> Result<Vec<(String, PathBuf)>, String> {
        let mut out: Vec<(String, PathBuf)> = Vec::new();
        for f in items {
            let Some((name, dir)) = f.split_once('=').map(|(n, d)| (n.trim(), d.trim())).filter(|(n, d)| !n.is_empty() && !d.is_empty()) else {
                return Err(format!("'{f}': give NAME=DIR, e.g. bevy_render=crates/bevy_render/src (then bevy_render::maths is DIR/maths.wesl)"));
            };
            check_package(name, &out)?;
            out.push((name.to_string(), PathBuf::from(dir)));
        }
        Ok(out)
    }
}

/// A package's name: an identifier, not `package` (the sampler's own root), given once. The
/// error quotes the name; its caller names the flag or key.
pub(super) fn check_package(name: &str, given: &[(String, PathBuf)]) -> Result<(), String> {
    if !is_name(name) || name == "package" || name == "super" {
        return Err(format!("'{name}': a package name is an identifier other than package and super (WESL's own path starts), as an import names it: bevy_render in `import bevy_render::maths::PI;`"));
    }
    if given.iter().any(|(n, _)| n == name) {
        return Err(format!("'{name}': given twice; one package has one folder"));
    }
    Ok(())
}

/// A call expression of a sampler: which of its functions it stands for, and so the names it
/// is written over (`wi` and `u` for the sample, `d` for the densities, `p` for a light's normal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Call {
    Sample,
    Pdf,
    Eval,
    Normal,
}

impl Call {
    /// The setting that gives it (the command line names its flag, a scene its key).
    pub fn setting(self) -> Setting {
        match self {
            Call::Sample => Setting::Sample,
            Call::Pdf => Setting::Pdf,
            Call::Eval => Setting::Eval,
            Call::Normal => Setting::Normal,
        }
    }

    /// The error `why` of its expression `expr`, keyed by its setting.
    pub fn error(self, expr: &str, why: impl std::fmt::Display) -> CheckError {
        CheckError::setting(self.setting(), format!("'{expr}': {why}"))
    }

    /// The error of its expression `expr` whose value has the wrong type: `'{expr}' returns
    /// {what}`, keyed by its setting.
    pub fn returns(self, expr: &str, what: impl std::fmt::Display) -> CheckError {
        CheckError::setting(self.setting(), format!("'{expr}' returns {what}"))
    }
}

/// What a sample expression's result means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SampleReturns {
    /// The sampled direction d (vec3) or (d, pdf) (vec4).
    #[default]
    Direction,
    /// A half vector h (vec3) or (h, pdf of h) (vec4): lobes reflects wi about h, d = 2 (wi·h) h − wi,
    /// and divides the pdf of h by the reflection's Jacobian 4 |wi·h| (Walter et al. 2007, eq. 14).
    HalfVector,
}

/// What one random draw of the user's sampler decides (`--rand-order`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Draw {
    /// The first coordinate that moves the direction smoothly: u.x.
    X,
    /// The second: u.y.
    Y,
    /// A draw that chooses an event (a lobe of a mixture): u.z, the next one u.w. lobes' Jacobian
    /// check differentiates in u.x and u.y and measures events' shares along u.z and u.w.
    Event,
}

impl Draw {
    /// `event,x,y`: at most one x, one y and two events.
    pub fn parse_list(s: &str) -> Result<Vec<Draw>, String> {
        let allowed = "a comma-separated list of x, y and event (at most one x, one y, two events), e.g. event,x,y";
        let draws = s
            .split(',')
            .map(|w| match w.trim() {
                "x" => Ok(Draw::X),
                "y" => Ok(Draw::Y),
                "event" => Ok(Draw::Event),
                other => Err(format!("'{other}' is not a draw; give {allowed}")),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let count = |d| draws.iter().filter(|&&x| x == d).count();
        if count(Draw::X) > 1 || count(Draw::Y) > 1 || count(Draw::Event) > 2 {
            return Err(format!("'{s}' gives u.x, u.y or u.z/u.w twice; give {allowed}"));
        }
        Ok(draws)
    }

    /// The component of u each draw takes, in call order; draws past the list take the
    /// components left, in the order x, y, z, w.
    pub fn components(order: &[Draw]) -> [u32; 4] {
        let mut out = Vec::new();
        let mut events = [2u32, 3].into_iter();
        for d in order {
            out.push(match d {
                Draw::X => 0,
                Draw::Y => 1,
                Draw::Event => events.next().expect("at most two events (parse_list)"),
            });
        }
        for c in 0..4 {
            if !out.contains(&c) {
                out.push(c);
            }
        }
        [out[0], out[1], out[2], out[3]]
    }

    /// The order as written: `event,x,y`.
    pub fn list(components: &[u32; 4], draws: usize) -> String {
        let names: Vec<&str> = components.iter().take(draws).map(|c| match c {
            0 => "x",
            1 => "y",
            _ => "event",
        }).collect();
        names.join(",")
    }
}

/// The way the files compose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    /// Plain WGSL files, concatenated in order.
    Wgsl,
    /// naga_oil's `#import` / `#define_import_path` / shader defs.
    NagaOil,
    /// WESL's `import package::…;`.
    Wesl,
    /// GLSL, translated by naga ([`super::dialect::glsl`]).
    Glsl,
    /// A SPIR-V module, translated by naga ([`super::dialect::spirv`]).
    Spirv,
}

impl Dialect {
    pub fn name(self) -> &'static str {
        match self {
            Dialect::Wgsl => "WGSL",
            Dialect::NagaOil => "naga_oil",
            Dialect::Wesl => "WESL",
            Dialect::Glsl => "GLSL",
            Dialect::Spirv => "SPIR-V",
        }
    }
}

/// Whether `s` names a function (with the contract's signature) rather than being a call
/// expression over lobes' names.
pub(super) fn is_name(s: &str) -> bool {
    let mut c = s.trim().chars();
    c.next().is_some_and(|f| f.is_ascii_alphabetic() || f == '_') && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

/// An item of an imported module: (its name in the composed text, the module path, its name in
/// that module).
pub(super) type Origin = (String, String, String);

/// The user's code before lobes' glue: the parts of its text, and where names from other modules
/// came from.
#[derive(Debug, Clone)]
pub(super) struct UserCode {
    pub dialect: Dialect,
    /// The files as they are (plain WGSL), or one part: the composed tree.
    pub parts: Vec<Source>,
    /// Where the items of imported modules came from.
    pub origins: Vec<Origin>,
    /// The files the tree was read from (for messages).
    pub files: Vec<String>,
    /// Where the declarations of a WESL tree came from (the wesl crate writes the tree anew).
    pub decls: Vec<super::compose::DeclOrigin>,
    /// The functions naga's WGSL writer renamed in `parts` (`würfel` → `wrfel`, `rand_` → `rand`).
    pub renamed: Renamed,
    /// OpenGL's loose uniforms that a GLSL translation made module variables (0 until set):
    /// each one's name and `file:line`.
    pub uniforms: Vec<(String, String)>,
}

/// (the name naga's WGSL writer gave a function, its name in the module it wrote).
pub(super) type Renamed = Vec<(String, String)>;

impl UserCode {
    /// A tree composed into one part (its name says the sampler's file and `by`, what composed
    /// it: `naga_oil`, `wesl`), without declarations' origins or renamed functions.
    pub(super) fn tree(dialect: Dialect, sources: &[Source], by: &str, text: String, origins: Vec<Origin>) -> Self {
        let part = Source { name: format!("<{} with its modules, composed by {by}>", sources[0].name), text };
        let files = sources.iter().map(|s| s.name.clone()).collect();
        UserCode { dialect, parts: vec![part], origins, files, decls: Vec::new(), renamed: Vec::new(), uniforms: Vec::new() }
    }

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

/// One resource item, NAME=FILE or (a sampler) NAME=FILTER, as the name and what it binds; the
/// message quotes the item, its caller names the kind.
fn parse_resource(kind: ResourceKind, item: &str) -> Result<(&str, Resource), String> {
    let value_form = if kind == ResourceKind::Sampler { "linear or nearest" } else { "FILE" };
    let usage = || format!("'{item}': give NAME={value_form}, NAME the variable the sampler's files declare, e.g. {}", kind.example());
    let (name, value) = item.split_once('=').map(|(n, v)| (n.trim(), v.trim())).filter(|(n, v)| is_name(n) && !v.is_empty()).ok_or_else(usage)?;
    let resource = match kind {
        ResourceKind::Texture => Resource::Texture(value.into()),
        ResourceKind::Buffer => Resource::Buffer(value.into()),
        ResourceKind::Sampler => Resource::Sampler(Filter::parse(value).ok_or_else(|| format!("'{item}': the filter '{value}' is unknown; give linear or nearest (the sampler clamps to the edge)"))?),
    };
    Ok((name, resource))
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn a_sampler_flag_is_a_name_and_a_filter() {
        let items = [(ResourceKind::Texture, "env=sky.hdr".into()), (ResourceKind::Sampler, "lut_sampler=linear".into()), (ResourceKind::Sampler, " s = nearest ".into())];
        let r = Composition::parse_resources(&items).unwrap();
        assert_eq!(r, vec![("env".into(), Resource::Texture("sky.hdr".into())), ("lut_sampler".into(), Resource::Sampler(Filter::Linear)), ("s".into(), Resource::Sampler(Filter::Nearest))]);
    }

    #[test]
    fn a_bad_sampler_flag_says_what_to_give() {
        let bad = |s: &str| Composition::parse_resources(&[(ResourceKind::Sampler, s.into())]).unwrap_err();
        assert_eq!(bad("s=bilinear").kind, ResourceKind::Sampler);
        assert!(bad("s=bilinear").message.contains("'bilinear' is unknown; give linear or nearest"), "{:?}", bad("s=bilinear"));
        assert!(bad("s").message.contains("give NAME=linear or nearest"));
        assert!(bad("1s=linear").message.contains("e.g. lut_sampler=linear"));
        let twice = Composition::parse_resources(&[(ResourceKind::Texture, "s=a.hdr".into()), (ResourceKind::Sampler, "s=linear".into())]).unwrap_err();
        assert!(twice.kind == ResourceKind::Sampler && twice.message.contains("s is bound twice"), "{twice:?}");
    }
}
