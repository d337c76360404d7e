//! Testing your own sampler: `lobes check` for any WGSL sampler and pdf.
//!
//! A renderer's WGSL file defines, under names of its choosing (the contract, in
//! `docs/testing-your-own-sampler.md`):
//!
//! ```wgsl
//! fn my_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> // (d, pdf)
//! fn my_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32
//! fn my_eval(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32          // optional
//! ```
//!
//! and [`check`] judges it on the GPU as lobes judges its own samplers:
//! 1. `chi2`: the GPU histogram of the samples against the expected histogram, the user's pdf
//!    integrated per bin by adaptive quadrature on the GPU ([`quadrature`]);
//! 2. `pdf_consistency`: the pdf the sampler reports against the pdf function at the same point;
//! 3. `jacobian`: the pdf against the finite-difference Jacobian of the map u ↦ d ([`jacobian`]);
//! 4. `weights` and `albedo` (with an eval): eval/pdf from the sampler against eval/pdf(d), and
//!    the mean weight against the quadrature of eval;
//! 5. `hard_cases`: u at 0, 2⁻²⁴, ½, 1 − 2⁻²⁴, 1 and grazing or below-surface incidence
//!    ([`hard`]);
//! 6. `pdf_values`: the pdf never NaN, ∞ or negative at the quadrature's nodes;
//! 7. `normalization`: ∫pdf over the domain against the fraction of valid samples: a pdf off by a
//!    constant factor (a wrong normalisation, an approximated G1) shows here at any sample count.
//!
//! It returns a [`Report`] with each check's typed figures ([`report`]); [`power`] runs it at
//! growing sample counts. `lobes check --out` draws the histogram with `crate::report::check`.
//!
//! ```no_run
//! use lobes::check::{check, Settings, UserSampler, Domain};
//! let sampler = UserSampler::from_files(&["my_ggx.wgsl".into()], "my_sample", "my_pdf", None, Domain::Sphere)?;
//! let gpu = lobes::engine::gpu::Gpu::new()?;
//! let report = check(&gpu, &sampler, &Settings { params: vec![0.3, 0.3], ..Settings::default() })?;
//! report.assert_passed();
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod budget;
mod builtin;
mod call_graph;
pub mod compose;
pub mod composition;
pub mod conventions;
pub mod dialect;
mod exr;
mod glue;
mod gpu;
pub mod hard;
pub mod modules;
pub mod jacobian;
mod judge;
pub mod light;
mod message;
pub mod power;
pub mod probe;
pub mod quadrature;
pub mod report;
pub mod resources;
mod shaders;
pub mod support;

pub use compose::Source;
pub use message::Message;
pub use conventions::{Conventions, Frame, Incident, Measure};
/// glam, whose `DVec3` [`Reference`] takes: a renderer's tests need no glam of their own.
pub use glam;
pub use composition::{Composition, Dialect, Draw, SampleReturns};
pub use report::{Check, Figures, InvalidCounts, Report};

use crate::engine::gpu::{Gpu, GpuError};
use report::REPORT_VERSION;
use std::path::PathBuf;

