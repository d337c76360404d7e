//! Bin-by-bin charts of a measured histogram against its expectation, drawn by `plotters`: the
//! two marginals of a 2-D histogram (`marginals.png`: over cos θ and over φ) and the items of a
//! discrete distribution (`bars.png`).
//!
//! Each bin shows the measured count as a bar, the expected count `e` as a black tick and the
//! band `e ± 2σ` with `σ = √e`, the Poisson approximation of one bin's multinomial spread
//! (`Var = N p (1 − p) ≤ N p`). A correct sampler keeps about 95% of its bars' tops inside the
//! band; bars outside it are drawn red, so the bins that drive χ² stand out.
//!
//! Where a panel's counts span more than three decades (a narrow lobe's tails, the rows near
//! the horizon) its count axis is logarithmic ("samples per bin (log)"), so the small bins stay
//! readable; a negative expected count (a pdf below 0) keeps the axis linear and extends it below
//! 0, where the tick is drawn.

use super::text::{PLOTTERS_FONT as FONT, register_plotters_font};
use image::RgbImage;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One chart: bins with edges `edges[i]..edges[i + 1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Drawn above the chart.
    pub title: String,
    /// The horizontal axis, e.g. "cos θ".
    pub x_label: &'static str,
    /// `measured.len() + 1` increasing bin edges.
    pub edges: Vec<f64>,
    pub measured: Vec<f64>,
    pub expected: Vec<f64>,
}

/// Size of one panel, and the height of the caption and legend above the panels.
const PANEL: (u32, u32) = (560, 380);
const HEAD_H: u32 = 64;
/// The legend's width: the narrowest picture.
const LEGEND_W: u32 = 860;
const TEXT_PX: f64 = 16.0;
const BAR: RGBColor = RGBColor(240, 150, 40);
const BAR_OUT: RGBColor = RGBColor(210, 30, 30);
const BAND: RGBColor = RGBColor(170, 200, 235);

/// Whether a measured count lies outside its band `e ± 2√e`.
pub fn outside_band(measured: f64, expected: f64) -> bool {
    (measured - expected).abs() > 2.0 * expected.max(0.0).sqrt()
}

/// The picture: `caption` and a legend on top, then the panels side by side.
pub fn plot(caption: &str, panels: &[Panel]) -> anyhow::Result<RgbImage> {
    register_plotters_font();
    let n = panels.len().max(1) as u32;
    // wide enough for the caption (`text_width` measures at 18 px, the charts write at 16)
    let caption_w = (super::text::text_width(caption) as f64 * TEXT_PX / 18.0) as u32 + 24;
    let (w, h) = ((PANEL.0 * n).max(caption_w).max(LEGEND_W), PANEL.1 + HEAD_H);
    let mut buf = vec![0; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (head, body) = root.split_vertically(HEAD_H);
        draw_head(&head, caption)?;
        for (area, panel) in body.split_evenly((1, n as usize)).iter().zip(panels) {
            draw_panel(area, panel)?;
        }
        root.present()?;
    }
    Ok(RgbImage::from_raw(w, h, buf).expect("the buffer holds w × h RGB pixels"))
}

/// Renders [`plot`] and writes it as a PNG to `path`, atomically.
pub fn write_png(path: &Path, caption: &str, panels: &[Panel]) -> anyhow::Result<()> {
    let png = super::png::encode(&plot(caption, panels)?)?;
    Ok(super::atomic::write_atomic(path, &png)?)
}

/// The caption line, then one swatch and name per element of the charts.
fn draw_head<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, caption: &str) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let font = (FONT, TEXT_PX).into_font().color(&BLACK);
    area.draw(&Text::new(caption.to_string(), (12, 8), font.clone()))?;
    let (mut x, y) = (12, 44);
    let mut entry = |swatch: &dyn Fn(i32) -> anyhow::Result<()>, name: &str| -> anyhow::Result<()> {
        swatch(x)?;
        area.draw(&Text::new(name.to_string(), (x + 30, y - TEXT_PX as i32 / 2 - 1), font.clone()))?;
        x += 30 + area.estimate_text_size(name, &font)?.0 as i32 + 24;
        Ok(())
    };
    let rect = |c: RGBColor| move |x: i32| Ok(area.draw(&Rectangle::new([(x, y - 7), (x + 22, y + 7)], c.filled()))?);
    entry(&rect(BAR), "measured")?;
    entry(&rect(BAR_OUT), "outside the band (1 bin in 20 by chance)")?;
    entry(&|x| Ok(area.draw(&PathElement::new([(x, y), (x + 22, y)], BLACK.stroke_width(2)))?), "expected")?;
    entry(&rect(BAND), "expected ± 2σ (σ = √expected)")
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let bins = p.measured.len().min(p.expected.len()).min(p.edges.len().saturating_sub(1));
    let band = |i: usize| 2.0 * p.expected[i].max(0.0).sqrt();
    let top = (0..bins).map(|i| p.measured[i].max(p.expected[i] + band(i))).fold(0.0, f64::max);
    let top = if top > 0.0 { top * 1.05 } else { 1.0 };
    let lowest = (0..bins).map(|i| p.expected[i]).fold(0.0, f64::min);
    let log = log_axis(&p.measured[..bins], &p.expected[..bins]);
    // the count axis: log₁₀ of the count from half a count up, or the count itself
    let y = |v: f64| if log { v.max(LOG_FLOOR).log10() } else { v };
    let (y0, y1) = if log { (LOG_FLOOR.log10(), top.log10()) } else { (1.05 * lowest, top) };
    let (x0, x1) = match (p.edges.first(), p.edges.last()) {
        (Some(&a), Some(&b)) if b > a => (a, b),
        _ => (0.0, 1.0),
    };
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, (FONT, TEXT_PX))
        .margin(10)
        .margin_right(20)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .x_desc(p.x_label)
        .y_desc(if log { "samples per bin (log)" } else { "samples per bin" })
        .y_label_formatter(&|v| super::label::compact(if log { 10f64.powf(*v) } else { *v }))
        // a tick computed as a sum of steps lands near 0 as ±1e-16: shown as 0
        .x_label_formatter(&|v| super::label::compact(if v.abs() < 1e-9 * (x1 - x0) { 0.0 } else { *v }))
        .label_style((FONT, TEXT_PX - 2.0))
        .axis_desc_style((FONT, TEXT_PX))
        .bold_line_style(RGBColor(230, 230, 230))
        .draw()?;
    let edge = |i: usize| (p.edges[i], p.edges[i + 1]);
    chart.draw_series((0..bins).map(|i| {
        let (a, b) = edge(i);
        let e = p.expected[i];
        Rectangle::new([(a, y((e - band(i)).max(0.0))), (b, y(e + band(i)))], BAND.filled())
    }))?;
    chart.draw_series((0..bins).map(|i| {
        let (a, b) = edge(i);
        let inset = 0.15 * (b - a);
        let colour = if outside_band(p.measured[i], p.expected[i]) { BAR_OUT } else { BAR };
        Rectangle::new([(a + inset, y(0.0)), (b - inset, y(p.measured[i]))], colour.mix(0.85).filled())
    }))?;
    chart.draw_series((0..bins).map(|i| {
        let (a, b) = edge(i);
        PathElement::new([(a, y(p.expected[i])), (b, y(p.expected[i]))], BLACK.stroke_width(2))
    }))?;
    Ok(())
}

/// The bottom of a logarithmic count axis: half a count (an empty bin's bar has no height).
const LOG_FLOOR: f64 = 0.5;

/// Whether a panel's count axis is logarithmic: its positive counts span more than three
/// decades, and no expected count is negative.
pub fn log_axis(measured: &[f64], expected: &[f64]) -> bool {
    if expected.iter().any(|&e| e < 0.0) {
        return false;
    }
    let positive = measured.iter().chain(expected).copied().filter(|&v| v >= LOG_FLOOR);
    let (lo, hi) = positive.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    hi > 1000.0 * lo
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_band_is_two_poisson_sigmas() {
        // e = 100: σ = 10, the band is 80..120
        assert!(!outside_band(119.0, 100.0) && !outside_band(81.0, 100.0));
        assert!(outside_band(121.0, 100.0) && outside_band(79.0, 100.0));
        // nothing expected: any sample is outside
        assert!(outside_band(1.0, 0.0) && !outside_band(0.0, 0.0));
    }

    #[test]
    fn small_counts_get_a_log_axis() {
        assert!(!log_axis(&[100.0, 400.0, 0.0], &[100.0, 400.0, 0.0]));
        assert!(log_axis(&[1e6, 3.0, 0.0], &[1e6, 2.5, 0.1]));
        assert!(!log_axis(&[1e6, 3.0], &[1e6, -2.0]), "a negative expectation keeps the axis linear");
    }

    #[test]
    fn a_chart_draws_bars_to_their_heights() {
        let panel = |measured: Vec<f64>| Panel {
            title: "items".into(),
            x_label: "item",
            edges: vec![-0.5, 0.5, 1.5, 2.5],
            measured,
            expected: vec![100.0, 400.0, 0.0],
        };
        let img = plot("caption", &[panel(vec![100.0, 400.0, 0.0])]).unwrap();
        assert_eq!((img.width(), img.height()), (LEGEND_W, PANEL.1 + HEAD_H));
        let count = |img: &RgbImage, c: RGBColor| img.pixels().filter(|p| p.0 == [c.0, c.1, c.2]).count();
        // bars inside their bands: no red; a bar far outside its band (and a sample where
        // nothing is expected) turns red
        let red = |img: &RgbImage| {
            img.enumerate_pixels().filter(|(_, y, p)| *y >= HEAD_H && p.0[0] > 180 && p.0[1] < 80 && p.0[2] < 80).count()
        };
        assert_eq!(red(&img), 0);
        let bad = plot("caption", &[panel(vec![100.0, 200.0, 30.0])]).unwrap();
        assert!(red(&bad) > 100, "{}", red(&bad));
        // the band is drawn where counts are expected
        assert!(count(&img, BAND) > 100);
    }
}
