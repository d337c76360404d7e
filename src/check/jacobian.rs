//! The pdf against the Jacobian of the sample map, sample by sample.
//!
//! A sampler maps u ∈ [0, 1]² to a point d; where the map is smooth and one-to-one its density is
//! p(d) = 1 / |J(u)|, with |J| = |∂d/∂u₁ × ∂d/∂u₂| on the sphere (the area of the image of a unit
//! square of u, per unit solid angle) and |det ∂(x, y)/∂(u₁, u₂)| on the plane (pbrt-v4 §2.4.1,
//! "transforming between distributions"). The derivatives are central differences of the GPU's
//! map with step ε; a sample is skipped where the map is not smooth at that scale (the second
//! difference exceeds a tenth of the first: a fold, a seam or a branch between lobes).
//! This catches a missing Jacobian factor (the reflection's 1/(4|ωr·h|), a cos θ) even where a
//! coarse histogram cannot.
//!
//! **Events.** A sampler that chooses an event with u.z (a rough dielectric reflects with
//! probability F(ωi·h), else refracts; a mixture picks a lobe) has at d the density s/|J|, where
//! s(u₁, u₂) is the share of u.z ∈ [0, 1) that makes the same choice (the 3-D map's density
//! integrated over u.z) and J is the chosen event's map. The probe pass measures s on the GPU
//! (`lobes_share` in `shaders/check/user_passes.wgsl`): the share of u.z, at u.x, u.y, u.w fixed,
//! whose sample lands on the same d within 10⁻⁶, by a scan of 256 nodes with each change bisected
//! to f32 resolution; likewise for u.w. s depends on u₁, u₂ only through the event's probability
//! (F(ωi·h)), so it is well defined wherever the map is smooth (where u ± ε crosses into another
//! event d jumps: not smooth). Its error, about 2⁻²³, stays under 10⁻³ of s because a run of u.z
//! landing on d shorter than 2⁻¹² (the step ε) is read as "d moves with u.z"; a share near 1 is
//! 1 minus a small one, bisected where it is small. Only an event narrower than 2⁻⁸ lying wholly
//! between two nodes escapes the scan. Where d moves with u.z or u.w (continuously, not by
//! events), or both choose, the probe is skipped. Another event may land on the same d (a
//! mixture's lobes overlap) and add its density there, which the map around u does not see: where
//! s < 1 the ratio p · |J| / s may exceed 1 by that much, and only a ratio below 1 is off. With
//! ∫p equal to the valid fraction (`normalization`), p ≥ each event's density leaves no room for a
//! p too large where the events do not overlap.

use serde::{Deserialize, Serialize};

/// Finite-difference step in u (2⁻¹²: its central-difference truncation error, ε²/6 of the
/// third derivative, and the f32 rounding of d over 2ε, about 10⁻⁴, both stay well under the
/// tolerance for maps of moderate curvature).
pub const EPS: f32 = 1.0 / 4096.0;
/// A sample is off when |p · |J| / share − 1| exceeds this (for an event: 1 − p · |J| / share).
pub const TOLERANCE: f64 = 1e-2;
/// The check fails when more than this share of the compared samples is off.
pub const MAX_SHARE_OFF: f64 = 1e-2;
/// Fewer compared samples than this and the check does not apply.
pub const MIN_COMPARED: u64 = 100;

/// What the comparison found.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, schemars::JsonSchema)]
pub struct JacobianCheck {
    pub probed: u64,
    pub compared: u64,
    /// Samples where d moves continuously with u.z or u.w, or where both choose an event.
    pub skipped_selection: u64,
    /// Samples where the map is not smooth at the step's scale.
    pub skipped_not_smooth: u64,
    /// Samples with an invalid point or pdf at or around them.
    pub skipped_invalid: u64,
    /// Compared samples where the sampler chose an event with u.z or u.w (share < 1), judged by
    /// p · |J| / share.
    pub compared_events: u64,
    /// Those of them above 1 + TOLERANCE: not off (another event may land on the same d).
    pub above_events: u64,
    /// Compared samples with |p · |J| / share − 1| > TOLERANCE (for an event: below 1 − TOLERANCE).
    pub off: u64,
    pub share_off: f64,
    /// Median and worst p · |J| / share over the compared samples (1 for a correct pdf; no median
    /// without compared samples; an event's ratio above 1 is not the worst).
    pub median_ratio: Option<f64>,
    pub worst_ratio: f64,
    /// The u of the worst sample.
    pub worst_u: [f32; 4],
    pub tolerance: f64,
    /// Whether enough samples could be compared for a verdict.
    pub applicable: bool,
    pub passed: bool,
}

