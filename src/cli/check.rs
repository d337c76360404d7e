//! `lobes check`: judge a user's WGSL sampler (see [`crate::check`]).

use super::{NumberList, OutputArgs, emit, emit_json, interrupt, parse_azimuth, parse_number_list, parse_polar_180, usage};
use crate::report::check::CHECK_FILES;
use crate::report::folder::{Access, OutFolder};
use crate::report::table;
use crate::check::{self, CheckError, Conventions, Domain, Frame, Incident, Measure, Setting, Settings, UserSampler};
use crate::check::resources::ResourceKind;
use crate::engine::gpu::{Gpu, GpuError};
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Where the user's sampler puts its points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DomainChoice {
    /// Unit directions anywhere on the sphere.
    Sphere,
    /// Points (d.x, d.y) of the box given by --bounds.
    Plane,
    /// Unit directions binned on the texels of a latitude–longitude map (--bins ROWS,COLS its
    /// texels): rows uniform in θ from +z (v = θ/π), columns in φ = atan2(y, x) (u = (φ + π)/2π).
    Latlong,
    /// Unit directions binned on the texels of an octahedral equal-area map (--bins ROWS,COLS
    /// its texels; pbrt-v4's environment maps): +z at the square's centre, −z at its corners,
    /// columns along u, rows along v.
    EqualArea,
}

/// What a sample expression returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ReturnsChoice {
    /// The direction d (vec3), or (d, pdf) (vec4).
    Direction,
    /// A half vector h (vec3), or (h, pdf of h) (vec4).
    HalfVector,
}

