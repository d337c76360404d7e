//! Heat maps of 2-D histograms, rendered to PNG with no font crates.
//!
//! A [`Heatmap`] is a row-major grid of values over (cos θ, φ). [`render`] draws it as an
//! RGB image: the cells scaled up to a few pixels each (row 0 at the *bottom*), a vertical
//! colour bar with min/mid/max tick labels on the right, the title on top and the axis range
//! labels. Text uses an embedded 5×7 bitmap font drawn at 2×; characters it lacks become a
//! hollow box, so any `&str` is safe to draw. [`write_png`] writes the image atomically
//! ([`super::atomic`]).
//!
//! Colour scales:
//! - [`Scale::Sequential`]: viridis-like, from `min(0, min v)` to `max v`. When every value
//!   is `>= 0` and `max / min_positive > 1e3`, it switches to `log10(1 + v/p)` with `p` the
//!   smallest positive value (for integer counts `p = 1`, i.e. plain `log10(1 + v)`), and
//!   the colour bar is captioned "log".
//! - [`Scale::Diverging`]: blue-white-red, symmetric in `[-L, L]` with `L = max |v|`
//!   (at least a tiny positive number), so 0 is white.
//!
//! Non-finite values (NaN, ±inf) are drawn grey and ignored when fitting the scale; an
//! all-zero or empty map renders without dividing by zero.

use std::io;
use std::path::Path;

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder, Rgb, RgbImage};

/// How cell values map to colours.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Non-negative values such as counts: viridis-like, log-scaled when the range is wide.
    Sequential,
    /// Signed values such as residuals: blue-white-red, symmetric around 0.
    Diverging,
}

/// A 2-D histogram to draw.
#[derive(Debug, Clone, Copy)]
pub struct Heatmap<'a> {
    /// Title drawn at the top (any text; unknown characters become a box).
    pub title: &'a str,
    /// Number of rows (the vertical axis, e.g. cos θ bins).
    pub rows: usize,
    /// Number of columns (the horizontal axis, e.g. φ bins).
    pub cols: usize,
    /// Row-major values, `values[r * cols + c]`; row 0 is drawn at the bottom. Missing
    /// entries (a short slice) are drawn like NaN.
    pub values: &'a [f64],
    /// Colour scale.
    pub scale: Scale,
    /// Label of the vertical axis, e.g. "cos θ".
    pub row_label: &'a str,
    /// Label of the horizontal axis, e.g. "φ".
    pub col_label: &'a str,
    /// Value range of the rows: (bottom edge, top edge), e.g. (-1, 1).
    pub row_range: (f64, f64),
    /// Value range of the columns: (left edge, right edge), e.g. (-π, π).
    pub col_range: (f64, f64),
}

/// Colour of NaN / infinite / missing cells; absent from both colormaps.
const NAN_GREY: Rgb<u8> = Rgb([128, 128, 128]);
/// Background.
const BG: Rgb<u8> = Rgb([255, 255, 255]);
/// Text and tick colour.
const INK: Rgb<u8> = Rgb([20, 20, 20]);
/// Frame around the map and the colour bar.
const FRAME: Rgb<u8> = Rgb([70, 70, 70]);

/// Font glyph size in font pixels (7 rows above the baseline plus one descender row), and
/// the factor text is drawn at.
const GLYPH_W: u32 = 5;
const GLYPH_H: u32 = 8;
const TEXT_SCALE: u32 = 2;
/// Height of one line of text in image pixels.
const LINE_H: u32 = GLYPH_H * TEXT_SCALE;
/// Outer margin and small gaps.
const PAD: u32 = 12;
const GAP: u32 = 6;
/// The map aims at about this many pixels per side; cells are at most `MAX_CELL` wide.
const MAP_TARGET: usize = 512;
const MAX_CELL: usize = 32;
/// Colour bar width and its distance from the map.
const BAR_W: u32 = 20;
const BAR_GAP: u32 = 20;
/// Length of the colour bar's tick marks.
const TICK_LEN: u32 = 4;
/// Above this max / min-positive ratio a sequential map goes logarithmic.
const LOG_RATIO: f64 = 1e3;
/// Widest canvas a long title may ask for; beyond it the title is clipped.
const MAX_WIDTH: u32 = 4096;

/// Viridis sampled at t = 0, 1/8, …, 1.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 82, 139],
    [44, 114, 142],
    [33, 145, 140],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Blue → white → red (ColorBrewer RdBu, reversed) at t = 0, 1/4, …, 1.
const BLUE_WHITE_RED: [[u8; 3]; 5] = [
    [5, 48, 97],
    [67, 147, 195],
    [247, 247, 247],
    [214, 96, 77],
    [103, 0, 31],
];

