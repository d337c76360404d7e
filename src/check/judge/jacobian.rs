//! `jacobian`: the pdf against the finite-difference Jacobian of the map u ↦ d at the probes
//! ([`crate::check::jacobian`] holds the differentiation and the tests; this, their message).

use super::{Measured, Run};
use crate::check::hard;
use crate::check::jacobian::{self as map, JacobianCheck};
use crate::check::report::{Check, Figures};
use crate::check::CONDITIONING_ULPS;

pub(crate) fn check(run: &Run, m: &Measured) -> Check {
    let jac = map::judge(&m.probes, &m.probe_u, &m.at, &m.kappa, CONDITIONING_ULPS, run.sampler.domain, m.jump);
    let summary = if jac.applicable { applicable(&jac, &not_unit(run, m, &jac)) } else { not_applicable(&jac) };
    Check { passed: jac.passed, summary, figures: Figures::Jacobian(jac) }
}

/// The length of d at the worst probe: a map onto non-unit vectors has the wrong |J| on the
/// sphere, and the cause is then the length, not the density.
fn not_unit(run: &Run, m: &Measured, jac: &JacobianCheck) -> String {
    let worst_length = m.probes.iter().zip(&m.probe_u).find(|(_, u)| **u == jac.worst_u).map(|(p, _)| p.length);
    match worst_length {
        Some(l) if run.sampler.domain.directions() && !jac.passed && !hard::is_unit(l) => format!("; |d| = {} at the worst sample, not a unit vector", hard::show(l)),
        _ => String::new(),
    }
}

fn applicable(jac: &JacobianCheck, not_unit: &str) -> String {
    let events = match jac.compared_events {
        0 => String::new(),
        k => format!("; {k} of them chose an event with u.z or u.w, judged by pdf · |J| / share ({} above 1)", jac.above_events),
    };
    format!(
        "pdf · |J| has median {:.4} and worst {:.4} (allowed ±{:.1}% there); {:.2}% of {} samples off by more than {:.0}% + the f32 resolution of |J| and of the pdf (limit {:.0}%){events}{}{}{not_unit}",
        jac.median_ratio.unwrap_or(f64::NAN),
        jac.worst_ratio,
        100.0 * jac.worst_limit,
        100.0 * jac.share_off,
        jac.compared,
        100.0 * jac.tolerance,
        100.0 * map::MAX_SHARE_OFF,
        systematic(jac),
        unresolved(jac),
    ) + &jump(jac)
}

/// A jump of the map ([`map::Jump`]): why every probe was judged as an event's.
fn jump(jac: &JacobianCheck) -> String {
    match jac.jump {
        Some(j) => format!(
            "; the map u ↦ d jumps along u.{} (at {:.4}, on {} of {} lines scanned): a choice made with that uniform and reused, so several u land on one d and pdf · |J| ≥ 1 there, judged as an event's (off only below 1)",
            ["x", "y"][j.axis as usize],
            j.at,
            j.lines,
            j.scanned
        ),
        None => String::new(),
    }
}

fn systematic(jac: &JacobianCheck) -> String {
    match jac.median_deviation {
        Some(m) if jac.resolved >= map::MIN_COMPARED => format!(
            "; systematically: {} of {} samples resolved to {:.1}% off by more than {:.1}% + their f32 resolution (at most {:.0} may be: half, plus chance), median |pdf · |J| − 1| {:.1e}",
            jac.systematic_off,
            jac.resolved,
            100.0 * map::RESOLVED,
            100.0 * jac.systematic_tolerance,
            jac.systematic_limit.floor(),
            m
        ),
        _ => format!("; systematic test not applicable: {} samples resolved to {:.1}%", jac.resolved, 100.0 * map::RESOLVED),
    }
}

fn unresolved(jac: &JacobianCheck) -> String {
    match jac.skipped_unresolved {
        0 => String::new(),
        k => format!(
            "; {k} samples skipped where no three steps agree on |J| to {:.0}% (d moves by only a few f32 ulps there: an f32 staircase, e.g. sin θ = √(1 − cos²θ) near a pole)",
            100.0 * map::UNRESOLVED
        ),
    }
}

fn not_applicable(jac: &JacobianCheck) -> String {
    format!(
        "not applicable: only {} of {} samples comparable ({} move with u.z or u.w, {} not smooth, {} unresolved in f32, {} invalid)",
        jac.compared, jac.probed, jac.skipped_selection, jac.skipped_not_smooth, jac.skipped_unresolved, jac.skipped_invalid
    )
}
