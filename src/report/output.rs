//! Per-case outputs: `histogram.json` and PNG heat maps of the measured histogram, the
//! expected one and the signed residual (measured − expected)/√expected, the same histograms as
//! `counts.npy` and `expected.npy` ([`super::npy`]), and `timing.json`; shard files; and the
//! summary of `lobes run` and `lobes merge` (`OUT/summary.json`, `OUT/junit.xml`, `--json`). Each
//! is a serde struct that writer and
//! reader share, with a `format_version`; `docs/schema/` holds their JSON Schema
//! ([`super::schema`]). Every file is written atomically ([`super::atomic`]), and
//! `histogram.json` last, so a case folder with a `histogram.json` is complete.
//! A case's files have one builder each over [`super::outcome::Outcome`], a lobe's case or a
//! user's sampler's alike.
//!
//! `histogram.json` holds only what the scene and the adapter determine: the times are in
//! `timing.json`, so two runs of a scene on one adapter write byte-identical `histogram.json`
//! files. JSON is compact unless `--pretty` asks for indentation.

use super::atomic::write_atomic;
use super::caption;
use super::compare::{self, Comparison};
use super::heatmap::{self, Heatmap, Scale};
use super::npy;
use super::outcome::Outcome;
use crate::stats::weighted::AlbedoTest;
use crate::reference::effects::Effects;
use crate::reference::ByReason;
use crate::run::record::{CaseDescription, Timing, WeightedTiming};
use crate::run::shard::ShardFile;
use crate::run::user::UserResult;
use crate::run::{CaseResult, WeightedResult};
use crate::stats::chi2::{Chi2, FamilyTest};
use crate::stats::family;
use crate::run::compare::AngleCheck;
use crate::stats::weighted::{AlbedoCheck, WeightedSums};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The version of the layout of `histogram.json` (2: the times moved to `timing.json`; 3:
/// `counting` in place of `workgroup_counting`; 4: a user's case may be binned on a fitted cap,
/// `domain = "cap"` with `cap_axis` and `cap_height`; 5: one list of invalid reasons for lobes and
/// user's samplers, `invalid` filled for both, its first two keys `non_finite_point` and
/// `outside_domain` (were `non_finite_direction`, `below_horizon`), `user_sampler.invalid` gone).
pub const HISTOGRAM_VERSION: u32 = 5;
/// The version of the layout of `timing.json`.
pub const TIMING_VERSION: u32 = 1;
/// The version of the layout of the summaries of `lobes run` and `lobes merge` (`summary.json`,
/// `--json`) and of `lobes run --shard` (2: the run's status, lobes' version, why a case failed;
/// 3: the status `error` with its `error`, and `stale`).
pub const SUMMARY_VERSION: u32 = 3;

/// `histogram.json`: a case's measured and expected histograms and its verdicts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct HistogramFile {
    /// [`HISTOGRAM_VERSION`].
    pub format_version: u32,
    pub case: String,
    #[serde(flatten)]
    pub description: CaseDescription,
    /// ωi as a unit vector, normal on +z (null for a discrete case).
    pub incident: Option<[f64; 3]>,
    pub samples: u64,
    pub seed: u64,
    pub adapter: String,
    /// `gpu` or `cpu` (shards from both, merged: `cpu + gpu`).
    pub backend: String,
    /// Bin edges over cos θ (rows) and φ (columns); null for a discrete case.
    pub cos_theta_edges: Option<Vec<f64>>,
    pub phi_edges: Option<Vec<f64>>,
    /// Counts, rows × cols (one row of items for a discrete case).
    pub counts: Vec<Vec<u64>>,
    /// Expected counts, rows × cols.
    pub expected: Vec<Vec<f64>>,
    /// Invalid samples by reason (for a user's sampler, `refracted_near_side` is always 0).
    pub invalid: Option<ByReason<u64>>,
    /// The expected count of each reason's cell (lobe cases; a user's sampler's invalid samples
    /// are one pooled cell: `user_sampler.expected_invalid`).
    pub expected_invalid: Option<ByReason<f64>>,
    pub chi2: Chi2,
    /// GPU directions of the first samples against f64 (GPU lobe cases).
    pub per_sample_check: Option<AngleCheck>,
    /// The expected histogram's quadrature (lobe cases).
    pub quadrature: Option<QuadratureRecord>,
    /// How the GPU counted the bins: `workgroup` (a u32 workgroup atomic per bin),
    /// `workgroup-packed` (two 16-bit ones a word), `global` (a storage atomic per sample) or
    /// `slabs` (per-invocation slabs, on CPU adapters); null on the CPU engine, and where merged
    /// shards counted differently.
    pub counting: Option<String>,
    /// The weighted histogram of a case with effects.
    pub weighted: Option<WeightedRecord>,
    /// The checks of a user's WGSL sampler (`lobes check`); absent for lobes' own samplers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub user_sampler: Option<UserSamplerRecord>,
}