/// Renders the heat map, colour bar, title and axis labels into an RGB image.
pub fn render(h: &Heatmap) -> RgbImage {
    let mapping = Mapping::fit(h.scale, cell_values(h));
    let ticks = tick_labels(&mapping);
    let has_bad = (0..h.rows * h.cols).any(|i| !cell(h, i).is_finite());
    let lay = Layout::new(h, &ticks, has_bad);
    let mut img = RgbImage::from_pixel(lay.width, lay.height, BG);
    draw_cells(&mut img, h, &mapping, &lay);
    draw_colour_bar(&mut img, h.scale, &mapping, &ticks, &lay);
    if has_bad {
        draw_nan_key(&mut img, &lay);
    }
    draw_axis_labels(&mut img, h, &lay);
    let title_x = (lay.width as i64 - text_width(h.title) as i64) / 2;
    draw_text(&mut img, title_x.max(PAD as i64), PAD as i64, h.title, INK);
    img
}

/// Renders `h` and writes it as a PNG to `path`, atomically ([`super::atomic`]).
pub fn write_png(h: &Heatmap, path: &Path) -> io::Result<()> {
    let img = render(h);
    super::atomic::write_atomic_with(path, |out| encode_png(&img, out))
}

/// Encodes `img` as PNG into `out`.
fn encode_png(img: &RgbImage, out: &mut dyn io::Write) -> io::Result<()> {
    PngEncoder::new(out)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            ExtendedColorType::Rgb8,
        )
        .map_err(io::Error::other)
}

/// Value of cell `i` (row-major); missing cells read as NaN.
fn cell(h: &Heatmap, i: usize) -> f64 {
    h.values.get(i).copied().unwrap_or(f64::NAN)
}

/// The values that belong to cells (a longer slice's tail is ignored).
fn cell_values<'a>(h: &Heatmap<'a>) -> &'a [f64] {
    &h.values[..h.values.len().min(h.rows.saturating_mul(h.cols))]
}

// ---------------------------------------------------------------------------------------
// Value → colour
// ---------------------------------------------------------------------------------------

/// Maps finite values to `t ∈ [0, 1]` along the colormap, and back for tick labels.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Mapping {
    /// `t = (v - lo) / (hi - lo)`, with `hi > lo`.
    Linear { lo: f64, hi: f64 },
    /// `t = ln(1 + v/p) / ln(1 + hi/p)`, `p` the smallest positive value, `hi > 0`.
    Log { p: f64, hi: f64 },
    /// `t = (1 + v/lim) / 2`, with `lim > 0`.
    Symmetric { lim: f64 },
}

impl Mapping {
    /// Chooses the mapping for `values` (non-finite ones ignored).
    fn fit(scale: Scale, values: &[f64]) -> Self {
        let s = Stats::of(values);
        match scale {
            Scale::Diverging => Mapping::Symmetric {
                lim: s.max_abs.max(f64::MIN_POSITIVE),
            },
            Scale::Sequential => match s.min_pos {
                Some(p) if s.min >= 0.0 && s.max / p > LOG_RATIO => Mapping::Log { p, hi: s.max },
                _ => Self::linear(s.min.min(0.0), s.max),
            },
        }
    }

    /// A linear mapping over `[lo, hi]`, widened to `[lo, lo + 1]` when empty.
    fn linear(lo: f64, hi: f64) -> Self {
        let hi = if hi > lo { hi } else { lo + 1.0 };
        Mapping::Linear { lo, hi }
    }

    /// Position of finite `v` along the colormap, clamped to `[0, 1]`.
    fn unit(&self, v: f64) -> f64 {
        let t = match *self {
            Mapping::Linear { lo, hi } => (v - lo) / (hi - lo),
            Mapping::Log { p, hi } => log_ratio(v, p) / log_ratio(hi, p),
            Mapping::Symmetric { lim } => 0.5 + 0.5 * v / lim,
        };
        if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }
    }

    /// The value at colormap position `t` (inverse of [`Mapping::unit`]).
    fn value_at(&self, t: f64) -> f64 {
        match *self {
            Mapping::Linear { lo, hi } => lo + t * (hi - lo),
            Mapping::Log { hi, .. } if t >= 1.0 => hi,
            Mapping::Log { p, hi } => p * (t * log_ratio(hi, p)).exp_m1(),
            Mapping::Symmetric { lim } => (2.0 * t - 1.0) * lim,
        }
    }

    fn is_log(&self) -> bool {
        matches!(self, Mapping::Log { .. })
    }
}

/// `ln(1 + v/p)`, robust when `v/p` overflows.
fn log_ratio(v: f64, p: f64) -> f64 {
    let r = v.max(0.0) / p;
    if r.is_finite() {
        r.ln_1p()
    } else {
        v.ln() - p.ln()
    }
}

