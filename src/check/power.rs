//! `lobes check --power`: the whole check at growing sample counts, to say from which count, and
//! after how much GPU time, an error is caught (a test's power grows with N: a χ² test sees a
//! relative error δ in the bins once N Σ p δ² is large against √(2 · dof)).

use super::report::{Chi2Figures, REPORT_VERSION};
use super::{CheckError, Settings, UserSampler, check};
use crate::engine::gpu::Gpu;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// One sample count of a power sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PowerPoint {
    pub samples: u64,
    /// The χ² family's p-value (Holm's smallest, [`crate::stats::family::judge`]) and verdict at
    /// this count.
    pub p_value: f64,
    pub chi2_passed: bool,
    /// The normalisation check's verdict at this count.
    pub normalization_passed: bool,
    /// Whether every check passed, and the names of those that failed.
    pub passed: bool,
    pub failed: Vec<String>,
    /// GPU time of the check at this count (null without timestamp queries) and its wall time.
    pub gpu_seconds: Option<f64>,
    pub seconds: f64,
}

/// From which count on an error is caught: the smallest count of the sweep at which the check
/// fails and fails at every larger count too.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Caught {
    pub samples: u64,
    /// What the check at that count costs: GPU time (null without timestamp queries) and wall
    /// time; a CI job that runs it at that count catches the error for that price.
    pub gpu_seconds: Option<f64>,
    pub seconds: f64,
    /// The checks that fail there.
    pub failed: Vec<String>,
}

/// A power sweep: `lobes check --power --json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PowerSweep {
    /// [`REPORT_VERSION`].
    pub format_version: u32,
    pub sampler: String,
    pub points: Vec<PowerPoint>,
    /// Whether every check passed at every count (the exit status 0).
    pub passed: bool,
    /// From which count the error is caught; null when the largest count passes.
    pub caught: Option<Caught>,
}

impl PowerSweep {
    /// The sweep of `points` (in increasing count).
    pub fn new(sampler: String, points: Vec<PowerPoint>) -> Self {
        let passed = points.iter().all(|p| p.passed);
        let from = points.iter().rposition(|p| p.passed).map_or(0, |i| i + 1);
        let caught = points.get(from).map(|p| Caught { samples: p.samples, gpu_seconds: p.gpu_seconds, seconds: p.seconds, failed: p.failed.clone() });
        Self { format_version: REPORT_VERSION, sampler, points, passed, caught }
    }

    /// One line that says what the sweep found.
    ///
    /// ```
    /// use lobes::check::power::{PowerPoint, PowerSweep};
    /// let point = |samples, passed: bool| PowerPoint {
    ///     samples, p_value: 0.5, chi2_passed: passed, normalization_passed: true, passed,
    ///     failed: if passed { vec![] } else { vec!["chi2".into()] }, gpu_seconds: Some(0.25), seconds: 1.0,
    /// };
    /// let sweep = PowerSweep::new("s/p".into(), vec![point(65536, false), point(262144, true), point(1048576, false)]);
    /// assert_eq!(sweep.caught.as_ref().unwrap().samples, 1048576); // fails from 2^20 on
    /// assert_eq!(sweep.verdict(), "caught from 1048576 samples (chi2 failing), after 0.250 s of GPU time (1.00 s wall) at that count");
    /// ```
    pub fn verdict(&self) -> String {
        match &self.caught {
            Some(c) => {
                let gpu = c.gpu_seconds.map_or("no GPU timestamps".into(), |s| format!("after {s:.3} s of GPU time"));
                format!("caught from {} samples ({} failing), {gpu} ({:.2} s wall) at that count", c.samples, c.failed.join(", "), c.seconds)
            }
            None if self.passed => format!("every check passed at every count up to {} samples", self.points.last().map_or(0, |p| p.samples)),
            None => {
                let failed: Vec<String> = self.points.iter().filter(|p| !p.passed).map(|p| p.samples.to_string()).collect();
                format!(
                    "failed at {} samples but passed at the largest count: not caught consistently (at significance α a correct sampler fails a count with probability about α)",
                    failed.join(", ")
                )
            }
        }
    }
}

/// The sample counts of a power sweep up to `max`: 2¹⁶, 2¹⁸, … (×4), ending at `max`.
pub fn power_counts(max: u64) -> Vec<u64> {
    let mut v: Vec<u64> = std::iter::successors(Some(1u64 << 16), |n| n.checked_mul(4)).take_while(|&n| n < max).collect();
    v.push(max);
    v
}

/// The whole check at each count of [`power_counts`]`(settings.samples)`, with its χ² p-value
/// and time.
pub fn power(gpu: &Gpu, sampler: &UserSampler, settings: &Settings) -> Result<PowerSweep, CheckError> {
    let points = power_counts(settings.samples)
        .into_iter()
        .map(|samples| {
            let r = check(gpu, sampler, &Settings { samples, ..settings.clone() })?;
            let chi2 = r.figures::<Chi2Figures>().expect("every check has chi2");
            Ok(PowerPoint {
                samples,
                p_value: chi2.chi2.family_p_value.unwrap_or(chi2.chi2.p_value),
                chi2_passed: chi2.chi2.passed,
                normalization_passed: r.get("normalization").expect("every check has normalization").passed,
                passed: r.passed,
                failed: r.failed().into_iter().map(String::from).collect(),
                gpu_seconds: r.gpu_seconds,
                seconds: r.wall_seconds,
            })
        })
        .collect::<Result<Vec<_>, CheckError>>()?;
    Ok(PowerSweep::new(super::describe(sampler), points))
}
