//! Charts with plotters: line charts (with line styles, percentile bands, reference lines,
//! outlines, markers and shaded spans), small multiples (a panel per value of a factor) and heat
//! maps, each written as PNG and SVG. [`runs`] draws the standard charts of a results folder.
//!
//! Conventions every chart follows: a palette of [`PALETTE_LEN`] distinguishable colours (a swept
//! factor gets the colours, a second one the line styles of [`STYLES`]); the legend sits in a
//! column right of the data, never over it; tick labels never read `-0.0`; trajectories can be
//! drawn at equal scale on both axes; a note under the chart says what was left out or why curves
//! coincide. The font (DejaVu Sans) comes from the `dejavu` crate as bytes, so no system font
//! library is needed; PNG text and wide lines are drawn by [`bitmap`] (plotters' own drop glyph
//! side bearings and break lines that run over themselves). Files are written under a temporary name and renamed
//! (see [`crate::output`]).

pub mod bitmap;
pub mod runs;

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::output::{rename, temp_path, write_atomic};
use bitmap::PngBackend;
use vehsim_core::error::{Error, Result};

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        // The bytes are a valid TTF shipped by the dejavu crate; registration cannot fail on them,
        // and if it did the charts would only lack text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, bitmap::sans_bytes());
    });
}

/// One labelled curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label (empty: not in the legend).
    pub label: String,
    /// (x, y) points in drawing order; non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
}

/// How a curve is drawn: a colour of the palette and a stroke of [`STYLES`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LineStyle {
    /// Index into the palette (wraps after [`PALETTE_LEN`]).
    pub colour: usize,
    /// Index into [`STYLES`] (wraps).
    pub stroke: usize,
    /// Markers at the points only, no line (measured or fitted points).
    pub points_only: bool,
    /// A thin, translucent line (one of very many runs drawn alike).
    pub faint: bool,
}

/// The strokes a second factor is shown by: four dash patterns, then solid lines with markers.
pub const STYLES: [&str; 7] =
    ["solid", "dashed", "dotted", "dash-dot", "solid, circles", "solid, triangles", "solid, squares"];

/// A shaded band between two curves on the same x values (a percentile range of many runs).
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    pub label: String,
    pub colour: usize,
    /// Opacity of the fill, 0–1.
    pub alpha: f64,
    /// (x, lower y, upper y).
    pub points: Vec<(f64, f64, f64)>,
}

/// A horizontal reference line across the whole chart (e.g. the friction limit mu g).
#[derive(Debug, Clone, PartialEq)]
pub struct RefLine {
    pub label: String,
    pub y: f64,
}

/// A line chart: title, axis labels with units, and curves.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LineChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Text under the chart (empty: none), e.g. why curves coincide.
    pub note: String,
}

/// A line chart with extra elements: styles per curve, percentile bands, reference lines, closed
/// outlines (vehicle bodies), point markers (cones), highlighted points (cone strikes), shaded
/// x-spans (time windows) and a note.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct XyChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Style of each curve, parallel to `series`; missing entries: colour = curve index, solid.
    pub styles: Vec<LineStyle>,
    pub bands: Vec<Band>,
    pub ref_lines: Vec<RefLine>,
    /// Reference curves drawn dashed in grey (a reference path), not from the palette.
    pub ref_paths: Vec<Series>,
    pub outlines: Vec<Vec<(f64, f64)>>,
    pub markers: Vec<(f64, f64)>,
    pub highlights: Vec<(f64, f64)>,
    pub spans: Vec<(f64, f64)>,
    /// Same metres per pixel on both axes (trajectories).
    pub equal_aspect: bool,
    /// Text under the chart (empty: none).
    pub note: String,
    /// Axis ranges to use instead of the data's (panels of a figure share them).
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
}

impl XyChart {
    /// The data ranges (padded) the chart draws unless `x_range`/`y_range` are set.
    pub fn data_ranges(&self) -> ((f64, f64), (f64, f64)) {
        let (x, y) = self.data_extent();
        (padded(x), padded(y))
    }

    /// The smallest and largest x and y of the data (unpadded; (inf, -inf) without data).
    fn data_extent(&self) -> ((f64, f64), (f64, f64)) {
        let pts = || {
            self.series
                .iter()
                .chain(&self.ref_paths)
                .flat_map(|s| s.points.iter().copied())
                .chain(self.outlines.iter().flatten().copied())
                .chain(self.markers.iter().copied())
                .chain(self.bands.iter().flat_map(|b| b.points.iter().flat_map(|p| [(p.0, p.1), (p.0, p.2)])))
        };
        (extent(pts().map(|p| p.0)), extent(pts().map(|p| p.1).chain(self.ref_lines.iter().map(|r| r.y))))
    }

    /// The style of curve `i`.
    pub fn style(&self, i: usize) -> LineStyle {
        self.styles.get(i).copied().unwrap_or(LineStyle { colour: i, ..LineStyle::default() })
    }

    /// Legend entries in drawing order, each label once: curves, bands, reference lines.
    pub fn legend(&self) -> Vec<LegendEntry> {
        let mut out: Vec<LegendEntry> = Vec::new();
        let mut push = |e: LegendEntry| {
            if !e.label.is_empty() && !out.iter().any(|o| o.label == e.label) {
                out.push(e);
            }
        };
        for (i, s) in self.series.iter().enumerate() {
            push(LegendEntry { label: s.label.clone(), kind: LegendKind::Line(self.style(i)) });
        }
        for b in &self.bands {
            push(LegendEntry { label: b.label.clone(), kind: LegendKind::Fill(b.colour, b.alpha) });
        }
        for r in &self.ref_lines {
            push(LegendEntry { label: r.label.clone(), kind: LegendKind::Reference });
        }
        for r in &self.ref_paths {
            push(LegendEntry { label: r.label.clone(), kind: LegendKind::Reference });
        }
        out
    }
}

/// One line of a legend.
#[derive(Debug, Clone, PartialEq)]
pub struct LegendEntry {
    pub label: String,
    pub kind: LegendKind,
}

/// What a legend line shows beside its label.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LegendKind {
    Line(LineStyle),
    Fill(usize, f64),
    Reference,
}

