//! `lobes run`: every case of a scene, sampled and histogrammed on the GPU, judged against
//! the f64 reference, with per-case outputs and a table; with `--shard I/N`, one shard of every
//! case, written as raw results for `lobes merge`.

use super::{ChecksFailed, FileArgs, Interrupted, OutputArgs, emit, emit_json, interrupt, parse_level, usage};
use crate::report::outcome::Outcome;
use crate::report::output::{self, CaseSummary, JsonStyle, RunStatus, RunSummary, SUMMARY_VERSION, ShardCaseSummary, ShardSummary};
use crate::run::shard::{SceneSource, Shard, ShardFile, ShardOrigin, fnv1a64};
use crate::run::user::run_user;
use crate::run::{Backend, CaseResult, Expected, device_lost, judge, run_case};
use crate::scene::{Case, DEFAULT_SCENE, Entry, Overrides, Scene, UserCase};
use crate::engine::gpu::GpuError;
use crate::stats::chi2::sidak;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use crate::report::folder::{Access, OutFolder};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

#[derive(Debug, Clone, Args)]
pub struct RunArgs {
    /// Scene file (TOML), or - to read it from standard input; without it, the embedded
    /// scenes/all-lobes.toml (every lobe and method).
    pub scene: Option<PathBuf>,
    /// Run only the cases whose names match NAME, a pattern such as 'ggx-*' (* any text, ? one
    /// character, `[ab]` one of them; ignoring case); repeat it for more.
    #[arg(long = "case", value_name = "NAME", conflicts_with = "shard")]
    pub cases: Vec<String>,
    /// Samples of every case, in place of the scene's.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=crate::scene::MAX_SAMPLES), allow_hyphen_values = true, conflicts_with = "shard")]
    pub samples: Option<u64>,
    /// Seed of every case, in place of the scene's.
    #[arg(long, value_name = "S", allow_hyphen_values = true, conflicts_with = "shard")]
    pub seed: Option<u64>,
    /// Output folder: one subfolder per case with histogram.json and PNG heat maps, and the
    /// run's summary.json and junit.xml (also when cases fail or the run is interrupted).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Family-wise significance level, Šidák-corrected over the scene's cases.
    #[arg(long, default_value_t = 0.01, value_parser = parse_level, allow_hyphen_values = true)]
    pub significance: f64,
    /// Run on the CPU reference engine (f64, all cores) instead of a GPU adapter. Without it a
    /// missing adapter is an error (exit 3), never a silent move to the CPU.
    #[arg(long)]
    pub cpu: bool,
    /// Run only shard I of N (0 ≤ I < N) of every case: its contiguous range of sample indices,
    /// written as raw counts to `OUT/<case>/shard-I-of-N.json` for `lobes merge`.
    #[arg(long, value_name = "I/N", value_parser = Shard::parse)]
    pub shard: Option<Shard>,
    #[command(flatten)]
    pub files: FileArgs,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// Reads and validates a scene (the embedded default when `path` is None). A file that cannot
/// be read, is not UTF-8 or is not a valid scene is a [`super::UsageError`] naming the file (and
/// the line and column).
pub fn load_scene(path: Option<&PathBuf>) -> anyhow::Result<Scene> {
    read_scene(path, Overrides::default()).map(|(_, scene)| scene)
}

/// [`load_scene`] with `overrides`, and the scene's name and text (for shard files). The path
/// `-` reads the scene from standard input (a user sampler's files are then found relative to
/// the current folder).
fn read_scene(path: Option<&PathBuf>, overrides: Overrides) -> anyhow::Result<(SceneSource, Scene)> {
    let (name, bytes) = match path {
        Some(p) if p.as_os_str() == "-" => {
            let mut bytes = Vec::new();
            std::io::Read::read_to_end(&mut std::io::stdin().lock(), &mut bytes).map_err(|e| usage(format!("cannot read the scene from standard input: {e}")))?;
            ("<stdin>".to_string(), bytes)
        }
        Some(p) => {
            let bytes = std::fs::read(p).map_err(|e| {
                usage(format!(
                    "cannot read scene file {}: {e}; give the path of a TOML scene such as scenes/tutorial.toml",
                    p.display()
                ))
            })?;
            (p.display().to_string(), bytes)
        }
        None => ("<embedded scenes/all-lobes.toml>".to_string(), DEFAULT_SCENE.as_bytes().to_vec()),
    };
    let scene = Scene::from_bytes_with(&name, &bytes, overrides).map_err(|e| usage(e.to_string()))?;
    // from_bytes has checked that the text is UTF-8
    Ok((SceneSource { name, text: String::from_utf8_lossy(&bytes).into_owned() }, scene))
}

/// Checks, before anything runs, that every case fits the GPU adapter (histograms larger than a
/// storage binding are split into tiles; a discrete table must fit one binding), and says
/// which cases are split.
fn check_fits(backend: &Backend, scene: &Scene) -> anyhow::Result<()> {
    let Backend::Gpu(engine) = backend else { return Ok(()) };
    for (i, case) in scene.cases.iter().enumerate() {
        let tiling = engine
            .tiling(&case.job)
            .map_err(|e| usage(format!("{}: case '{}': {e}", scene.case_location(i), case.name)))?;
        if tiling.tiles > 1 {
            crate::console::say(format_args!(
                "lobes: note: case '{}': {} bins exceed one storage binding of this adapter; counting them in {} passes of {} bins",
                case.name,
                case.job.bins(),
                tiling.tiles,
                tiling.tile_bins
            ));
        }
    }
    Ok(())
}

/// Runs one case and writes its outputs (an earlier run's were removed before the first case,
/// [`OutFolder::clean`], so a case that fails here leaves no complete-looking `histogram.json`
/// behind). The expected counts (f64 quadrature on the CPU) are computed on another thread while the GPU
/// samples.
fn run_and_write(backend: &mut Backend, case: &Case, level: f64, out: &Path, style: JsonStyle, progress: &mut dyn FnMut(u64)) -> anyhow::Result<CaseResult> {
    let (sampled, expected) = std::thread::scope(|s| {
        let quadrature = s.spawn(|| Expected::of(case));
        let sampled = run_case(backend, case, 0..case.samples, progress);
        (sampled, quadrature.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
    });
    let result = judge(case, sampled?, expected, level)?;
    let adapter = backend.adapter();
    output::write_case(out, Outcome::Lobe(&result), &adapter, backend.name(), style)
        .map_err(|e| anyhow::anyhow!("writing the outputs into {}: {e:#}", out.join(&case.name).display()))?;
    Ok(result)
}

/// Runs the checks of a user's sampler case and writes its outputs, as [`run_and_write`].
fn run_user_and_write(backend: &Backend, case: &UserCase, level: f64, out: &Path, style: JsonStyle) -> anyhow::Result<([String; 9], CaseSummary)> {
    let result = run_user(backend, case, level)?;
    let ran = Outcome::User(&result);
    output::write_case(out, ran, &result.report.adapter, backend.name(), style)
        .map_err(|e| anyhow::anyhow!("writing the outputs into {}: {e:#}", out.join(&case.name).display()))?;
    Ok((output::table_row(ran), CaseSummary { backend: Some(backend.name().into()), ..CaseSummary::of(ran, out) }))
}

/// The first user's sampler case of a scene and its location, if any.
fn first_user_case(scene: &Scene) -> Option<(String, String)> {
    scene.entries().find_map(|(e, at)| matches!(e, Entry::User(_)).then(|| (e.name().to_string(), at)))
}

fn progress_bar(samples: u64, name: &str) -> ProgressBar {
    let bar = ProgressBar::new(samples);
    bar.set_style(ProgressStyle::with_template("{msg:24} [{bar:40}] {percent:>3}% {per_sec} eta {eta}").unwrap().progress_chars("=> "));
    bar.set_message(name.to_string());
    bar
}

/// Progress off a terminal (a CI log), where indicatif draws nothing: a plain line per finished
/// case, and a line a minute while a long case runs.
struct PlainProgress {
    on: bool,
    cases: usize,
}

impl PlainProgress {
    const EVERY: Duration = Duration::from_secs(60);

    fn new(cases: usize) -> Self {
        PlainProgress { on: !std::io::stderr().is_terminal(), cases }
    }

    /// The progress callback of case `i` (lobe cases report samples done).
    fn samples<'a>(&self, i: usize, name: &'a str, samples: u64, bar: &'a ProgressBar) -> impl FnMut(u64) + 'a {
        let (on, cases, start) = (self.on, self.cases, Instant::now());
        let mut last = start;
        move |done| {
            bar.set_position(done);
            if on && last.elapsed() >= Self::EVERY {
                last = Instant::now();
                crate::console::say(format_args!("lobes: [{}/{cases}] {name}: {done} of {samples} samples, {:.0} s", i + 1, start.elapsed().as_secs_f64()));
            }
        }
    }

    fn finished(&self, i: usize, name: &str, verdict: &str, seconds: f64) {
        if self.on {
            crate::console::say(format_args!("lobes: [{}/{}] {name}: {verdict} ({seconds:.2} s)", i + 1, self.cases));
        }
    }
}

/// The scene to run and the backend to run it on, or why the run cannot start.
fn start(args: &RunArgs) -> anyhow::Result<(Scene, Backend)> {
    let overrides = Overrides { samples: args.samples, seed: args.seed };
    let scene = read_scene(args.scene.as_ref(), overrides)?.1.select(&args.cases).map_err(|e| usage(format!("--case {e}")))?;
    if args.cpu
        && let Some((name, at)) = first_user_case(&scene)
    {
        return Err(usage(format!("{at}: case '{name}' is a WGSL sampler, which runs on a GPU adapter only; run without --cpu")));
    }
    let backend = Backend::open(args.cpu)?;
    check_fits(&backend, &scene)?;
    Ok((scene, backend))
}

/// A run that stops before its cases (bad input, no adapter) into an output folder that
/// already exists: the earlier run's outputs are removed and the summary files say why no case
/// ran (status `error`), so that CI reads this run's failure, never the earlier run's pass.
pub(super) fn record_error(folder: &OutFolder, significance: f64, err: &anyhow::Error) {
    let written = folder.clean(&[]).and_then(|stale| {
        let summary = RunSummary { stale, ..RunSummary::of_error(significance, format!("{err:#}")) };
        crate::report::summary::write(folder.path(), &summary, &[])
    });
    if let Err(e) = written {
        crate::console::say(format_args!("lobes: error: {e:#}"));
    }
}

pub fn run(args: &RunArgs) -> anyhow::Result<()> {
    if let Some(shard) = args.shard {
        return run_shard(args, shard);
    }
    // An --out that exists is locked first: where another lobes holds it, nothing is touched
    let existing = args.files.claim_existing(&args.out)?;
    let (scene, mut backend) = match start(args) {
        Ok(started) => started,
        Err(e) => {
            if let Some(folder) = &existing {
                record_error(folder, args.significance, &e);
            }
            return Err(e);
        }
    };
    let folder = match existing {
        Some(folder) => folder,
        None => args.files.claim(&args.out, Access::Owner)?,
    };
    let names: Vec<String> = scene.entries().map(|(e, _)| e.name().to_string()).collect();
    let stale = folder.clean(&names.iter().map(String::as_str).collect::<Vec<_>>())?;
    if !stale.is_empty() {
        crate::console::say(format_args!(
            "lobes: note: removed the outputs of {} cases of an earlier run in {} that this run does not have ({})",
            stale.len(),
            args.out.display(),
            stale.join(", ")
        ));
    }
    let n = scene.len();
    let level = sidak(args.significance, n);
    let heading = vec![format!("adapter: {}", backend.adapter()), format!("significance {} (Šidák over {n} cases: {level:.3e} each)", args.significance)];
    let summary = Arc::new(Mutex::new(RunSummary { stale, ..RunSummary::new(backend.adapter(), backend.name().into(), args.significance, level) }));
    interrupt::watch("stopping after the case in flight (a case of your own sampler stops at once); interrupt again to stop now", None)?;
    summary_on_exit(names, args.out.clone(), heading.clone(), summary.clone());
    let table = run_cases(args, &scene, &mut backend, level, &summary);
    let summary = summary.lock().unwrap_or_else(|p| p.into_inner()).clone();
    let written = crate::report::summary::write(&args.out, &summary, &heading);
    if args.output.json {
        emit_json(&summary)?;
    } else {
        emit(&table.text(args, &heading, &summary, n))?;
    }
    verdict(&summary, n, written)
}

/// A second signal ends the process at once: it writes the summary first, the case in flight
/// and the rest as not run.
fn summary_on_exit(all: Vec<String>, out: PathBuf, heading: Vec<String>, shared: Arc<Mutex<RunSummary>>) {
    interrupt::before_exit(move || {
        let mut s = shared.lock().unwrap_or_else(|p| p.into_inner()).clone();
        s.status = RunStatus::Interrupted;
        s.not_run = all.iter().filter(|n| !s.cases.iter().any(|c| &c.case == *n)).cloned().collect();
        if let Err(e) = crate::report::summary::write(&out, &s, &heading) {
            crate::console::say(format_args!("lobes: error: {e:#}"));
        }
    });
}

/// The table's rows, and which footnotes they need.
#[derive(Default)]
struct Table {
    rows: Vec<[String; 9]>,
    /// Rows timed by the wall clock (no timestamp queries, or the CPU engine), and rows of a
    /// user's sampler.
    wall_rows: bool,
    user_rows: bool,
}

impl Table {
    /// The row of a case that has no result: its name, samples and the word.
    fn push_dashes(&mut self, entry: &Entry, word: &str) {
        self.rows.push(output::dash_row(entry, word));
    }

    fn text(&self, args: &RunArgs, heading: &[String], summary: &RunSummary, n: usize) -> String {
        let mut text = format!("{}\n\n", heading.join("\n"));
        text += &output::format_table(&self.rows);
        if self.wall_rows {
            text += if args.cpu { "\n* wall time of the CPU engine (--cpu)\n" } else { "\n* wall time: the adapter has no timestamp queries\n" };
        }
        if self.user_rows {
            text += "\n† a WGSL sampler of your own: wall time of all its checks (lobes check); FAIL names the checks that failed\n";
        }
        if self.rows.iter().any(|r| r[1].ends_with(output::BUDGET_MARK)) {
            text += &format!("\n{} the count the case's budget picked: pilot checks measured its time on this adapter (histogram.json: user_sampler.budget)\n", output::BUDGET_MARK);
        }
        if !summary.not_run.is_empty() {
            text += &format!("\ninterrupted: {} of {n} cases not run ({})\n", summary.not_run.len(), summary.not_run.join(", "));
        }
        text + &format!("\noutputs in {} (index.html, summary.json, junit.xml)\n", args.out.display())
    }
}

/// Every case of `scene` in turn. A case that cannot run (a write that fails, a lost device) is
/// reported and the others still run; a stop asked for by SIGINT/SIGTERM ends the run after the
/// case in flight.
fn run_cases(args: &RunArgs, scene: &Scene, backend: &mut Backend, level: f64, summary: &Mutex<RunSummary>) -> Table {
    let record = |f: &mut dyn FnMut(&mut RunSummary)| f(&mut summary.lock().unwrap_or_else(|p| p.into_inner()));
    let mut table = Table::default();
    let plain = PlainProgress::new(scene.len());
    // The case in which the device was lost: no further case runs on it.
    let mut lost: Option<String> = None;
    for (i, (entry, at)) in scene.entries().enumerate() {
        if interrupt::requested() {
            record(&mut |s| s.not_run_now(entry.name()));
            continue;
        }
        let t = Instant::now();
        let outcome = match &lost {
            Some(why) => Err(anyhow::anyhow!("not run: {why}")),
            None => run_entry(args, backend, &entry, level, &plain, i, &mut table),
        };
        let verdict = match outcome {
            Ok((row, case_summary)) => {
                table.rows.push(row);
                record(&mut |s| s.push(case_summary.clone()));
                if case_summary.passed { "pass" } else { "FAIL" }
            }
            Err(e) if stopped(&e) => {
                // the case in flight stopped by SIGINT/SIGTERM did not finish: it is not run
                record(&mut |s| s.not_run_now(entry.name()));
                continue;
            }
            Err(e) if timed_out(&e) => {
                // a failure of the case, with its reason; the device still runs its work
                crate::console::say(format_args!("lobes: case '{}' ({at}) FAILED: {e:#}; the remaining cases do not run on this GPU device", entry.name()));
                lost = Some(format!("the GPU device is still running case '{}', which ran out of time", entry.name()));
                table.push_dashes(&entry, "FAIL");
                record(&mut |s| s.push(CaseSummary { failure: Some(format!("{e:#}")), error: None, ..CaseSummary::error(&entry, String::new()) }));
                "FAIL"
            }
            Err(e) => {
                if lost.is_none() {
                    crate::console::say(format_args!("lobes: error: case '{}' ({at}): {e:#}; no histogram.json was written for it", entry.name()));
                    if device_lost(&e) {
                        crate::console::say(format_args!("lobes: error: the GPU device is unusable; the remaining cases do not run"));
                        lost = Some(format!("the GPU device was lost in case '{}'", entry.name()));
                    }
                }
                table.push_dashes(&entry, "ERROR");
                record(&mut |s| s.push(CaseSummary::error(&entry, format!("{e:#}"))));
                "ERROR"
            }
        };
        plain.finished(i, entry.name(), verdict, t.elapsed().as_secs_f64());
    }
    table
}

/// One case: a lobe's on the engine, a user's sampler through `lobes check`; its table row and
/// summary.
fn run_entry(args: &RunArgs, backend: &mut Backend, entry: &Entry, level: f64, plain: &PlainProgress, i: usize, table: &mut Table) -> anyhow::Result<([String; 9], CaseSummary)> {
    match entry {
        Entry::Lobe(case) => {
            let bar = progress_bar(case.samples, &case.name);
            let outcome = run_and_write(backend, case, level, &args.out, args.files.style(), &mut plain.samples(i, &case.name, case.samples, &bar));
            bar.finish_and_clear();
            outcome.map(|result| {
                table.wall_rows |= result.gpu_seconds.is_none();
                let ran = Outcome::Lobe(&result);
                (output::table_row(ran), CaseSummary { backend: Some(backend.name().into()), ..CaseSummary::of(ran, &args.out) })
            })
        }
        Entry::User(case) => {
            table.user_rows = true;
            let bar = ProgressBar::new_spinner().with_message(format!("{}: lobes check", case.name));
            bar.enable_steady_tick(Duration::from_millis(200));
            // a user's sampler may never return: a signal stops it at once
            let _stop = match &*backend {
                Backend::Gpu(engine) => Some(engine.gpu.stop_when(interrupt::requested)),
                Backend::Cpu => None,
            };
            let outcome = run_user_and_write(backend, case, level, &args.out, args.files.style());
            bar.finish_and_clear();
            outcome
        }
    }
}

/// The run's exit: interrupted (130), cases failed (1), cases that could not run.
fn verdict(summary: &RunSummary, n: usize, written: anyhow::Result<()>) -> anyhow::Result<()> {
    let (errors, failed) = (summary.errors, summary.failed);
    if summary.status == RunStatus::Interrupted {
        if let Err(e) = &written {
            crate::console::say(format_args!("lobes: error: {e:#}"));
        }
        let finished = n - summary.not_run.len();
        return Err(Interrupted(format!("interrupted after {finished} of {n} cases ({errors} could not run, {failed} failed)")).into());
    }
    written?;
    match (errors, failed) {
        (0, 0) => Ok(()),
        (0, f) => Err(ChecksFailed(format!("{f} of {n} cases failed the χ² test or the albedo checks (or, for a WGSL sampler, one of its checks)")).into()),
        (e, 0) => anyhow::bail!("{e} of {n} cases could not run (see the errors above)"),
        (e, f) => anyhow::bail!("{e} of {n} cases could not run and {f} failed the χ² test or the albedo checks"),
    }
}

/// Whether `e` is a user's case stopped by SIGINT/SIGTERM ([`GpuError::Stopped`]).
fn stopped(e: &anyhow::Error) -> bool {
    e.chain().any(|c| matches!(c.downcast_ref::<GpuError>(), Some(GpuError::Stopped(_))))
}

/// Whether `e` is a user's case out of time ([`GpuError::TimedOut`]): a failure of the case.
fn timed_out(e: &anyhow::Error) -> bool {
    e.chain().any(|c| matches!(c.downcast_ref::<GpuError>(), Some(GpuError::TimedOut { .. })))
}

/// `lobes run SCENE --shard I/N --out DIR`: samples shard I of every case and writes
/// `DIR/<case>/shard-I-of-N.json` for `lobes merge`.
fn run_shard(args: &RunArgs, shard: Shard) -> anyhow::Result<()> {
    let (source, scene) = read_scene(args.scene.as_ref(), Overrides::default())?;
    if let Some((name, at)) = first_user_case(&scene) {
        return Err(usage(format!(
            "{at}: case '{name}' is a WGSL sampler of your own, which --shard does not split: its checks (the Jacobian probe, \
             the quadrature of its pdf, the hard cases) judge the whole case, not sums over sample ranges; \
             run it without --shard, or put it in a scene of its own"
        )));
    }
    let mut backend = Backend::open(args.cpu)?;
    let adapter = backend.adapter();
    // shared with other shard runs into the same folder; held until the process ends
    let _folder = args.files.claim(&args.out, Access::Shard)?;
    let origin = ShardOrigin { scene: &source, cases: scene.cases.len(), shard, adapter: &adapter, backend: backend.name() };
    let mut cases = Vec::new();
    for (case_index, case) in scene.cases.iter().enumerate() {
        let sampled = run_case(&mut backend, case, shard.range(case.samples), &mut |_| {})?;
        let file = ShardFile::new(&origin, case_index, case, &sampled);
        let path = output::write_shard(&args.out, &file)?;
        cases.push(ShardCaseSummary::of(&file, path));
    }
    let hash = fnv1a64(&source.text);
    if args.output.json {
        emit_json(&ShardSummary { format_version: SUMMARY_VERSION, shard, adapter, backend: backend.name().into(), scene_fnv1a64: hash, cases })?;
    } else {
        let mut t = format!("adapter: {adapter}\nshard {shard} of scene {} ({hash})\n\n", source.name);
        let w = cases.iter().map(|c| c.case.len()).max().unwrap_or(4).max(4);
        t += &format!("{:<w$}  {:>25}  {:>10}\n", "case", "samples", "time");
        for c in &cases {
            let time = c.gpu_seconds.map_or(format!("{:.3} s*", c.wall_seconds), |g| format!("{g:.3} s"));
            t += &format!("{:<w$}  {:>25}  {time:>10}\n", c.case, format!("{}..{}", c.first, c.end));
        }
        t += &format!("\nshard files in {}/<case>/{}; add them up with `lobes merge`\n", args.out.display(), shard.file_name());
        emit(&t)?;
    }
    Ok(())
}
