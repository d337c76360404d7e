//! Scene files: a TOML list of cases, each one lobe (or discrete distribution, or a user's WGSL
//! sampler) to sample, histogram and judge. Errors name the file, line and column and what is allowed.
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
//! alpha_angle = 30.0    # degrees from +x to the alpha_x axis about the normal (default 0)
//! incident_theta = 45.0 # degrees from the normal, [0, 90) ([0, 180) for a dielectric)
//! incident_phi = 0.0    # degrees
//! # scatter = "dielectric"  # rough glass (ggx or beckmann, ndf or vndf) with eta = n_below / n_above
//! # effects (any of them makes the case weighted: Σ f cos θ / pdf per bin)
//! fresnel = "schlick"   # none | schlick (f0) | conductor (eta, k) | dielectric (eta)
//! f0 = 0.04
//! masking = "g1"        # none | g1 | separable | height-correlated (not for ward)
//! # weighted = true     # a weighted histogram without Fresnel or masking
//!
//! [[case]]               # a sampler of your own, in WGSL, judged by `lobes check`'s checks
//! name = "my-ggx"
//! sampler = { wgsl = ["ggx.wgsl"], sample = "ggx_sample", pdf = "ggx_pdf", eval = "ggx_eval" }
//! params = [0.3, 0.3]    # up to 16 numbers, `params` of the WGSL functions
//! domain = "sphere"      # sphere | plane (then bounds = [x0, y0, x1, y1])
//! incident_theta = [0, 45, 80]  # an array sweeps: one case per value, named my-ggx-theta0 …
//! ```
//!
//! Any key with one number or name sweeps when given an array (`alpha = [0.1, 0.3]`,
//! `method = ["ndf", "vndf"]`), and several such keys make their product (`sweep`).
//!
//! Every value is read as a TOML value first and checked here, so a wrong type, a value out
//! of range, NaN or infinity, an unknown name or a key that does not apply to the case's lobe
//! is a [`SceneError`] pointing at the value (a value set in `[defaults]` is reported where
//! `[defaults]` sets it). Parsing never panics, whatever the bytes (`tests/bad_input.rs`
//! fuzzes it).

mod raw;
mod select;
/// "Did you mean" ([`crate::suggest`], here too for the scene's messages).
pub use crate::suggest;
mod sweep;
pub mod template;
pub(crate) mod user;
mod value;

pub use sweep::MAX_CASES;
pub use user::UserCase;

use crate::engine::job::{DiscreteMethod, Job, Scatter};
use crate::reference::discrete::{Distribution, WeightsError};
use crate::reference::effects::Effects;
use crate::reference::fresnel::Fresnel;
use crate::reference::masking::Masking;
use crate::reference::sampler::{self, Shape};
use crate::reference::{Lobe, LobeKind, Method, reflect};
use crate::stats::histogram::SphereGrid;
use crate::stats::expected::MIN_ALPHA;
use std::collections::HashMap;
use suggest::did_you_mean;
use raw::{RawCase, RawScene};
use sweep::{Point, Val};
use value::{Common, Ctx, Defaults, grid, line_column, incident_phi, kind_of, number, reject_keys, roughness_keys, effect_keys, string, whole};
pub use value::{DEFAULT_INCIDENT_PHI, MAX_BINS, Overrides, SceneError};
use std::ops::Range;
use toml::{Spanned, Value};

/// The scene `lobes run` uses when no file is given: every lobe and method.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/all-lobes.toml");
/// The tutorial's examples as a scene.
pub const TUTORIAL_SCENE: &str = include_str!("../../scenes/tutorial.toml");

pub use crate::engine::job::MAX_SAMPLES;
/// The largest sample count of a weighted case (its 64-bit fixed-point sums hold 2^32 samples
/// of mean weight up to 4096).
pub const MAX_WEIGHTED_SAMPLES: u64 = 1 << 32;
/// A case's samples unless the case or `[defaults]` sets them.
pub const DEFAULT_SAMPLES: u64 = 10_000_000;
/// A case's seed unless the case or `[defaults]` sets it.
pub const DEFAULT_SEED: u64 = 1;
/// A lobe case's bins unless the case or `[defaults]` sets them: 64 rows over cos θ, 128
/// columns over φ.
pub const DEFAULT_BINS: SphereGrid = SphereGrid { rows: 64, cols: 128 };
/// A lobe case's sampler unless `method` is given.
pub const DEFAULT_METHOD: Method = Method::Ndf;
/// A discrete case's sampler unless `method` is given.
pub const DEFAULT_DISCRETE_METHOD: DiscreteMethod = DiscreteMethod::Cdf;
/// A lobe case's incident polar angle in degrees unless given (a user sampler's is
/// [`crate::check::Settings`]'s).
pub const DEFAULT_INCIDENT_THETA: f64 = 0.0;
/// The turn of a lobe's tangent frame, degrees (`alpha_angle`).
pub const DEFAULT_ALPHA_ANGLE: f64 = 0.0;
/// The longest case name (it names a folder).
pub const MAX_NAME_LEN: usize = 100;

/// One validated case.
#[derive(Debug, Clone)]
pub struct Case {
    pub name: String,
    pub job: Job,
    pub samples: u64,
    pub seed: u64,
    /// Incident angles in degrees (lobes).
    pub incident_deg: (f64, f64),
    /// For a weighted histogram (`weighted = true`, or any of `fresnel`, `masking`): the
    /// effects whose estimator weights are summed per bin. `None`: counts only.
    pub effects: Option<Effects>,
}

