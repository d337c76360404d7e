//! The sampler registry: one [`SamplerSpec`] per (lobe, method), the single list every other
//! list of samplers comes from (the uber-kernel's ids, `lobes bench`, `lobes tradeoff`, the
//! stress suite, the WGSL call sites of the counting and weighted kernels).
//!
//! An entry names the sampler, the library modules that define its WGSL functions, the call
//! sites of those functions, its f64 Rust twin ([`Reference`], `None` for a sampler known only
//! as WGSL) and whether its WGSL also composes in f64 (`lobes tradeoff`).
//! Adding a sampler is one entry here plus its files.

use super::microfacet::{self, Microfacet, pdf_ndf, pdf_vndf};
use super::ward;
use super::beckmann::Beckmann;
use super::ggx::Ggx;
use serde::{Deserialize, Serialize};
use glam::DVec3;

/// Which lobe.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LobeKind {
    Ward,
    Beckmann,
    Ggx,
}

/// How the half vector is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// The lobe's own distribution: Ward's p(h), or D(h) cos θh for microfacets.
    Ndf,
    /// Visible normals: spherical caps for GGX, Heitz & d'Eon for Beckmann.
    Vndf,
    /// Bounded VNDF (Eto & Tokuyoshi 2023), GGX only.
    Bounded,
}

impl LobeKind {
    /// Every lobe, in [`LOBES`]' order: what a scene's `lobe` and `--lobe` accept.
    pub const ALL: [LobeKind; LOBES.len()] = {
        let mut out = [LobeKind::Ward; LOBES.len()];
        let mut i = 0;
        while i < LOBES.len() {
            // LOBES is in the enum's order, so that `spec` is an index
            assert!(LOBES[i].kind as usize == i, "LOBES lists the lobes in LobeKind's order");
            out[i] = LOBES[i].kind;
            i += 1;
        }
        out
    };

    /// Its entry in [`LOBES`].
    pub fn spec(self) -> &'static LobeSpec {
        &LOBES[self as usize]
    }
    /// Its name in scenes, on the command line and in outputs.
    pub fn name(self) -> &'static str {
        self.spec().name
    }
    /// One line on the lobe (the command line's help).
    pub fn about(self) -> &'static str {
        self.spec().about
    }
    /// The lobe called `name` ([`LobeKind::name`]).
    ///
    /// ```
    /// use lobes::reference::LobeKind;
    /// assert_eq!(LobeKind::from_name("ggx"), Some(LobeKind::Ggx));
    /// assert_eq!(LobeKind::from_name("GGX"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
    /// Whether this lobe has a sampler for `method`.
    pub fn supports(self, method: Method) -> bool {
        of_kind(self).any(|s| s.method == method)
    }
    /// The methods it has a sampler for, in [`Method::ALL`]'s order.
    pub fn methods(self) -> impl Iterator<Item = Method> {
        Method::ALL.into_iter().filter(move |&m| self.supports(m))
    }
}

impl Method {
    /// Every method: what a scene's `method` and `--method` accept for a lobe.
    pub const ALL: [Method; 3] = [Method::Ndf, Method::Vndf, Method::Bounded];

    /// Its name in scenes, on the command line and in outputs.
    pub fn name(self) -> &'static str {
        match self {
            Method::Ndf => "ndf",
            Method::Vndf => "vndf",
            Method::Bounded => "bounded",
        }
    }
    /// One line on the method (the command line's help).
    pub fn about(self) -> &'static str {
        match self {
            Method::Ndf => "The lobe's own distribution (Ward's p(h), or D(h) cos θh)",
            Method::Vndf => "Visible normals",
            Method::Bounded => "Bounded VNDF (Eto & Tokuyoshi 2023)",
        }
    }
    /// The method called `name` ([`Method::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// One sampler: a lobe and the method that draws its half vectors.
#[derive(Debug, Clone, Copy)]
pub struct SamplerSpec {
    pub kind: LobeKind,
    pub method: Method,
    pub wgsl: Wgsl,
    /// The f64 reference the GPU sampler is judged against (`None`: no f64 twin).
    pub reference: Option<Reference>,
}