/// `timing.json`: a case's times, which differ from run to run (kept out of `histogram.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TimingFile {
    /// [`TIMING_VERSION`].
    pub format_version: u32,
    pub case: String,
    /// The histogram pass (lobes' samplers).
    pub histogram: Option<Timing>,
    /// The expected histogram's quadrature (lobe cases).
    pub quadrature_seconds: Option<f64>,
    /// The weighted pass of a case with effects.
    pub weighted: Option<WeightedTiming>,
    /// Wall time of all the checks of a user's WGSL sampler.
    pub checks_wall_seconds: Option<f64>,
}

impl TimingFile {
    /// The `timing.json` of a case: the histogram pass, the quadrature and the weighted pass of
    /// a lobe's, the checks of a user's sampler.
    pub fn of(r: Outcome) -> Self {
        let lobe = r.lobe();
        TimingFile {
            format_version: TIMING_VERSION,
            case: r.name().into(),
            histogram: lobe.map(|l| Timing { gpu_seconds: l.gpu_seconds, histogram_wall_seconds: l.histogram_seconds }),
            quadrature_seconds: lobe.and_then(|l| l.expected.quadrature.as_ref().map(|_| l.quadrature_seconds)),
            weighted: lobe.and_then(|l| l.weighted.as_ref()).map(|w| WeightedTiming { gpu_seconds: w.gpu_seconds, wall_seconds: w.wall_seconds }),
            checks_wall_seconds: r.user().map(|u| u.wall_seconds),
        }
    }
}

/// The `user_sampler` section: every check of `lobes check`, and the expectation of the one cell
/// of the χ² test that pools the invalid samples of every reason (the case's `invalid`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct UserSamplerRecord {
    /// Whether every check passed (the case's verdict).
    pub passed: bool,
    /// Every check, as in `lobes check`'s report: `{"name", "figures", "passed", "summary"}`.
    pub checks: Vec<crate::check::Check>,
    /// The expected count of the pooled invalid cell.
    pub expected_invalid: f64,
    /// With the case's `budget`: the pilot checks, the fitted time model and the count picked
    /// (the `samples` above).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget: Option<crate::check::budget::BudgetPick>,
}

/// The accuracy and time of the expected histogram's quadrature.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct QuadratureRecord {
    pub error_estimate: f64,
    pub max_error_sigma_at_1e8: f64,
    pub below_horizon_probability: f64,
}

/// The `weighted` section: the effects, the verdict, and per bin the albedo estimate, its f64
/// quadrature and the largest weight difference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WeightedRecord {
    pub effects: Effects,
    pub check: AlbedoCheck,
    pub bin_albedo: Vec<Vec<f64>>,
    pub bin_albedo_reference: Vec<Vec<f64>>,
    pub bin_max_weight_error: Vec<Vec<f32>>,
    pub sums: WeightedSums,
}

/// Rows of a row-major grid.
fn nested<T: Copy>(values: &[T], cols: usize) -> Vec<Vec<T>> {
    values.chunks(cols.max(1)).map(<[T]>::to_vec).collect()
}

