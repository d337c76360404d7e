//! Cases of a user's WGSL sampler: `sampler = { wgsl = [...], sample = "...", pdf = "...",
//! eval = "..." }` with `params`, `domain` (and `bounds` on the plane), judged by the checks of
//! `lobes check` ([`crate::check`]). The WGSL files are read relative to the scene file and
//! checked against the contract while the scene is parsed, so that a missing file, function or
//! signature is a [`SceneError`] at the case's `sampler` before any case runs.

use super::raw::{RawCase, RawSampler};
use super::sweep::{Point, Val};
use super::value::{Common, Ctx, Defaults, SceneError, effect_keys, grid, incident_phi, kind_of, number, reject_keys, roughness_keys, string};
use crate::check::budget::Budget;
use crate::check::resources::{Resource, ResourceKind};
use crate::check::{Conventions, DEFAULT_TIMEOUT, Domain, MAX_PARAMS, MAX_TIMEOUT_SECONDS, Settings, UserSampler};
use std::path::Path;
use std::sync::Arc;
use toml::{Spanned, Value};

/// One validated case of a user's sampler: the sampler (shared by the cases of a sweep) and the
/// settings of its check (the significance is the run's, per case).
#[derive(Debug, Clone)]
pub struct UserCase {
    pub name: String,
    pub sampler: Arc<UserSampler>,
    /// `settings.samples` is the case's count, or with a `budget` the count pilot checks pick
    /// when the case runs ([`crate::check::budget::pick`]).
    pub settings: Settings,
    pub budget: Option<Budget>,
}

const SAMPLER_ALLOWED: &str = "write sampler = { light = \"NAME\" } (one of lobes' built-in lights, its geometry in params), or sampler = { wgsl = [\"file.wgsl\", ...], sample = \"fn name or call\", pdf = \"fn name or call\", eval = \"fn name or call\" } (eval optional; also rand = [\"fn\", ...], rand_order = \"event,x,y\", shader_root = [\"dir\", ...], define = { NAME = true }, stub = { \"module\" = \"file\" }, package = { NAME = \"dir\" }, texture = { NAME = \"file.hdr\" }, buffer = { NAME = \"file.npy\" }, filter = { NAME = \"linear\" or \"nearest\" } (a renderer's sampler), sample_returns = \"half-vector\", and the conventions incident = \"upper\", reflection_only = true, u_open = true, measure = \"projected\" or \"area\" (with normal = \"WGSL over p\"), frame = \"y-up\"; paths relative to the scene file)";
const GRID_ALLOWED: &str = "give [rows, cols]: whole numbers ≥ 1, rows × cols ≤ 2^24 (16777216)";
const BOUNDS_ALLOWED: &str = "give bounds = [x0, y0, x1, y1], finite numbers with x0 < x1 and y0 < y1";

/// The sampler of a `[[case]]` table: its files read and checked against the contract.
pub(super) fn sampler(ctx: &Ctx, c: &RawCase, p: &Point, raw: &Spanned<RawSampler>) -> Result<Arc<UserSampler>, SceneError> {
    let not_here = "does not apply to a user sampler (its WGSL is the whole sampler); remove it";
    reject_keys(ctx, &[("lobe", c.lobe.as_ref()), ("method", p.get("method")), ("scatter", p.get("scatter"))], not_here)?;
    reject_keys(ctx, &roughness_keys(p), not_here)?;
    if let Some(w) = &c.weights {
        return Err(ctx.err(w.span(), format!("weights {not_here}")));
    }
    reject_keys(ctx, &effect_keys(c, p), "does not apply to a user sampler (give an eval function for the weight and albedo checks); remove it")?;
    let r = raw.get_ref();
    if let Some(light) = &r.light {
        return builtin_light(ctx, r, light);
    }
    let name = |v: &Option<Val>, key: &str| -> Result<Option<String>, SceneError> {
        v.as_ref().map(|v| string(ctx, v, &format!("sampler.{key}"), SAMPLER_ALLOWED).map(String::from)).transpose()
    };
    let missing = |key: &str| ctx.err(raw.span(), format!("the sampler has no {key}; {SAMPLER_ALLOWED}"));
    let Some(wgsl) = &r.wgsl else { return Err(missing("wgsl")) };
    let sample = name(&r.sample, "sample")?.ok_or_else(|| missing("sample"))?;
    let pdf = name(&r.pdf, "pdf")?.ok_or_else(|| missing("pdf"))?;
    let eval = name(&r.eval, "eval")?;
    let files = match wgsl.get_ref() {
        Value::Array(items) if !items.is_empty() => items
            .iter()
            .map(|i| match i {
                Value::String(s) => Ok(s.as_str()),
                other => Err(ctx.err(wgsl.span(), format!("sampler.wgsl must hold file names (strings), got {}; {SAMPLER_ALLOWED}", kind_of(other)))),
            })
            .collect::<Result<Vec<_>, _>>()?,
        Value::Array(_) => return Err(ctx.err(wgsl.span(), format!("sampler.wgsl is empty; {SAMPLER_ALLOWED}"))),
        other => return Err(ctx.err(wgsl.span(), format!("sampler.wgsl must be an array of file names, got {}; {SAMPLER_ALLOWED}", kind_of(other)))),
    };
    let base = Path::new(ctx.file).parent().unwrap_or(Path::new(""));
    let paths: Vec<_> = files.iter().map(|f| base.join(f)).collect();
    let domain = domain(ctx, c)?;
    let conventions = conventions(ctx, r)?;
    let composition = composition(ctx, r, base)?;
    UserSampler::from_repository(&paths, &sample, &pdf, eval.as_deref(), domain, composition)
        .and_then(|s| s.with_conventions(conventions))
        .map_err(|e| match e {
            crate::check::CheckError::Setting { setting, message } => ctx.err(raw.span(), format!("{}: {message}", scene_key(setting))),
            crate::check::CheckError::Advised(m) => ctx.err(raw.span(), format!("sampler: {}", m.render(&scene_key))),
            e => ctx.err(raw.span(), format!("sampler: {e}")),
        })
        .map(Arc::new)
}

