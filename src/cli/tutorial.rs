//! The tutorial subcommands: `discrete` (part 1), `pdf-convert` (part 2) and `sample`
//! (part 3), each one evaluation of the f64 reference, printed as a table or as one JSON
//! object (`--json`).

use super::{
    IncidentArgs, LobeArgs, NumberList, OutputArgs, emit, emit_json, parse_non_negative, parse_number_list,
    parse_polar_90, parse_unit_list, parse_unit_pair, usage,
};
use crate::engine::job::DiscreteMethod;
use crate::reference::discrete::{AliasTable, DiscreteSample, Distribution};
use crate::reference::{Invalid, reflect};
use crate::report::table;
use clap::builder::PossibleValue;
use clap::{Args, ValueEnum};
use glam::DVec3;
use serde::Serialize;

/// `--method` takes the library's [`DiscreteMethod`] by its names; clap stays inside `cli/`.
impl ValueEnum for DiscreteMethod {
    fn value_variants<'a>() -> &'a [Self] {
        &DiscreteMethod::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        let help = match self {
            DiscreteMethod::Cdf => "Binary search for the first CDF entry ≥ u (the tutorial's rule)",
            DiscreteMethod::Alias => "Walker's alias table (Vose's construction), one uniform per draw",
        };
        Some(PossibleValue::new(self.name()).help(help))
    }
}