impl HistogramFile {
    /// The `histogram.json` of a case.
    pub fn of(r: Outcome, adapter: &str, backend: &str) -> Self {
        let description = CaseDescription::of(r.subject());
        let cols = description.cols;
        let (lobe, grid) = (r.lobe(), r.sphere_grid());
        HistogramFile {
            format_version: HISTOGRAM_VERSION,
            case: r.name().into(),
            description,
            incident: r.incident(),
            samples: r.samples(),
            seed: r.seed(),
            adapter: adapter.into(),
            backend: backend.into(),
            cos_theta_edges: grid.map(|g| g.cos_theta_edges()),
            phi_edges: grid.map(|g| g.phi_edges()),
            counts: nested(r.counts(), cols),
            expected: nested(r.expected(), cols),
            invalid: Some(r.invalid().into()),
            expected_invalid: lobe.map(|l| l.expected.invalid.into()),
            chi2: r.chi2().clone(),
            per_sample_check: lobe.and_then(|l| l.angle.clone()),
            quadrature: lobe.and_then(|l| l.expected.quadrature.as_ref()).map(|q| QuadratureRecord {
                error_estimate: q.error_estimate,
                max_error_sigma_at_1e8: q.max_error_sigma,
                below_horizon_probability: q.below_horizon,
            }),
            counting: lobe.and_then(|l| l.counting.clone()),
            weighted: lobe.and_then(|l| Some(WeightedRecord::new(l, l.weighted.as_ref()?, cols))),
            user_sampler: r.user().map(UserSamplerRecord::of),
        }
    }

    /// Reads a `histogram.json`.
    pub fn read(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
        serde_json::from_str(&text).map_err(|e| anyhow::anyhow!("{}: not a lobes histogram.json: {e}", path.display()))
    }
}

impl WeightedRecord {
    fn new(r: &CaseResult, w: &WeightedResult, cols: usize) -> Self {
        let n = r.case.samples;
        let estimate: Vec<f64> = (0..w.sums.bins.len()).map(|i| w.sums.bin_albedo(i, n)).collect();
        WeightedRecord {
            effects: r.case.effects.expect("a weighted case has effects"),
            check: w.check.clone(),
            bin_albedo: nested(&estimate, cols),
            bin_albedo_reference: nested(&w.check.reference_bins, cols),
            bin_max_weight_error: nested(&w.sums.max_error, cols),
            sums: w.sums.clone(),
        }
    }
}

impl UserSamplerRecord {
    fn of(r: &UserResult) -> Self {
        UserSamplerRecord {
            passed: r.report.passed,
            checks: r.report.checks.to_vec(),
            expected_invalid: r.expected_invalid,
            budget: r.budget.clone(),
        }
    }
}

/// Writes a shard file to `dir/<case>/shard-I-of-N.json` and returns its path.
pub fn write_shard(dir: &Path, shard: &ShardFile) -> anyhow::Result<PathBuf> {
    let folder = dir.join(&shard.case);
    std::fs::create_dir_all(&folder)?;
    let file = folder.join(shard.shard.file_name());
    write_atomic(&file, serde_json::to_string(shard)?.as_bytes())?;
    Ok(file)
}

/// How JSON files are laid out: compact (one line), or indented for people (`--pretty`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JsonStyle {
    #[default]
    Compact,
    Pretty,
}

impl JsonStyle {
    /// `value` as JSON in this style, with a final newline.
    pub fn to_bytes(self, value: &impl Serialize) -> serde_json::Result<Vec<u8>> {
        let mut text = match self {
            JsonStyle::Compact => serde_json::to_string(value)?,
            JsonStyle::Pretty => serde_json::to_string_pretty(value)?,
        };
        text.push('\n');
        Ok(text.into_bytes())
    }
}

/// The files of a case after its heat maps: `counts.npy`, `expected.npy`, `timing.json`, and
/// `histogram.json` last.
struct CaseFiles<'a> {
    counts: &'a [u64],
    expected: &'a [f64],
    timing: TimingFile,
    histogram: HistogramFile,
}

impl CaseFiles<'_> {
    /// `shape`: the histogram's rows × cols.
    fn write(&self, folder: &Path, shape: [usize; 2], style: JsonStyle) -> anyhow::Result<()> {
        write_atomic(&folder.join("counts.npy"), &npy::encode(&shape, self.counts))?;
        write_atomic(&folder.join("expected.npy"), &npy::encode(&shape, self.expected))?;
        write_atomic(&folder.join("timing.json"), &style.to_bytes(&self.timing)?)?;
        write_atomic(&folder.join("histogram.json"), &style.to_bytes(&self.histogram)?)?;
        Ok(())
    }
}

