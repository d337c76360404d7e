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
pub mod compose;
pub mod conventions;
mod gpu;
pub mod hard;
pub mod modules;
pub mod jacobian;
mod pdf_values;
pub mod power;
pub mod quadrature;
pub mod report;

pub use compose::Source;
pub use conventions::{Conventions, Frame, Incident, Measure};
/// glam, whose `DVec3` [`Reference`] takes: a renderer's tests need no glam of their own.
pub use glam;
pub use modules::{Composition, Dialect, Draw, SampleReturns};
pub use report::{Check, Figures, REASONS, Report};

use crate::engine::gpu::{Gpu, GpuError};
use crate::reference::rng;
use crate::stats::family;
use report::{AlbedoFigures, Chi2Figures, ConsistencyFigures, NormalizationFigures, PdfValuesFigures, REPORT_VERSION, WeightFigures};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Why a check could not be run (as opposed to a check that ran and failed).
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// Bad input: a flag, a file, a function name.
    #[error("{0}")]
    Input(String),
    /// The user's WGSL does not parse or validate; the message points at file:line:column.
    #[error("{0}")]
    Wgsl(String),
    /// The device failed (lost, out of memory, readback).
    #[error("the GPU failed: {0}")]
    Device(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A fault of lobes itself.
    #[error("internal error in lobes check: {0}")]
    Internal(String),
    /// The expected histogram is not accurate enough to judge by (the quadrature of the pdf did
    /// not converge, [`quadrature::Integrals::converged`]): no verdict, neither pass nor fail
    /// (exit 3, as `lobes run`'s unconverged reference).
    #[error("{0}")]
    NoVerdict(String),
}

impl CheckError {
    /// Whether the error is the user's input (exit code 2) rather than a failure to run (1).
    pub fn is_input(&self) -> bool {
        matches!(self, CheckError::Input(_) | CheckError::Wgsl(_))
    }
}

/// Where the sampled points live.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "lowercase", tag = "kind")]
pub enum Domain {
    /// Unit directions anywhere on the sphere, binned in (cos θ, φ) as lobes bins its lobes.
    Sphere,
    /// Points (d.x, d.y) of the box `[x0, y0, x1, y1]`, binned on a rows × cols grid of it.
    Plane { bounds: [f64; 4] },
}

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
        if gpu::is_name(self.pdf.trim()) { format!("{}(d)", self.pdf.trim()) } else { self.pdf.clone() }
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
        s.validate()?;
        Ok(s)
    }

    /// The same sampler declared in `conventions` (`--incident upper`, `--reflection-only`, …).
    pub fn with_conventions(self, conventions: Conventions) -> Result<Self, CheckError> {
        let s = Self { conventions, ..self };
        s.conventions.validate(matches!(s.domain, Domain::Plane { .. }))?;
        Ok(s)
    }

    /// The files alone must validate, define the named functions with the contract's
    /// signatures, and leave lobes' own names free.
    pub fn validate(&self) -> Result<(), CheckError> {
        if let Domain::Plane { bounds: [x0, y0, x1, y1] } = self.domain
            && !(x0 < x1 && y0 < y1 && [x0, y0, x1, y1].iter().all(|v| v.is_finite()))
        {
            return Err(CheckError::Input(format!("--bounds: {x0},{y0},{x1},{y1} is not a box: need X0 < X1 and Y0 < Y1, all finite")));
        }
        self.conventions.validate(matches!(self.domain, Domain::Plane { .. }))?;
        if self.composition.sample_returns == SampleReturns::HalfVector && matches!(self.domain, Domain::Plane { .. }) {
            return Err(CheckError::Input("--sample-returns half-vector: a half vector reflects wi into a direction; it does not apply to --domain plane".into()));
        }
        let code = modules::compose_user(&self.sources, &self.composition)?;
        // a name is a function of the contract's signature; an expression is judged in the glue
        let mut functions = vec![(self.sample.as_str(), compose::SAMPLE), (self.pdf.as_str(), compose::PDF)];
        if let Some(e) = &self.eval {
            functions.push((e.as_str(), compose::EVAL));
        }
        functions.retain(|(n, _)| gpu::is_name(n));
        let module = compose::check_user(&code.parts, &code.decls, &functions)?;
        let imported = |n: &String| code.origins.iter().any(|o| &o.0 == n);
        if let Some(name) = compose::global_names(&module).into_iter().find(|n| gpu::reserved(n) && !imported(n)) {
            return Err(CheckError::Input(format!(
                "{}: the name `{name}` is lobes' own (its RNG or a `lobes_` name); rename it in your file",
                self.sources.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
            )));
        }
        // the glue's own errors (a call expression's, a --rand function's) now, not at the GPU
        gpu::prepare(self, Draw::components(self.composition.rand_order.as_deref().unwrap_or(&[])))?;
        Ok(())
    }

    /// The composed WGSL that `check` runs (the user's files, the glue, lobes' passes).
    pub fn composed(&self) -> Result<String, CheckError> {
        Ok(gpu::compose(self)?.text)
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
    /// ([`crate::engine::gpu::dispatch::Bounds`]).
    pub timeout: std::time::Duration,
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
        }
    }
}

