//! The grid fitted to a small support: a sampler whose directions all fall in a small cap (a
//! light seen from afar, a lobe of α 10⁻³) is binned on a [`Domain::Cap`] about them, so that
//! a light of 10⁻⁶ sr gets as many cells as one of a steradian, instead of the one or two cells of
//! the sphere's grid that it covers (χ² on 1 dof: no power) and parts too coarse for the
//! quadrature to resolve its edge (no verdict).
//!
//! The cap is fitted in two steps. Its axis is the mean direction of the probed samples (the
//! same 4096 the other checks probe), its first height four times their largest 1 − cos θ′
//! about it (twice the angle) or [`FIT_HEIGHT`], whichever is less. Then every sample of the run
//! is counted, by the run's own counting pass, on [`FIT_ROWS`] rows of that cap: where none falls
//! outside it the cap ends one row past the farthest sample, which no sample of the run (the
//! same counter-based draws) can then fall outside; where some do, the next try is the cap of
//! [`FIT_HEIGHT`], and past that the sphere. The fit depends on the samples, but only through
//! their farthest one: a cap that ends at the sample farthest out of N leaves out a mass of
//! order 1/N, a fraction of one expected count, which `normalization` and the χ² see as the
//! pdf's mass outside (where the pdf function claims mass that the sampler never reaches, they
//! fail, as they should).

use super::gpu::Passes;
pub use super::settings::{FIT_HEIGHT, Fit};
use super::{CheckError, Domain, Settings, UserSampler};
use crate::check::probe::Probe;
use crate::reference::Invalid;
use glam::DVec3;

/// Rows of the fitting count: the farthest sample is placed to 1/4096 of the tried height.
pub const FIT_ROWS: u32 = 4096;

/// The axis and first height of a cap about the valid probed samples: their mean direction and
/// four times their largest 1 − cos θ′ about it (at most `limit`); `None` where fewer than 64
/// are valid, where they spread too far for their mean to be a direction (|mean| < 0.5), or
/// where they all are one direction (a delta: no cap has room for a grid).
pub fn probed_cap(probes: &[Probe], limit: f64) -> Option<([f64; 3], f64)> {
    let d: Vec<DVec3> = probes.iter().filter(|p| p.valid()).map(|p| DVec3::from(p.d().map(f64::from))).collect();
    if d.len() < 64 {
        return None;
    }
    let mean = d.iter().copied().sum::<DVec3>() / d.len() as f64;
    if mean.length() < 0.5 {
        return None;
    }
    let (axis, _) = Domain::cap(mean.into(), 1.0)?.as_cap()?;
    let frame = crate::stats::domain::Frame::of(axis);
    let farthest = d.iter().map(|&v| frame.local(v).0).fold(0.0, f64::max);
    (farthest > 0.0 && farthest <= limit).then_some((axis, (4.0 * farthest).min(limit)))
}

/// The cap one row of [`FIT_ROWS`] past the farthest of `counts` (rows of the cap of `height`
/// about `axis`, then the reasons), or `None` where a sample fell outside it.
pub fn fitted(axis: [f64; 3], height: f64, counts: &[u64]) -> Option<Domain> {
    let rows = FIT_ROWS as usize;
    let outside = counts[rows + Invalid::OutsideDomain.index()];
    let top = counts[..rows].iter().rposition(|&c| c > 0)?;
    (outside == 0).then(|| Domain::cap(axis, height * ((top + 2).min(rows) as f64) / rows as f64)).flatten()
}