/// Writes the heat maps, the arrays, `timing.json` and then `histogram.json` into `dir/<case>/`.
pub fn write_case(dir: &Path, r: Outcome, adapter: &str, backend: &str, style: JsonStyle) -> anyhow::Result<()> {
    let folder = dir.join(r.name());
    std::fs::create_dir_all(&folder)?;
    let doc = HistogramFile::of(r, adapter, backend);
    let (rows, cols) = (doc.description.rows, doc.description.cols);
    let lobe = r.lobe();
    let weighted = lobe.and_then(|l| l.weighted.as_ref());
    let measured: Vec<f64> = r.counts().iter().map(|&c| c as f64).collect();
    let mut verdict = caption::verdict(r.passed(), r.chi2());
    if weighted.is_some_and(|w| !w.check.passed) {
        verdict += ", albedo check failed";
    }
    let caption = format!("{} ({}): {verdict}", r.name(), caption::parameters(&doc.description));
    // a lobe's invalid samples (a user's sampler's are in its report)
    let invalid: u64 = r.invalid().iter().sum();
    let note = if invalid > 0 { format!("{invalid} invalid samples not shown") } else { String::new() };
    let coarse = family::caught_grid(r.chi2());
    compare::write(&folder, &Comparison { bins: r.bins(), measured: &measured, expected: r.expected(), caption: &caption, note: &note, coarse })?;
    if let (Some(l), Some(w)) = (lobe, weighted) {
        write_albedo_map(&folder, l, w, [rows, cols])?;
    }
    let files = CaseFiles { counts: r.counts(), expected: r.expected(), timing: TimingFile::of(r), histogram: doc };
    files.write(&folder, [rows, cols], style)
}

/// `albedo.png`: a weighted case's albedo estimate per bin; `shape` its rows × cols.
fn write_albedo_map(folder: &Path, r: &CaseResult, w: &WeightedResult, [rows, cols]: [usize; 2]) -> anyhow::Result<()> {
    let albedo: Vec<f64> = (0..w.sums.bins.len()).map(|i| w.sums.bin_albedo(i, r.case.samples)).collect();
    let title = format!("{}: albedo per bin (sum of f cos / pdf over N)", r.case.name);
    let pi = std::f64::consts::PI;
    let map = Heatmap { title: &title, rows, cols, values: &albedo, scale: Scale::Sequential, row_label: "cos θ", col_label: "φ", row_range: (-1.0, 1.0), col_range: (-pi, pi), marked_key: "" };
    Ok(heatmap::write_png(&map, &folder.join("albedo.png"))?)
}

/// The summary of `lobes run` and `lobes merge`: `OUT/summary.json` (written on every run that
/// got as far as its output folder, failed and interrupted ones included,
/// [`super::summary::write`]) and the `--json` output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct RunSummary {
    /// [`SUMMARY_VERSION`].
    pub format_version: u32,
    /// The version of lobes that wrote it.
    pub lobes_version: String,
    /// Whether every case of the scene is in `cases`, or the run was interrupted.
    pub status: RunStatus,
    pub adapter: String,
    pub backend: String,
    /// The family-wise level, and the Šidák-corrected level of each case.
    pub significance: f64,
    pub per_case_significance: f64,
    /// The shard files added up (`lobes merge` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard_files: Option<usize>,
    /// Cases that ran and failed a check.
    pub failed: usize,
    /// Cases that could not run (for `lobes merge`: whose outputs could not be written).
    pub errors: usize,
    /// The cases that finished (passed, failed or could not run), in scene order.
    pub cases: Vec<CaseSummary>,
    /// The scene's cases that never started because the run was interrupted.
    pub not_run: Vec<String>,
    /// Case folders an earlier run left in the output folder that are not cases of this run:
    /// their outputs were removed ([`super::folder::OutFolder::clean`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stale: Vec<String>,
    /// Why the run ran no case (status `error`): the message lobes printed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum RunStatus {
    /// Every case of the scene ran (or could not run, with its error).
    Complete,
    /// Stopped by SIGINT or SIGTERM after the case in flight (or, at a second signal, during
    /// it); `not_run` lists the rest.
    Interrupted,
    /// No case ran: bad input (exit 2, such as a scene that does not parse) or the tool could
    /// not start (exit 3, such as no adapter); `error` says why. Written only into an output
    /// folder that already existed, replacing an earlier run's summary, so that CI never reads
    /// an earlier pass as this run's.
    Error,
}

impl RunStatus {
    /// Its name in `summary.json` and `junit.xml`.
    pub fn name(self) -> &'static str {
        match self {
            RunStatus::Complete => "complete",
            RunStatus::Interrupted => "interrupted",
            RunStatus::Error => "error",
        }
    }
}