/// Why a check could not be run (as opposed to a check that ran and failed).
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// Bad input: a flag, a file, a function name.
    #[error("{0}")]
    Input(String),
    /// Bad input whose message names the settings that would mend it (the command line shows
    /// each by its flag, a scene by its key).
    #[error("{0}")]
    Advised(Message),
    /// The user's WGSL does not parse or validate; the message points at file:line:column.
    #[error("{0}")]
    Wgsl(String),
    /// The device failed (lost, out of memory, readback).
    #[error("the GPU failed: {0}")]
    Device(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A setting of [`Settings`] out of its range, named by its [`Setting`] (the command line
    /// says its flag, a scene its key).
    #[error("{}: {message}", setting.key())]
    Setting { setting: Setting, message: String },
    /// A fault of lobes itself.
    #[error("internal error in lobes check: {0}")]
    Internal(String),
    /// The expected histogram is not accurate enough to judge by (the quadrature of the pdf did
    /// not converge, [`quadrature::Integrals::converged`]): no verdict, neither pass nor fail
    /// (exit 3, as `lobes run`'s unconverged reference); the message may name settings.
    #[error("{0}")]
    NoVerdict(Message),
}

impl CheckError {
    /// A setting's error: `message` says what is wrong with its value.
    pub fn setting(setting: Setting, message: impl Into<String>) -> Self {
        CheckError::Setting { setting, message: message.into() }
    }

    /// Whether the error is the user's input (exit code 2) rather than a failure to run (1).
    pub fn is_input(&self) -> bool {
        matches!(self, CheckError::Input(_) | CheckError::Advised(_) | CheckError::Wgsl(_) | CheckError::Setting { .. })
    }
}

/// A field of [`Settings`], of a sampler's [`Composition`] or one of its call expressions
/// ([`composition::Call`]), as errors name it: the command line by its flag, a scene by its key
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

pub use crate::stats::domain::Domain;

/// A user's sampler: WGSL files and how to call its functions.
///
/// `sample`, `pdf` and `eval` are each a function name with the contract's signature, or a WGSL
/// call expression over lobes' names `wi`, `u` (sample), `d` (pdf, eval), `params`, `p0` … `p15`
/// and `rng` (a `ptr<function, u32>` seeded per sample); `composition` says where imported
/// modules are found and which functions are the user's RNG ([`Composition`]).
#[derive(Debug, Clone, PartialEq)]
pub struct UserSampler {
    pub sources: Vec<Source>,
    pub sample: String,
    pub pdf: String,
    pub eval: Option<String>,
    pub domain: Domain,
    /// How the sampler is written: its frame, measure and declared domain ([`Conventions`]).
    pub conventions: Conventions,
    /// How its files are composed and its functions called ([`Composition`]).
    pub composition: Composition,
}

/// The user's parameters: at most this many numbers (`params: array<vec4<f32>, 4>`).
pub const MAX_PARAMS: usize = 16;

impl UserSampler {
    /// The pdf at a sample's d as the user named it, for messages: `NAME(d)` for a function
    /// name (`my_pdf(d)`), a call expression as written (`ggx_vndf_pdf(wi, d, p0)`, never
    /// `ggx_vndf_pdf(wi, d, p0)(d)`).
    pub fn pdf_at_d(&self) -> String {
        if composition::is_name(self.pdf.trim()) { format!("{}(d)", self.pdf.trim()) } else { self.pdf.clone() }
    }

    /// Reads the files (in order) and checks the functions against the contract.
    pub fn from_files(paths: &[PathBuf], sample: &str, pdf: &str, eval: Option<&str>, domain: Domain) -> Result<Self, CheckError> {
        Self::from_repository(paths, sample, pdf, eval, domain, Composition::default())
    }

    /// [`Self::from_files`] for files as they are in a renderer's repository: imports found
    /// under the shader roots, call expressions, the renderer's own RNG.
    ///
    /// ```no_run
    /// use lobes::check::{check, Composition, Domain, Settings, UserSampler};
    /// let composition = Composition::default()
    ///     .shader_root("shaders")
    ///     .stub("package::bindings", "tests/no_bindings.wesl")
    ///     .rand("rand_f");
    /// let sampler = UserSampler::from_repository(
    ///     &["shaders/sampling.wesl".into()],
    ///     "sample_ggx_vndf(wi, p0, rng)",
    ///     "ggx_vndf_pdf(wi, d, p0)",
    ///     None,
    ///     Domain::Sphere,
    ///     composition,
    /// )?;
    /// let gpu = lobes::engine::gpu::Gpu::new()?;
    /// check(&gpu, &sampler, &Settings { params: vec![0.3], ..Settings::default() })?.assert_passed();
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_repository(paths: &[PathBuf], sample: &str, pdf: &str, eval: Option<&str>, domain: Domain, composition: Composition) -> Result<Self, CheckError> {
        let sources = paths.iter().map(|p| Source::read(p)).collect::<Result<Vec<_>, _>>()?;
        Self::build(sources, sample, pdf, eval, domain, composition)
    }

    /// As [`UserSampler::from_files`], from texts already read (a renderer's `include_str!`),
    /// in lobes' conventions ([`UserSampler::with_conventions`] declares others).
    ///
    /// ```
    /// use lobes::check::{Conventions, Domain, Source, UserSampler};
    /// let text = "fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> { return vec4<f32>(0.0, 0.0, 1.0, 1.0); }\n\
    ///             fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 { return 1.0; }";
    /// let s = UserSampler::from_sources(vec![Source { name: "s.wgsl".into(), text: text.into() }], "s", "p", None, Domain::Sphere)?
    ///     .with_conventions(Conventions { u_open: true, ..Conventions::default() })?;
    /// assert!(s.conventions.u_open);
    /// # Ok::<(), lobes::check::CheckError>(())
    /// ```
    pub fn from_sources(sources: Vec<Source>, sample: &str, pdf: &str, eval: Option<&str>, domain: Domain) -> Result<Self, CheckError> {
        Self::build(sources, sample, pdf, eval, domain, Composition::default())
    }

    fn build(sources: Vec<Source>, sample: &str, pdf: &str, eval: Option<&str>, domain: Domain, composition: Composition) -> Result<Self, CheckError> {
        let s = Self { sources, sample: sample.into(), pdf: pdf.into(), eval: eval.map(Into::into), domain, conventions: Conventions::default(), composition };
        s.validate_code()?;
        Ok(s)
    }

    /// The same sampler declared in `conventions` (`--incident upper`, `--reflection-only`, …).
    pub fn with_conventions(self, conventions: Conventions) -> Result<Self, CheckError> {
        let s = Self { conventions, ..self };
        s.conventions.validate(s.domain)?;
        s.light_measure()?;
        Ok(s)
    }

    /// `--measure area` and `--normal` come together, and not with a half vector.
    fn light_measure(&self) -> Result<(), CheckError> {
        let area = self.conventions.measure == conventions::Measure::Area;
        match (area, &self.composition.normal) {
            (true, None) => Err(CheckError::setting(
                Setting::Normal,
                "needed with the area measure (a sample that is a point of a light): the light's unit normal at the sampled point p, WGSL over p and params, for the area-to-solid-angle factor |p|²/|n·d|",
            )),
            (false, Some(_)) => Err(CheckError::setting(Setting::Normal, "only with the area measure (a sample that is a point of a light, with its area density); remove it")),
            (true, Some(_)) if self.composition.sample_returns == SampleReturns::HalfVector => {
                Err(CheckError::setting(Setting::SampleReturns, "a half vector is not a light's point (the area measure); keep one"))
            }
            _ => Ok(()),
        }
    }

    /// The conventions must fit the domain and each other, and the code [`Self::validate_code`].
    pub fn validate(&self) -> Result<(), CheckError> {
        self.conventions.validate(self.domain)?;
        self.light_measure()?;
        self.validate_code()
    }

    /// The files alone must validate, define the named functions with the contract's
    /// signatures, and leave lobes' own names free.
    fn validate_code(&self) -> Result<(), CheckError> {
        self.domain.validate().map_err(|e| CheckError::setting(Setting::Bounds, e.to_string()))?;
        if self.composition.sample_returns == SampleReturns::HalfVector && !self.domain.directions() {
            return Err(CheckError::setting(Setting::SampleReturns, "a half vector reflects wi into a direction; a point of the plane is none"));
        }
        let code = modules::compose_user(&self.sources, &self.composition)?;
        // a name is a function of the contract's signature; an expression is judged in the glue
        let mut functions = vec![(self.sample.as_str(), compose::SAMPLE), (self.pdf.as_str(), compose::PDF)];
        if let Some(e) = &self.eval {
            functions.push((e.as_str(), compose::EVAL));
        }
        functions.retain(|(n, _)| composition::is_name(n));
        let module = compose::check_user(&code.parts, &code.decls, &functions)?;
        let imported = |n: &String| code.origins.iter().any(|o| &o.0 == n);
        if let Some(name) = compose::global_names(&module).into_iter().find(|n| gpu::reserved(n) && !imported(n)) {
            return Err(CheckError::Input(format!(
                "{}: the name `{name}` is lobes' own (its RNG or a `lobes_` name); rename it in your file",
                self.sources.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
            )));
        }
        // the glue's own errors (a call expression's, a --rand function's) now, not at the GPU
        glue::prepare(self, gpu::default_order(self))?;
        Ok(())
    }

    /// The composed WGSL of lobes' passes with the user's files and glue (the probes, the
    /// quadrature, the weights), one module that `check` runs.
    pub fn composed(&self) -> Result<String, CheckError> {
        Ok(gpu::compose(self)?.text)
    }

    /// The composed WGSL of the histogram on a `rows` × `cols` grid as `check` counts it on an
    /// adapter of `device` type with `limits`: `lobes run`'s counting kernel drawing the
    /// sampler, the other module that `check` runs.
    pub fn composed_histogram(&self, device: wgpu::DeviceType, limits: &wgpu::Limits, rows: u32, cols: u32) -> Result<String, CheckError> {
        let (tiling, counting) = gpu::histogram_counting(device, limits, rows * cols, None)?;
        Ok(gpu::compose_histogram(self, gpu::default_order(self), (rows, cols, tiling.tile_bins as u32), counting, &[])?.0.text)
    }
}

/// How to check.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// The user's numbers (at most 16), zero-padded into `params`.
    pub params: Vec<f64>,
    /// Incident direction: θ from the normal (+z) and φ from +x, in degrees.
    pub incident_theta: f64,
    pub incident_phi: f64,
    pub samples: u64,
    /// Histogram rows × cols; `None` takes 64 × 128 on the sphere, 64 × 64 on the plane.
    pub bins: Option<(u32, u32)>,
    pub seed: u64,
    /// Significance of the χ² and albedo tests.
    pub significance: f64,
    /// Samples probed for the Jacobian and pdf-consistency checks.
    pub probe_samples: u32,
    /// An f64 reference pdf p(wi, d) on the CPU (the design's "CPU reference"): when given, the
    /// expected histogram integrates it instead of the WGSL pdf, in f64.
    pub reference: Option<Reference>,
    /// The time the whole check may take ([`DEFAULT_TIMEOUT`]; at most [`MAX_TIMEOUT_SECONDS`]): the
    /// GPU's work still unfinished then ends the check with [`GpuError::TimedOut`] (a sampler
    /// that loops forever never returns), and the device is abandoned
    /// ([`crate::engine::gpu::context::Bounds`]).
    pub timeout: std::time::Duration,
    /// Whether a sampler on the sphere whose samples fall in a small cap is binned on a grid
    /// fitted to it ([`support`]).
    pub fit: support::Fit,
}