/// The cap to bin `sampler`'s samples on, and the passes composed for it; `None` where the
/// settings or the sampler's domain ask for none, or the samples do not fit one. `probes` are
/// the run's probed samples (drawn by any domain's passes: probes do not bin).
pub(super) fn fit<'g>(gpu: &'g crate::engine::gpu::Gpu, sampler: &UserSampler, settings: &Settings, probes: &[Probe]) -> Result<Option<(Domain, Passes<'g>, String)>, CheckError> {
    let Some(limit) = settings.fit.limit() else { return Ok(None) };
    if !sampler.domain.is_sphere() {
        return Ok(None);
    }
    let Some((axis, first)) = probed_cap(probes, limit) else { return Ok(None) };
    let trial = UserSampler { domain: Domain::cap(axis, first).expect("a cap"), ..sampler.clone() };
    let counting = Settings { bins: Some((FIT_ROWS, 1)), ..settings.clone() };
    let params = super::gpu::params_of(&trial, &counting);
    let (passes, draws) = super::gpu::compose_passes(gpu, &trial, settings, &params)?;
    let tries = if first < limit { vec![first, limit] } else { vec![first] };
    for height in tries {
        let bounds = [axis[0] as f32, axis[1] as f32, axis[2] as f32, height as f32];
        let params = super::gpu::Params { bounds, ..params };
        let counts = super::gpu::histogram(&passes, &params, &trial, settings.samples)?;
        if let Some(cap) = fitted(axis, height, &counts) {
            return Ok(Some((cap, passes, draws)));
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn probe(d: DVec3) -> Probe {
        let mut p = Probe::zeroed();
        p.sample = [d.x as f32, d.y as f32, d.z as f32, 1.0];
        p.pdf = 1.0;
        p.length = 1.0;
        p
    }
    use bytemuck::Zeroable;

    #[test]
    fn a_cone_of_probes_gives_a_cap_about_its_axis_twice_its_angle() {
        // 400 directions on the rim and inside of a cone of 10⁻³ rad about (0, 0.6, 0.8)
        let axis = DVec3::new(0.0, 0.6, 0.8);
        let frame = crate::stats::domain::Frame::of(axis.into());
        let rho: f64 = 1e-3;
        let probes: Vec<Probe> = (0..400).map(|i| probe(frame.direction(2.0 * (0.5 * rho * ((i % 20) as f64 + 1.0) / 20.0).sin().powi(2), i as f64 * 0.37))).collect();
        let (a, h) = probed_cap(&probes, FIT_HEIGHT).expect("a cap");
        assert!(DVec3::from(a).angle_between(axis) < 1e-4, "{a:?}");
        // 1 − cos(2ρ) = 4 (1 − cos ρ) to O(ρ⁴), measured about the probes' mean (off the
        // cone's axis by up to 10⁻⁴ rad here: up to 10 % of ρ farther, 21 % in 1 − cos)
        assert!((1.0..1.21).contains(&(h / (1.0 - (2.0 * rho).cos()))), "{h}");
    }

    #[test]
    fn wide_or_degenerate_probes_give_no_cap() {
        let wide: Vec<Probe> = (0..400).map(|i| probe(DVec3::new((i as f64).cos(), (i as f64).sin(), 0.3).normalize())).collect();
        assert_eq!(probed_cap(&wide, FIT_HEIGHT), None, "around a ring: the mean is short");
        let delta = vec![probe(DVec3::Z); 100];
        assert_eq!(probed_cap(&delta, FIT_HEIGHT), None, "a delta");
        let few = vec![probe(DVec3::Z); 10];
        assert_eq!(probed_cap(&few, FIT_HEIGHT), None);
    }

    #[test]
    fn the_fitted_cap_ends_a_row_past_the_farthest_sample() {
        let mut counts = vec![0u64; FIT_ROWS as usize + Invalid::COUNT];
        counts[10] = 5;
        counts[99] = 1;
        let (_, height) = fitted([0.0, 0.0, 1.0], 1.0, &counts).and_then(|d| d.as_cap()).expect("a cap");
        assert_eq!(height, (101.0f64 / FIT_ROWS as f64) as f32 as f64);
        counts[FIT_ROWS as usize + Invalid::OutsideDomain.index()] = 1;
        assert_eq!(fitted([0.0, 0.0, 1.0], 1.0, &counts), None, "a sample outside");
    }
}
