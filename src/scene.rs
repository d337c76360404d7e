//! Scene files: a TOML list of cases, each one lobe (or discrete distribution) to sample,
//! histogram and judge. Errors name the file, line and column and what is allowed.
//!
//! ```toml
//! [defaults]            # optional; every case may override these
//! samples = 10_000_000
//! bins = [64, 128]      # rows over cos θ, columns over φ
//! seed = 1
//!
//! [[case]]
//! name = "ggx-vndf"
//! lobe = "ggx"          # ward | beckmann | ggx | discrete
//! method = "vndf"       # ndf | vndf | bounded (lobes); cdf | alias (discrete)
//! alpha = 0.2           # or alpha_x and alpha_y
//! incident_theta = 45.0 # degrees from the normal, [0, 90)
//! incident_phi = 0.0    # degrees
//! ```

use crate::job::{DiscreteMethod, Job};
use crate::reference::discrete::Distribution;
use crate::reference::{Lobe, LobeKind, Method, reflect};
use crate::stats::histogram::SphereGrid;
use serde::Deserialize;
use std::collections::HashSet;
use std::ops::Range;
use toml::Spanned;

/// The scene `lobes run` uses when no file is given: every lobe and method.
pub const DEFAULT_SCENE: &str = include_str!("../scenes/all-lobes.toml");
/// The tutorial's examples as a scene.
pub const TUTORIAL_SCENE: &str = include_str!("../scenes/tutorial.toml");

/// The largest sample count a case may ask for (2^40; counts are exact far beyond it).
pub const MAX_SAMPLES: u64 = 1 << 40;

/// A scene error with its location.
#[derive(Debug, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct SceneError {
    pub file: String,
    pub line: usize,
    pub column: usize,
    pub message: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    #[serde(default)]
    defaults: RawDefaults,
    #[serde(default)]
    case: Vec<Spanned<RawCase>>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDefaults {
    samples: Option<Spanned<u64>>,
    bins: Option<Spanned<[u32; 2]>>,
    seed: Option<u64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCase {
    name: Spanned<String>,
    lobe: Spanned<String>,
    method: Option<Spanned<String>>,
    alpha: Option<Spanned<f64>>,
    alpha_x: Option<Spanned<f64>>,
    alpha_y: Option<Spanned<f64>>,
    incident_theta: Option<Spanned<f64>>,
    incident_phi: Option<Spanned<f64>>,
    weights: Option<Spanned<Vec<f64>>>,
    samples: Option<Spanned<u64>>,
    bins: Option<Spanned<[u32; 2]>>,
    seed: Option<u64>,
}

/// One validated case.
#[derive(Debug, Clone)]
pub struct Case {
    pub name: String,
    pub job: Job,
    pub samples: u64,
    pub seed: u64,
    /// Incident angles in degrees (lobes).
    pub incident_deg: (f64, f64),
}

/// A validated scene.
#[derive(Debug, Clone)]
pub struct Scene {
    pub cases: Vec<Case>,
}

struct Ctx<'a> {
    file: &'a str,
    text: &'a str,
}

impl Ctx<'_> {
    fn err(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        let before = &self.text[..span.start.min(self.text.len())];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        SceneError { file: self.file.to_string(), line, column, message: message.into() }
    }
}

impl Scene {
    /// Parses and validates a scene; `file` names it in errors.
    pub fn parse(file: &str, text: &str) -> Result<Scene, SceneError> {
        let ctx = Ctx { file, text };
        let raw: RawScene = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            ctx.err(span, e.message().trim().to_string())
        })?;
        if raw.case.is_empty() {
            return Err(ctx.err(0..0, "the scene has no [[case]] tables; add at least one"));
        }
        let mut names = HashSet::new();
        let mut cases = Vec::new();
        for c in &raw.case {
            let case = validate_case(&ctx, c.get_ref(), &raw.defaults)?;
            if !names.insert(case.name.clone()) {
                return Err(ctx.err(c.get_ref().name.span(), format!("duplicate case name '{}'; names must be unique", case.name)));
            }
            cases.push(case);
        }
        Ok(Scene { cases })
    }
}

fn finite_in(ctx: &Ctx, v: &Spanned<f64>, what: &str, ok: impl Fn(f64) -> bool, allowed: &str) -> Result<f64, SceneError> {
    let x = *v.get_ref();
    if !x.is_finite() || !ok(x) {
        return Err(ctx.err(v.span(), format!("{what} = {x} is not allowed; {allowed}")));
    }
    Ok(x)
}

