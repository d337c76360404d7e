//! The `lobes` command line: argument definitions, input validation and dispatch.
//!
//! Each subcommand is a variant of [`Command`] whose arguments are a clap `Args` struct and
//! whose work is a function returning `anyhow::Result<()>`. [`exit_code`] maps its error to the
//! process's exit code ([`EXIT_CODES`], also in `lobes --help` and docs/errors.md):
//!
//! - a case or check that ran and failed its test: a [`ChecksFailed`], [`EXIT_CHECKS_FAILED`] = 1;
//! - bad input: a [`UsageError`] (or clap's own while parsing), [`EXIT_USAGE`] = 2;
//! - the tool could not do the work (no adapter, a lost device, an output not written, any
//!   other error): [`EXIT_TOOL_FAILURE`] = 3;
//! - stopped by SIGINT or SIGTERM: an [`Interrupted`], [`EXIT_INTERRUPTED`] = 130.
//!
//! Syntax and per-value checks (a malformed list, u outside [0, 1], α ≤ 0) run as clap value
//! parsers, so clap's message names the flag; checks that need the reference (weights, which
//! methods a lobe supports) run in the subcommand and produce a [`UsageError`] whose message
//! starts with the flag.

pub mod bench;
pub mod check;
pub mod interrupt;
pub mod merge;
pub mod run;
pub mod scene;
pub mod shader;
pub mod stress;
pub mod tradeoff;
pub mod tutorial;
pub mod wgsl;

use crate::reference::{LobeKind, Method};
use crate::engine::gpu::GpuError;
use crate::report::folder::{Access, FolderError, OutFolder};
use crate::run::shard::ShardError;
use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::DVec3;
use std::io::Write;
use std::path::Path;

/// Exit code when every case ran and some failed its checks (χ², albedo, a user's checks).
pub const EXIT_CHECKS_FAILED: u8 = 1;
/// Exit code for bad input: usage and validation errors (clap's own code for usage errors).
pub const EXIT_USAGE: u8 = 2;
/// Exit code when the tool could not do the work: no GPU adapter, a lost device, an output
/// that could not be written, a case that could not run.
pub const EXIT_TOOL_FAILURE: u8 = 3;
/// Exit code of a run stopped by SIGINT or SIGTERM (128 + SIGINT, as shells report Ctrl-C).
pub const EXIT_INTERRUPTED: u8 = 130;

/// The exit codes, as `lobes --help` shows them.
pub const EXIT_CODES: &str = "Exit codes:
  0    every case passed (or the command succeeded)
  1    some case or check ran and failed its test
  2    bad input: a scene, a flag or a file lobes cannot use
  3    the tool could not do the work: no GPU adapter (without --cpu), a lost device,
       an output that could not be written
  130  interrupted (SIGINT/SIGTERM): finished cases are reported and written";

