//! `tradeoff.png`: L1 against time on log-log axes, one panel per sampler, one curve per
//! precision, with the `c/√N` line an exact sampler at f32-accurate speed would follow;
//! drawn by `plotters` into an RGB buffer.

use crate::experiments::tradeoff::{SweepLobe, Precision, Sweep, SweepPoint};
use crate::report::text;
use image::RgbImage;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

/// Size of one panel, and the height of the legend above the panels.
const PANEL: (u32, u32) = (460, 340);
const LEGEND_H: u32 = 40;
use crate::report::text::PLOTTERS_FONT as FONT;
const TEXT_PX: f64 = 16.0;
const GREY: RGBColor = RGBColor(120, 120, 120);

fn colour(p: Precision) -> RGBColor {
    match p {
        Precision::F32Fast => RGBColor(230, 120, 20),
        Precision::F32Accurate => RGBColor(30, 90, 200),
        Precision::F64 => RGBColor(20, 150, 60),
    }
}

/// The picture: a legend line, then the panels two to a row.
pub fn plot(sweep: &Sweep) -> anyhow::Result<RgbImage> {
    text::register_plotters_font();
    let panels = sweep.lobes.len().max(1) as u32;
    let cols = panels.min(2);
    let rows = panels.div_ceil(cols);
    let (w, h) = (PANEL.0 * cols, PANEL.1 * rows + LEGEND_H);
    let mut buf = vec![0; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (legend, grid) = root.split_vertically(LEGEND_H);
        draw_legend(&legend)?;
        for (area, lobe) in grid.split_evenly((rows as usize, cols as usize)).iter().zip(&sweep.lobes) {
            draw_panel(area, sweep, lobe)?;
        }
        root.present()?;
    }
    Ok(RgbImage::from_raw(w, h, buf).expect("the buffer holds w × h RGB pixels"))
}

/// One swatch and name per precision, then the dashed reference line's.
fn draw_legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let font = (FONT, TEXT_PX).into_font().color(&BLACK);
    let (mut x, y) = (12, LEGEND_H as i32 / 2);
    let mut entry = |line: &dyn Fn(i32) -> anyhow::Result<()>, name: &str| -> anyhow::Result<()> {
        line(x)?;
        area.draw(&Text::new(name.to_string(), (x + 30, y - TEXT_PX as i32 / 2 - 1), font.clone()))?;
        x += 30 + area.estimate_text_size(name, &font)?.0 as i32 + 24;
        Ok(())
    };
    for prec in Precision::ALL {
        let style = colour(prec).stroke_width(4);
        entry(&|x| Ok(area.draw(&PathElement::new([(x, y), (x + 24, y)], style))?), prec.name())?;
    }
    let dashed = |x| Ok(area.draw(&DashedPathElement::new([(x, y), (x + 24, y)], 6, 6, GREY.stroke_width(2)))?);
    entry(&dashed, "c/√N, f32-accurate speed")
}

/// log10 of a point's (seconds, L1), floored away from log 0.
fn log_point(p: &SweepPoint) -> (f64, f64) {
    (p.seconds().max(1e-9).log10(), p.l1.max(1e-12).log10())
}

/// The decades `floor(min)..=ceil(max)` of `values` (at least one decade wide).
fn decades(values: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let lo = values.clone().fold(f64::MAX, f64::min).floor();
    let hi = values.fold(f64::MIN, f64::max).ceil();
    (lo, hi.max(lo + 1.0))
}