/// Small multiples: one panel per value of a factor, a shared legend right of the panels.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Figure {
    pub title: String,
    /// Each panel's title names its value of the factor.
    pub panels: Vec<XyChart>,
    pub note: String,
}

/// A heat map of a grid: `values[row][col]`, rows along the vertical axis.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatMap {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// Label of the colour scale, with unit.
    pub value_label: String,
    /// Physical extent: x from `x_range.0` to `x_range.1` across columns, y likewise across rows.
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    pub values: Vec<Vec<f64>>,
    /// Discrete classes (value, name), e.g. (0, "dry"), (1, "wet"): each cell takes the colour of
    /// the nearest class and a key replaces the continuous colour bar. Empty: continuous scale.
    pub classes: Vec<(f64, String)>,
}

const SIZE: (u32, u32) = (1000, 640);

fn plot_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Io { path: path.to_path_buf(), source: std::io::Error::other(e.to_string()) }
}

/// Number of colours before the palette repeats.
pub const PALETTE_LEN: usize = 12;

/// The palette: twelve colours chosen to stay apart from each other and from the white background
/// (tested in CIELAB below).
pub fn palette(i: usize) -> RGBColor {
    const C: [RGBColor; PALETTE_LEN] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(23, 190, 207),
        RGBColor(188, 189, 34),
        RGBColor(30, 30, 30),
        RGBColor(140, 140, 140),
        RGBColor(0, 90, 80),
    ];
    C[i % C.len()]
}

/// Colour of reference lines and reference paths (outside the palette).
const REFERENCE: RGBColor = RGBColor(90, 90, 90);

/// The smallest and largest finite value, (inf, -inf) when there is none.
fn extent(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (lo, hi)
}

/// An axis range around the extent (lo, hi): 5 % of the span on either side (10 % of |lo|, or 1,
/// for a single value; (0, 1) without data).
fn padded((lo, hi): (f64, f64)) -> (f64, f64) {
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-12 {
        let pad = if lo.abs() > 0.0 { lo.abs() * 0.1 } else { 1.0 };
        return (lo - pad, hi + pad);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Widen the shorter range about its centre so that both axes have the same units per pixel on a
/// plotting area of `px` (width, height) pixels.
pub fn equal_aspect(x: (f64, f64), y: (f64, f64), px: (u32, u32)) -> ((f64, f64), (f64, f64)) {
    let (w, h) = (f64::from(px.0.max(1)), f64::from(px.1.max(1)));
    let per_px = ((x.1 - x.0) / w).max((y.1 - y.0) / h);
    let widen = |r: (f64, f64), n: f64| {
        let (c, half) = (0.5 * (r.0 + r.1), 0.5 * per_px * n);
        (c - half, c + half)
    };
    (widen(x, w), widen(y, h))
}

/// The tick spacing plotters 0.3.7 uses on an axis from `lo` to `hi` with at most `max` labels:
/// starting from the power of ten below the span, it divides by 2, 5 and 10 in turn while the
/// ticks that fall inside the range (multiples of the step) stay no more than `max`.
pub fn tick_step(lo: f64, hi: f64, max: usize) -> f64 {
    let (lo, hi) = (lo.min(hi), lo.max(hi));
    let span = (hi - lo).max(1e-300);
    let max = max.max(1) as f64;
    let inside = |step: f64| 1.0 + (hi / step).floor() - (lo / step).ceil();
    let mut step = 10f64.powf(span.log10().floor());
    if 1.0 + (span / step).floor() > max {
        step *= 10.0;
    }
    // 60 decades below the span: far past any tick count plotters would accept.
    for _ in 0..60 {
        let coarse = step;
        for m in [2.0, 5.0, 10.0] {
            if inside(coarse / m) > max {
                return step;
            }
            step = coarse / m;
        }
    }
    step
}

/// A tick label for value `v` on an axis from `lo` to `hi` with at most `max` labels: the
/// decimals the tick spacing needs (so neighbouring ticks never read alike), and never `-0` or
/// `-0.0`.
pub fn tick_label(v: f64, lo: f64, hi: f64, max: usize) -> String {
    let step = tick_step(lo, hi, max);
    let decimals = (-(step.log10() + 1e-9).floor()).clamp(0.0, 9.0) as usize;
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

fn stroke_points(s: &Series) -> Vec<(f64, f64)> {
    s.points.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite()).collect()
}

/// Drop points closer than `dx` and `dy` (about a pixel) to the last kept one, keeping the
/// last point: a dense polyline of sub-pixel segments otherwise renders as a dotted line.
pub fn thin(points: &[(f64, f64)], dx: f64, dy: f64) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(points.len());
    for (i, &p) in points.iter().enumerate() {
        let last = i + 1 == points.len();
        match out.last() {
            Some(q) if !last && (p.0 - q.0).abs() < dx && (p.1 - q.1).abs() < dy => {}
            _ => out.push(p),
        }
    }
    out
}

type DrawResult = std::result::Result<(), String>;

fn e2s(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// Draw one chart (without its legend) into `area`.
fn draw_chart<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, c: &XyChart, caption: u32) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let area =
        if c.title.is_empty() { area.clone() } else { area.titled(&c.title, ("sans-serif", caption)).map_err(e2s)? };
    let (xd, yd) = c.data_ranges();
    let mut xr = c.x_range.unwrap_or(xd);
    let mut yr = c.y_range.unwrap_or(yd);
    let build = |b: &mut ChartBuilder<DB>| {
        b.margin(10).margin_right(16).x_label_area_size(44).y_label_area_size(72);
    };
    if c.equal_aspect {
        let mut probe = ChartBuilder::on(&area);
        build(&mut probe);
        let dims = probe.build_cartesian_2d(0.0..1.0, 0.0..1.0).map_err(e2s)?.plotting_area().dim_in_pixel();
        (xr, yr) = equal_aspect(xr, yr, dims);
    }
    let (x0, x1) = xr;
    let (y0, y1) = yr;
    let mut builder = ChartBuilder::on(&area);
    build(&mut builder);
    let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1).map_err(e2s)?;
    // Fewer labels in the small panels of a figure.
    let n = if caption < 20 { 6 } else { 10 };
    let xf = move |v: &f64| tick_label(*v, x0, x1, n);
    let yf = move |v: &f64| tick_label(*v, y0, y1, n);
    chart
        .configure_mesh()
        .x_labels(n)
        .y_labels(n)
        .x_desc(&c.x_label)
        .y_desc(&c.y_label)
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(e2s)?;
    for &(a, b) in &c.spans {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(a, y0), (b, y1)],
                RGBColor(255, 200, 120).mix(0.35).filled(),
            )))
            .map_err(e2s)?;
    }
    for b in &c.bands {
        let mut poly: Vec<(f64, f64)> = b.points.iter().map(|p| (p.0, p.1)).collect();
        poly.extend(b.points.iter().rev().map(|p| (p.0, p.2)));
        poly.retain(|p| p.0.is_finite() && p.1.is_finite());
        chart.draw_series(std::iter::once(Polygon::new(poly, palette(b.colour).mix(b.alpha).filled()))).map_err(e2s)?;
    }
    for o in &c.outlines {
        let mut closed = o.clone();
        if let Some(first) = o.first() {
            closed.push(*first);
        }
        chart.draw_series(std::iter::once(PathElement::new(closed, BLACK.mix(0.5)))).map_err(e2s)?;
    }
    chart
        .draw_series(c.markers.iter().map(|&(x, y)| TriangleMarker::new((x, y), 4, RGBColor(255, 120, 0).filled())))
        .map_err(e2s)?;
    for r in &c.ref_lines {
        chart
            .draw_series(DashedLineSeries::new([(x0, r.y), (x1, r.y)], 8, 5, REFERENCE.stroke_width(2)))
            .map_err(e2s)?;
    }
    let (px, py) = chart.plotting_area().dim_in_pixel();
    let (dx, dy) = ((x1 - x0) / f64::from(px.max(1)), (y1 - y0) / f64::from(py.max(1)));
    for (i, s) in c.series.iter().enumerate() {
        let st = c.style(i);
        let pts = if st.points_only { stroke_points(s) } else { thin(&stroke_points(s), dx, dy) };
        draw_curve(&mut chart, &pts, st)?;
    }
    for r in &c.ref_paths {
        chart.draw_series(DashedLineSeries::new(stroke_points(r), 8, 5, REFERENCE.stroke_width(2))).map_err(e2s)?;
    }
    chart.draw_series(c.highlights.iter().map(|&(x, y)| Cross::new((x, y), 7, RED.stroke_width(3)))).map_err(e2s)?;
    Ok(())
}

