//! The user's sampler at the inputs where samplers break: every component of u at 0, 2⁻²⁴, ½,
//! 1 − 2⁻²⁴ and 1 (625 combinations), from normal, oblique, grazing and below-the-surface
//! incidence. A sample must be either rejected (reported pdf exactly 0 at a finite point) or
//! valid: a finite point (a unit direction on the sphere, inside the bounds on the plane) with a
//! finite reported pdf > 0 and a finite pdf(d) ≥ 0. NaN, ∞ or a negative pdf is never
//! acceptable, nor a NaN or infinite point, whatever pdf comes with it.

use super::probe::Probe;
use serde::{Deserialize, Serialize};

/// The values every component of u takes.
pub const U_VALUES: [f32; 5] = [0.0, 1.0 / 16_777_216.0, 0.5, 1.0 - 1.0 / 16_777_216.0, 1.0];
/// Incident θ in degrees on the sphere: normal, oblique, grazing, and from below the surface
/// (for samplers of transmission or phase functions; a reflection-only sampler rejects those).
pub const INCIDENT_THETA: [f64; 7] = [0.0, 45.0, 89.9, 89.999, 90.001, 135.0, 180.0];

/// Every u of the table with components among `values` ([`U_VALUES`], or those of
/// `Conventions::hard_u_values`), in order.
pub fn uniforms(values: &[f32]) -> Vec<[f32; 4]> {
    let v = values;
    let mut out = Vec::with_capacity(v.len().pow(4));
    for &a in v {
        for &b in v {
            for &c in v {
                for &d in v {
                    out.push([a, b, c, d]);
                }
            }
        }
    }
    out
}

/// One incident direction's row of the table.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, schemars::JsonSchema)]
pub struct HardRow {
    /// Incident θ in degrees (on the plane: the run's).
    pub incident_theta: f64,
    pub samples: u32,
    pub valid: u32,
    /// Reported pdf exactly 0.
    pub rejected: u32,
    /// Reported pdf NaN, ∞ or negative.
    pub bad_pdf: u32,
    /// The point not finite (whatever the pdf), or with pdf > 0 not a unit direction or outside
    /// the bounds.
    pub bad_point: u32,
    /// pdf(d) of a valid sample NaN, ∞ or negative.
    pub bad_pdf_function: u32,
    /// The u of the first failing sample.
    pub first_failure: Option<[f32; 4]>,
    /// What that sample got, e.g. "d = (0, 0, NaN), |d| = NaN, pdf = 0.1592, pdf(d) = 0.1592"
    /// (as text: NaN and ∞ have no JSON number).
    pub first_failure_got: Option<String>,
    pub passed: bool,
}

/// A number as the messages print it: 4 significant digits, NaN, ∞.
pub fn show(x: f32) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x.is_infinite() {
        if x > 0.0 { "∞".into() } else { "−∞".into() }
    } else if x == 0.0 || (1e-3..1e4).contains(&x.abs()) {
        format!("{}", (x as f64 * 1e4).round() / 1e4)
    } else {
        format!("{x:.3e}")
    }
}

/// What a probed sample got: its point, length, reported pdf and pdf(d).
fn got(p: &Probe) -> String {
    let d = p.d();
    format!("d = ({}, {}, {}), |d| = {}, pdf = {}, pdf(d) = {}", show(d[0]), show(d[1]), show(d[2]), show(p.length), show(p.reported_pdf()), show(p.pdf))
}

/// Classifies the probed samples of one row.
pub fn row(incident_theta: f64, probes: &[Probe], u: &[[f32; 4]], bounds: Option<[f64; 4]>) -> HardRow {
    let mut r = HardRow {
        incident_theta,
        samples: probes.len() as u32,
        valid: 0,
        rejected: 0,
        bad_pdf: 0,
        bad_point: 0,
        bad_pdf_function: 0,
        first_failure: None,
        first_failure_got: None,
        passed: true,
    };
    for (p, u) in probes.iter().zip(u) {
        let (d, pdf) = (p.d(), p.reported_pdf());
        let finite = d[..3].iter().all(|x| x.is_finite());
        let in_domain = finite
            && match bounds {
                Some([x0, y0, x1, y1]) => (x0..=x1).contains(&(d[0] as f64)) && (y0..=y1).contains(&(d[1] as f64)),
                None => is_unit(p.length),
            };
        let fn_pdf = p.pdf;
        let failed = if !pdf.is_finite() || pdf < 0.0 {
            r.bad_pdf += 1;
            true
        } else if pdf == 0.0 && finite {
            r.rejected += 1;
            false
        } else if !in_domain {
            r.bad_point += 1;
            true
        } else if !fn_pdf.is_finite() || fn_pdf < 0.0 {
            r.bad_pdf_function += 1;
            true
        } else {
            r.valid += 1;
            false
        };
        if failed && r.first_failure.is_none() {
            r.first_failure = Some(*u);
            r.first_failure_got = Some(got(p));
        }
    }
    r.passed = r.first_failure.is_none();
    r
}

/// Whether a direction's length |d| is 1 to the hard cases' tolerance, 10⁻³ (NaN is not).
pub(super) fn is_unit(length: f32) -> bool {
    (length as f64 - 1.0).abs() <= 1e-3
}