/// A sampler's WGSL: its files and the call sites of its functions. The call sites are
/// expressions in the names of the kernels that call them: `a: vec2<f32>` (αx, αy), `wi`,
/// `wr: vec3<f32>`, `h = normalize(wi + wr)`, `u: vec2<f32>` and a drawn `s: LobeSample`.
#[derive(Debug, Clone, Copy)]
pub struct Wgsl {
    /// The library module (`#define_import_path` of its `shaders/lib` file) that defines the
    /// sampler.
    pub module: &'static str,
    /// The library module that defines its density, BRDF and weight (it imports `module`).
    pub eval_module: &'static str,
    /// `fn (a, wi, u) -> LobeSample`.
    pub sample: &'static str,
    /// p(ωr), the sampler's density, in terms of `a`, `wi`, `wr`.
    pub pdf: &'static str,
    /// f without Fresnel and masking, in terms of `a`, `wi`, `wr`, `h`: D / (4 cos θi cos θr)
    /// for microfacets, Ward's BRDF.
    pub eval: &'static str,
    /// The estimator weight without Fresnel and masking (see
    /// [`Effects::weight`](super::effects::Effects::weight)), in terms of `a`, `wi`, `s`.
    pub weight: &'static str,
    /// Smith's G1(w) in terms of `a`, `w` (microfacet lobes; `None`: no masking).
    pub g1: Option<&'static str>,
    /// Whether `module` is written over the type `Real` (`shaders/math`), so that the same
    /// sampler composes in f64 for `lobes tradeoff`'s f64 kernels; a sampler written in f32
    /// has no f64 kernel.
    pub f64: bool,
    /// The rough dielectric over this sampler's half vectors (`shaders/lib/dielectric.wgsl`,
    /// f64 twin [`RoughDielectric`](super::dielectric::RoughDielectric)):
    /// `fn (a, wi, u: vec3<Real>, eta) -> LobeSample`, u.xy drawing h and u.z the event, the
    /// sample's `wr` the scattered direction on either side. `None`: no dielectric sampler.
    pub dielectric: Option<&'static str>,
    /// The weighted pass of that dielectric (`shaders/lib/dielectric_eval.wgsl`, f64 twins
    /// `RoughDielectric::pdf`, `eval` and `weight`); `None` exactly where `dielectric` is.
    pub dielectric_eval: Option<DielectricEval>,
}

/// A rough dielectric's density, BSDF (without G) and weight (without G), as expressions like
/// [`Wgsl`]'s in `a`, `wi`, `wr` (on either side), `s` and the job's η, `lobe_eta()`.
#[derive(Debug, Clone, Copy)]
pub struct DielectricEval {
    pub pdf: &'static str,
    pub eval: &'static str,
    pub weight: &'static str,
}

/// The f64 reference of a sampler (`src/reference`).
/// A lobe's roughness (αx, αy), along the axes of its tangent frame.
pub type Alpha = (f64, f64);

#[derive(Debug, Clone, Copy)]
pub struct Reference {
    /// The half vector drawn for uniforms `u`.
    pub sample_h: fn(Alpha, DVec3, [f64; 2]) -> DVec3,
    /// The density of h, per unit solid angle.
    pub pdf_h: fn(Alpha, DVec3, DVec3) -> f64,
    /// p(ωr) given h, where the method defines its own reflected density rather than
    /// p(h) / (4 |ωr·h|) (bounded VNDF).
    pub pdf_r: Option<fn(Alpha, DVec3, DVec3) -> f64>,
}

/// One lobe: its names and the f64 terms of its BRDF, which [`Effects`](super::effects::Effects)
/// builds the BRDF, the estimator weight and the furnace test from.
#[derive(Debug, Clone, Copy)]
pub struct LobeSpec {
    pub kind: LobeKind,
    /// Its name in scenes, on the command line and in outputs.
    pub name: &'static str,
    /// One line on the lobe (the command line's help).
    pub about: &'static str,
    /// f(ωi, ωr) without Fresnel in the local frame, 0 unless both are above the horizon
    /// (microfacets: with height-correlated Smith G2).
    pub eval: fn(Alpha, DVec3, DVec3) -> f64,
    pub shape: Shape,
}