/// A named time budget (`lobes::check::budget::Profile`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ProfileChoice {
    /// 20 s a check: a CI job on a CPU runner.
    Ci,
    /// 300 s a check: a nightly job.
    Thorough,
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The files that define the sampler, in order: WGSL, WESL, naga_oil, GLSL (one translation
    /// unit, with its #includes) or one SPIR-V module (.spv).
    #[arg(required = true, value_name = "FILE.wgsl")]
    pub files: Vec<PathBuf>,
    /// The sampling function: `fn(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32>`,
    /// or a WGSL call expression over wi, u, params, p0 … p15 and rng returning vec4 (d, pdf) or
    /// vec3 (d), e.g. 'sample_ggx_vndf(wi, p0, rng)'.
    #[arg(long, value_name = "NAME|EXPR")]
    pub sample: String,
    /// The density: `fn(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32`, or a call
    /// expression over wi, d, params, p0 … p15 and rng, e.g. 'ggx_vndf_pdf(wi, d, p0)'.
    #[arg(long, value_name = "NAME|EXPR")]
    pub pdf: String,
    /// Optional f·|cos| (or the phase function), same forms as --pdf: adds the weight and
    /// albedo checks.
    #[arg(long, value_name = "NAME|EXPR")]
    pub eval: Option<String>,
    /// Where imported modules are found (repeatable): naga_oil's #import paths or WESL's
    /// package root. Default: the first file's folder.
    #[arg(long = "shader-root", value_name = "DIR")]
    pub shader_root: Vec<PathBuf>,
    /// A shader def (repeatable): naga_oil's #ifdef/#if (VALUE true, false or an integer), WESL's
    /// @if features (true or false). No value: true.
    #[arg(long, value_name = "NAME[=VALUE]")]
    pub define: Vec<String>,
    /// A stand-in for a module the test does not need (repeatable): bind groups, scene bindings,
    /// ray queries. MODULE as the imports name it (a::b, package::a::b).
    #[arg(long, value_name = "MODULE=FILE")]
    pub stub: Vec<String>,
    /// Where another WESL package's modules are (repeatable): NAME::a::b is DIR/a/b.wesl (or
    /// .wgsl). Without it, lobes looks for NAME::a::b as a/b.wesl under the shader roots.
    #[arg(long, value_name = "NAME=DIR")]
    pub package: Vec<String>,
    /// A renderer's texture the sampler reads (repeatable): a Radiance .hdr, an OpenEXR .exr
    /// (scanline; NONE, RLE, ZIPS or ZIP) or a .png image (its stored values: 8-bit v is v/255,
    /// no sRGB decoding) bound as the files' NAME:
    /// `texture_2d<f32>` (rgba32float, for textureLoad or a --sampler).
    #[arg(long, value_name = "NAME=FILE")]
    pub texture: Vec<String>,
    /// A renderer's table the sampler reads (repeatable): a .npy array of float32, uint32 or int32,
    /// or raw little-endian 32-bit words (.bin, .raw), bound as the files'
    /// `var<storage, read> NAME: array<f32>` (or u32, i32).
    #[arg(long, value_name = "NAME=FILE")]
    pub buffer: Vec<String>,
    /// A renderer's sampler the sampler reads (repeatable): bound as the files' NAME: sampler
    /// with FILTER linear or nearest, clamp-to-edge (for textureSampleLevel over a --texture).
    #[arg(long, value_name = "NAME=FILTER")]
    pub sampler: Vec<String>,
    /// The sampler's random function (repeatable): its body becomes lobes' queue of u.x, u.y, u.z,
    /// u.w in call order (vec2/3/4 results take 2/3/4); at most four draws per sample.
    #[arg(long, value_name = "NAME")]
    pub rand: Vec<String>,
    /// Which --rand draw is which, in call order: x, y (smooth coordinates) and event (a draw
    /// that chooses a lobe), e.g. event,x,y. Default: found by lobes' probe.
    #[arg(long, value_name = "ORDER")]
    pub rand_order: Option<String>,
    /// What the sample expression returns: the direction d, or a half vector h that lobes
    /// reflects wi about (dividing a returned pdf of h by 4 |wi·h|).
    #[arg(long, value_enum, default_value = "direction")]
    pub sample_returns: ReturnsChoice,
    #[arg(long, value_enum, default_value = "sphere")]
    pub domain: DomainChoice,
    /// On the sphere, whether the histogram's grid is fitted to a small support: auto (a cap
    /// about the samples where they all fall within about 0.1 sr: small lights), never (the
    /// whole sphere), always (a cap wherever they fall within a hemisphere).
    #[arg(long, value_name = "auto|never|always", value_parser = parse_fit, default_value = "auto")]
    pub fit: check::support::Fit,
    /// The plane's box, X0,Y0,X1,Y1 (with --domain plane).
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_number_list, allow_hyphen_values = true)]
    pub bounds: Option<NumberList>,
    /// Up to 16 numbers passed to every function as `params` (zero-padded).
    #[arg(long, value_name = "P1,P2,...", value_parser = parse_number_list, allow_hyphen_values = true)]
    pub params: Option<NumberList>,
    /// Incident θ in degrees from the normal (+z), [0, 180]; θ > 90 comes from below.
    #[arg(long, value_name = "DEG", value_parser = parse_polar_180, default_value = "30")]
    pub incident_theta: f64,
    /// Incident φ in degrees from +x.
    #[arg(long, value_name = "DEG", value_parser = parse_azimuth, allow_hyphen_values = true, default_value = "0")]
    pub incident_phi: f64,
    /// Where the sampler's incident light may come from: sphere, or upper (above the surface
    /// only: the hard cases and --incident-theta stay below 90°).
    #[arg(long, value_name = "sphere|upper", default_value = "sphere")]
    pub incident: Incident,
    /// The sampler only reflects: --incident upper, and any d with d·n ≤ 0 is a rejection
    /// whatever pdf it reports (its pdf and eval taken as 0 there).
    #[arg(long)]
    pub reflection_only: bool,
    /// The sampler's uniforms are in [0, 1): the hard cases never feed exactly 1.
    #[arg(long)]
    pub u_open: bool,
    /// The measure of the pdf (and eval): solid-angle, or projected (per |cos θ| dσ; eval is then
    /// f without the cosine), or area: the sample is a point p of a light, relative to the shading
    /// point, with its density per unit area (needs --normal); lobes judges d = p/|p| with
    /// pdf_A·|p|²/|n·d|, and --pdf and --eval stay per solid angle.
    #[arg(long, value_name = "solid-angle|projected|area", default_value = "solid-angle")]
    pub measure: Measure,
    /// With --measure area: the light's unit normal at the sampled point p, a WGSL expression
    /// over p, params and p0 … p15 (e.g. `'vec3<f32>(0.0, 0.0, -1.0)'` for a light facing down).
    #[arg(long, value_name = "EXPR")]
    pub normal: Option<String>,
    /// The sampler's tangent frame: z-up, or y-up (normal +y; --incident-theta from +y, φ from +x
    /// towards +z).
    #[arg(long, value_name = "z-up|y-up", default_value = "z-up")]
    pub frame: Frame,
    /// Samples drawn for the histogram (and the weights), 1 to 2^40.
    #[arg(long, value_name = "N", default_value_t = 1 << 22, value_parser = clap::value_parser!(u64).range(1..=crate::scene::MAX_SAMPLES))]
    pub samples: u64,
    /// Pick --samples for a time budget: short pilot checks measure this sampler's fixed time
    /// and time per sample on this adapter, and the check runs at the largest count whose
    /// predicted wall time fits SECONDS (the pilots' time comes on top). Not with --samples.
    #[arg(long, value_name = "SECONDS", value_parser = parse_budget, conflicts_with_all = ["samples", "profile"])]
    pub budget: Option<f64>,
    /// A named --budget: ci (20 s: the panel of subtly broken samplers caught on lavapipe) or
    /// thorough (300 s, a nightly job). Not with --samples or --budget.
    #[arg(long, value_enum, conflicts_with = "samples")]
    pub profile: Option<ProfileChoice>,
    /// Seconds the check may take (default 600): a sampler that is still running then (an
    /// endless loop) fails the check with the pass it was in; raise it for a large --samples.
    /// Composing the sampler's modules, before any GPU work, is bounded by it too: past it,
    /// no verdict (exit 3).
    #[arg(long, value_name = "SECONDS", value_parser = parse_timeout)]
    pub timeout: Option<f64>,
    /// Histogram ROWS,COLS (default 64,128 on the sphere, 64,64 on the plane).
    #[arg(long, value_name = "ROWS,COLS", value_parser = parse_number_list)]
    pub bins: Option<NumberList>,
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,
    /// Significance of the χ² and albedo tests.
    #[arg(long, value_name = "A", default_value_t = 0.01)]
    pub significance: f64,
    /// Run the whole check at 2^16, 2^18, … samples up to --samples and print the χ² p-value and
    /// time at each, and from which count (after how much GPU time) an error is caught; exit 1
    /// when some count fails.
    #[arg(long)]
    pub power: bool,
    /// Write report.json, heat maps of the histogram (measured.png, expected.png, residual.png)
    /// and the composed WGSL to this folder (power.json with --power).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Where another lobes is writing --out, wait until it has finished (without it: exit 2,
    /// naming that process). One run or check owns an output folder at a time.
    #[arg(long)]
    pub wait: bool,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// A check's error as the command's: bad input (exit 2), a stop asked for (130), out of time
