//! The pixel (PNG) side of the charts: text laid out from the font's own metrics, and lines
//! that stay whole, where plotters 0.3.7 (the newest release) gets both wrong on bitmaps. SVG
//! charts are unaffected: the viewer lays out their text and strokes their paths.
//!
//! [`PngBackend`] wraps any pixel backend and passes every drawing call through unchanged except
//! these:
//!
//! - **Text.** plotters rasterises each glyph at the pen position, dropping the glyph's left side
//!   bearing and rounding the pen to whole pixels, so letters drift into each other ("class_a"
//!   reads "dass_a"). Here glyph k sits at pen x_k = sum over earlier glyphs of (advance + kerning
//!   with its successor), at sub-pixel precision, and its outline is placed relative to that pen,
//!   so the side bearings come out as the font defines them. The baseline is the whole pixel
//!   nearest to centring the font's ascent–descent range in the layout box plotters reserves
//!   (height = size / 1.24 px), so digits centre on their tick marks. Coverage of overlapping
//!   glyphs adds up before blending, capped at 1. The layout box (width = advance + kerning sum)
//!   is plotters' own, so anchoring, legends and label areas stay as plotters computed them.
//!   `size` is the font's ascent-to-descent height in pixels, as plotters uses it. Every text is
//!   drawn in DejaVu Sans, the one face the charts register (bytes from the `dejavu` crate, so
//!   no system font is needed).
//! - **Wide paths.** plotters fills one polygon around a whole path by the even-odd rule, so
//!   where a path runs over itself (the second lap of a constant-radius trajectory) the overlap
//!   cancels and the line falls apart into fragments. Here a path `w` pixels wide is `w` solid
//!   one-pixel polylines side by side, offset across each segment's minor axis.
//! - **Horizontal lines.** plotters-bitmap draws a one-pixel horizontal line given right to left
//!   as only the pixels strictly between its ends (a 1 px step vanishes); such lines are drawn
//!   left to right here. One-pixel paths, wide single lines, polygons and circles are drawn
//!   through this backend's lines (plotters' rasterisers with this backend), so their spans get
//!   the same treatment.

use std::sync::OnceLock;

use ab_glyph::{point, Font, FontRef, PxScale, ScaleFont};
use plotters_backend::rasterizer;
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind};

/// The chart font's bytes (DejaVu Sans).
pub(crate) fn sans_bytes() -> &'static [u8] {
    dejavu::sans::regular()
}

/// The chart font, parsed once.
pub(crate) fn sans() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    // The dejavu crate ships a valid TTF; failing to parse it is a build defect, not input.
    FONT.get_or_init(|| FontRef::try_from_slice(sans_bytes()).expect("DejaVu Sans parses"))
}

/// One line of text rasterised: coverage (0–1) per pixel of the rectangle whose top-left pixel is
/// (`left`, `top`) in layout-box coordinates (origin: top-left of the box, x right, y down).
#[derive(Debug, Clone, PartialEq)]
pub struct Raster {
    pub left: i32,
    pub top: i32,
    pub width: usize,
    pub height: usize,
    /// Row-major, `width * height` values.
    pub coverage: Vec<f32>,
}

/// Pen x (pixels, from the start of the text) of every glyph of `text` at pixel size `size`.
pub fn pen_positions(text: &str, size: f64) -> Vec<f32> {
    let font = sans().as_scaled(PxScale::from(size as f32));
    let mut pens = Vec::with_capacity(text.len());
    let mut pen = 0.0f32;
    let mut prev = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            pen += font.kern(p, id);
        }
        pens.push(pen);
        pen += font.h_advance(id);
        prev = Some(id);
    }
    pens
}