/// A validated scene.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The cases of lobes' own samplers (lobes and discrete distributions).
    pub cases: Vec<Case>,
    /// The cases of users' WGSL samplers (`sampler = { wgsl = [...], ... }`).
    pub user_cases: Vec<UserCase>,
    /// The file name used in messages.
    pub file: String,
    /// Every case in the file's order, with the line and column of its `[[case]]` table.
    order: Vec<(Slot, (usize, usize))>,
}

/// Where a case of [`Scene::entries`] is held.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Slot {
    Lobe(usize),
    User(usize),
}

/// A case of a scene: one of lobes' samplers, or a user's.
#[derive(Debug, Clone, Copy)]
pub enum Entry<'a> {
    Lobe(&'a Case),
    User(&'a UserCase),
}

impl<'a> Entry<'a> {
    pub fn name(&self) -> &'a str {
        match self {
            Entry::Lobe(c) => &c.name,
            Entry::User(c) => &c.name,
        }
    }
    pub fn samples(&self) -> u64 {
        match self {
            Entry::Lobe(c) => c.samples,
            Entry::User(c) => c.settings.samples,
        }
    }
}

/// A case as validated, before it takes its place in the scene.
enum Parsed {
    Lobe(Case),
    User(UserCase),
}

const SAMPLES_ALLOWED: &str = "give a whole number of samples from 1 to 2^40 (1099511627776), e.g. 10_000_000";
const SEED_ALLOWED: &str = "give a whole number ≥ 0";
const BINS_ALLOWED: &str = "give [rows, cols]: whole numbers ≥ 1, rows even (the horizon is a row edge), rows × cols ≤ 2^24 (16777216)";

fn samples(ctx: &Ctx, v: &Val) -> Result<u64, SceneError> {
    whole(ctx, v, "samples", 1, MAX_SAMPLES, SAMPLES_ALLOWED)
}

fn seed(ctx: &Ctx, v: &Val) -> Result<u64, SceneError> {
    whole(ctx, v, "seed", 0, u64::MAX, SEED_ALLOWED)
}

fn bins(ctx: &Ctx, v: &Val) -> Result<SphereGrid, SceneError> {
    grid(ctx, v, true, BINS_ALLOWED)
}

impl Scene {
    /// Parses and validates a scene; `file` names it in errors.
    pub fn parse(file: &str, text: &str) -> Result<Scene, SceneError> {
        Scene::parse_with(file, text, Overrides::default())
    }

    /// [`Scene::parse`], with `overrides` replacing every case's samples and seed.
    pub fn parse_with(file: &str, text: &str, overrides: Overrides) -> Result<Scene, SceneError> {
        let ctx = Ctx { file, text };
        let raw: RawScene = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            let message = suggest::unknown_field(e.message().trim())
                .replace("struct RawScene", "[defaults] and [[case]] tables")
                .replace("struct RawDefaults", "a [defaults] table")
                .replace("struct RawCase", "a [[case]] table")
                .replace("struct RawSampler", "a sampler table { wgsl = [\"file.wgsl\"], sample = \"...\", pdf = \"...\" }")
                // `case` is the only plain sequence (weights say what they expect themselves)
                .replace("expected a sequence", "expected [[case]] tables (write [[case]] for each case, not [case])");
            ctx.err(span, message)
        })?;
        let d = raw.defaults.as_ref().map(|d| d.get_ref());
        let defaults = Defaults {
            samples: d.and_then(|d| d.samples.as_ref()).map(|v| samples(&ctx, v).map(|n| (n, v))).transpose()?,
            bins: d.and_then(|d| d.bins.as_ref()).map(|v| bins(&ctx, v)).transpose()?,
            seed: d.and_then(|d| d.seed.as_ref()).map(|v| seed(&ctx, v)).transpose()?,
            overrides,
        };
        if raw.case.is_empty() {
            return Err(ctx.err(0..0, "the scene has no [[case]] tables; add at least one (see scenes/all-lobes.toml)"));
        }
        // Names are compared ignoring case: they name folders, and some file systems ignore case.
        let mut names: HashMap<String, (usize, usize)> = HashMap::new();
        let mut scene = Scene { cases: Vec::new(), user_cases: Vec::new(), file: file.to_string(), order: Vec::new() };
        for c in &raw.case {
            let here = line_column(text, c.span().start);
            let name_span = c.get_ref().name.as_ref().map_or(c.span(), |n| n.span());
            for parsed in validate_table(&ctx, c, &defaults, MAX_CASES - scene.order.len() as u64)? {
                let name = match &parsed {
                    Parsed::Lobe(case) => &case.name,
                    Parsed::User(case) => &case.name,
                };
                if let Some((line, column)) = names.insert(name.to_lowercase(), here) {
                    return Err(ctx.err(
                        name_span,
                        format!(
                            "duplicate case name '{name}' (the case at {line}:{column} has it too, ignoring case); names must be unique, they name the output folders"
                        ),
                    ));
                }
                let slot = match parsed {
                    Parsed::Lobe(case) => {
                        scene.cases.push(case);
                        Slot::Lobe(scene.cases.len() - 1)
                    }
                    Parsed::User(case) => {
                        scene.user_cases.push(case);
                        Slot::User(scene.user_cases.len() - 1)
                    }
                };
                scene.order.push((slot, here));
            }
        }
        Ok(scene)
    }

    /// Parses a scene from raw bytes: text that is not UTF-8 is an error at the first bad byte.
    pub fn from_bytes(file: &str, bytes: &[u8]) -> Result<Scene, SceneError> {
        Scene::from_bytes_with(file, bytes, Overrides::default())
    }

    /// [`Scene::from_bytes`] with [`Overrides`].
    pub fn from_bytes_with(file: &str, bytes: &[u8], overrides: Overrides) -> Result<Scene, SceneError> {
        match std::str::from_utf8(bytes) {
            Ok(text) => Scene::parse_with(file, text, overrides),
            Err(e) => {
                let good = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or_default();
                let (line, column) = line_column(good, good.len());
                Err(SceneError {
                    file: file.to_string(),
                    line,
                    column,
                    message: format!("the file is not UTF-8 text (byte {} is invalid); save it as UTF-8", e.valid_up_to()),
                })
            }
        }
    }

    /// "file:line:column" of the `[[case]]` table of `cases[index]`.
    pub fn case_location(&self, index: usize) -> String {
        let at = self.order.iter().find(|(s, _)| *s == Slot::Lobe(index)).map_or((1, 1), |o| o.1);
        self.location(at)
    }

    fn location(&self, (line, column): (usize, usize)) -> String {
        format!("{}:{line}:{column}", self.file)
    }

    /// Every case, lobes' and users', in the file's order, with "file:line:column" of its
    /// `[[case]]` table.
    pub fn entries(&self) -> impl Iterator<Item = (Entry<'_>, String)> {
        self.order.iter().map(|&(slot, at)| {
            let entry = match slot {
                Slot::Lobe(i) => Entry::Lobe(&self.cases[i]),
                Slot::User(i) => Entry::User(&self.user_cases[i]),
            };
            (entry, self.location(at))
        })
    }

    /// The number of cases (lobes' and users').
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// Whether the scene has no cases (never, for a parsed scene).
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }
}