/// A setting as a scene names it: a key of the case (`incident_theta`, `bounds`) or of its
/// `sampler` table (`sampler.measure`).
pub(crate) fn scene_key(setting: crate::check::Setting) -> String {
    use crate::check::Setting::*;
    match setting {
        Params | IncidentTheta | IncidentPhi | Samples | Timeout | Bins | Significance | Bounds | Budget => setting.key().to_string(),
        _ => format!("sampler.{}", setting.key()),
    }
}

/// `sampler = { light = "NAME" }`: lobes' built-in light of that name (the case's `params` its
/// geometry), alone in the table.
fn builtin_light(ctx: &Ctx, r: &RawSampler, light: &Val) -> Result<Arc<UserSampler>, SceneError> {
    use crate::reference::light::registry::{LIGHTS, by_name, names};
    let allowed = format!("sampler.light is one of {} (lobes' built-in lights, their geometry in params)", names());
    let name = string(ctx, light, "sampler.light", &allowed)?;
    let Some(spec) = by_name(name) else {
        let hint = crate::scene::suggest::did_you_mean(name, LIGHTS.iter().map(|l| l.name));
        return Err(ctx.err(light.span(), format!("sampler.light: unknown light '{name}'{hint}; {allowed}")));
    };
    let others = [("wgsl", &r.wgsl), ("sample", &r.sample), ("pdf", &r.pdf), ("eval", &r.eval), ("measure", &r.measure), ("normal", &r.normal), ("rand", &r.rand), ("texture", &r.texture), ("buffer", &r.buffer)];
    if let Some((key, v)) = others.iter().find_map(|(k, v)| v.as_ref().map(|v| (k, v))) {
        return Err(ctx.err(v.span(), format!("sampler.{key} does not apply to a built-in light (light = \"{name}\" is the whole sampler: {}); remove it", spec.layout)));
    }
    Ok(Arc::new(UserSampler::light(spec)))
}

/// `incident = "upper"`, `reflection_only = true`, `u_open = true`, `measure = "projected"`,
/// `frame = "y-up"`: the flags of `lobes check` as keys of `sampler`.
fn conventions(ctx: &Ctx, r: &RawSampler) -> Result<Conventions, SceneError> {
    fn named<T: std::str::FromStr<Err = String>>(ctx: &Ctx, v: &Option<Val>, key: &str, names: &[&str]) -> Result<Option<T>, SceneError> {
        let allowed = format!("sampler.{key} is one of {}", names.join(", "));
        v.as_ref()
            .map(|v| string(ctx, v, &format!("sampler.{key}"), &allowed)?.parse::<T>().map_err(|e| ctx.err(v.span(), format!("sampler.{key}: {e}"))))
            .transpose()
    }
    let flag = |v: &Option<Val>, key: &str| -> Result<bool, SceneError> {
        match v.as_ref().map(|v| (v, v.get_ref())) {
            None => Ok(false),
            Some((_, Value::Boolean(b))) => Ok(*b),
            Some((v, other)) => Err(ctx.err(v.span(), format!("sampler.{key} must be true or false, got {}", kind_of(other)))),
        }
    };
    let d = Conventions::default();
    use crate::check::{Frame, Incident, Measure};
    Ok(Conventions {
        incident: named(ctx, &r.incident, "incident", Incident::NAMES)?.unwrap_or(d.incident),
        reflection_only: flag(&r.reflection_only, "reflection_only")?,
        u_open: flag(&r.u_open, "u_open")?,
        measure: named(ctx, &r.measure, "measure", Measure::NAMES)?.unwrap_or(d.measure),
        frame: named(ctx, &r.frame, "frame", Frame::NAMES)?.unwrap_or(d.frame),
    })
}

