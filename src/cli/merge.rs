//! Scale-out: `lobes run SCENE --shard I/N` runs one index range of every case and writes its
//! raw counts; `lobes merge DIR... --out DIR` adds the shards of a scene and judges the sums.
//!
//! Sample `i` of a case depends only on (seed, i) (counter-based RNG), and histograms add, so
//! shard I of N (0-based) histograms samples `⌊I·S/N⌋ .. ⌊(I+1)·S/N⌋` of a case of S samples,
//! and the merged counts are bit-identical to the unsharded run on the same adapter.
//!
//! A shard file, `DIR/<case>/shard-I-of-N.json`, holds (format `lobes-shard`, version 1):
//! `case`, `case_index`, `seed`, `samples` (of the whole case), `shard` (`index`, `count`),
//! `first` and `end` (the sample range `first .. end`), `lobe`, `method`, `params`, `rows`,
//! `cols`, `counts` (flat, row-major, `rows × cols`), `invalid` (reason → count), `adapter`,
//! `backend`, `timing`, `workgroup_counting`, `per_sample_check` (only in the shard that starts
//! at sample 0: the GPU directions of the first samples against f64, with the exact bits of its
//! two angles in `per_sample_check_f64_bits`), and the scene itself
//! (`scene`: its full text, `scene_name`, `scene_fnv1a64`), so that `lobes merge` needs nothing
//! else.

use super::{OutputArgs, emit, emit_json, usage};
use crate::engine::gpu::WeightedRun;
use crate::engine::job::{Counts, Job, SampleRange};
use crate::reference::Invalid;
use crate::report::output;
use crate::run::{self, ANGLE_CHECK_SAMPLES, Backend, CaseResult};
use crate::scene::{Case, DEFAULT_SCENE, Scene};
use crate::stats::chi2::sidak;
use crate::stats::compare::{self, AngleCheck};
use crate::stats::weighted::WeightedSums;
use clap::Args;
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The format tag of a shard file.
pub const SHARD_FORMAT: &str = "lobes-shard";
/// The version of the shard file layout.
pub const SHARD_VERSION: u64 = 1;

/// Shard `index` of `count` (0-based: `0 ≤ index < count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// I, counting from 0.
    pub index: u64,
    /// N, the number of shards.
    pub count: u64,
}

impl Shard {
    /// The sample range `first .. end` of this shard of a case of `samples` samples: contiguous
    /// ranges that tile `0 .. samples`, their lengths differing by at most one.
    ///
    /// ```
    /// use lobes::cli::merge::Shard;
    /// let r: Vec<_> = (0..3).map(|i| Shard { index: i, count: 3 }.range(10)).collect();
    /// assert_eq!(r, [0..3, 3..6, 6..10]);
    /// ```
    pub fn range(&self, samples: u64) -> std::ops::Range<u64> {
        let at = |i: u64| (samples as u128 * i as u128 / self.count as u128) as u64;
        at(self.index)..at(self.index + 1)
    }