/// Range statistics over the finite values.
struct Stats {
    min: f64,
    max: f64,
    max_abs: f64,
    min_pos: Option<f64>,
}

impl Stats {
    /// Statistics of the finite entries of `values`; all zero when there are none.
    fn of(values: &[f64]) -> Self {
        let finite = || values.iter().copied().filter(|v| v.is_finite());
        let min = finite().fold(f64::INFINITY, f64::min);
        let max = finite().fold(f64::NEG_INFINITY, f64::max);
        let min_pos = finite()
            .filter(|&v| v > 0.0)
            .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.min(v))));
        let (min, max) = if min <= max { (min, max) } else { (0.0, 0.0) };
        Stats {
            min,
            max,
            max_abs: min.abs().max(max.abs()),
            min_pos,
        }
    }
}

/// Colour at position `t ∈ [0, 1]` of the scale's colormap.
fn colour(scale: Scale, t: f64) -> Rgb<u8> {
    match scale {
        Scale::Sequential => lerp_table(&VIRIDIS, t),
        Scale::Diverging => lerp_table(&BLUE_WHITE_RED, t),
    }
}

/// Piecewise-linear interpolation in an evenly spaced colour table; `t = 1` gives the last
/// entry exactly.
fn lerp_table(table: &[[u8; 3]], t: f64) -> Rgb<u8> {
    let x = t.clamp(0.0, 1.0) * (table.len() - 1) as f64;
    let i = (x.floor() as usize).min(table.len() - 2);
    let f = x - i as f64;
    let (a, b) = (table[i], table[i + 1]);
    let mix = |k: usize| (a[k] as f64 + (b[k] as f64 - a[k] as f64) * f).round() as u8;
    Rgb([mix(0), mix(1), mix(2)])
}

/// Colour of one cell value.
fn cell_colour(scale: Scale, mapping: &Mapping, v: f64) -> Rgb<u8> {
    if v.is_finite() {
        colour(scale, mapping.unit(v))
    } else {
        NAN_GREY
    }
}

// ---------------------------------------------------------------------------------------
// Layout and drawing
// ---------------------------------------------------------------------------------------

/// Pixel geometry of the picture.
#[derive(Debug, Clone, Copy)]
struct Layout {
    cell_w: u32,
    cell_h: u32,
    map_x: u32,
    map_y: u32,
    map_w: u32,
    map_h: u32,
    bar_x: u32,
    width: u32,
    height: u32,
}

impl Layout {
    /// Places map, colour bar and labels; `ticks` are the colour bar labels, `has_bad`
    /// whether a NaN key is drawn under the bar.
    fn new(h: &Heatmap, ticks: &[String; 3], has_bad: bool) -> Self {
        let cell_w = cell_size(h.cols);
        let cell_h = cell_size(h.rows);
        let (map_w, map_h) = (cell_w * h.cols as u32, cell_h * h.rows as u32);
        let row_texts = [
            axis_text(h.row_range.0),
            axis_text(h.row_range.1),
            h.row_label.into(),
        ];
        let left = row_texts.iter().map(|s| text_width(s)).max().unwrap_or(0) + GAP + PAD;
        // title line, then the colour-bar caption line, then the map
        let map_y = PAD + LINE_H + GAP + LINE_H + GAP + LINE_H / 2;
        let bar_x = left + map_w + BAR_GAP;
        let tick_w = ticks.iter().map(|s| text_width(s)).max().unwrap_or(0);
        let key_w = if has_bad {
            LINE_H + GAP + text_width("nan")
        } else {
            0
        };
        let right = bar_x + BAR_W + TICK_LEN + GAP + tick_w.max(key_w).max(text_width("log")) + PAD;
        let width = right.max((text_width(h.title) + 2 * PAD).min(MAX_WIDTH));
        // below the map: the column labels, and (lower, clear of the last tick label) the NaN key
        let height = nan_key_y(map_y, map_h) + LINE_H + PAD;
        Layout {
            cell_w,
            cell_h,
            map_x: left,
            map_y,
            map_w,
            map_h,
            bar_x,
            width,
            height,
        }
    }
}

/// Pixels per cell along an axis with `n` cells: about `MAP_TARGET / n`, at least 1.
fn cell_size(n: usize) -> u32 {
    (MAP_TARGET / n.max(1)).clamp(1, MAX_CELL) as u32
}

/// Fills the map area cell by cell; row 0 at the bottom.
fn draw_cells(img: &mut RgbImage, h: &Heatmap, mapping: &Mapping, lay: &Layout) {
    for r in 0..h.rows {
        let y = lay.map_y + (h.rows - 1 - r) as u32 * lay.cell_h;
        for c in 0..h.cols {
            let rgb = cell_colour(h.scale, mapping, cell(h, r * h.cols + c));
            let x = lay.map_x + c as u32 * lay.cell_w;
            fill_rect(img, x, y, lay.cell_w, lay.cell_h, rgb);
        }
    }
    frame(img, lay.map_x, lay.map_y, lay.map_w, lay.map_h);
}