fn check_name(ctx: &Ctx, c: &Spanned<RawCase>) -> Result<String, SceneError> {
    let Some(v) = &c.get_ref().name else {
        return Err(ctx.err(c.span(), "this [[case]] has no name; add name = \"...\" (letters, digits, '-', '_', '.')"));
    };
    let allowed = "a case name uses only letters, digits, '-', '_' and '.', at most 100 characters, not only dots (it names a folder)";
    let name = string(ctx, v, "name", allowed)?;
    let ok = !name.is_empty()
        && name.len() <= MAX_NAME_LEN
        && name.chars().all(|ch| ch.is_ascii_alphanumeric() || "-_.".contains(ch))
        && !name.chars().all(|ch| ch == '.');
    if !ok {
        return Err(ctx.err(v.span(), format!("case name {name:?} is not allowed; {allowed}")));
    }
    Ok(name.to_string())
}

/// The cases of one `[[case]]` table: one, or one per point of its sweeps, of which the scene
/// has room for `room` more ([`MAX_CASES`]; counted before the sweeps are expanded).
fn validate_table(ctx: &Ctx, spanned: &Spanned<RawCase>, d: &Defaults, room: u64) -> Result<Vec<Parsed>, SceneError> {
    let c = spanned.get_ref();
    let name = check_name(ctx, spanned)?;
    let name_span = c.name.as_ref().map_or(spanned.span(), |n| n.span());
    let sweeps = c.sweeps();
    for (key, sweep) in sweep::KEYS.iter().zip(sweeps) {
        if let Some(s) = sweep
            && !key.list
            && s.is_empty_sweep()
        {
            return Err(ctx.err(s.span(), format!("{} = [] sweeps over no values; give a value, or an array of values (one case each)", key.name)));
        }
    }
    let (count, factors) = sweep::count(sweeps);
    if count > room as u128 {
        let above = match MAX_CASES - room {
            0 => String::new(),
            n => format!(", after the {n} cases of the tables above"),
        };
        return Err(ctx.err(
            spanned.span(),
            format!(
                "case '{name}' sweeps to {count} cases ({}){above}; a scene makes at most {MAX_CASES} cases: sweep fewer values, or split the scene",
                sweep::describe(&factors)
            ),
        ));
    }
    let points = sweep::points(sweeps);
    let sampler = match &c.sampler {
        Some(raw) => Some(user::sampler(ctx, c, &points[0], raw)?),
        None => {
            let user_keys =
                [("params", points[0].get("params")), ("domain", c.domain.as_ref()), ("bounds", c.bounds.as_ref()), ("timeout", c.timeout.as_ref()), ("budget", c.budget.as_ref())];
            reject_keys(ctx, &user_keys, "only applies to a user sampler (sampler = { wgsl = [...], sample = ..., pdf = ... }); remove it")?;
            None
        }
    };
    points
        .into_iter()
        .map(|point| {
            let name = format!("{name}{}", point.suffix);
            if let Some(why) = crate::folder_names::reserved(&name) {
                return Err(ctx.err(name_span.clone(), format!("case name '{name}' is reserved: {why} (each case writes OUT/<case>/); rename the case")));
            }
            if name.len() > MAX_NAME_LEN {
                return Err(ctx.err(
                    name_span.clone(),
                    format!("the sweep makes the case name '{name}', longer than {MAX_NAME_LEN} characters (it names a folder); shorten the name"),
                ));
            }
            let samples = match (d.overrides.samples, point.get("samples")) {
                (Some(n), _) => n,
                (None, Some(v)) => samples(ctx, v)?,
                (None, None) => d.samples.map_or(DEFAULT_SAMPLES, |(n, _)| n),
            };
            let seed = match (d.overrides.seed, point.get("seed")) {
                (Some(s), _) => s,
                (None, Some(v)) => seed(ctx, v)?,
                (None, None) => d.seed.unwrap_or(DEFAULT_SEED),
            };
            let common = Common { name, samples, seed };
            match &sampler {
                Some(s) => user::case(ctx, d, &point, common, s, (c.timeout.as_ref(), c.budget.as_ref())).map(Parsed::User),
                None => validate_case(ctx, spanned, d, &point, common).map(Parsed::Lobe),
            }
        })
        .collect()
}