type Chart2d<'a, DB> =
    ChartContext<'a, DB, Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>>;

fn draw_curve<DB: DrawingBackend>(chart: &mut Chart2d<'_, DB>, line: &[(f64, f64)], st: LineStyle) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let colour = palette(st.colour);
    let stroke = st.stroke % STYLES.len();
    let shape = if st.faint { colour.mix(0.35).stroke_width(1) } else { colour.stroke_width(2) };
    if st.points_only {
        return chart.draw_series(line.iter().map(|&p| Circle::new(p, 5, colour.filled()))).map(|_| ()).map_err(e2s);
    }
    match stroke {
        1 => chart.draw_series(DashedLineSeries::new(line.iter().copied(), 10, 6, shape)).map(|_| ()),
        2 => chart.draw_series(DashedLineSeries::new(line.iter().copied(), 2, 5, shape)).map(|_| ()),
        3 => chart.draw_series(DashedLineSeries::new(line.iter().copied(), 14, 4, shape)).map(|_| ()).and_then(|_| {
            // The dots of dash-dot: short dashes offset into the gaps would need a custom element;
            // a thinner second pass with short dashes reads as dash-dot at plot scale.
            chart.draw_series(DashedLineSeries::new(line.iter().copied(), 2, 16, colour.stroke_width(2))).map(|_| ())
        }),
        _ => chart.draw_series(LineSeries::new(line.iter().copied(), shape)).map(|_| ()),
    }
    .map_err(e2s)?;
    if stroke >= 4 {
        let every = (line.len() / 12).max(1);
        let marks = line.iter().step_by(every).copied();
        match stroke {
            4 => chart.draw_series(marks.map(|p| Circle::new(p, 4, colour.filled()))).map(|_| ()),
            5 => chart.draw_series(marks.map(|p| TriangleMarker::new(p, 5, colour.filled()))).map(|_| ()),
            _ => chart.draw_series(marks.map(|p| Rectangle::new([p, p], colour.filled()))).map(|_| ()),
        }
        .map_err(e2s)?;
    }
    Ok(())
}

/// A note for a chart whose curves (two or more) all coincide to within 1e-9 of their largest
/// value, e.g. a tyre force that does not depend on the swept temperature; empty otherwise.
/// `quantity` names what is plotted, e.g. "Fy".
pub fn coincidence_note(series: &[Series], quantity: &str) -> String {
    let [first, .., last] = series else { return String::new() };
    let scale = series.iter().flat_map(|s| s.points.iter().map(|p| p.1.abs())).fold(0.0, f64::max).max(1e-300);
    if !series.iter().all(|s| same_curve(s, first, 1e-9 * scale)) {
        return String::new();
    }
    format!(
        "Note: all {} curves coincide ({} to {}): {quantity} does not depend on the swept value in this model.",
        series.len(),
        first.label,
        last.label
    )
}

/// Whether `a` and `b` have the same x values and every y within `tol` of each other.
fn same_curve(a: &Series, b: &Series, tol: f64) -> bool {
    a.points.len() == b.points.len()
        && a.points.iter().zip(&b.points).all(|(p, q)| p.0 == q.0 && (p.1 - q.1).abs() <= tol)
}