impl RunSummary {
    /// The summary header of a run of this version of lobes; the caller fills in the cases.
    pub fn new(adapter: String, backend: String, significance: f64, per_case_significance: f64) -> Self {
        RunSummary {
            format_version: SUMMARY_VERSION,
            lobes_version: env!("CARGO_PKG_VERSION").into(),
            status: RunStatus::Complete,
            adapter,
            backend,
            significance,
            per_case_significance,
            shard_files: None,
            failed: 0,
            errors: 0,
            cases: Vec::new(),
            not_run: Vec::new(),
            stale: Vec::new(),
            error: None,
        }
    }

    /// The summary of a run that ran no case because of `error` (status `error`).
    pub fn of_error(significance: f64, error: String) -> Self {
        RunSummary { status: RunStatus::Error, error: Some(error), ..RunSummary::new("none".into(), "none".into(), significance, significance) }
    }

    /// Adds a finished case, counting it as failed or as an error.
    pub fn push(&mut self, case: CaseSummary) {
        self.failed += usize::from(case.error.is_none() && !case.passed);
        self.errors += usize::from(case.error.is_some());
        self.cases.push(case);
    }

    /// A case not run: the run was interrupted before or during it.
    pub fn not_run_now(&mut self, case: &str) {
        self.status = RunStatus::Interrupted;
        self.not_run.push(case.to_string());
    }
}

/// One case of a [`RunSummary`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct CaseSummary {
    pub case: String,
    pub samples: u64,
    /// The shards added up (`lobes merge` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shards: Option<usize>,
    /// The backend the case ran on (`lobes run` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backend: Option<String>,
    /// The case's verdict ([`CaseResult::passed`]): χ² and, where weighted, the albedo checks;
    /// for a user's sampler, every check of `lobes check`.
    pub passed: bool,
    /// The checks a user's sampler failed, by name (absent for lobes' own samplers).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failed_checks: Option<Vec<String>>,
    /// Why a case that ran failed, in one line (absent where it passed or could not run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
    /// What the case measured (absent where it could not run).
    #[serde(flatten)]
    pub measured: Option<CaseMeasured>,
    /// Why the case could not run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The case's output folder (null where it could not run).
    pub output: Option<PathBuf>,
}

/// What a case measured, in a [`CaseSummary`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct CaseMeasured {
    pub gpu_seconds: Option<f64>,
    pub wall_seconds: f64,
    /// The fine grid's χ² test.
    pub chi2: f64,
    pub dof: u64,
    pub p_value: f64,
    /// The family's p-value (Holm's smallest) that the verdict compares with the per-case
    /// significance, and every test's p-values, the fine grid first
    /// ([`crate::stats::family::judge`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub family_p_value: Option<f64>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub family: Vec<FamilyTest>,
    pub albedo: Option<AlbedoSummary>,
    pub max_angle_rad: Option<f64>,
}

/// The albedo checks of a weighted case, in a [`CaseSummary`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct AlbedoSummary {
    pub albedo: f64,
    pub reference: f64,
    pub relative_error: f64,
    pub p_value: f64,
    pub max_weight_error: f32,
    pub passed: bool,
    /// A rough dielectric's transmitted albedo (the reflected one is above).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmitted: Option<AlbedoTest>,
}

impl AlbedoSummary {
    /// The albedo checks of a case: a weighted lobe's, or a user's sampler's with an eval.
    pub fn of(r: Outcome) -> Option<Self> {
        match r {
            Outcome::Lobe(r) => r.weighted.as_ref().map(|w| AlbedoSummary {
                albedo: w.check.reflected.albedo,
                reference: w.check.reflected.reference,
                relative_error: w.check.reflected.relative_error,
                p_value: w.check.reflected.p_value,
                max_weight_error: w.check.max_weight_error,
                passed: w.check.passed,
                transmitted: w.check.transmitted,
            }),
            Outcome::User(r) => r.albedo.map(|a| AlbedoSummary {
                albedo: a.mean_weight,
                reference: a.quadrature,
                relative_error: a.relative_error(),
                p_value: a.p_value,
                max_weight_error: a.max_weight_error as f32,
                passed: a.passed,
                transmitted: None,
            }),
        }
    }
}