/// What a lobe's BRDF is made of.
#[derive(Debug, Clone, Copy)]
pub enum Shape {
    /// Microfacets, f = F D G / (4 cos θi cos θr) (Walter et al. 2007, eq. 20).
    Microfacet(MicrofacetTerms),
    /// A BRDF of its own, with no masking: the estimator weight F f cos θr / p(ωr) of its sampler,
    /// given F, ωi, h and ωr in the local frame.
    Own { weight: fn(f64, DVec3, DVec3, DVec3) -> f64 },
}

/// The terms of a microfacet lobe at roughness α: D(h), Smith's G1(ω) in its grazing-stable
/// form (|cos θ| for ω below the horizon) and Λ(ω), G1 = 1 / (1 + Λ).
#[derive(Debug, Clone, Copy)]
pub struct MicrofacetTerms {
    pub d: fn(Alpha, DVec3) -> f64,
    pub g1: fn(Alpha, DVec3) -> f64,
    pub lambda: fn(Alpha, DVec3) -> f64,
}

/// Every lobe.
pub const LOBES: [LobeSpec; 3] = [
    LobeSpec {
        kind: LobeKind::Ward,
        name: "ward",
        about: "Ward's lobe with Walter's pdf",
        eval: |(ax, ay), wi, wr| ward::eval(ax, ay, wi, wr),
        // F (ωi·h)⁺ cos³θh √(|cos θr| / cos θi) (Walter 2005, eq. 10)
        shape: Shape::Own { weight: |f, wi, h, wr| f * wi.dot(h).max(0.0) * h.z.powi(3) * (wr.z.abs() / wi.z).sqrt() },
    },
    LobeSpec {
        kind: LobeKind::Beckmann,
        name: "beckmann",
        about: "Beckmann microfacets",
        eval: |(ax, ay), wi, wr| microfacet::eval(&Beckmann { ax, ay }, wi, wr),
        shape: Shape::Microfacet(MicrofacetTerms {
            d: |(ax, ay), h| Beckmann { ax, ay }.d(h),
            g1: |(ax, ay), w| w.z.abs() * Beckmann { ax, ay }.g1_over_cos(w),
            lambda: |(ax, ay), w| Beckmann { ax, ay }.lambda(w),
        }),
    },
    LobeSpec {
        kind: LobeKind::Ggx,
        name: "ggx",
        about: "GGX (Trowbridge–Reitz) microfacets",
        eval: |(ax, ay), wi, wr| microfacet::eval(&Ggx { ax, ay }, wi, wr),
        shape: Shape::Microfacet(MicrofacetTerms { d: |(ax, ay), h| Ggx { ax, ay }.d(h), g1: |(ax, ay), w| Ggx { ax, ay }.g1(w), lambda: |(ax, ay), w| Ggx { ax, ay }.lambda(w) }),
    },
];

const MICROFACET_NDF_WEIGHT: &str = "microfacet_ndf_weight(wi, s.h)";
const GGX_EVAL: &str = "ggx_d(a, h) / (4.0 * wi.z * wr.z)";
const BECKMANN_EVAL: &str = "beckmann_d(a, h) / (4.0 * wi.z * wr.z)";
const DIELECTRIC_GGX_EVAL: &str = "dielectric_ggx_eval(a, wi, wr, lobe_eta())";
const DIELECTRIC_BECKMANN_EVAL: &str = "dielectric_beckmann_eval(a, wi, wr, lobe_eta())";

