//! `lobes check --budget SECONDS` and `--profile ci|thorough`: the largest sample count whose
//! check fits a time budget on this adapter. A check's wall time is a fixed part (composing and
//! compiling the passes, the quadrature of the pdf, the probe passes: independent of N) plus N
//! times the time per sample of the histogram (and weights) passes; short pilot checks measure
//! both on the adapter at hand, and the count is the largest whose predicted time
//! t₀ + N · s is within the budget (docs/check-reference.md, `--budget`).

use super::{CheckError, Setting, Settings, UserSampler, check};
use crate::engine::gpu::Gpu;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The named budgets of `--profile`, in seconds of one check's wall time.
///
/// `ci`: 20 s. On lavapipe (2 vCPU, loaded) a check of GGX's visible normals measured 0.7–2.3 s
/// fixed and 0.08–0.23 µs a sample, so 20 s buys 2²⁶–2²⁷ samples: past the 2²³ from which the
/// family catches every defect of the panel of subtly broken samplers (docs/statistics.md), and
/// about the 2²⁵–2²⁶ from which the fine grid alone does.
///
/// `thorough`: 300 s, five minutes: a nightly job, about 15× the samples of `ci` on the same
/// machine: a defect about 4× smaller (the count a χ² test needs grows as 1/ε²).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Profile {
    Ci,
    Thorough,
}

impl Profile {
    pub fn seconds(self) -> f64 {
        match self {
            Profile::Ci => 20.0,
            Profile::Thorough => 300.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Profile::Ci => "ci",
            Profile::Thorough => "thorough",
        }
    }
}

/// A time budget as the user wrote it: seconds, or a [`Profile`]'s name (`lobes check --budget` /
/// `--profile`, and a scene case's `budget` key).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    pub seconds: f64,
    pub profile: Option<Profile>,
}

impl Budget {
    /// What a budget may be, for messages.
    pub fn allowed() -> String {
        let (ci, thorough) = (Profile::Ci, Profile::Thorough);
        format!(
            "a budget is seconds of one check's wall time, a number > 0 and at most {:e}, or \"{}\" ({} s) or \"{}\" ({} s)",
            super::MAX_TIMEOUT_SECONDS,
            ci.name(),
            ci.seconds(),
            thorough.name(),
            thorough.seconds()
        )
    }

    /// `"ci"` or `"thorough"`.
    pub fn named(name: &str) -> Option<Self> {
        [Profile::Ci, Profile::Thorough].into_iter().find(|p| p.name() == name).map(|p| Budget { seconds: p.seconds(), profile: Some(p) })
    }

    /// Seconds, > 0 and at most [`super::MAX_TIMEOUT_SECONDS`].
    pub fn seconds(seconds: f64) -> Option<Self> {
        (seconds > 0.0 && seconds <= super::MAX_TIMEOUT_SECONDS).then_some(Budget { seconds, profile: None })
    }
}

/// The check at a picked count is predicted to take at most 1/`TIMEOUT_MARGIN` of its timeout:
/// the prediction is a line through two pilots on a machine whose load may change, and a
/// correct sampler cut off by its timeout reads as one that hangs (a `timeout` FAIL).
pub const TIMEOUT_MARGIN: f64 = 2.0;

/// The timeout of a check whose count a `budget` of seconds picks: `given` where the user gave
/// one (the count is then picked for at most 1/[`TIMEOUT_MARGIN`] of it, [`pick`]), else the
/// default, raised to [`TIMEOUT_MARGIN`] × the budget where that is more (`--budget 1000`
/// alone runs its 1000 s check under a 2000 s timeout, not the default 600 s).
///
/// ```
/// use lobes::check::budget::timeout_for;
/// use std::time::Duration;
/// assert_eq!(timeout_for(1000.0, None), Duration::from_secs(2000));
/// assert_eq!(timeout_for(20.0, None), lobes::check::DEFAULT_TIMEOUT);
/// assert_eq!(timeout_for(40.0, Some(Duration::from_secs(10))), Duration::from_secs(10));
/// ```
pub fn timeout_for(budget: f64, given: Option<std::time::Duration>) -> std::time::Duration {
    given.unwrap_or_else(|| super::DEFAULT_TIMEOUT.max(std::time::Duration::from_secs_f64((TIMEOUT_MARGIN * budget).min(super::MAX_TIMEOUT_SECONDS))))
}