/// Draws the vertical colour bar with its min/mid/max ticks and, in log mode, a "log"
/// caption above it.
fn draw_colour_bar(
    img: &mut RgbImage,
    scale: Scale,
    m: &Mapping,
    ticks: &[String; 3],
    lay: &Layout,
) {
    let span = lay.map_h.max(1);
    for dy in 0..lay.map_h {
        let t = 1.0 - (dy as f64 + 0.5) / span as f64;
        fill_rect(img, lay.bar_x, lay.map_y + dy, BAR_W, 1, colour(scale, t));
    }
    frame(img, lay.bar_x, lay.map_y, BAR_W, lay.map_h);
    let label_x = (lay.bar_x + BAR_W + TICK_LEN + GAP) as i64;
    for (k, label) in ticks.iter().enumerate() {
        let y = lay.map_y as i64 + ((2 - k) as i64 * (span as i64 - 1)) / 2;
        fill_rect(img, lay.bar_x + BAR_W, y.max(0) as u32, TICK_LEN, 2, INK);
        let top = (y - LINE_H as i64 / 2).max(lay.map_y as i64 - LINE_H as i64 / 2);
        draw_text(img, label_x, top, label, INK);
    }
    if m.is_log() {
        let y = lay.map_y as i64 - (LINE_H / 2 + GAP + LINE_H) as i64;
        draw_text(img, lay.bar_x as i64, y, "log", INK);
    }
}

/// Top of the NaN key: under the colour bar, below the half line the bottom tick label
/// overhangs.
fn nan_key_y(map_y: u32, map_h: u32) -> u32 {
    map_y + map_h + LINE_H / 2 + GAP
}

/// Draws the grey swatch and "nan" under the colour bar.
fn draw_nan_key(img: &mut RgbImage, lay: &Layout) {
    let y = nan_key_y(lay.map_y, lay.map_h);
    fill_rect(img, lay.bar_x, y, LINE_H, LINE_H - TEXT_SCALE, NAN_GREY);
    draw_text(img, (lay.bar_x + LINE_H + GAP) as i64, y as i64, "nan", INK);
}

/// Draws the axis range labels and axis names: rows to the left, columns underneath.
fn draw_axis_labels(img: &mut RgbImage, h: &Heatmap, lay: &Layout) {
    let right_of = |s: &str| lay.map_x as i64 - GAP as i64 - text_width(s) as i64;
    let (bottom, top) = (axis_text(h.row_range.0), axis_text(h.row_range.1));
    let map_bottom = (lay.map_y + lay.map_h) as i64;
    draw_text(img, right_of(&top), lay.map_y as i64, &top, INK);
    draw_text(
        img,
        right_of(&bottom),
        map_bottom - LINE_H as i64,
        &bottom,
        INK,
    );
    let mid_y = lay.map_y as i64 + (lay.map_h as i64 - LINE_H as i64) / 2;
    draw_text(img, right_of(h.row_label), mid_y, h.row_label, INK);

    let y = map_bottom + GAP as i64;
    let (left, right) = (axis_text(h.col_range.0), axis_text(h.col_range.1));
    let map_right = (lay.map_x + lay.map_w) as i64;
    draw_text(img, lay.map_x as i64, y, &left, INK);
    draw_text(img, map_right - text_width(&right) as i64, y, &right, INK);
    let mid_x = lay.map_x as i64 + (lay.map_w as i64 - text_width(h.col_label) as i64) / 2;
    draw_text(img, mid_x, y, h.col_label, INK);
}

/// Fills a rectangle, clipped to the image.
pub(crate) fn fill_rect(img: &mut RgbImage, x: u32, y: u32, w: u32, h: u32, rgb: Rgb<u8>) {
    let (x1, y1) = (
        x.saturating_add(w).min(img.width()),
        y.saturating_add(h).min(img.height()),
    );
    for py in y..y1 {
        for px in x..x1 {
            img.put_pixel(px, py, rgb);
        }
    }
}

/// A one-pixel frame just outside the rectangle (x, y, w, h).
fn frame(img: &mut RgbImage, x: u32, y: u32, w: u32, h: u32) {
    let (x0, y0) = (x.saturating_sub(1), y.saturating_sub(1));
    fill_rect(img, x0, y0, w + 2, 1, FRAME);
    fill_rect(img, x0, y + h, w + 2, 1, FRAME);
    fill_rect(img, x0, y0, 1, h + 2, FRAME);
    fill_rect(img, x + w, y0, 1, h + 2, FRAME);
}

