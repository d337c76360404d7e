//! A case that ran, as the per-case outputs see it: a lobe's ([`CaseResult`], `lobes run` and
//! `lobes merge`) or a user's WGSL sampler's ([`UserResult`], a `sampler` case of `lobes run`).
//! Each output has one builder over an [`Outcome`] ([`super::output::HistogramFile::of`],
//! [`super::output::TimingFile::of`], [`super::output::CaseSummary::of`] with
//! [`super::output::AlbedoSummary::of`],
//! [`super::output::table_row`], [`super::output::write_case`]): what both kinds have comes
//! through the methods here, the sections only one kind has through [`Outcome::lobe`] and
//! [`Outcome::user`].

use super::compare::Bins;
use crate::engine::job::Job;
use crate::run::CaseResult;
use crate::run::record::Subject;
use crate::run::user::UserResult;
use crate::stats::chi2::Chi2;
use crate::stats::domain::Domain;
use crate::stats::histogram::SphereGrid;

/// A case that ran.
#[derive(Debug, Clone, Copy)]
pub enum Outcome<'a> {
    Lobe(&'a CaseResult),
    User(&'a UserResult),
}

impl<'a> Outcome<'a> {
    /// A lobe's case (None for a user's sampler).
    pub fn lobe(self) -> Option<&'a CaseResult> {
        match self {
            Outcome::Lobe(r) => Some(r),
            Outcome::User(_) => None,
        }
    }

    /// A user's sampler case (None for a lobe's).
    pub fn user(self) -> Option<&'a UserResult> {
        match self {
            Outcome::Lobe(_) => None,
            Outcome::User(r) => Some(r),
        }
    }

    pub fn name(self) -> &'a str {
        match self {
            Outcome::Lobe(r) => &r.case.name,
            Outcome::User(r) => &r.case.name,
        }
    }

    /// The samples drawn (for a user's `budget`, the count it picked).
    pub fn samples(self) -> u64 {
        match self {
            Outcome::Lobe(r) => r.case.samples,
            Outcome::User(r) => r.case.settings.samples,
        }
    }

    pub fn seed(self) -> u64 {
        match self {
            Outcome::Lobe(r) => r.case.seed,
            Outcome::User(r) => r.case.settings.seed,
        }
    }

    /// What the case samples, for its [`crate::run::record::CaseDescription`].
    pub fn subject(self) -> Subject<'a> {
        match self {
            Outcome::Lobe(r) => Subject::Lobe(&r.case),
            Outcome::User(r) => Subject::User(&r.case, r.report.grid()),
        }
    }

    /// Invalid samples per reason, in the order of [`crate::reference::Invalid::ALL`].
    pub fn invalid(self) -> [u64; crate::reference::Invalid::COUNT] {
        match self {
            Outcome::Lobe(r) => r.counts.invalid,
            Outcome::User(r) => r.report.invalid,
        }
    }

    /// Counts and expected counts per bin, row-major.
    pub fn counts(self) -> &'a [u64] {
        match self {
            Outcome::Lobe(r) => &r.counts.bins,
            Outcome::User(r) => &r.report.counts,
        }
    }

    pub fn expected(self) -> &'a [f64] {
        match self {
            Outcome::Lobe(r) => &r.expected.bins,
            Outcome::User(r) => &r.report.expected,
        }
    }

    pub fn chi2(self) -> &'a Chi2 {
        match self {
            Outcome::Lobe(r) => &r.chi2,
            Outcome::User(r) => &r.chi2,
        }
    }

    /// The case's verdict: χ² and, where weighted, the albedo checks; for a user's sampler,
    /// every check of `lobes check`.
    pub fn passed(self) -> bool {
        match self {
            Outcome::Lobe(r) => r.passed(),
            Outcome::User(r) => r.passed(),
        }
    }

    /// ωi as a unit vector, where the case samples directions (not a discrete case, nor a
    /// user's sampler on the plane).
    pub fn incident(self) -> Option<[f64; 3]> {
        match self {
            Outcome::Lobe(r) => match &r.case.job {
                Job::Lobe { incident, .. } => Some(incident.to_array()),
                Job::Discrete { .. } => None,
            },
            Outcome::User(r) => {
                let s = &r.case.settings;
                let wi = crate::reference::reflect::spherical(s.incident_theta.to_radians(), s.incident_phi.to_radians());
                r.report.domain.directions().then(|| wi.to_array())
            }
        }
    }

    /// The grid over the whole sphere the case was binned on, if it was (a fitted cap's edges
    /// are in its description).
    pub fn sphere_grid(self) -> Option<SphereGrid> {
        match self {
            Outcome::Lobe(r) => match &r.case.job {
                Job::Lobe { grid, .. } => Some(*grid),
                Job::Discrete { .. } => None,
            },
            Outcome::User(r) => r.report.domain.is_sphere().then_some(SphereGrid { rows: r.report.rows, cols: r.report.cols }),
        }
    }

    /// The bins of the heat maps.
    pub fn bins(self) -> Bins {
        match self {
            Outcome::Lobe(r) => match &r.case.job {
                Job::Lobe { grid, .. } => Bins::Grid(Domain::Sphere.grid(grid.rows, grid.cols)),
                Job::Discrete { dist, .. } => Bins::Items(dist.len()),
            },
            Outcome::User(r) => Bins::Grid(r.report.grid()),
        }
    }

    /// The time of the histogram pass from GPU timestamp queries (None where the adapter has
    /// none, on the CPU engine, and for a user's sampler).
    pub fn gpu_seconds(self) -> Option<f64> {
        self.lobe().and_then(|r| r.gpu_seconds)
    }

    /// The wall time of the histogram pass; for a user's sampler, of all its checks.
    pub fn wall_seconds(self) -> f64 {
        match self {
            Outcome::Lobe(r) => r.histogram_seconds,
            Outcome::User(r) => r.wall_seconds,
        }
    }

    /// The checks a user's sampler failed, by name (None for a lobe's case).
    pub fn failed_checks(self) -> Option<Vec<&'a str>> {
        self.user().map(UserResult::failed_checks)
    }
}