fn v3(v: [f32; 4]) -> [f64; 3] {
    [v[0] as f64, v[1] as f64, v[2] as f64]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// |J| of the map at a probed sample with the share of its event, or why it cannot be compared.
enum Local {
    Jacobian { j: f64, share: f64 },
    Selection,
    NotSmooth,
    Invalid,
}

fn local(probe: &[[f32; 4]; 7], plane: bool) -> Local {
    let finite = probe[..6].iter().all(|v| v.iter().all(|x| x.is_finite()));
    if !finite || probe[0][3] <= 0.0 || !(probe[6][0] > 0.0 && probe[6][0].is_finite()) {
        return Local::Invalid;
    }
    let d0 = v3(probe[0]);
    let mut d = [v3(probe[1]), v3(probe[2]), v3(probe[3]), v3(probe[4])];
    if plane {
        for p in &mut d {
            p[2] = 0.0;
        }
    }
    // shares of u.z and u.w: 1 unused, < 0 d moves with it (user_passes.wgsl: lobes_share)
    let (sz, sw) = (probe[5][0] as f64, probe[5][1] as f64);
    if sz < 0.0 || sw < 0.0 || (sz < 1.0 && sw < 1.0) {
        return Local::Selection;
    }
    let h = 2.0 * EPS as f64;
    let (dx, dy) = (sub(d[0], d[1]), sub(d[2], d[3]));
    let second = |p: [f64; 3], m: [f64; 3]| norm([p[0] - 2.0 * d0[0] + m[0], p[1] - 2.0 * d0[1] + m[1], p[2] - 2.0 * d0[2] + m[2]]);
    if second(d[0], d[1]) > 0.1 * norm(dx) || second(d[2], d[3]) > 0.1 * norm(dy) || norm(dx) == 0.0 || norm(dy) == 0.0 {
        return Local::NotSmooth;
    }
    let area = if plane { (dx[0] * dy[1] - dx[1] * dy[0]).abs() } else { norm(cross(dx, dy)) };
    Local::Jacobian { j: area / (h * h), share: sz.min(sw) }
}

/// Compares the pdf function at each probed sample with 1 / |J|; `u` are the probed uniforms.
pub fn judge(probes: &[[[f32; 4]; 7]], u: &[[f32; 4]], plane: bool) -> JacobianCheck {
    let mut c = JacobianCheck {
        probed: probes.len() as u64,
        compared: 0,
        skipped_selection: 0,
        skipped_not_smooth: 0,
        skipped_invalid: 0,
        compared_events: 0,
        above_events: 0,
        off: 0,
        share_off: 0.0,
        median_ratio: None,
        worst_ratio: 1.0,
        worst_u: [0.0; 4],
        tolerance: TOLERANCE,
        applicable: false,
        passed: true,
    };
    let mut ratios = Vec::new();
    for (p, u) in probes.iter().zip(u) {
        match local(p, plane) {
            Local::Invalid => c.skipped_invalid += 1,
            Local::Selection => c.skipped_selection += 1,
            Local::NotSmooth => c.skipped_not_smooth += 1,
            Local::Jacobian { j, share } => {
                let ratio = p[6][0] as f64 * j / share;
                ratios.push(ratio);
                let event = share < 1.0;
                let deviation = if event { (1.0 - ratio).max(0.0) } else { (ratio - 1.0).abs() };
                c.compared_events += event as u64;
                c.above_events += (event && ratio > 1.0 + TOLERANCE) as u64;
                if deviation > TOLERANCE {
                    c.off += 1;
                }
                if deviation > (c.worst_ratio - 1.0).abs() {
                    c.worst_ratio = ratio;
                    c.worst_u = *u;
                }
            }
        }
    }
    c.compared = ratios.len() as u64;
    if !ratios.is_empty() {
        ratios.sort_by(f64::total_cmp);
        c.median_ratio = Some(ratios[ratios.len() / 2]);
        c.share_off = c.off as f64 / c.compared as f64;
    }
    c.applicable = c.compared >= MIN_COMPARED;
    c.passed = !c.applicable || c.share_off <= MAX_SHARE_OFF;
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The probe of the uniform map onto the plane's unit square (|J| = 1) at (0.3, 0.6), with a
    /// pdf and the shares of u.z and u.w.
    fn probe(pdf: f32, shares: [f32; 2]) -> [[f32; 4]; 7] {
        let (e, x, y) = (EPS, 0.3f32, 0.6f32);
        [[x, y, 0.0, pdf], [x + e, y, 0.0, pdf], [x - e, y, 0.0, pdf], [x, y + e, 0.0, pdf], [x, y - e, 0.0, pdf], [shares[0], shares[1], 0.0, 0.0], [pdf, 0.0, 0.0, 0.0]]
    }

    fn judged(pdf: f32, shares: [f32; 2]) -> JacobianCheck {
        let n = MIN_COMPARED as usize;
        judge(&vec![probe(pdf, shares); n], &vec![[0.3, 0.6, 0.0, 0.0]; n], true)
    }

    /// |J| = 1: a pdf of 1 matches, 2 does not.
    #[test]
    fn identity_map_on_the_plane() {
        let good = judged(1.0, [1.0, 1.0]);
        assert!(good.applicable && good.passed && (good.median_ratio.unwrap() - 1.0).abs() < 1e-3, "{good:?}");
        assert_eq!(good.compared_events, 0);
        let bad = judged(2.0, [1.0, 1.0]);
        assert!(bad.applicable && !bad.passed && (bad.worst_ratio - 2.0).abs() < 1e-3, "{bad:?}");
    }

    /// An event of probability ¼ chosen with u.z (or u.w) has density ¼ / |J|: pdf ¼ matches, ⅛
    /// is off by ½; ½ (another event landing there too) is above, not off.
    #[test]
    fn an_event_is_judged_by_its_share() {
        for shares in [[0.25, 1.0], [1.0, 0.25]] {
            let good = judged(0.25, shares);
            assert!(good.passed && good.compared_events == MIN_COMPARED && (good.median_ratio.unwrap() - 1.0).abs() < 1e-6, "{good:?}");
            let low = judged(0.125, shares);
            assert!(!low.passed && (low.worst_ratio - 0.5).abs() < 1e-6, "{low:?}");
            let high = judged(0.5, shares);
            assert!(high.passed && high.off == 0 && high.above_events == MIN_COMPARED && high.worst_ratio == 1.0, "{high:?}");
        }
    }

    /// d moving continuously with u.z or u.w (share −1), or events chosen by both: skipped.
    #[test]
    fn continuous_or_double_choices_are_skipped() {
        for shares in [[-1.0, 1.0], [1.0, -1.0], [0.5, 0.5]] {
            let c = judged(1.0, shares);
            assert!(c.compared == 0 && c.skipped_selection == MIN_COMPARED && !c.applicable && c.passed, "{c:?}");
        }
    }
}