/// The time a check may take unless told otherwise: 10 minutes (the default 2²² samples take
/// seconds on lavapipe; 2³² samples of a costly sampler on a laptop's GPU take minutes).
pub const DEFAULT_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(600);
/// The longest `timeout` allowed: 10⁶ s (11.6 days).
pub const MAX_TIMEOUT_SECONDS: f64 = 1e6;

/// An f64 pdf p(wi, d) written in Rust, integrated with the f64 quadrature instead of the WGSL pdf.
///
/// ```
/// // glam is re-exported: a renderer's tests need no glam dependency of their own
/// use lobes::check::glam::DVec3;
/// let uniform = lobes::check::Reference::new(|_wi: DVec3, _d: DVec3| 1.0 / (4.0 * std::f64::consts::PI));
/// assert!(((uniform.0)(DVec3::Z, DVec3::X) - 0.0795775).abs() < 1e-7);
/// ```
#[derive(Clone)]
pub struct Reference(pub std::sync::Arc<dyn Fn(glam::DVec3, glam::DVec3) -> f64 + Send + Sync>);

impl Reference {
    pub fn new(pdf: impl Fn(glam::DVec3, glam::DVec3) -> f64 + Send + Sync + 'static) -> Self {
        Self(std::sync::Arc::new(pdf))
    }
}

