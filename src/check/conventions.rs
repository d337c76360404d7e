//! The conventions a sampler is written in, declared instead of written as guards: where its
//! incident light may come from, whether it only reflects, whether its uniforms reach 1, the
//! measure of its pdf and the axis of its normal (`--incident`, `--reflection-only`, `--u-open`,
//! `--measure`, `--frame`; the same keys in a scene's `sampler = { ... }`).
//!
//! lobes' checks work in one frame (normal +z) and per solid angle. The WGSL half of this layer
//! (`shaders/check/conventions.wgsl`) sits between the user's functions, as the generated
//! contract wrappers `lobes_contract_sample/pdf/eval` call them, and the passes' `lobes_user_*`:
//! it turns directions into the user's frame and back, converts a pdf per projected solid angle
//! into one per solid angle, and turns a reflection-only sampler's samples under the horizon into
//! rejections. The host half here keeps the hard cases, the incident directions and the grid of
//! u values within what the sampler is declared for.

use super::{CheckError, Setting};
use serde::{Deserialize, Serialize};

/// Where the incident light of the sampler may come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Incident {
    /// Anywhere on the sphere (transmission, phase functions): the default.
    #[default]
    Sphere,
    /// Only above the surface (θi < 90°), as most renderers' BRDF samplers.
    Upper,
}

/// The measure the sampler's pdf (and eval) is per.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, schemars::JsonSchema)]
pub enum Measure {
    /// Per solid angle dσ: the default.
    #[default]
    #[serde(rename = "solid-angle")]
    SolidAngle,
    /// Per projected solid angle |cos θ| dσ (some SSGI code): the pdf is that of d per
    /// |d·n| dσ and eval is f itself (without the cosine); lobes multiplies both by |d·n|.
    #[serde(rename = "projected")]
    Projected,
    /// The sample is a point of a light per unit area (`--measure area`, with the light's normal
    /// `--normal`): the sample returns (p, pdf_A), p the point on the light relative to the
    /// shading point; lobes takes d = p/|p| and pdf_ω = pdf_A |p|² / |n·d| (the area-to-solid-
    /// angle Jacobian, pbrt-v4 §4.2.3 eq. 4.9). The pdf and eval functions stay per solid angle.
    #[serde(rename = "area")]
    Area,
}

/// The axis of the normal in the sampler's tangent frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, schemars::JsonSchema)]
pub enum Frame {
    /// Normal along +z: lobes' own frame, the default.
    #[default]
    #[serde(rename = "z-up")]
    ZUp,
    /// Normal along +y (GLSL path tracers): the user's (x, y, z) is lobes' (x, z, y).
    #[serde(rename = "y-up")]
    YUp,
}

/// The conventions of a sampler; the default is lobes' contract: any incidence, u in [0, 1],
/// per solid angle, normal +z.
///
/// ```
/// use lobes::check::{Conventions, Incident};
/// // Bevy's bounded VNDF: defined for light above the surface, samples under the horizon invalid
/// let bevy = Conventions { reflection_only: true, ..Conventions::default() };
/// assert_eq!(bevy.incident(), Incident::Upper);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Conventions {
    /// `--incident upper`: hard cases, incident angles and sweeps stay above the horizon.
    pub incident: Incident,
    /// `--reflection-only`: `--incident upper`, and any d with d·n ≤ 0 is a rejection whatever
    /// pdf the sampler reports, the pdf (and eval) taken as 0 there.
    pub reflection_only: bool,
    /// `--u-open`: the sampler's uniforms are in [0, 1): the hard cases never feed exactly 1.
    pub u_open: bool,
    /// `--measure projected`: the pdf is per projected solid angle.
    pub measure: Measure,
    /// `--frame y-up`: the normal is +y.
    pub frame: Frame,
}

/// Each convention's names, as flags and scene keys write them (`--measure projected`), from one
/// list per type.
macro_rules! named {
    ($ty:ident { $($variant:ident = $name:literal),* }) => {
        impl $ty {
            pub const NAMES: &'static [&'static str] = &[$($name),*];
            pub fn name(&self) -> &'static str {
                match self {
                    $($ty::$variant => $name,)*
                }
            }
        }
        impl std::str::FromStr for $ty {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                match s {
                    $($name => Ok($ty::$variant),)*
                    other => Err(format!("'{other}' is not one of {}", $ty::NAMES.join(", "))),
                }
            }
        }
    };
}
named!(Incident { Sphere = "sphere", Upper = "upper" });
named!(Measure { SolidAngle = "solid-angle", Projected = "projected", Area = "area" });
named!(Frame { ZUp = "z-up", YUp = "y-up" });

impl Conventions {
    /// Where incident light may come from: `Upper` when declared so or reflection-only.
    pub fn incident(&self) -> Incident {
        if self.reflection_only { Incident::Upper } else { self.incident }
    }

    /// Whether every convention is lobes' own.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Conventions that mean nothing for the plane's points, which have no normal: all but
    /// `u_open` apply to directions.
    pub fn validate(&self, domain: super::Domain) -> Result<(), CheckError> {
        let directional = [
            (Setting::Incident, self.incident == Incident::Upper),
            (Setting::ReflectionOnly, self.reflection_only),
            (Setting::Measure, self.measure != Measure::SolidAngle),
            (Setting::Frame, self.frame == Frame::YUp),
        ];
        match directional.iter().find(|(_, set)| !domain.directions() && *set) {
            Some(&(setting, _)) => Err(CheckError::setting(setting, "only for directions (a point of the plane has no normal); remove it")),
            None => Ok(()),
        }
    }