/// Rasterise `text` at pixel size `size` into a layout box `box_height` pixels tall.
pub fn rasterise(text: &str, size: f64, box_height: i32) -> Raster {
    let font = sans().as_scaled(PxScale::from(size as f32));
    let baseline = ((box_height as f32 + font.ascent() + font.descent()) / 2.0).round();
    let outlines: Vec<_> = text
        .chars()
        .zip(pen_positions(text, size))
        .filter_map(|(c, pen)| {
            let glyph = font.glyph_id(c).with_scale_and_position(font.scale(), point(pen, baseline));
            font.outline_glyph(glyph)
        })
        .collect();
    if outlines.is_empty() {
        return Raster { left: 0, top: 0, width: 0, height: 0, coverage: Vec::new() };
    }
    let bounds: Vec<_> = outlines.iter().map(|o| o.px_bounds()).collect();
    let left = bounds.iter().map(|b| b.min.x as i32).min().unwrap_or(0);
    let top = bounds.iter().map(|b| b.min.y as i32).min().unwrap_or(0);
    let right = bounds.iter().map(|b| b.max.x as i32).max().unwrap_or(0);
    let bottom = bounds.iter().map(|b| b.max.y as i32).max().unwrap_or(0);
    let (width, height) = ((right - left).max(0) as usize, (bottom - top).max(0) as usize);
    let mut coverage = vec![0.0f32; width * height];
    for (o, b) in outlines.iter().zip(&bounds) {
        let (ox, oy) = (b.min.x as i32 - left, b.min.y as i32 - top);
        o.draw(|x, y, c| {
            let (px, py) = (ox + x as i32, oy + y as i32);
            if px >= 0 && py >= 0 && (px as usize) < width && (py as usize) < height {
                let cell = &mut coverage[py as usize * width + px as usize];
                *cell = (*cell + c).min(1.0);
            }
        });
    }
    Raster { left, top, width, height, coverage }
}

/// The pixels of the segment from `a` to `b`, both ends included: one per step along the major
/// axis, the minor coordinate rounded from the exact line (Bresenham's choice).
fn solid_line(a: BackendCoord, b: BackendCoord) -> impl Iterator<Item = BackendCoord> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let n = dx.abs().max(dy.abs());
    (0..=n).map(move |i| {
        if n == 0 {
            return a;
        }
        // Integer rounding of a + d * i / n, halves away from zero.
        let step = |d: i32| {
            let num = 2 * d * i + d.signum() * n;
            num / (2 * n)
        };
        (a.0 + step(dx), a.1 + step(dy))
    })
}

/// A pixel backend with the text, wide paths and horizontal lines of the module header; the rest
/// goes to the inner backend unchanged.
pub struct PngBackend<B>(pub B);

