//! Text in the PNG reports: DejaVu Sans (embedded by the `dejavu` crate, licence in that
//! crate's `assets/`), laid out and rasterised by `ab_glyph` at [`LINE_H`] pixels per line.
//! Characters the font lacks are drawn as its `.notdef` box, so any `&str` is safe to draw.

use ab_glyph::{Font, FontRef, GlyphId, PxScale, ScaleFont, point};
use image::{Rgb, RgbImage};
use std::sync::LazyLock;

/// Height of one line of text in pixels (ascent − descent of the font at this scale).
pub const LINE_H: u32 = 18;

const SCALE: PxScale = PxScale {
    x: LINE_H as f32,
    y: LINE_H as f32,
};

/// The font file's bytes, also handed to `plotters` for the tradeoff plot.
pub fn font_bytes() -> &'static [u8] {
    dejavu::sans::regular()
}

/// The family name the embedded font goes by in `plotters` charts ([`register_plotters_font`]).
pub const PLOTTERS_FONT: &str = "sans-serif";

/// Hands the embedded font to `plotters` as [`PLOTTERS_FONT`] (once per process; call before
/// drawing a chart).
pub fn register_plotters_font() {
    static REGISTERED: std::sync::Once = std::sync::Once::new();
    REGISTERED.call_once(|| {
        plotters::style::register_font(PLOTTERS_FONT, plotters::style::FontStyle::Normal, font_bytes())
            .unwrap_or_else(|_| panic!("the embedded font parses"));
    });
}

static FONT: LazyLock<FontRef<'static>> =
    LazyLock::new(|| FontRef::try_from_slice(font_bytes()).expect("the embedded DejaVu Sans parses"));

/// The pen position of each glyph of `s` along the line (kerning included), and the
/// advance past the last one.
fn layout(s: &str) -> (Vec<(GlyphId, f32)>, f32) {
    let font = FONT.as_scaled(SCALE);
    let mut pen = 0.0;
    let mut prev: Option<GlyphId> = None;
    let mut glyphs = Vec::with_capacity(s.len());
    for c in s.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            pen += font.kern(p, id);
        }
        glyphs.push((id, pen));
        pen += font.h_advance(id);
        prev = Some(id);
    }
    (glyphs, pen)
}

/// Width in pixels of `s` drawn by [`draw_text`].
pub fn text_width(s: &str) -> u32 {
    layout(s).1.ceil() as u32
}

/// Draws `s` with the top-left corner of its line box at (x, y), anti-aliased over what is
/// there and clipped to the image.
pub fn draw_text(img: &mut RgbImage, x: i64, y: i64, s: &str, rgb: Rgb<u8>) {
    let (w, h) = (i64::from(img.width()), i64::from(img.height()));
    // a glyph reaches at most one line height beyond its pen position and line box
    let reach = 2 * i64::from(LINE_H);
    if y <= -reach || y >= h || x >= w {
        return;
    }
    let ascent = FONT.as_scaled(SCALE).ascent();
    let (glyphs, _) = layout(s);
    for (id, pen) in glyphs {
        // skip glyphs far outside the image before converting to f32 coordinates
        let gx = x.saturating_add(pen as i64);
        if gx <= -reach || gx >= w {
            continue;
        }
        let glyph = id.with_scale_and_position(SCALE, point(gx as f32 + pen.fract(), y as f32 + ascent));
        let Some(outline) = FONT.outline_glyph(glyph) else { continue };
        let min = outline.px_bounds().min;
        outline.draw(|px, py, coverage| {
            let (px, py) = (min.x as i64 + i64::from(px), min.y as i64 + i64::from(py));
            if (0..w).contains(&px) && (0..h).contains(&py) {
                let p = img.get_pixel_mut(px as u32, py as u32);
                let c = coverage.clamp(0.0, 1.0);
                for k in 0..3 {
                    p.0[k] = (f32::from(p.0[k]) * (1.0 - c) + f32::from(rgb.0[k]) * c).round() as u8;
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const INK: Rgb<u8> = Rgb([20, 20, 20]);

    #[test]
    fn text_is_inked_inside_its_box_and_nowhere_else() {
        let s = "χ²/ndf = 1.02";
        let (w, x, y) = (text_width(s), 5, 3);
        let mut img = RgbImage::from_pixel(w + 20, 2 * LINE_H, Rgb([255, 255, 255]));
        draw_text(&mut img, x, y, s, INK);
        let inked: Vec<(u32, u32)> =
            img.enumerate_pixels().filter(|(_, _, p)| p.0 != [255; 3]).map(|(px, py, _)| (px, py)).collect();
        assert!(inked.len() > 50, "{} pixels inked", inked.len());
        for (px, py) in inked {
            assert!((x as u32..=x as u32 + w).contains(&px) && (y as u32..y as u32 + LINE_H).contains(&py), "({px}, {py})");
        }
    }

    #[test]
    fn width_grows_with_the_text() {
        assert_eq!(text_width(""), 0);
        let one = text_width("x");
        assert!(one > 4 && one < LINE_H, "{one}");
        // widths add up (one glyph's width is rounded up, so 100 of them lie within 100 px)
        let hundred = text_width(&"x".repeat(100));
        assert!(hundred > 100 * (one - 1) && hundred <= 100 * one, "{hundred} vs {one}");
    }

    #[test]
    fn text_on_unicode_and_edges_does_not_panic() {
        let mut img = RgbImage::new(40, 20);
        let s = "χ²/ndf = 1.02 θφ√∑ 🎉 \u{0301}\n\0 ÅÉ 日本語";
        for (x, y) in [(0, 0), (-50, -50), (30, 15), (i64::MAX / 4, 0), (0, i64::MIN / 4), (i64::MIN / 4, 0)] {
            draw_text(&mut img, x, y, s, INK);
        }
    }

    proptest::proptest! {
        #[test]
        fn any_string_draws(s in "\\PC*", x in -100i64..100, y in -100i64..100) {
            let mut img = RgbImage::new(64, 32);
            draw_text(&mut img, x, y, &s, INK);
        }
    }
}