/// The `lobes` command line.
#[derive(Debug, Parser)]
#[command(
    name = "lobes",
    version,
    about = "Importance sampling of reflectance lobes and discrete distributions, checked against an f64 reference",
    after_help = EXIT_CODES
)]
pub struct Cli {
    /// The subcommand to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
#[allow(clippy::large_enum_variant)] // parsed once: the size of the largest, check's, costs nothing
pub enum Command {
    // The tutorial's worked examples (docs/tutorial.md): listed after the main commands.
    /// Sample a discrete distribution by CDF inversion or an alias table (tutorial part 1).
    #[command(display_order = 100)]
    Discrete(tutorial::DiscreteArgs),
    /// Convert a half-vector pdf p(ωh) to the reflected pdf p(ωr), in plane (tutorial part 2).
    #[command(display_order = 101)]
    PdfConvert(tutorial::PdfConvertArgs),
    /// Draw one half vector from a lobe and reflect ωi about it (tutorial part 3).
    #[command(display_order = 102)]
    Sample(tutorial::SampleArgs),
    /// Run a scene: sample and histogram every case on the GPU, judge it with a χ² test
    /// against the f64 reference, and write histogram.json and heat maps per case.
    #[command(after_help = EXIT_CODES)]
    Run(run::RunArgs),
    /// Print a scene template with every key and its default (--template), or the cases a
    /// scene makes, its sweeps expanded.
    Scene(scene::SceneArgs),
    /// Measure samples per second (sampling + histogram on the device) per lobe, method and
    /// backend: the GPU adapter and the f64 CPU reference on all cores.
    Bench(bench::BenchArgs),
    /// Drive every sampler with the inputs where naive formulas break, on the GPU (f32) and
    /// the CPU (f64); print case, kernel, worst errors and verdict.
    #[command(after_help = EXIT_CODES)]
    Stress(stress::StressArgs),
    /// Print the composed WGSL that `lobes run` compiles for a scene's cases (each distinct
    /// module once), with the override constants its pipelines are made with.
    Shader(shader::ShaderArgs),
    /// Add up the shards of a scene (`lobes run SCENE --shard I/N`), judge the sums with the χ²
    /// test and write the same outputs as `lobes run`.
    #[command(after_help = EXIT_CODES)]
    Merge(merge::MergeArgs),
    /// Judge your own WGSL sampler: its histogram against the GPU quadrature of its pdf (χ²),
    /// the pdf against the map's Jacobian, weights and albedo with an eval, and hard cases.
    #[command(after_help = EXIT_CODES)]
    Check(check::CheckArgs),
    /// Accuracy against cost: sample count × kernel precision (f32 fast / f32 / f64), spherical
    /// caps against bounded VNDF, and the expected histogram's quadrature; writes tradeoff.md,
    /// tradeoff.png and tradeoff.json with --out.
    Tradeoff(tradeoff::TradeoffArgs),
    /// Print lobes' WGSL for your own shaders: the named modules (rng, ggx, fresnel, ...) with
    /// what they use, every name prefixed `lobes_`; or, with --naga-oil, as naga_oil modules.
    Wgsl(wgsl::WgslArgs),
}

impl Cli {
    /// Runs the parsed command.
    pub fn run(self) -> anyhow::Result<()> {
        match self.command {
            Command::Discrete(args) => tutorial::discrete(&args),
            Command::PdfConvert(args) => tutorial::pdf_convert(&args),
            Command::Sample(args) => tutorial::sample(&args),
            Command::Run(args) => run::run(&args),
            Command::Scene(args) => scene::run(&args),
            Command::Bench(args) => bench::run(&args),
            Command::Stress(args) => stress::run(&args),
            Command::Merge(args) => merge::run(&args),
            Command::Shader(args) => shader::run(&args),
            Command::Tradeoff(args) => tradeoff::run(&args),
            Command::Check(args) => check::run(&args),
            Command::Wgsl(args) => wgsl::run(&args),
        }
    }
}

/// Bad input found after clap's parsing: the message names the flag and what is allowed.
/// [`exit_code`] maps it to [`EXIT_USAGE`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// A [`UsageError`] as an `anyhow::Error`.
pub fn usage(message: impl Into<String>) -> anyhow::Error {
    UsageError(message.into()).into()
}

/// An output folder lobes cannot use, named by its flags: bad input.
pub fn folder_error(e: FolderError) -> anyhow::Error {
    usage(e.render("--out", "--wait"))
}

/// Cases or checks that ran and failed their tests (the outputs are complete).
/// [`exit_code`] maps it to [`EXIT_CHECKS_FAILED`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct ChecksFailed(pub String);

/// A run stopped by SIGINT or SIGTERM after the case in flight. [`exit_code`] maps it to
/// [`EXIT_INTERRUPTED`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct Interrupted(pub String);

/// The process exit code for an error, by what is anywhere in its chain: an [`Interrupted`]
/// gives [`EXIT_INTERRUPTED`]; a [`UsageError`], a clap error, bad shards ([`ShardError`]), an
/// output folder lobes cannot use ([`FolderError`]) or a `WGPU_BACKEND` that names no backend
/// [`EXIT_USAGE`]; a [`ChecksFailed`] [`EXIT_CHECKS_FAILED`]; anything else (the tool could not
/// do the work) [`EXIT_TOOL_FAILURE`].
pub fn exit_code(err: &anyhow::Error) -> u8 {
    let any = |f: &dyn Fn(&(dyn std::error::Error + 'static)) -> bool| err.chain().any(f);
    if any(&|e| e.is::<Interrupted>()) {
        EXIT_INTERRUPTED
    } else if any(&|e| e.is::<UsageError>() || e.is::<clap::Error>() || e.is::<ShardError>() || e.is::<FolderError>() || e.downcast_ref::<GpuError>().is_some_and(GpuError::is_bad_input)) {
        EXIT_USAGE
    } else if any(&|e| e.is::<ChecksFailed>()) {
        EXIT_CHECKS_FAILED
    } else {
        EXIT_TOOL_FAILURE
    }
}

/// Creates the `--out` folder; a path that is not a folder or cannot be created is bad input.
pub fn prepare_out(out: &Path) -> anyhow::Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(usage(format!("--out {}: exists and is not a folder; give a folder (created if missing)", out.display())));
    }
    std::fs::create_dir_all(out).map_err(|e| usage(format!("--out {}: cannot create the output folder: {e}", out.display())))
}

/// A significance level strictly between 0 and 1 (`--significance` of run and merge).
pub fn parse_level(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x < 1.0 => Ok(x),
        _ => Err(format!("'{s}' is not a significance level; give a number strictly between 0 and 1")),
    }
}

