//! The judge: one measurement of a sampler, then a list of small checks over it.
//!
//! [`Run`] holds what every check reads: the composed passes, their parameters and the grid.
//! [`Measured`] is the one measurement all checks share (the histogram, the probes with the
//! pdf's f32 conditioning and the map around them, the quadrature of the pdf). Each check is a
//! function of its own module, `check(&Run, &Measured) -> Check`, in the order
//! [`super::check`] lists them.

pub mod chi2;
pub mod hard_cases;
pub mod jacobian;
pub mod normalization;
pub mod pdf_consistency;
pub mod pdf_values;
pub mod weights;

use super::gpu::{CHUNK, Params, Passes, histogram};
use super::probe::Probe;
use super::quadrature::{self, Integrals, Integrand};
use super::{CheckError, Message, SampleReturns, Setting, Settings, UserSampler, jacobian as map};
use crate::stats::domain::Grid;
use crate::engine::gpu::Gpu;
use crate::reference::rng;

/// One check of one sampler at one setting: the composed passes and their parameters. Its
/// sampler is the user's, on the cap fitted to its support where one is ([`super::support`]).
pub(crate) struct Run<'a, 'g> {
    pub sampler: std::borrow::Cow<'a, UserSampler>,
    pub settings: &'a Settings,
    pub passes: Passes<'g>,
    pub params: Params,
    /// The note on the order of the user's --rand draws, for the report.
    pub draws: String,
    /// The incident direction in f32, as the passes see it.
    pub wi: [f32; 3],
    pub rows: u32,
    pub cols: u32,
}

impl<'a, 'g> Run<'a, 'g> {
    /// The run of `sampler`, on a grid fitted to its support where the settings and its samples
    /// call for one ([`super::support::fit`]).
    pub fn new(gpu: &'g Gpu, sampler: &'a UserSampler, settings: &'a Settings) -> Result<Self, CheckError> {
        let params = super::gpu::params_of(sampler, settings);
        let (passes, draws) = super::gpu::compose_passes(gpu, sampler, settings, &params)?;
        let run = Self::on(std::borrow::Cow::Borrowed(sampler), settings, passes, draws);
        if settings.fit.limit().is_none() || !sampler.domain.is_sphere() {
            return Ok(run);
        }
        let probes = run.passes.probe(&run.params, &probe_items(&run))?;
        Ok(match super::support::fit(gpu, sampler, settings, &probes)? {
            Some((domain, passes, draws)) => Self::on(std::borrow::Cow::Owned(UserSampler { domain, ..sampler.clone() }), settings, passes, draws),
            None => run,
        })
    }

    fn on(sampler: std::borrow::Cow<'a, UserSampler>, settings: &'a Settings, passes: Passes<'g>, draws: String) -> Self {
        let (rows, cols) = settings.grid(&sampler.domain);
        let params = super::gpu::params_of(&sampler, settings);
        let wi = super::incident(settings.incident_theta, settings.incident_phi);
        Self { sampler, settings, passes, params, draws, wi, rows, cols }
    }
    pub fn bins(&self) -> usize {
        (self.rows * self.cols) as usize
    }
    /// The histogram's grid over the sampler's domain.
    pub fn grid(&self) -> Grid {
        self.sampler.domain.grid(self.rows, self.cols)
    }
    pub fn samples(&self) -> f64 {
        self.settings.samples as f64
    }
    /// The pdf as the user named it at a sample's d, for messages.
    pub fn pdf(&self) -> String {
        self.sampler.pdf_at_d()
    }
    /// What integrates the pdf, handed to `f`: the f64 reference on the CPU where the settings
    /// give one, else the WGSL pdf on the GPU.
    pub fn with_integrand<R>(&self, f: impl FnOnce(&dyn Integrand<CheckError>) -> R) -> R {
        let wi = glam::DVec3::new(self.wi[0] as f64, self.wi[1] as f64, self.wi[2] as f64);
        match &self.settings.reference {
            Some(r) => {
                let pdf = move |d: glam::DVec3| (r.0)(wi, d);
                f(&quadrature::CpuPdf::new(&pdf, self.sampler.domain, quadrature::Jumps::Locate))
            }
            None => f(&(&self.passes, &self.params)),
        }
    }
}