impl<B: DrawingBackend> DrawingBackend for PngBackend<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.0.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.present()
    }

    fn draw_pixel(&mut self, p: BackendCoord, c: BackendColor) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_pixel(p, c)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        if style.stroke_width() != 1 {
            return rasterizer::draw_line(self, from, to, style);
        }
        // plotters-bitmap fills a horizontal line drawn right to left as the pixels strictly
        // between its ends, so a polygon's one- and two-pixel spans vanish.
        let (from, to) = if from.1 == to.1 && from.0 > to.0 { (to, from) } else { (from, to) };
        self.0.draw_line(from, to, style)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let w = style.stroke_width();
        if style.color().alpha == 0.0 || w == 0 {
            return Ok(());
        }
        let points: Vec<BackendCoord> = path.into_iter().collect();
        if w == 1 {
            for seg in points.windows(2) {
                self.draw_line(seg[0], seg[1], style)?;
            }
            return Ok(());
        }
        // `w` one-pixel polylines side by side, offset across each segment's minor axis (rows
        // for a flat segment, columns for a steep one), each pixel solid; see the module header.
        let colour = style.color();
        let first = -((w as i32 - 1) / 2);
        for seg in points.windows(2) {
            let (a, b) = (seg[0], seg[1]);
            let flat = (b.0 - a.0).abs() >= (b.1 - a.1).abs();
            for p in solid_line(a, b) {
                for k in first..first + w as i32 {
                    let q = if flat { (p.0, p.1 + k) } else { (p.0 + k, p.1) };
                    self.0.draw_pixel(q, colour)?;
                }
            }
        }
        Ok(())
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let vert: Vec<BackendCoord> = vert.into_iter().collect();
        rasterizer::fill_polygon(self, &vert, style)
    }

    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        self.0.estimate_text_size(text, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.blit_bitmap(pos, size, src)
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let colour = style.color();
        if colour.alpha == 0.0 {
            return Ok(());
        }
        // plotters' layout box, so anchoring agrees with the space plotters reserved.
        let ((x0, y0), (x1, y1)) = style.layout_box(text).map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
        let (w, h) = (x1 - x0, y1 - y0);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Center => -w / 2,
            HPos::Right => -w,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -h / 2,
            VPos::Bottom => -h,
        };
        let raster = rasterise(text, style.size(), h);
        let turn = style.transform();
        for row in 0..raster.height {
            for col in 0..raster.width {
                let c = raster.coverage[row * raster.width + col];
                if c <= 0.0 {
                    continue;
                }
                let (x, y) = turn.transform(raster.left + col as i32 + dx, raster.top + row as i32 + dy);
                let ink = BackendColor { alpha: colour.alpha * f64::from(c), rgb: colour.rgb };
                self.0.draw_pixel((pos.0 + x, pos.1 + y), ink)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    /// Ink extent (left, right) in pixels from the pen origin of each glyph of `text`, from the
    /// font tables directly: hmtx advances, kerning and each outline's bounding box in font units.
    fn metric_ink(text: &str, size: f32) -> Vec<(f32, f32)> {
        let font = sans();
        let px_per_unit = size / (font.ascent_unscaled() - font.descent_unscaled());
        let mut pen = 0.0;
        let mut prev = None;
        let mut out = Vec::new();
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = prev {
                pen += font.kern_unscaled(p, id) * px_per_unit;
            }
            if let Some(o) = font.outline(id) {
                out.push((pen + o.bounds.min.x * px_per_unit, pen + o.bounds.max.x * px_per_unit));
            }
            pen += font.h_advance_unscaled(id) * px_per_unit;
            prev = Some(id);
        }
        out
    }

    /// Draw `text` black on white at `size` px with its layout box's top-left at (`x0`, 10), through
    /// [`PngBackend`] (or plotters' own text when `plain`); return the runs of inked columns.
    fn ink_runs(text: &str, size: u32, x0: i32, plain: bool) -> Vec<(i32, i32)> {
        super::super::register_font();
        let (w, h) = (800u32, 120u32);
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let font = ("sans-serif", size).into_font().color(&BLACK);
            let bitmap = BitMapBackend::with_buffer(&mut buf, (w, h));
            if plain {
                let area = bitmap.into_drawing_area();
                area.draw_text(text, &font, (x0, 10)).unwrap();
                area.present().unwrap();
            } else {
                let area = PngBackend(bitmap).into_drawing_area();
                area.draw_text(text, &font, (x0, 10)).unwrap();
                area.present().unwrap();
            }
        }
        let inked = |x: u32| (0..h).any(|y| buf[((y * w + x) * 3) as usize] < 255);
        let mut runs: Vec<(i32, i32)> = Vec::new();
        for x in 0..w {
            if inked(x) {
                match runs.last_mut() {
                    Some(r) if r.1 == x as i32 - 1 => r.1 = x as i32,
                    _ => runs.push((x as i32, x as i32)),
                }
            }
        }
        runs
    }

    /// Each glyph's inked columns, as rendered, against the font's metrics: one separate run of
    /// ink per glyph, starting and ending within a pixel of the metric ink box. `text` must have
    /// at least `min_gap` px between the metric ink boxes of neighbours. (plotters' own bitmap
    /// text fails this for every text the tests use.)
    fn check_glyph_boxes(text: &str, size: u32, min_gap: f32, plain: bool) -> std::result::Result<(), String> {
        let x0 = 20;
        let want = metric_ink(text, size as f32);
        for pair in want.windows(2) {
            assert!(pair[1].0 - pair[0].1 >= min_gap, "{text:?} at {size} px: glyphs closer than {min_gap} px");
        }
        let got = ink_runs(text, size, x0, plain);
        if got.len() != want.len() {
            return Err(format!("{text:?} at {size} px: {} glyphs, {} runs of ink {got:?}", want.len(), got.len()));
        }
        for (k, (g, m)) in got.iter().zip(&want).enumerate() {
            let (left, right) = (x0 + m.0.floor() as i32, x0 + m.1.ceil() as i32 - 1);
            if (g.0 - left).abs() > 1 || (g.1 - right).abs() > 1 {
                return Err(format!("{text:?} at {size} px, glyph {k}: ink {g:?}, metrics say ({left}, {right})"));
            }
        }
        Ok(())
    }

    #[test]
    fn each_glyph_is_inked_where_advances_kerning_and_bearings_place_it() {
        for (text, size) in [("classic", 40), ("rate", 40), ("ice", 40), ("classic", 28)] {
            check_glyph_boxes(text, size, 2.0, false).unwrap();
        }
        // At the legend size the pair that read "d" in "class_a": 1.9 px apart by the metrics.
        check_glyph_boxes("cl", 14, 1.5, false).unwrap();
    }

    #[test]
    fn plotters_own_bitmap_text_fails_the_same_check() {
        // The check above can fail: plotters 0.3.7 drops side bearings. Should a newer plotters
        // pass, its bitmap text is fixed and PngBackend's text can be retired.
        for (text, size, gap) in [("classic", 40, 2.0), ("rate", 40, 2.0), ("ice", 40, 2.0), ("cl", 14, 1.5)] {
            assert!(check_glyph_boxes(text, size, gap, true).is_err(), "{text:?} at {size} px");
        }
    }

    /// Stroke `path` `width` px wide in black into the RGB buffer `buf` of `size`, through
    /// [`PngBackend`] or plotters alone (`plain`).
    fn stroke(buf: &mut [u8], size: (u32, u32), path: Vec<(i32, i32)>, width: u32, plain: bool) {
        let line = PathElement::new(path, ShapeStyle { color: BLACK.to_rgba(), filled: false, stroke_width: width });
        let bitmap = BitMapBackend::with_buffer(buf, size);
        if plain {
            let area = bitmap.into_drawing_area();
            area.draw(&line).unwrap();
            area.present().unwrap();
        } else {
            let area = PngBackend(bitmap).into_drawing_area();
            area.draw(&line).unwrap();
            area.present().unwrap();
        }
    }

    /// One and a half laps of a circle of radius 200 px (a constant-radius trajectory), as
    /// rounded points about 1.5 px apart, counter-clockwise on screen, stroked 2 px wide in black on
    /// white through [`PngBackend`] or plotters alone: how many of its vertices are not inked, and
    /// the largest distance of any ink from the circle (px).
    fn stroke_laps(plain: bool) -> (usize, f64) {
        let (w, h, c, r) = (460u32, 460u32, 230.0, 200.0);
        let n = 840;
        let mut pts: Vec<(i32, i32)> = (0..=n * 3 / 2)
            .map(|k| {
                let a = -std::f64::consts::TAU * k as f64 / n as f64;
                ((c + r * a.cos()).round() as i32, (c + r * a.sin()).round() as i32)
            })
            .collect();
        pts.dedup();
        let mut buf = vec![255u8; (w * h * 3) as usize];
        stroke(&mut buf, (w, h), pts.clone(), 2, plain);
        let ink = |x: i32, y: i32| buf[((y as u32 * w + x as u32) * 3) as usize] < 128;
        let bare = pts.iter().filter(|p| !ink(p.0, p.1)).count();
        let mut stray: f64 = 0.0;
        for y in 0..h as i32 {
            for x in 0..w as i32 {
                if ink(x, y) {
                    stray = stray.max(((f64::from(x) - c).hypot(f64::from(y) - c) - r).abs());
                }
            }
        }
        (bare, stray)
    }

    #[test]
    fn a_wide_line_over_itself_stays_inked() {
        let (bare, stray) = stroke_laps(false);
        assert_eq!(bare, 0, "vertices without ink");
        assert!(stray <= 2.5, "ink {stray} px off the circle");
        // plotters alone: the second lap cancels the first (even-odd fill). Should this pass,
        // plotters has fixed it and PngBackend::draw_path can go.
        let (bare, _) = stroke_laps(true);
        assert!(bare > 50, "plotters' own wide path now unbroken ({bare} bare vertices)");
    }

    /// Pixels inked by a one-pixel horizontal line from x = 50 to x = `to_x` at y = 5.
    fn horizontal_line_pixels(to_x: i32, plain: bool) -> usize {
        let (w, h) = (100u32, 10u32);
        let mut buf = vec![255u8; (w * h * 3) as usize];
        stroke(&mut buf, (w, h), vec![(50, 5), (to_x, 5)], 1, plain);
        buf.chunks(3).filter(|p| p[0] < 128).count()
    }

    #[test]
    fn horizontal_lines_cover_both_ends_either_way() {
        for to_x in [40, 60, 49, 51] {
            assert_eq!(horizontal_line_pixels(to_x, false), (to_x - 50).unsigned_abs() as usize + 1, "to {to_x}");
        }
        // plotters alone: right to left loses both ends, and a 1 px step vanishes.
        assert_eq!((horizontal_line_pixels(40, true), horizontal_line_pixels(49, true)), (9, 0));
    }

    #[test]
    fn a_line_of_chart_text_spans_its_metric_width() {
        // The charts' legend and note size; the whole line's ink from the first glyph's left edge
        // to the last glyph's right edge, within a pixel.
        for text in ["class_a, pacejka", "Pacejka", "Colour: vehicle; line style: tyre_model"] {
            let want = metric_ink(text, 14.0);
            let got = ink_runs(text, 14, 20, false);
            let (first, last) = (got.first().unwrap().0, got.last().unwrap().1);
            let left = 20 + want.first().unwrap().0.floor() as i32;
            let right = 20 + want.iter().map(|m| m.1).fold(f32::MIN, f32::max).ceil() as i32 - 1;
            assert!(
                (first - left).abs() <= 1 && (last - right).abs() <= 1,
                "{text:?}: ink {first}..{last}, metrics {left}..{right}"
            );
        }
    }
}