impl std::fmt::Debug for Reference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Reference(f64 pdf)")
    }
}

impl PartialEq for Reference {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            params: Vec::new(),
            incident_theta: 30.0,
            incident_phi: 0.0,
            samples: 1 << 22,
            bins: None,
            seed: 1,
            significance: 0.01,
            probe_samples: 4096,
            reference: None,
            timeout: DEFAULT_TIMEOUT,
            fit: support::Fit::Auto,
        }
    }
}

impl Settings {
    pub fn grid(&self, domain: &Domain) -> (u32, u32) {
        self.bins.unwrap_or(domain.default_grid())
    }
    /// Bad input, named by its [`Setting`]: more than 16 params or one that is not a finite
    /// f32 (named by its index), an incident θ outside [0, 180], no samples, an empty or too
    /// large grid, a significance outside (0, 1).
    ///
    /// ```
    /// use lobes::check::{CheckError, Setting, Settings};
    /// let e = Settings { incident_theta: 200.0, ..Settings::default() }.validate().unwrap_err();
    /// assert!(matches!(e, CheckError::Setting { setting: Setting::IncidentTheta, .. }));
    /// assert_eq!(e.to_string(), "incident_theta: 200 is outside [0, 180] degrees");
    /// ```
    pub fn validate(&self) -> Result<(), CheckError> {
        let bad = |setting, message: String| Err(CheckError::setting(setting, message));
        if self.params.len() > MAX_PARAMS {
            return bad(Setting::Params, format!("{} numbers given, at most {MAX_PARAMS} fit `params: array<vec4<f32>, 4>`", self.params.len()));
        }
        // the shader's params are f32: 1e39 is finite here and ∞ there
        if let Some((i, p)) = self.params.iter().enumerate().find(|(_, p)| !(**p as f32).is_finite()) {
            let why = if p.is_finite() { format!("{p:e}, beyond f32's range (±{:e}): params are f32 in WGSL", f32::MAX) } else { format!("{p}, not a finite number") };
            return bad(Setting::Params, format!("the item at index {i} (counting from 0) is {why}"));
        }
        if !(self.incident_theta.is_finite() && (0.0..=180.0).contains(&self.incident_theta)) {
            return bad(Setting::IncidentTheta, format!("{} is outside [0, 180] degrees", self.incident_theta));
        }
        if !self.incident_phi.is_finite() {
            return bad(Setting::IncidentPhi, format!("{} is not finite", self.incident_phi));
        }
        if !(1..=crate::engine::job::MAX_SAMPLES).contains(&self.samples) {
            return bad(Setting::Samples, format!("{} is not allowed; give a whole number from 1 to 2^40 ({})", self.samples, crate::engine::job::MAX_SAMPLES));
        }
        let t = self.timeout.as_secs_f64();
        if !(t > 0.0 && t <= MAX_TIMEOUT_SECONDS) {
            return bad(Setting::Timeout, format!("{t} s is not allowed; give seconds > 0, at most {MAX_TIMEOUT_SECONDS:e}"));
        }
        if let Some((r, c)) = self.bins
            && (r == 0 || c == 0 || r as u64 * c as u64 > 1 << 24)
        {
            return bad(Setting::Bins, format!("{r},{c}: rows and cols must be ≥ 1 with at most 2^24 bins"));
        }
        if !(self.significance > 0.0 && self.significance < 1.0) {
            return bad(Setting::Significance, format!("{} is outside (0, 1)", self.significance));
        }
        Ok(())
    }
}