/// A note naming each labelled curve that a later-drawn curve covers: the same x values and every y
/// within 1e-3 of the chart's y span (about a pixel), e.g. two tyre models that agree on Fy, so a
/// reader does not take the missing colour for a missing run. Empty when nothing is covered.
pub fn hidden_note(series: &[Series]) -> String {
    let ys = || series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).filter(|y| y.is_finite());
    let span = ys().fold(f64::NEG_INFINITY, f64::max) - ys().fold(f64::INFINITY, f64::min);
    if !(span > 0.0) {
        return String::new();
    }
    let covers = |a: &Series, b: &Series| a.points.len() > 1 && same_curve(a, b, 1e-3 * span);
    let pairs: Vec<String> = series
        .iter()
        .enumerate()
        .filter(|(_, a)| !a.label.is_empty())
        .filter_map(|(i, a)| {
            let b = series[i + 1..].iter().find(|b| !b.label.is_empty() && covers(a, b))?;
            Some(format!("'{}' lies under '{}'", a.label, b.label))
        })
        .collect();
    match pairs.len() {
        0 => String::new(),
        n if n > 3 => format!(
            "Note: {} and {} more curves lie under later ones (equal to within 0.1 % of the axis).",
            pairs[..3].join(", "),
            n - 3
        ),
        _ => format!("Note: {} (equal to within 0.1 % of the axis).", pairs.join(", ")),
    }
}

/// Width of the legend column for `entries` (none: 0).
fn legend_width(entries: &[LegendEntry]) -> u32 {
    match entries.iter().map(|e| e.label.chars().count()).max() {
        None => 0,
        Some(n) => (60 + 8 * n as u32).clamp(140, 460),
    }
}

/// Draw the legend entries top-down into `area`; entries that do not fit are summarised.
fn draw_legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, entries: &[LegendEntry]) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let row = 20;
    let (_, h) = area.dim_in_pixel();
    let fit = ((h.saturating_sub(60)) / row) as usize;
    let shown = if entries.len() > fit { fit.saturating_sub(1) } else { entries.len() };
    let font = ("sans-serif", 14).into_font();
    for (k, e) in entries.iter().take(shown).enumerate() {
        let y = 50 + (k as i32) * row as i32;
        match e.kind {
            LegendKind::Line(st) => {
                let c = palette(st.colour);
                if st.points_only {
                    area.draw(&Circle::new((20, y), 5, c.filled())).map_err(e2s)?;
                } else {
                    let seg = [(4, y), (36, y)];
                    match st.stroke % STYLES.len() {
                        1 => area.draw(&DashedPathElement::new(seg, 7, 4, c.stroke_width(2))),
                        2 => area.draw(&DashedPathElement::new(seg, 2, 4, c.stroke_width(2))),
                        3 => area.draw(&DashedPathElement::new(seg, 10, 5, c.stroke_width(2))),
                        _ => area.draw(&PathElement::new(seg, c.stroke_width(2))),
                    }
                    .map_err(e2s)?;
                    match st.stroke % STYLES.len() {
                        4 => area.draw(&Circle::new((20, y), 4, c.filled())).map_err(e2s)?,
                        5 => area.draw(&TriangleMarker::new((20, y), 5, c.filled())).map_err(e2s)?,
                        6 => area.draw(&Rectangle::new([(17, y - 3), (23, y + 3)], c.filled())).map_err(e2s)?,
                        _ => {}
                    }
                }
            }
            LegendKind::Fill(c, a) => {
                area.draw(&Rectangle::new([(4, y - 6), (36, y + 6)], palette(c).mix(a).filled())).map_err(e2s)?
            }
            LegendKind::Reference => {
                area.draw(&DashedPathElement::new([(4, y), (36, y)], 8, 5, REFERENCE.stroke_width(2))).map_err(e2s)?
            }
        }
        area.draw_text(&e.label, &font.color(&BLACK), (44, y - 8)).map_err(e2s)?;
    }
    if shown < entries.len() {
        let y = 50 + (shown as i32) * row as i32;
        let text = format!("... and {} more", entries.len() - shown);
        area.draw_text(&text, &font.color(&BLACK), (44, y - 8)).map_err(e2s)?;
    }
    Ok(())
}

/// Lines of a note as drawn (wrapped at about `chars` characters).
pub fn note_lines(note: &str, chars: usize) -> Vec<String> {
    let mut out = Vec::new();
    for para in note.lines() {
        let mut line = String::new();
        for w in para.split_whitespace() {
            if !line.is_empty() && line.chars().count() + 1 + w.chars().count() > chars {
                out.push(std::mem::take(&mut line));
            }
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(w);
        }
        if !line.is_empty() {
            out.push(line);
        }
    }
    out
}

/// Split a note strip off the bottom of `root` and draw `note` there; returns the rest.
fn with_note<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    note: &str,
) -> std::result::Result<DrawingArea<DB, Shift>, String>
where
    DB::ErrorType: 'static,
{
    let (w, h) = root.dim_in_pixel();
    let lines = note_lines(note, (w as usize / 8).max(20));
    if lines.is_empty() {
        return Ok(root.clone());
    }
    let strip = 10 + 18 * lines.len() as u32;
    let (top, bottom) = root.split_vertically(h.saturating_sub(strip));
    let font = ("sans-serif", 14).into_font();
    for (k, l) in lines.iter().enumerate() {
        bottom.draw_text(l, &font.color(&RGBColor(60, 60, 60)), (12, 2 + 18 * k as i32)).map_err(e2s)?;
    }
    Ok(top)
}

fn draw_lines<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, c: &XyChart) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(e2s)?;
    let body = with_note(&root, &c.note)?;
    let entries = c.legend();
    let lw = legend_width(&entries);
    let (w, _) = body.dim_in_pixel();
    let (main, side) = body.split_horizontally(w - lw);
    draw_chart(&main, c, 22)?;
    draw_legend(&side, &entries)?;
    root.present().map_err(e2s)
}

/// Rows and columns of a grid of `n` panels (at most four columns).
pub fn grid(n: usize) -> (usize, usize) {
    let cols = match n {
        0..=1 => 1,
        2..=4 => 2,
        5..=9 => 3,
        _ => 4,
    };
    (n.div_ceil(cols).max(1), cols)
}