impl Settings {
    pub fn grid(&self, domain: &Domain) -> (u32, u32) {
        self.bins.unwrap_or(match domain {
            Domain::Sphere => (64, 128),
            Domain::Plane { .. } => (64, 64),
        })
    }
    /// Bad input, named by its command-line flag: more than 16 params, an incident θ outside
    /// [0, 180], no samples, an empty or too large grid, a significance outside (0, 1).
    pub fn validate(&self) -> Result<(), CheckError> {
        let bad = |flag: &str, what: String| Err(CheckError::Input(format!("{flag}: {what}")));
        if self.params.len() > MAX_PARAMS {
            return bad("--params", format!("{} numbers given, at most {MAX_PARAMS} fit `params: array<vec4<f32>, 4>`", self.params.len()));
        }
        if let Some(p) = self.params.iter().find(|p| !p.is_finite()) {
            return bad("--params", format!("{p} is not a finite number"));
        }
        if !(self.incident_theta.is_finite() && (0.0..=180.0).contains(&self.incident_theta)) {
            return bad("--incident-theta", format!("{} is outside [0, 180] degrees", self.incident_theta));
        }
        if !self.incident_phi.is_finite() {
            return bad("--incident-phi", format!("{} is not finite", self.incident_phi));
        }
        if !(1..=crate::engine::job::MAX_SAMPLES).contains(&self.samples) {
            return bad("--samples", format!("{} is not allowed; give a whole number from 1 to 2^40 ({})", self.samples, crate::engine::job::MAX_SAMPLES));
        }
        let t = self.timeout.as_secs_f64();
        if !(t > 0.0 && t <= MAX_TIMEOUT_SECONDS) {
            return bad("--timeout", format!("{t} s is not allowed; give seconds > 0, at most {MAX_TIMEOUT_SECONDS:e}"));
        }
        if let Some((r, c)) = self.bins
            && (r == 0 || c == 0 || r as u64 * c as u64 > 1 << 24)
        {
            return bad("--bins", format!("{r},{c}: rows and cols must be ≥ 1 with at most 2^24 bins"));
        }
        if !(self.significance > 0.0 && self.significance < 1.0) {
            return bad("--significance", format!("{} is outside (0, 1)", self.significance));
        }
        Ok(())
    }
}

/// The incident direction at θ, φ in degrees (lobes' frame; the same numbers in a y-up frame,
/// `conventions::Frame`).
fn incident(theta: f64, phi: f64) -> [f32; 3] {
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
    let bounds = match sampler.domain {
        Domain::Plane { bounds } => bounds.map(|b| b as f32),
        Domain::Sphere => [0.0; 4],
    };
    gpu::Params {
        user,
        wi: [wi[0], wi[1], wi[2], 0.0],
        bounds,
        seed: gpu::split(settings.seed),
        base: [0, 0],
        count: 0,
        eps: jacobian::EPS,
        samples_per_thread: 1,
        rows,
        cols,
        slabs: 0,
        _pad_b: 0,
        _pad_c: 0,
    }
}

/// The sampler's passes, with the user's --rand draws (at most four) in the order lobes' probe
/// finds them unless --rand-order gave it, and the note on that order for the report.
fn compose_passes<'g>(gpu: &'g Gpu, sampler: &UserSampler, settings: &Settings, params: &gpu::Params) -> Result<(gpu::Passes<'g>, String), CheckError> {
    let mut passes = gpu::Passes::new(gpu, &gpu::compose(sampler)?)?;
    let mut draws = String::new();
    if !sampler.composition.rand.is_empty() {
        let (order, note) = gpu::rand_order(&passes, params, sampler, settings.seed)?;
        if sampler.composition.rand_order.is_none() && order != Draw::components(&[]) {
            passes = gpu::Passes::new(gpu, &gpu::compose_ordered(sampler, order)?)?;
        }
        draws = note;
    }
    Ok((passes, draws))
}

