//! How to check: the settings of one check of a sampler, each checked against its range.

use super::{CheckError, Domain, Setting};

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
    /// GPU's work still unfinished then ends the check with [`GpuError::TimedOut`](crate::engine::gpu::GpuError::TimedOut) (a sampler
    /// that loops forever never returns), and the device is abandoned
    /// ([`crate::engine::gpu::context::Bounds`]).
    pub timeout: std::time::Duration,
    /// Whether a sampler on the sphere whose samples fall in a small cap is binned on a grid
    /// fitted to it ([`super::support`]).
    pub fit: Fit,
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
            fit: Fit::Auto,
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

/// Whether to fit the grid to a small support.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Fit {
    /// Where the samples fall within a cap of height [`FIT_HEIGHT`] (about 0.1 sr).
    #[default]
    Auto,
    /// Never: the sampler's declared domain, as lobes did before.
    Never,
    /// Wherever the samples fall within a hemisphere.
    Always,
}

impl Fit {
    /// The names `--fit` takes.
    pub const NAMES: [&'static str; 3] = ["auto", "never", "always"];

    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(Fit::Auto),
            "never" => Some(Fit::Never),
            "always" => Some(Fit::Always),
            _ => None,
        }
    }

    /// The largest cap height fitted: [`FIT_HEIGHT`], or a hemisphere's 1 with `Always`.
    pub fn limit(self) -> Option<f64> {
        match self {
            Fit::Auto => Some(FIT_HEIGHT),
            Fit::Always => Some(1.0),
            Fit::Never => None,
        }
    }
}

/// The largest cap `Fit::Auto` fits, as 1 − cos ρ: 1/64, a cap of π/32 ≈ 0.098 sr (ρ 10.1°),
/// which holds 64 cells of the sphere's default 64 × 128 grid; a larger support already gets
/// that many cells there.
pub const FIT_HEIGHT: f64 = 1.0 / 64.0;

/// The user's parameters: at most this many numbers (`params: array<vec4<f32>, 4>`).
pub const MAX_PARAMS: usize = 16;
