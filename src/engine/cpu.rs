//! The CPU engine: the same samples as the GPU (same counter-based uniforms), drawn in f64 by
//! the reference samplers on all cores. It serves where no GPU adapter exists, and as the CPU
//! backend of the benchmark.

use crate::engine::job::{Counts, DiscreteMethod, Job, SampleRange, Scatter};
use crate::reference::effects::Effects;
use crate::stats::weighted::WeightedSums;
use crate::reference::Invalid;
use crate::reference::dielectric::{Event, RoughDielectric};
use crate::reference::discrete::AliasTable;
use rayon::prelude::*;

/// Samples per task of the thread pool.
const BLOCK: u64 = 1 << 16;

/// Histograms the samples of `range`.
///
/// ```
/// use lobes::{engine::job::{Job, SampleRange, Scatter}, reference::{Lobe, LobeKind, Method}, stats::histogram::SphereGrid};
/// let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Ndf, alpha_x: 0.5, alpha_y: 0.5, alpha_angle: 0.0 };
/// let job = Job::Lobe { lobe, incident: glam::DVec3::Z, grid: SphereGrid { rows: 8, cols: 16 }, scatter: Scatter::Reflect };
/// let counts = lobes::engine::cpu::histogram(&job, SampleRange::whole(1, 10_000));
/// assert_eq!(counts.total(), 10_000);
/// ```
pub fn histogram(job: &Job, range: SampleRange) -> Counts {
    let alias = match job {
        Job::Discrete { dist, method: DiscreteMethod::Alias } => Some(AliasTable::new(dist)),
        _ => None,
    };
    let bins = job.bins();
    let cells = (0..range.chunk_count(BLOCK))
        .into_par_iter()
        .fold(
            || vec![0u64; bins + Invalid::COUNT],
            |mut cells, b| {
                for i in range.chunk(b, BLOCK).indices() {
                    cells[job.cell_f64(range.seed, i, alias.as_ref())] += 1;
                }
                cells
            },
        )
        .reduce(|| vec![0u64; bins + Invalid::COUNT], |mut a, b| {
            a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
            a
        });
    Counts::from_cells(&cells)
}

/// The weighted histogram of the samples of `range` of a lobe job with `effects`,
/// in f64: the same fixed-point sums as `shaders/passes/weighted.wgsl`, and per bin the largest
/// relative difference between the weight and eval · |cos θo| / pdf. A rough dielectric's
/// samples ([`RoughDielectric`]) land on both sides, its Fresnel term its own.
pub fn weighted(job: &Job, effects: &Effects, range: SampleRange) -> WeightedSums {
    let Job::Lobe { lobe, incident, grid, scatter } = job else { panic!("weighted histograms are for lobe jobs") };
    let wi = *incident;
    let glass = match *scatter {
        Scatter::Reflect => None,
        Scatter::Dielectric { eta } => Some(RoughDielectric::new(*lobe, eta).expect("a dielectric job is checked when made")),
    };
    // one sample: its direction, its reason if invalid, its weight, and eval · |cos θo| / pdf
    let draw = |u: [f64; 4]| match &glass {
        None => {
            let s = lobe.sample(wi, [u[0], u[1]]);
            let check = || effects.eval(lobe, wi, s.omega_r) * s.omega_r.z / lobe.pdf_r(wi, s.omega_r);
            (s.omega_r, s.invalid, effects.weight(lobe, wi, &s), s.invalid.is_none().then(check))
        }
        Some(glass) => {
            let s = glass.sample(wi, [u[0], u[1], u[2]]);
            let invalid = Invalid::check_scattered(wi, s.omega_o, s.pdf_o, s.event == Event::Reflection);
            let check = || glass.eval(wi, s.omega_o, effects.masking) * s.omega_o.z.abs() / glass.pdf(wi, s.omega_o);
            (s.omega_o, invalid, glass.weight(wi, &s, effects.masking), invalid.is_none().then(check))
        }
    };
    let bins = job.bins();
    (0..range.chunk_count(BLOCK))
        .into_par_iter()
        .fold(
            || WeightedSums::zeros(bins),
            |mut sums, b| {
                for i in range.chunk(b, BLOCK).indices() {
                    let (wo, invalid, w, check) = draw(crate::reference::rng::uniforms(range.seed, i));
                    match (invalid, check) {
                        (Some(r), _) => sums.record(bins + r.code() as usize - 1, w),
                        (None, check) => {
                            let check = check.expect("a valid sample has its check");
                            let bin = grid.bin_of(wo);
                            sums.record(bin, w);
                            let e = if w == check { 0.0 } else { ((w - check).abs() / check) as f32 };
                            sums.max_error[bin] = sums.max_error[bin].max(if e.is_nan() { f32::INFINITY } else { e });
                        }
                    }
                }
                sums
            },
        )
        .reduce(|| WeightedSums::zeros(bins), |mut a, b| {
            a.add(&b);
            a
        })
}