/// (a failed check, 1), or the tool's failure (3).
fn input(e: CheckError) -> anyhow::Error {
    match e {
        CheckError::Gpu(GpuError::Stopped(_)) => super::Interrupted(e.to_string()).into(),
        CheckError::Gpu(GpuError::TimedOut { .. }) => super::ChecksFailed(e.to_string()).into(),
        CheckError::Setting { setting, message } => usage(format!("--{}: {message}", flag(setting))),
        CheckError::Advised(m) => usage(m.render(&|s| format!("--{}", flag(s)))),
        CheckError::NoVerdict(m) => anyhow::anyhow!("{}", m.render(&|s| format!("--{}", flag(s)))),
        e if e.is_input() => usage(e.to_string()),
        e => e.into(),
    }
}

/// The flag that sets `setting`.
pub(super) fn flag(setting: Setting) -> &'static str {
    match setting {
        Setting::Params => "params",
        Setting::IncidentTheta => "incident-theta",
        Setting::IncidentPhi => "incident-phi",
        Setting::Samples => "samples",
        Setting::Timeout => "timeout",
        Setting::Bins => "bins",
        Setting::Significance => "significance",
        Setting::ShaderRoot => "shader-root",
        Setting::Define => "define",
        Setting::Stub => "stub",
        Setting::Package => "package",
        Setting::RandOrder => "rand-order",
        Setting::Sample => "sample",
        Setting::Pdf => "pdf",
        Setting::Eval => "eval",
        Setting::Normal => "normal",
        Setting::Incident => "incident",
        Setting::ReflectionOnly => "reflection-only",
        Setting::Measure => "measure",
        Setting::Frame => "frame",
        Setting::Bounds => "bounds",
        Setting::SampleReturns => "sample-returns",
        Setting::Rand => "rand",
        Setting::Texture => "texture",
        Setting::Buffer => "buffer",
        Setting::Filter => "sampler",
        Setting::Budget => "budget",
    }
}

