//! What a histogram run samples, and what it returns. Shared by the GPU engine ([`crate::engine::gpu`])
//! and the CPU reference engine ([`crate::engine::cpu`]).

/// The largest sample count a case or a check may ask for (2^40; counts are exact far beyond it).
pub const MAX_SAMPLES: u64 = 1 << 40;

use crate::reference::discrete::{AliasTable, Distribution};
use crate::reference::dielectric::{Event, RoughDielectric};
use crate::reference::{Invalid, Lobe};
use crate::stats::histogram::SphereGrid;
use glam::DVec3;
use std::ops::Range;

/// Samples `first .. first + count` of the run keyed by `seed`. Sample `i` draws the uniforms
/// of the counter `(seed, i)` ([`crate::reference::rng::uniforms`]) wherever it is drawn, so a
/// run cut into ranges (chunks, tiles, shards) counts exactly what the whole run counts.
///
/// ```
/// use lobes::engine::job::SampleRange;
/// let (head, tail) = SampleRange::whole(7, 10).split_at(4);
/// assert_eq!(tail, SampleRange { seed: 7, first: 4, count: 6 });
/// assert_eq!(head.indices().chain(tail.indices()).collect::<Vec<_>>(), (0..10).collect::<Vec<_>>());
/// assert_eq!(tail.chunks(4).map(|c| c.count).collect::<Vec<_>>(), [4, 2]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleRange {
    pub seed: u64,
    pub first: u64,
    pub count: u64,
}

impl SampleRange {
    /// Samples `0 .. count` of the run keyed by `seed`.
    pub fn whole(seed: u64, count: u64) -> Self {
        Self { seed, first: 0, count }
    }

    /// The sample indices.
    pub fn indices(&self) -> Range<u64> {
        self.first..self.first + self.count
    }

    /// The first `n` samples (at most `count`) and the rest.
    pub fn split_at(self, n: u64) -> (Self, Self) {
        let n = n.min(self.count);
        (Self { count: n, ..self }, Self { first: self.first + n, count: self.count - n, ..self })
    }

    /// Chunk `index` of the range cut into chunks of `len` samples (the last may be shorter).
    pub fn chunk(&self, index: u64, len: u64) -> Self {
        let start = (index * len).min(self.count);
        Self { first: self.first + start, count: len.min(self.count - start), ..*self }
    }

    /// The number of chunks of `len` samples: none for an empty range.
    pub fn chunk_count(&self, len: u64) -> u64 {
        self.count.div_ceil(len)
    }

    /// The range cut into chunks of `len` samples, in order.
    pub fn chunks(self, len: u64) -> impl Iterator<Item = Self> {
        (0..self.chunk_count(len)).map(move |i| self.chunk(i, len))
    }
}

/// How a discrete distribution is sampled (with the distributions, so that `lobes::embed`
/// needs no engine).
pub use crate::reference::discrete::DiscreteMethod;

/// What a lobe job's surface does with light.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Scatter {
    /// Reflects it: the lobe's BRDF.
    #[default]
    Reflect,
    /// Reflects and refracts it as a rough dielectric whose lower medium has relative index
    /// `eta` ([`RoughDielectric`]).
    Dielectric { eta: f64 },
}

impl Scatter {
    /// The dielectric's η, 0 for a reflection (the kernels' `lobe_eta()`).
    pub fn eta(self) -> f64 {
        match self {
            Scatter::Reflect => 0.0,
            Scatter::Dielectric { eta } => eta,
        }
    }
}

/// A sampling job: a lobe seen from one incident direction, or a discrete distribution.
#[derive(Debug, Clone)]
pub enum Job {
    Lobe { lobe: Lobe, incident: DVec3, grid: SphereGrid, scatter: Scatter },
    Discrete { dist: Distribution, method: DiscreteMethod },
}

impl Job {
    /// The number of bins: rows · cols, or the number of items.
    pub fn bins(&self) -> usize {
        match self {
            Job::Lobe { grid, .. } => grid.bins(),
            Job::Discrete { dist, .. } => dist.len(),
        }
    }

    /// Draws sample `index` of the run keyed by `seed` in f64 and returns its cell: a bin, or
    /// `bins + reason code − 1` for an invalid sample (the layout of the GPU counters).
    pub fn cell_f64(&self, seed: u64, index: u64, alias: Option<&AliasTable>) -> usize {
        let u = crate::reference::rng::uniforms(seed, index);
        match self {
            Job::Lobe { lobe, incident, grid, scatter: Scatter::Reflect } => {
                let s = lobe.sample(*incident, [u[0], u[1]]);
                match s.invalid {
                    None => grid.bin_of(s.omega_r),
                    Some(r) => self.bins() + r.code() as usize - 1,
                }
            }
            Job::Lobe { lobe, incident, grid, scatter: Scatter::Dielectric { eta } } => {
                let s = RoughDielectric::new(*lobe, *eta).expect("a dielectric job is checked when made").sample(*incident, [u[0], u[1], u[2]]);
                match Invalid::check_scattered(*incident, s.omega_o, s.pdf_o, s.event == Event::Reflection) {
                    None => grid.bin_of(s.omega_o),
                    Some(r) => self.bins() + r.code() as usize - 1,
                }
            }
            Job::Discrete { dist, method: DiscreteMethod::Cdf } => dist.sample_cdf_gpu_layout(u[0], u[1]).index,
            Job::Discrete { method: DiscreteMethod::Alias, .. } => {
                alias.expect("alias table built by the caller").sample(u[0], u[1]).index
            }
        }
    }
}

/// The raw result of a run: exact 64-bit counts per bin and per invalid reason.
#[derive(Debug, Clone, PartialEq)]
pub struct Counts {
    pub bins: Vec<u64>,
    /// Indexed like [`Invalid::ALL`].
    pub invalid: [u64; Invalid::COUNT],
}

impl Counts {
    pub fn zeros(bins: usize) -> Self {
        Self { bins: vec![0; bins], invalid: [0; Invalid::COUNT] }
    }
    /// Splits a cell vector (bins followed by the reasons) as laid out by the kernels.
    pub fn from_cells(cells: &[u64]) -> Self {
        let n = cells.len() - Invalid::COUNT;
        Self { bins: cells[..n].to_vec(), invalid: cells[n..].try_into().expect("one cell per reason") }
    }
    pub fn total(&self) -> u64 {
        self.bins.iter().sum::<u64>() + self.invalid.iter().sum::<u64>()
    }
    pub fn invalid_count(&self, reason: Invalid) -> u64 {
        self.invalid[reason.code() as usize - 1]
    }
    /// Adds another run's counts (shards of one run add exactly).
    pub fn add(&mut self, other: &Counts) {
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            *a += b;
        }
        for (a, b) in self.invalid.iter_mut().zip(&other.invalid) {
            *a += b;
        }
    }
}
