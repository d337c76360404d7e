//! `lobes check --power`: the whole check at growing sample counts, to say from which count, and
//! after how much GPU time, an error is caught (a test's power grows with N: a χ² test sees a
//! relative error δ in the bins once N Σ p δ² is large against √(2 · dof)).

use super::report::{Chi2Figures, REPORT_VERSION, Report};
use super::{CheckError, Settings, UserSampler, check};
use crate::engine::gpu::Gpu;
use crate::stats::chi2::FamilyTest;
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
    /// Every test of the χ² family at this count, the fine grid first
    /// ([`crate::stats::family::judge`]): its p-value, Holm's, and whether it rejects.
    #[serde(default)]
    pub family: Vec<FamilyTest>,
    /// Every check's verdict at this count, in the report's order.
    #[serde(default)]
    pub checks: Vec<CheckVerdict>,
}

/// One check's verdict at one count of a sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct CheckVerdict {
    pub name: String,
    pub passed: bool,
}

/// What a row of [`PowerSweep::tests`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum TestKind {
    /// A test of the χ² family (a grid or a marginal): it catches the error where it rejects
    /// after Holm's adjustment, which is what fails the chi2 check.
    Chi2Family,
    /// One of the check's checks (pdf_consistency, jacobian, normalization, …): it catches the
    /// error where it fails.
    Check,
}

/// From which count one test, or one check, catches the error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TestCaught {
    /// The test's name ("64 × 128", "8 × 16", "cos θ", "φ") or the check's ("jacobian").
    pub test: String,
    pub kind: TestKind,
    /// From which count it catches the error (it rejects there and at every larger count of
    /// the sweep), with the whole check's time at that count; null when it does not reject at
    /// the largest count.
    pub caught: Option<Caught>,
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
    /// From which count each test of the χ² family (each grid level and each marginal) and each
    /// check catches the error: the family's tests first, fine grid first, then the checks.
    #[serde(default)]
    pub tests: Vec<TestCaught>,
}

/// The index from which `failing` holds at every later point, where it holds at the last.
fn caught_from<T>(points: &[T], failing: impl Fn(&T) -> bool) -> Option<usize> {
    let from = points.iter().rposition(|p| !failing(p)).map_or(0, |i| i + 1);
    (from < points.len()).then_some(from)
}

impl PowerSweep {
    /// The sweep of `points` (in increasing count).
    pub fn new(sampler: String, points: Vec<PowerPoint>) -> Self {
        let passed = points.iter().all(|p| p.passed);
        let at = |i: usize| {
            let p = &points[i];
            Caught { samples: p.samples, gpu_seconds: p.gpu_seconds, seconds: p.seconds, failed: p.failed.clone() }
        };
        let caught = caught_from(&points, |p| !p.passed).map(at);
        // the rows are the first point's tests and checks (every point has the same ones)
        let first = points.first();
        let family = first.map_or(&[][..], |p| &p.family[..]).iter().map(|t| (t.test.clone(), TestKind::Chi2Family));
        let checks = first.map_or(&[][..], |p| &p.checks[..]).iter().map(|c| (c.name.clone(), TestKind::Check));
        let tests = family
            .chain(checks)
            .map(|(test, kind)| {
                let failing = |p: &PowerPoint| match kind {
                    TestKind::Chi2Family => p.family.iter().any(|t| t.test == test && t.rejected),
                    TestKind::Check => p.checks.iter().any(|c| c.name == test && !c.passed),
                };
                TestCaught { caught: caught_from(&points, failing).map(at), test, kind }
            })
            .collect();
        Self { format_version: REPORT_VERSION, sampler, points, passed, caught, tests }
    }

    /// One line that says what the sweep found.
    ///
    /// ```
    /// use lobes::check::power::{PowerPoint, PowerSweep};
    /// let point = |samples, passed: bool| PowerPoint {
    ///     samples, p_value: 0.5, chi2_passed: passed, normalization_passed: true, passed,
    ///     failed: if passed { vec![] } else { vec!["chi2".into()] }, gpu_seconds: Some(0.25), seconds: 1.0,
    ///     family: vec![], checks: vec![],
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
        .map(|samples| Ok(PowerPoint::of(samples, &check(gpu, sampler, &Settings { samples, ..settings.clone() })?)))
        .collect::<Result<Vec<_>, CheckError>>()?;
    Ok(PowerSweep::new(sampler.describe(), points))
}

impl PowerPoint {
    /// The point of a check's report at `samples`.
    pub fn of(samples: u64, r: &Report) -> Self {
        let chi2 = r.figures::<Chi2Figures>().expect("every check has chi2");
        PowerPoint {
            samples,
            p_value: chi2.chi2.family_p_value.unwrap_or(chi2.chi2.p_value),
            chi2_passed: chi2.chi2.passed,
            normalization_passed: r.get("normalization").expect("every check has normalization").passed,
            passed: r.passed,
            failed: r.failed().into_iter().map(String::from).collect(),
            gpu_seconds: r.gpu_seconds,
            seconds: r.wall_seconds,
            family: chi2.chi2.family.clone(),
            checks: r.checks.iter().map(|c| CheckVerdict { name: c.name().to_string(), passed: c.passed }).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test(name: &str, rejected: bool) -> FamilyTest {
        FamilyTest { test: name.into(), rows: 1, cols: 1, statistic: 0.0, dof: 1, p_value: 0.5, holm_p_value: if rejected { 1e-4 } else { 0.5 }, rejected }
    }

    fn point(samples: u64, coarse: bool, fine: bool, normalization: bool) -> PowerPoint {
        let passed = !coarse && !fine && normalization;
        PowerPoint {
            samples,
            p_value: 0.5,
            chi2_passed: !coarse && !fine,
            normalization_passed: normalization,
            passed,
            failed: vec![],
            gpu_seconds: Some(samples as f64 * 1e-6),
            seconds: 1.0,
            family: vec![test("64 × 128", fine), test("8 × 16", coarse)],
            checks: vec![CheckVerdict { name: "chi2".into(), passed: !coarse && !fine }, CheckVerdict { name: "normalization".into(), passed: normalization }],
        }
    }

    /// Each test's row: the coarse grid rejects from the second count on (a chance rejection at
    /// the first count that does not persist does not count), the fine grid only at the last,
    /// the normalisation never.
    #[test]
    fn each_test_is_caught_from_its_own_count() {
        let points = vec![point(1 << 16, true, false, true), point(1 << 18, false, false, true), point(1 << 20, true, false, true), point(1 << 22, true, true, true)];
        let sweep = PowerSweep::new("s".into(), points);
        let from: Vec<(&str, TestKind, Option<u64>)> = sweep.tests.iter().map(|t| (t.test.as_str(), t.kind, t.caught.as_ref().map(|c| c.samples))).collect();
        assert_eq!(
            from,
            [
                ("64 × 128", TestKind::Chi2Family, Some(1 << 22)),
                ("8 × 16", TestKind::Chi2Family, Some(1 << 20)),
                ("chi2", TestKind::Check, Some(1 << 20)),
                ("normalization", TestKind::Check, None),
            ]
        );
        assert_eq!(sweep.tests[1].caught.as_ref().unwrap().gpu_seconds, Some((1u64 << 20) as f64 * 1e-6));
        assert_eq!(sweep.caught.unwrap().samples, 1 << 20);
    }
}