    /// `shard-I-of-N.json`.
    ///
    /// ```
    /// assert_eq!(lobes::cli::merge::Shard { index: 2, count: 8 }.file_name(), "shard-2-of-8.json");
    /// ```
    pub fn file_name(&self) -> String {
        format!("shard-{}-of-{}.json", self.index, self.count)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Parses `I/N`, 0 ≤ I < N (a Slurm array index with `--array=0-(N-1)`, or a Kubernetes
/// indexed Job's `JOB_COMPLETION_INDEX`).
///
/// ```
/// use lobes::cli::merge::{parse_shard, Shard};
/// assert_eq!(parse_shard("2/8"), Ok(Shard { index: 2, count: 8 }));
/// assert!(parse_shard("8/8").is_err());
/// assert!(parse_shard("1").is_err());
/// ```
pub fn parse_shard(s: &str) -> Result<Shard, String> {
    let hint = "give I/N with 0 ≤ I < N, e.g. --shard 0/4 (I counts from 0, like SLURM_ARRAY_TASK_ID with --array=0-(N-1) or JOB_COMPLETION_INDEX)";
    let (i, n) = s.split_once('/').ok_or_else(|| format!("'{s}' is not a shard; {hint}"))?;
    let parse = |x: &str| x.trim().parse::<u64>().map_err(|_| format!("'{s}' is not a shard: '{x}' is not a whole number; {hint}"));
    let (index, count) = (parse(i)?, parse(n)?);
    if count == 0 || index >= count {
        return Err(format!("'{s}' is not a shard: I = {index} is not in 0..{count}; {hint}"));
    }
    Ok(Shard { index, count })
}

/// 64-bit FNV-1a of the scene text, to name a scene in errors and files.
///
/// ```
/// assert_eq!(lobes::cli::merge::fnv1a64(""), "cbf29ce484222325");
/// assert_eq!(lobes::cli::merge::fnv1a64("a"), "af63dc4c8601ec8c");
/// ```
pub fn fnv1a64(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// Reads a scene's name and text (the embedded default for `None`) and validates it, with the
/// errors of `lobes run` ([`super::run::load_scene`]).
pub fn scene_text(path: Option<&PathBuf>) -> anyhow::Result<(String, String, Scene)> {
    let scene = super::run::load_scene(path)?;
    let (name, text) = match path {
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| usage(format!("cannot read scene file {}: {e}", p.display())))?;
            (p.display().to_string(), text)
        }
        None => ("<embedded scenes/all-lobes.toml>".to_string(), DEFAULT_SCENE.to_string()),
    };
    Ok((name, text, scene))
}

/// Creates the `--out` folder; a path that is not a folder or cannot be created is bad input.
fn prepare_out(out: &Path) -> anyhow::Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(usage(format!("--out {}: exists and is not a folder; give a folder (created if missing)", out.display())));
    }
    std::fs::create_dir_all(out).map_err(|e| usage(format!("--out {}: cannot create the output folder: {e}", out.display())))
}

fn reasons(values: &[u64; 4]) -> Value {
    Value::Object(Invalid::ALL.iter().zip(values).map(|(r, &v)| (r.name().to_string(), v.into())).collect())
}

fn describe_case(case: &Case) -> (String, String, Value, usize, usize) {
    match &case.job {
        Job::Lobe { lobe, grid, .. } => (
            lobe.kind.name().into(),
            lobe.method.name().into(),
            json!({"alpha_x": lobe.alpha_x, "alpha_y": lobe.alpha_y,
                   "incident_theta_deg": case.incident_deg.0, "incident_phi_deg": case.incident_deg.1}),
            grid.rows as usize,
            grid.cols as usize,
        ),
        Job::Discrete { dist, method } => {
            ("discrete".into(), format!("{method:?}").to_lowercase(), json!({"weights": dist.weights()}), 1, dist.len())
        }
    }
}