/// The most samples of one dispatch of the histogram and weights passes.
const CHUNK: u64 = 1 << 26;

/// The histogram of `samples` samples: counts per bin, then per invalid reason, in dispatches
/// of at most [`CHUNK`] samples.
fn histogram(passes: &gpu::Passes, params: &gpu::Params, samples: u64, bins: usize) -> Result<Vec<u64>, CheckError> {
    let mut totals = vec![0u64; bins + 4];
    let mut first = 0;
    while first < samples {
        let n = CHUNK.min(samples - first) as u32;
        for (t, c) in totals.iter_mut().zip(passes.histogram(params, first, n, bins + 4, None)?) {
            *t += c as u64;
        }
        first += n as u64;
    }
    let counted: u64 = totals.iter().sum();
    if counted != samples {
        return Err(CheckError::Internal(format!("{counted} samples counted for {samples} drawn")));
    }
    Ok(totals)
}

/// The histograms alone (none of the other checks) of `sampler` at each (samples, seed) of
/// `runs`, the passes composed once: counts per bin then per reason of [`REASONS`], and the
/// wall seconds of each histogram. For measurements over many seeds and counts (`lobes
/// tradeoff`'s detection table), judged against the expected counts of one [`check`] of the
/// same settings.
pub fn histograms(gpu: &Gpu, sampler: &UserSampler, settings: &Settings, runs: &[(u64, u64)]) -> Result<Vec<(Vec<u64>, f64)>, CheckError> {
    settings.validate()?;
    let _deadline = gpu.deadline(settings.timeout);
    sampler.validate()?;
    let (rows, cols) = settings.grid(&sampler.domain);
    let (passes, _) = compose_passes(gpu, sampler, settings, &params_of(sampler, settings))?;
    runs.iter()
        .map(|&(samples, seed)| {
            let params = params_of(sampler, &Settings { seed, ..settings.clone() });
            let started = std::time::Instant::now();
            let counts = histogram(&passes, &params, samples, (rows * cols) as usize)?;
            Ok((counts, started.elapsed().as_secs_f64()))
        })
        .collect()
}

