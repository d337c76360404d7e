//! `pdf_values`: the pdf never NaN, ∞ or negative at the quadrature's nodes. Where it is, the
//! pdf is evaluated on a fine grid of the domain (the centres of 256 × 512 cells in (cos θ, φ) on the
//! sphere, 256 × 256 of the box on the plane) and the worst point named: NaN first, then ±∞,
//! then the most negative value.

use super::{Measured, Run};
use crate::check::conventions::Conventions;
use crate::check::gpu::{Params, Passes};
use crate::check::hard::show;
use crate::check::report::{Check, Figures, PdfValuesFigures};
use crate::check::{CheckError, Domain, Message};

/// The grid's cells per cell of the domain's default histogram, along each axis (256 × 512 on
/// the sphere, 256 × 256 on the plane).
const FINER: u32 = 4;

/// The worst value found and where, in the user's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Worst {
    /// The point (in the user's frame on the sphere) and its θ, φ in degrees (the same numbers in
    /// either frame).
    pub d: [f64; 3],
    pub angles: (f64, f64),
    pub value: f32,
}

impl Worst {
    /// "pdf(d) = NaN at d = (0.1, 0.2, 0.97) (θ 14.1°, φ 63.4°)" (θ, φ on the sphere only), with
    /// `pdf_at_d` the pdf at d as the user named it ([`super::UserSampler::pdf_at_d`]).
    pub fn describe(&self, pdf_at_d: &str, domain: Domain) -> String {
        let [x, y, z] = self.d.map(|v| show(v as f32));
        let angles = if domain.directions() {
            let (t, p) = self.angles;
            format!(" (θ {t:.1}°, φ {p:.1}°)")
        } else {
            String::new()
        };
        format!("{pdf_at_d} = {} at d = ({x}, {y}, {z}){angles}", show(self.value))
    }
}

fn angles(d: [f64; 3]) -> (f64, f64) {
    (d[2].clamp(-1.0, 1.0).acos().to_degrees(), d[1].atan2(d[0]).to_degrees())
}

/// How bad a value is: NaN 3, ±∞ 2, negative 1 (then by how negative), else none.
fn badness(v: f32) -> Option<(u8, f32)> {
    if v.is_nan() {
        Some((3, 0.0))
    } else if v.is_infinite() {
        Some((2, 0.0))
    } else if v < 0.0 {
        Some((1, -v))
    } else {
        None
    }
}

/// The worst point of the grid, if any is bad.
fn worst(passes: &Passes, params: &Params, domain: &Domain, conventions: &Conventions) -> Result<Option<Worst>, CheckError> {
    let (rows, cols) = domain.default_grid();
    let points: Vec<[f32; 4]> = domain.grid(FINER * rows, FINER * cols).centres().iter().map(|&[x, y, z]| [x as f32, y as f32, z as f32, 0.0]).collect();
    let values = passes.pdf_at(params, &points)?;
    let worst = points
        .iter()
        .zip(&values)
        .filter_map(|(d, v)| badness(v[0]).map(|b| (b, d, v[0])))
        .max_by(|a, b| a.0.0.cmp(&b.0.0).then(a.0.1.total_cmp(&b.0.1)));
    Ok(worst.map(|(_, d, value)| {
        let d = [d[0] as f64, d[1] as f64, d[2] as f64];
        Worst { d: if domain.directions() { conventions.to_user(d) } else { d }, angles: angles(d), value }
    }))
}

/// `pdf_values`: the pdf finite and ≥ 0 at every quadrature node; where not, its worst point.
pub(crate) fn check(run: &Run, m: &Measured) -> Result<Check, CheckError> {
    let (bad, parts) = (m.integrals.bad_parts, m.integrals.parts);
    let s = &*run.sampler;
    let worst = if bad > 0 { worst(&run.passes, &run.params, &s.domain, &s.conventions)? } else { None };
    if bad > 0
        && let Some(pole) = super::half_vector_pole(s, run.settings, Some(worst.as_ref().map(|w| w.angles)))
    {
        let at = worst.as_ref().map_or("between the points of a fine grid".into(), |w| w.describe(&run.pdf(), s.domain));
        return Err(CheckError::NoVerdict(Message::text(format!("{} returned NaN, ∞ or a negative value in {bad} of {parts} quadrature parts, {at}", run.pdf())).append(pole)));
    }
    let worst = worst.map(|w| w.describe(&run.pdf(), s.domain));
    let summary = if bad == 0 {
        format!("{} finite and ≥ 0 at every quadrature node ({parts} parts)", run.pdf())
    } else {
        let at = worst.clone().unwrap_or_else(|| "no such value on a fine grid of the domain: it lies between the grid's points".into());
        format!("{} returned NaN, ∞ or a negative value in {bad} of {parts} quadrature parts; {at}", run.pdf())
    };
    Ok(Check { passed: bad == 0, summary, figures: Figures::PdfValues(PdfValuesFigures { bad_parts: bad, parts, worst }) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_is_worse_than_infinity_is_worse_than_negative() {
        assert!(badness(f32::NAN) > badness(f32::INFINITY));
        assert!(badness(f32::NEG_INFINITY) > badness(-1e30));
        assert!(badness(-2.0) > badness(-1.0));
        assert_eq!(badness(0.0), None);
        let w = Worst { d: [0.0, 0.0, -1.0], angles: angles([0.0, 0.0, -1.0]), value: -1.0 };
        assert_eq!(w.describe("p(d)", Domain::Sphere), "p(d) = -1 at d = (0, 0, -1) (θ 180.0°, φ 0.0°)");
    }
}