/// The first pilot count, and the granularity of a picked count.
pub const PILOT_SAMPLES: u64 = 1 << 16;

/// One pilot check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Pilot {
    pub samples: u64,
    /// Its wall time and GPU time (null without timestamp queries).
    pub seconds: f64,
    pub gpu_seconds: Option<f64>,
}

/// What `--budget` picked and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct BudgetPick {
    /// The budget: seconds of wall time for the one check at the picked count.
    pub budget_seconds: f64,
    /// The profile that named it, if one did.
    pub profile: Option<String>,
    /// The pilot checks, in order (the first warms the driver's pipelines and is not used).
    pub pilots: Vec<Pilot>,
    /// The fitted model t(N) = fixed_seconds + N · seconds_per_sample.
    pub fixed_seconds: f64,
    pub seconds_per_sample: f64,
    /// The count picked (a multiple of [`PILOT_SAMPLES`], at most 2⁴⁰) and its predicted time.
    pub samples: u64,
    pub predicted_seconds: f64,
}

impl BudgetPick {
    /// One line saying what was picked and why.
    pub fn explain(&self) -> String {
        let named = self.profile.as_ref().map_or(String::new(), |p| format!(" (profile {p})"));
        let rate = if self.seconds_per_sample > 0.0 { format!("{:.3e} samples/s", 1.0 / self.seconds_per_sample) } else { "no measurable time per sample".into() };
        let capped = if self.samples == crate::engine::job::MAX_SAMPLES { ", capped at 2^40" } else { "" };
        format!(
            "budget {:.1} s{named}: {} samples picked{capped}, predicted {:.2} s: {} pilot checks on this adapter measured {:.2} s fixed + {rate}",
            self.budget_seconds,
            self.samples,
            self.predicted_seconds,
            self.pilots.len(),
            self.fixed_seconds,
        )
    }
}

/// The count that fits `budget` seconds: from the pilots' fixed part `fixed` and time per
/// sample `per_sample`, the largest multiple of [`PILOT_SAMPLES`] with fixed + N · per_sample ≤
/// budget, at most 2⁴⁰; `None` when not even [`PILOT_SAMPLES`] fit.
///
/// ```
/// use lobes::check::budget::fit;
/// // 1 s fixed, 10⁷ samples/s: 10 s buys 9·10⁷ samples, rounded down to a multiple of 2¹⁶
/// assert_eq!(fit(10.0, 1.0, 1e-7), Some(89980928));
/// assert_eq!(fit(1.0, 1.5, 1e-7), None);
/// ```
pub fn fit(budget: f64, fixed: f64, per_sample: f64) -> Option<u64> {
    let max = crate::engine::job::MAX_SAMPLES;
    let n = if per_sample > 0.0 { ((budget - fixed) / per_sample).min(max as f64) } else { max as f64 };
    let n = (n.max(0.0) as u64) / PILOT_SAMPLES * PILOT_SAMPLES;
    (n >= PILOT_SAMPLES && fixed + n as f64 * per_sample <= budget).then_some(n)
}

/// A sample's time from the base pilot and the last: the slope of the line through them. Where
/// the samples' share was not measured (the pilots stopped at an eighth of the budget no slower
/// than the fixed part's noise: another process on the adapter slowed the base pilot), the slope
/// is noise, and 0 would pick 2⁴⁰; the last pilot bounds it then: all of its time spent on its
/// samples is the most a sample can cost, so the count picked does not outrun the budget.
fn cost_per_sample(base: &Pilot, last: &Pilot) -> f64 {
    let slope = ((last.seconds - base.seconds) / (last.samples - base.samples) as f64).max(0.0);
    let measured = last.seconds - base.seconds >= 0.5 * base.seconds || last.samples >= crate::engine::job::MAX_SAMPLES / 4;
    if measured { slope } else { slope.max(last.seconds / last.samples as f64) }
}

/// Seconds as a user reads them: as typed for ordinary values, in exponent form for tiny or huge
/// ones (`1e-300`, not 300 zeros).
fn seconds(s: f64) -> String {
    if (1e-3..1e7).contains(&s) { format!("{s}") } else { format!("{s:e}") }
}