/// Everything the checks judge, measured once.
pub(crate) struct Measured {
    /// Counts per bin, then per invalid reason ([`crate::reference::Invalid::ALL`]).
    pub totals: Vec<u64>,
    /// The probed uniforms and what the probe pass found at each.
    pub probe_u: Vec<[f32; 4]>,
    pub probes: Vec<Probe>,
    /// The pdf's f32 conditioning at each probe's d (0 where the pdf is not finite and > 0).
    pub kappa: Vec<f64>,
    /// The map at the Jacobian's steps around each probe.
    pub at: Vec<[[f32; 4]; map::AROUND]>,
    /// The quadrature of the pdf (and eval) over the grid.
    pub integrals: Integrals,
    /// The quadrature's first part width, from the largest reported pdf.
    pub width: f64,
    /// How far ∫pdf moves on the quadrature's parts when the WGSL pdf's inputs move by an ulp
    /// ([`quadrature::sensitivity`]; on a cap, the direction too:
    /// [`quadrature::direction_sensitivity`]; 0 for an f64 reference).
    pub f32_moved: f64,
    /// A jump of the sample map along u.x or u.y ([`map::find_jump`]).
    pub jump: Option<map::Jump>,
}

impl Measured {
    pub fn counts(&self, bins: usize) -> &[u64] {
        &self.totals[..bins]
    }
    pub fn invalid(&self, bins: usize) -> super::InvalidCounts {
        self.totals[bins..].try_into().expect("a count per reason")
    }
    /// ∫pdf over the domain.
    pub fn pdf_total(&self) -> f64 {
        self.integrals.probabilities.iter().sum()
    }
}

/// Measures `run`: the histogram, the probes, and the quadrature of the pdf.
pub(crate) fn measure(run: &Run) -> Result<Measured, CheckError> {
    let totals = histogram(&run.passes, &run.params, &run.sampler, run.settings.samples)?;
    let probe_u = probe_uniforms(run.settings);
    let probes = run.passes.probe(&run.params, &probe_items(run))?;
    let points: Vec<[f32; 3]> = probes.iter().map(Probe::d).map(|d| if d.iter().all(|x| x.is_finite()) { d } else { [0.0; 3] }).collect();
    let kappa: Vec<f64> = run.passes.conditioning(&run.params, &points)?.iter().map(|v| v[1] as f64).collect();
    let around: Vec<[f32; 4]> = probe_u.iter().flat_map(|u| map::around(*u)).collect();
    let at = run.passes.map(&run.params, &around)?.chunks(map::AROUND).map(|c| c.try_into().expect("AROUND per probe")).collect();
    let p_max = probes.iter().filter(|p| p.valid()).map(|p| p.reported_pdf() as f64).fold(0.0, f64::max);
    let width = quadrature::initial_width(p_max, run.sampler.domain, run.rows);
    let denser = |bins: &[bool]| denser_witnesses(run, bins);
    let evidence = quadrature::Evidence { observed: &totals[..run.bins()], witnesses: witnesses(run, &probes)?, denser: Some(&denser) };
    let (integrals, f32_moved) = integrate(run, &evidence, width)?;
    let jump = map_jump(run, &probes, &probe_u)?;
    Ok(Measured { totals, probe_u, probes, kappa, at, integrals, width, f32_moved, jump })
}

/// Samples drawn for the quadrature's [`quadrature::Witnesses`], besides the probes': at
/// 2¹⁶, a region of the support holding 10⁻⁴ of the mass is missed by all of them with
/// probability e^(−6.6).
pub const WITNESSES: u64 = 1 << 16;

/// The valid samples of the probes and of [`WITNESSES`] more uniforms (a stream of their own),
/// as the quadrature's witnesses.
fn witnesses(run: &Run, probes: &[Probe]) -> Result<quadrature::Witnesses, CheckError> {
    // the largest f32 below 1: u stays in [0, 1)
    let below_one = 1.0 - f32::EPSILON / 2.0;
    let us: Vec<[f32; 4]> = (0..WITNESSES).map(|i| rng::uniforms(run.settings.seed ^ 0x5851_f42d_4c95_7f2d, i).map(|x| (x as f32).min(below_one))).collect();
    let samples = run.passes.map(&run.params, &us)?;
    let points = probes.iter().map(|p| p.sample).chain(samples).filter(valid_witness).map(|s| [s[0], s[1], s[2]].map(f64::from));
    Ok(quadrature::Witnesses::new(&run.grid(), points))
}

/// Whether a sample can witness the support: a pdf > 0, every component finite.
fn valid_witness(s: &[f32; 4]) -> bool {
    s[3] > 0.0 && s.iter().all(|x| x.is_finite())
}

/// Samples drawn for [`denser_witnesses`]: 2²², 64 times [`WITNESSES`], in dispatches of 2²⁰.
pub const DENSE_WITNESSES: u64 = 1 << 22;

