//! Messages that name settings of a check, as the advice in an error does ("add its folder with
//! --shader-root"): the command line names a setting by its flag, a scene by its key, so the
//! message holds the [`Setting`] and whoever shows it names it.

use super::resources;

/// Text and settings in turn.
///
/// ```
/// use lobes::check::{Message, Setting};
/// let m = Message::text("add its folder with ").setting(Setting::ShaderRoot);
/// assert_eq!(m.render(&|s| format!("--{}", s.key().replace('_', "-"))), "add its folder with --shader-root");
/// assert_eq!(m.to_string(), "add its folder with shader_root");
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Message(Vec<Piece>);

#[derive(Debug, Clone, PartialEq, Eq)]
enum Piece {
    Text(String),
    Setting(Setting),
}

impl Message {
    /// `text` alone.
    pub fn text(text: impl Into<String>) -> Self {
        Message(vec![Piece::Text(text.into())])
    }

    /// The message, then `setting`'s name.
    pub fn setting(mut self, setting: Setting) -> Self {
        self.0.push(Piece::Setting(setting));
        self
    }

    /// The message, then `text`.
    pub fn then(mut self, text: impl Into<String>) -> Self {
        self.0.push(Piece::Text(text.into()));
        self
    }

    /// The message, then `other`.
    pub fn append(mut self, other: Message) -> Self {
        self.0.extend(other.0);
        self
    }

    /// Whether it names a setting.
    pub fn names_settings(&self) -> bool {
        self.0.iter().any(|p| matches!(p, Piece::Setting(_)))
    }

    /// The text with each setting named by `name`.
    pub fn render(&self, name: &dyn Fn(Setting) -> String) -> String {
        self.0
            .iter()
            .map(|p| match p {
                Piece::Text(t) => t.clone(),
                Piece::Setting(s) => name(*s),
            })
            .collect()
    }
}

impl std::fmt::Display for Message {
    /// Each setting by its key ([`Setting::key`]).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.render(&|s| s.key().to_string()))
    }
}

/// A field of [`super::Settings`], of a sampler's [`super::Composition`] or one of its call expressions
/// ([`super::composition::Call`]), as errors name it: the command line by its flag, a scene by its key
/// ([`Setting::key`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    Params,
    IncidentTheta,
    IncidentPhi,
    Samples,
    Timeout,
    Bins,
    Significance,
    ShaderRoot,
    Define,
    Stub,
    Package,
    RandOrder,
    Sample,
    Pdf,
    Eval,
    Normal,
    Incident,
    ReflectionOnly,
    Measure,
    Frame,
    Bounds,
    SampleReturns,
    Rand,
    Texture,
    Buffer,
    Filter,
    Budget,
}

impl Setting {
    /// Its name as a field and as a scene's key: `incident_theta`.
    pub fn key(self) -> &'static str {
        match self {
            Setting::Params => "params",
            Setting::IncidentTheta => "incident_theta",
            Setting::IncidentPhi => "incident_phi",
            Setting::Samples => "samples",
            Setting::Timeout => "timeout",
            Setting::Bins => "bins",
            Setting::Significance => "significance",
            Setting::ShaderRoot => "shader_root",
            Setting::Define => "define",
            Setting::Stub => "stub",
            Setting::Package => "package",
            Setting::RandOrder => "rand_order",
            Setting::Sample => "sample",
            Setting::Pdf => "pdf",
            Setting::Eval => "eval",
            Setting::Normal => "normal",
            Setting::Incident => "incident",
            Setting::ReflectionOnly => "reflection_only",
            Setting::Measure => "measure",
            Setting::Frame => "frame",
            Setting::Bounds => "bounds",
            Setting::SampleReturns => "sample_returns",
            Setting::Rand => "rand",
            Setting::Texture => "texture",
            Setting::Buffer => "buffer",
            Setting::Filter => "filter",
            Setting::Budget => "budget",
        }
    }
}

impl From<resources::ResourceKind> for Setting {
    fn from(kind: resources::ResourceKind) -> Self {
        match kind {
            resources::ResourceKind::Texture => Setting::Texture,
            resources::ResourceKind::Buffer => Setting::Buffer,
            resources::ResourceKind::Sampler => Setting::Filter,
        }
    }
}