/// Every sampler; an uber-kernel's sampler id is its index here.
pub const REGISTRY: [SamplerSpec; 6] = [
    SamplerSpec {
        kind: LobeKind::Ward,
        method: Method::Ndf,
        wgsl: Wgsl {
            module: "lobes::ward",
            eval_module: "lobes::ward_eval",
            sample: "ward_sample",
            pdf: "ward_pdf(a, wi, wr)",
            eval: "ward_eval(a, wi, wr)",
            weight: "ward_weight(wi, s.h, s.wr)",
            g1: None,
            f64: true,
            dielectric: None,
            dielectric_eval: None,
        },
        reference: Some(Reference {
            sample_h: |(ax, ay), _, u| ward::sample_h(ax, ay, u),
            pdf_h: |(ax, ay), _, h| ward::pdf_h(ax, ay, h),
            pdf_r: None,
        }),
    },
    SamplerSpec {
        kind: LobeKind::Beckmann,
        method: Method::Ndf,
        wgsl: Wgsl {
            module: "lobes::beckmann",
            eval_module: "lobes::beckmann_eval",
            sample: "beckmann_sample_ndf",
            pdf: "beckmann_pdf_ndf(a, wi, wr)",
            eval: BECKMANN_EVAL,
            weight: MICROFACET_NDF_WEIGHT,
            g1: Some("beckmann_g1(a, w)"),
            f64: true,
            dielectric: Some("dielectric_beckmann_ndf"),
            dielectric_eval: Some(DielectricEval { pdf: "dielectric_beckmann_ndf_pdf(a, wi, wr, lobe_eta())", eval: DIELECTRIC_BECKMANN_EVAL, weight: MICROFACET_NDF_WEIGHT }),
        },
        reference: Some(Reference {
            sample_h: |(ax, ay), _, u| Beckmann { ax, ay }.sample_ndf(u),
            pdf_h: |(ax, ay), _, h| pdf_ndf(&Beckmann { ax, ay }, h),
            pdf_r: None,
        }),
    },
    SamplerSpec {
        kind: LobeKind::Beckmann,
        method: Method::Vndf,
        wgsl: Wgsl {
            module: "lobes::beckmann",
            eval_module: "lobes::beckmann_eval",
            sample: "beckmann_sample_vndf",
            pdf: "beckmann_pdf_vndf(a, wi, wr)",
            eval: BECKMANN_EVAL,
            weight: "beckmann_vndf_weight(a, wi)",
            g1: Some("beckmann_g1(a, w)"),
            f64: true,
            dielectric: Some("dielectric_beckmann_vndf"),
            dielectric_eval: Some(DielectricEval { pdf: "dielectric_beckmann_vndf_pdf(a, wi, wr, lobe_eta())", eval: DIELECTRIC_BECKMANN_EVAL, weight: "dielectric_beckmann_vndf_weight(a, wi)" }),
        },
        reference: Some(Reference {
            sample_h: |(ax, ay), wi, u| Beckmann { ax, ay }.sample_vndf(wi, u),
            pdf_h: |(ax, ay), wi, h| pdf_vndf(&Beckmann { ax, ay }, wi, h),
            pdf_r: None,
        }),
    },
    SamplerSpec {
        kind: LobeKind::Ggx,
        method: Method::Ndf,
        wgsl: Wgsl {
            module: "lobes::ggx",
            eval_module: "lobes::ggx_eval",
            sample: "ggx_sample_ndf",
            pdf: "ggx_pdf_ndf(a, wi, wr)",
            eval: GGX_EVAL,
            weight: MICROFACET_NDF_WEIGHT,
            g1: Some("ggx_g1(a, w)"),
            f64: true,
            dielectric: Some("dielectric_ggx_ndf"),
            dielectric_eval: Some(DielectricEval { pdf: "dielectric_ggx_ndf_pdf(a, wi, wr, lobe_eta())", eval: DIELECTRIC_GGX_EVAL, weight: MICROFACET_NDF_WEIGHT }),
        },
        reference: Some(Reference {
            sample_h: |(ax, ay), _, u| Ggx { ax, ay }.sample_ndf(u),
            pdf_h: |(ax, ay), _, h| pdf_ndf(&Ggx { ax, ay }, h),
            pdf_r: None,
        }),
    },
    SamplerSpec {
        kind: LobeKind::Ggx,
        method: Method::Vndf,
        wgsl: Wgsl {
            module: "lobes::ggx",
            eval_module: "lobes::ggx_eval",
            sample: "ggx_sample_vndf",
            pdf: "ggx_pdf_vndf(a, wi, wr)",
            eval: GGX_EVAL,
            weight: "ggx_vndf_weight(a, wi)",
            g1: Some("ggx_g1(a, w)"),
            f64: true,
            dielectric: Some("dielectric_ggx_vndf"),
            dielectric_eval: Some(DielectricEval { pdf: "dielectric_ggx_vndf_pdf(a, wi, wr, lobe_eta())", eval: DIELECTRIC_GGX_EVAL, weight: "dielectric_ggx_vndf_weight(a, wi)" }),
        },
        reference: Some(Reference {
            sample_h: |(ax, ay), wi, u| Ggx { ax, ay }.sample_vndf(wi, u),
            pdf_h: |(ax, ay), wi, h| pdf_vndf(&Ggx { ax, ay }, wi, h),
            pdf_r: None,
        }),
    },
    SamplerSpec {
        kind: LobeKind::Ggx,
        method: Method::Bounded,
        wgsl: Wgsl {
            module: "lobes::ggx",
            eval_module: "lobes::ggx_eval",
            sample: "ggx_sample_bounded",
            pdf: "ggx_pdf_bounded(a, wi, wr)",
            eval: GGX_EVAL,
            weight: "ggx_bounded_weight(a, wi)",
            g1: Some("ggx_g1(a, w)"),
            f64: true,
            dielectric: None,
            dielectric_eval: None,
        },
        reference: Some(Reference {
            sample_h: |(ax, ay), wi, u| Ggx { ax, ay }.sample_bounded(wi, u),
            // the reflected density (Eto & Tokuyoshi 2023, listing 2) through the reflection Jacobian
            pdf_h: |(ax, ay), wi, h| {
                let wr = super::reflect::reflect(wi, h);
                if wr.z > 0.0 { Ggx { ax, ay }.pdf_bounded_r(wi, h) * 4.0 * wi.dot(h).abs() } else { 0.0 }
            },
            pdf_r: Some(|(ax, ay), wi, h| Ggx { ax, ay }.pdf_bounded_r(wi, h)),
        }),
    },
];