/// `lobes run SCENE --shard I/N --out DIR`: histograms shard I of every case and writes
/// `DIR/<case>/shard-I-of-N.json`. Called by [`super::run::run`] when `--shard` is given.
pub fn run_shard(args: &super::run::RunArgs, shard: Shard) -> anyhow::Result<()> {
    let (scene_name, text, scene) = scene_text(args.scene.as_ref())?;
    let hash = fnv1a64(&text);
    let mut backend = if args.cpu { Backend::Cpu } else { Backend::open_or_cpu() };
    let adapter = backend.adapter();
    prepare_out(&args.out)?;
    let mut rows = Vec::new();
    for (case_index, case) in scene.cases.iter().enumerate() {
        let range = shard.range(case.samples);
        let n = range.end - range.start;
        let run::HistogramRun { counts, gpu_seconds, wall_seconds, workgroup_counting } = run::histogram(&mut backend, case, range.start, n, &mut |_| {})?;
        anyhow::ensure!(counts.total() == n, "case '{}': {} samples counted for {n} requested", case.name, counts.total());
        let angle = match (&mut backend, &case.job) {
            (Backend::Gpu(engine), Job::Lobe { .. }) if range.start == 0 => {
                let k = ANGLE_CHECK_SAMPLES.min(case.samples.min(u32::MAX as u64) as u32);
                let dirs = engine.directions(&case.job, SampleRange::whole(case.seed, k as u64))?;
                Some(compare::angle_check(&case.job, case.seed, 0, &dirs))
            }
            _ => None,
        };
        let weighted = match case.effects {
            Some(_) => Some(run::weighted_sums(&mut backend, case, range.start, n)?),
            None => None,
        };
        let (lobe, method, params, r, c) = describe_case(case);
        let doc = json!({
            "format": SHARD_FORMAT, "version": SHARD_VERSION, "lobes_version": env!("CARGO_PKG_VERSION"),
            "case": case.name, "case_index": case_index, "cases": scene.cases.len(),
            "lobe": lobe, "method": method, "params": params,
            "seed": case.seed, "samples": case.samples,
            "shard": {"index": shard.index, "count": shard.count},
            "first": range.start, "end": range.end,
            "rows": r, "cols": c,
            "counts": counts.bins, "invalid": reasons(&counts.invalid),
            "adapter": adapter, "backend": backend.name(),
            "timing": {"gpu_seconds": gpu_seconds, "histogram_wall_seconds": wall_seconds},
            "workgroup_counting": workgroup_counting,
            "per_sample_check": angle,
            "weighted": weighted.as_ref().map(|w| &w.sums),
            "weighted_timing": weighted.as_ref().map(|w| json!({"gpu_seconds": w.gpu_seconds, "wall_seconds": w.wall_seconds})),
            // serde_json reads floats back to within an ulp only: the exact bits, for the merge.
            "per_sample_check_f64_bits": angle.as_ref().map(|a| json!({
                "max_angle_rad": a.max_angle_rad.to_bits(), "mean_angle_rad": a.mean_angle_rad.to_bits()})),
            "scene_name": scene_name, "scene_fnv1a64": hash, "scene": text,
        });
        let folder = args.out.join(&case.name);
        std::fs::create_dir_all(&folder)?;
        let file = folder.join(shard.file_name());
        crate::report::atomic::write_atomic(&file, serde_json::to_string(&doc)?.as_bytes())
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", file.display()))?;
        rows.push((case.name.clone(), range, gpu_seconds, wall_seconds, file));
    }
    if args.output.json {
        let cases: Vec<Value> = rows
            .iter()
            .map(|(name, r, g, w, f)| json!({"case": name, "first": r.start, "end": r.end, "samples": r.end - r.start,
                                             "gpu_seconds": g, "wall_seconds": w, "file": f}))
            .collect();
        emit_json(&json!({"shard": {"index": shard.index, "count": shard.count}, "adapter": adapter,
                          "backend": backend.name(), "scene_fnv1a64": hash, "cases": cases}))?;
    } else {
        let mut t = format!("adapter: {adapter}\nshard {shard} of scene {scene_name} ({hash})\n\n");
        let w = rows.iter().map(|r| r.0.len()).max().unwrap_or(4).max(4);
        t += &format!("{:<w$}  {:>25}  {:>10}\n", "case", "samples", "time");
        for (name, r, g, wall, _) in &rows {
            let time = g.map_or(format!("{wall:.3} s*"), |g| format!("{g:.3} s"));
            t += &format!("{name:<w$}  {:>25}  {time:>10}\n", format!("{}..{}", r.start, r.end));
        }
        t += &format!("\nshard files in {}/<case>/{}; add them up with `lobes merge`\n", args.out.display(), shard.file_name());
        emit(&t)?;
    }
    Ok(())
}