fn validate_case(ctx: &Ctx, spanned: &Spanned<RawCase>, d: &Defaults, point: &Point, common: Common) -> Result<Case, SceneError> {
    let c = spanned.get_ref();
    let Common { name, samples, seed } = common;
    let lobes_allowed = "use ward, beckmann, ggx or discrete";
    let Some(lobe_v) = &c.lobe else {
        return Err(ctx.err(
            spanned.span(),
            format!("case '{name}' has no lobe; add lobe = \"...\" ({lobes_allowed}), or sampler = {{ wgsl = [...], sample = ..., pdf = ... }} for a sampler of your own"),
        ));
    };
    let lobe_name = string(ctx, lobe_v, "lobe", lobes_allowed)?;
    let method = point.get("method").map(|m| Ok::<_, SceneError>((string(ctx, m, "method", "use ndf, vndf or bounded (lobes), cdf or alias (discrete)")?, m.span()))).transpose()?;
    if lobe_name == DISCRETE {
        let job = discrete_job(ctx, c, point, lobe_v, method)?;
        return Ok(Case { name, job, samples, seed, incident_deg: (0.0, 0.0), effects: None });
    }
    let (kind, method, method_span) = lobe_method(ctx, lobe_name, lobe_v, method)?;
    if let Some(w) = &c.weights {
        return Err(ctx.err(w.span(), "weights only apply to lobe = \"discrete\"; remove them"));
    }
    let (ax, ay) = roughness(ctx, point, lobe_v, &name)?;
    let scatter = scatter(ctx, c, point, kind, method, lobe_v, &method_span)?;
    let theta = incident_theta(ctx, point, scatter)?;
    let phi = incident_phi(ctx, point)?;
    let grid = match point.get("bins") {
        Some(v) => bins(ctx, v)?,
        None => d.bins.unwrap_or(DEFAULT_BINS),
    };
    let incident = reflect::spherical(theta.to_radians(), phi.to_radians());
    // allowed with any α (an isotropic lobe turned is the same lobe), so sweeps over α need no special case
    let angle = match point.get("alpha_angle") {
        Some(v) => number(ctx, v, "alpha_angle", |x| (-360.0..=360.0).contains(&x), "alpha_angle is in degrees from +x to the alpha_x axis, −360 ≤ angle ≤ 360")?,
        None => DEFAULT_ALPHA_ANGLE,
    };
    let lobe = Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: angle };
    // a dielectric case has no Fresnel keys (`scatter` rejects them) and reads eta itself
    let effects = effects(ctx, c, point, kind, scatter)?;
    if effects.is_some() && samples > MAX_WEIGHTED_SAMPLES {
        let (span, given) = match (d.overrides.samples, point.get("samples").or(d.samples.map(|(_, v)| v))) {
            (Some(_), _) => (spanned.span(), " (the command line's, for every case)"),
            (None, v) => (v.map_or(spanned.span(), |v| v.span()), ""),
        };
        return Err(ctx.err(span, format!("samples = {samples}{given} is too many for a weighted case; at most 2^32 (4294967296)")));
    }
    Ok(Case { name, job: Job::Lobe { lobe, incident, grid, scatter }, samples, seed, incident_deg: (theta, phi), effects })
}

/// A discrete case's job: its weights and method, with no key of a lobe's.
fn discrete_job(ctx: &Ctx, c: &RawCase, point: &Point, lobe_v: &Val, method: Option<(&str, Range<usize>)>) -> Result<Job, SceneError> {
    let method = match method {
        None => DEFAULT_DISCRETE_METHOD,
        Some(("cdf", _)) => DiscreteMethod::Cdf,
        Some(("alias", _)) => DiscreteMethod::Alias,
        Some((other, span)) => return Err(ctx.err(span, format!("method '{other}' is not a discrete method; use cdf or alias{}", did_you_mean(other, ["cdf", "alias"])))),
    };
    reject_keys(ctx, &roughness_keys(point), "does not apply to lobe = \"discrete\" (a discrete distribution has no roughness); remove it")?;
    reject_keys(
        ctx,
        &[("incident_theta", point.get("incident_theta")), ("incident_phi", point.get("incident_phi")), ("bins", point.get("bins")), ("scatter", point.get("scatter"))],
        "does not apply to lobe = \"discrete\" (a discrete histogram has one bin per weight); remove it",
    )?;
    reject_keys(ctx, &effect_keys(c, point), "does not apply to lobe = \"discrete\" (effects are for ward, beckmann and ggx); remove it")?;
    let Some(w) = &c.weights else {
        return Err(ctx.err(lobe_v.span(), "a discrete case needs weights = [w0, w1, ...]: finite numbers ≥ 0, not all zero"));
    };
    let items = &w.get_ref().0;
    if items.len() as u64 > MAX_BINS {
        return Err(ctx.err(w.span(), format!("weights has {} items; at most 2^24 (16777216)", items.len())));
    }
    let values = items
        .iter()
        .enumerate()
        .map(|(i, v)| number(ctx, v, &format!("weights[{i}]"), |x| x >= 0.0, "weights must be finite numbers ≥ 0"))
        .collect::<Result<Vec<f64>, _>>()?;
    let dist = Distribution::new(&values).map_err(|e| {
        let span = match e {
            WeightsError::Invalid { index, .. } => items.get(index).map_or(w.span(), |v| v.span()),
            _ => w.span(),
        };
        ctx.err(span, format!("weights: {e}"))
    })?;
    Ok(Job::Discrete { dist, method })
}