/// Output selection shared by the subcommands.
#[derive(Debug, Clone, Copy, Args)]
pub struct OutputArgs {
    /// Print exactly one JSON object on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// How `lobes run` and `lobes merge` write their output folder.
#[derive(Debug, Clone, Args)]
pub struct FileArgs {
    /// Indent histogram.json and timing.json for reading (default: compact, one line).
    #[arg(long)]
    pub pretty: bool,
    /// Where another lobes is writing --out, wait until it has finished (without it: exit 2,
    /// naming that process). One run owns an output folder at a time.
    #[arg(long)]
    pub wait: bool,
}

impl FileArgs {
    /// Creates and locks the output folder `out` ([`OutFolder::claim`]).
    pub fn claim(&self, out: &Path, access: Access) -> anyhow::Result<OutFolder> {
        OutFolder::claim(out, access, self.wait).map_err(folder_error)
    }

    /// Locks `out` if it is already a folder ([`OutFolder::claim_existing`]).
    pub fn claim_existing(&self, out: &Path) -> anyhow::Result<Option<OutFolder>> {
        OutFolder::claim_existing(out, Access::Owner, self.wait).map_err(folder_error)
    }

    pub fn style(&self) -> crate::report::output::JsonStyle {
        if self.pretty { crate::report::output::JsonStyle::Pretty } else { crate::report::output::JsonStyle::Compact }
    }
}

/// Writes `text` to stdout. A reader that has gone (a closed pipe: `lobes check … | head -2`)
/// wants no more: the text is dropped and the command ends with its verdict's exit code; any
/// other failed write (a full disk) is a runtime error.
pub fn emit(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(anyhow::anyhow!("writing to stdout: {e}")),
        _ => Ok(()),
    }
}

/// Writes `value` to stdout as one compact JSON object and a newline. Non-finite numbers
/// become `null` (serde_json's rule).
pub fn emit_json(value: &impl serde::Serialize) -> anyhow::Result<()> {
    let mut text = serde_json::to_string(value)?;
    text.push('\n');
    emit(&text)
}

/// `--lobe`'s values: the registry's lobes, each with its methods.
impl ValueEnum for LobeKind {
    fn value_variants<'a>() -> &'a [Self] {
        &LobeKind::ALL
    }
    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        let methods: Vec<&str> = self.methods().map(Method::name).collect();
        Some(clap::builder::PossibleValue::new(self.name()).help(format!("{} (--method {})", self.about(), methods.join("|"))))
    }
}

/// `--method`'s values, each with the lobes that have it.
impl ValueEnum for Method {
    fn value_variants<'a>() -> &'a [Self] {
        &Method::ALL
    }
    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        let lobes: Vec<&str> = LobeKind::ALL.into_iter().filter(|k| k.supports(*self)).map(LobeKind::name).collect();
        Some(clap::builder::PossibleValue::new(self.name()).help(format!("{}; lobes: {}", self.about(), lobes.join(", "))))
    }
}

