//! The scene file as written: serde's shape of the TOML, every value with its span, before
//! any is checked.

use super::sweep::{self, Sweep, Val, spanned_items};
use serde::Deserialize;
use toml::Spanned;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScene {
    pub(super) defaults: Option<Spanned<RawDefaults>>,
    #[serde(default)]
    pub(super) case: Vec<Spanned<RawCase>>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawDefaults {
    pub(super) samples: Option<Val>,
    pub(super) bins: Option<Val>,
    pub(super) seed: Option<Val>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCase {
    pub(super) name: Option<Val>,
    pub(super) lobe: Option<Val>,
    pub(super) method: Option<Sweep>,
    pub(super) alpha: Option<Sweep>,
    pub(super) alpha_x: Option<Sweep>,
    pub(super) alpha_y: Option<Sweep>,
    pub(super) alpha_angle: Option<Sweep>,
    pub(super) incident_theta: Option<Sweep>,
    pub(super) incident_phi: Option<Sweep>,
    pub(super) weights: Option<Spanned<Weights>>,
    pub(super) samples: Option<Sweep>,
    pub(super) bins: Option<Sweep>,
    pub(super) seed: Option<Sweep>,
    pub(super) weighted: Option<Val>,
    pub(super) fresnel: Option<Sweep>,
    pub(super) f0: Option<Sweep>,
    pub(super) eta: Option<Sweep>,
    pub(super) k: Option<Sweep>,
    pub(super) masking: Option<Sweep>,
    pub(super) scatter: Option<Sweep>,
    pub(super) sampler: Option<Spanned<RawSampler>>,
    pub(super) params: Option<Sweep>,
    pub(super) domain: Option<Val>,
    pub(super) bounds: Option<Val>,
    pub(super) timeout: Option<Val>,
    pub(super) budget: Option<Val>,
}

impl RawCase {
    /// The sweepable keys' values, in the order of [`sweep::KEYS`].
    pub(super) fn sweeps(&self) -> [Option<&Sweep>; sweep::KEYS.len()] {
        [
            &self.method,
            &self.alpha,
            &self.alpha_x,
            &self.alpha_y,
            &self.alpha_angle,
            &self.incident_theta,
            &self.incident_phi,
            &self.fresnel,
            &self.f0,
            &self.eta,
            &self.k,
            &self.masking,
            &self.scatter,
            &self.params,
            &self.bins,
            &self.samples,
            &self.seed,
        ]
        .map(Option::as_ref)
    }
}

/// `weights = [...]`, each item with its own span (so an error points at the bad weight).
#[derive(Debug)]
pub(super) struct Weights(pub(super) Vec<Val>);

impl<'de> Deserialize<'de> for Weights {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Weights;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an array of weights such as [15, 5, 25]")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Weights, A::Error> {
                spanned_items(seq).map(Weights)
            }
        }
        d.deserialize_seq(V)
    }
}

/// `sampler = { ... }` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSampler {
    /// One of lobes' built-in lights (`crate::reference::light::registry::LIGHTS`), instead of
    /// WGSL files: `sampler = { light = "sphere" }`, the geometry in the case's `params`.
    pub(super) light: Option<Val>,
    pub(super) wgsl: Option<Val>,
    pub(super) sample: Option<Val>,
    pub(super) pdf: Option<Val>,
    pub(super) eval: Option<Val>,
    // the sampler's conventions (crate::check::conventions), as `lobes check`'s flags
    pub(super) incident: Option<Val>,
    pub(super) reflection_only: Option<Val>,
    pub(super) u_open: Option<Val>,
    pub(super) measure: Option<Val>,
    pub(super) frame: Option<Val>,
    pub(super) rand: Option<Val>,
    pub(super) rand_order: Option<Val>,
    pub(super) shader_root: Option<Val>,
    pub(super) define: Option<Val>,
    pub(super) stub: Option<Val>,
    pub(super) package: Option<Val>,
    pub(super) texture: Option<Val>,
    pub(super) buffer: Option<Val>,
    /// The renderer's samplers, `NAME = "linear"` or `"nearest"` (`--sampler`; the key
    /// `sampler` is this table's own).
    pub(super) filter: Option<Val>,
    pub(super) sample_returns: Option<Val>,
    pub(super) normal: Option<Val>,
}