/// The incident direction at θ, φ in degrees (lobes' frame; the same numbers in a y-up frame,
/// `conventions::Frame`).
pub(crate) fn incident(theta: f64, phi: f64) -> [f32; 3] {
    let w = crate::reference::reflect::spherical(theta.to_radians(), phi.to_radians());
    [w.x as f32, w.y as f32, w.z as f32]
}

/// Largest relative difference allowed between the reported pdf and the pdf function (f32
/// evaluation of the same formula in two places: agreement to a few ulps is expected, 10⁻³
/// leaves room for a differently-ordered but equivalent expression), where the pdf is well
/// conditioned; see [`CONDITIONING_ULPS`].
pub const PDF_CONSISTENCY_LIMIT: f64 = 1e-3;

/// Pointwise comparisons of the pdf (`pdf_consistency`, `jacobian`, `weights`) allow, on top of
/// their limit, this many times the pdf's f32 conditioning at the point: the largest relative
/// change of pdf(d) under a change of one component of d by 2⁻²³ |d|∞, measured on the GPU
/// (`lobes_conditioning_at` in shaders/check/user_passes.wgsl). A narrow lobe amplifies an ulp:
/// GGX's D(m) in the form α² / (π ((α² − 1) m.z² + 1)²) turns an ulp of m.z into ≈ 4/α² ulps of
/// D (0.4 % at α = 0.008), so a correct sampler and its pdf, the same f32 code compiled at two
/// call sites, differ by that much. A sampler's d carries a few ulps of rounding: 4 of them.
pub const CONDITIONING_ULPS: f64 = 4.0;