/// The `lobe` of a case that draws from a discrete distribution, not a lobe.
const DISCRETE: &str = "discrete";

/// A lobe case's lobe and method (the default method unless given), and where the method was
/// said (the lobe's span when it was not).
fn lobe_method(ctx: &Ctx, lobe_name: &str, lobe_v: &Val, method: Option<(&str, Range<usize>)>) -> Result<(LobeKind, Method, Range<usize>), SceneError> {
    let Some(kind) = LobeKind::from_name(lobe_name) else {
        let lobes: Vec<&str> = LobeKind::ALL.iter().map(|k| k.name()).chain([DISCRETE]).collect();
        let hint = did_you_mean(lobe_name, lobes.iter().copied());
        return Err(ctx.err(lobe_v.span(), format!("lobe '{lobe_name}' is unknown; use {}{hint}", either(&lobes))));
    };
    let method_span = method.as_ref().map_or(lobe_v.span(), |m| m.1.clone());
    let method_name = method.map_or(DEFAULT_METHOD.name(), |m| m.0);
    let Some(method) = Method::from_name(method_name) else {
        let methods: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
        let hint = did_you_mean(method_name, methods.iter().copied());
        let use_ = either(&methods);
        return Err(ctx.err(method_span, format!("method '{method_name}' is unknown for a lobe; use {use_} (cdf and alias are for lobe = \"{DISCRETE}\"){hint}")));
    };
    if !kind.supports(method) {
        let each: Vec<String> = LobeKind::ALL.iter().map(|k| format!("{}: {}", k.name(), k.methods().map(Method::name).collect::<Vec<_>>().join(", "))).collect();
        return Err(ctx.err(method_span, format!("{} has no '{}' sampler; {}", kind.name(), method.name(), each.join("; "))));
    }
    Ok((kind, method, method_span))
}

/// "a, b or c".
fn either(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} or {last}", rest.join(", ")),
    }
}

/// (αx, αy) from `alpha`, or from `alpha_x` and `alpha_y`, each ≥ [`MIN_ALPHA`].
fn roughness(ctx: &Ctx, point: &Point, lobe_v: &Val, name: &str) -> Result<(f64, f64), SceneError> {
    let rough = "roughness must be a finite number > 0";
    let positive = |v: &Val, key| {
        let a = number(ctx, v, key, |x| x > 0.0, rough)?;
        if a < MIN_ALPHA {
            return Err(ctx.err(
                v.span(),
                format!("{key} = {a:e} is below the smallest roughness lobes judges, {MIN_ALPHA:e}: the f64 reference cannot resolve a narrower lobe, so its histogram could not be judged; give {key} ≥ {MIN_ALPHA:e}"),
            ));
        }
        Ok(a)
    };
    match (point.get("alpha"), point.get("alpha_x"), point.get("alpha_y")) {
        (Some(a), None, None) => positive(a, "alpha").map(|a| (a, a)),
        (None, Some(x), Some(y)) => Ok((positive(x, "alpha_x")?, positive(y, "alpha_y")?)),
        (Some(_), Some(v), _) | (Some(_), None, Some(v)) => Err(ctx.err(v.span(), "give either alpha or both alpha_x and alpha_y, not both")),
        (None, Some(v), None) => Err(ctx.err(v.span(), "alpha_x needs alpha_y too (or give alpha alone)")),
        (None, None, Some(v)) => Err(ctx.err(v.span(), "alpha_y needs alpha_x too (or give alpha alone)")),
        (None, None, None) => Err(ctx.err(lobe_v.span(), format!("case '{name}' needs a roughness: alpha = A, or alpha_x = AX and alpha_y = AY ({rough})"))),
    }
}

/// `incident_theta` in degrees: below 90 for a reflection, below 180 for a dielectric.
fn incident_theta(ctx: &Ctx, point: &Point, scatter: Scatter) -> Result<f64, SceneError> {
    match (point.get("incident_theta"), scatter) {
        (Some(t), Scatter::Reflect) => number(ctx, t, "incident_theta", |x| (0.0..90.0).contains(&x), "incident_theta is in degrees from the normal, 0 ≤ θ < 90"),
        (Some(t), Scatter::Dielectric { .. }) => number(
            ctx,
            t,
            "incident_theta",
            |x| (0.0..180.0).contains(&x),
            "incident_theta is in degrees from the normal, 0 ≤ θ < 180 for scatter = \"dielectric\" (θ > 90: light from inside)",
        ),
        (None, _) => Ok(DEFAULT_INCIDENT_THETA),
    }
}