impl CheckArgs {
    /// What the sampler's flags say beyond its files and functions: its domain, conventions
    /// and composition (each checked here, at once).
    fn sampler_parts(&self) -> anyhow::Result<(Domain, Conventions, check::Composition)> {
        let name = self.domain.to_possible_value().expect("every domain is a value");
        let domain = match (Domain::of_directions(name.get_name()), &self.bounds) {
            (Some(directions), None) => directions,
            (Some(_), Some(_)) => return Err(usage("--bounds: only with --domain plane")),
            (None, None) => return Err(usage("--domain plane needs --bounds X0,Y0,X1,Y1")),
            (None, Some(b)) => match b.0[..] {
                [x0, y0, x1, y1] => Domain::Plane { bounds: [x0, y0, x1, y1] },
                _ => return Err(usage(format!("--bounds: expected 4 numbers X0,Y0,X1,Y1, got {}", b.0.len()))),
            },
        };
        if self.fit == check::support::Fit::Always && !domain.is_sphere() {
            return Err(usage(format!("--fit always: only with --domain sphere (a cap is fitted on the sphere; --domain {} keeps its own grid)", domain.name())));
        }
        let conventions = Conventions { incident: self.incident, reflection_only: self.reflection_only, u_open: self.u_open, measure: self.measure, frame: self.frame };
        let returns = match self.sample_returns {
            ReturnsChoice::Direction => check::SampleReturns::Direction,
            ReturnsChoice::HalfVector => check::SampleReturns::HalfVector,
        };
        let composition = self.composition(returns)?;
        let packages = check::Composition::parse_packages(&self.package).map_err(|e| usage(format!("--package {e}")))?;
        let kinds = [(ResourceKind::Texture, &self.texture), (ResourceKind::Buffer, &self.buffer), (ResourceKind::Sampler, &self.sampler)];
        let items: Vec<(ResourceKind, String)> = kinds.iter().flat_map(|(k, items)| items.iter().map(|i| (*k, i.clone()))).collect();
        let resources = check::Composition::parse_resources(&items).map_err(|e| usage(format!("--{} {}", flag(e.kind.into()), e.message)))?;
        let composition = check::Composition { normal: self.normal.clone(), packages, resources, ..composition };
        Ok((domain, conventions, composition))
    }

    /// The composition the flags give: `--define NAME[=VALUE]`, `--stub MODULE=FILE`,
    /// `--rand-order event,x,y`, read here; what they say is the library's to check
    /// ([`check::Composition::validate`]).
    fn composition(&self, sample_returns: check::SampleReturns) -> anyhow::Result<check::Composition> {
        let defines = self.define.iter().map(|d| match d.split_once('=') {
            Some((n, v)) => (n.trim().to_string(), Some(v.trim().to_string())),
            None => (d.trim().to_string(), None),
        });
        let stubs = self.stub.iter().map(|s| match s.split_once('=') {
            Some((m, f)) if !m.trim().is_empty() && !f.trim().is_empty() => Ok((m.trim().to_string(), PathBuf::from(f.trim()))),
            _ => Err(usage(format!("--stub '{s}': give MODULE=FILE, e.g. --stub package::bindings=tests/no_bindings.wesl"))),
        });
        let rand_order = self.rand_order.as_deref().map(|o| check::Draw::parse_list(o).map_err(|e| usage(format!("--rand-order: {e}")))).transpose()?;
        Ok(check::Composition {
            shader_roots: self.shader_root.clone(),
            defines: defines.collect(),
            stubs: stubs.collect::<anyhow::Result<_>>()?,
            rand: self.rand.clone(),
            rand_order,
            sample_returns,
            ..Default::default()
        })
    }