/// The panels with common axis ranges (the union of their data), so they compare at a glance;
/// ranges a panel sets itself are kept.
pub fn shared_axes(panels: &[XyChart]) -> Vec<XyChart> {
    let ranges: Vec<_> =
        panels.iter().filter(|p| !p.series.is_empty() || !p.bands.is_empty()).map(XyChart::data_extent).collect();
    // the union of the data, padded once (padding each panel first would leave the panel that
    // sets an end with its own, possibly tiny, margin: a trace on the axis' edge)
    type Ranges = ((f64, f64), (f64, f64));
    let union = |f: &dyn Fn(&Ranges) -> (f64, f64)| {
        ranges.iter().map(f).fold((f64::INFINITY, f64::NEG_INFINITY), |a, r| (a.0.min(r.0), a.1.max(r.1)))
    };
    let (x, y) = (union(&|r| r.0), union(&|r| r.1));
    if !x.0.is_finite() || !y.0.is_finite() {
        return panels.to_vec();
    }
    let (x, y) = (padded(x), padded(y));
    panels
        .iter()
        .map(|p| {
            let mut p = p.clone();
            p.x_range = p.x_range.or(Some(x));
            p.y_range = p.y_range.or(Some(y));
            p
        })
        .collect()
}

/// Pixel size of a figure of `n` panels.
fn figure_size(n: usize) -> (u32, u32) {
    let (rows, _) = grid(n);
    (1500, 80 + 300 * rows as u32)
}

fn draw_figure<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, f: &Figure) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(e2s)?;
    let titled = root.titled(&f.title, ("sans-serif", 22)).map_err(e2s)?;
    let body = with_note(&titled, &f.note)?;
    let mut entries: Vec<LegendEntry> = Vec::new();
    for e in f.panels.iter().flat_map(|p| p.legend()) {
        if !entries.iter().any(|o| o.label == e.label) {
            entries.push(e);
        }
    }
    let lw = legend_width(&entries);
    let (w, _) = body.dim_in_pixel();
    let (main, side) = body.split_horizontally(w - lw);
    let cells = main.split_evenly(grid(f.panels.len()));
    for (p, cell) in shared_axes(&f.panels).iter().zip(&cells) {
        draw_chart(cell, p, 16)?;
    }
    draw_legend(&side, &entries)?;
    root.present().map_err(e2s)
}

/// Colour for a value in [0, 1] on a blue–cyan–yellow–red scale.
fn heat_colour(t: f64) -> RGBColor {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let stops = [
        (0.0, (20.0, 30.0, 140.0)),
        (0.35, (40.0, 180.0, 220.0)),
        (0.65, (250.0, 220.0, 40.0)),
        (1.0, (200.0, 20.0, 20.0)),
    ];
    for w in stops.windows(2) {
        let (a, ca) = w[0];
        let (b, cb) = w[1];
        if t <= b {
            let u = (t - a) / (b - a);
            let m = |p: f64, q: f64| (p + u * (q - p)).round() as u8;
            return RGBColor(m(ca.0, cb.0), m(ca.1, cb.1), m(ca.2, cb.2));
        }
    }
    RGBColor(200, 20, 20)
}

/// Colours of discrete classes: a sand tone, then the palette (so dry/wet read as sand/blue).
fn class_colour(k: usize) -> RGBColor {
    if k == 0 {
        RGBColor(225, 200, 150)
    } else {
        palette(k - 1)
    }
}

/// The index of the class nearest to `v` (`None` without classes or for a non-finite value).
pub fn class_of(classes: &[(f64, String)], v: f64) -> Option<usize> {
    if !v.is_finite() {
        return None;
    }
    classes.iter().enumerate().min_by(|a, b| (a.1 .0 - v).abs().total_cmp(&(b.1 .0 - v).abs())).map(|(k, _)| k)
}

fn draw_heat<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, h: &HeatMap) -> std::result::Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (main, bar) = root.split_horizontally(SIZE.0 - 150);
    let ((x0, x1), (y0, y1)) = (h.x_range, h.y_range);
    let xf = move |v: &f64| tick_label(*v, x0, x1, 10);
    let yf = move |v: &f64| tick_label(*v, y0, y1, 10);
    let (lo, hi) = padded(extent(h.values.iter().flatten().copied()));
    let span = (hi - lo).max(1e-300);
    let rows = h.values.len();
    let cols = h.values.iter().map(|r| r.len()).max().unwrap_or(0);
    let mut chart = ChartBuilder::on(&main)
        .caption(&h.title, ("sans-serif", 24))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(h.x_range.0..h.x_range.1, h.y_range.0..h.y_range.1)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(&h.x_label)
        .y_desc(&h.y_label)
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(|e| e.to_string())?;
    let colour = |v: f64| match class_of(&h.classes, v) {
        Some(k) => class_colour(k),
        None => heat_colour((v - lo) / span),
    };
    if rows > 0 && cols > 0 {
        let dx = (h.x_range.1 - h.x_range.0) / cols as f64;
        let dy = (h.y_range.1 - h.y_range.0) / rows as f64;
        chart
            .draw_series(h.values.iter().enumerate().flat_map(|(r, row)| {
                row.iter().enumerate().map(move |(c, v)| {
                    let x = h.x_range.0 + c as f64 * dx;
                    let y = h.y_range.0 + r as f64 * dy;
                    Rectangle::new([(x, y), (x + dx, y + dy)], colour(*v).filled())
                })
            }))
            .map_err(|e| e.to_string())?;
    }
    if !h.classes.is_empty() {
        // A key of the classes instead of a colour bar.
        let font = ("sans-serif", 15).into_font();
        bar.draw_text(&h.value_label, &font.color(&BLACK), (10, 50)).map_err(e2s)?;
        for (k, (_, name)) in h.classes.iter().enumerate() {
            let y = 80 + 26 * k as i32;
            bar.draw(&Rectangle::new([(10, y), (30, y + 18)], class_colour(k).filled())).map_err(e2s)?;
            bar.draw(&Rectangle::new([(10, y), (30, y + 18)], BLACK.stroke_width(1))).map_err(e2s)?;
            bar.draw_text(name, &font.color(&BLACK), (38, y + 1)).map_err(e2s)?;
        }
        return root.present().map_err(e2s);
    }
    // Colour bar with its scale.
    let mut cb = ChartBuilder::on(&bar)
        .margin_top(50)
        .margin_bottom(60)
        .margin_right(10)
        .y_label_area_size(70)
        .caption(&h.value_label, ("sans-serif", 14))
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(|e| e.to_string())?;
    let bf = move |v: &f64| tick_label(*v, lo, hi, 10);
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(10)
        .y_label_formatter(&bf)
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| e.to_string())?;
    let n = 100;
    cb.draw_series((0..n).map(|i| {
        let a = lo + span * i as f64 / n as f64;
        let b = lo + span * (i + 1) as f64 / n as f64;
        Rectangle::new([(0.0, a), (1.0, b)], heat_colour(i as f64 / (n - 1) as f64).filled())
    }))
    .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

