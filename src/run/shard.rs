//! Scale-out: shard I of N of a case, and the shard file that carries its raw results.
//!
//! Sample `i` of a case depends only on (seed, i) (counter-based RNG), and histograms add, so
//! shard I of N (0-based) histograms samples `⌊I·S/N⌋ .. ⌊(I+1)·S/N⌋` of a case of S samples,
//! and the merged counts ([`super::merge`]) are bit-identical to the unsharded run on the same
//! adapter.
//!
//! A shard file, `DIR/<case>/shard-I-of-N.json`, is a [`ShardFile`]: the case and its range,
//! the raw counts (flat, row-major), the per-sample check (only in the shard that starts at
//! sample 0), the weighted sums of a weighted case, and the scene's full text, so that
//! `lobes merge` needs nothing else. Floats are written so that they read back bit-exactly
//! (serde_json's `float_roundtrip`).
//!
//! A shard file is read only by the lobes that wrote it (the same `lobes_version`: another
//! version may draw or count differently), and carries a checksum of its results
//! (`counts_fnv1a64`, [`ShardFile::checksum`]): its counts are totalled with checked additions
//! and must add up to its range, and an edit that keeps the total (a count moved from one bin to
//! another) changes the checksum. Both are refused as bad input. (The checksum finds edits and
//! damage, not an attacker: anyone can recompute it.)

use super::record::{CaseDescription, Subject, Timing, WeightedTiming};
use crate::reference::ByReason;
use super::Sampled;
use crate::engine::gpu::WeightedRun;
use crate::engine::job::Counts;
use crate::reference::Invalid;
use crate::scene::Case;
use crate::run::compare::AngleCheck;
use crate::stats::weighted::WeightedSums;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The format tag of a shard file.
pub const SHARD_FORMAT: &str = "lobes-shard";
/// The version of the shard file layout (1: the layout before `format_version`, with the
/// exact bits of the per-sample check in a side field; 3: `counts_fnv1a64`; 4: `counting` in
/// place of `workgroup_counting`; 5: `invalid`'s first two keys `non_finite_point` and
/// `outside_domain`, the names `lobes check` gives them, were `non_finite_direction` and
/// `below_horizon`).
pub const SHARD_VERSION: u32 = 5;
/// The lobes that writes (and alone reads) shard files.
pub const LOBES_VERSION: &str = env!("CARGO_PKG_VERSION");

/// Bad shards: a file that is not a readable shard of this lobes, or shards that do not add up
/// to one scene. Bad input: the CLI exits with its usage code, and adds the command that writes
/// what is missing.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShardError {
    /// A folder given holds no shard file.
    #[error("{}: no shard files (<case>/shard-I-of-N.json) found", dir.display())]
    NoneIn { dir: std::path::PathBuf },
    /// No shard covers samples `from .. to` of a case.
    #[error("case '{case}': samples {from}..{to} are missing (no shard covers them)")]
    Missing { case: String, from: u64, to: u64 },
    /// Any other: an unreadable file, shards of different scenes, overlaps…
    #[error("{0}")]
    Bad(String),
}