/// Every (lobe, method) pair of the registry, in its order.
pub const SAMPLERS: [(LobeKind, Method); REGISTRY.len()] = {
    let mut out = [(LobeKind::Ward, Method::Ndf); REGISTRY.len()];
    let mut i = 0;
    while i < REGISTRY.len() {
        out[i] = (REGISTRY[i].kind, REGISTRY[i].method);
        i += 1;
    }
    out
};

impl SamplerSpec {
    /// `ggx-vndf`, `ward-ndf`, … .
    pub fn name(&self) -> String {
        format!("{}-{}", self.kind.name(), self.method.name())
    }

    /// The uber-kernel's id of this sampler: its index in [`REGISTRY`].
    pub fn id(&self) -> u32 {
        REGISTRY.iter().position(|s| (s.kind, s.method) == (self.kind, self.method)).expect("an entry of the registry") as u32
    }
}

/// The entry of a lobe and method. Ward has one sampler, whatever the method (as `lobes run`
/// rejects other methods for it before this is asked), and Beckmann's visible normals stand for
/// every method but NDF.
pub fn find(kind: LobeKind, method: Method) -> &'static SamplerSpec {
    let method = match kind {
        LobeKind::Ward => Method::Ndf,
        LobeKind::Beckmann if method != Method::Ndf => Method::Vndf,
        _ => method,
    };
    REGISTRY.iter().find(|s| (s.kind, s.method) == (kind, method)).expect("every supported lobe/method pair has an entry")
}

/// The entry named `name` (`ggx-vndf`, …).
pub fn by_name(name: &str) -> Option<&'static SamplerSpec> {
    REGISTRY.iter().find(|s| s.name() == name.trim())
}

/// The samplers of `kind`.
pub fn of_kind(kind: LobeKind) -> impl Iterator<Item = &'static SamplerSpec> {
    REGISTRY.iter().filter(move |s| s.kind == kind)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_are_unique_and_supported() {
        for (i, s) in REGISTRY.iter().enumerate() {
            assert!(s.kind.supports(s.method), "{}", s.name());
            assert_eq!(s.id() as usize, i, "{} listed twice", s.name());
            assert_eq!(find(s.kind, s.method).name(), s.name());
        }
    }

    #[test]
    fn every_lobe_and_method_named_has_a_sampler() {
        for kind in LobeKind::ALL {
            assert!(kind.methods().next().is_some() && LobeKind::from_name(kind.name()) == Some(kind), "{kind:?}");
        }
        for method in Method::ALL {
            assert!(LobeKind::ALL.iter().any(|k| k.supports(method)) && Method::from_name(method.name()) == Some(method), "{method:?}");
        }
        assert!(REGISTRY.iter().all(|s| LobeKind::ALL.contains(&s.kind) && Method::ALL.contains(&s.method)));
        assert_eq!(LobeKind::Ward.methods().collect::<Vec<_>>(), [Method::Ndf]);
        assert_eq!(LobeKind::Ggx.methods().collect::<Vec<_>>(), Method::ALL);
    }
}