/// Measures the check's time on `gpu` by pilot checks and picks the count for `budget` seconds,
/// or for 1/[`TIMEOUT_MARGIN`] of `settings.timeout` where that is less (the pick's
/// `budget_seconds` is then that part of the timeout): a count whose check is predicted to run
/// past its timeout is never picked.
/// The pilots: one at [`PILOT_SAMPLES`] that warms the driver's pipelines (not used), one more
/// there (the fixed part), then 2²⁰, 2²², … until the samples' share of the time is measurable
/// (half the fixed part, or an eighth of the budget), and the line through the last two
/// (`cost_per_sample`, which bounds a slope that was not measured).
pub fn pick(gpu: &Gpu, sampler: &UserSampler, settings: &Settings, budget: f64, profile: Option<Profile>) -> Result<BudgetPick, CheckError> {
    let (given, budget) = (budget, budget.min(settings.timeout.as_secs_f64() / TIMEOUT_MARGIN));
    let named = if budget < given {
        format!("{} s, capped at 1/{TIMEOUT_MARGIN} of the timeout ({} s),", seconds(given), seconds(budget))
    } else {
        format!("{} s", seconds(budget))
    };
    let run = |samples: u64| -> Result<Pilot, CheckError> {
        let r = check(gpu, sampler, &Settings { samples, ..settings.clone() })?;
        Ok(Pilot { samples, seconds: r.wall_seconds, gpu_seconds: r.gpu_seconds })
    };
    let mut pilots = vec![run(PILOT_SAMPLES)?, run(PILOT_SAMPLES)?];
    let base = pilots[1].clone();
    if base.seconds >= budget {
        return Err(CheckError::setting(Setting::Budget, format!(
            "{named} is too small: a check of {PILOT_SAMPLES} samples of this sampler took {:.2} s on this adapter (the fixed part: composing, compiling, the quadrature of the pdf); give a budget above {:.1} s",
            base.seconds,
            2.0 * base.seconds
        )));
    }
    let mut n = 1u64 << 20;
    loop {
        let p = run(n)?;
        pilots.push(p.clone());
        if p.seconds - base.seconds >= 0.5 * base.seconds || p.seconds >= budget / 8.0 || n >= crate::engine::job::MAX_SAMPLES / 4 {
            break;
        }
        n *= 4;
    }
    let last = pilots.last().expect("a pilot");
    let per_sample = cost_per_sample(&base, last);
    let fixed = (base.seconds - per_sample * base.samples as f64).max(0.0);
    let samples = fit(budget, fixed, per_sample).ok_or_else(|| {
        CheckError::setting(Setting::Budget, format!(
            "{named} is too small: the check's fixed part on this adapter is {fixed:.2} s and {PILOT_SAMPLES} samples do not fit after it; give a budget above {:.1} s",
            fixed + 2.0 * per_sample * PILOT_SAMPLES as f64 + 0.5
        ))
    })?;
    Ok(BudgetPick {
        budget_seconds: budget,
        profile: profile.map(|p| p.name().to_string()),
        pilots,
        fixed_seconds: fixed,
        seconds_per_sample: per_sample,
        samples,
        predicted_seconds: fixed + per_sample * samples as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pilot(samples: u64, seconds: f64) -> Pilot {
        Pilot { samples, seconds, gpu_seconds: None }
    }

    #[test]
    fn an_unmeasured_slope_is_bounded_by_the_last_pilot() {
        // CI's case: the base pilot slowed to 0.66 s by another test, 2²⁰ samples in 0.60 s
        let (base, last) = (pilot(1 << 16, 0.66), pilot(1 << 20, 0.60));
        let s = cost_per_sample(&base, &last);
        assert!((s - 0.60 / (1u64 << 20) as f64).abs() < 1e-15, "{s}");
        let n = fit(4.0, 0.0, s).unwrap();
        assert!(n as f64 * s <= 4.0 && n < 1 << 23, "{n}");
        // a measured share: the line through the two pilots, 0.7 s over 2²⁰ − 2¹⁶ samples
        let s = cost_per_sample(&pilot(1 << 16, 0.3), &pilot(1 << 20, 1.0));
        assert!((s - 0.7 / ((1u64 << 20) - (1 << 16)) as f64).abs() < 1e-15, "{s}");
    }
}
