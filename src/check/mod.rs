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
mod error;
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
mod sampler;
mod settings;
mod shaders;
pub mod support;

pub use compose::Source;
pub use error::CheckError;
pub use judge::normalization::invalid_expectation;
pub use gpu::CONDITIONING_ULPS;
pub use judge::pdf_consistency::PDF_CONSISTENCY_LIMIT;
pub use message::{Message, Setting};
pub use sampler::UserSampler;
pub(crate) use settings::incident;
pub use settings::{DEFAULT_TIMEOUT, MAX_PARAMS, MAX_TIMEOUT_SECONDS, Reference, Settings};
pub use conventions::{Conventions, Frame, Incident, Measure};
/// glam, whose `DVec3` [`Reference`] takes: a renderer's tests need no glam of their own.
pub use glam;
pub use composition::{Composition, Dialect, Draw, SampleReturns};
pub use report::{Check, Figures, InvalidCounts, Report};

use crate::engine::gpu::Gpu;
use report::REPORT_VERSION;
use std::path::PathBuf;

pub use crate::stats::domain::Domain;

impl UserSampler {
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



    /// The conventions must fit the domain and each other, and the code `Self::validate_code`.
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
    let (passes, _) = gpu::compose_passes(gpu, sampler, settings, &gpu::params_of(sampler, settings))?;
    runs.iter()
        .map(|&(samples, seed)| {
            let params = gpu::params_of(sampler, &Settings { seed, ..settings.clone() });
            let started = std::time::Instant::now();
            let counts = gpu::histogram(&passes, &params, sampler, samples)?;
            Ok((counts, started.elapsed().as_secs_f64()))
        })
        .collect()
}

/// Runs every check of `sampler` on `gpu`: measures once (`judge::measure`), then judges.
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
        sampler: run.sampler.describe() + &run.draws,
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