/// A list of strings (`rand`, `shader_root`).
fn strings<'v>(ctx: &Ctx, v: &'v Val, key: &str) -> Result<Vec<&'v str>, SceneError> {
    match v.get_ref() {
        Value::Array(items) => items
            .iter()
            .map(|i| match i {
                Value::String(s) => Ok(s.as_str()),
                other => Err(ctx.err(v.span(), format!("sampler.{key} must hold strings, got {}; {SAMPLER_ALLOWED}", kind_of(other)))),
            })
            .collect(),
        other => Err(ctx.err(v.span(), format!("sampler.{key} must be an array of strings, got {}; {SAMPLER_ALLOWED}", kind_of(other)))),
    }
}

/// The keys of a sampler as it is in its repository: rand, rand_order, shader_root, define,
/// stub, package, texture, buffer, filter (`--sampler`), sample_returns, normal (the flags of
/// `lobes check`), paths relative to the scene file.
fn composition(ctx: &Ctx, r: &RawSampler, base: &Path) -> Result<crate::check::Composition, SceneError> {
    use crate::check::{Composition, Draw, SampleReturns};
    let mut c = Composition::default();
    if let Some(v) = &r.rand {
        c.rand = strings(ctx, v, "rand")?.into_iter().map(String::from).collect();
    }
    if let Some(v) = &r.rand_order {
        let o = string(ctx, v, "sampler.rand_order", "write rand_order = \"event,x,y\"")?;
        c.rand_order = Some(Draw::parse_list(o).map_err(|e| ctx.err(v.span(), format!("sampler.rand_order: {e}")))?);
    }
    if let Some(v) = &r.shader_root {
        c.shader_roots = strings(ctx, v, "shader_root")?.into_iter().map(|d| base.join(d)).collect();
    }
    let table = |v: &Val, key: &str| match v.get_ref() {
        Value::Table(t) => Ok(t.clone()),
        other => Err(ctx.err(v.span(), format!("sampler.{key} must be a table, got {}; {SAMPLER_ALLOWED}", kind_of(other)))),
    };
    if let Some(v) = &r.define {
        for (name, value) in table(v, "define")? {
            let value = match value {
                Value::Boolean(true) => None,
                Value::Boolean(false) => Some("false".to_string()),
                Value::Integer(i) => Some(i.to_string()),
                Value::String(s) => Some(s),
                other => return Err(ctx.err(v.span(), format!("sampler.define.{name} must be true, false or an integer, got {}", kind_of(&other)))),
            };
            c.defines.push((name, value));
        }
    }
    // the tables of names to paths: `key = { NAME = "path" }`
    let paths = |v: &Val, key: &str, what: &str| -> Result<Vec<(String, std::path::PathBuf)>, SceneError> {
        let mut out = Vec::new();
        for (name, path) in table(v, key)? {
            let Value::String(p) = path else {
                return Err(ctx.err(v.span(), format!("sampler.{key}.\"{name}\" must be {what} (a string); {SAMPLER_ALLOWED}")));
            };
            out.push((name, base.join(p)));
        }
        Ok(out)
    };
    let flags = |named: &[(String, std::path::PathBuf)]| -> Vec<String> { named.iter().map(|(n, p)| format!("{n}={}", p.display())).collect() };
    if let Some(v) = &r.stub {
        c.stubs = paths(v, "stub", "a file name")?;
    }
    if let Some(v) = &r.package {
        c.packages = paths(v, "package", "a folder name")?;
        Composition::parse_packages(&flags(&c.packages)).map_err(|e| ctx.err(v.span(), format!("sampler.package {e}")))?;
    }
    c.resources = resources(ctx, r, base)?;
    if let Some(v) = &r.sample_returns {
        c.sample_returns = match string(ctx, v, "sampler.sample_returns", "use \"direction\" or \"half-vector\"")? {
            "direction" => SampleReturns::Direction,
            "half-vector" => SampleReturns::HalfVector,
            other => return Err(ctx.err(v.span(), format!("sampler.sample_returns '{other}' is unknown; use \"direction\" or \"half-vector\""))),
        };
    }
    if let Some(v) = &r.normal {
        c.normal = Some(string(ctx, v, "sampler.normal", "write normal = \"WGSL over p\", the light's unit normal at the sampled point (with measure = \"area\")")?.to_string());
    }
    Ok(c)
}