/// Arguments of `lobes discrete`.
#[derive(Debug, Clone, Args)]
pub struct DiscreteArgs {
    /// Comma-separated weights, finite and ≥ 0, not all zero, e.g. 15,5,5,25,5,10,15,5,5,10.
    #[arg(long, value_name = "W1,W2,...", value_parser = parse_number_list, allow_hyphen_values = true)]
    pub weights: NumberList,
    /// Comma-separated uniforms in [0, 1], one draw each, e.g. 0.5,0.25,0.9,0.65.
    #[arg(long, value_name = "U1,U2,...", value_parser = parse_unit_list, allow_hyphen_values = true)]
    pub u: NumberList,
    /// Sampling method.
    #[arg(long, value_enum, default_value = "cdf")]
    pub method: DiscreteMethod,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// One draw of `discrete`.
#[derive(Debug, Clone, Serialize)]
pub struct DiscreteDraw {
    /// The uniform used.
    pub u: f64,
    /// The 0-based index selected.
    pub index: usize,
    /// The weight at that index.
    pub value: f64,
    /// pmf at that index.
    pub probability: f64,
    /// CDF at that index.
    pub cdf: f64,
}

/// What `discrete` reports.
#[derive(Debug, Clone, Serialize)]
pub struct DiscreteReport {
    /// The weights as given.
    pub weights: Vec<f64>,
    /// pmf_i = w_i / Σw.
    pub pmf: Vec<f64>,
    /// CDF_i = Σ_{j≤i} w_j / Σw.
    pub cdf: Vec<f64>,
    /// The method used.
    pub method: DiscreteMethod,
    /// One draw per uniform, in order.
    pub samples: Vec<DiscreteDraw>,
}

/// Computes the `discrete` report; bad weights are a [`super::UsageError`] naming `--weights`.
pub fn discrete_report(args: &DiscreteArgs) -> anyhow::Result<DiscreteReport> {
    let dist = Distribution::new(&args.weights.0).map_err(|e| usage(format!("--weights: {e}")))?;
    let draw: Box<dyn Fn(f64) -> DiscreteSample> = match args.method {
        DiscreteMethod::Cdf => Box::new(|u| dist.sample_cdf(u)),
        DiscreteMethod::Alias => {
            let table = AliasTable::new(&dist);
            Box::new(move |u| table.sample_one(u))
        }
    };
    let samples = args
        .u
        .0
        .iter()
        .map(|&u| {
            let s = draw(u);
            DiscreteDraw {
                u,
                index: s.index,
                value: dist.weights()[s.index],
                probability: s.probability,
                cdf: dist.cdf()[s.index],
            }
        })
        .collect();
    Ok(DiscreteReport {
        weights: dist.weights().to_vec(),
        pmf: dist.pmf().to_vec(),
        cdf: dist.cdf().to_vec(),
        method: args.method,
        samples,
    })
}

/// `lobes discrete`: tutorial part 1.
pub fn discrete(args: &DiscreteArgs) -> anyhow::Result<()> {
    let r = discrete_report(args)?;
    if args.output.json {
        return emit_json(&r);
    }
    let mut t = format!("distribution ({} entries)\n", r.weights.len());
    t += &table::render(
        &["index", "weight", "pmf", "cdf"],
        r.weights.iter().zip(&r.pmf).zip(&r.cdf).enumerate().map(|(i, ((w, p), c))| {
            vec![i.to_string(), w.to_string(), format!("{p:.6}"), format!("{c:.6}")]
        }),
    );
    let method = match r.method {
        DiscreteMethod::Cdf => "cdf (first CDF entry ≥ u)",
        DiscreteMethod::Alias => "alias (Walker/Vose, one uniform)",
    };
    t += &format!("\ndraws, method {method}\n");
    t += &table::render(
        &["u", "index", "value", "probability", "cdf"],
        r.samples.iter().map(|s| {
            vec![s.u.to_string(), s.index.to_string(), s.value.to_string(), format!("{:.6}", s.probability), format!("{:.6}", s.cdf)]
        }),
    );
    emit(&t)
}

/// Arguments of `lobes pdf-convert`: ωi, h and the normal in one plane, ωi and h on the same
/// side of the normal, so ωi·h = cos(θi − θh).
#[derive(Debug, Clone, Args)]
pub struct PdfConvertArgs {
    /// The half-vector density p(ωh), per unit solid angle: a finite number ≥ 0.
    #[arg(long, value_name = "P", value_parser = parse_non_negative, allow_hyphen_values = true)]
    pub pdf_h: f64,
    /// θh = arccos(n·h) in degrees, in [0, 90].
    #[arg(long, value_name = "DEG", value_parser = parse_polar_90, allow_hyphen_values = true)]
    pub theta_h: f64,
    /// θi = arccos(n·ωi) in degrees, in [0, 90].
    #[arg(long, value_name = "DEG", value_parser = parse_polar_90, allow_hyphen_values = true)]
    pub theta_i: f64,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// What `pdf-convert` reports.
#[derive(Debug, Clone, Serialize)]
pub struct PdfConvertReport {
    /// p(ωh) as given.
    pub pdf_h: f64,
    /// θh in degrees, as given.
    pub theta_h_deg: f64,
    /// θi in degrees, as given.
    pub theta_i_deg: f64,
    /// ωi = (sin θi, 0, cos θi).
    pub omega_i: [f64; 3],
    /// h = (sin θh, 0, cos θh).
    pub h: [f64; 3],
    /// ωr = 2(ωi·h)h − ωi.
    pub omega_r: [f64; 3],
    /// ωi·h = cos(θi − θh).
    pub cos_ih: f64,
    /// dωh/dωr = 1 / (4 |ωr·h|).
    pub jacobian: f64,
    /// p(ωr) = p(ωh) · dωh/dωr.
    pub pdf_r: f64,
    /// Whether ωr is a usable reflected direction.
    pub valid: bool,
    /// Why not, if not.
    pub invalid_reason: Option<Invalid>,
}

/// Computes the `pdf-convert` report.
pub fn pdf_convert_report(args: &PdfConvertArgs) -> PdfConvertReport {
    let wi = reflect::spherical(args.theta_i.to_radians(), 0.0);
    let h = reflect::spherical(args.theta_h.to_radians(), 0.0);
    let wr = reflect::reflect(wi, h);
    let pdf_r = reflect::pdf_reflected(args.pdf_h, wr, h);
    let invalid = Invalid::check(wr, pdf_r);
    PdfConvertReport {
        pdf_h: args.pdf_h,
        theta_h_deg: args.theta_h,
        theta_i_deg: args.theta_i,
        omega_i: wi.to_array(),
        h: h.to_array(),
        omega_r: wr.to_array(),
        cos_ih: wi.dot(h),
        jacobian: reflect::jacobian(wr, h),
        pdf_r,
        valid: invalid.is_none(),
        invalid_reason: invalid,
    }
}

/// `lobes pdf-convert`: tutorial part 2.
pub fn pdf_convert(args: &PdfConvertArgs) -> anyhow::Result<()> {
    let r = pdf_convert_report(args);
    if args.output.json {
        return emit_json(&r);
    }
    let t = table::render(
        &[],
        [
            ["p(ωh)".into(), r.pdf_h.to_string()],
            ["θh, θi".into(), format!("{}°, {}° (in plane, same side)", r.theta_h_deg, r.theta_i_deg)],
            ["ωi".into(), vec3(r.omega_i)],
            ["h".into(), vec3(r.h)],
            ["ωr = 2(ωi·h)h − ωi".into(), vec3(r.omega_r)],
            ["ωi·h".into(), format!("{:.6}", r.cos_ih)],
            ["dωh/dωr = 1/(4|ωr·h|)".into(), format!("{:.6}", r.jacobian)],
            ["p(ωr)".into(), format!("{:.6}", r.pdf_r)],
            ["valid".into(), validity(r.invalid_reason)],
        ]
        .map(Vec::from),
    );
    emit(&t)
}

/// Arguments of `lobes sample`.
#[derive(Debug, Clone, Args)]
pub struct SampleArgs {
    #[command(flatten)]
    pub lobe: LobeArgs,
    /// The two uniforms U1,U2, each in [0, 1].
    #[arg(long, value_name = "U1,U2", value_parser = parse_unit_pair, allow_hyphen_values = true)]
    pub u: [f64; 2],
    #[command(flatten)]
    pub incident: IncidentArgs,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// What `sample` reports.
#[derive(Debug, Clone, Serialize)]
pub struct SampleReport {
    /// The lobe's name.
    pub lobe: &'static str,
    /// The sampling method's name.
    pub method: &'static str,
    /// Roughness along x.
    pub alpha_x: f64,
    /// Roughness along y.
    pub alpha_y: f64,
    /// The uniforms used.
    pub u: [f64; 2],
    /// The incident direction ωi.
    pub omega_i: [f64; 3],
    /// θh = arccos(h.z) in degrees.
    pub theta_h_deg: f64,
    /// φh = atan2(h.y, h.x) in degrees, in [0, 360).
    pub phi_h_deg: f64,
    /// The half vector.
    pub h: [f64; 3],
    /// The reflected direction ωr = 2(ωi·h)h − ωi.
    pub omega_r: [f64; 3],
    /// The density of h, per unit solid angle.
    pub pdf_h: f64,
    /// The density of ωr, per unit solid angle.
    pub pdf_r: f64,
    /// Whether the sample is usable.
    pub valid: bool,
    /// Why not, if not.
    pub invalid_reason: Option<Invalid>,
}

/// Computes the `sample` report; an unsupported lobe/method pair is a [`super::UsageError`].
pub fn sample_report(args: &SampleArgs) -> anyhow::Result<SampleReport> {
    let lobe = args.lobe.lobe()?;
    let wi = args.incident.omega_i();
    let s = lobe.sample(wi, args.u);
    Ok(SampleReport {
        lobe: lobe.kind.name(),
        method: lobe.method.name(),
        alpha_x: lobe.alpha_x,
        alpha_y: lobe.alpha_y,
        u: args.u,
        omega_i: wi.to_array(),
        theta_h_deg: s.h.z.clamp(-1.0, 1.0).acos().to_degrees(),
        phi_h_deg: azimuth_deg(s.h),
        h: s.h.to_array(),
        omega_r: s.omega_r.to_array(),
        pdf_h: s.pdf_h,
        pdf_r: s.pdf_r,
        valid: s.invalid.is_none(),
        invalid_reason: s.invalid,
    })
}

/// `lobes sample`: tutorial part 3 (and every other lobe/method).
pub fn sample(args: &SampleArgs) -> anyhow::Result<()> {
    let r = sample_report(args)?;
    if args.output.json {
        return emit_json(&r);
    }
    let i = &args.incident;
    let t = table::render(
        &[],
        [
            ["lobe".into(), format!("{} ({}), αx = {}, αy = {}", r.lobe, r.method, r.alpha_x, r.alpha_y)],
            ["u".into(), format!("{}, {}", r.u[0], r.u[1])],
            ["ωi".into(), format!("{}  (θ {}°, φ {}°)", vec3(r.omega_i), i.incident_theta, i.incident_phi)],
            ["θh, φh".into(), format!("{:.6}°, {:.6}°", r.theta_h_deg, r.phi_h_deg)],
            ["h".into(), vec3(r.h)],
            ["ωr".into(), vec3(r.omega_r)],
            ["p(h)".into(), format!("{:.6}", r.pdf_h)],
            ["p(ωr)".into(), format!("{:.6}", r.pdf_r)],
            ["valid".into(), validity(r.invalid_reason)],
        ]
        .map(Vec::<String>::from),
    );
    emit(&t)
}

/// atan2(h.y, h.x) in degrees, in [0, 360) (NaN stays NaN).
fn azimuth_deg(h: DVec3) -> f64 {
    let phi = h.y.atan2(h.x).to_degrees().rem_euclid(360.0);
    // rem_euclid of a tiny negative angle rounds to exactly 360
    if phi >= 360.0 { 0.0 } else { phi }
}

fn vec3(v: [f64; 3]) -> String {
    format!("({:.6}, {:.6}, {:.6})", v[0], v[1], v[2])
}

fn validity(invalid: Option<Invalid>) -> String {
    match invalid {
        None => "yes".into(),
        Some(i) => format!("no ({})", i.name()),
    }
}