    /// The sampler, read and composed on a thread of its own while this one waits for it
    /// against `limit` and SIGINT/SIGTERM. Composition runs before any GPU work (whose own
    /// deadline starts when it does) and nothing stops it midway: naga_oil's time grows faster
    /// than N² in the depth N of a chain of imports (5 s for 1000 modules; issue 35 §11). Past
    /// `limit` the check ends without a verdict (exit 3) saying what was being composed
    /// ([`check::modules::composing`]); at a signal it ends with 130. Either way the thread is
    /// left to the process's exit.
    fn compose(&self, limit: Duration) -> anyhow::Result<UserSampler> {
        let started = Instant::now();
        let (domain, conventions, composition) = self.sampler_parts()?;
        let (files, sample, pdf, eval) = (self.files.clone(), self.sample.clone(), self.pdf.clone(), self.eval.clone());
        let (tx, rx) = std::sync::mpsc::channel();
        // the stack of every parse of the user's WGSL (crate::engine::gpu::stack)
        let worker = std::thread::Builder::new().name("lobes-compose".into()).stack_size(crate::engine::gpu::stack::BIG_STACK);
        let worker = worker
            .spawn(move || {
                let made = UserSampler::from_repository(&files, &sample, &pdf, eval.as_deref(), domain, composition).and_then(|s| s.with_conventions(conventions));
                let _ = tx.send(made);
            })
            .map_err(|e| anyhow::anyhow!("cannot start a thread to compose the sampler on: {e}"))?;
        loop {
            match rx.recv_timeout(Duration::from_millis(50)) {
                Ok(made) => return made.map_err(input),
                // a panic while composing stays a panic (exit 101), as it was on this thread
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => match worker.join() {
                    Err(panic) => std::panic::resume_unwind(panic),
                    Ok(()) => return Err(anyhow::anyhow!("internal error: the thread composing the sampler ended without a result")),
                },
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    if let Some(stopped) = self.composing_stopped(started, limit) {
                        return Err(stopped);
                    }
                }
            }
        }
    }

    /// Why composing that began at `started` ends now, if it does: a signal (exit 130), or
    /// `limit` gone by (no verdict, exit 3, naming the files and the modules being composed).
    fn composing_stopped(&self, started: Instant, limit: Duration) -> Option<anyhow::Error> {
        let doing = || check::modules::composing().unwrap_or_else(|| format!("reading and composing {}", self.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", ")));
        let seconds = started.elapsed().as_secs_f64();
        if interrupt::requested() {
            return Some(super::Interrupted(format!("lobes check interrupted after {seconds:.1} s while lobes was {}, before any GPU work: no verdict", doing())).into());
        }
        (started.elapsed() >= limit).then(|| {
            let doing = doing();
            let why = if doing.contains("naga_oil") { " (naga_oil's time grows faster than the square of the depth of a chain of imports: about 5 s for 1000 modules)" } else { "" };
            anyhow::anyhow!(
                "no verdict: the time limit of {} s (--timeout) ran out after {seconds:.1} s while lobes was {doing}, before any GPU work{why}; the sampler was not run. Raise --timeout to give composing more time",
                limit.as_secs_f64()
            )
        })
    }

    /// The time budget of `--budget` or `--profile`, if either is given.
    fn budget_seconds(&self) -> Option<f64> {
        self.budget.or(self.profile().map(|p| p.seconds()))
    }

    fn profile(&self) -> Option<check::budget::Profile> {
        self.profile.map(|p| match p {
            ProfileChoice::Ci => check::budget::Profile::Ci,
            ProfileChoice::Thorough => check::budget::Profile::Thorough,
        })
    }

    fn settings(&self) -> anyhow::Result<Settings> {
        let bins = match &self.bins {
            None => None,
            // the grid's limits are Settings::validate's
            Some(b) => match b.0[..] {
                [r, c] if [r, c].iter().all(|v| v.fract() == 0.0 && (0.0..=u32::MAX as f64).contains(v)) => Some((r as u32, c as u32)),
                _ => return Err(usage("--bins: expected ROWS,COLS, two whole numbers, e.g. 64,128")),
            },
        };
        Ok(Settings {
            params: self.params.as_ref().map(|p| p.0.clone()).unwrap_or_default(),
            incident_theta: self.incident_theta,
            incident_phi: self.incident_phi,
            samples: self.samples,
            bins,
            seed: self.seed,
            significance: self.significance,
            timeout: self.time_limit(),
            fit: self.fit,
            ..Settings::default()
        })
    }

    /// The time the check may take: `--timeout` (default [`check::DEFAULT_TIMEOUT`]),
    /// raised by `--budget` ([`check::budget::timeout_for`]).
    fn time_limit(&self) -> Duration {
        match self.budget_seconds() {
            Some(budget) => check::budget::timeout_for(budget, self.timeout.map(Duration::from_secs_f64)),
            None => self.timeout.map_or(check::DEFAULT_TIMEOUT, Duration::from_secs_f64),
        }
    }
}