/// The passes' parameters of a check: the user's numbers, the incident direction, the seed and
/// the grid.
fn params_of(sampler: &UserSampler, settings: &Settings) -> gpu::Params {
    let (rows, cols) = settings.grid(&sampler.domain);
    let mut user = [[0f32; 4]; 4];
    for (i, p) in settings.params.iter().enumerate() {
        user[i / 4][i % 4] = *p as f32;
    }
    let wi = incident(settings.incident_theta, settings.incident_phi);
    let bounds = sampler.domain.uniform_bounds();
    gpu::Params {
        user,
        wi: [wi[0], wi[1], wi[2], 0.0],
        bounds,
        seed: gpu::split(settings.seed),
        eps: jacobian::EPS,
        samples_per_thread: 1,
        rows,
        cols,
        ..bytemuck::Zeroable::zeroed()
    }
}

/// The sampler's passes, with the user's --rand draws (at most four) in the order lobes' probe
/// finds them unless --rand-order gave it, and the note on that order for the report.
fn compose_passes<'g>(gpu: &'g Gpu, sampler: &UserSampler, settings: &Settings, params: &gpu::Params) -> Result<(gpu::Passes<'g>, String), CheckError> {
    let mut passes = gpu::Passes::new(gpu, sampler)?;
    let mut draws = String::new();
    if !sampler.composition.rand.is_empty() {
        let (order, note) = gpu::rand_order(&passes, params, sampler, settings.seed)?;
        if sampler.composition.rand_order.is_none() && order != Draw::components(&[]) {
            passes = gpu::Passes::ordered(gpu, sampler, order)?;
        }
        draws = note;
    }
    Ok((passes, draws))
}

/// The histograms alone (none of the other checks) of `sampler` at each (samples, seed) of
/// `runs`, the passes composed once: counts per bin then per reason of [`crate::reference::Invalid::ALL`], and the
/// wall seconds of each histogram. For measurements over many seeds and counts (`lobes
/// tradeoff`'s detection table), judged against the expected counts of one [`check`] of the
/// same settings, on the sampler's own domain: a grid fitted to the samples
/// ([`support`]) would differ from run to run, so such a check takes `fit: Fit::Never`.
pub fn histograms(gpu: &Gpu, sampler: &UserSampler, settings: &Settings, runs: &[(u64, u64)]) -> Result<Vec<(Vec<u64>, f64)>, CheckError> {
    settings.validate()?;
    let _deadline = gpu.deadline(settings.timeout);
    sampler.validate()?;
    let (passes, _) = compose_passes(gpu, sampler, settings, &params_of(sampler, settings))?;
    runs.iter()
        .map(|&(samples, seed)| {
            let params = params_of(sampler, &Settings { seed, ..settings.clone() });
            let started = std::time::Instant::now();
            let counts = gpu::histogram(&passes, &params, sampler, samples)?;
            Ok((counts, started.elapsed().as_secs_f64()))
        })
        .collect()
}

