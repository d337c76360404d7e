//! Adding up shards: find the shard files, check that they come from one scene and that each
//! case's ranges tile `0 .. samples` exactly, and add each case's results ([`super::Sampled`])
//! for [`super::judge`], the same verdict as an unsharded run.

use super::Sampled;
use super::shard::{Shard, ShardError, ShardFile, ShardOnDisk, fnv1a64};
use crate::scene::{Case, Scene};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The shard files under the given folders (each folder and its immediate subfolders) or
/// named directly, each once, sorted.
pub fn find_shards(dirs: &[PathBuf]) -> Result<Vec<PathBuf>, ShardError> {
    let list = |d: &Path| -> Result<Vec<PathBuf>, ShardError> {
        let entries = std::fs::read_dir(d).map_err(|e| ShardError::Bad(format!("cannot read folder {}: {e}", d.display())))?;
        Ok(entries.filter_map(|e| e.ok().map(|e| e.path())).collect())
    };
    let mut found = Vec::new();
    for dir in dirs {
        if dir.is_file() {
            found.push(dir.clone());
            continue;
        }
        let mut here = Vec::new();
        for p in list(dir)? {
            if p.is_dir() {
                here.extend(list(&p)?.into_iter().filter(|q| q.is_file() && Shard::is_file_name(q)));
            } else if Shard::is_file_name(&p) {
                here.push(p);
            }
        }
        if here.is_empty() {
            return Err(ShardError::NoneIn { dir: dir.clone() });
        }
        found.extend(here);
    }
    let mut seen = std::collections::HashSet::new();
    found.retain(|p| seen.insert(std::fs::canonicalize(p).unwrap_or_else(|_| p.clone())));
    found.sort();
    Ok(found)
}

/// Reads the shard files under `dirs` ([`find_shards`]).
pub fn read_shards(dirs: &[PathBuf]) -> Result<Vec<ShardOnDisk>, ShardError> {
    find_shards(dirs)?.into_iter().map(|path| Ok(ShardOnDisk { file: ShardFile::read(&path)?, path })).collect()
}

/// Checks that the shards of one case tile `0 .. samples` exactly (empty ranges ignored) and
/// returns them sorted; a gap or an overlap is an error naming the files and ranges.
pub fn check_tiling<'a>(case: &str, samples: u64, shards: &[&'a ShardOnDisk]) -> Result<Vec<&'a ShardOnDisk>, ShardError> {
    let mut sorted: Vec<&ShardOnDisk> = shards.iter().copied().filter(|s| s.file.end > s.file.first).collect();
    sorted.sort_by_key(|s| (s.file.first, s.file.end));
    let mut at = 0u64;
    let mut last: Option<&ShardOnDisk> = None;
    let missing = |from: u64, to: u64| ShardError::Missing { case: case.to_string(), from, to };
    for s in &sorted {
        if s.file.first > at {
            return Err(missing(at, s.file.first));
        }
        if s.file.first < at {
            let prev = last.expect("a shard before");
            return Err(ShardError::Bad(format!(
                "case '{case}': shards overlap: {} covers samples {}..{} and {} covers {}..{}; pass each shard once",
                prev.path.display(),
                prev.file.first,
                prev.file.end,
                s.path.display(),
                s.file.first,
                s.file.end
            )));
        }
        at = s.file.end;
        last = Some(s);
    }
    if at < samples {
        return Err(missing(at, samples));
    }
    Ok(sorted)
}

/// Shards added up: the scene they come from and, per case, the sum of its shards' results.
#[derive(Debug, Clone)]
pub struct Merged {
    pub scene: Scene,
    /// The scene's file name when the shards were run, and the FNV-1a hash of its text.
    pub scene_name: String,
    pub scene_fnv1a64: String,
    /// The adapters and backends that drew the shards, each once, joined by ` + `.
    pub adapter: String,
    pub backend: String,
    /// What differs between the shards' origins, one line each: more than one backend, more
    /// than one adapter, each value with its number of files and one of them.
    pub mixtures: Vec<String>,
    /// Per case of the scene, in order: the added results and the number of shards.
    pub cases: Vec<(Sampled, usize)>,
}

