//! A user's sampler: its files and how its functions are called, as data; [`super::check`]
//! composes and validates it.

use super::composition;
use super::conventions::{self, Conventions};
use super::{CheckError, Composition, Domain, SampleReturns, Setting, Source};

/// A user's sampler: WGSL files and how to call its functions.
///
/// `sample`, `pdf` and `eval` are each a function name with the contract's signature, or a WGSL
/// call expression over lobes' names `wi`, `u` (sample), `d` (pdf, eval), `params`, `p0` … `p15`
/// and `rng` (a `ptr<function, u32>` seeded per sample); `composition` says where imported
/// modules are found and which functions are the user's RNG ([`Composition`]).
#[derive(Debug, Clone, PartialEq)]
pub struct UserSampler {
    pub sources: Vec<Source>,
    pub sample: String,
    pub pdf: String,
    pub eval: Option<String>,
    pub domain: Domain,
    /// How the sampler is written: its frame, measure and declared domain ([`Conventions`]).
    pub conventions: Conventions,
    /// How its files are composed and its functions called ([`Composition`]).
    pub composition: Composition,
}

impl UserSampler {
    /// The pdf at a sample's d as the user named it, for messages: `NAME(d)` for a function
    /// name (`my_pdf(d)`), a call expression as written (`ggx_vndf_pdf(wi, d, p0)`, never
    /// `ggx_vndf_pdf(wi, d, p0)(d)`).
    pub fn pdf_at_d(&self) -> String {
        if composition::is_name(self.pdf.trim()) { format!("{}(d)", self.pdf.trim()) } else { self.pdf.clone() }
    }

    /// The same sampler declared in `conventions` (`--incident upper`, `--reflection-only`, …).
    pub fn with_conventions(self, conventions: Conventions) -> Result<Self, CheckError> {
        let s = Self { conventions, ..self };
        s.conventions.validate(s.domain)?;
        s.light_measure()?;
        Ok(s)
    }

    /// `--measure area` and `--normal` come together, and not with a half vector.
    pub(super) fn light_measure(&self) -> Result<(), CheckError> {
        let area = self.conventions.measure == conventions::Measure::Area;
        match (area, &self.composition.normal) {
            (true, None) => Err(CheckError::setting(
                Setting::Normal,
                "needed with the area measure (a sample that is a point of a light): the light's unit normal at the sampled point p, WGSL over p and params, for the area-to-solid-angle factor |p|²/|n·d|",
            )),
            (false, Some(_)) => Err(CheckError::setting(Setting::Normal, "only with the area measure (a sample that is a point of a light, with its area density); remove it")),
            (true, Some(_)) if self.composition.sample_returns == SampleReturns::HalfVector => {
                Err(CheckError::setting(Setting::SampleReturns, "a half vector is not a light's point (the area measure); keep one"))
            }
            _ => Ok(()),
        }
    }

    /// "my_sample/my_pdf in file.wgsl", and the conventions declared: "… (reflection-only)".
    pub(crate) fn describe(&self) -> String {
        let files: Vec<&str> = self.sources.iter().map(|f| f.name.as_str()).collect();
        let conventions = if self.conventions.is_default() { String::new() } else { format!(" ({})", self.conventions.declared()) };
        format!("{}/{} in {}{conventions}", self.sample, self.pdf, files.join(", "))
    }
}