/// Arguments of `lobes merge`.
#[derive(Debug, Clone, Args)]
pub struct MergeArgs {
    /// Folders (or shard files) to read shards from: each folder's `*/shard-*-of-*.json` and
    /// `shard-*-of-*.json`, as written by `lobes run --shard I/N --out DIR`.
    #[arg(required = true, value_name = "DIR")]
    pub dirs: Vec<PathBuf>,
    /// Output folder: one subfolder per case with histogram.json and PNG heat maps, as `lobes run`.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Family-wise significance level, Šidák-corrected over the scene's cases.
    #[arg(long, default_value_t = 0.01, value_parser = super::run::parse_level, allow_hyphen_values = true)]
    pub significance: f64,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// One shard file, read back.
#[derive(Debug, Clone)]
pub struct ShardFile {
    /// Where it was read from.
    pub path: PathBuf,
    /// The case's name.
    pub case: String,
    /// The case's seed.
    pub seed: u64,
    /// The case's sample count (all shards together).
    pub samples: u64,
    /// The first sample index of this shard.
    pub first: u64,
    /// One past the last sample index of this shard.
    pub end: u64,
    /// The raw counts of samples `first .. end`.
    pub counts: Counts,
    /// The adapter that drew them.
    pub adapter: String,
    /// `gpu` or `cpu`.
    pub backend: String,
    /// GPU time from timestamp queries, where the adapter has them.
    pub gpu_seconds: Option<f64>,
    /// Wall time of the histogram.
    pub wall_seconds: f64,
    /// Whether bins were counted in workgroup memory (GPU only).
    pub workgroup_counting: Option<bool>,
    /// The per-sample check (only in the shard starting at sample 0, on the GPU).
    pub angle: Option<AngleCheck>,
    /// The weighted sums of a case with effects, with the GPU and wall seconds of their pass.
    pub weighted: Option<(WeightedSums, Option<f64>, f64)>,
    /// The scene's file name when the shard was run.
    pub scene_name: String,
    /// The scene's full text.
    pub scene: String,
}

fn is_shard_name(p: &Path) -> bool {
    let Some(name) = p.file_name().and_then(|n| n.to_str()) else { return false };
    let Some(mid) = name.strip_prefix("shard-").and_then(|n| n.strip_suffix(".json")) else { return false };
    mid.split_once("-of-").is_some_and(|(i, n)| i.parse::<u64>().is_ok() && n.parse::<u64>().is_ok())
}

/// The shard files under the given folders (each folder and its immediate subfolders) or
/// named directly, each once, sorted.
pub fn find_shards(dirs: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let mut found = Vec::new();
    for dir in dirs {
        if dir.is_file() {
            found.push(dir.clone());
            continue;
        }
        let list = |d: &Path| -> anyhow::Result<Vec<PathBuf>> {
            let entries = std::fs::read_dir(d).map_err(|e| usage(format!("cannot read folder {}: {e}", d.display())))?;
            Ok(entries.filter_map(|e| e.ok().map(|e| e.path())).collect())
        };
        let mut here = Vec::new();
        for p in list(dir)? {
            if p.is_dir() {
                here.extend(list(&p)?.into_iter().filter(|q| q.is_file() && is_shard_name(q)));
            } else if is_shard_name(&p) {
                here.push(p);
            }
        }
        if here.is_empty() {
            return Err(usage(format!(
                "{}: no shard files (<case>/shard-I-of-N.json) found; write them with `lobes run SCENE --shard I/N --out {}`",
                dir.display(),
                dir.display()
            )));
        }
        found.extend(here);
    }
    let mut seen = std::collections::HashSet::new();
    found.retain(|p| seen.insert(std::fs::canonicalize(p).unwrap_or_else(|_| p.clone())));
    found.sort();
    Ok(found)
}

/// Reads and checks one shard file; every problem is a usage error naming the file.
pub fn read_shard(path: &Path) -> anyhow::Result<ShardFile> {
    let bad = |what: String| usage(format!("{}: {what}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| bad(format!("cannot read: {e}")))?;
    let v: Value = serde_json::from_str(&text).map_err(|e| bad(format!("not a lobes shard file (invalid JSON: {e})")))?;
    if v["format"] != SHARD_FORMAT {
        return Err(bad(format!("not a lobes shard file (no \"format\": \"{SHARD_FORMAT}\")")));
    }
    if v["version"].as_u64() != Some(SHARD_VERSION) {
        return Err(bad(format!("shard format version {} is not supported (this lobes reads version {SHARD_VERSION})", v["version"])));
    }
    let u64_of = |k: &str| v[k].as_u64().ok_or_else(|| bad(format!("missing or invalid field '{k}'")));
    let str_of = |k: &str| v[k].as_str().map(str::to_string).ok_or_else(|| bad(format!("missing or invalid field '{k}'")));
    let bins: Vec<u64> = v["counts"]
        .as_array()
        .and_then(|a| a.iter().map(Value::as_u64).collect())
        .ok_or_else(|| bad("missing or invalid field 'counts'".into()))?;
    let mut invalid = [0u64; 4];
    for (slot, r) in invalid.iter_mut().zip(Invalid::ALL) {
        *slot = v["invalid"][r.name()].as_u64().ok_or_else(|| bad(format!("missing or invalid field 'invalid.{}'", r.name())))?;
    }
    let angle = match &v["per_sample_check"] {
        Value::Null => None,
        a => {
            let exact = |k: &str| match v["per_sample_check_f64_bits"][k].as_u64() {
                Some(bits) => f64::from_bits(bits),
                None => a[k].as_f64().unwrap_or(f64::NAN),
            };
            Some(AngleCheck {
                compared: a["compared"].as_u64().unwrap_or(0),
                validity_mismatches: a["validity_mismatches"].as_u64().unwrap_or(0),
                max_angle_rad: exact("max_angle_rad"),
                mean_angle_rad: exact("mean_angle_rad"),
            })
        }
    };
    let weighted = match &v["weighted"] {
        Value::Null => None,
        w => {
            let sums: WeightedSums = serde_json::from_value(w.clone()).map_err(|e| bad(format!("invalid field 'weighted': {e}")))?;
            if sums.bins.len() != bins.len() || sums.max_error.len() != bins.len() {
                return Err(bad(format!("field 'weighted' has {} bins where 'counts' has {}", sums.bins.len(), bins.len())));
            }
            let t = &v["weighted_timing"];
            Some((sums, t["gpu_seconds"].as_f64(), t["wall_seconds"].as_f64().unwrap_or(0.0)))
        }
    };
    let shard = ShardFile {
        weighted,
        path: path.to_path_buf(),
        case: str_of("case")?,
        seed: u64_of("seed")?,
        samples: u64_of("samples")?,
        first: u64_of("first")?,
        end: u64_of("end")?,
        counts: Counts { bins, invalid },
        adapter: str_of("adapter")?,
        backend: str_of("backend")?,
        gpu_seconds: v["timing"]["gpu_seconds"].as_f64(),
        wall_seconds: v["timing"]["histogram_wall_seconds"].as_f64().unwrap_or(0.0),
        workgroup_counting: v["workgroup_counting"].as_bool(),
        angle,
        scene_name: str_of("scene_name")?,
        scene: str_of("scene")?,
    };
    if shard.first > shard.end || shard.end > shard.samples {
        return Err(bad(format!("sample range {}..{} is not within 0..{}", shard.first, shard.end, shard.samples)));
    }
    if shard.counts.total() != shard.end - shard.first {
        return Err(bad(format!(
            "counts add up to {} but the range {}..{} has {} samples (a damaged file?)",
            shard.counts.total(),
            shard.first,
            shard.end,
            shard.end - shard.first
        )));
    }
    Ok(shard)
}

/// Checks that the shards of one case tile `0 .. samples` exactly (empty ranges ignored) and
/// returns them sorted; a gap or an overlap is a usage error naming the files and ranges.
pub fn check_tiling<'a>(case: &str, samples: u64, shards: &[&'a ShardFile]) -> anyhow::Result<Vec<&'a ShardFile>> {
    let mut sorted: Vec<&ShardFile> = shards.iter().copied().filter(|s| s.end > s.first).collect();
    sorted.sort_by_key(|s| (s.first, s.end));
    let mut at = 0u64;
    let mut last: Option<&ShardFile> = None;
    let missing = |from: u64, to: u64| {
        usage(format!(
            "case '{case}': samples {from}..{to} are missing (no shard covers them); run the missing \
             `lobes run SCENE --shard I/N` and pass its output folder to `lobes merge` too"
        ))
    };
    for s in &sorted {
        if s.first > at {
            return Err(missing(at, s.first));
        }
        if s.first < at {
            let prev = last.expect("a shard before");
            return Err(usage(format!(
                "case '{case}': shards overlap: {} covers samples {}..{} and {} covers {}..{}; pass each shard once",
                prev.path.display(),
                prev.first,
                prev.end,
                s.path.display(),
                s.first,
                s.end
            )));
        }
        at = s.end;
        last = Some(s);
    }
    if at < samples {
        return Err(missing(at, samples));
    }
    Ok(sorted)
}

