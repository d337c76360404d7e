//! The pdf against the Jacobian of the sample map, sample by sample.
//!
//! A sampler maps u ∈ [0, 1]² to a point d; where the map is smooth and one-to-one its density is
//! p(d) = 1 / |J(u)|, with |J| = |∂d/∂u₁ × ∂d/∂u₂| on the sphere (the area of the image of a unit
//! square of u, per unit solid angle) and |det ∂(x, y)/∂(u₁, u₂)| on the plane (pbrt-v4 §2.4.1,
//! "transforming between distributions"). The derivatives are central differences of the GPU's
//! map with step ε; a sample is skipped where the map is not smooth at that scale (the second
//! difference exceeds a tenth of the first: a fold, a seam or a branch between lobes), and where
//! moving u.z or u.w changes d (the sampler chooses between lobes or events with them, so its
//! density is a mixture that one 2-D map does not give). This catches a missing Jacobian factor
//! (the reflection's 1/(4|ωr·h|), a cos θ) even where a coarse histogram cannot.

use serde::{Deserialize, Serialize};

/// Finite-difference step in u (2⁻¹²: its central-difference truncation error, ε²/6 of the
/// third derivative, and the f32 rounding of d over 2ε, about 10⁻⁴, both stay well under the
/// tolerance for maps of moderate curvature).
pub const EPS: f32 = 1.0 / 4096.0;
/// A sample is off when |p · |J| − 1| exceeds this.
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
    /// Samples whose map depends on u.z or u.w (lobe selection).
    pub skipped_selection: u64,
    /// Samples where the map is not smooth at the step's scale.
    pub skipped_not_smooth: u64,
    /// Samples with an invalid point or pdf at or around them.
    pub skipped_invalid: u64,
    /// Compared samples with |p · |J| − 1| > TOLERANCE.
    pub off: u64,
    pub share_off: f64,
    /// Median and worst p · |J| over the compared samples (1 for a correct pdf; no median
    /// without compared samples).
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

/// |J| of the map at a probed sample, or why it cannot be compared.
enum Local {
    Jacobian(f64),
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
    if norm(sub(v3(probe[5]), d0)) > 1e-6 * norm(d0).max(1.0) {
        return Local::Selection;
    }
    let h = 2.0 * EPS as f64;
    let (dx, dy) = (sub(d[0], d[1]), sub(d[2], d[3]));
    let second = |p: [f64; 3], m: [f64; 3]| norm([p[0] - 2.0 * d0[0] + m[0], p[1] - 2.0 * d0[1] + m[1], p[2] - 2.0 * d0[2] + m[2]]);
    if second(d[0], d[1]) > 0.1 * norm(dx) || second(d[2], d[3]) > 0.1 * norm(dy) || norm(dx) == 0.0 || norm(dy) == 0.0 {
        return Local::NotSmooth;
    }
    let area = if plane { (dx[0] * dy[1] - dx[1] * dy[0]).abs() } else { norm(cross(dx, dy)) };
    Local::Jacobian(area / (h * h))
}

/// Compares the pdf function at each probed sample with 1 / |J|; `u` are the probed uniforms.
pub fn judge(probes: &[[[f32; 4]; 7]], u: &[[f32; 4]], plane: bool) -> JacobianCheck {
    let mut c = JacobianCheck {
        probed: probes.len() as u64,
        compared: 0,
        skipped_selection: 0,
        skipped_not_smooth: 0,
        skipped_invalid: 0,
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
            Local::Jacobian(j) => {
                let ratio = p[6][0] as f64 * j;
                ratios.push(ratio);
                if (ratio - 1.0).abs() > TOLERANCE {
                    c.off += 1;
                }
                if (ratio - 1.0).abs() > (c.worst_ratio - 1.0).abs() {
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

    /// The uniform map onto the plane's unit square has |J| = 1: a pdf of 1 matches, 2 does not.
    #[test]
    fn identity_map_on_the_plane() {
        let e = EPS;
        let probe = |pdf: f32| {
            let (x, y) = (0.3f32, 0.6f32);
            [[x, y, 0.0, pdf], [x + e, y, 0.0, pdf], [x - e, y, 0.0, pdf], [x, y + e, 0.0, pdf], [x, y - e, 0.0, pdf], [x, y, 0.0, pdf], [pdf, 0.0, 0.0, 0.0]]
        };
        let u = vec![[0.3, 0.6, 0.0, 0.0]; MIN_COMPARED as usize];
        let good = judge(&vec![probe(1.0); MIN_COMPARED as usize], &u, true);
        assert!(good.applicable && good.passed && (good.median_ratio.unwrap() - 1.0).abs() < 1e-3, "{good:?}");
        let bad = judge(&vec![probe(2.0); MIN_COMPARED as usize], &u, true);
        assert!(bad.applicable && !bad.passed && (bad.worst_ratio - 2.0).abs() < 1e-3, "{bad:?}");
    }
}