impl Merged {
    /// The cases with their added results.
    pub fn iter(&self) -> impl Iterator<Item = (&Case, &Sampled, usize)> {
        self.scene.cases.iter().zip(&self.cases).map(|(c, (s, n))| (c, s, *n))
    }
}

/// Where the shards differ in `what` (`backend`, `adapter`): the values, each with its number of
/// files and the first of them; None where they agree.
fn mixture(what: &str, shards: &[ShardOnDisk], value: impl Fn(&ShardFile) -> &str) -> Option<String> {
    let mut by: BTreeMap<&str, (usize, &Path)> = BTreeMap::new();
    for s in shards {
        by.entry(value(&s.file)).or_insert((0, &s.path)).0 += 1;
    }
    (by.len() > 1).then(|| {
        let each: Vec<String> = by.iter().map(|(v, (n, p))| format!("'{v}' in {n} file{} (such as {})", if *n == 1 { "" } else { "s" }, p.display())).collect();
        format!("the shards come from more than one {what}: {}", each.join(", "))
    })
}

/// Adds `part` to `total` cell by cell; None where a sum would exceed 2⁶⁴ − 1.
fn checked_add(total: &mut [u64], part: &[u64]) -> Option<()> {
    for (t, p) in total.iter_mut().zip(part) {
        *t = t.checked_add(*p)?;
    }
    Some(())
}

/// Whether adding `b` to `a` keeps every count and sum within 64 bits ([`Sampled::add`] adds
/// them unchecked).
fn adds_within_64_bits(a: &Sampled, b: &Sampled) -> bool {
    let mut counts = a.counts.bins.clone();
    let mut invalid = a.counts.invalid;
    let fits = checked_add(&mut counts, &b.counts.bins).and(checked_add(&mut invalid, &b.counts.invalid));
    let weighted = match (&a.weighted, &b.weighted) {
        (Some(x), Some(y)) => {
            let (x, y) = (&x.sums, &y.sums);
            let scalars = [x.squares_bins, x.squares_all, x.overflow, x.squares_lower];
            let other = [y.squares_bins, y.squares_all, y.overflow, y.squares_lower];
            checked_add(&mut x.bins.clone(), &y.bins).and(checked_add(&mut x.invalid.clone(), &y.invalid)).and(checked_add(&mut scalars.clone(), &other))
        }
        _ => Some(()),
    };
    fits.and(weighted).is_some()
}

fn joined(values: impl Iterator<Item = String>) -> String {
    let mut v: Vec<String> = values.collect();
    v.sort();
    v.dedup();
    v.join(" + ")
}

