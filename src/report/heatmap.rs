//! Heat maps of 2-D histograms, rendered to PNG.
//!
//! A [`Heatmap`] is a row-major grid of values over (cos θ, φ). [`render`] lays it out as an
//! RGB image: the cells scaled up to a few pixels each (row 0 at the *bottom*), a vertical
//! colour bar with min/mid/max tick labels on the right (captioned "log" on a log scale, see
//! [`super::colour`]), a grey "nan" key when some cells are not finite (and, when the map
//! names one, a magenta key for cells marked −∞: e.g. a residual where the expectation is below
//! 0), the title on top and the axis range labels. [`write_png`] writes the image atomically ([`super::atomic`]).

use super::colour::{MARKED, NAN_GREY, colour, value_colour};
use super::label::{axis_text, compact};
use super::text::{LINE_H, draw_text, text_width};
use image::{Rgb, RgbImage};
use std::io;
use std::path::Path;

pub use super::colour::{Mapping, Scale};

/// A 2-D histogram to draw.
#[derive(Debug, Clone, Copy)]
pub struct Heatmap<'a> {
    /// Title drawn at the top, a line per `\n` (any text; characters the font lacks become a box).
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
    /// What a cell of value −∞ means, written beside its [`MARKED`] swatch under the colour bar
    /// (e.g. "pdf < 0"); empty: −∞ is drawn grey like NaN.
    pub marked_key: &'a str,
}

/// Background.
const BG: Rgb<u8> = Rgb([255, 255, 255]);
/// Text and tick colour.
const INK: Rgb<u8> = Rgb([20, 20, 20]);
/// Frame around the map and the colour bar.
const FRAME: Rgb<u8> = Rgb([70, 70, 70]);

/// Outer margin and small gaps.
const PAD: u32 = 12;
const GAP: u32 = 6;
/// The map aims at about this many pixels per side; cells are at most `MAX_CELL` wide.
const MAP_TARGET: usize = 512;
const MAX_CELL: usize = 32;
/// The map is at least this tall, so the three tick labels beside it and the three row
/// labels (bottom, name, top) do not overlap.
const MIN_MAP_H: u32 = 3 * LINE_H + 2 * GAP;
/// Colour bar width and its distance from the map.
const BAR_W: u32 = 20;
const BAR_GAP: u32 = 20;
/// Length of the colour bar's tick marks.
const TICK_LEN: u32 = 4;
/// Widest canvas a long title may ask for; beyond it the title is clipped.
const MAX_WIDTH: u32 = 4096;

/// Renders the heat map, colour bar, title and axis labels into an RGB image.
pub fn render(h: &Heatmap) -> RgbImage {
    render_scaled(h, Mapping::fit(h.scale, cell_values(h)))
}

/// As [`render`], on a colour scale fitted elsewhere: maps drawn on one [`Mapping`] (fitted to
/// all their values) can be compared colour for colour.
pub fn render_scaled(h: &Heatmap, mapping: Mapping) -> RgbImage {
    let ticks = tick_labels(&mapping);
    let keys = keys(h);
    let lay = Layout::new(h, &ticks, &keys);
    let mut img = RgbImage::from_pixel(lay.width, lay.height, BG);
    draw_cells(&mut img, h, &mapping, &lay);
    draw_colour_bar(&mut img, h.scale, &mapping, &ticks, &lay);
    draw_keys(&mut img, &keys, &lay);
    draw_axis_labels(&mut img, h, &lay);
    for (k, line) in h.title.split('\n').enumerate() {
        let x = (lay.width as i64 - text_width(line) as i64) / 2;
        draw_text(&mut img, x.max(PAD as i64), (PAD + k as u32 * LINE_H) as i64, line, INK);
    }
    img
}

/// Renders `h` and writes it as a PNG to `path`, atomically: the file goes to a temporary
/// name in the same directory, is synced, and is then renamed over `path`.
pub fn write_png(h: &Heatmap, path: &Path) -> io::Result<()> {
    write_image(&render(h), path)
}

/// As [`write_png`], on the colour scale `mapping` ([`render_scaled`]).
pub fn write_png_scaled(h: &Heatmap, mapping: Mapping, path: &Path) -> io::Result<()> {
    write_image(&render_scaled(h, mapping), path)
}

fn write_image(img: &RgbImage, path: &Path) -> io::Result<()> {
    let png = super::png::encode(img).map_err(io::Error::other)?;
    super::atomic::write_atomic(path, &png)
}

/// Value of cell `i` (row-major); missing cells read as NaN.
fn cell(h: &Heatmap, i: usize) -> f64 {
    h.values.get(i).copied().unwrap_or(f64::NAN)
}

/// Whether a value is drawn [`MARKED`]: −∞ on a map that names what it means.
fn marked(h: &Heatmap, v: f64) -> bool {
    v == f64::NEG_INFINITY && !h.marked_key.is_empty()
}

/// The colour of one cell's value.
fn cell_colour(h: &Heatmap, mapping: &Mapping, v: f64) -> Rgb<u8> {
    if marked(h, v) { MARKED } else { value_colour(h.scale, mapping, v) }
}

/// The keys under the colour bar, each a swatch and its text: "nan" when some cell is not finite
/// (and not marked), the map's `marked_key` when some cell is marked.
fn keys<'a>(h: &Heatmap<'a>) -> Vec<(Rgb<u8>, &'a str)> {
    let values = (0..h.rows * h.cols).map(|i| cell(h, i));
    let (mut bad, mut mark) = (false, false);
    for v in values {
        bad |= !v.is_finite() && !marked(h, v);
        mark |= marked(h, v);
    }
    let mut keys = Vec::new();
    if bad {
        keys.push((NAN_GREY, "nan"));
    }
    if mark {
        keys.push((MARKED, h.marked_key));
    }
    keys
}