/// Shard `index` of `count` (0-based: `0 ≤ index < count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
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
    /// use lobes::run::shard::Shard;
    /// let r: Vec<_> = (0..3).map(|i| Shard { index: i, count: 3 }.range(10)).collect();
    /// assert_eq!(r, [0..3, 3..6, 6..10]);
    /// ```
    pub fn range(&self, samples: u64) -> Range<u64> {
        let at = |i: u64| (samples as u128 * i as u128 / self.count as u128) as u64;
        at(self.index)..at(self.index + 1)
    }

    /// `shard-I-of-N.json`.
    ///
    /// ```
    /// assert_eq!(lobes::run::shard::Shard { index: 2, count: 8 }.file_name(), "shard-2-of-8.json");
    /// ```
    pub fn file_name(&self) -> String {
        format!("shard-{}-of-{}.json", self.index, self.count)
    }

    /// Parses `I/N`, 0 ≤ I < N (a Slurm array index with `--array=0-(N-1)`, or a Kubernetes
    /// indexed Job's `JOB_COMPLETION_INDEX`).
    ///
    /// ```
    /// use lobes::run::shard::Shard;
    /// assert_eq!(Shard::parse("2/8"), Ok(Shard { index: 2, count: 8 }));
    /// assert!(Shard::parse("8/8").is_err());
    /// assert!(Shard::parse("1").is_err());
    /// ```
    pub fn parse(s: &str) -> Result<Shard, String> {
        let hint = "give I/N with 0 ≤ I < N, e.g. 0/4 (I counts from 0, like SLURM_ARRAY_TASK_ID with --array=0-(N-1) or JOB_COMPLETION_INDEX)";
        let (i, n) = s.split_once('/').ok_or_else(|| format!("'{s}' is not a shard; {hint}"))?;
        let parse = |x: &str| x.trim().parse::<u64>().map_err(|_| format!("'{s}' is not a shard: '{x}' is not a whole number; {hint}"));
        let (index, count) = (parse(i)?, parse(n)?);
        if count == 0 || index >= count {
            return Err(format!("'{s}' is not a shard: I = {index} is not in 0..{count}; {hint}"));
        }
        Ok(Shard { index, count })
    }

    /// Whether `path` is named like a shard file, `shard-I-of-N.json`.
    pub fn is_file_name(path: &Path) -> bool {
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else { return false };
        let Some(mid) = name.strip_prefix("shard-").and_then(|n| n.strip_suffix(".json")) else { return false };
        mid.split_once("-of-").is_some_and(|(i, n)| i.parse::<u64>().is_ok() && n.parse::<u64>().is_ok())
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// 64-bit FNV-1a of the scene text, to name a scene in errors and files.
///
/// ```
/// assert_eq!(lobes::run::shard::fnv1a64(""), "cbf29ce484222325");
/// assert_eq!(lobes::run::shard::fnv1a64("a"), "af63dc4c8601ec8c");
/// ```
pub fn fnv1a64(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// The scene a shard belongs to: its file name when the shard was run and its full text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneSource {
    pub name: String,
    pub text: String,
}

/// Where a shard run's files come from: the scene, the shard, and what drew the samples.
#[derive(Debug, Clone, Copy)]
pub struct ShardOrigin<'a> {
    pub scene: &'a SceneSource,
    /// The scene's number of cases.
    pub cases: usize,
    pub shard: Shard,
    pub adapter: &'a str,
    /// `gpu` or `cpu`.
    pub backend: &'a str,
}

/// A shard file, `DIR/<case>/shard-I-of-N.json`, as written and read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ShardFile {
    /// Always `lobes-shard`.
    #[schemars(extend("const" = SHARD_FORMAT))]
    pub format: String,
    /// [`SHARD_VERSION`].
    pub format_version: u32,
    /// The lobes that wrote it.
    pub lobes_version: String,
    /// The case's name, its index in the scene and the scene's number of cases.
    pub case: String,
    pub case_index: usize,
    pub cases: usize,
    #[serde(flatten)]
    pub description: CaseDescription,
    pub seed: u64,
    /// The case's sample count (all shards together).
    pub samples: u64,
    pub shard: Shard,
    /// The sample range of this shard, `first .. end`.
    pub first: u64,
    pub end: u64,
    /// Raw counts per bin, flat and row-major (`rows × cols`).
    pub counts: Vec<u64>,
    /// Raw counts per invalid reason.
    pub invalid: ByReason<u64>,
    pub adapter: String,
    /// `gpu` or `cpu`.
    pub backend: String,
    pub timing: Timing,
    /// How the GPU counted the bins (`workgroup`, `workgroup-packed`, `global` or `slabs`:
    /// [`crate::engine::gpu::Counting`]); null on the CPU engine.
    pub counting: Option<String>,
    /// GPU directions of the first samples against f64 (only in the shard that starts at 0).
    pub per_sample_check: Option<AngleCheck>,
    /// The weighted sums of a case with effects, and the time of their pass.
    pub weighted: Option<WeightedSums>,
    pub weighted_timing: Option<WeightedTiming>,
    /// The scene's file name, the FNV-1a hash of its text, and the text.
    pub scene_name: String,
    pub scene_fnv1a64: String,
    pub scene: String,
    /// The FNV-1a hash of the results that merge adds up ([`ShardFile::checksum`]).
    pub counts_fnv1a64: String,
}

/// The results a shard's checksum covers, in the order hashed.
#[derive(Serialize)]
struct Results<'a> {
    first: u64,
    end: u64,
    counts: &'a [u64],
    invalid: &'a ByReason<u64>,
    weighted: &'a Option<WeightedSums>,
}

/// The minimum read first, to tell a file of another kind or version from a damaged one.
#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    format_version: Option<u64>,
    version: Option<u64>,
    lobes_version: Option<String>,
}