/// `texture = { NAME = "file.hdr" }`, `buffer = { NAME = "file.npy" }` and `filter = { NAME =
/// "linear" }`: the renderer's resources (`--texture`, `--buffer`, `--sampler`), the files
/// relative to `base`.
fn resources(ctx: &Ctx, r: &RawSampler, base: &Path) -> Result<Vec<(String, Resource)>, SceneError> {
    let keyed = [(ResourceKind::Texture, &r.texture), (ResourceKind::Buffer, &r.buffer), (ResourceKind::Sampler, &r.filter)];
    let Some(at) = keyed.iter().find_map(|(_, v)| v.as_ref()).map(|v| v.span()) else { return Ok(Vec::new()) };
    let mut items = Vec::new();
    for (kind, v) in keyed {
        let Some(v) = v else { continue };
        let key = kind.key();
        let Value::Table(t) = v.get_ref() else {
            return Err(ctx.err(v.span(), format!("sampler.{key} must be a table, got {}; {SAMPLER_ALLOWED}", kind_of(v.get_ref()))));
        };
        let what = if kind == ResourceKind::Sampler { "\"linear\" or \"nearest\"" } else { "a file name" };
        for (name, value) in t {
            let Value::String(s) = value else {
                return Err(ctx.err(v.span(), format!("sampler.{key}.\"{name}\" must be {what} (a string); {SAMPLER_ALLOWED}")));
            };
            items.push((kind, if kind == ResourceKind::Sampler { format!("{name}={s}") } else { format!("{name}={}", base.join(s).display()) }));
        }
    }
    crate::check::Composition::parse_resources(&items).map_err(|e| ctx.err(at, format!("sampler.{} {}", e.kind.key(), e.message)))
}

/// `domain` and `bounds`: the sphere unless `domain = "plane"`, which needs `bounds` and has no
/// incident direction, or `domain = "latlong"` or `"equal-area"` (the sphere binned on an
/// environment map's texels).
fn domain(ctx: &Ctx, c: &RawCase) -> Result<Domain, SceneError> {
    let allowed = "use sphere (unit directions), latlong or equal-area (unit directions binned on the texels of a lat-long or an octahedral equal-area map) or plane (points of the box given by bounds)";
    let directions = match &c.domain {
        None => Some(Domain::Sphere),
        Some(v) => match string(ctx, v, "domain", allowed)? {
            "plane" => None,
            name => match Domain::of_directions(name) {
                Some(directions) => Some(directions),
                None => return Err(ctx.err(v.span(), format!("domain '{name}' is unknown; {allowed}{}", super::suggest::did_you_mean(name, Domain::NAMES)))),
            },
        },
    };
    if let Some(directions) = directions {
        reject_keys(ctx, &[("bounds", c.bounds.as_ref())], "only applies to domain = \"plane\"; remove it (or set domain = \"plane\")")?;
        return Ok(directions);
    }
    let angles = [("incident_theta", c.incident_theta.as_ref().map(|s| s.whole())), ("incident_phi", c.incident_phi.as_ref().map(|s| s.whole()))];
    let angles: Vec<(&str, Option<&Val>)> = angles.iter().map(|(k, v)| (*k, v.as_ref())).collect();
    reject_keys(ctx, &angles, "does not apply to domain = \"plane\" (a point of the plane has no incident direction); remove it")?;
    let domain_v = c.domain.as_ref().expect("domain = \"plane\" is written");
    let Some(b) = &c.bounds else { return Err(ctx.err(domain_v.span(), format!("domain = \"plane\" needs bounds; {BOUNDS_ALLOWED}"))) };
    let Value::Array(items) = b.get_ref() else {
        return Err(ctx.err(b.span(), format!("bounds must be an array, got {}; {BOUNDS_ALLOWED}", kind_of(b.get_ref()))));
    };
    let numbers = items.iter().map(|i| number(ctx, &Spanned::new(b.span(), i.clone()), "bounds", |_| true, BOUNDS_ALLOWED)).collect::<Result<Vec<_>, _>>()?;
    let plane = match numbers[..] {
        [x0, y0, x1, y1] => Domain::plane([x0, y0, x1, y1]).ok(),
        _ => None,
    };
    plane.ok_or_else(|| ctx.err(b.span(), format!("bounds = {} is not a box; {BOUNDS_ALLOWED}", b.get_ref())))
}