/// Adds up shards of one scene: checks that they all carry the same scene, that each belongs
/// to a case of it (name, seed, samples, bins), that each case's ranges tile it exactly, and
/// that a weighted case's shards carry weighted sums.
pub fn merge(shards: &[ShardOnDisk]) -> Result<Merged, ShardError> {
    let first = shards.first().ok_or_else(|| ShardError::Bad("no shard files to merge".into()))?;
    if let Some(other) = shards.iter().find(|s| s.file.scene != first.file.scene) {
        return Err(ShardError::Bad(format!(
            "shards come from different scenes: {} ({}, {}) and {} ({}, {}); merge the shards of one scene at a time",
            first.path.display(),
            first.file.scene_name,
            fnv1a64(&first.file.scene),
            other.path.display(),
            other.file.scene_name,
            fnv1a64(&other.file.scene)
        )));
    }
    let scene = Scene::parse(&first.file.scene_name, &first.file.scene)
        .map_err(|e| ShardError::Bad(format!("{}: the scene stored in the shard does not parse: {e}", first.path.display())))?;
    if let Some(user) = scene.user_cases.first() {
        // `lobes run --shard` refuses such scenes, so no shard of one is ever written
        return Err(ShardError::Bad(format!("{}: case '{}' is a WGSL sampler, which is never sharded; run it with `lobes run`", first.path.display(), user.name)));
    }
    let mut by_case: BTreeMap<&str, Vec<&ShardOnDisk>> = BTreeMap::new();
    for s in shards {
        let f = &s.file;
        let Some(case) = scene.cases.iter().find(|c| c.name == f.case) else {
            return Err(ShardError::Bad(format!("{}: case '{}' is not in the scene", s.path.display(), f.case)));
        };
        if f.seed != case.seed || f.samples != case.samples || f.counts.len() != case.job.bins() {
            return Err(ShardError::Bad(format!(
                "{}: case '{}' has seed {}, {} samples and {} bins, but the scene says seed {}, {} samples, {} bins",
                s.path.display(),
                f.case,
                f.seed,
                f.samples,
                f.counts.len(),
                case.seed,
                case.samples,
                case.job.bins()
            )));
        }
        if case.effects.is_some() && f.weighted.is_none() {
            return Err(ShardError::Bad(format!(
                "{}: case '{}' is weighted in the scene but this shard has no weighted sums; run the shard again with this lobes",
                s.path.display(),
                case.name
            )));
        }
        by_case.entry(f.case.as_str()).or_default().push(s);
    }
    let mut cases = Vec::new();
    for case in &scene.cases {
        let list = by_case.get(case.name.as_str()).cloned().unwrap_or_default();
        let parts = check_tiling(&case.name, case.samples, &list)?;
        // scenes have ≥ 1 sample per case, so the tiling has a first shard
        let (head, rest) = parts.split_first().expect("a tiling of 0 .. samples ≥ 1");
        let mut sum = head.file.sampled();
        for p in rest {
            let part = p.file.sampled();
            if !adds_within_64_bits(&sum, &part) {
                return Err(ShardError::Bad(format!(
                    "case '{}': adding {} makes a count or sum exceed 2^64 − 1 (a damaged or edited file); run its shard again",
                    case.name,
                    p.path.display()
                )));
            }
            sum.add(&part);
        }
        cases.push((sum, parts.len()));
    }
    Ok(Merged {
        scene_name: first.file.scene_name.clone(),
        scene_fnv1a64: fnv1a64(&first.file.scene),
        adapter: joined(shards.iter().map(|s| s.file.adapter.clone())),
        backend: joined(shards.iter().map(|s| s.file.backend.clone())),
        mixtures: [mixture("backend", shards, |f| &f.backend), mixture("adapter", shards, |f| &f.adapter)].into_iter().flatten().collect(),
        scene,
        cases,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::shard::tests::example;

    fn fake(first: u64, end: u64) -> ShardOnDisk {
        ShardOnDisk { path: PathBuf::from(format!("s{first}.json")), file: example(first, end) }
    }

    /// Issue 24 item 14: a shard whose backend differs names the backends and files, not "more
    /// than one adapter" and one adapter.
    #[test]
    fn a_mixture_names_what_differs_and_where() {
        let a = fake(0, 5);
        let mut b = fake(5, 10);
        b.path = PathBuf::from("p/b.json");
        assert_eq!(mixture("backend", &[a.clone(), b.clone()], |f| &f.backend), None);
        b.file.backend = "cpu".into();
        b.file.adapter = "cpu (f64 reference, 2 threads)".into();
        let m = mixture("backend", &[a.clone(), b.clone()], |f| &f.backend).unwrap();
        assert_eq!(m, "the shards come from more than one backend: 'cpu' in 1 file (such as p/b.json), 'gpu' in 1 file (such as s0.json)");
        assert!(mixture("adapter", &[a, b], |f| &f.adapter).unwrap().contains("'a' in 1 file"));
    }

    #[test]
    fn sums_beyond_64_bits_are_found() {
        let (a, b) = (fake(0, 5).file.sampled(), fake(5, 10).file.sampled());
        assert!(adds_within_64_bits(&a, &b));
        let mut big = b.clone();
        big.counts.bins[0] = u64::MAX;
        assert!(!adds_within_64_bits(&a, &big));
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
        let empty = fake(3, 3);
        assert_eq!(check_tiling("c", 10, &[&a, &empty, &b, &c]).unwrap().len(), 3);
    }
}