impl CaseSummary {
    /// The summary of a case that ran, with its outputs in `out/<case>`.
    pub fn of(r: Outcome, out: &Path) -> Self {
        CaseSummary {
            case: r.name().into(),
            samples: r.samples(),
            shards: None,
            backend: None,
            passed: r.passed(),
            failed_checks: r.failed_checks().map(|names| names.into_iter().map(String::from).collect()),
            failure: failure(r),
            measured: Some(CaseMeasured {
                gpu_seconds: r.gpu_seconds(),
                wall_seconds: r.wall_seconds(),
                chi2: r.chi2().statistic,
                dof: r.chi2().dof,
                p_value: r.chi2().p_value,
                family_p_value: r.chi2().family_p_value,
                family: r.chi2().family.clone(),
                albedo: AlbedoSummary::of(r),
                max_angle_rad: r.lobe().and_then(|l| l.angle.as_ref()).map(|a| a.max_angle_rad),
            }),
            error: None,
            output: Some(out.join(r.name())),
        }
    }

    /// The summary of a case that could not run.
    pub fn error(case: &crate::scene::Entry, error: String) -> Self {
        CaseSummary {
            case: case.name().to_string(),
            samples: case.samples(),
            shards: None,
            backend: None,
            passed: false,
            failed_checks: None,
            failure: None,
            measured: None,
            error: Some(error),
            output: None,
        }
    }
}

/// Why a case failed, in one line: a user's sampler's failed checks with their summaries.
fn failure(r: Outcome) -> Option<String> {
    match r {
        Outcome::Lobe(r) => lobe_failure(r),
        Outcome::User(r) => (!r.passed()).then(|| {
            let failed = r.report.checks.iter().filter(|c| !c.passed);
            failed.map(|c| format!("{}: {}", c.name(), c.summary)).collect::<Vec<_>>().join("; ")
        }),
    }
}

/// Why a lobe's case failed: the χ² test and, where weighted, the albedo checks.
fn lobe_failure(r: &CaseResult) -> Option<String> {
    let mut why = Vec::new();
    let c = &r.chi2;
    if !c.passed {
        why.extend(crate::run::compare::chi2_failure(&r.counts, &r.expected, c));
    }
    if let Some(w) = r.weighted.as_ref().filter(|w| !w.check.passed) {
        let a = &w.check;
        let albedo = |what: &str, albedo: f64, reference: f64, relative_error: f64, p: f64| {
            format!("{what} {albedo:.5} against {reference:.5} by quadrature (relative error {relative_error:+.1e}, p = {p:.3e}, level {:.3e})", a.significance)
        };
        let reflected = if a.transmitted.is_some() { "reflected albedo" } else { "albedo" };
        let r = &a.reflected;
        if r.p_value < a.significance {
            why.push(albedo(reflected, r.albedo, r.reference, r.relative_error, r.p_value));
        }
        if let Some(t) = a.transmitted.as_ref().filter(|t| t.p_value < a.significance) {
            why.push(albedo("transmitted albedo", t.albedo, t.reference, t.relative_error, t.p_value));
        }
        if let Some(p) = a.furnace_p_value.filter(|&p| p < a.significance) {
            why.push(format!("white furnace p = {p:.3e}"));
        }
        if a.max_weight_error > a.weight_error_limit {
            why.push(format!("weight error {:.1e} above the limit {:.1e}", a.max_weight_error, a.weight_error_limit));
        }
        if a.overflow > 0 {
            why.push(format!("{} weights not finite or ≥ 2²³", a.overflow));
        }
    }
    (!why.is_empty()).then(|| why.join("; "))
}

/// The `--json` summary of `lobes run --shard I/N`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ShardSummary {
    /// [`SUMMARY_VERSION`].
    pub format_version: u32,
    pub shard: crate::run::shard::Shard,
    pub adapter: String,
    pub backend: String,
    pub scene_fnv1a64: String,
    pub cases: Vec<ShardCaseSummary>,
}

/// One case of a [`ShardSummary`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ShardCaseSummary {
    pub case: String,
    /// The shard's sample range `first .. end`, and its length.
    pub first: u64,
    pub end: u64,
    pub samples: u64,
    pub gpu_seconds: Option<f64>,
    pub wall_seconds: f64,
    /// The shard file written.
    pub file: PathBuf,
}