    /// An incident θ in degrees (from the normal of the user's frame) that the sampler is declared
    /// for: below 90° when it takes light from above only.
    pub fn check_incident(&self, theta: f64) -> Result<(), CheckError> {
        if self.incident() == Incident::Upper && theta >= 90.0 {
            let why = if self.reflection_only { "reflection-only" } else { "for upper incidence" };
            let message = format!("{theta}° is not above the surface, and the sampler is declared {why} (θ below 90°); give θ < 90 or drop that declaration");
            return Err(CheckError::setting(Setting::IncidentTheta, message));
        }
        Ok(())
    }

    /// The incident θ of the hard cases (on the sphere): [`super::hard::INCIDENT_THETA`], those
    /// below 90° with `--incident upper`.
    pub fn hard_thetas(&self) -> Vec<f64> {
        super::hard::INCIDENT_THETA.iter().copied().filter(|&t| self.incident() == Incident::Sphere || t < 90.0).collect()
    }

    /// The values each component of u takes in the hard cases: [`super::hard::U_VALUES`], without
    /// 1 with `--u-open`.
    pub fn hard_u_values(&self) -> Vec<f32> {
        super::hard::U_VALUES.iter().copied().filter(|&u| !(self.u_open && u == 1.0)).collect()
    }

    /// The user's frame's direction for one of lobes' (`lobes_frame` in WGSL): y and z swapped
    /// with the normal +y.
    pub fn to_user(&self, d: [f64; 3]) -> [f64; 3] {
        match self.frame {
            Frame::ZUp => d,
            Frame::YUp => [d[0], d[2], d[1]],
        }
    }

    /// The WGSL of the layer: its constants and `shaders/check/conventions.wgsl`, defining the
    /// passes' `lobes_user_sample/pdf/eval` over `lobes_contract_sample/pdf/eval`.
    pub fn wgsl(&self) -> String {
        format!(
            "// Generated by lobes check: the sampler's conventions (src/check/conventions.rs).\n\
             const LOBES_Y_UP: bool = {};\nconst LOBES_PROJECTED: bool = {};\nconst LOBES_REFLECTION_ONLY: bool = {};\n{}",
            self.frame == Frame::YUp,
            self.measure == Measure::Projected,
            self.reflection_only,
            include_str!("../../shaders/check/conventions.wgsl")
        )
    }

    /// The conventions declared, each by its setting and value as a report names them
    /// ("reflection-only, measure projected"; "" for the default).
    pub fn declared(&self) -> String {
        let set = [
            (self.incident == Incident::Upper && !self.reflection_only).then(|| format!("incident {}", self.incident.name())),
            self.reflection_only.then(|| "reflection-only".to_string()),
            self.u_open.then(|| "u-open".to_string()),
            (self.measure != Measure::SolidAngle).then(|| format!("measure {}", self.measure.name())),
            (self.frame == Frame::YUp).then(|| format!("frame {}", self.frame.name())),
        ];
        set.into_iter().flatten().collect::<Vec<_>>().join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hard cases keep above the horizon with `--incident upper` (and `--reflection-only`),
    /// and drop u = 1 with `--u-open`.
    #[test]
    fn hard_cases_follow_the_declared_domain() {
        let all = Conventions::default();
        assert_eq!(all.hard_thetas().len(), 7);
        assert_eq!(all.hard_u_values().len(), 5);
        for c in [Conventions { incident: Incident::Upper, ..all }, Conventions { reflection_only: true, ..all }] {
            assert_eq!(c.hard_thetas(), [0.0, 45.0, 89.9, 89.999]);
            assert!(c.check_incident(89.0).is_ok() && c.check_incident(90.0).is_err() && c.check_incident(135.0).is_err());
        }
        assert!(all.check_incident(135.0).is_ok());
        let open = Conventions { u_open: true, ..all };
        assert!(open.hard_u_values().iter().all(|&u| u < 1.0) && open.hard_u_values().len() == 4);
    }

    /// With the normal +y, θ is measured from +y: θ = 0 is the user's (0, 1, 0), lobes' (0, 0, 1),
    /// and θ = 90°, φ = 90° the user's +z.
    #[test]
    fn y_up_incident_directions() {
        let c = Conventions { frame: Frame::YUp, ..Conventions::default() };
        // lobes' incident direction at (θ, φ) read in the user's frame: the same spherical coordinates
        let user = |t, p| c.to_user(crate::check::incident(t, p).map(f64::from));
        let near = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6);
        assert!(near(user(0.0, 0.0), [0.0, 1.0, 0.0]));
        assert!(near(user(90.0, 90.0), [0.0, 0.0, 1.0]));
        assert!(near(user(90.0, 0.0), [1.0, 0.0, 0.0]));
        let s = 60f64.to_radians().sin();
        assert!(near(user(60.0, 0.0), [s, 0.5, 0.0]));
    }

    /// Conventions of directions on the plane are input errors naming the flag.
    #[test]
    fn directional_conventions_are_refused_on_the_plane() {
        let c = Conventions { measure: Measure::Projected, ..Conventions::default() };
        let plane = crate::stats::domain::Domain::UNIT_SQUARE;
        assert!(c.validate(crate::stats::domain::Domain::Sphere).is_ok());
        assert!(matches!(c.validate(plane), Err(CheckError::Setting { setting: Setting::Measure, .. })));
        let y_up = Conventions { frame: Frame::YUp, ..Conventions::default() };
        assert!(matches!(y_up.validate(plane), Err(CheckError::Setting { setting: Setting::Frame, .. })));
        assert!(Conventions { u_open: true, ..Conventions::default() }.validate(plane).is_ok());
    }
}