// ---------------------------------------------------------------------------------------
// Numbers and text
// ---------------------------------------------------------------------------------------

/// Colour bar labels at t = 0, ½, 1 (bottom, middle, top).
fn tick_labels(m: &Mapping) -> [String; 3] {
    [0.0, 0.5, 1.0].map(|t| fmt_num(m.value_at(t)))
}

/// An axis range end: multiples of π (like -π, π, 2π) by name, other values compactly.
fn axis_text(v: f64) -> String {
    let k = v / std::f64::consts::PI;
    let kr = k.round();
    if v != 0.0 && kr != 0.0 && (k - kr).abs() < 1e-9 && kr.abs() <= 9.0 {
        match kr as i64 {
            1 => "π".into(),
            -1 => "-π".into(),
            n => format!("{n}π"),
        }
    } else {
        fmt_num(v)
    }
}

/// A compact number: up to 3 significant digits in plain notation for 0.01 ≤ |v| < 10⁴,
/// otherwise a 2-digit mantissa with an exponent (`1.2e4`, `-3.5e-5`).
fn fmt_num(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}").to_lowercase();
    }
    let a = v.abs();
    if (1e-2..1e4).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        return trim_zeros(&format!("{v:.decimals$}")).to_string();
    }
    let s = format!("{v:.1e}");
    match s.split_once('e') {
        Some((mant, exp)) => format!("{}e{exp}", trim_zeros(mant)),
        None => s,
    }
}

/// Drops trailing zeros after a decimal point, and the point itself if left bare.
fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// Width in pixels of `s` drawn by [`draw_text`].
pub(crate) fn text_width(s: &str) -> u32 {
    let n = s.chars().count() as u32;
    (n * (GLYPH_W + 1) * TEXT_SCALE).saturating_sub(TEXT_SCALE)
}

/// Draws `s` with its top-left corner at (x, y), clipped to the image.
pub(crate) fn draw_text(img: &mut RgbImage, x: i64, y: i64, s: &str, rgb: Rgb<u8>) {
    let advance = ((GLYPH_W + 1) * TEXT_SCALE) as i64;
    for (i, ch) in s.chars().enumerate() {
        draw_glyph(img, x + i as i64 * advance, y, glyph(ch), rgb);
    }
}

/// Draws one glyph at `TEXT_SCALE`, clipped to the image.
fn draw_glyph(img: &mut RgbImage, x: i64, y: i64, rows: [u8; 8], rgb: Rgb<u8>) {
    let s = TEXT_SCALE as i64;
    for (gy, bits) in rows.iter().enumerate() {
        for gx in 0..GLYPH_W as i64 {
            if bits >> (GLYPH_W as i64 - 1 - gx) & 1 == 1 {
                let (px, py) = (x + gx * s, y + gy as i64 * s);
                if px >= 0 && py >= 0 && px < img.width() as i64 && py < img.height() as i64 {
                    fill_rect(img, px as u32, py as u32, TEXT_SCALE, TEXT_SCALE, rgb);
                }
            }
        }
    }
}

/// The hollow box drawn for characters the font lacks.
const MISSING_GLYPH: [u8; 7] = [0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F];

/// 5×8 bitmap of `c`: eight rows, top first, bit 4 the leftmost pixel; row 7 is below the
/// baseline and used only by descenders.
fn glyph(c: char) -> [u8; 8] {
    if let Some(g) = descender_glyph(c) {
        return g;
    }
    let r = base_glyph(c);
    [r[0], r[1], r[2], r[3], r[4], r[5], r[6], 0]
}

/// Glyphs that reach below the baseline.
fn descender_glyph(c: char) -> Option<[u8; 8]> {
    Some(match c {
        'g' => [0x00, 0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E],
        'j' => [0x02, 0x00, 0x06, 0x02, 0x02, 0x02, 0x12, 0x0C],
        'p' => [0x00, 0x00, 0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10],
        'q' => [0x00, 0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x01],
        'y' => [0x00, 0x00, 0x11, 0x11, 0x11, 0x0F, 0x01, 0x0E],
        ',' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08],
        ';' => [0x00, 0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x04, 0x08],
        'φ' | 'ϕ' => [0x00, 0x04, 0x0E, 0x15, 0x15, 0x0E, 0x04, 0x04],
        'μ' | 'µ' => [0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x1D, 0x10],
        _ => return None,
    })
}

/// 5×7 bitmap of a character sitting on the baseline: seven rows, top first.
fn base_glyph(c: char) -> [u8; 7] {
    match c {
        '0'..='9' => digit_glyph(c),
        'a'..='z' => lower_glyph(c),
        'A'..='Z' => upper_glyph(c),
        _ => symbol_glyph(c),
    }
}

