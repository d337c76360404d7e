//! Why a sample is invalid: one list of reasons for `lobes run`'s lobes and `lobes check`'s
//! samplers, on the CPU and in the WGSL passes (codes 1 ..= [`Invalid::COUNT`], counted in the
//! cells after a histogram's bins, in the order of [`Invalid::ALL`]), and the per-reason record
//! the output files hold ([`ByReason`]).

use glam::DVec3;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Why a sample is not a usable point of its domain. Every invalid sample is counted under
/// exactly one reason, checked in this order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Invalid {
    /// The sampled point (a direction, or a point of a plane domain) has a NaN or infinite
    /// component.
    NonFinitePoint,
    /// The point is outside the sampler's domain. For a lobe, whose domain is the hemisphere
    /// above the surface: ωr.z ≤ 0 (for a rough dielectric: a reflection that left through the
    /// surface, to the far side from ωi). For a user's sampler: off the sphere (|d| not 1), off
    /// the plane's bounds, or off a fitted grid's support.
    OutsideDomain,
    /// The density is NaN or infinite.
    NonFinitePdf,
    /// The density is ≤ 0: a rejection, as the samplers' contract writes one.
    ZeroPdf,
    /// A rough dielectric's refraction that stayed on the incident side (a microfacet tilted
    /// past the macro surface, [`dielectric`](super::dielectric)); never a user's sampler's.
    RefractedNearSide,
}

impl Invalid {
    pub const ALL: [Invalid; 5] = [Invalid::NonFinitePoint, Invalid::OutsideDomain, Invalid::NonFinitePdf, Invalid::ZeroPdf, Invalid::RefractedNearSide];
    /// The number of reasons.
    pub const COUNT: usize = Invalid::ALL.len();

    /// The name in the output files and messages (snake case, as serde writes it).
    pub fn name(self) -> &'static str {
        match self {
            Invalid::NonFinitePoint => "non_finite_point",
            Invalid::OutsideDomain => "outside_domain",
            Invalid::NonFinitePdf => "non_finite_pdf",
            Invalid::ZeroPdf => "zero_pdf",
            Invalid::RefractedNearSide => "refracted_near_side",
        }
    }

    /// The position in [`Invalid::ALL`], and of the reason's cell after a histogram's bins.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The code the WGSL passes use for this reason (0 is a valid sample).
    pub const fn code(self) -> u32 {
        self as u32 + 1
    }

    /// The WGSL constants of the codes, `{prefix}_NON_FINITE_POINT` …, and `{prefix}_COUNT`:
    /// the engine's kernels (`lobes::job`, prefix `REASON`) and the check's passes (a generated
    /// `lobes::invalid`, prefix `LOBES_REASON`, a name no user's file may take) read the same
    /// codes under the names their namespaces allow.
    pub fn wgsl_consts(prefix: &str) -> String {
        let mut src = format!("const {prefix}_COUNT: u32 = {}u;\n", Invalid::COUNT);
        for r in Invalid::ALL {
            src += &format!("const {prefix}_{}: u32 = {}u;\n", r.name().to_uppercase(), r.code());
        }
        src
    }

    /// Classifies a sampled direction and its density.
    pub fn check(wr: DVec3, pdf_r: f64) -> Option<Invalid> {
        Invalid::check_scattered(DVec3::Z, wr, pdf_r, true)
    }

    /// Classifies a direction that may leave on either side of the surface, a rough
    /// dielectric's ([`dielectric`](super::dielectric)) seen from ωi: `reflected` says its event. A reflection is
    /// valid on the side of ωi, a refraction on the other (ωo on the surface is on neither); a
    /// sample on the wrong side of its event is [`Invalid::OutsideDomain`] (a reflection) or
    /// [`Invalid::RefractedNearSide`], before its density is looked at. With ωi = +z and a
    /// reflection, this is [`Invalid::check`].
    pub fn check_scattered(wi: DVec3, wo: DVec3, pdf_o: f64, reflected: bool) -> Option<Invalid> {
        // ωo.z on ωi's side taken positive (light from inside is mirrored, dielectric.rs)
        let side = if wi.z < 0.0 { -wo.z } else { wo.z };
        if !wo.is_finite() {
            Some(Invalid::NonFinitePoint)
        } else if reflected && side <= 0.0 {
            Some(Invalid::OutsideDomain)
        } else if !reflected && side >= 0.0 {
            Some(Invalid::RefractedNearSide)
        } else if !pdf_o.is_finite() {
            Some(Invalid::NonFinitePdf)
        } else if pdf_o <= 0.0 {
            Some(Invalid::ZeroPdf)
        } else {
            None
        }
    }
}