/// Lobe, method and roughness: `--lobe L [--method M] (--alpha A | --alpha-x AX --alpha-y AY)`.
#[derive(Debug, Clone, Args)]
#[command(group = clap::ArgGroup::new("roughness").args(["alpha", "alpha_x", "alpha_y"]).required(true).multiple(true))]
pub struct LobeArgs {
    /// The lobe.
    #[arg(long, value_enum)]
    pub lobe: LobeKind,
    /// How the half vector is drawn (each lobe's methods are listed under --lobe).
    #[arg(long, value_enum, default_value = "ndf")]
    pub method: Method,
    /// Isotropic roughness α: a finite number > 0.
    #[arg(long, value_name = "A", value_parser = parse_alpha, allow_hyphen_values = true,
          conflicts_with_all = ["alpha_x", "alpha_y"])]
    pub alpha: Option<f64>,
    /// Anisotropic roughness along x (with --alpha-y): a finite number > 0.
    #[arg(long, value_name = "AX", value_parser = parse_alpha, allow_hyphen_values = true, requires = "alpha_y")]
    pub alpha_x: Option<f64>,
    /// Anisotropic roughness along y (with --alpha-x): a finite number > 0.
    #[arg(long, value_name = "AY", value_parser = parse_alpha, allow_hyphen_values = true, requires = "alpha_x")]
    pub alpha_y: Option<f64>,
}

impl LobeArgs {
    /// The reference lobe, or a [`UsageError`] if the lobe has no sampler for the method.
    pub fn lobe(&self) -> anyhow::Result<crate::reference::Lobe> {
        let (kind, method) = (self.lobe, self.method);
        if !kind.supports(method) {
            let supported: Vec<&str> = kind.methods().map(Method::name).collect();
            return Err(usage(format!(
                "--method {} is not available for --lobe {}; {} supports --method {}",
                method.name(),
                kind.name(),
                kind.name(),
                supported.join("|")
            )));
        }
        let (alpha_x, alpha_y) = match (self.alpha, self.alpha_x, self.alpha_y) {
            (Some(a), None, None) => (a, a),
            (None, Some(ax), Some(ay)) => (ax, ay),
            // clap's group, conflicts and requires rule these out; keep a clear message anyway.
            _ => return Err(usage("give either --alpha A or both --alpha-x AX and --alpha-y AY")),
        };
        Ok(crate::reference::Lobe { kind, method, alpha_x, alpha_y, alpha_angle: 0.0 })
    }
}

/// The incident direction ωi in degrees: `--incident-theta` from the normal, `--incident-phi`
/// azimuth from +x.
#[derive(Debug, Clone, Copy, Args)]
pub struct IncidentArgs {
    /// Polar angle of ωi from the normal, in degrees, in [0, 180] (above 90: from below).
    #[arg(long, value_name = "DEG", default_value_t = 0.0, value_parser = parse_polar_180, allow_hyphen_values = true)]
    pub incident_theta: f64,
    /// Azimuth of ωi from +x, in degrees, in [-360, 360].
    #[arg(long, value_name = "DEG", default_value_t = 0.0, value_parser = parse_azimuth, allow_hyphen_values = true)]
    pub incident_phi: f64,
}

impl IncidentArgs {
    /// ωi as a unit vector, normal on +z.
    pub fn omega_i(&self) -> DVec3 {
        crate::reference::reflect::spherical(self.incident_theta.to_radians(), self.incident_phi.to_radians())
    }
}

/// A comma-separated list of numbers as given on the command line (syntax checked only).
#[derive(Debug, Clone, PartialEq)]
pub struct NumberList(pub Vec<f64>);

/// Parses one number; accepts what Rust's `f64` parser accepts (including `nan`, `inf`), so
/// callers decide about non-finite values.
pub fn parse_number(s: &str) -> Result<f64, String> {
    let t = s.trim();
    if t.is_empty() {
        return Err("expected a number, got nothing".into());
    }
    t.parse::<f64>().map_err(|_| format!("'{t}' is not a number"))
}

/// Parses a comma-separated list such as `15,5,5.5`. An empty or blank string is the empty
/// list; an empty item (`1,,2`, `1,`) or a non-number is an error naming its 0-based index.
pub fn parse_number_list(s: &str) -> Result<NumberList, String> {
    if s.trim().is_empty() {
        return Ok(NumberList(Vec::new()));
    }
    s.split(',')
        .enumerate()
        .map(|(i, item)| {
            parse_number(item).map_err(|e| {
                format!("item at index {i} (counting from 0): {e}; expected comma-separated numbers such as 1,2.5,3")
            })
        })
        .collect::<Result<Vec<_>, _>>()
        .map(NumberList)
}

/// Checks a uniform: u ∈ [0, 1] (NaN excluded).
pub fn check_unit(u: f64) -> Result<f64, String> {
    if (0.0..=1.0).contains(&u) {
        Ok(u)
    } else {
        Err(format!("{u} is not in [0, 1]; each u must be a number in [0, 1]"))
    }
}

