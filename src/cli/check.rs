//! `lobes check`: judge a user's WGSL sampler (see [`crate::check`]).

use super::{NumberList, OutputArgs, emit, emit_json, parse_azimuth, parse_number_list, parse_polar_180, usage};
use crate::report::table;
use crate::check::{self, CheckError, Domain, Settings, UserSampler};
use crate::engine::gpu::Gpu;
use clap::{Args, ValueEnum};
use std::path::PathBuf;

/// Where the user's sampler puts its points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DomainChoice {
    /// Unit directions anywhere on the sphere.
    Sphere,
    /// Points (d.x, d.y) of the box given by --bounds.
    Plane,
}

/// What a sample expression returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ReturnsChoice {
    /// The direction d (vec3), or (d, pdf) (vec4).
    Direction,
    /// A half vector h (vec3), or (h, pdf of h) (vec4).
    HalfVector,
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The WGSL files that define the sampler, in order.
    #[arg(required = true, value_name = "FILE.wgsl")]
    pub files: Vec<PathBuf>,
    /// The sampling function: fn(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32>,
    /// or a WGSL call expression over wi, u, params, p0 … p15 and rng returning vec4 (d, pdf) or
    /// vec3 (d), e.g. 'sample_ggx_vndf(wi, p0, rng)'.
    #[arg(long, value_name = "NAME|EXPR")]
    pub sample: String,
    /// The density: fn(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32, or a call
    /// expression over wi, d, params, p0 … p15 and rng, e.g. 'ggx_vndf_pdf(wi, d, p0)'.
    #[arg(long, value_name = "NAME|EXPR")]
    pub pdf: String,
    /// Optional f·|cos| (or the phase function), same forms as --pdf: adds the weight and
    /// albedo checks.
    #[arg(long, value_name = "NAME|EXPR")]
    pub eval: Option<String>,
    /// Where imported modules are found (repeatable): naga_oil's #import paths or WESL's
    /// package root. Default: the first file's folder.
    #[arg(long = "shader-root", value_name = "DIR")]
    pub shader_root: Vec<PathBuf>,
    /// A shader def (repeatable): naga_oil's #ifdef/#if (VALUE true, false or an integer), WESL's
    /// @if features (true or false). No value: true.
    #[arg(long, value_name = "NAME[=VALUE]")]
    pub define: Vec<String>,
    /// A stand-in for a module the test does not need (repeatable): bind groups, scene bindings,
    /// ray queries. MODULE as the imports name it (a::b, package::a::b).
    #[arg(long, value_name = "MODULE=FILE")]
    pub stub: Vec<String>,
    /// The sampler's random function (repeatable): its body becomes lobes' queue of u.x, u.y, u.z,
    /// u.w in call order (vec2/3/4 results take 2/3/4); at most four draws per sample.
    #[arg(long, value_name = "NAME")]
    pub rand: Vec<String>,
    /// Which --rand draw is which, in call order: x, y (smooth coordinates) and event (a draw
    /// that chooses a lobe), e.g. event,x,y. Default: found by lobes' probe.
    #[arg(long, value_name = "ORDER")]
    pub rand_order: Option<String>,
    /// What the sample expression returns: the direction d, or a half vector h that lobes
    /// reflects wi about (dividing a returned pdf of h by 4 |wi·h|).
    #[arg(long, value_enum, default_value = "direction")]
    pub sample_returns: ReturnsChoice,
    #[arg(long, value_enum, default_value = "sphere")]
    pub domain: DomainChoice,
    /// The plane's box, X0,Y0,X1,Y1 (with --domain plane).
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_number_list, allow_hyphen_values = true)]
    pub bounds: Option<NumberList>,
    /// Up to 16 numbers passed to every function as `params` (zero-padded).
    #[arg(long, value_name = "P1,P2,...", value_parser = parse_number_list, allow_hyphen_values = true)]
    pub params: Option<NumberList>,
    /// Incident θ in degrees from the normal (+z), [0, 180]; θ > 90 comes from below.
    #[arg(long, value_name = "DEG", value_parser = parse_polar_180, default_value = "30")]
    pub incident_theta: f64,
    /// Incident φ in degrees from +x.
    #[arg(long, value_name = "DEG", value_parser = parse_azimuth, allow_hyphen_values = true, default_value = "0")]
    pub incident_phi: f64,
    /// Samples drawn for the histogram (and the weights).
    #[arg(long, value_name = "N", default_value_t = 1 << 22)]
    pub samples: u64,
    /// Histogram ROWS,COLS (default 64,128 on the sphere, 64,64 on the plane).
    #[arg(long, value_name = "ROWS,COLS", value_parser = parse_number_list)]
    pub bins: Option<NumberList>,
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,
    /// Significance of the χ² and albedo tests.
    #[arg(long, value_name = "A", default_value_t = 0.01)]
    pub significance: f64,
    /// Run the whole check at 2^16, 2^18, … samples up to --samples and print the χ² p-value and
    /// time at each, and from which count (after how much GPU time) an error is caught; exit 1
    /// when some count fails.
    #[arg(long)]
    pub power: bool,
    /// Write report.json, heat maps of the histogram (measured.png, expected.png, residual.png)
    /// and the composed WGSL to this folder (power.json with --power).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub output: OutputArgs,
}

