//! The CPU engine: the same samples as the GPU (same counter-based uniforms), drawn in f64 by
//! the reference samplers on all cores. It serves where no GPU adapter exists, and as the CPU
//! backend of the benchmark.

use crate::job::{Counts, DiscreteMethod, Job};
use crate::reference::discrete::AliasTable;
use rayon::prelude::*;

/// Histograms samples `first .. first + samples` of the run keyed by `seed`.
///
/// ```
/// use lobes::{job::Job, reference::{Lobe, LobeKind, Method}, stats::histogram::SphereGrid};
/// let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Ndf, alpha_x: 0.5, alpha_y: 0.5 };
/// let job = Job::Lobe { lobe, incident: glam::DVec3::Z, grid: SphereGrid { rows: 8, cols: 16 } };
/// let counts = lobes::cpu::histogram(&job, 1, 0, 10_000);
/// assert_eq!(counts.total(), 10_000);
/// ```
pub fn histogram(job: &Job, seed: u64, first: u64, samples: u64) -> Counts {
    let alias = match job {
        Job::Discrete { dist, method: DiscreteMethod::Alias } => Some(AliasTable::new(dist)),
        _ => None,
    };
    let bins = job.bins();
    const BLOCK: u64 = 1 << 16;
    let blocks = samples.div_ceil(BLOCK);
    let cells = (0..blocks)
        .into_par_iter()
        .fold(
            || vec![0u64; bins + 4],
            |mut cells, b| {
                let start = first + b * BLOCK;
                let end = (start + BLOCK).min(first + samples);
                for i in start..end {
                    cells[job.cell_f64(seed, i, alias.as_ref())] += 1;
                }
                cells
            },
        )
        .reduce(|| vec![0u64; bins + 4], |mut a, b| {
            a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
            a
        });
    Counts::from_cells(&cells)
}