/// Parses a non-empty list of uniforms in [0, 1].
pub fn parse_unit_list(s: &str) -> Result<NumberList, String> {
    let list = parse_number_list(s)?;
    if list.0.is_empty() {
        return Err("the list is empty; give at least one number in [0, 1], e.g. 0.5,0.25".into());
    }
    for (i, &u) in list.0.iter().enumerate() {
        check_unit(u).map_err(|e| format!("item at index {i} (counting from 0): {e}"))?;
    }
    Ok(list)
}

/// Parses exactly two uniforms in [0, 1], `U1,U2`.
pub fn parse_unit_pair(s: &str) -> Result<[f64; 2], String> {
    let list = parse_unit_list(s)?.0;
    match list[..] {
        [u1, u2] => Ok([u1, u2]),
        _ => Err(format!("expected exactly 2 numbers U1,U2 in [0, 1], got {}", list.len())),
    }
}

/// Parses a roughness α: finite and > 0.
pub fn parse_alpha(s: &str) -> Result<f64, String> {
    let a = parse_number(s)?;
    if a.is_finite() && a > 0.0 { Ok(a) } else { Err(format!("roughness must be a finite number > 0, got {a}")) }
}

/// Parses a finite number ≥ 0 (a density).
pub fn parse_non_negative(s: &str) -> Result<f64, String> {
    let x = parse_number(s)?;
    if x.is_finite() && x >= 0.0 { Ok(x) } else { Err(format!("must be a finite number ≥ 0, got {x}")) }
}

fn parse_degrees_in(s: &str, lo: f64, hi: f64) -> Result<f64, String> {
    let x = parse_number(s)?;
    if (lo..=hi).contains(&x) {
        Ok(x)
    } else {
        Err(format!("{x} is outside [{lo}, {hi}]; give an angle in degrees in [{lo}, {hi}]"))
    }
}

/// Parses a polar angle of the upper hemisphere in degrees, [0, 90].
pub fn parse_polar_90(s: &str) -> Result<f64, String> {
    parse_degrees_in(s, 0.0, 90.0)
}

/// Parses a polar angle in degrees, [0, 180].
pub fn parse_polar_180(s: &str) -> Result<f64, String> {
    parse_degrees_in(s, 0.0, 180.0)
}

/// Parses an azimuth in degrees, [-360, 360].
pub fn parse_azimuth(s: &str) -> Result<f64, String> {
    parse_degrees_in(s, -360.0, 360.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_shards_are_bad_input() {
        let err = anyhow::Error::from(ShardError::Missing { case: "c".into(), from: 3, to: 6 }).context("lobes merge");
        assert_eq!(exit_code(&err), EXIT_USAGE);
        assert_eq!(exit_code(&usage("x")), EXIT_USAGE);
        assert_eq!(exit_code(&anyhow::anyhow!("disk full")), EXIT_TOOL_FAILURE);
    }

    #[test]
    fn each_outcome_has_its_own_exit_code() {
        let failed = anyhow::Error::from(ChecksFailed("1 of 3 cases failed".into())).context("lobes run");
        assert_eq!(exit_code(&failed), EXIT_CHECKS_FAILED);
        let stopped = anyhow::Error::from(Interrupted("interrupted".into())).context("lobes run");
        assert_eq!(exit_code(&stopped), EXIT_INTERRUPTED);
        let mut codes = [EXIT_CHECKS_FAILED, EXIT_USAGE, EXIT_TOOL_FAILURE, EXIT_INTERRUPTED, 0];
        codes.sort();
        assert!(codes.windows(2).all(|w| w[0] < w[1]), "distinct codes: {codes:?}");
        for code in [EXIT_CHECKS_FAILED, EXIT_USAGE, EXIT_TOOL_FAILURE, EXIT_INTERRUPTED] {
            assert!(EXIT_CODES.contains(&format!("\n  {code} ")), "--help documents {code}");
        }
    }

    #[test]
    fn every_domain_flag_value_is_a_domains_name() {
        use clap::ValueEnum;
        let flags: Vec<String> = check::DomainChoice::value_variants().iter().map(|d| d.to_possible_value().unwrap().get_name().to_owned()).collect();
        assert_eq!(flags, crate::stats::domain::Domain::NAMES);
        let directions = flags.iter().filter(|f| crate::stats::domain::Domain::of_directions(f).is_some()).count();
        assert_eq!(directions, 3, "every name but plane is a domain of directions");
    }
}