/// The values that belong to cells (a longer slice's tail is ignored).
fn cell_values<'a>(h: &Heatmap<'a>) -> &'a [f64] {
    &h.values[..h.values.len().min(h.rows.saturating_mul(h.cols))]
}

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
    /// Places map, colour bar and labels; `ticks` are the colour bar labels, `keys` the keys
    /// drawn under the bar, one a line.
    fn new(h: &Heatmap, ticks: &[String; 3], keys: &[(Rgb<u8>, &str)]) -> Self {
        let cell_w = cell_size(h.cols);
        let cell_h = cell_size(h.rows).max(MIN_MAP_H.div_ceil(h.rows.max(1) as u32));
        let (map_w, map_h) = (cell_w * h.cols as u32, cell_h * h.rows as u32);
        let row_texts = [
            axis_text(h.row_range.0),
            axis_text(h.row_range.1),
            h.row_label.into(),
        ];
        let left = row_texts.iter().map(|s| text_width(s)).max().unwrap_or(0) + GAP + PAD;
        // the title's lines, then the colour-bar caption line, then the map
        let title_lines = h.title.split('\n').count() as u32;
        let map_y = PAD + title_lines * LINE_H + GAP + LINE_H + GAP + LINE_H / 2;
        let bar_x = left + map_w + BAR_GAP;
        let tick_w = ticks.iter().map(|s| text_width(s)).max().unwrap_or(0);
        let key_w = keys.iter().map(|(_, k)| LINE_H + GAP + text_width(k)).max().unwrap_or(0);
        let right = bar_x + BAR_W + TICK_LEN + GAP + tick_w.max(key_w).max(text_width("log")) + PAD;
        let title_w = h.title.split('\n').map(text_width).max().unwrap_or(0);
        let width = right.max((title_w + 2 * PAD).min(MAX_WIDTH));
        // below the map: the column labels, and (lower, clear of the last tick label) the keys
        let height = key_y(map_y, map_h) + keys.len().max(1) as u32 * LINE_H + PAD;
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
            let rgb = cell_colour(h, mapping, cell(h, r * h.cols + c));
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

/// Top of the first key: under the colour bar, below the half line the bottom tick label
/// overhangs.
fn key_y(map_y: u32, map_h: u32) -> u32 {
    map_y + map_h + LINE_H / 2 + GAP
}

/// Draws each key's swatch and text under the colour bar, one a line.
fn draw_keys(img: &mut RgbImage, keys: &[(Rgb<u8>, &str)], lay: &Layout) {
    for (k, (rgb, text)) in keys.iter().enumerate() {
        let y = key_y(lay.map_y, lay.map_h) + k as u32 * LINE_H;
        fill_rect(img, lay.bar_x, y + 2, LINE_H - 4, LINE_H - 4, *rgb);
        draw_text(img, (lay.bar_x + LINE_H + GAP) as i64, y as i64, text, INK);
    }
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
fn fill_rect(img: &mut RgbImage, x: u32, y: u32, w: u32, h: u32, rgb: Rgb<u8>) {
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

/// Colour bar labels at t = 0, ½, 1 (bottom, middle, top).
fn tick_labels(m: &Mapping) -> [String; 3] {
    [0.0, 0.5, 1.0].map(|t| compact(m.value_at(t)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::colour::{BLUE_WHITE_RED, VIRIDIS};
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
            marked_key: "",
        }
    }

    /// The pixel at the centre of cell (r, c) in the rendered image.
    fn cell_pixel(h: &Heatmap, img: &RgbImage, r: usize, c: usize) -> Rgb<u8> {
        let m = Mapping::fit(h.scale, cell_values(h));
        let lay = Layout::new(h, &tick_labels(&m), &keys(h));
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
        let lay = Layout::new(&h, &tick_labels(&Mapping::fit(h.scale, &v)), &[]);
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
    fn marked_cells_are_magenta_with_their_key() {
        let v = [-1.0, 1.0, f64::NEG_INFINITY, f64::NAN];
        let plain = map(2, 2, &v, Scale::Diverging);
        let h = Heatmap { marked_key: "pdf < 0", ..plain };
        let img = render(&h);
        assert_eq!(cell_pixel(&h, &img, 1, 0), MARKED);
        assert_eq!(cell_pixel(&h, &img, 1, 1), NAN_GREY);
        assert_eq!(keys(&h), [(NAN_GREY, "nan"), (MARKED, "pdf < 0")]);
        // the key's swatch is drawn under the bar: more magenta pixels than the one cell holds
        let lay = Layout::new(&h, &tick_labels(&Mapping::fit(h.scale, &v)), &keys(&h));
        let magenta = img.pixels().filter(|p| **p == MARKED).count() as u32;
        assert_eq!(magenta, lay.cell_w * lay.cell_h + (LINE_H - 4) * (LINE_H - 4));
        // without a key −∞ is grey like NaN, and no key is drawn for it
        assert_eq!(cell_pixel(&plain, &render(&plain), 1, 0), NAN_GREY);
        assert_eq!(keys(&plain), [(NAN_GREY, "nan")]);
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
    fn unicode_and_long_titles_render() {
        let s = "χ²/ndf = 1.02 θφ√∑ 🎉 \u{0301}\n\0 ÅÉ 日本語";
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
        fn any_string_renders(s in "\\PC*") {
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