/// Runs every check of `sampler` on `gpu`.
pub fn check(gpu: &Gpu, sampler: &UserSampler, settings: &Settings) -> Result<Report, CheckError> {
    let started = std::time::Instant::now();
    settings.validate()?;
    let _deadline = gpu.deadline(settings.timeout);
    sampler.validate()?;
    if !matches!(sampler.domain, Domain::Plane { .. }) {
        sampler.conventions.check_incident(settings.incident_theta)?;
    }
    let (rows, cols) = settings.grid(&sampler.domain);
    let wi = incident(settings.incident_theta, settings.incident_phi);
    let params = params_of(sampler, settings);
    let (passes, draws) = compose_passes(gpu, sampler, settings, &params)?;
    let plane = matches!(sampler.domain, Domain::Plane { .. });
    let mut checks = Vec::new();

    let bins = (rows * cols) as usize;
    let totals = histogram(&passes, &params, settings.samples, bins)?;

    // The probe: uniforms away from the edges by 2ε, so that u ± ε stays in [0, 1].
    let margin = 2.0 * jacobian::EPS as f64;
    let probe_u: Vec<[f32; 4]> = (0..settings.probe_samples as u64)
        .map(|i| rng::uniforms(settings.seed ^ 0x9e37_79b9_7f4a_7c15, i).map(|x| (margin + (1.0 - 2.0 * margin) * x) as f32))
        .collect();
    let items: Vec<([f32; 4], [f32; 3])> = probe_u.iter().map(|u| (*u, wi)).collect();
    let probes = passes.probe(&params, &items)?;

    // The pdf's f32 conditioning at each probe's d (0 where the pdf is not finite and > 0),
    // and the map around each probe at the Jacobian's steps.
    let points: Vec<[f32; 3]> = probes.iter().map(|p| [p[0][0], p[0][1], p[0][2]]).map(|d| if d.iter().all(|x| x.is_finite()) { d } else { [0.0; 3] }).collect();
    let kappa: Vec<f64> = passes.conditioning(&params, &points)?.iter().map(|v| v[1] as f64).collect();
    let around: Vec<[f32; 4]> = probe_u.iter().flat_map(|u| jacobian::around(*u)).collect();
    let at: Vec<[[f32; 4]; jacobian::AROUND]> =
        passes.map(&params, &around)?.chunks(jacobian::AROUND).map(|c| c.try_into().expect("AROUND per probe")).collect();

    // pdf consistency: the reported pdf against the pdf function, at valid samples, each within
    // the limit widened by the pdf's conditioning there.
    let mut consistency = ConsistencyFigures {
        compared: 0,
        max_relative_difference: 0.0,
        pdf_function_not_finite: 0,
        worst_u: [0.0; 4],
        limit: PDF_CONSISTENCY_LIMIT,
        worst_limit: PDF_CONSISTENCY_LIMIT,
        widened: 0,
        over_limit: 0,
    };
    let mut p_max: f64 = 0.0;
    let mut worst = 0.0;
    for ((p, u), k) in probes.iter().zip(&probe_u).zip(&kappa) {
        let (rep, fun) = (p[0][3] as f64, p[6][0] as f64);
        if rep > 0.0 && rep.is_finite() && p[0][..3].iter().all(|x| x.is_finite()) {
            consistency.compared += 1;
            if !fun.is_finite() {
                // the worst of all: the first such sample is the one shown
                if consistency.pdf_function_not_finite == 0 {
                    consistency.worst_u = *u;
                }
                consistency.pdf_function_not_finite += 1;
            } else {
                let diff = (rep - fun).abs() / rep.max(fun);
                let limit = PDF_CONSISTENCY_LIMIT + CONDITIONING_ULPS * k;
                consistency.max_relative_difference = consistency.max_relative_difference.max(diff);
                consistency.widened += u64::from(diff > PDF_CONSISTENCY_LIMIT && diff <= limit);
                consistency.over_limit += u64::from(diff > limit);
                if diff / limit > worst {
                    worst = diff / limit;
                    consistency.worst_limit = limit;
                    if consistency.pdf_function_not_finite == 0 {
                        consistency.worst_u = *u;
                    }
                }
            }
            p_max = p_max.max(rep);
        }
    }
    let consistent = consistency.over_limit == 0 && consistency.pdf_function_not_finite == 0;
    let not_finite = match consistency.pdf_function_not_finite {
        0 => String::new(),
        k => format!("; {} NaN or ∞ at {k} of them", sampler.pdf_at_d()),
    };
    let widened = match (consistency.widened, consistency.over_limit) {
        (0, 0) => String::new(),
        (w, 0) => format!("; {w} beyond {PDF_CONSISTENCY_LIMIT:.0e} but within the pdf's f32 conditioning there"),
        (_, o) => format!("; {o} beyond the limit widened by the pdf's f32 conditioning (worst: {:.2e} allowed there)", consistency.worst_limit),
    };
    checks.push(Check {
        passed: consistent,
        summary: format!(
            "the pdf the sampler reports and {} differ by at most {:.2e} (limit {PDF_CONSISTENCY_LIMIT:.0e} + {CONDITIONING_ULPS} × the pdf's f32 conditioning) over {} samples{widened}{not_finite}",
            sampler.pdf_at_d(), consistency.max_relative_difference, consistency.compared
        ),
        figures: Figures::PdfConsistency(consistency),
    });

    // The Jacobian.
    let jump = map_jump(&passes, &params, &probes, &probe_u, plane)?;
    let jac = jacobian::judge(&probes, &probe_u, &at, &kappa, CONDITIONING_ULPS, plane, jump);
    let unresolved = match jac.skipped_unresolved {
        0 => String::new(),
        k => format!(
            "; {k} samples skipped where no three steps agree on |J| to {:.0}% (d moves by only a few f32 ulps there: an f32 staircase, e.g. sin θ = √(1 − cos²θ) near a pole)",
            100.0 * jacobian::UNRESOLVED
        ),
    };
    // the length of d at the worst probe: a map onto non-unit vectors has the wrong |J| on the
    // sphere, and the cause is then the length, not the density
    let worst_length = probes.iter().zip(&probe_u).find(|(_, u)| **u == jac.worst_u).map(|(p, _)| p[6][2]);
    let not_unit = match worst_length {
        Some(l) if !plane && !jac.passed && !hard::is_unit(l) => format!("; |d| = {} at the worst sample, not a unit vector", hard::show(l)),
        _ => String::new(),
    };
    let systematic = match jac.median_deviation {
        Some(m) if jac.resolved >= jacobian::MIN_COMPARED => format!(
            "; systematically: {} of {} samples resolved to {:.1}% off by more than {:.1}% + their f32 resolution (at most {:.0} may be: half, plus chance), median |pdf · |J| − 1| {:.1e}",
            jac.systematic_off,
            jac.resolved,
            100.0 * jacobian::RESOLVED,
            100.0 * jac.systematic_tolerance,
            jac.systematic_limit.floor(),
            m
        ),
        _ => format!("; systematic test not applicable: {} samples resolved to {:.1}%", jac.resolved, 100.0 * jacobian::RESOLVED),
    };
    let jumps = match jac.jump {
        Some(j) => format!(
            "; the map u ↦ d jumps along u.{} (at {:.4}, on {} of {} lines scanned): a choice made with that uniform and reused, so several u land on one d and pdf · |J| ≥ 1 there, judged as an event's (off only below 1)",
            ["x", "y"][j.axis as usize],
            j.at,
            j.lines,
            j.scanned
        ),
        None => String::new(),
    };
    let summary = if jac.applicable {
        format!(
            "pdf · |J| has median {:.4} and worst {:.4} (allowed ±{:.1}% there); {:.2}% of {} samples off by more than {:.0}% + the f32 resolution of |J| and of the pdf (limit {:.0}%){}{systematic}{unresolved}{not_unit}",
            jac.median_ratio.unwrap_or(f64::NAN),
            jac.worst_ratio,
            100.0 * jac.worst_limit,
            100.0 * jac.share_off,
            jac.compared,
            100.0 * jac.tolerance,
            100.0 * jacobian::MAX_SHARE_OFF,
            match jac.compared_events {
                0 => String::new(),
                k => format!("; {k} of them chose an event with u.z or u.w, judged by pdf · |J| / share ({} above 1)", jac.above_events),
            }
        ) + &jumps
    } else {
        format!(
            "not applicable: only {} of {} samples comparable ({} move with u.z or u.w, {} not smooth, {} unresolved in f32, {} invalid)",
            jac.compared, jac.probed, jac.skipped_selection, jac.skipped_not_smooth, jac.skipped_unresolved, jac.skipped_invalid
        )
    };
    checks.push(Check { passed: jac.passed, summary, figures: Figures::Jacobian(jac) });

    // The expected histogram.
    let width = quadrature::initial_width(p_max, plane);
    // what integrates the pdf: the WGSL pdf on the GPU, or the f64 reference on the CPU
    let gpu_integrand = (&passes, &params);
    let wi64 = glam::DVec3::new(wi[0] as f64, wi[1] as f64, wi[2] as f64);
    let reference_pdf = settings.reference.as_ref().map(|r| move |d: glam::DVec3| (r.0)(wi64, d));
    let cpu_integrand = reference_pdf.as_ref().map(|pdf| quadrature::CpuPdf { pdf, plane, jumps: quadrature::Jumps::Locate });
    let pdf_integrand: &dyn quadrature::Integrand = match &cpu_integrand {
        Some(cpu) => cpu,
        None => &gpu_integrand,
    };
    let (mut integrals, leaves) = quadrature::integrate_leaves(pdf_integrand, &sampler.domain, rows, cols, width, settings.samples, Some(&totals[..bins]))?;
    if cpu_integrand.is_some() && sampler.eval.is_some() {
        // eval has no f64 twin: its integral stays the GPU's
        integrals.eval = quadrature::integrate(&gpu_integrand, &sampler.domain, rows, cols, width, settings.samples, Some(&totals[..bins]))?.eval;
    }
    // a pdf that returned NaN, ∞ or a negative value fails `pdf_values` whatever else; otherwise
    // expected counts the quadrature could not resolve give no verdict
    if integrals.bad_parts == 0 {
        integrals.converged(settings.samples).map_err(CheckError::NoVerdict)?;
    }
    let n = settings.samples as f64;
    let pdf_total: f64 = integrals.probabilities.iter().sum();
    // where the pdf is bad: its worst point on a fine grid (the WGSL pdf's, as the hard cases)
    let worst = if integrals.bad_parts > 0 { pdf_values::worst(&passes, &params, &sampler.domain, &sampler.conventions)? } else { None };
    let worst_text = worst.as_ref().map(|w| w.describe(&sampler.pdf_at_d(), plane));
    checks.push(Check {
        passed: integrals.bad_parts == 0,
        summary: if integrals.bad_parts == 0 {
            format!("{} finite and ≥ 0 at every quadrature node ({} parts)", sampler.pdf_at_d(), integrals.parts)
        } else {
            format!(
                "{} returned NaN, ∞ or a negative value in {} of {} quadrature parts; {}",
                sampler.pdf_at_d(),
                integrals.bad_parts,
                integrals.parts,
                worst_text.clone().unwrap_or_else(|| "no such value on a fine grid of the domain: it lies between the grid's points".into())
            )
        },
        figures: Figures::PdfValues(PdfValuesFigures { bad_parts: integrals.bad_parts, parts: integrals.parts, worst: worst_text }),
    });
    let expected: Vec<f64> = integrals.probabilities.iter().map(|p| n * p).collect();
    // what the report holds and the pictures draw: the pdf's signed integral, below 0 where the
    // pdf is (the χ² leaves those parts out, and `pdf_values` fails)
    let signed: Vec<f64> = if integrals.dropped.is_empty() {
        expected.clone()
    } else {
        integrals.probabilities.iter().zip(&integrals.dropped).map(|(p, d)| n * (p + d)).collect()
    };
    let invalid: [u64; 4] = totals[bins..].try_into().expect("four reasons");
    let resolution = integral_resolution(&integrals, pdf_total, cpu_integrand.is_none().then_some((&passes, &params, &leaves[..])))?;
    let observed_invalid = totals[bins..].iter().sum::<u64>() as f64 / n;
    let expected_invalid = invalid_expectation(settings.samples, totals[bins..].iter().sum(), pdf_total, resolution);
    // Normalisation: ∫pdf over the domain is the probability of a valid sample, which the
    // histogram measures as the valid fraction f (standard error √(f(1 − f)/N)).
    let valid = 1.0 - observed_invalid;
    let norm_tolerance = 2.0 * resolution + 4.0 * (valid * (1.0 - valid) / n).sqrt();
    let norm = NormalizationFigures { pdf_integral: pdf_total, valid_fraction: valid, resolution, tolerance: norm_tolerance };
    checks.push(Check {
        passed: (pdf_total - valid).abs() <= norm_tolerance,
        summary: format!(
            "∫{} over the domain = {pdf_total:.6} against the valid fraction {valid:.6} of the samples (tolerance {norm_tolerance:.1e})",
            sampler.pdf_at_d()
        ),
        figures: Figures::Normalization(norm),
    });
    // column edges off the axes that f32 binning cannot place as finely as the lobe needs: their
    // two bins judged as one cell
    let (judged_counts, judged_expected, joined) = if plane {
        (totals[..bins].to_vec(), expected.clone(), 0)
    } else {
        let strips = quadrature::edge_strips(pdf_integrand, rows, cols, width, settings.samples, &integrals.probabilities)?;
        quadrature::join_unresolved_edges(&totals[..bins], &expected, &strips, rows, cols, settings.samples)
    };
    let grid = if plane { family::Grid::plane(rows, cols) } else { family::Grid::sphere(rows, cols) };
    let chi2 = family::judge(grid, (&judged_counts, &judged_expected), (&[invalid.iter().sum()], &[expected_invalid]), settings.significance);
    let family_p = chi2.family_p_value.unwrap_or(chi2.p_value);
    let summary = format!(
        "{}{}χ² = {:.1} on {} dof, p = {:.3e}; over {} grids and marginals (Holm) p = {:.3e} (significance {}){}{}; ∫pdf = {:.6}; {} samples in cells of zero probability; quadrature error ≤ {:.2}σ{}",
        chi2.untested.map_or(String::new(), |u| format!("{}; ", u.describe())),
        family::caught(&chi2).map_or(String::new(), |c| format!("{c}; ")),
        chi2.statistic,
        chi2.dof,
        chi2.p_value,
        chi2.family.len(),
        family_p,
        settings.significance,
        report::invalid_dominates(&invalid, expected_invalid, chi2.statistic).map_or(String::new(), |m| format!("; {m}")),
        report::borderline(family_p, settings.significance, settings.seed).map_or(String::new(), |m| format!("; {m}")),
        pdf_total,
        chi2.in_impossible_cells,
        integrals.max_error_sigma,
        if joined > 0 {
            format!("; {joined} column edges off the axes lie closer to the lobe than f32 binning places them (±{:.0e} rad): the bins beside each judged as one", quadrature::EDGE_RESOLUTION)
        } else {
            String::new()
        }
    );
    let passed = chi2.passed;
    let figures = Chi2Figures { chi2, pdf_integral: pdf_total, invalid, expected_invalid, quadrature: integrals.clone(), joined_edges: joined as u64 };
    checks.push(Check { passed, summary, figures: Figures::Chi2(figures) });

    // Weights and albedo, with an eval.
    if sampler.eval.is_some() {
        let (mut sw, mut sw2, mut max_err, mut sum_err, mut judged) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut first = 0;
        while first < settings.samples {
            let n = CHUNK.min(settings.samples - first) as u32;
            for [v, e] in passes.weights(&params, first, n)? {
                sw += v[0] as f64;
                sw2 += v[1] as f64;
                max_err = max_err.max(v[2] as f64);
                sum_err += e[0] as f64;
                judged = judged.max(e[1] as f64);
            }
            first += n as u64;
        }
        let limit = crate::stats::weighted::WEIGHT_ERROR_LIMIT as f64;
        let wf = WeightFigures { max_weight_error: max_err, limit, max_over_allowance: judged };
        let widened = if max_err > limit && judged <= 1.0 { " (beyond it only within the pdf's f32 conditioning there)" } else { "" };
        checks.push(Check {
            passed: judged <= 1.0,
            summary: format!(
                "eval/pdf from the sampler and eval/{} differ by at most {max_err:.2e} (limit {limit:.0e} + {CONDITIONING_ULPS} × the pdf's f32 conditioning){widened}",
                sampler.pdf_at_d()
            ),
            figures: Figures::Weights(wf),
        });
        let mean = sw / n;
        let var = (sw2 / n - mean * mean).max(0.0);
        let se = (var / n).sqrt();
        let quad: f64 = integrals.eval.iter().sum();
        // ∫eval is known to the quadrature's resolution, taken relative as that of ∫pdf (its
        // error estimate, the f32 rounding of the sum and the pdf's conditioning), twice as
        // `normalization` allows; the
        // mean weight is biased by the f32 error of the weights, which the mean of
        // |w − eval/pdf(d)| over the samples within the weights' allowance measures (a larger
        // error is the sampler's, and counts 0), and by its own f32 sums (2·10⁻⁶)
        let quad_err = resolution / pdf_total.max(f64::MIN_POSITIVE) * quad.abs();
        let weight_err = sum_err / n + 2e-6 * mean.abs();
        let allowance = 2.0 * quad_err + weight_err;
        let excess = ((mean - quad).abs() - allowance).max(0.0) * (mean - quad).signum();
        let z = if excess == 0.0 { 0.0 } else { excess / se.max(f64::MIN_POSITIVE) };
        let p = libm::erfc(z.abs() / std::f64::consts::SQRT_2);
        let af = AlbedoFigures {
            mean_weight: mean,
            std_error: se,
            quadrature: quad,
            quadrature_error: quad_err,
            weight_error: weight_err,
            allowance,
            z,
            p_value: p,
            significance: settings.significance,
        };
        checks.push(Check {
            passed: p >= settings.significance,
            summary: format!(
                "mean weight {mean:.6} ± {se:.1e} against ∫eval = {quad:.6} (f32 allowance {allowance:.1e}: quadrature, weights): z = {z:.2}, p = {p:.3e}{}",
                report::borderline(p, settings.significance, settings.seed).map_or(String::new(), |m| format!("; {m}"))
            ),
            figures: Figures::Albedo(af),
        });
    }

    // Hard cases.
    let us = hard::uniforms(&sampler.conventions.hard_u_values());
    let thetas: Vec<f64> = if plane { vec![settings.incident_theta] } else { sampler.conventions.hard_thetas() };
    let items: Vec<([f32; 4], [f32; 3])> =
        thetas.iter().flat_map(|&t| us.iter().map(move |u| (*u, incident(t, settings.incident_phi)))).collect();
    let probes = passes.probe(&params, &items)?;
    let bounds = match sampler.domain {
        Domain::Plane { bounds } => Some(bounds),
        Domain::Sphere => None,
    };
    let table: Vec<hard::HardRow> =
        thetas.iter().zip(probes.chunks(us.len())).map(|(&t, p)| hard::row(t, p, &us, bounds)).collect();
    let failing_rows: Vec<&hard::HardRow> = table.iter().filter(|r| !r.passed).collect();
    let failing: Vec<String> = match failing_rows.first() {
        None => Vec::new(),
        Some(first) => {
            let angles: Vec<String> = failing_rows.iter().map(|r| format!("{}°", r.incident_theta)).collect();
            vec![format!(
                "θi {}; the first at θi {}°, u = {:?}: {}",
                angles.join(", "),
                first.incident_theta,
                first.first_failure.unwrap_or_default(),
                first.first_failure_got.as_deref().unwrap_or("")
            )]
        }
    };
    checks.push(Check {
        passed: failing.is_empty(),
        summary: if failing.is_empty() {
            let ones = if sampler.conventions.u_open { "" } else { ", 1" };
            format!("{} inputs at u ∈ {{0, 2⁻²⁴, ½, 1 − 2⁻²⁴{ones}}}⁴ × {} incident angles: every sample valid or rejected with pdf 0", items.len(), thetas.len())
        } else {
            format!("NaN, ∞, a negative pdf or a bad point at {}", failing.join(", "))
        },
        figures: Figures::HardCases(table),
    });

    let passed = checks.iter().all(|c| c.passed);
    Ok(Report {
        format_version: REPORT_VERSION,
        passed,
        checks,
        sampler: describe(sampler) + &draws,
        domain: sampler.domain,
        samples: settings.samples,
        rows,
        cols,
        adapter: gpu.adapter_name(),
        gpu_seconds: passes.gpu_seconds(),
        wall_seconds: started.elapsed().as_secs_f64(),
        counts: totals[..bins].to_vec(),
        invalid,
        expected: signed,
    })
}

