//! The parts of lobes' output files that shard files ([`super::shard::ShardFile`]) and
//! `histogram.json` ([`crate::report::output::HistogramFile`]) share: what a case samples,
//! counts by invalid reason, and the histogram's timing. Writers and readers use the same
//! structs; `docs/schema/` holds their JSON Schema ([`crate::report::schema`]).

use crate::engine::job::{Job, Scatter};
use crate::scene::{Case, UserCase};
use crate::stats::domain::{Domain, Grid};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// What a case samples: `lobe`, `method`, `params`, and the histogram's `rows` × `cols`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct CaseDescription {
    /// A lobe's name as a scene names it (`ggx`, `ward`, …), `discrete`, or `user` for a user's
    /// WGSL sampler.
    pub lobe: String,
    /// A method's name as a scene names it (`vndf`, `ndf`, …), for a discrete case `cdf` or
    /// `alias`, for a user's sampler `wgsl`.
    pub method: String,
    pub params: Params,
    /// Rows over cos θ (1 for a discrete case, over y on the plane).
    pub rows: usize,
    /// Columns over φ (the items of a discrete case, over x on the plane).
    pub cols: usize,
}

/// A case's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
#[allow(clippy::large_enum_variant)] // one per case of a run: the user's variant's size costs nothing
pub enum Params {
    Lobe {
        alpha_x: f64,
        alpha_y: f64,
        /// Degrees from +x to the αx axis about the normal (rotated anisotropy; 0 in records
        /// written before it existed).
        #[serde(default)]
        alpha_angle: f64,
        incident_theta_deg: f64,
        incident_phi_deg: f64,
        /// A rough dielectric's η (`scatter = "dielectric"`); absent for a reflection.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        eta: Option<f64>,
    },
    Discrete { weights: Vec<f64> },
    /// A user's WGSL sampler ([`crate::check`]).
    User {
        /// The WGSL files, in order, as the scene resolves them.
        wgsl: Vec<String>,
        sample: String,
        pdf: String,
        eval: Option<String>,
        /// The numbers passed as `params` (before zero-padding).
        params: Vec<f64>,
        /// `sphere`, `plane` or `cap` (a cap fitted to the samples, `lobes::check::support`).
        domain: String,
        /// The plane's box `[x0, y0, x1, y1]` (null elsewhere).
        bounds: Option<[f64; 4]>,
        /// A fitted cap's unit axis and height 1 − cos ρ: rows uniform in 1 − cos θ′ over [0,
        /// height], columns in φ′ ∈ [−π, π) about the axis (null elsewhere).
        cap_axis: Option<[f64; 3]>,
        cap_height: Option<f64>,
        /// The incident direction (null on the plane, where there is none).
        incident_theta_deg: Option<f64>,
        incident_phi_deg: Option<f64>,
    },
}

/// What a case samples, as its records describe it: a lobe's case, or a user's sampler with the
/// grid its samples were binned on (its domain's, or a cap fitted to them).
#[derive(Debug, Clone, Copy)]
pub enum Subject<'a> {
    Lobe(&'a Case),
    User(&'a UserCase, Grid),
}

impl CaseDescription {
    /// The description of a case: a lobe's from its job, a user's sampler's from its settings
    /// and the grid it was binned on.
    pub fn of(subject: Subject<'_>) -> Self {
        match subject {
            Subject::User(case, grid) => {
                let (rows, cols) = (grid.rows as usize, grid.cols as usize);
                CaseDescription { lobe: "user".into(), method: "wgsl".into(), params: Params::user(case, &grid.domain), rows, cols }
            }
            Subject::Lobe(case) => Self::of_job(case),
        }
    }

    /// A lobe's or a discrete distribution's case, from its job.
    fn of_job(case: &Case) -> Self {
        match &case.job {
            Job::Lobe { lobe, grid, scatter, .. } => CaseDescription {
                lobe: lobe.kind.name().into(),
                method: lobe.method.name().into(),
                params: Params::Lobe {
                    alpha_x: lobe.alpha_x,
                    alpha_y: lobe.alpha_y,
                    alpha_angle: lobe.alpha_angle,
                    incident_theta_deg: case.incident_deg.0,
                    incident_phi_deg: case.incident_deg.1,
                    eta: match scatter {
                        Scatter::Reflect => None,
                        Scatter::Dielectric { eta } => Some(*eta),
                    },
                },
                rows: grid.rows as usize,
                cols: grid.cols as usize,
            },
            Job::Discrete { dist, method } => CaseDescription {
                lobe: "discrete".into(),
                method: format!("{method:?}").to_lowercase(),
                params: Params::Discrete { weights: dist.weights().to_vec() },
                rows: 1,
                cols: dist.len(),
            },
        }
    }
}

impl Params {
    /// The parameters of a user's sampler case binned on `domain`.
    fn user(case: &UserCase, domain: &Domain) -> Self {
        let (s, set) = (&case.sampler, &case.settings);
        let sphere = domain.directions();
        let (cap_axis, cap_height) = domain.as_cap().unzip();
        Params::User {
            wgsl: s.sources.iter().map(|f| f.name.clone()).collect(),
            sample: s.sample.clone(),
            pdf: s.pdf.clone(),
            eval: s.eval.clone(),
            params: set.params.clone(),
            domain: domain.name().into(),
            bounds: domain.bounds(),
            cap_axis,
            cap_height,
            incident_theta_deg: sphere.then_some(set.incident_theta),
            incident_phi_deg: sphere.then_some(set.incident_phi),
        }
    }
}

/// The histogram pass's time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Timing {
    /// From GPU timestamp queries; null where the adapter has none (and on the CPU engine).
    pub gpu_seconds: Option<f64>,
    pub histogram_wall_seconds: f64,
}

/// The weighted pass's time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WeightedTiming {
    pub gpu_seconds: Option<f64>,
    pub wall_seconds: f64,
}