/// `scatter` of a lobe case (reflect unless given) with a dielectric's `eta`: only for a
/// sampler of the registry with a dielectric twin, and without Fresnel keys (its Fresnel term
/// is its own).
fn scatter(ctx: &Ctx, c: &RawCase, p: &Point, kind: LobeKind, method: Method, lobe_v: &Val, method_span: &Range<usize>) -> Result<Scatter, SceneError> {
    let allowed = "use reflect or dielectric (with eta)";
    let form = match p.get("scatter") {
        None => None,
        Some(v) => match string(ctx, v, "scatter", allowed)? {
            "reflect" => None,
            "dielectric" => Some(v),
            other => return Err(ctx.err(v.span(), format!("scatter '{other}' is unknown; {allowed}{}", did_you_mean(other, ["reflect", "dielectric"])))),
        },
    };
    let Some(form) = form else {
        if let (Some(v), None) = (p.get("eta"), p.get("fresnel")) {
            return Err(ctx.err(
                v.span(),
                "eta applies to scatter = \"dielectric\" or to fresnel = \"conductor\" or \"dielectric\"; remove it or set one of them",
            ));
        }
        return Ok(Scatter::Reflect);
    };
    if sampler::find(kind, method).wgsl.dielectric.is_none() {
        // the lobes and methods that have one, from the registry
        let has = |k: LobeKind| sampler::of_kind(k).filter(|s| s.wgsl.dielectric.is_some()).map(|s| s.method).collect::<Vec<_>>();
        let (span, what) = match has(kind).is_empty() {
            true => (lobe_v.span(), format!("{} has no dielectric sampler", kind.name())),
            false => (method_span.clone(), format!("{} {} has no dielectric sampler", kind.name(), method.name())),
        };
        let lobes: Vec<&str> = LobeKind::ALL.into_iter().filter(|&k| !has(k).is_empty()).map(LobeKind::name).collect();
        let methods: Vec<&str> = Method::ALL.into_iter().filter(|m| LobeKind::ALL.into_iter().any(|k| has(k).contains(m))).map(Method::name).collect();
        return Err(ctx.err(span, format!("{what}; scatter = \"dielectric\" needs lobe {} with method {}", lobes.join(" or "), methods.join(" or "))));
    }
    reject_keys(
        ctx,
        &effect_keys(c, p).into_iter().filter(|(k, _)| ["fresnel", "f0", "k"].contains(k)).collect::<Vec<_>>(),
        "does not apply to scatter = \"dielectric\" (the dielectric's Fresnel term is its own, from eta); remove it",
    )?;
    let eta_allowed = "eta is the index of the medium below the surface relative to the one above, > 0 and ≠ 1";
    let eta = match p.get("eta") {
        Some(v) => number(ctx, v, "eta", |x| x > 0.0 && x != 1.0, eta_allowed)?,
        None => return Err(ctx.err(form.span(), format!("scatter = \"dielectric\" needs eta; add eta = ... ({eta_allowed})"))),
    };
    Ok(Scatter::Dielectric { eta })
}

/// The effects of a lobe case: `None` unless it asks for a weighted histogram. A rough
/// dielectric (`scatter`) has masking only: `scatter` has rejected the Fresnel keys, and its
/// `eta` is its own.
fn effects(ctx: &Ctx, c: &RawCase, p: &Point, kind: LobeKind, scatter: Scatter) -> Result<Option<Effects>, SceneError> {
    let dielectric = scatter != Scatter::Reflect;
    let fresnel_allowed = "use none, schlick (with f0), conductor (with eta and k) or dielectric (with eta)";
    let fresnel = match p.get("fresnel") {
        None => Fresnel::None,
        Some(v) => match string(ctx, v, "fresnel", fresnel_allowed)? {
            "none" => Fresnel::None,
            "schlick" => Fresnel::Schlick {
                f0: required(ctx, v, p.get("f0"), "f0", |x| (0.0..=1.0).contains(&x), "f0 is the reflectance at normal incidence, 0 ≤ f0 ≤ 1")?,
            },
            "conductor" => Fresnel::Conductor {
                eta: required(ctx, v, p.get("eta"), "eta", |x| x > 0.0, "eta is the real part of the index of refraction, > 0")?,
                k: required(ctx, v, p.get("k"), "k", |x| x >= 0.0, "k is the absorption (imaginary part of the index), ≥ 0")?,
            },
            "dielectric" => Fresnel::Dielectric {
                eta: required(ctx, v, p.get("eta"), "eta", |x| x > 0.0, "eta is the relative index of refraction n_t / n_i, > 0")?,
            },
            other => {
                let hint = did_you_mean(other, ["none", "schlick", "conductor", "dielectric"]);
                return Err(ctx.err(v.span(), format!("fresnel '{other}' is unknown; {fresnel_allowed}{hint}")));
            }
        },
    };
    // Parameters that the chosen form does not read.
    let unused = |key: &str, v: Option<&Val>, used: bool| match v {
        Some(v) if !used => Err(ctx.err(v.span(), format!("{key} does not apply to fresnel = \"{}\"; remove it ({fresnel_allowed})", fresnel.name()))),
        _ => Ok(()),
    };
    unused("f0", p.get("f0"), matches!(fresnel, Fresnel::Schlick { .. }))?;
    unused("eta", p.get("eta"), dielectric || matches!(fresnel, Fresnel::Conductor { .. } | Fresnel::Dielectric { .. }))?;
    unused("k", p.get("k"), matches!(fresnel, Fresnel::Conductor { .. }))?;
    let masking_allowed = "use none, g1, separable or height-correlated";
    let masking = match p.get("masking") {
        None => Masking::None,
        Some(v) => {
            let m = match string(ctx, v, "masking", masking_allowed)? {
                "none" => Masking::None,
                "g1" => Masking::G1,
                "separable" => Masking::Separable,
                "height-correlated" => Masking::HeightCorrelated,
                other => {
                    let hint = did_you_mean(other, ["none", "g1", "separable", "height-correlated"]);
                    return Err(ctx.err(v.span(), format!("masking '{other}' is unknown; {masking_allowed}{hint}")));
                }
            };
            if matches!(kind.spec().shape, Shape::Own { .. }) && m != Masking::None {
                let e = format!("lobe = \"{}\" has no Smith masking (its BRDF is not a microfacet one); use masking = \"none\" (or leave it out)", kind.name());
                return Err(ctx.err(v.span(), e));
            }
            m
        }
    };
    let weighted = match &c.weighted {
        None => None,
        Some(v) => match v.get_ref() {
            Value::Boolean(b) => Some((*b, v)),
            other => return Err(ctx.err(v.span(), format!("weighted must be true or false, got {}", kind_of(other)))),
        },
    };
    let asked = p.get("fresnel").or(p.get("masking"));
    match (weighted, asked) {
        (Some((false, _)), Some(v)) => Err(ctx.err(
            v.span(),
            "Fresnel and masking only change the estimator weights, which a case with weighted = false does not sum; set weighted = true or remove them",
        )),
        (Some((true, _)), _) | (None, Some(_)) => Ok(Some(Effects { fresnel, masking })),
        _ => Ok(None),
    }
}