/// `budget = SECONDS` or `"ci"` / `"thorough"`: the case's count picked by pilot checks when it
/// runs, as `lobes check --budget`; not with the case's own `samples`. A `--samples` given to
/// `lobes run` sets every case's count, so there the budget is not used.
fn budget(ctx: &Ctx, d: &Defaults, point: &Point, v: &Val) -> Result<Option<Budget>, SceneError> {
    if let Some(s) = point.get("samples") {
        return Err(ctx.err(s.span(), "samples and budget both set the case's sample count; keep one (budget picks the count that fits its seconds on the adapter)".to_string()));
    }
    let budget = match v.get_ref() {
        Value::String(name) => Budget::named(name),
        Value::Integer(i) => Budget::seconds(*i as f64),
        Value::Float(x) => Budget::seconds(*x),
        _ => None,
    };
    let budget = budget.ok_or_else(|| ctx.err(v.span(), format!("budget = {} is not a budget; {}", v.get_ref(), Budget::allowed())))?;
    Ok(d.overrides.samples.is_none().then_some(budget))
}

/// One case of a user's sampler at one point of its sweeps.
pub(super) fn case(ctx: &Ctx, d: &Defaults, point: &Point, common: Common, sampler: &Arc<UserSampler>, (timeout_v, budget_v): (Option<&Val>, Option<&Val>)) -> Result<UserCase, SceneError> {
    let defaults = Settings::default();
    let incident_theta = match point.get("incident_theta") {
        Some(t) => {
            let theta = number(ctx, t, "incident_theta", |x| (0.0..=180.0).contains(&x), "incident_theta is in degrees from the normal, 0 ≤ θ ≤ 180 (above 90 the light comes from below)")?;
            // a sweep stays where the sampler is declared for (incident = "upper": below 90°)
            if sampler.domain.directions() {
                sampler.conventions.check_incident(theta).map_err(|e| ctx.err(t.span(), e.to_string()))?;
            }
            theta
        }
        None => defaults.incident_theta,
    };
    let incident_phi = incident_phi(ctx, point)?;
    let params = match point.get("params") {
        None => Vec::new(),
        Some(p) => params(ctx, p)?,
    };
    let bins = match (point.get("bins"), &d.bins) {
        (Some(v), _) => Some(grid(ctx, v, false, GRID_ALLOWED)?),
        (None, Some(g)) => Some(*g),
        (None, None) => None,
    };
    let timeout = match timeout_v {
        Some(t) => {
            let allowed = format!("timeout is the seconds the case's checks may take, a number > 0 and at most {MAX_TIMEOUT_SECONDS:e} (default {})", DEFAULT_TIMEOUT.as_secs());
            // a timeout under a nanosecond would be 0 s, which the check refuses when it runs
            let positive = |x: f64| x > 0.0 && x <= MAX_TIMEOUT_SECONDS && !std::time::Duration::from_secs_f64(x).is_zero();
            std::time::Duration::from_secs_f64(number(ctx, t, "timeout", positive, &allowed)?)
        }
        None => defaults.timeout,
    };
    let budget = match budget_v {
        Some(v) => budget(ctx, d, point, v)?,
        None => None,
    };
    let timeout = budget.map_or(timeout, |b| crate::check::budget::timeout_for(b.seconds, timeout_v.is_some().then_some(timeout)));
    let Common { name, samples, seed } = common;
    let settings = Settings { params, incident_theta, incident_phi, samples, bins: bins.map(|g| (g.rows, g.cols)), seed, timeout, ..defaults };
    Ok(UserCase { name, sampler: sampler.clone(), settings, budget })
}

/// `params = [p1, p2, ...]`: at most [`MAX_PARAMS`] numbers, each finite as an f32 (WGSL's
/// `params` are f32: 1e39 would be ∞ there).
fn params(ctx: &Ctx, v: &Val) -> Result<Vec<f64>, SceneError> {
    let allowed = format!("params is a list of at most {MAX_PARAMS} finite numbers within f32's range (±{:e}), params[i / 4][i % 4] in WGSL (an array of such lists sweeps)", f32::MAX);
    let Value::Array(items) = v.get_ref() else {
        return Err(ctx.err(v.span(), format!("params must be an array, got {}; {allowed}", kind_of(v.get_ref()))));
    };
    if items.len() > MAX_PARAMS {
        return Err(ctx.err(v.span(), format!("params has {} numbers; {allowed}", items.len())));
    }
    items.iter().map(|i| number(ctx, &Spanned::new(v.span(), i.clone()), "params", |x| (x as f32).is_finite(), &allowed)).collect()
}