fn input(e: CheckError) -> anyhow::Error {
    if e.is_input() { usage(e.to_string()) } else { e.into() }
}

impl CheckArgs {
    fn sampler(&self) -> anyhow::Result<UserSampler> {
        let domain = match (self.domain, &self.bounds) {
            (DomainChoice::Sphere, None) => Domain::Sphere,
            (DomainChoice::Sphere, Some(_)) => return Err(usage("--bounds: only with --domain plane")),
            (DomainChoice::Plane, None) => return Err(usage("--domain plane needs --bounds X0,Y0,X1,Y1")),
            (DomainChoice::Plane, Some(b)) => match b.0[..] {
                [x0, y0, x1, y1] => Domain::Plane { bounds: [x0, y0, x1, y1] },
                _ => return Err(usage(format!("--bounds: expected 4 numbers X0,Y0,X1,Y1, got {}", b.0.len()))),
            },
        };
        let composition = check::Composition::from_flags(
            &self.shader_root,
            &self.define,
            &self.stub,
            &self.rand,
            self.rand_order.as_deref(),
            match self.sample_returns {
                ReturnsChoice::Direction => check::SampleReturns::Direction,
                ReturnsChoice::HalfVector => check::SampleReturns::HalfVector,
            },
        )
        .map_err(usage)?;
        UserSampler::from_repository(&self.files, &self.sample, &self.pdf, self.eval.as_deref(), domain, composition).map_err(input)
    }

    fn settings(&self) -> anyhow::Result<Settings> {
        let bins = match &self.bins {
            None => None,
            // the grid's limits are Settings::validate's
            Some(b) => match b.0[..] {
                [r, c] if [r, c].iter().all(|v| v.fract() == 0.0 && (0.0..=u32::MAX as f64).contains(v)) => Some((r as u32, c as u32)),
                _ => return Err(usage("--bins: expected ROWS,COLS, two whole numbers, e.g. 64,128")),
            },
        };
        Ok(Settings {
            params: self.params.as_ref().map(|p| p.0.clone()).unwrap_or_default(),
            incident_theta: self.incident_theta,
            incident_phi: self.incident_phi,
            samples: self.samples,
            bins,
            seed: self.seed,
            significance: self.significance,
            ..Settings::default()
        })
    }
}

pub fn run(args: &CheckArgs) -> anyhow::Result<()> {
    let sampler = args.sampler()?;
    let settings = args.settings()?;
    settings.validate().map_err(input)?;
    if let Some(dir) = &args.out {
        super::prepare_out(dir)?;
    }
    let gpu = Gpu::new()?;
    if args.power {
        return power(&gpu, &sampler, &settings, args);
    }
    let report = check::check(&gpu, &sampler, &settings).map_err(input)?;
    if let Some(dir) = &args.out {
        crate::report::check::write(dir, &report, &sampler.composed().map_err(input)?)?;
    }
    if args.output.json {
        emit_json(&report)?;
    } else {
        let mut t = format!("{} on {} ({} samples, {}×{} bins)\n", report.sampler, report.adapter, report.samples, report.rows, report.cols);
        t += &table::render(&["check", "result", "summary"], report.checks.iter().map(|c| vec![c.name(), verdict(c.passed), &c.summary]));
        t += if report.passed { "passed\n" } else { "FAILED\n" };
        emit(&t)?;
    }
    if !report.passed {
        return Err(super::ChecksFailed(format!("{} failed: {}", report.sampler, report.failed().join(", "))).into());
    }
    Ok(())
}

fn verdict(passed: bool) -> &'static str {
    if passed { "ok" } else { "FAIL" }
}

/// `--power`: exits 0 when every check passes at every count, 1 when some count fails.
fn power(gpu: &Gpu, sampler: &UserSampler, settings: &Settings, args: &CheckArgs) -> anyhow::Result<()> {
    let sweep = check::power::power(gpu, sampler, settings).map_err(input)?;
    if let Some(dir) = &args.out {
        crate::report::check::write_power(dir, &sweep)?;
    }
    if args.output.json {
        emit_json(&sweep)?;
    } else {
        let seconds = |s: Option<f64>| s.map_or("-".to_string(), |s| format!("{s:.3}"));
        let mut t = format!("{}\n", sweep.sampler);
        t += &table::render(
            &["samples", "chi2 p", "chi2", "normalization", "all", "GPU s", "wall s"],
            sweep.points.iter().map(|p| {
                vec![
                    p.samples.to_string(),
                    format!("{:.3e}", p.p_value),
                    verdict(p.chi2_passed).into(),
                    verdict(p.normalization_passed).into(),
                    verdict(p.passed).into(),
                    seconds(p.gpu_seconds),
                    format!("{:.2}", p.seconds),
                ]
            }),
        );
        t += &sweep.verdict();
        t.push('\n');
        emit(&t)?;
    }
    if !sweep.passed {
        return Err(super::ChecksFailed(format!("{}: {}", sweep.sampler, sweep.verdict())).into());
    }
    Ok(())
}