/// Runs every check of `sampler` on `gpu`: measures once ([`judge::measure`]), then judges.
pub fn check(gpu: &Gpu, sampler: &UserSampler, settings: &Settings) -> Result<Report, CheckError> {
    let started = std::time::Instant::now();
    settings.validate()?;
    let _deadline = gpu.deadline(settings.timeout);
    sampler.validate()?;
    if sampler.domain.directions() {
        sampler.conventions.check_incident(settings.incident_theta)?;
    }
    let run = judge::Run::new(gpu, sampler, settings)?;
    let m = judge::measure(&run)?;
    judge::require_converged(&run, &m)?;
    let pointwise = vec![judge::pdf_consistency::check(&run, &m), judge::jacobian::check(&run, &m), judge::pdf_values::check(&run, &m)?];
    let mut integral = vec![judge::normalization::check(&run, &m), judge::chi2::check(&run, &m)?];
    if sampler.eval.is_some() {
        integral.extend(judge::weights::check(&run, &m)?);
    }
    let hard = judge::hard_cases::check(&run)?;
    // a support narrower than the nodes decides nothing by its integrals, nor does a χ² its pdf's
    // f32 rounding could fail; a failing point does
    if pointwise.iter().chain([&hard]).all(|c| c.passed) {
        m.integrals.support_seen().map_err(CheckError::NoVerdict)?;
        let chi2_passed = integral.iter().all(|c| !matches!(c.figures, report::Figures::Chi2(_)) || c.passed);
        judge::normalization::rounding_resolved(&run, &m, chi2_passed).map_err(CheckError::NoVerdict)?;
    }
    let checks = pointwise.into_iter().chain(integral).chain([hard]).collect();
    Ok(report(&run, &m, checks, gpu.adapter_name(), started))
}

/// The report of `checks` over the measurement `m` of `run`.
fn report(run: &judge::Run, m: &judge::Measured, checks: Vec<Check>, adapter: String, started: std::time::Instant) -> Report {
    let bins = run.bins();
    // what the report holds and the pictures draw: the pdf's signed integral, below 0 where the
    // pdf is (the χ² leaves those parts out, and `pdf_values` fails)
    let n = run.samples();
    let expected = if m.integrals.dropped.is_empty() {
        judge::chi2::expected(run, m)
    } else {
        m.integrals.probabilities.iter().zip(&m.integrals.dropped).map(|(p, d)| n * (p + d)).collect()
    };
    Report {
        format_version: REPORT_VERSION,
        passed: checks.iter().all(|c| c.passed),
        checks,
        sampler: describe(&run.sampler) + &run.draws,
        domain: run.sampler.domain,
        samples: run.settings.samples,
        rows: run.rows,
        cols: run.cols,
        adapter,
        gpu_seconds: run.passes.gpu_seconds(),
        wall_seconds: started.elapsed().as_secs_f64(),
        counts: m.counts(bins).to_vec(),
        invalid: m.invalid(bins),
        expected,
    }
}