/// The number `key` that `fresnel` (at `form`) needs.
fn required(ctx: &Ctx, form: &Val, v: Option<&Val>, key: &str, ok: impl Fn(f64) -> bool, allowed: &str) -> Result<f64, SceneError> {
    match v {
        Some(v) => number(ctx, v, key, ok, allowed),
        None => Err(ctx.err(form.span(), format!("this Fresnel form needs {key}; add {key} = ... ({allowed})"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_scenes_parse() {
        assert!(Scene::parse("all-lobes.toml", DEFAULT_SCENE).unwrap().cases.len() > 10);
        assert_eq!(Scene::parse("tutorial.toml", TUTORIAL_SCENE).unwrap().cases.len(), 3);
    }

    #[test]
    fn an_array_of_incident_angles_sweeps_a_lobe_case() {
        let text = "[[case]]\nname = \"g\"\nlobe = \"ggx\"\nalpha = 0.3\nincident_theta = [0, 60]\nincident_phi = [-30, 90]\n\n[[case]]\nname = \"w\"\nlobe = \"ward\"\nalpha = 0.2\n";
        let scene = Scene::parse("s.toml", text).unwrap();
        let names: Vec<&str> = scene.entries().map(|(e, _)| e.name()).collect();
        assert_eq!(names, ["g-theta0-phi-30", "g-theta0-phi90", "g-theta60-phi-30", "g-theta60-phi90", "w"]);
        assert_eq!(scene.cases[3].incident_deg, (60.0, 90.0));
        // (sin 60° cos 90°, sin 60° sin 90°, cos 60°)
        let Job::Lobe { incident, .. } = &scene.cases[3].job else { panic!("a lobe") };
        assert!((incident.y - 0.75f64.sqrt()).abs() < 1e-12 && incident.x.abs() < 1e-12 && (incident.z - 0.5).abs() < 1e-12);
        assert_eq!(scene.case_location(4), "s.toml:8:1");
        assert!(scene.entries().all(|(_, at)| at.starts_with("s.toml:")));
        let err = Scene::parse("s.toml", "[[case]]\nname = \"g\"\nlobe = \"ggx\"\nalpha = 0.3\nincident_theta = [0, 95]\n").unwrap_err();
        assert_eq!((err.line, err.column), (5, 22), "{err}");
        let err = Scene::parse("s.toml", "[[case]]\nname = \"g\"\nlobe = \"ggx\"\nalpha = 0.3\nincident_theta = []\n").unwrap_err();
        assert!(err.message.contains("sweeps over no values"), "{err}");
        let long = format!("[[case]]\nname = \"{}\"\nlobe = \"ggx\"\nalpha = 0.3\nincident_theta = [45]\n", "n".repeat(95));
        let err = Scene::parse("s.toml", &long).unwrap_err();
        assert!(err.message.contains("longer than 100 characters") && err.line == 2, "{err}");
        let dup = "[[case]]\nname = \"g-theta0\"\nlobe = \"ward\"\nalpha = 0.2\n[[case]]\nname = \"g\"\nlobe = \"ggx\"\nalpha = 0.3\nincident_theta = [0]\n";
        assert!(Scene::parse("s.toml", dup).unwrap_err().message.contains("duplicate case name 'g-theta0'"));
    }

    /// Issue 24 item 2: α below what the f64 reference resolves (1e-12 passed on 0 dof) is
    /// refused at its value, naming the smallest α supported.
    #[test]
    fn alpha_below_the_smallest_supported_is_refused() {
        let parse = |keys: &str| Scene::parse("s.toml", &format!("[[case]]\nname = \"g\"\nlobe = \"ggx\"\nmethod = \"vndf\"\n{keys}\n"));
        let err = parse("alpha = 1e-12").unwrap_err();
        assert!(err.message.contains("below the smallest roughness lobes judges, 1e-4") && (err.line, err.column) == (5, 9), "{err}");
        let err = parse("alpha_x = 0.3\nalpha_y = 5e-5").unwrap_err();
        assert!(err.message.starts_with("alpha_y = 5e-5 is below") && err.line == 6, "{err}");
        assert!(parse(&format!("alpha = {MIN_ALPHA}")).is_ok());
    }

    #[test]
    fn alpha_angle_turns_the_lobe_frame_in_degrees() {
        let case = |extra: &str| Scene::parse("s.toml", &format!("[[case]]\nname = \"g\"\nlobe = \"ggx\"\nalpha_x = 0.3\nalpha_y = 0.1\n{extra}"));
        let angle = |extra: &str| match &case(extra).unwrap().cases[0].job {
            Job::Lobe { lobe, .. } => lobe.alpha_angle,
            Job::Discrete { .. } => panic!("a lobe"),
        };
        assert_eq!(angle(""), 0.0);
        assert_eq!(angle("alpha_angle = 90\n"), 90.0);
        assert_eq!(angle("alpha_angle = -45.0\n"), -45.0);
        let err = case("alpha_angle = 400\n").unwrap_err();
        assert!(err.message.contains("alpha_angle is in degrees") && (err.line, err.column) == (6, 15), "{err}");
        let err = Scene::parse("s.toml", "[[case]]\nname = \"d\"\nlobe = \"discrete\"\nweights = [1, 2]\nalpha_angle = 10\n").unwrap_err();
        assert!(err.message.contains("alpha_angle") && err.line == 5, "{err}");
        // swept like the other numbers
        let scene = case("alpha_angle = [0, 30]\n").unwrap();
        let names: Vec<&str> = scene.entries().map(|(e, _)| e.name()).collect();
        assert_eq!(names, ["g-turn0", "g-turn30"]);
    }

    #[test]
    fn roughness_method_samples_seed_and_bins_sweep_as_a_product() {
        let text = "[[case]]\nname = \"g\"\nlobe = \"ggx\"\nmethod = [\"ndf\", \"vndf\"]\nalpha = [0.1, 0.3]\nsamples = [1000, 2000]\n\n\
                    [[case]]\nname = \"a\"\nlobe = \"beckmann\"\nalpha_x = [0.1, 0.2]\nalpha_y = 0.05\nbins = [[8, 16], [16, 32]]\nseed = [7, 9]\n\n\
                    [[case]]\nname = \"d\"\nlobe = \"discrete\"\nmethod = [\"cdf\", \"alias\"]\nweights = [1, 2]\n\n\
                    [[case]]\nname = \"f\"\nlobe = \"ggx\"\nalpha = 0.2\nfresnel = \"schlick\"\nf0 = [0.04, 1]\n";
        let scene = Scene::parse("s.toml", text).unwrap();
        let names: Vec<&str> = scene.entries().map(|(e, _)| e.name()).collect();
        assert_eq!(names.len(), 8 + 8 + 2 + 2);
        assert_eq!(names[..3], ["g-ndf-alpha0.1-n1000", "g-ndf-alpha0.1-n2000", "g-ndf-alpha0.3-n1000"]);
        assert_eq!(names[7], "g-vndf-alpha0.3-n2000");
        assert_eq!(names[8..10], ["a-ax0.1-bins8_16-seed7", "a-ax0.1-bins8_16-seed9"]);
        assert_eq!(names[15], "a-ax0.2-bins16_32-seed9");
        assert_eq!(names[16..], ["d-cdf", "d-alias", "f-f0_0.04", "f-f0_1"]);
        let lobe = |i: usize| match &scene.cases[i].job {
            Job::Lobe { lobe, grid, .. } => (lobe.method, lobe.alpha_x, lobe.alpha_y, grid.rows, grid.cols),
            Job::Discrete { .. } => panic!("a lobe"),
        };
        assert_eq!(lobe(7), (Method::Vndf, 0.3, 0.3, 64, 128));
        assert_eq!((scene.cases[7].samples, scene.cases[7].seed), (2000, DEFAULT_SEED));
        assert_eq!(lobe(15), (Method::Ndf, 0.2, 0.05, 16, 32));
        assert_eq!((scene.cases[15].samples, scene.cases[15].seed), (DEFAULT_SAMPLES, 9));
        assert!(matches!(scene.cases[17].job, Job::Discrete { method: DiscreteMethod::Alias, .. }));
        assert_eq!(scene.cases[19].effects.unwrap().fresnel, Fresnel::Schlick { f0: 1.0 });
        // each swept value is checked where it is written
        let err = Scene::parse("s.toml", "[[case]]\nname = \"g\"\nlobe = \"ggx\"\nmethod = [\"vndf\", \"cdf\"]\nalpha = 0.1\n").unwrap_err();
        assert_eq!((err.line, err.column), (4, 19), "{err}");
        // overrides win over the scene and its sweeps
        let scene = Scene::parse_with("s.toml", text, Overrides { samples: Some(500), seed: Some(4) }).unwrap();
        assert!(scene.entries().all(|(e, _)| e.samples() == 500) && scene.cases.iter().all(|c| c.seed == 4));
    }

    #[test]
    fn a_user_sampler_case_reads_its_files_relative_to_the_scene() {
        let file = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/user-samplers.toml");
        let scene = Scene::parse(file, &std::fs::read_to_string(file).unwrap()).unwrap();
        assert!(scene.cases.is_empty());
        assert_eq!(scene.len(), 6);
        let hg = &scene.user_cases[4];
        assert_eq!((hg.name.as_str(), hg.settings.params.as_slice()), ("henyey-greenstein-params-0.3", &[-0.3][..]));
        assert_eq!(hg.settings.samples, 1_000_000);
        let plane = &scene.user_cases[5];
        assert_eq!(plane.sampler.domain, crate::check::Domain::Plane { bounds: [0.0, 0.0, 1.0, 1.0] });
        // the three θi of one sampler share its files
        assert!(std::sync::Arc::ptr_eq(&scene.user_cases[0].sampler, &scene.user_cases[2].sampler));
        assert_eq!(scene.user_cases[2].settings.incident_theta, 80.0);
        // elsewhere, the same relative path names no file
        let err = Scene::parse("elsewhere/s.toml", &std::fs::read_to_string(file).unwrap()).unwrap_err();
        assert!(err.message.contains("elsewhere/../examples/samplers/ggx_vndf.wgsl: cannot read"), "{err}");
    }

    #[test]
    fn line_column_counts_characters_and_never_splits_one() {
        let t = "aé\nθx";
        assert_eq!(line_column(t, 0), (1, 1));
        assert_eq!(line_column(t, 3), (1, 3));
        assert_eq!(line_column(t, 4), (2, 1));
        assert_eq!(line_column(t, 5), (2, 1)); // inside θ: rounded down to its start
        assert_eq!(line_column(t, 99), (2, 3));
    }
}