impl ShardCaseSummary {
    pub fn of(shard: &ShardFile, file: PathBuf) -> Self {
        ShardCaseSummary {
            case: shard.case.clone(),
            first: shard.first,
            end: shard.end,
            samples: shard.end - shard.first,
            gpu_seconds: shard.timing.gpu_seconds,
            wall_seconds: shard.timing.histogram_wall_seconds,
            file,
        }
    }
}

/// One line of the run table. A user's sampler's time is the wall time of all its checks
/// (marked †), and its verdict names the checks that failed.
pub fn table_row(r: Outcome) -> [String; 9] {
    let time = match (r.user(), r.gpu_seconds()) {
        (Some(_), _) => format!("{:.3} s†", r.wall_seconds()),
        (None, Some(g)) => format!("{g:.3} s"),
        (None, None) => format!("{:.3} s*", r.wall_seconds()),
    };
    let budget = r.user().is_some_and(|u| u.budget.is_some());
    let failed = r.failed_checks().filter(|f| !f.is_empty());
    let verdict = match failed {
        Some(names) => format!("FAIL ({})", names.join(", ")),
        None => if r.passed() { "pass" } else { "FAIL" }.into(),
    };
    let angle = r.lobe().and_then(|l| l.angle.as_ref());
    [
        r.name().into(),
        format!("{}{}", r.samples(), if budget { BUDGET_MARK } else { "" }),
        time,
        format!("{:.1}", r.chi2().statistic),
        r.chi2().dof.to_string(),
        format!("{:.4}", r.chi2().p_value),
        verdict,
        angle.map_or("-".into(), |a| format!("{:.2e} rad", a.max_angle_rad)),
        AlbedoSummary::of(r).map_or("-".into(), |a| albedo_cell(&a)),
    ]
}

/// The row of a case that has no result (it could not run, or ran out of time): its name,
/// samples and `word` (`ERROR`, `FAIL`), dashes elsewhere.
pub fn dash_row(case: &crate::scene::Entry, word: &str) -> [String; 9] {
    let dash = || "-".to_string();
    [case.name().to_string(), case.samples().to_string(), dash(), dash(), dash(), dash(), word.into(), dash(), dash()]
}

/// The albedo column: the estimate and its relative error, a rough dielectric's reflected (R)
/// and transmitted (T) ones.
fn albedo_cell(a: &AlbedoSummary) -> String {
    match &a.transmitted {
        None => format!("{:.5} ({:+.1e})", a.albedo, a.relative_error),
        Some(t) => format!("R {:.5} ({:+.1e}) T {:.5} ({:+.1e})", a.albedo, a.relative_error, t.albedo, t.relative_error),
    }
}

/// The mark of a sample count picked by a case's `budget` in the run table.
pub const BUDGET_MARK: &str = "‡";

pub const TABLE_HEADER: [&str; 9] = ["case", "samples", "GPU time", "chi2", "dof", "p-value", "verdict", "max angle err", "albedo (rel err)"];

/// The run table (`lobes run`, `lobes merge`).
pub fn format_table(rows: &[[String; 9]]) -> String {
    super::table::render(&TABLE_HEADER, rows.iter().map(|r| r.to_vec()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_albedo_column_names_a_dielectrics_sides() {
        let reflected = AlbedoSummary { albedo: 0.5, reference: 0.5, relative_error: 1e-4, p_value: 0.5, max_weight_error: 0.0, passed: true, transmitted: None };
        assert_eq!(albedo_cell(&reflected), "0.50000 (+1.0e-4)");
        let transmitted = Some(AlbedoTest::new(0.25, 1e-3, 0.25));
        assert_eq!(albedo_cell(&AlbedoSummary { transmitted, ..reflected }), "R 0.50000 (+1.0e-4) T 0.25000 (+0.0e0)");
    }

    #[test]
    fn a_case_without_a_result_is_a_row_of_dashes() {
        let scene = crate::scene::Scene::from_bytes("t.toml", b"[[case]]\nname = \"g\"\nlobe = \"ggx\"\nalpha = 0.3\nsamples = 1000\n").unwrap();
        let row = dash_row(&crate::scene::Entry::Lobe(&scene.cases[0]), "ERROR");
        assert_eq!(row, ["g", "1000", "-", "-", "-", "-", "ERROR", "-", "-"]);
    }
}