impl ShardFile {
    /// The shard file of case `case_index` of the run `origin`.
    pub fn new(origin: &ShardOrigin, case_index: usize, case: &Case, sampled: &Sampled) -> ShardFile {
        let (scene, shard) = (origin.scene, origin.shard);
        let range = shard.range(case.samples);
        ShardFile {
            format: SHARD_FORMAT.into(),
            format_version: SHARD_VERSION,
            lobes_version: env!("CARGO_PKG_VERSION").into(),
            case: case.name.clone(),
            case_index,
            cases: origin.cases,
            description: CaseDescription::of(Subject::Lobe(case)),
            seed: case.seed,
            samples: case.samples,
            shard,
            first: range.start,
            end: range.end,
            counts: sampled.counts.bins.clone(),
            invalid: sampled.counts.invalid.into(),
            adapter: origin.adapter.into(),
            backend: origin.backend.into(),
            timing: Timing { gpu_seconds: sampled.gpu_seconds, histogram_wall_seconds: sampled.wall_seconds },
            counting: sampled.counting.clone(),
            per_sample_check: sampled.angle.clone(),
            weighted: sampled.weighted.as_ref().map(|w| w.sums.clone()),
            weighted_timing: sampled.weighted.as_ref().map(|w| WeightedTiming { gpu_seconds: w.gpu_seconds, wall_seconds: w.wall_seconds }),
            scene_name: scene.name.clone(),
            scene_fnv1a64: fnv1a64(&scene.text),
            scene: scene.text.clone(),
            counts_fnv1a64: String::new(),
        }
        .sealed()
    }

    /// The FNV-1a hash of the results merge adds up: the range, the counts, the invalid counts
    /// and the weighted sums (as their JSON, which reads back exactly).
    pub fn checksum(&self) -> String {
        let results = Results { first: self.first, end: self.end, counts: &self.counts, invalid: &self.invalid, weighted: &self.weighted };
        fnv1a64(&serde_json::to_string(&results).expect("numbers serialise"))
    }

    /// The file with its checksum set (after results are changed on purpose, as tests do).
    pub fn sealed(mut self) -> ShardFile {
        self.counts_fnv1a64 = self.checksum();
        self
    }

    /// Parses and checks a shard file's text; `path` names it in errors.
    pub fn parse(path: &Path, text: &str) -> Result<ShardFile, ShardError> {
        let bad = |what: String| ShardError::Bad(format!("{}: {what}", path.display()));
        let header: Header = serde_json::from_str(text).map_err(|e| bad(format!("not a lobes shard file (invalid JSON: {e})")))?;
        if header.format.as_deref() != Some(SHARD_FORMAT) {
            return Err(bad(format!("not a lobes shard file (no \"format\": \"{SHARD_FORMAT}\")")));
        }
        let version = header.format_version.or(header.version);
        if version != Some(SHARD_VERSION as u64) {
            let v = version.map_or("(none)".to_string(), |v| v.to_string());
            return Err(bad(format!(
                "shard format version {v} is not supported (this lobes reads version {SHARD_VERSION}); run the shard again with this lobes"
            )));
        }
        if let Some(v) = header.lobes_version.as_deref().filter(|v| *v != LOBES_VERSION) {
            return Err(bad(format!(
                "written by lobes {v}, and this is lobes {LOBES_VERSION}: another version may draw or count samples differently; \
                 run the shard again with this lobes"
            )));
        }
        let s: ShardFile = serde_json::from_str(text).map_err(|e| bad(format!("not a valid shard file: {e}")))?;
        if s.first > s.end || s.end > s.samples {
            return Err(bad(format!("sample range {}..{} is not within 0..{}", s.first, s.end, s.samples)));
        }
        let cells = s.counts.iter().chain(<[u64; Invalid::COUNT]>::from(s.invalid).iter()).copied().collect::<Vec<u64>>();
        let total = cells.iter().try_fold(0u64, |t, &c| t.checked_add(c));
        if total != Some(s.end - s.first) {
            let total = total.map_or("more than 2^64 − 1".to_string(), |t| t.to_string());
            return Err(bad(format!(
                "counts add up to {total} but the range {}..{} has {} samples (a damaged or edited file)",
                s.first,
                s.end,
                s.end - s.first
            )));
        }
        let checksum = s.checksum();
        if s.counts_fnv1a64 != checksum {
            return Err(bad(format!(
                "the results do not match their checksum (counts_fnv1a64 {} in the file, {checksum} of its counts, invalid counts \
                 and weighted sums): the file was edited or damaged; run the shard again",
                s.counts_fnv1a64
            )));
        }
        if let Some(why) = backend_mismatch(&s.backend, &s.adapter) {
            return Err(bad(why));
        }
        if let Some(w) = &s.weighted
            && (w.bins.len() != s.counts.len() || w.max_error.len() != s.counts.len())
        {
            return Err(bad(format!("field 'weighted' has {} bins where 'counts' has {}", w.bins.len(), s.counts.len())));
        }
        Ok(s)
    }