/// `--fit`: one of [`check::support::Fit::NAMES`].
fn parse_fit(s: &str) -> Result<check::support::Fit, String> {
    check::support::Fit::parse(s).ok_or_else(|| format!("'{s}' is not one of {}", check::support::Fit::NAMES.join(", ")))
}

/// `--budget`: seconds, a number > 0 and at most [`check::MAX_TIMEOUT_SECONDS`].
fn parse_budget(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(t) if t > 0.0 && t <= check::MAX_TIMEOUT_SECONDS => Ok(t),
        _ => Err(format!("'{s}' is not a time budget; give seconds, a number > 0 and at most {:e}", check::MAX_TIMEOUT_SECONDS)),
    }
}

/// `--timeout`: seconds, a number > 0 and at most [`check::MAX_TIMEOUT_SECONDS`].
fn parse_timeout(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(t) if t > 0.0 && t <= check::MAX_TIMEOUT_SECONDS => Ok(t),
        _ => Err(format!("'{s}' is not a time limit; give seconds, a number > 0 and at most {:e}", check::MAX_TIMEOUT_SECONDS)),
    }
}

pub fn run(args: &CheckArgs) -> anyhow::Result<()> {
    // An --out that exists is locked first (as `lobes run` does): where another lobes holds
    // it, nothing is touched; bad input then removes the earlier check's outputs, so that no
    // report.json is left that reads as this check's
    let existing = args.out.as_deref().map(|dir| OutFolder::claim_existing(dir, Access::Owner, args.wait)).transpose().map_err(super::folder_error)?.flatten();
    // before the sampler is composed, which a long chain of imports makes slow: a signal while
    // it is (also where a script's `&` left SIGINT ignored) ends the check at once (exit 130);
    // on the GPU the stop is seen within 50 ms of a wait, and 1.5 s after it a process still
    // held (by a thread in the driver) ends all the same
    interrupt::watch("stopping the check now (interrupt again to end at once)", Some(Duration::from_millis(1500)))?;
    let started = (|| {
        // the settings first: a bad one is refused at once, not after a long composition
        let settings = args.settings()?;
        settings.validate().map_err(input)?;
        let sampler = args.compose(args.time_limit())?;
        if sampler.domain.directions() {
            sampler.conventions.check_incident(settings.incident_theta).map_err(input)?;
        }
        Ok::<_, anyhow::Error>((sampler, settings))
    })();
    let (sampler, settings) = match started {
        Ok(s) => s,
        Err(e) => {
            if let Some(folder) = &existing
                && let Err(clean) = folder.clean_files(&CHECK_FILES)
            {
                crate::console::say(format_args!("lobes: error: {clean:#}"));
            }
            return Err(e);
        }
    };
    // held until the process ends: a second check or run into the folder waits or exits 2
    let out_folder = match (existing, &args.out) {
        (Some(folder), _) => Some(folder),
        (None, Some(dir)) => Some(OutFolder::claim(dir, Access::Owner, args.wait).map_err(super::folder_error)?),
        (None, None) => None,
    };
    if let Some(folder) = &out_folder {
        folder.clean_files(&CHECK_FILES)?;
    }
    let gpu = Gpu::new()?;
    let _stop = gpu.stop_when(interrupt::requested);
    let settings = match args.budget_seconds() {
        None => settings,
        Some(budget) => {
            let pick = check::budget::pick(&gpu, &sampler, &settings, budget, args.profile()).map_err(input)?;
            let capped = if pick.budget_seconds < budget {
                format!(" (the budget {budget} s capped at 1/{} of --timeout {} s)", check::budget::TIMEOUT_MARGIN, settings.timeout.as_secs_f64())
            } else {
                String::new()
            };
            // the reason on stdout before the table; with --json (one object on stdout) on stderr
            if args.output.json {
                crate::console::say(format_args!("lobes: {}{capped}", pick.explain()));
            } else {
                emit(&format!("{}{capped}\n", pick.explain()))?;
            }
            Settings { samples: pick.samples, ..settings }
        }
    };
    if args.power {
        return power(&gpu, &sampler, &settings, args);
    }
    let started = Instant::now();
    let report = match check::check(&gpu, &sampler, &settings) {
        Ok(report) => report,
        Err(CheckError::Gpu(e @ (GpuError::TimedOut { .. } | GpuError::Stopped(_)))) => {
            return unfinished(&gpu, &sampler, &settings, args, &e, started.elapsed().as_secs_f64());
        }
        Err(e) => return Err(input(e)),
    };
    if let Some(dir) = &args.out {
        // the module that ran: on the report's domain (a cap fitted to the samples, where one was)
        let ran = UserSampler { domain: report.domain, ..sampler.clone() };
        let histogram = ran.composed_histogram(gpu.info.device_type, &gpu.limits, report.rows, report.cols).map_err(input)?;
        let modules = [ran.composed().map_err(input)?, histogram];
        crate::report::check::write(dir, &report, &modules)?;
    }
    if args.output.json {
        emit_json(&report)?;
    } else {
        let mut t = format!("{} on {} ({} samples, {}×{} bins)\n", report.sampler, report.adapter, report.samples, report.rows, report.cols);
        t += &table::render(&["check", "result", "summary"], report.checks.iter().map(|c| vec![c.name(), verdict(c.passed), &c.summary]));
        t += if report.passed { "passed\n" } else { "FAILED\n" };
        emit(&t)?;
    }
    if !report.passed {
        return Err(super::ChecksFailed(format!("{} failed: {}", report.sampler, report.failed().join(", "))).into());
    }
    Ok(())
}