/// One sampler's panel: its points by precision, on log10 axes labelled by decade.
fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, sweep: &Sweep, lobe: &SweepLobe) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let title = format!("{} (L1 vs seconds)", lobe.sampler);
    let pts: Vec<&SweepPoint> = sweep.points.iter().filter(|p| p.sampler == lobe.sampler).collect();
    if pts.is_empty() {
        area.titled(&title, (FONT, TEXT_PX))?;
        return Ok(());
    }
    let logs: Vec<(f64, f64)> = pts.iter().map(|p| log_point(p)).collect();
    let (x0, x1) = decades(logs.iter().map(|l| l.0));
    let (y0, y1) = decades(logs.iter().map(|l| l.1));
    let mut chart = ChartBuilder::on(area)
        .caption(&title, (FONT, TEXT_PX))
        .margin(10)
        .margin_right(24)
        .x_label_area_size(44)
        .y_label_area_size(52)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    // one label per decade: with span + 1 labels allowed, plotters' steps are whole decades
    let decade = |v: &f64| format!("1e{}", v.round() as i32);
    chart
        .configure_mesh()
        .x_labels((x1 - x0) as usize + 1)
        .y_labels((y1 - y0) as usize + 1)
        .max_light_lines(0)
        .x_label_formatter(&decade)
        .y_label_formatter(&decade)
        .x_desc("seconds")
        .y_desc("L1")
        .label_style((FONT, TEXT_PX - 2.0))
        .axis_desc_style((FONT, TEXT_PX))
        .bold_line_style(RGBColor(225, 225, 225))
        .draw()?;
    // L1 = c/√N with N = t / (seconds per sample of f32-accurate at its largest N):
    // log L1 = log c − (log t − log sps)/2, clipped to the panel's y range
    if let Some(a) = pts.iter().rfind(|p| p.precision == Precision::F32Accurate) {
        let (lc, ls) = (lobe.l1_noise_coefficient.log10(), (a.seconds() / a.samples as f64).log10());
        let f = |lx: f64| lc - 0.5 * (lx - ls);
        let (a, z) = (x0.max(ls + 2.0 * (lc - y1)), x1.min(ls + 2.0 * (lc - y0)));
        if a < z {
            chart.draw_series(DashedLineSeries::new([(a, f(a)), (z, f(z))], 6, 6, GREY.stroke_width(2)))?;
        }
    }
    for prec in Precision::ALL {
        let curve: Vec<(f64, f64)> =
            pts.iter().zip(&logs).filter(|(p, _)| p.precision == prec).map(|(_, &l)| l).collect();
        let c = colour(prec);
        chart.draw_series(LineSeries::new(curve.iter().copied(), c.stroke_width(2)))?;
        chart.draw_series(curve.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::compare::AngleCheck;

    fn point(sampler: &str, precision: Precision, samples: u64, seconds: f64) -> SweepPoint {
        SweepPoint {
            sampler: sampler.into(),
            precision,
            samples,
            wall_seconds: seconds,
            gpu_seconds: None,
            chi2: 1.0,
            dof: 1,
            p_value: 0.5,
            l1: 30.0 / (samples as f64).sqrt(),
            l1_noise: 30.0 / (samples as f64).sqrt(),
            angle: AngleCheck { compared: 0, validity_mismatches: 0, max_angle_rad: 0.0, mean_angle_rad: 0.0 },
        }
    }

    fn lobe(sampler: &str) -> SweepLobe {
        SweepLobe {
            sampler: sampler.into(),
            alpha: 0.3,
            incident_theta_deg: 45.0,
            l1_noise_coefficient: 30.0,
            quadrature_max_error_sigma_at_1e8: 0.0,
        }
    }

    /// Pixels of exactly `c` in the columns `xs`, below the legend.
    fn count(img: &RgbImage, c: RGBColor, xs: std::ops::Range<u32>) -> usize {
        img.enumerate_pixels().filter(|(x, y, p)| xs.contains(x) && *y >= LEGEND_H && p.0 == [c.0, c.1, c.2]).count()
    }

    #[test]
    fn each_panel_shows_its_own_curves_and_the_reference_line() {
        let mut sweep = Sweep { lobes: vec![lobe("left"), lobe("right-empty")], ..Default::default() };
        for k in 0..4 {
            let n = 1u64 << (12 + 2 * k);
            sweep.points.push(point("left", Precision::F32Accurate, n, n as f64 * 1e-9));
            sweep.points.push(point("left", Precision::F64, n, n as f64 * 4e-9));
        }
        let img = plot(&sweep).unwrap();
        assert_eq!(img.dimensions(), (2 * PANEL.0, PANEL.1 + LEGEND_H));
        let (left, right) = (0..PANEL.0, PANEL.0..2 * PANEL.0);
        for prec in [Precision::F32Accurate, Precision::F64] {
            assert!(count(&img, colour(prec), left.clone()) > 100, "{prec:?} curve missing");
            assert_eq!(count(&img, colour(prec), right.clone()), 0, "{prec:?} drawn in the empty panel");
        }
        assert_eq!(count(&img, colour(Precision::F32Fast), left.clone()), 0, "no f32-fast points");
        assert!(count(&img, GREY, left) > 50, "the c/√N line is missing");
    }
}