    /// Reads and checks a shard file.
    pub fn read(path: &Path) -> Result<ShardFile, ShardError> {
        let text = std::fs::read_to_string(path).map_err(|e| ShardError::Bad(format!("{}: cannot read: {e}", path.display())))?;
        Self::parse(path, &text)
    }

    /// Its results, to add up with the other shards of the case.
    pub fn sampled(&self) -> Sampled {
        Sampled {
            counts: Counts { bins: self.counts.clone(), invalid: self.invalid.into() },
            gpu_seconds: self.timing.gpu_seconds,
            wall_seconds: self.timing.histogram_wall_seconds,
            counting: self.counting.clone(),
            angle: self.per_sample_check.clone(),
            weighted: self.weighted.as_ref().map(|sums| WeightedRun {
                sums: sums.clone(),
                gpu_seconds: self.weighted_timing.and_then(|t| t.gpu_seconds),
                wall_seconds: self.weighted_timing.map_or(0.0, |t| t.wall_seconds),
            }),
        }
    }
}

/// Why a shard's `backend` cannot be what drew it: not one lobes writes, or not the kind of its
/// `adapter` (the CPU engine's adapter is `cpu (f64 reference, …)`, [`super::Backend::adapter`]).
fn backend_mismatch(backend: &str, adapter: &str) -> Option<String> {
    let cpu_adapter = adapter.starts_with("cpu (");
    match backend {
        "gpu" | "cpu" if (backend == "cpu") == cpu_adapter => None,
        "gpu" | "cpu" => Some(format!(
            "backend is '{backend}' but the adapter '{adapter}' is {}: the file was edited or damaged; run the shard again",
            if cpu_adapter { "lobes' CPU engine" } else { "a GPU adapter" }
        )),
        other => Some(format!("backend '{other}' is not one lobes writes (gpu or cpu): the file was edited or damaged; run the shard again")),
    }
}

/// A shard file read from disk: where from, and what it holds.
#[derive(Debug, Clone)]
pub struct ShardOnDisk {
    pub path: PathBuf,
    pub file: ShardFile,
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::run::record::Params;

    /// A shard file of a one-item discrete case of 10 samples, covering `first .. end`.
    pub(crate) fn example(first: u64, end: u64) -> ShardFile {
        ShardFile {
            format: SHARD_FORMAT.into(),
            format_version: SHARD_VERSION,
            lobes_version: LOBES_VERSION.into(),
            case: "c".into(),
            case_index: 0,
            cases: 1,
            description: CaseDescription { lobe: "discrete".into(), method: "cdf".into(), params: Params::Discrete { weights: vec![1.0] }, rows: 1, cols: 1 },
            seed: 1,
            samples: 10,
            shard: Shard { index: 0, count: 1 },
            first,
            end,
            counts: vec![end - first],
            invalid: ByReason::from([0; Invalid::COUNT]),
            adapter: "a".into(),
            backend: "gpu".into(),
            timing: Timing { gpu_seconds: None, histogram_wall_seconds: 0.0 },
            counting: None,
            per_sample_check: None,
            weighted: None,
            weighted_timing: None,
            scene_name: "s".into(),
            scene_fnv1a64: fnv1a64(""),
            scene: "".into(),
            counts_fnv1a64: String::new(),
        }
        .sealed()
    }

