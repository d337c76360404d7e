//! A user's WGSL sampler as a case of `lobes run`: every check of `lobes check`
//! ([`crate::check::check`]) at the case's samples, bins, seed and incident direction, at the
//! run's per-case (Šidák) significance, so that its χ² test is one of the run's family of tests.
//! The case passes when every check passes.
//!
//! A user's case runs whole: its checks (the Jacobian probe, the quadrature of the pdf, the hard
//! cases) are not sums over sample ranges, so `lobes run --shard` refuses scenes that have one.

use super::Backend;
use crate::check::budget::BudgetPick;
use crate::check::report::{AlbedoFigures, Chi2Figures, WeightFigures};
use crate::check::{self, CheckError, Report, Settings};
use crate::scene::UserCase;
use crate::stats::chi2::Chi2;
use std::time::Instant;

/// What the checks of a user's case found.
#[derive(Debug, Clone)]
pub struct UserResult {
    /// The case as it ran: with a `budget`, `settings.samples` is the count picked.
    pub case: UserCase,
    /// With a `budget`: what the pilot checks measured and the count they picked.
    pub budget: Option<BudgetPick>,
    pub report: Report,
    /// The χ² test of the histogram against the quadrature of the user's pdf.
    pub chi2: Chi2,
    /// The expected count of the invalid-sample cell (the pdf's missing mass, [`check::check`]).
    pub expected_invalid: f64,
    /// The albedo check, where the sampler has an eval.
    pub albedo: Option<Albedo>,
    /// Wall time of all the checks (a budget's pilot checks included).
    pub wall_seconds: f64,
}

/// The weights and albedo checks of a sampler with an eval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Albedo {
    /// The mean weight eval/pdf of the samples, and ∫eval by quadrature.
    pub mean_weight: f64,
    pub quadrature: f64,
    pub p_value: f64,
    pub max_weight_error: f64,
    /// Both the weights and the albedo checks passed.
    pub passed: bool,
}

impl Albedo {
    /// mean weight / ∫eval − 1.
    pub fn relative_error(&self) -> f64 {
        self.mean_weight / self.quadrature - 1.0
    }
}

/// A check's error as a run's: a GPU error keeps its type, so that a lost device stops the run's
/// remaining cases ([`super::device_lost`]); settings are named by their scene keys.
fn run_error(e: CheckError) -> anyhow::Error {
    use crate::scene::user::scene_key;
    match e {
        CheckError::Gpu(g) => anyhow::Error::new(g),
        // a setting, and the settings a message names, as the scene names them
        CheckError::Setting { setting, message } => anyhow::anyhow!("{}: {message}", scene_key(setting)),
        CheckError::Advised(m) | CheckError::NoVerdict(m) => anyhow::anyhow!("{}", m.render(&scene_key)),
        other => other.into(),
    }
}

impl UserResult {
    pub fn passed(&self) -> bool {
        self.report.passed
    }

    /// The checks that failed, by name.
    pub fn failed_checks(&self) -> Vec<&str> {
        self.report.checks.iter().filter(|c| !c.passed).map(|c| c.name()).collect()
    }
}

/// Runs the checks of a user's case at per-case `significance`: on the GPU only (the sampler is
/// WGSL), so on the CPU backend it is an error.
pub fn run_user(backend: &Backend, case: &UserCase, significance: f64) -> anyhow::Result<UserResult> {
    let Backend::Gpu(engine) = backend else {
        anyhow::bail!("case '{}' is a WGSL sampler and runs on a GPU adapter only; none is in use (CPU engine)", case.name);
    };
    let t = Instant::now();
    let mut settings = Settings { significance, ..case.settings.clone() };
    let budget = match case.budget {
        Some(b) => Some(check::budget::pick(&engine.gpu, &case.sampler, &settings, b.seconds, b.profile).map_err(run_error)?),
        None => None,
    };
    if let Some(pick) = &budget {
        settings.samples = pick.samples;
    }
    let report = check::check(&engine.gpu, &case.sampler, &settings).map_err(run_error)?;
    let wall_seconds = t.elapsed().as_secs_f64();
    let chi2_figures = report.figures::<Chi2Figures>().ok_or_else(|| anyhow::anyhow!("the check report has no chi2 check"))?;
    let (chi2, expected_invalid) = (chi2_figures.chi2.clone(), chi2_figures.expected_invalid);
    let passed = |name: &str| report.get(name).is_some_and(|c| c.passed);
    let albedo = match (report.figures::<AlbedoFigures>(), report.figures::<WeightFigures>()) {
        (Some(a), Some(w)) => Some(Albedo {
            mean_weight: a.mean_weight,
            quadrature: a.quadrature,
            p_value: a.p_value,
            max_weight_error: w.max_weight_error,
            passed: passed("albedo") && passed("weights"),
        }),
        _ => None,
    };
    let case = UserCase { settings: Settings { samples: settings.samples, ..case.settings.clone() }, ..case.clone() };
    Ok(UserResult { case, budget, report, chi2, expected_invalid, albedo, wall_seconds })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::gpu::GpuError;

    #[test]
    fn a_lost_device_in_a_users_check_is_seen_as_one() {
        let lost = run_error(CheckError::Gpu(GpuError::Lost("Parent device is lost".into())));
        assert!(super::super::device_lost(&lost));
        assert!(!super::super::device_lost(&run_error(CheckError::Device("out of memory".into()))));
    }
}