fn validate_case(ctx: &Ctx, c: &RawCase, d: &RawDefaults) -> Result<Case, SceneError> {
    let name = c.name.get_ref().clone();
    if name.is_empty() || !name.chars().all(|ch| ch.is_ascii_alphanumeric() || "-_.".contains(ch)) {
        return Err(ctx.err(c.name.span(), format!("case name '{name}' must be non-empty and use only letters, digits, '-', '_' and '.' (it names a folder)")));
    }
    let samples_s = c.samples.as_ref().or(d.samples.as_ref());
    let samples = samples_s.map_or(10_000_000, |s| *s.get_ref());
    if samples == 0 || samples > MAX_SAMPLES {
        let span = samples_s.map_or(c.name.span(), |s| s.span());
        return Err(ctx.err(span, format!("samples = {samples} is not allowed; give 1 to {MAX_SAMPLES}")));
    }
    let seed = c.seed.or(d.seed).unwrap_or(1);
    let method_name = c.method.as_ref().map(|m| m.get_ref().as_str());
    let method_span = c.method.as_ref().map_or(c.lobe.span(), |m| m.span());
    let lobe_name = c.lobe.get_ref().as_str();
    if lobe_name == "discrete" {
        let method = match method_name.unwrap_or("cdf") {
            "cdf" => DiscreteMethod::Cdf,
            "alias" => DiscreteMethod::Alias,
            other => return Err(ctx.err(method_span, format!("method '{other}' is not a discrete method; use cdf or alias"))),
        };
        let Some(w) = &c.weights else {
            return Err(ctx.err(c.lobe.span(), "a discrete case needs weights = [w0, w1, ...]"));
        };
        let dist = Distribution::new(w.get_ref()).map_err(|e| ctx.err(w.span(), format!("weights: {e}")))?;
        return Ok(Case { name, job: Job::Discrete { dist, method }, samples, seed, incident_deg: (0.0, 0.0) });
    }
    let kind = match lobe_name {
        "ward" => LobeKind::Ward,
        "beckmann" => LobeKind::Beckmann,
        "ggx" => LobeKind::Ggx,
        other => return Err(ctx.err(c.lobe.span(), format!("lobe '{other}' is unknown; use ward, beckmann, ggx or discrete"))),
    };
    let method = match method_name.unwrap_or("ndf") {
        "ndf" => Method::Ndf,
        "vndf" => Method::Vndf,
        "bounded" => Method::Bounded,
        other => return Err(ctx.err(method_span, format!("method '{other}' is unknown; use ndf, vndf or bounded"))),
    };
    if !kind.supports(method) {
        return Err(ctx.err(method_span, format!("{} has no '{}' sampler; ward: ndf; beckmann: ndf, vndf; ggx: ndf, vndf, bounded", kind.name(), method.name())));
    }
    if c.weights.is_some() {
        return Err(ctx.err(c.weights.as_ref().unwrap().span(), "weights only apply to lobe = \"discrete\""));
    }
    let positive = |v: &Spanned<f64>, what| finite_in(ctx, v, what, |x| x > 0.0, "roughness must be finite and > 0");
    let (ax, ay) = match (&c.alpha, &c.alpha_x, &c.alpha_y) {
        (Some(a), None, None) => {
            let a = positive(a, "alpha")?;
            (a, a)
        }
        (None, Some(x), Some(y)) => (positive(x, "alpha_x")?, positive(y, "alpha_y")?),
        (Some(a), _, _) => return Err(ctx.err(a.span(), "give either alpha or both alpha_x and alpha_y, not both")),
        _ => return Err(ctx.err(c.lobe.span(), "a lobe case needs alpha, or both alpha_x and alpha_y")),
    };
    let theta = match &c.incident_theta {
        Some(t) => finite_in(ctx, t, "incident_theta", |x| (0.0..90.0).contains(&x), "incident_theta is in degrees from the normal, 0 ≤ θ < 90")?,
        None => 0.0,
    };
    let phi = match &c.incident_phi {
        Some(p) => finite_in(ctx, p, "incident_phi", |x| (-360.0..=360.0).contains(&x), "incident_phi is in degrees, −360 to 360")?,
        None => 0.0,
    };
    let bins_s = c.bins.as_ref().or(d.bins.as_ref());
    let [rows, cols] = bins_s.map_or([64, 128], |b| *b.get_ref());
    if rows == 0 || cols == 0 || rows % 2 == 1 || (rows as u64 * cols as u64) > (1 << 24) {
        let span = bins_s.map_or(c.name.span(), |b| b.span());
        return Err(ctx.err(span, format!("bins = [{rows}, {cols}] is not allowed; rows must be even (the horizon is a row edge), both ≥ 1, rows × cols ≤ 2^24")));
    }
    let incident = reflect::spherical(theta.to_radians(), phi.to_radians());
    let lobe = Lobe { kind, method, alpha_x: ax, alpha_y: ay };
    Ok(Case { name, job: Job::Lobe { lobe, incident, grid: SphereGrid { rows, cols } }, samples, seed, incident_deg: (theta, phi) })
}