/// Why a half-vector sampler's pdf may defeat the quadrature without a fault of its own, for a
/// no-verdict message: with `--sample-returns half-vector` and reflections below the surface kept,
/// the density of d = 2 (wi·h) h − wi is p(h) / (4 wi·h) with h = normalize(wi + d), which has an
/// integrable pole at d = −wi wherever p(h) is not 0 for h ⊥ wi (NDF sampling: D(h) cos θh at
/// θi > 0); no f32 quadrature resolves it, and the f32 pdf may be ∞ or NaN beside it. `bad_at`:
/// for bad pdf values, the (θ, φ) in degrees of the worst one (None: between a fine grid's
/// points), which must lie within 1° of −wi; None for an unconverged quadrature.
fn half_vector_pole(sampler: &UserSampler, settings: &Settings, bad_at: Option<Option<(f64, f64)>>) -> Option<Message> {
    if sampler.composition.sample_returns != SampleReturns::HalfVector || sampler.conventions.reflection_only || !sampler.domain.directions() {
        return None;
    }
    let pole = crate::reference::reflect::spherical((180.0 - settings.incident_theta).to_radians(), (settings.incident_phi + 180.0).to_radians());
    if let Some(Some((theta, phi))) = bad_at
        && crate::reference::reflect::spherical(theta.to_radians(), phi.to_radians()).dot(pole).clamp(-1.0, 1.0).acos() > 1f64.to_radians()
    {
        return None;
    }
    let (t, p) = (pole.z.clamp(-1.0, 1.0).acos().to_degrees(), pole.y.atan2(pole.x).to_degrees());
    Some(
        Message::text("; with ")
            .setting(Setting::SampleReturns)
            .then(format!(" half-vector the density of the reflected d, p(h) / (4 wi·h), has an integrable pole at d = −wi (θ {t:.1}°, φ {p:.1}°) where p(h) is not 0 for h ⊥ wi (NDF sampling), which no f32 quadrature resolves: no verdict. A sampler whose renderer discards reflections under the surface is checked with "))
            .setting(Setting::ReflectionOnly)
            .then(" (they are then rejections, and d = −wi is one of them)"),
    )
}

/// The invalid cell's expected count, for `invalid` of N = `samples` samples where the pdf
/// integrates to `pdf_total` over the domain, known to `resolution`: N × the observed invalid
/// fraction clamped into 1 − ∫pdf ± 2 × resolution, the value within that band closest to what
/// was observed, so that neither a rejection the pdf allows nor the quadrature's own error reads
/// as a sampler's fault (a rejection rate under the band is below what the test can see, even
/// where the pdf integrates to more than 1). Twice the resolution, as `normalization`'s
/// tolerance: the error estimate is the coarse rule's, and across a jump of the pdf the accepted
/// finer value is off by as much (a uniform cone of half-angle 0.3 rad about the normal: ∫pdf
/// 0.999830 with an error estimate of 1.65·10⁻⁴; within 1× the cell expected 12 samples where
/// none can be, a false fail at 2 of 3 seeds).
///
/// ```
/// // a pdf that integrates to 0.9998 known to 10⁻⁴ leaves 2·10⁻⁴ ± 2·10⁻⁴ to rejections:
/// // 0 or 300 rejected of 10⁶ both read as allowed
/// assert_eq!(lobes::check::invalid_expectation(1_000_000, 0, 0.9998, 1e-4), 0.0);
/// assert!((lobes::check::invalid_expectation(1_000_000, 300, 0.9998, 1e-4) - 300.0).abs() < 1e-6);
/// // 2 000 rejected is beyond 4·10⁻⁴: the cell expects 400
/// assert!((lobes::check::invalid_expectation(1_000_000, 2_000, 0.9998, 1e-4) - 400.0).abs() < 1e-6);
/// ```
pub fn invalid_expectation(samples: u64, invalid: u64, pdf_total: f64, resolution: f64) -> f64 {
    let n = samples.max(1) as f64;
    let (missing, band) = (1.0 - pdf_total, 2.0 * resolution);
    n * (invalid as f64 / n).clamp((missing - band).max(0.0), (missing + band).max(band))
}

/// "my_sample/my_pdf in file.wgsl", and the conventions declared: "… (reflection-only)".
fn describe(s: &UserSampler) -> String {
    let files: Vec<&str> = s.sources.iter().map(|f| f.name.as_str()).collect();
    let conventions = if s.conventions.is_default() { String::new() } else { format!(" ({})", s.conventions.declared()) };
    format!("{}/{} in {}{conventions}", s.sample, s.pdf, files.join(", "))
}