/// Why a check ended without every verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
enum Status {
    /// SIGINT or SIGTERM: no verdict (exit 130).
    Interrupted,
    /// Out of time (`--timeout`): the check fails (exit 1).
    TimedOut,
}

/// The report of a check that ended early, on stdout (one JSON object with --json); `--out`
/// then holds no `report.json` (an earlier one is removed when the check starts).
#[derive(Debug, Serialize)]
struct Unfinished {
    format_version: u32,
    status: Status,
    passed: bool,
    sampler: String,
    adapter: String,
    samples: u64,
    timeout_seconds: f64,
    wall_seconds: f64,
    /// What the GPU was doing, and what to do.
    reason: String,
}

/// Reports a check that was interrupted (exit 130) or ran out of time (a failure, exit 1).
/// The GPU may still be running the sampler: the device is abandoned, never waited for.
fn unfinished(gpu: &Gpu, sampler: &UserSampler, settings: &Settings, args: &CheckArgs, e: &GpuError, seconds: f64) -> anyhow::Result<()> {
    let (status, reason) = match e {
        GpuError::TimedOut { pass, .. } if pass.starts_with("pipeline creation") => (
            Status::TimedOut,
            format!("{e}; a shader the driver compiles for longer than the time limit (a very large sampler) ends here; raise --timeout to give it more"),
        ),
        GpuError::TimedOut { .. } => (
            Status::TimedOut,
            format!("{e}; a sampler, pdf or eval that never returns (an endless loop) ends here; for a larger --samples raise --timeout"),
        ),
        _ => (Status::Interrupted, format!("{e}; no verdict")),
    };
    let report = Unfinished {
        format_version: check::report::REPORT_VERSION,
        status,
        passed: false,
        sampler: format!("{}/{} in {}", sampler.sample, sampler.pdf, sampler.sources.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")),
        adapter: gpu.adapter_name(),
        samples: settings.samples,
        timeout_seconds: settings.timeout.as_secs_f64(),
        wall_seconds: seconds,
        reason,
    };
    if args.output.json {
        emit_json(&report)?;
    } else {
        let name = if status == Status::TimedOut { "timeout" } else { "interrupted" };
        let mut t = format!("{} on {} ({} samples)\n", report.sampler, report.adapter, report.samples);
        let result = if status == Status::TimedOut { verdict(false) } else { "-" };
        t += &table::render(&["check", "result", "summary"], [vec![name, result, &report.reason]]);
        t += if status == Status::TimedOut { "FAILED\n" } else { "interrupted\n" };
        emit(&t)?;
    }
    match status {
        Status::TimedOut => Err(super::ChecksFailed(format!("{} failed: {e}", report.sampler)).into()),
        Status::Interrupted => Err(super::Interrupted(format!("lobes check interrupted after {seconds:.1} s: no verdict")).into()),
    }
}

fn verdict(passed: bool) -> &'static str {
    if passed { "ok" } else { "FAIL" }
}