/// Glyphs for '0'..='9'.
fn digit_glyph(c: char) -> [u8; 7] {
    match c {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        _ => MISSING_GLYPH,
    }
}

/// Glyphs for 'a'..='z' (those with descenders are in [`descender_glyph`]).
fn lower_glyph(c: char) -> [u8; 7] {
    match c {
        'a' => [0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F],
        'b' => [0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1E],
        'c' => [0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E],
        'd' => [0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F],
        'e' => [0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E],
        'f' => [0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08],
        'h' => [0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11],
        'i' => [0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E],
        'k' => [0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12],
        'l' => [0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E],
        'm' => [0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11],
        'n' => [0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11],
        'o' => [0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E],
        'r' => [0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10],
        's' => [0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E],
        't' => [0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06],
        'u' => [0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D],
        'v' => [0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04],
        'w' => [0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A],
        'x' => [0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11],
        'z' => [0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F],
        _ => MISSING_GLYPH,
    }
}

/// Glyphs for 'A'..='Z'.
fn upper_glyph(c: char) -> [u8; 7] {
    match c {
        'A' => [0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
        'B' => [0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E],
        'C' => [0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E],
        'D' => [0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C],
        'E' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F],
        'F' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10],
        'G' => [0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F],
        'H' => [0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
        'I' => [0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E],
        'J' => [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C],
        'K' => [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11],
        'L' => [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F],
        'M' => [0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11],
        'N' => [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11],
        'O' => [0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'P' => [0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10],
        'Q' => [0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D],
        'R' => [0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11],
        'S' => [0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E],
        'T' => [0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
        'U' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'V' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04],
        'W' => [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A],
        'X' => [0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11],
        'Y' => [0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04],
        'Z' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F],
        _ => MISSING_GLYPH,
    }
}

/// Glyphs for punctuation and the few Greek / math symbols titles use.
fn symbol_glyph(c: char) -> [u8; 7] {
    match c {
        ' ' | '\t' => [0; 7],
        '.' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C],
        ':' => [0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00],
        '-' | '−' => [0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00],
        '+' => [0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00],
        '=' => [0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00],
        '_' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F],
        '*' | '×' => [0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00],
        '/' => [0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00],
        '\\' => [0x00, 0x10, 0x08, 0x04, 0x02, 0x01, 0x00],
        '(' => [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02],
        ')' => [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08],
        '[' => [0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E],
        ']' => [0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E],
        '{' => [0x02, 0x04, 0x04, 0x08, 0x04, 0x04, 0x02],
        '}' => [0x08, 0x04, 0x04, 0x02, 0x04, 0x04, 0x08],
        '<' => [0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02],
        '>' => [0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08],
        '%' => [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03],
        '#' => [0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A],
        '|' => [0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
        '!' => [0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04],
        '?' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04],
        '\'' => [0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00],
        '"' => [0x0A, 0x0A, 0x0A, 0x00, 0x00, 0x00, 0x00],
        '^' => [0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00],
        '~' => [0x00, 0x00, 0x08, 0x15, 0x02, 0x00, 0x00],
        _ => greek_glyph(c),
    }
}