/// One value per invalid reason ([`Invalid::ALL`], whose names are the keys). Files written
/// before the reasons were shared with `lobes check` (histogram and shard format 4) named the
/// first two `non_finite_direction` and `below_horizon`: read under those names too.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[schemars(bound = "T: JsonSchema + Default")]
pub struct ByReason<T> {
    #[serde(alias = "non_finite_direction")]
    pub non_finite_point: T,
    #[serde(alias = "below_horizon")]
    pub outside_domain: T,
    pub non_finite_pdf: T,
    pub zero_pdf: T,
    /// Absent in records written before the rough dielectric (read as 0).
    #[serde(default)]
    pub refracted_near_side: T,
}

impl<T: Copy> From<[T; Invalid::COUNT]> for ByReason<T> {
    /// From values in the order of [`Invalid::ALL`].
    fn from([non_finite_point, outside_domain, non_finite_pdf, zero_pdf, refracted_near_side]: [T; Invalid::COUNT]) -> Self {
        ByReason { non_finite_point, outside_domain, non_finite_pdf, zero_pdf, refracted_near_side }
    }
}

impl<T: Copy> From<ByReason<T>> for [T; Invalid::COUNT] {
    /// To values in the order of [`Invalid::ALL`].
    fn from(r: ByReason<T>) -> Self {
        [r.non_finite_point, r.outside_domain, r.non_finite_pdf, r.zero_pdf, r.refracted_near_side]
    }
}

impl<T> ByReason<T> {
    /// The value for `reason`.
    pub fn get(&self, reason: Invalid) -> &T {
        match reason {
            Invalid::NonFinitePoint => &self.non_finite_point,
            Invalid::OutsideDomain => &self.outside_domain,
            Invalid::NonFinitePdf => &self.non_finite_pdf,
            Invalid::ZeroPdf => &self.zero_pdf,
            Invalid::RefractedNearSide => &self.refracted_near_side,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reasons_are_keyed_by_their_names_in_order() {
        let v = serde_json::to_value(ByReason::from([10u64, 11, 12, 13, 14])).unwrap();
        for (i, r) in Invalid::ALL.into_iter().enumerate() {
            assert_eq!(r.index(), i);
            assert_eq!(v[r.name()], 10 + i as u64, "{}", r.name());
            assert_eq!(serde_json::to_value(r).unwrap(), r.name());
            assert_eq!(*ByReason::from([10u64, 11, 12, 13, 14]).get(r), 10 + i as u64);
        }
        assert_eq!(v.as_object().unwrap().len(), 5);
        let back: [u64; 5] = serde_json::from_value::<ByReason<u64>>(v).unwrap().into();
        assert_eq!(back, [10, 11, 12, 13, 14]);
        // a record from before the rough dielectric has four reasons, under their old names
        let old = serde_json::json!({"non_finite_direction": 1, "below_horizon": 2, "non_finite_pdf": 3, "zero_pdf": 4});
        assert_eq!(<[u64; 5]>::from(serde_json::from_value::<ByReason<u64>>(old).unwrap()), [1, 2, 3, 4, 0]);
    }

    /// The WGSL constants hold the codes 1 ..= 5 in the order of `ALL`, parsed back by naga.
    #[test]
    fn the_wgsl_codes_are_the_cpu_codes() {
        let module = naga::front::wgsl::parse_str(&Invalid::wgsl_consts("R")).unwrap();
        let value = |name: &str| {
            let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).unwrap_or_else(|| panic!("{name}"));
            match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => v,
                ref e => panic!("{name}: {e:?}"),
            }
        };
        assert_eq!(value("R_COUNT"), 5);
        for (i, r) in Invalid::ALL.into_iter().enumerate() {
            assert_eq!(value(&format!("R_{}", r.name().to_uppercase())), i as u32 + 1);
        }
    }
}