fn write_both(
    stem: &Path,
    draw_png: impl FnOnce(&Path) -> std::result::Result<(), String>,
    draw_svg: impl FnOnce(&mut String) -> std::result::Result<(), String>,
) -> Result<()> {
    register_font();
    let png = stem.with_extension("png");
    // plotters picks the encoder from the extension, so the temporary name keeps ".png".
    let tmp = temp_path(&png).with_extension("tmp.png");
    draw_png(&tmp).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        plot_err(&png, e)
    })?;
    rename(&tmp, &png)?;
    let svg_path = stem.with_extension("svg");
    let mut svg = String::new();
    draw_svg(&mut svg).map_err(|e| plot_err(&svg_path, e))?;
    write_atomic(&svg_path, svg.as_bytes())
}

/// Write `chart` to `<stem>.png` and `<stem>.svg`.
pub fn line_chart(stem: &Path, chart: &LineChart) -> Result<()> {
    let xy = XyChart {
        title: chart.title.clone(),
        x_label: chart.x_label.clone(),
        y_label: chart.y_label.clone(),
        series: chart.series.clone(),
        note: chart.note.clone(),
        ..XyChart::default()
    };
    xy_chart(stem, &xy)
}

/// Pixel size of `chart`: the standard size, or for an equal-aspect chart a height that fits the
/// data's aspect (a long straight course gets a short, wide image).
pub fn chart_size(chart: &XyChart) -> (u32, u32) {
    if !chart.equal_aspect {
        return SIZE;
    }
    let all = || {
        chart
            .series
            .iter()
            .chain(&chart.ref_paths)
            .flat_map(|s| s.points.iter().copied())
            .chain(chart.markers.iter().copied())
    };
    let (x0, x1) = padded(extent(all().map(|p| p.0)));
    let (y0, y1) = padded(extent(all().map(|p| p.1)));
    let plot_w = f64::from(SIZE.0 - legend_width(&chart.legend()) - 110);
    let notes = 18 * note_lines(&chart.note, SIZE.0 as usize / 8).len() as u32;
    let h = (plot_w * (y1 - y0) / (x1 - x0)).round() as u32 + 130 + notes;
    (SIZE.0, h.clamp(360, 900))
}

/// Write `chart` (with its outlines, markers and spans) to `<stem>.png` and `<stem>.svg`.
pub fn xy_chart(stem: &Path, chart: &XyChart) -> Result<()> {
    // Curves that cover others are named under the chart (unless they all coincide, which the
    // caller's coincidence note says).
    let hidden = hidden_note(&chart.series);
    let noted;
    let chart = if hidden.is_empty() || !coincidence_note(&chart.series, "").is_empty() {
        chart
    } else {
        let note = if chart.note.is_empty() { hidden } else { format!("{} {hidden}", chart.note) };
        noted = XyChart { note, ..chart.clone() };
        &noted
    };
    let size = chart_size(chart);
    write_both(
        stem,
        |p| draw_lines(PngBackend(BitMapBackend::new(p, size)).into_drawing_area(), chart),
        |s| draw_lines(SVGBackend::with_string(s, size).into_drawing_area(), chart),
    )
}

/// Write the small multiples `fig` to `<stem>.png` and `<stem>.svg`.
pub fn figure(stem: &Path, fig: &Figure) -> Result<()> {
    // A curve covered in every panel is named once under the figure (panels differ: not named).
    let hidden: Vec<String> = fig.panels.iter().map(|p| hidden_note(&p.series)).collect();
    let noted;
    let fig = match hidden.first() {
        Some(h) if !h.is_empty() && hidden.iter().all(|x| x == h) => {
            let note = if fig.note.is_empty() { h.clone() } else { format!("{} {h}", fig.note) };
            noted = Figure { note, ..fig.clone() };
            &noted
        }
        _ => fig,
    };
    let size = figure_size(fig.panels.len());
    write_both(
        stem,
        |p| draw_figure(PngBackend(BitMapBackend::new(p, size)).into_drawing_area(), fig),
        |s| draw_figure(SVGBackend::with_string(s, size).into_drawing_area(), fig),
    )
}