    /// Every f64 a shard carries reads back bit for bit (serde_json's `float_roundtrip`; without
    /// it, serde_json's fast float parser may be an ulp off).
    #[test]
    fn floats_read_back_exactly() {
        let awkward = [
            0.1 + 0.2,
            std::f64::consts::PI,
            1.0 / 3.0,
            f64::MIN_POSITIVE,
            5e-324, // the smallest subnormal
            f64::MAX,
            -2.2250738585072014e-308,
            1.0000000000000002,
            2.594_800_000_000_000_4e-6,
        ];
        // and values from a simple LCG over all bit patterns of finite doubles
        let mut bits: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut values: Vec<f64> = awkward.to_vec();
        while values.len() < 2000 {
            bits = bits.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let x = f64::from_bits(bits);
            if x.is_finite() {
                values.push(x);
            }
        }
        for pair in values.chunks(2) {
            let mut s = example(0, 10);
            s.timing = Timing { gpu_seconds: Some(pair[0]), histogram_wall_seconds: pair[1] };
            s.per_sample_check = Some(AngleCheck { compared: 4096, validity_mismatches: 0, max_angle_rad: pair[1], mean_angle_rad: pair[0] });
            let s = s.sealed();
            let text = serde_json::to_string(&s).unwrap();
            let back = ShardFile::parse(Path::new("x.json"), &text).unwrap();
            let a = back.per_sample_check.as_ref().unwrap();
            assert_eq!(a.max_angle_rad.to_bits(), pair[1].to_bits(), "{text}");
            assert_eq!(a.mean_angle_rad.to_bits(), pair[0].to_bits());
            assert_eq!(back.timing.gpu_seconds.unwrap().to_bits(), pair[0].to_bits());
            assert_eq!(back, s);
        }
    }

    #[test]
    fn files_of_another_kind_or_version_are_refused() {
        let good = serde_json::to_value(example(0, 10)).unwrap();
        let err = |v: serde_json::Value| ShardFile::parse(Path::new("d/x.json"), &v.to_string()).unwrap_err().to_string();
        let mut old = good.clone();
        old.as_object_mut().unwrap().remove("format_version");
        old["version"] = 1.into();
        assert!(err(old).contains(&format!("d/x.json: shard format version 1 is not supported (this lobes reads version {SHARD_VERSION})")));
        let mut other = good.clone();
        other["format"] = "lobes-histogram".into();
        assert!(err(other).contains("not a lobes shard file"));
        let mut damaged = good.clone();
        damaged["counts"] = serde_json::json!([9]);
        assert!(err(damaged).contains("counts add up to 9 but the range 0..10 has 10 samples"));
        let mut newer = good.clone();
        newer["lobes_version"] = "9.9.9".into();
        let e = err(newer);
        assert!(e.contains("d/x.json: written by lobes 9.9.9, and this is lobes ") && e.contains("run the shard again with this lobes"), "{e}");
        let mut quantum = good.clone();
        quantum["backend"] = "quantum".into();
        assert!(err(quantum).contains("backend 'quantum' is not one lobes writes (gpu or cpu)"));
        let mut cpu = good.clone();
        cpu["backend"] = "cpu".into();
        assert!(err(cpu).contains("backend is 'cpu' but the adapter 'a' is a GPU adapter"));
        let mut missing = good;
        missing.as_object_mut().unwrap().remove("seed");
        assert!(err(missing).contains("missing field `seed`"));
        assert!(ShardFile::parse(Path::new("x"), "{").unwrap_err().to_string().contains("invalid JSON"));
    }

    /// Issue 24 item 9: a bin set to 2⁶⁴ − 1 with a bin that wraps the total back to the range
    /// was accepted (the unchecked sum wrapped); a count moved between bins kept the total.
    #[test]
    fn counts_that_wrap_or_move_are_refused() {
        let mut two = example(0, 10);
        two.counts = vec![4, 6];
        two.description.cols = 2;
        let good = serde_json::to_value(two.sealed()).unwrap();
        assert!(ShardFile::parse(Path::new("x.json"), &good.to_string()).is_ok());
        let err = |v: &serde_json::Value| ShardFile::parse(Path::new("x.json"), &v.to_string()).unwrap_err().to_string();
        let mut wraps = good.clone();
        // (2^64 − 1) + 11 wraps to 10, the range's length
        wraps["counts"] = serde_json::json!([u64::MAX, 11]);
        assert!(err(&wraps).contains("counts add up to more than 2^64 − 1"), "{}", err(&wraps));
        let mut moved = good.clone();
        moved["counts"] = serde_json::json!([5, 5]);
        assert!(err(&moved).contains("do not match their checksum"), "{}", err(&moved));
        let mut resealed: ShardFile = serde_json::from_value(moved).unwrap();
        resealed = resealed.sealed();
        assert!(ShardFile::parse(Path::new("x.json"), &serde_json::to_string(&resealed).unwrap()).is_ok(), "a sealed edit passes");
    }

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

    #[test]
    fn shard_names() {
        assert!(Shard::is_file_name(Path::new("x/shard-0-of-3.json")));
        assert!(!Shard::is_file_name(Path::new("x/histogram.json")));
        assert!(!Shard::is_file_name(Path::new("x/shard-a-of-3.json")));
    }
}