/// A jump of the sample map along u.x or u.y ([`jacobian::find_jump`]) on the lines through the
/// first [`jacobian::JUMP_LINES`] probes with a valid sample.
fn map_jump(passes: &gpu::Passes, params: &gpu::Params, probes: &[[[f32; 4]; 7]], probe_u: &[[f32; 4]], plane: bool) -> Result<Option<jacobian::Jump>, CheckError> {
    let valid: Vec<[f32; 4]> = probes
        .iter()
        .zip(probe_u)
        .filter(|(p, _)| p[0][3] > 0.0 && p[0].iter().all(|x| x.is_finite()))
        .map(|(_, u)| *u)
        .take(jacobian::JUMP_LINES)
        .collect();
    jacobian::find_jump(&valid, plane, &|us| passes.map(params, us))
}

/// The resolution of ∫pdf: the mass the pdf leaves to invalid samples, 1 − ∫pdf, is known no
/// better than the quadrature (its error estimate, the f32 rounding of the sum;
/// [`invalid_expectation`] says what the invalid cell makes of it), and, for the WGSL pdf on the
/// GPU (`gpu`: its passes, parameters and the quadrature's parts), no better than the f32 pdf
/// moves the integral: [`quadrature::sensitivity`] measures how far ∫pdf moves on the same parts
/// when the pdf's inputs move by an ulp. Not CONDITIONING_ULPS × the pdf's mean conditioning: that
/// bounds each node's error at its worst, while the integral sums the errors with their signs (a
/// Phong lobe at n = 1000: 5·10⁻⁴ bounded, 10⁻⁴ moved, and a pdf normalised with (n + 2)/2π,
/// 10⁻³ too large, passed within the bound).
fn integral_resolution(integrals: &quadrature::Integrals, pdf_total: f64, gpu: Option<(&gpu::Passes, &gpu::Params, &[quadrature::Leaf])>) -> Result<f64, CheckError> {
    let moved = match gpu {
        Some((passes, params, leaves)) => quadrature::f32_sensitivity(passes, params, leaves)?,
        None => 0.0,
    };
    Ok(integrals.error_estimate + 2e-6 * pdf_total + moved)
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

/// "my_sample/my_pdf in file.wgsl", and the conventions declared: "… (--reflection-only)".
fn describe(s: &UserSampler) -> String {
    let files: Vec<&str> = s.sources.iter().map(|f| f.name.as_str()).collect();
    let conventions = if s.conventions.is_default() { String::new() } else { format!(" ({})", s.conventions.flags()) };
    format!("{}/{} in {}{conventions}", s.sample, s.pdf, files.join(", "))
}