/// Glyphs for θ π χ σ ² √ ± ° (φ and μ descend); anything else gets [`MISSING_GLYPH`].
fn greek_glyph(c: char) -> [u8; 7] {
    match c {
        'θ' => [0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x0E],
        'π' => [0x00, 0x00, 0x1F, 0x0A, 0x0A, 0x0A, 0x13],
        'χ' => [0x00, 0x00, 0x19, 0x0A, 0x04, 0x0A, 0x13],
        'σ' => [0x00, 0x00, 0x0F, 0x12, 0x11, 0x11, 0x0E],
        '²' => [0x0C, 0x02, 0x04, 0x0E, 0x00, 0x00, 0x00],
        '√' => [0x03, 0x02, 0x02, 0x02, 0x12, 0x0A, 0x04],
        '±' => [0x04, 0x04, 0x1F, 0x04, 0x04, 0x00, 0x1F],
        '°' => [0x0C, 0x12, 0x12, 0x0C, 0x00, 0x00, 0x00],
        _ => MISSING_GLYPH,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A heat map over the usual (cos θ, φ) ranges.
    fn map<'a>(rows: usize, cols: usize, values: &'a [f64], scale: Scale) -> Heatmap<'a> {
        Heatmap {
            title: "test map",
            rows,
            cols,
            values,
            scale,
            row_label: "cos θ",
            col_label: "φ",
            row_range: (-1.0, 1.0),
            col_range: (-PI, PI),
        }
    }

    /// The pixel at the centre of cell (r, c) in the rendered image.
    fn cell_pixel(h: &Heatmap, img: &RgbImage, r: usize, c: usize) -> Rgb<u8> {
        let m = Mapping::fit(h.scale, cell_values(h));
        let has_bad = (0..h.rows * h.cols).any(|i| !cell(h, i).is_finite());
        let lay = Layout::new(h, &tick_labels(&m), has_bad);
        let x = lay.map_x + c as u32 * lay.cell_w + lay.cell_w / 2;
        let y = lay.map_y + (h.rows - 1 - r) as u32 * lay.cell_h + lay.cell_h / 2;
        *img.get_pixel(x, y)
    }

    /// A peaked lobe around cos θ = 1, brighter towards φ = 0, as integer counts.
    fn lobe_counts(rows: usize, cols: usize) -> Vec<f64> {
        let mut v = Vec::with_capacity(rows * cols);
        for r in 0..rows {
            let z = -1.0 + (r as f64 + 0.5) * 2.0 / rows as f64;
            for c in 0..cols {
                let phi = -PI + (c as f64 + 0.5) * 2.0 * PI / cols as f64;
                let pdf = (-(1.0 - z) / 0.05).exp() * (1.0 + 0.5 * phi.cos());
                v.push((1e5 * pdf).round());
            }
        }
        v
    }

    #[test]
    fn dimensions_are_sane() {
        let v = vec![1.0; 64 * 128];
        let img = render(&map(64, 128, &v, Scale::Sequential));
        assert!((520..900).contains(&img.width()), "width {}", img.width());
        assert!(
            (520..700).contains(&img.height()),
            "height {}",
            img.height()
        );
        let tiny = render(&map(1, 1, &[3.0], Scale::Sequential));
        assert!(tiny.width() > 32 && tiny.height() > 32);
    }

    #[test]
    fn max_cell_gets_top_colour_and_row_zero_is_at_the_bottom() {
        let mut v: Vec<f64> = (0..32).map(|i| i as f64 * 0.1).collect();
        v[2] = 100.0; // row 0, col 2
        let h = map(4, 8, &v, Scale::Sequential);
        let img = render(&h);
        assert_eq!(cell_pixel(&h, &img, 0, 2), Rgb(VIRIDIS[8]));
        assert_eq!(cell_pixel(&h, &img, 0, 0), Rgb(VIRIDIS[0]));
        // the bottom-most map row of pixels belongs to row 0
        let lay = Layout::new(&h, &tick_labels(&Mapping::fit(h.scale, &v)), false);
        let x = lay.map_x + 2 * lay.cell_w + 1;
        assert_eq!(
            *img.get_pixel(x, lay.map_y + lay.map_h - 1),
            Rgb(VIRIDIS[8])
        );
    }

    #[test]
    fn log_scale_max_cell_gets_top_colour() {
        let v = lobe_counts(16, 32);
        let h = map(16, 32, &v, Scale::Sequential);
        assert!(Mapping::fit(h.scale, &v).is_log());
        let (i, _) = v
            .iter()
            .enumerate()
            .fold((0, 0.0), |b, (i, &x)| if x > b.1 { (i, x) } else { b });
        let img = render(&h);
        assert_eq!(cell_pixel(&h, &img, i / 32, i % 32), Rgb(VIRIDIS[8]));
    }

    #[test]
    fn nan_cells_are_grey_and_do_not_break_the_scale() {
        let v = [0.0, 1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 2.0];
        let h = map(2, 3, &v, Scale::Sequential);
        let img = render(&h);
        assert_eq!(cell_pixel(&h, &img, 0, 2), NAN_GREY);
        assert_eq!(cell_pixel(&h, &img, 1, 0), NAN_GREY);
        assert_eq!(cell_pixel(&h, &img, 1, 1), NAN_GREY);
        assert_eq!(cell_pixel(&h, &img, 0, 0), Rgb(VIRIDIS[0]));
        assert_eq!(cell_pixel(&h, &img, 1, 2), Rgb(VIRIDIS[8]));
        // a short slice: missing cells are NaN too
        let short = map(2, 3, &v[..4], Scale::Diverging);
        assert_eq!(cell_pixel(&short, &render(&short), 1, 2), NAN_GREY);
    }

    #[test]
    fn diverging_zero_is_white_and_extremes_are_blue_and_red() {
        let v = [-2.0, 0.0, 1.0, 0.5];
        let h = map(2, 2, &v, Scale::Diverging);
        let img = render(&h);
        let zero = cell_pixel(&h, &img, 0, 1);
        assert!(zero.0.iter().all(|&c| c > 230), "{zero:?}");
        assert_eq!(cell_pixel(&h, &img, 0, 0), Rgb(BLUE_WHITE_RED[0]));
        let pos = cell_pixel(&h, &img, 1, 0);
        assert!(pos.0[0] > pos.0[2], "positive is reddish: {pos:?}");
    }

    #[test]
    fn degenerate_maps_do_not_divide_by_zero() {
        for scale in [Scale::Sequential, Scale::Diverging] {
            let zeros = vec![0.0; 12];
            let h = map(3, 4, &zeros, scale);
            let img = render(&h);
            let c = cell_pixel(&h, &img, 1, 1);
            assert!(c != NAN_GREY);
            let nans = vec![f64::NAN; 12];
            render(&map(3, 4, &nans, scale));
            render(&map(0, 0, &[], scale));
            render(&map(0, 5, &[], scale));
        }
        assert_eq!(
            Mapping::fit(Scale::Sequential, &[0.0; 4]),
            Mapping::Linear { lo: 0.0, hi: 1.0 }
        );
    }

    #[test]
    fn numbers_are_compact() {
        let cases = [
            (0.0, "0"),
            (12000.0, "1.2e4"),
            (-3.5, "-3.5"),
            (1.0, "1"),
            (0.05, "0.05"),
            (7.777, "7.78"),
            (123.4, "123"),
            (1e-5, "1e-5"),
            (-2.5e-7, "-2.5e-7"),
            (1e5, "1e5"),
            (f64::NAN, "nan"),
        ];
        for (v, s) in cases {
            assert_eq!(fmt_num(v), s, "{v}");
        }
        assert_eq!(axis_text(-PI), "-π");
        assert_eq!(axis_text(2.0 * PI), "2π");
        assert_eq!(axis_text(-1.0), "-1");
    }

    #[test]
    fn text_on_unicode_and_edges_does_not_panic() {
        let mut img = RgbImage::new(40, 20);
        let s = "χ²/ndf = 1.02 θφ√∑ 🎉 \u{0301}\n\0 ÅÉ 日本語";
        for (x, y) in [
            (0, 0),
            (-50, -50),
            (30, 15),
            (i64::MAX / 4, 0),
            (0, i64::MIN / 4),
        ] {
            draw_text(&mut img, x, y, s, INK);
        }
        let long = "x".repeat(2000);
        for title in [s, long.as_str(), ""] {
            let v = [1.0, 2.0];
            let h = Heatmap {
                title,
                row_label: title,
                col_label: title,
                ..map(1, 2, &v, Scale::Diverging)
            };
            let img = render(&h);
            assert!(img.width() <= MAX_WIDTH + 2 * text_width(title));
        }
    }

    proptest::proptest! {
        #[test]
        fn any_string_renders(s in "\\PC*", x in -100i64..100, y in -100i64..100) {
            let mut img = RgbImage::new(64, 32);
            draw_text(&mut img, x, y, &s, INK);
            let v = [0.0, -1.0, 1.0, f64::NAN];
            let h = Heatmap { title: &s, row_label: &s, col_label: &s, ..map(2, 2, &v, Scale::Sequential) };
            render(&h);
        }
    }

    #[test]
    fn write_png_round_trips() {
        let dir = std::env::temp_dir();
        let v = lobe_counts(64, 128);
        let h = Heatmap {
            title: "lobe counts: exp(-(1-cos θ)/0.05)",
            ..map(64, 128, &v, Scale::Sequential)
        };
        let path = dir.join("heatmap_example.png");
        write_png(&h, &path).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back, render(&h));

        let res: Vec<f64> = (0..64 * 128).map(|i| residual(i, 64, 128)).collect();
        let h = Heatmap {
            title: "residual (obs-exp)/√exp",
            ..map(64, 128, &res, Scale::Diverging)
        };
        write_png(&h, &dir.join("heatmap_diverging.png")).unwrap();
        assert!(write_png(&h, &dir.join("no/such/dir/x.png")).is_err());
    }

    /// Synthetic residuals: LCG noise of unit scale plus a positive band near cos θ = 0.5 and
    /// a negative blob at φ ≈ -π/2, with a few NaN cells.
    fn residual(i: usize, rows: usize, cols: usize) -> f64 {
        let (r, c) = (i / cols, i % cols);
        let z = -1.0 + (r as f64 + 0.5) * 2.0 / rows as f64;
        let phi = -PI + (c as f64 + 0.5) * 2.0 * PI / cols as f64;
        let mut s = (i as u64 + 1)
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        s ^= s >> 33;
        let noise = (s % 2000) as f64 / 1000.0 - 1.0;
        let band = 4.0 * (-((z - 0.5) / 0.1).powi(2)).exp();
        let blob = -5.0 * (-((z + 0.3).powi(2) + (phi + PI / 2.0).powi(2)) / 0.05).exp();
        if r == 10 && c % 16 == 0 {
            f64::NAN
        } else {
            noise + band + blob
        }
    }
}