/// `--power`: exits 0 when every check passes at every count, 1 when some count fails.
fn power(gpu: &Gpu, sampler: &UserSampler, settings: &Settings, args: &CheckArgs) -> anyhow::Result<()> {
    let sweep = check::power::power(gpu, sampler, settings).map_err(input)?;
    if let Some(dir) = &args.out {
        crate::report::check::write_power(dir, &sweep)?;
    }
    if args.output.json {
        emit_json(&sweep)?;
    } else {
        let seconds = |s: Option<f64>| s.map_or("-".to_string(), |s| format!("{s:.3}"));
        let mut t = format!("{}\n", sweep.sampler);
        t += &table::render(
            &["samples", "chi2 p", "chi2", "normalization", "all", "GPU s", "wall s"],
            sweep.points.iter().map(|p| {
                vec![
                    p.samples.to_string(),
                    format!("{:.3e}", p.p_value),
                    verdict(p.chi2_passed).into(),
                    verdict(p.normalization_passed).into(),
                    verdict(p.passed).into(),
                    seconds(p.gpu_seconds),
                    format!("{:.2}", p.seconds),
                ]
            }),
        );
        t += "\nfrom which count each test of the χ² family and each check catches the error:\n";
        t += &table::render(
            &["test", "kind", "caught from", "GPU s", "wall s"],
            sweep.tests.iter().map(|r| {
                let kind = match r.kind {
                    check::power::TestKind::Chi2Family => "chi2 family",
                    check::power::TestKind::Check => "check",
                };
                match &r.caught {
                    Some(c) => vec![r.test.clone(), kind.into(), c.samples.to_string(), seconds(c.gpu_seconds), format!("{:.2}", c.seconds)],
                    None => vec![r.test.clone(), kind.into(), "-".into(), "-".into(), "-".into()],
                }
            }),
        );
        t += &sweep.verdict();
        t.push('\n');
        emit(&t)?;
    }
    if !sweep.passed {
        return Err(super::ChecksFailed(format!("{}: {}", sweep.sampler, sweep.verdict())).into());
    }
    Ok(())
}