fn joined(values: impl Iterator<Item = String>) -> String {
    let mut v: Vec<String> = values.collect();
    v.sort();
    v.dedup();
    v.join(" + ")
}

/// `lobes merge DIR... --out DIR`.
pub fn run(args: &MergeArgs) -> anyhow::Result<()> {
    let paths = find_shards(&args.dirs)?;
    let shards = paths.iter().map(|p| read_shard(p)).collect::<anyhow::Result<Vec<_>>>()?;
    let first = &shards[0];
    if let Some(other) = shards.iter().find(|s| s.scene != first.scene) {
        return Err(usage(format!(
            "shards come from different scenes: {} ({}, {}) and {} ({}, {}); merge the shards of one scene at a time",
            first.path.display(),
            first.scene_name,
            fnv1a64(&first.scene),
            other.path.display(),
            other.scene_name,
            fnv1a64(&other.scene)
        )));
    }
    let scene = Scene::parse(&first.scene_name, &first.scene)
        .map_err(|e| usage(format!("{}: the scene stored in the shard does not parse: {e}", first.path.display())))?;
    let mut by_case: BTreeMap<&str, Vec<&ShardFile>> = BTreeMap::new();
    for s in &shards {
        let Some(case) = scene.cases.iter().find(|c| c.name == s.case) else {
            return Err(usage(format!("{}: case '{}' is not in the scene", s.path.display(), s.case)));
        };
        if s.seed != case.seed || s.samples != case.samples || s.counts.bins.len() != case.job.bins() {
            return Err(usage(format!(
                "{}: case '{}' has seed {}, {} samples and {} bins, but the scene says seed {}, {} samples, {} bins",
                s.path.display(),
                s.case,
                s.seed,
                s.samples,
                s.counts.bins.len(),
                case.seed,
                case.samples,
                case.job.bins()
            )));
        }
        by_case.entry(s.case.as_str()).or_default().push(s);
    }
    let mut tiled = Vec::new();
    for case in &scene.cases {
        let list = by_case.get(case.name.as_str()).cloned().unwrap_or_default();
        tiled.push(check_tiling(&case.name, case.samples, &list)?);
    }
    let backends = joined(shards.iter().map(|s| s.backend.clone()));
    let adapter = joined(shards.iter().map(|s| s.adapter.clone()));
    if backends.contains(" + ") || adapter.contains(" + ") {
        eprintln!(
            "warning: the shards come from more than one adapter ({adapter}); their counts add exactly, \
             but the sum is not bit-identical to a run on any one of them"
        );
    }
    let level = sidak(args.significance, scene.cases.len());
    prepare_out(&args.out)?;
    let mut judge_backend = Backend::Cpu;
    let mut rows = Vec::new();
    let mut summary = Vec::new();
    let mut failed = 0;
    for (case, parts) in scene.cases.iter().zip(&tiled) {
        let mut counts = Counts::zeros(case.job.bins());
        for s in parts {
            counts.add(&s.counts);
        }
        anyhow::ensure!(counts.total() == case.samples, "case '{}': shards add up to {} samples, not {}", case.name, counts.total(), case.samples);
        let run::Verdict { expected, chi2, quadrature_seconds, .. } = run::judge(&mut judge_backend, case, counts.clone(), level)?;
        let gpu_seconds = parts.iter().map(|s| s.gpu_seconds).sum::<Option<f64>>();
        let weighted = match &case.effects {
            None => None,
            Some(_) => {
                let mut sums = WeightedSums::zeros(case.job.bins());
                let (mut gpu, mut wall) = (Some(0.0), 0.0);
                for s in parts {
                    let Some((w, g, t)) = &s.weighted else {
                        return Err(usage(format!(
                            "{}: case '{}' is weighted in the scene but this shard has no weighted sums; run the shard again with this lobes",
                            s.path.display(),
                            case.name
                        )));
                    };
                    sums.add(w);
                    gpu = gpu.zip(*g).map(|(a, b)| a + b);
                    wall += t;
                }
                Some(run::judge_weighted(case, WeightedRun { sums, gpu_seconds: gpu, wall_seconds: wall }, level))
            }
        };
        let wcs: Vec<Option<bool>> = parts.iter().map(|s| s.workgroup_counting).collect();
        let result = CaseResult {
            case: case.clone(),
            counts,
            expected,
            chi2,
            gpu_seconds,
            histogram_seconds: parts.iter().map(|s| s.wall_seconds).sum(),
            quadrature_seconds,
            angle: parts.iter().find(|s| s.first == 0).and_then(|s| s.angle.clone()),
            workgroup_counting: if wcs.iter().all(|w| *w == wcs[0]) { wcs[0] } else { None },
            weighted,
        };
        output::write_case(&args.out, &result, &adapter, &backends)?;
        failed += usize::from(!result.passed());
        rows.push(output::table_row(&result));
        summary.push(json!({
            "case": case.name, "samples": case.samples, "shards": parts.len(),
            "albedo": result.weighted.as_ref().map(|w| json!({"albedo": w.check.albedo, "reference": w.check.reference, "passed": w.check.passed})),
            "gpu_seconds": result.gpu_seconds, "wall_seconds": result.histogram_seconds,
            "chi2": result.chi2.statistic, "dof": result.chi2.dof, "p_value": result.chi2.p_value,
            "passed": result.chi2.passed, "max_angle_rad": result.angle.as_ref().map(|a| a.max_angle_rad),
            "output": args.out.join(&case.name),
        }));
    }
    if args.output.json {
        emit_json(&json!({"adapter": adapter, "backend": backends, "significance": args.significance,
                          "per_case_significance": level, "shard_files": shards.len(), "failed": failed, "cases": summary}))?;
    } else {
        let mut text = format!(
            "adapter: {adapter}\nmerged {} shard files of scene {} ({})\nsignificance {} (Šidák over {} cases: {level:.3e} each)\n\n",
            shards.len(),
            first.scene_name,
            fnv1a64(&first.scene),
            args.significance,
            scene.cases.len()
        );
        text += &output::format_table(&rows);
        if shards.iter().any(|s| s.gpu_seconds.is_none()) {
            text += "\n* wall time (no GPU timestamps for some shards)\n";
        }
        text += &format!("\noutputs in {}\n", args.out.display());
        emit(&text)?;
    }
    anyhow::ensure!(failed == 0, "{failed} of {} cases failed the χ² test", scene.cases.len());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_ranges_tile_every_size() {
        for samples in [0u64, 1, 2, 5, 1000, 1_000_001, (1 << 40) + 7] {
            for n in [1u64, 2, 3, 7, 64] {
                let mut at = 0;
                for i in 0..n {
                    let r = Shard { index: i, count: n }.range(samples);
                    assert_eq!(r.start, at);
                    assert!(r.end - r.start <= samples / n + 1);
                    at = r.end;
                }
                assert_eq!(at, samples);
            }
        }
    }

    fn fake(first: u64, end: u64) -> ShardFile {
        ShardFile {
            path: PathBuf::from(format!("s{first}.json")),
            case: "c".into(),
            seed: 1,
            samples: 10,
            first,
            end,
            counts: Counts { bins: vec![end - first], invalid: [0; 4] },
            adapter: "a".into(),
            backend: "gpu".into(),
            gpu_seconds: None,
            wall_seconds: 0.0,
            workgroup_counting: None,
            angle: None,
            weighted: None,
            scene_name: "s".into(),
            scene: "".into(),
        }
    }

    #[test]
    fn tiling_finds_gaps_and_overlaps() {
        let (a, b, c) = (fake(0, 3), fake(3, 6), fake(6, 10));
        assert_eq!(check_tiling("c", 10, &[&c, &a, &b]).unwrap().len(), 3);
        let gap = check_tiling("c", 10, &[&a, &c]).unwrap_err().to_string();
        assert!(gap.contains("samples 3..6 are missing"), "{gap}");
        let tail = check_tiling("c", 10, &[&a, &b]).unwrap_err().to_string();
        assert!(tail.contains("samples 6..10 are missing"), "{tail}");
        let o = fake(2, 5);
        let overlap = check_tiling("c", 10, &[&a, &b, &c, &o]).unwrap_err().to_string();
        assert!(overlap.contains("overlap"), "{overlap}");
        assert_eq!(super::super::exit_code(&check_tiling("c", 10, &[&a]).unwrap_err()), super::super::EXIT_USAGE);
        let empty = fake(3, 3);
        assert_eq!(check_tiling("c", 10, &[&a, &empty, &b, &c]).unwrap().len(), 3);
    }

    #[test]
    fn shard_names() {
        assert!(is_shard_name(Path::new("x/shard-0-of-3.json")));
        assert!(!is_shard_name(Path::new("x/histogram.json")));
        assert!(!is_shard_name(Path::new("x/shard-a-of-3.json")));
    }
}
