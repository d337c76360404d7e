//! Reading one value of a scene: its type and range checked, an error at its span (line and
//! column), and the values every case shares (defaults, name, samples, seed).

use super::raw::RawCase;
use super::sweep::{Point, Val};
use crate::stats::histogram::SphereGrid;
use std::ops::Range;
use toml::Value;

/// The most bins (rows × cols, or discrete items) a case may have: 2^24. The GPU engine splits
/// larger histograms into tiles that fit the adapter; this cap bounds the f64 quadrature, the
/// heat maps and `histogram.json`.
pub const MAX_BINS: u64 = 1 << 24;

/// A case's incident azimuth in degrees unless given.
pub const DEFAULT_INCIDENT_PHI: f64 = 0.0;

/// A scene error with its location (1-based line and column, the column in characters).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct SceneError {
    pub file: String,
    pub line: usize,
    pub column: usize,
    pub message: String,
}

pub(super) struct Ctx<'a> {
    pub(super) file: &'a str,
    pub(super) text: &'a str,
}

/// 1-based line and column (in characters) of byte offset `at` in `text`.
pub(super) fn line_column(text: &str, at: usize) -> (usize, usize) {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

impl Ctx<'_> {
    pub(super) fn err(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        let (line, column) = line_column(self.text, span.start);
        SceneError { file: self.file.to_string(), line, column, message: message.into() }
    }
}

/// "a string", "an integer", … for messages.
pub(super) fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a floating-point number",
        Value::Boolean(_) => "a boolean",
        Value::Datetime(_) => "a date-time",
        Value::Array(_) => "an array",
        Value::Table(_) => "a table",
    }
}

/// A number (TOML integer or float), finite and accepted by `ok`.
pub(super) fn number(ctx: &Ctx, v: &Val, key: &str, ok: impl Fn(f64) -> bool, allowed: &str) -> Result<f64, SceneError> {
    let x = match v.get_ref() {
        Value::Integer(i) => *i as f64,
        Value::Float(f) => *f,
        other => return Err(ctx.err(v.span(), format!("{key} must be a number, got {}; {allowed}", kind_of(other)))),
    };
    if !x.is_finite() || !ok(x) {
        return Err(ctx.err(v.span(), format!("{key} = {x} is not allowed; {allowed}")));
    }
    Ok(x)
}

/// A whole number in `lo ..= hi`.
pub(super) fn whole(ctx: &Ctx, v: &Val, key: &str, lo: u64, hi: u64, allowed: &str) -> Result<u64, SceneError> {
    match v.get_ref() {
        Value::Integer(i) if *i >= 0 && (lo..=hi).contains(&(*i as u64)) => Ok(*i as u64),
        Value::Integer(i) => Err(ctx.err(v.span(), format!("{key} = {i} is not allowed; {allowed}"))),
        Value::Float(f) => Err(ctx.err(v.span(), format!("{key} must be a whole number (an integer literal), got the floating-point number {f:?}; {allowed}"))),
        other => Err(ctx.err(v.span(), format!("{key} must be a whole number, got {}; {allowed}", kind_of(other)))),
    }
}

/// A string.
pub(super) fn string<'v>(ctx: &Ctx, v: &'v Val, key: &str, allowed: &str) -> Result<&'v str, SceneError> {
    match v.get_ref() {
        Value::String(s) => Ok(s),
        other => Err(ctx.err(v.span(), format!("{key} must be a string, got {}; {allowed}", kind_of(other)))),
    }
}

/// `[rows, cols]` with at most [`MAX_BINS`] bins (and an even number of rows where `even_rows`).
pub(super) fn grid(ctx: &Ctx, v: &Val, even_rows: bool, allowed: &str) -> Result<SphereGrid, SceneError> {
    let bad = |what: String| ctx.err(v.span(), format!("bins {what}; {allowed}"));
    let Value::Array(items) = v.get_ref() else { return Err(bad(format!("must be an array, got {}", kind_of(v.get_ref())))) };
    let [rows, cols] = items.as_slice() else { return Err(bad(format!("has {} items, not 2", items.len()))) };
    let dim = |x: &Value| match x {
        Value::Integer(i) if *i >= 1 && *i <= u32::MAX as i64 => Ok(*i as u32),
        Value::Integer(i) => Err(bad(format!("= [{rows}, {cols}] is not allowed ({i} is out of range)"))),
        other => Err(bad(format!("must hold whole numbers, got {}", kind_of(other)))),
    };
    let (r, c) = (dim(rows)?, dim(cols)?);
    if even_rows && r % 2 == 1 {
        return Err(bad(format!("= [{r}, {c}] is not allowed: {r} rows is odd")));
    }
    if r as u64 * c as u64 > MAX_BINS {
        return Err(bad(format!("= [{r}, {c}] is not allowed: {} bins is more than 2^24", r as u64 * c as u64)));
    }
    Ok(SphereGrid { rows: r, cols: c })
}

/// `[defaults]`, each value validated where it is written, and the command line's overrides.
pub(super) struct Defaults<'a> {
    pub(super) samples: Option<(u64, &'a Val)>,
    pub(super) bins: Option<SphereGrid>,
    pub(super) seed: Option<u64>,
    pub(super) overrides: Overrides,
}

/// Values that replace those of every case (`lobes run --samples N --seed S`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Overrides {
    /// Samples of every case, 1 ..= [`super::MAX_SAMPLES`] (a weighted case: ..= [`super::MAX_WEIGHTED_SAMPLES`]).
    pub samples: Option<u64>,
    pub seed: Option<u64>,
}

/// An error on the first of `keys` present: it does not apply to a case of this kind.
pub(super) fn reject_keys(ctx: &Ctx, keys: &[(&str, Option<&Val>)], why: &str) -> Result<(), SceneError> {
    match keys.iter().find_map(|(k, v)| v.map(|v| (k, v))) {
        Some((k, v)) => Err(ctx.err(v.span(), format!("{k} {why}"))),
        None => Ok(()),
    }
}

/// A case's name, sample count and seed (the name with its sweep suffix).
pub(super) struct Common {
    pub(super) name: String,
    pub(super) samples: u64,
    pub(super) seed: u64,
}

/// `incident_phi` of a case (0 unless given).
pub(super) fn incident_phi(ctx: &Ctx, point: &Point) -> Result<f64, SceneError> {
    match point.get("incident_phi") {
        Some(p) => number(ctx, p, "incident_phi", |x| (-360.0..=360.0).contains(&x), "incident_phi is in degrees, −360 ≤ φ ≤ 360"),
        None => Ok(DEFAULT_INCIDENT_PHI),
    }
}

pub(super) fn roughness_keys(p: &Point) -> [(&'static str, Option<&Val>); 4] {
    ["alpha", "alpha_x", "alpha_y", "alpha_angle"].map(|k| (k, p.get(k)))
}

pub(super) fn effect_keys<'a>(c: &'a RawCase, p: &'a Point) -> [(&'static str, Option<&'a Val>); 6] {
    [("weighted", c.weighted.as_ref()), ("fresnel", p.get("fresnel")), ("f0", p.get("f0")), ("eta", p.get("eta")), ("k", p.get("k")), ("masking", p.get("masking"))]
}