/// The valid samples of [`DENSE_WITNESSES`] more uniforms (a stream of their own) that fall in
/// the bins `bins` marks: where a bin's support is narrower than the quadrature's nodes and its
/// count exceeds its integral, the tip of a tapering sliver that the first witnesses missed.
fn denser_witnesses(run: &Run, bins: &[bool]) -> Result<quadrature::Witnesses, CheckError> {
    const BATCH: u64 = 1 << 20;
    let below_one = 1.0 - f32::EPSILON / 2.0;
    let grid = run.grid();
    let mut points = Vec::new();
    for first in (0..DENSE_WITNESSES).step_by(BATCH as usize) {
        let us: Vec<[f32; 4]> = (first..first + BATCH).map(|i| rng::uniforms(run.settings.seed ^ 0x2545_f491_4f6c_dd1d, i).map(|x| (x as f32).min(below_one))).collect();
        let samples = run.passes.map(&run.params, &us)?;
        let kept = samples.into_iter().filter(valid_witness).map(|s| [s[0], s[1], s[2]].map(f64::from));
        points.extend(kept.filter(|p| grid.cell_of(*p).is_some_and(|b| bins[b])));
    }
    Ok(quadrature::Witnesses::new(&grid, points))
}

/// A jump of the sample map along u.x or u.y ([`map::find_jump`]) on the lines through the first
/// [`map::JUMP_LINES`] probes with a valid sample.
fn map_jump(run: &Run, probes: &[Probe], probe_u: &[[f32; 4]]) -> Result<Option<map::Jump>, CheckError> {
    let valid: Vec<[f32; 4]> = probes.iter().zip(probe_u).filter(|(p, _)| p.valid()).map(|(_, u)| *u).take(map::JUMP_LINES).collect();
    map::find_jump(&valid, run.sampler.domain, &|us| run.passes.map(&run.params, us))
}

/// The probe's uniforms: away from the edges by 2ε, so that u ± ε stays in [0, 1].
/// The probed uniforms with the run's incident direction.
fn probe_items(run: &Run) -> Vec<([f32; 4], [f32; 3])> {
    probe_uniforms(run.settings).into_iter().map(|u| (u, run.wi)).collect()
}

fn probe_uniforms(settings: &Settings) -> Vec<[f32; 4]> {
    let margin = 2.0 * map::EPS as f64;
    (0..settings.probe_samples as u64)
        .map(|i| rng::uniforms(settings.seed ^ 0x9e37_79b9_7f4a_7c15, i).map(|x| (margin + (1.0 - 2.0 * margin) * x) as f32))
        .collect()
}

/// The quadrature of the pdf per bin (and of eval, which has no f64 twin: always the GPU's), and
/// how far the WGSL pdf's f32 evaluation moves ∫pdf ([`quadrature::f32_sensitivity`], and on a
/// cap fitted to a small support [`quadrature::direction_sensitivity`]; 0 for an f64 reference).
fn integrate(run: &Run, evidence: &quadrature::Evidence, width: f64) -> Result<(Integrals, f64), CheckError> {
    let (domain, rows, cols, samples) = (&run.sampler.domain, run.rows, run.cols, run.settings.samples);
    let (mut integrals, leaves) = run.with_integrand(|f| quadrature::integrate_leaves(f, domain, rows, cols, width, samples, Some(evidence)))?;
    if run.settings.reference.is_some() && run.sampler.eval.is_some() {
        integrals.eval = quadrature::integrate(&(&run.passes, &run.params), domain, rows, cols, width, samples, Some(evidence))?.eval;
    }
    if run.settings.reference.is_some() {
        return Ok((integrals, 0.0));
    }
    let inputs = quadrature::f32_sensitivity(&run.passes, &run.params, &leaves)?;
    let direction = if domain.as_cap().is_some() { quadrature::direction_sensitivity(&(&run.passes, &run.params), &leaves)? } else { 0.0 };
    Ok((integrals, inputs + direction))
}

/// A pdf that returned NaN, ∞ or a negative value fails `pdf_values` whatever else; otherwise
/// expected counts the quadrature could not resolve give no verdict.
pub(crate) fn require_converged(run: &Run, m: &Measured) -> Result<(), CheckError> {
    if m.integrals.bad_parts == 0 {
        m.integrals.converged(run.settings.samples).map_err(|e| CheckError::NoVerdict(match half_vector_pole(&run.sampler, run.settings, None) {
            Some(pole) => e.append(pole),
            None => e,
        }))?;
    }
    Ok(())
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