/// Write `map` to `<stem>.png` and `<stem>.svg`.
pub fn heat_map(stem: &Path, map: &HeatMap) -> Result<()> {
    write_both(
        stem,
        |p| draw_heat(PngBackend(BitMapBackend::new(p, SIZE)).into_drawing_area(), map),
        |s| draw_heat(SVGBackend::with_string(s, SIZE).into_drawing_area(), map),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_chart_and_heat_map_write_valid_png_and_svg() {
        let dir = std::env::temp_dir().join(format!("vehsim-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let chart = LineChart {
            title: "sine".into(),
            x_label: "t (s)".into(),
            y_label: "y (m)".into(),
            series: vec![Series {
                label: "a".into(),
                points: (0..50).map(|i| (i as f64 * 0.1, (i as f64 * 0.1).sin())).collect(),
            }],
            note: "a note under the chart".into(),
        };
        line_chart(&dir.join("lines"), &chart).unwrap();
        let map = HeatMap {
            title: "grid".into(),
            x_label: "x (mm)".into(),
            y_label: "y (mm)".into(),
            value_label: "p (kPa)".into(),
            x_range: (0.0, 4.0),
            y_range: (0.0, 3.0),
            values: vec![vec![1.0, 2.0, 3.0, 4.0], vec![2.0, 3.0, 4.0, 5.0], vec![3.0, 4.0, 5.0, 6.0]],
            classes: Vec::new(),
        };
        heat_map(&dir.join("heat"), &map).unwrap();
        let wet = HeatMap {
            classes: vec![(0.0, "dry".into()), (1.0, "wet".into())],
            values: vec![vec![0.0, 1.0], vec![1.0, 1.0]],
            ..map.clone()
        };
        heat_map(&dir.join("wet"), &wet).unwrap();
        let panel = |v: f64| XyChart {
            title: format!("mu = {v}"),
            series: vec![Series { label: "median".into(), points: vec![(0.0, v), (1.0, 2.0 * v)] }],
            bands: vec![Band {
                label: "5-95 %".into(),
                colour: 0,
                alpha: 0.2,
                points: vec![(0.0, 0.0, v), (1.0, v, 3.0 * v)],
            }],
            ..XyChart::default()
        };
        figure(
            &dir.join("panels"),
            &Figure { title: "panels".into(), panels: vec![panel(1.0), panel(2.0), panel(3.0)], note: String::new() },
        )
        .unwrap();
        let svg = std::fs::read_to_string(dir.join("panels.svg")).unwrap();
        assert!(svg.contains("mu = 3") && svg.contains("5-95 %"), "panel titles or shared legend missing");
        for f in ["lines.png", "heat.png", "wet.png", "panels.png"] {
            let b = std::fs::read(dir.join(f)).unwrap();
            assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "{f} is not a PNG");
        }
        for f in ["lines.svg", "heat.svg", "wet.svg", "panels.svg"] {
            let s = std::fs::read_to_string(dir.join(f)).unwrap();
            assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"), "{f} is not an SVG");
            assert!(s.contains("<text"), "{f} has no text");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// CIELAB (D65) of an sRGB colour, for the distinctness check (an independent formula, not
    /// the plotting code).
    fn lab(c: RGBColor) -> [f64; 3] {
        let lin = |u: u8| {
            let u = f64::from(u) / 255.0;
            if u > 0.04045 {
                ((u + 0.055) / 1.055).powf(2.4)
            } else {
                u / 12.92
            }
        };
        let (r, g, b) = (lin(c.0), lin(c.1), lin(c.2));
        let x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
        let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
        let z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
        let f = |t: f64| if t > 0.008856 { t.cbrt() } else { 7.787 * t + 16.0 / 116.0 };
        [116.0 * f(y) - 16.0, 500.0 * (f(x) - f(y)), 200.0 * (f(y) - f(z))]
    }

    fn delta_e(a: RGBColor, b: RGBColor) -> f64 {
        let (p, q) = (lab(a), lab(b));
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    }

    #[test]
    fn twelve_colours_are_distinct_from_each_other_and_the_background() {
        const { assert!(PALETTE_LEN >= 12) };
        for i in 0..PALETTE_LEN {
            assert!(delta_e(palette(i), WHITE) > 30.0, "colour {i} too close to white");
            for j in 0..i {
                // CIE76 distance; about 2 is barely noticeable, 20 clearly different hues.
                let d = delta_e(palette(i), palette(j));
                assert!(d > 20.0, "colours {i} and {j} too alike: dE = {d:.1}");
            }
        }
        assert_eq!(palette(PALETTE_LEN), palette(0));
    }

    #[test]
    fn tick_labels_never_read_minus_zero() {
        // Steps of 1, 2 or 5 times a power of ten, as plotters places its ticks.
        assert_eq!(tick_step(0.0, 9.9, 10), 1.0);
        assert_eq!(tick_step(0.0, 9.9, 6), 2.0);
        assert_eq!(tick_step(0.0, 0.42, 10), 0.05);
        assert_eq!(tick_step(0.0, 400.0, 10), 50.0);
        assert_eq!(tick_label(-0.0, 0.0, 1.0, 10), "0.0");
        assert_eq!(tick_label(-1e-17, 0.0, 1.0, 10), "0.0");
        assert_eq!(tick_label(-0.04, -5.0, 5.0, 10), "0");
        assert_eq!(tick_label(-0.5, -1.0, 1.0, 10), "-0.5");
        assert_eq!(tick_label(0.35, 0.0, 0.42, 10), "0.35");
        assert_eq!(tick_label(120.0, 0.0, 400.0, 10), "120");
        assert_eq!(tick_label(4.0, 0.0, 9.9, 10), "4");
    }

    #[test]
    fn tick_labels_of_plotters_own_ticks_are_distinct_and_exact_to_half_a_step() {
        use plotters::coord::ranged1d::Ranged;
        use plotters::coord::types::RangedCoordf64;
        // Ranges of many widths and offsets, including the steer axis of a constant-radius run
        // (about 3.97 to 4.46 deg), where labels once repeated ("4.0, 4.0, 4.0, 4.1").
        let mut ranges = vec![(3.97, 4.46), (3.9512, 4.4688), (-0.21, 0.16), (0.0, 7.35)];
        for k in 0..400 {
            let lo = -3.0 + 0.0173 * k as f64;
            ranges.push((lo, lo + 0.05 + 0.011 * (k % 97) as f64));
        }
        for (lo, hi) in ranges {
            for max in [6, 10] {
                let ticks = RangedCoordf64::from(lo..hi).key_points(max);
                let labels: Vec<String> = ticks.iter().map(|&v| tick_label(v, lo, hi, max)).collect();
                for (w, &v) in labels.windows(2).zip(&ticks) {
                    assert_ne!(w[0], w[1], "{lo}..{hi}, {max} labels: {labels:?}");
                    let step = tick_step(lo, hi, max);
                    assert!((w[0].parse::<f64>().unwrap() - v).abs() <= step / 2.0, "{v} as {}", w[0]);
                }
            }
        }
    }

    #[test]
    fn equal_aspect_gives_both_axes_the_same_scale_and_keeps_the_data() {
        let (x, y) = equal_aspect((0.0, 100.0), (-2.0, 6.0), (800, 500));
        assert!(((x.1 - x.0) / 800.0 - (y.1 - y.0) / 500.0).abs() < 1e-12);
        assert_eq!(x, (0.0, 100.0), "the longer axis keeps its range");
        assert!(y.0 <= -2.0 && y.1 >= 6.0 && (0.5 * (y.0 + y.1) - 2.0).abs() < 1e-12);
        // A tall data set widens x instead.
        let (x, y) = equal_aspect((-1.0, 1.0), (0.0, 50.0), (800, 500));
        assert!(((x.1 - x.0) / 800.0 - (y.1 - y.0) / 500.0).abs() < 1e-12 && y == (0.0, 50.0));
    }

    #[test]
    fn classes_take_the_nearest_value_and_legend_lists_each_label_once() {
        let c = vec![(0.0, "dry".to_string()), (1.0, "wet".to_string())];
        assert_eq!(class_of(&c, 0.0), Some(0));
        assert_eq!(class_of(&c, 0.9), Some(1));
        assert_eq!(class_of(&c, f64::NAN), None);
        assert_eq!(class_of(&[], 1.0), None);
        let chart = XyChart {
            series: vec![
                Series { label: "a".into(), points: vec![] },
                Series { label: "a".into(), points: vec![] },
                Series { label: String::new(), points: vec![] },
            ],
            ref_lines: vec![RefLine { label: "mu g".into(), y: 1.5 }],
            ..XyChart::default()
        };
        let l = chart.legend();
        assert_eq!(l.iter().map(|e| e.label.as_str()).collect::<Vec<_>>(), ["a", "mu g"]);
        assert_eq!(chart.style(2), LineStyle { colour: 2, ..LineStyle::default() });
        // Panels of a figure share the union of their ranges.
        let a = XyChart {
            series: vec![Series { label: String::new(), points: vec![(0.0, 0.0), (1.0, 1.0)] }],
            ..XyChart::default()
        };
        let b = XyChart {
            series: vec![Series { label: String::new(), points: vec![(0.0, -5.0), (3.0, 1.0)] }],
            ..XyChart::default()
        };
        let s = shared_axes(&[a, b.clone()]);
        assert_eq!(s[0].x_range, s[1].x_range);
        assert_eq!(s[0].y_range, Some(b.data_ranges().1));
        assert_eq!(s[0].x_range, Some(b.data_ranges().0));
        // The union is padded by 5 % of its own span at both ends, even where the panel that sets
        // an end spans little (y from 2 to 2.1 here, the union from -5 to 2.1).
        let c = XyChart {
            series: vec![Series { label: String::new(), points: vec![(0.0, 2.0), (1.0, 2.1)] }],
            ..XyChart::default()
        };
        let s = shared_axes(&[b, c]);
        let (lo, hi) = s[1].y_range.unwrap();
        assert!((hi - (2.1 + 0.05 * 7.1)).abs() < 1e-12 && (lo - (-5.0 - 0.05 * 7.1)).abs() < 1e-12, "{lo} {hi}");
    }

    #[test]
    fn coinciding_curves_get_a_note_and_different_ones_do_not() {
        let curve = |label: &str, k: f64| Series {
            label: label.into(),
            points: (0..5).map(|i| (i as f64, k * i as f64)).collect(),
        };
        let note = coincidence_note(&[curve("dT = 0 K", 1.0), curve("dT = 1 K", 1.0), curve("dT = 2 K", 1.0)], "Fy");
        assert!(
            note.contains("all 3 curves coincide") && note.contains("dT = 0 K to dT = 2 K") && note.contains("Fy"),
            "{note}"
        );
        assert!(coincidence_note(&[curve("a", 1.0), curve("b", 1.001)], "Fy").is_empty());
        assert!(coincidence_note(&[curve("a", 1.0)], "Fy").is_empty(), "one curve has nothing to coincide with");
    }

    #[test]
    fn a_covered_curve_is_named_under_the_chart() {
        let curve = |label: &str, k: f64| Series {
            label: label.into(),
            points: (0..5).map(|i| (i as f64, k * i as f64)).collect(),
        };
        let note = hidden_note(&[curve("dugoff", 1.0), curve("pacejka", 2.0), curve("dugoff_thermal", 1.0 + 1e-5)]);
        assert_eq!(note, "Note: 'dugoff' lies under 'dugoff_thermal' (equal to within 0.1 % of the axis).");
        assert!(hidden_note(&[curve("a", 1.0), curve("b", 1.01)]).is_empty(), "1 % apart is visible");
        assert!(hidden_note(&[curve("a", 1.0), curve("", 1.0)]).is_empty(), "unlabelled curves are not named");
    }

    #[test]
    fn thinning_keeps_ends_and_drops_sub_pixel_steps() {
        let pts: Vec<(f64, f64)> = (0..=1000).map(|i| (i as f64 * 1e-3, 0.0)).collect();
        let t = thin(&pts, 0.01, 0.01);
        assert_eq!(t.first(), Some(&(0.0, 0.0)));
        assert_eq!(t.last(), pts.last());
        assert!(t.len() <= 102 && t.len() >= 100, "{}", t.len());
        assert!(t.windows(2).take(t.len() - 2).all(|w| w[1].0 - w[0].0 >= 0.01 - 1e-12));
    }

    #[test]
    fn equal_aspect_images_follow_the_data_shape() {
        let path = |w: f64, h: f64| XyChart {
            series: vec![Series { label: String::new(), points: vec![(0.0, 0.0), (w, h)] }],
            equal_aspect: true,
            ..XyChart::default()
        };
        let (wide, square) = (chart_size(&path(110.0, 5.0)), chart_size(&path(80.0, 80.0)));
        assert!(wide.1 < square.1, "{wide:?} {square:?}");
        assert_eq!(chart_size(&XyChart::default()), SIZE);
    }

    #[test]
    fn notes_wrap_and_grids_hold_every_panel() {
        let lines = note_lines("one two three four five", 10);
        assert_eq!(lines, ["one two", "three four", "five"]);
        assert!(note_lines("", 10).is_empty());
        for n in 1..=24 {
            let (r, c) = grid(n);
            assert!(r * c >= n && c <= 4 && (r - 1) * c < n, "{n} panels in {r} x {c}");
        }
    }
}
